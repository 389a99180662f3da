"""Calibration, step 4: the gains of the rotating forces (unbalance, misalignment) at the
sensor bearing's shaft orders, read from the baseline's own lines there
(:mod:`cmsim.machine.calibration`).
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.machine.calibration.background_lines import _near
from cmsim.machine.machine import static_load
from cmsim.rig import Rig

__all__ = ["BALANCE_GRADE_MM_S", "SHAFT_ORDERS"]

#: Balance grade G = e·Ω (mm/s) the baseline's rotor is taken to have, its shaft-rate line
#: being its residual unbalance (:func:`_shaft_gains`): ISO 21940-11 G 6.3, the grade of
#: electric motors, pumps, fans and gear wheels of general machinery.
BALANCE_GRADE_MM_S = 6.3

#: Shaft orders whose baseline lines give a rotating force's gain (:func:`_shaft_gains`):
#: those of unbalance (1×) and misalignment (2×, 3×).
SHAFT_ORDERS = 3


def _shaft_gains(lines, rig, bearing, fr, df, forces):
    """({order: gain}, force N, share of the static load): the gains, sensor unit per N,
    from a rotating force at the orders 1 to :data:`SHAFT_ORDERS` of the sensor bearing's
    shaft (turning at ``fr`` Hz) to the sensor, read from the baseline's lines there (an
    order without a line gets none: :meth:`~cmsim.machine.Machine.rotating_gain` carries the
    path's shape there at the level of the nearest order that has one).

    The model makes no shaft line, so no model line reads the path there, yet an unbalance
    or a misalignment is judged there: held on the path's assumed f² shape from its lowest
    pin hundreds of hertz up, an unbalance of twice the static load lifted the twin's 1×
    line by at most 0.9 dB (the angle generator's bearing machine of seed 0) where the
    drawn machine's grows 12 dB. A baseline's shaft-rate line is
    its residual unbalance through the machine, so the gain at 1× is that line over the
    force of a residual unbalance of grade :data:`BALANCE_GRADE_MM_S`, e·Ω (ISO 21940-11):
    m·e·Ω² = m·G·Ω on the rotor, half of it on each of its shaft's bearings (both correction
    planes allotted alike), m the shaft's masses in the model (its gear or rotor and its
    bearing nodes). What drives a healthy machine's 2× and 3× lines (residual misalignment,
    run-out, a coupling) has no grade, and is taken as a force of the same magnitude: an
    unbalance or a misalignment is then sized as a trend against the baseline's own lines
    at its orders, which is what practice reads. These gains carry only the rotating
    forces (a sinusoid at a shaft order: a gain is all of its path that a spectrum sees);
    interpolated into the structural path they lifted it over a decade below its lowest
    pin, where the model's own lines then took the mains line for theirs. The static load
    the force is a share of is the model force's, the level an unbalance cause's relative
    amplitude refers to.
    """
    shaft = Rig.shaft_of(bearing) - 1
    s = rig.shafts[shaft]
    centre = ((rig.gears.driving if shaft == 0 else rig.gears.driven).mass_kg
              if rig.gears is not None else s.rotor.mass_kg)
    mass = centre + s.bearing_1.mass_kg + s.bearing_2.mass_kg
    force = 0.5 * mass * BALANCE_GRADE_MM_S * 1e-3 * 2.0 * math.pi * fr
    static = float(np.mean([static_load(x[e:e + n]) for x, e, n in forces]))
    gains = {}
    for k in range(1, SHAFT_ORDERS + 1):
        match = [a for f, a in lines if _near(f, k * fr, df)]
        if match and fr > 0.0:
            gains[k] = max(match) / force
    return gains, force, force / static


def _shaft_words(shaft, fr):
    """The machine file's note on the shaft-order gains (:func:`_shaft_gains`)."""
    gains, force, share = shaft
    if not gains:
        return ("no shaft-order line in the baseline: the rotating forces of unbalance and "
                "misalignment reach the sensor through the path's assumed shape there")
    return (f"rotating forces reach the sensor at the shaft orders "
            f"({', '.join(f'{k}× {k * fr:.2f} Hz' for k in sorted(gains))}) through gains "
            f"read from the baseline's lines there, each taken as the response to the force "
            f"of a residual unbalance of grade G {BALANCE_GRADE_MM_S:g} (ISO 21940-11; "
            f"{force:.3g} N on this bearing, {share:.2g} of its static load): an unbalance or "
            "a misalignment is sized as a trend against the baseline's own lines at its "
            f"orders (a rotor balanced to G 2.5 reads {BALANCE_GRADE_MM_S / 2.5:.1f}× too "
            "large)")
