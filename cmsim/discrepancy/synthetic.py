"""Records with a hidden effect: "measured" signals made by the model, for tests and benchmarks.

:func:`hidden_effect_record` simulates the CWRU-like bearing rig (6205 bearings, 10-kg rotor,
12 kHz) with one effect of the cause catalogue at a random severity, plus nuisances the
pipeline is not told about: the housing modes moved by ±5 % and their damping by ±25 %,
sensor noise of 7-14 % of the signal RMS, a 0.2 % speed wobble at 0.5-2 Hz and a radial load
off by ±10 %. ``effect=None`` gives a record with no hidden effect. The pipeline receives
only the documented rig and operating point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from cmsim.discrepancy.causes import CAUSES, ModelSetup
from cmsim.discrepancy.compare import simulate_setup
from cmsim.discrepancy.records import record_from_run
from cmsim.faults import SpeedFluctuation
from cmsim.rig import OperatingPoint, Rig, RollingBearing, Rotor
from cmsim.run import Run

__all__ = ["HIDDEN_EFFECTS", "HiddenRecord", "hidden_effect_record", "cwru_like_rig"]

#: Effect → (low, high) severity of the cause's parameter, drawn log-uniformly; a second
#: range (for factors) is drawn with probability 1/2.
HIDDEN_EFFECTS = {
    "bearing_outer_race": [(4e-4, 1.5e-3)],
    "bearing_inner_race": [(4e-4, 1.5e-3)],
    "bearing_ball": [(4e-4, 1.5e-3)],
    "clearance": [(2.5e-5, 6e-5)],
    "preload": [(3e-6, 1e-5)],
    "torque_mismatch": [(3.0, 5.0), (0.15, 0.3)],
    "speed_fluctuation": [(0.015, 0.05)],
    "transfer_path": [(0.55, 0.7), (1.4, 1.8)],
    "noise": [(0.8, 3.0)],
    "rolling_slip": [(0.03, 0.1)],
}

FS_HZ = 12_000.0
SPEED_RPM = 1797.0
DURATION_S = 3.0


def cwru_like_rig():
    """The CWRU rig model of the project (6205 bearings, 10-kg rotor)."""
    b = RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3, clearance_m=5e-6)
    return Rig.rotor_on_bearings(b, Rotor(mass_kg=10.0, inertia_kg_m2=0.02))


@dataclass(frozen=True)
class HiddenRecord:
    """A generated record and its answer key.

    Attributes
    ----------
    record : MeasuredRecord
        What the pipeline sees.
    effect : str or None
        The hidden cause (``None``: no hidden effect).
    value : float or None
        Its parameter value.
    component : str or None
        Its component.
    """

    record: object
    effect: str | None
    value: float | None
    component: str | None


def hidden_effect_record(effect, seed, *, duration_s=DURATION_S):
    """A "measured" record with one hidden effect (or none) and nuisances.

    Parameters
    ----------
    effect : str or None
        A key of :data:`HIDDEN_EFFECTS`, or None.
    seed : int
        Seed of the severity, nuisances and simulation.
    duration_s : float
        Record length, s.

    Returns
    -------
    HiddenRecord
    """
    rng = np.random.default_rng(seed)
    rig = cwru_like_rig()
    op = OperatingPoint(SPEED_RPM, radial_load_n=98.0665)
    h = rig.housing
    housing = replace(h, natural_frequencies_hz=tuple(
        f * rng.uniform(0.95, 1.05) for f in h.natural_frequencies_hz),
        damping_ratios=tuple(z * rng.uniform(0.8, 1.25) for z in h.damping_ratios))
    true_op = replace(op, radial_load_n=op.radial_load_n * rng.uniform(0.9, 1.1))
    wobble = SpeedFluctuation(relative_amplitude=0.002, frequency_hz=rng.uniform(0.5, 2.0))
    setup = ModelSetup(rig=rig, op=true_op, faults=(wobble,), housing=housing,
                       noise_ratio=rng.uniform(0.07, 0.14))
    value = component = None
    # the sensor noise is fixed by the healthy machine's level (a fault rises above it)
    ref = float(np.std(simulate_setup(setup, FS_HZ, 0.5, "accel_1b1_y", int(seed) + 200_000,
                                      noise_ref_rms=0.0)))
    if effect is not None:
        ranges = HIDDEN_EFFECTS[effect]
        lo, hi = ranges[int(rng.integers(len(ranges)))]
        value = float(math.exp(rng.uniform(math.log(lo), math.log(hi))))
        cause = CAUSES[effect]()
        component = cause.components(rig, "1b1")[0]
        setup = cause.apply(setup, value, component)
    x = simulate_setup(setup, FS_HZ, duration_s, "accel_1b1_y", int(seed) + 100_000,
                       noise_ref_rms=ref)
    run = Run(np.arange(x.size) / FS_HZ, {"DE": x}, {"fs_hz": FS_HZ}, source="measured")
    record = record_from_run(run, "DE", rig, op, model_signal="accel_1b1_y",
                             components={"1b1": "1b1", "1b2": "1b2"})
    return HiddenRecord(record=record, effect=effect, value=value, component=component)
