"""Records with a hidden effect: "measured" signals made by the model, for tests and benchmarks.

:func:`hidden_effect_record` simulates a rig with one effect of the cause catalogue at a
random severity on a random component, plus nuisances the pipeline is not told about: the
housing modes moved by ±5 % and their damping by ±25 %, sensor noise of 7-14 % of the
healthy signal's RMS, a 0.2 % speed wobble at 0.5-2 Hz and a load off by ±10 %.
``effect=None`` gives a record with no hidden effect. The pipeline receives only the
documented rig and operating point, as :func:`~cmsim.measured.read_record` would
build them.

Bearing, operating and measurement-chain effects sit on the CWRU-like rig (drive-end 6205
as ``1b1`` next to the sensor, fan-end 6203 as ``1b2``, 10-kg rotor, 1797 rpm, 12 kHz);
gear effects (``eccentricity``, ``tooth_fault``, ``friction``) and ``speed_fluctuation`` on
the paper's gear rig (1000 rpm, 50 N·m, sensor on bearing ``1b1``, 20 kHz). A once-per-rev
speed fluctuation of 1.5-5 % is read from the GMF sidebands it makes; on the gearless rig its
only trace is the frequency modulation of the weak ball-pass lines, 15-25 dB down, below the
record's noise (measured: Δχ² ≤ 11 there, under the naming threshold).

A hidden eccentricity is a fault, 25-100 µm: a radial run-out 2e of 50-200 µm, beyond the
ISO 1328 run-out tolerance of a grade-8 gear of this size (about 44 µm). Within tolerance
(e ≈ 10 µm) the shaft-rate sidebands it makes in this model barely leave the noise of 0.5-s
segments (measured: the eccentric model's features differ from the nominal one's by a χ² of
about 6 at 10 µm, 18 at 25 µm and 33 at 50 µm over 6 seeds, the naming threshold being 30).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from cmsim.discrepancy.causes import CAUSES, ModelSetup
from cmsim.discrepancy.evaluator import simulate_setup
from cmsim.measured import record_from_run
from cmsim.faults import SpeedFluctuation
from cmsim.rig import OperatingPoint, Rig, RollingBearing, Rotor
from cmsim.run import Run

__all__ = ["HIDDEN_EFFECTS", "GEAR_EFFECTS", "HiddenRecord", "hidden_effect_record",
           "cwru_like_rig"]

#: Effect → (low, high) severity of the cause's (first) parameter, drawn log-uniformly; a
#: second range (for factors) is drawn with probability 1/2.
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
    "eccentricity": [(2.5e-5, 1e-4)],
    "tooth_fault": [(5e-4, 2e-3)],
    "friction": [(8e-7, 2.5e-6)],
    "unbalance": [(0.2, 0.8)],
    "misalignment": [(0.2, 0.8)],
}

#: Effects simulated on the gear rig.
GEAR_EFFECTS = ("eccentricity", "tooth_fault", "friction", "speed_fluctuation")

FS_HZ = 12_000.0
SPEED_RPM = 1797.0
GEAR_FS_HZ = 20_000.0
GEAR_SPEED_RPM = 1000.0
GEAR_TORQUE_NM = 50.0
DURATION_S = 3.0


def cwru_like_rig():
    """The CWRU rig as the record reader models it: drive-end 6205 (``1b1``), fan-end 6203
    (``1b2``), 10-kg rotor, 5 µm clearance."""
    de = RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3, clearance_m=5e-6)
    fe = RollingBearing.from_pitch(8, 6.75e-3, 28.5e-3, clearance_m=5e-6)
    return Rig.rotor_on_bearings(de, Rotor(mass_kg=10.0, inertia_kg_m2=0.02), bearing_2=fe)


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
        Its (first) parameter value.
    component : str or None
        Its component.
    """

    record: object
    effect: str | None
    value: float | None
    component: str | None


def hidden_effect_record(effect, seed, *, duration_s=DURATION_S, rig_kind=None,
                         sim_seed=None):
    """A "measured" record with one hidden effect (or none) and nuisances.

    Parameters
    ----------
    effect : str or None
        A key of :data:`HIDDEN_EFFECTS`, or None.
    seed : int
        Seed of the severity, component, nuisances and simulation.
    duration_s : float
        Record length, s.
    rig_kind : {"bearing", "gear"}, optional
        Rig of a record without a hidden effect (default: the bearing rig); an effect
        brings its own rig.
    sim_seed : int, optional
        Seed of the simulation (default ``seed + 100000``): the machine (its nuisances)
        follows ``seed`` alone, so ``hidden_effect_record(None, seed, sim_seed=...)`` is a
        healthy baseline of the same machine, another realisation.

    Returns
    -------
    HiddenRecord
    """
    rng = np.random.default_rng(seed)
    gear = effect in GEAR_EFFECTS or (effect is None and rig_kind == "gear")
    if gear:
        rig, fs = Rig.paper_2016(), GEAR_FS_HZ
        op = OperatingPoint(GEAR_SPEED_RPM, GEAR_TORQUE_NM)
    else:
        rig, fs = cwru_like_rig(), FS_HZ
        op = OperatingPoint(SPEED_RPM, radial_load_n=98.0665)
    h = rig.housing
    housing = replace(h, natural_frequencies_hz=tuple(
        f * rng.uniform(0.95, 1.05) for f in h.natural_frequencies_hz),
        damping_ratios=tuple(z * rng.uniform(0.8, 1.25) for z in h.damping_ratios))
    factor = rng.uniform(0.9, 1.1)
    true_op = (replace(op, torque_nm=op.torque_nm * factor) if gear
               else replace(op, radial_load_n=op.radial_load_n * factor))
    wobble = SpeedFluctuation(relative_amplitude=0.002, frequency_hz=rng.uniform(0.5, 2.0))
    setup = ModelSetup(rig=rig, op=true_op, faults=(wobble,), housing=housing,
                       noise_ratio=rng.uniform(0.07, 0.14))
    value = component = None
    # the sensor noise is fixed by the healthy machine's level (a fault rises above it)
    ref = float(np.std(simulate_setup(setup, fs, 0.5, "accel_1b1_y", int(seed) + 200_000,
                                      noise_ref_rms=0.0)))
    if effect is not None:
        ranges = HIDDEN_EFFECTS[effect]
        lo, hi = ranges[int(rng.integers(len(ranges)))]
        value = float(math.exp(rng.uniform(math.log(lo), math.log(hi))))
        cause = CAUSES[effect]()
        comps = cause.components(rig, "1b1")
        component = comps[int(rng.integers(len(comps)))]
        values = {**cause.start(rig), cause.params[0].name: value}
        setup = cause.extend(setup, values, component)
    x = simulate_setup(setup, fs, duration_s, "accel_1b1_y",
                       int(seed) + 100_000 if sim_seed is None else int(sim_seed),
                       noise_ref_rms=ref)
    run = Run(np.arange(x.size) / fs, {"DE": x}, {"fs_hz": fs}, source="measured")
    comps = ({"1G1": "input gear", "2G1": "output gear"} if gear
             else {"1b1": "drive_end", "1b2": "fan_end"})
    record = record_from_run(run, "DE", rig, op, model_signal="accel_1b1_y",
                             components=comps, unit_scale=1.0)
    return HiddenRecord(record=record, effect=effect, value=value,
                        component=None if component is None else comps.get(component,
                                                                            component))

