"""Runs integrated together in one time loop (issue 49): a run's samples do not depend on its
batch, and agree with the single-run kernel.

Test tier: behaviour contracts against the reference path (:func:`cmsim.dynamics.simulate`,
the single-run kernel): bit-identity of a run alone and in batches of other sizes, orders and
companions; agreement with the single-run kernel within 1e-9 of each signal's range (the
batch sums each bearing's balls in order, the single-run kernel vectorised); a diverging run
flagged as the single-run path flags it while the others finish. Records of 0.02-0.03 s at
25.6 kHz (rk4, 2 steps per sample, through the anti-alias filter).
"""

from dataclasses import replace

import numpy as np
import pytest

import cmsim
from cmsim.dynamics.batch import kernel_layout, simulate_batch
from cmsim.dynamics.profiles import SpeedProfile
from cmsim.dynamics.simulation import integrate_prepared, prepare_run
from cmsim.errors import IntegrationDiverged
from cmsim.rig import PRESETS
from cmsim.faults import (BallDefect, InnerRaceDefect, OffSizeBall, OuterRaceDefect,
                          RollingSlip, SpeedFluctuation, ToothCrack, ToothSpall)

#: Batched runs: the module waits for the session's one compile of the batch integrator
#: (tests/conftest.py).
pytestmark = pytest.mark.batch_kernels

FS = 25_600.0
DURATION = 0.03


def _gear_runs():
    rig = cmsim.Rig.paper_2016()
    wobble = SpeedFluctuation(relative_amplitude=0.002, frequency_hz=3.0)
    slip = RollingSlip(cage_speed_rms=0.005)
    cases = [(900.0, 30.0, ()), (1000.0, 80.0, (ToothCrack(gear=1, depth_m=2e-3),)),
             (1200.0, 50.0, (ToothSpall(gear=2, width_m=1e-3, depth_m=20e-6),)),
             (1100.0, 20.0, ()), (950.0, 60.0, (ToothCrack(gear=2, depth_m=1e-3),))]
    return [prepare_run(rig, cmsim.OperatingPoint(rpm, torque), DURATION, fs_hz=FS, seed=i,
                        warmup_s=0.01, faults=(*faults, wobble, slip))
            for i, (rpm, torque, faults) in enumerate(cases)]


def _bearing_runs():
    rig = PRESETS["cwru_6205"]()
    slip = RollingSlip(cage_speed_rms=0.01)
    cases = [(1750.0, 300.0, OuterRaceDefect("1b1", size_m=0.5e-3, depth_m=0.2e-3)),
             (1730.0, 100.0, OuterRaceDefect("1b1", size_m=0.3e-3, depth_m=0.3e-3)),
             (1790.0, 500.0, OuterRaceDefect("1b1", size_m=0.7e-3, depth_m=0.1e-3))]
    return [prepare_run(rig, cmsim.OperatingPoint(rpm, radial_load_n=load), DURATION,
                        fs_hz=12_000.0, seed=10 + i, warmup_s=0.01, faults=(fault, slip))
            for i, (rpm, load, fault) in enumerate(cases)]


def _near_reference(setups, runs):
    """Each run within 1e-9 of each signal's range of the single-run kernel's."""
    for setup, run in zip(setups, runs):
        ref = integrate_prepared(setup)
        assert run.meta["scheme"] == ref.meta["scheme"]
        for name in ref.signals:
            span = np.ptp(ref[name]) + 1e-300
            assert np.max(np.abs(run[name] - ref[name])) <= 1e-9 * span, name


def _same(a, b):
    assert sorted(a.signals) == sorted(b.signals)
    for name in a.signals:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


@pytest.fixture(scope="module")
def gear():
    runs = _gear_runs()
    return runs, simulate_batch(runs)


def test_a_run_is_the_same_alone_and_in_any_batch(gear):
    runs, together = gear
    assert len({kernel_layout(r) for r in runs}) == 2          # healthy; tooth faults
    for i in (0, 1, 4):
        _same(simulate_batch([runs[i]])[0], together[i])        # a batch of one
    reordered = simulate_batch([runs[4], runs[2], runs[1]])     # other places, companions
    _same(reordered[0], together[4])
    _same(reordered[2], together[1])
    in_twos = simulate_batch(runs, batch_size=2)
    for a, b in zip(in_twos, together):
        _same(a, b)


def test_a_run_agrees_with_the_single_run_kernel(gear):
    runs, together = gear
    assert {r.meta["scheme"] for r in together} == {"rk4"}
    _near_reference(runs, together)


def test_bearing_defects_batch_like_the_single_run_kernel():
    runs = _bearing_runs()
    together = simulate_batch(runs)
    _near_reference(runs, together)
    _same(simulate_batch(runs[1:2])[0], together[1])


def test_every_kind_of_bearing_defect_batches_like_the_single_run_kernel():
    # inner race, a ball defect whose axis wanders (the share the races meet varies in time),
    # two defects on one bearing, and an off-size ball (the whole bearing ball by ball, run
    # by run through the single-run kernel): two runs of each, one batch per layout
    rig = PRESETS["cwru_6205"]()
    slip = RollingSlip(cage_speed_rms=0.01)
    kinds = [(InnerRaceDefect("1b1", size_m=0.5e-3, depth_m=0.2e-3),),
             (BallDefect("1b1", size_m=0.6e-3, depth_m=0.2e-3, axis_offset=0.3,
                         wander_s=0.005),),
             (OuterRaceDefect("1b1", size_m=0.4e-3, depth_m=0.2e-3),
              InnerRaceDefect("1b1", size_m=0.3e-3, depth_m=0.3e-3)),
             (OffSizeBall("1b1", ball=2, diameter_excess_m=3e-6),
              OuterRaceDefect("1b1", size_m=0.4e-3, depth_m=0.2e-3))]
    runs = [prepare_run(rig, cmsim.OperatingPoint(rpm, radial_load_n=load), DURATION,
                        fs_hz=12_000.0, seed=20 + 2 * j + i, warmup_s=0.01,
                        faults=(*faults, slip))
            for j, faults in enumerate(kinds)
            for i, (rpm, load) in enumerate(((1760.0, 400.0), (1795.0, 150.0)))]
    assert len({kernel_layout(r) for r in runs}) == len(kinds)
    together = simulate_batch(runs)
    _near_reference(runs, together)
    for i in (1, 2, 5, 6):
        _same(simulate_batch([runs[i]])[0], together[i])        # a batch of one
    _same(simulate_batch([runs[3], runs[2]])[1], together[2])    # another place


def test_a_diverging_run_is_flagged_and_the_others_finish(gear):
    runs, together = gear
    bad = replace(runs[3], y0=np.where(np.arange(runs[3].y0.size) == 0, 0.5, runs[3].y0))
    out = simulate_batch([runs[0], bad, runs[1]])
    assert isinstance(out[1], IntegrationDiverged)
    with pytest.raises(IntegrationDiverged) as alone:
        integrate_prepared(bad)
    assert str(out[1]) == str(alone.value)                    # as the single-run path says
    _same(out[0], together[0])
    _same(out[2], together[1])


def test_runs_the_batch_kernel_does_not_take_run_alone():
    rig = cmsim.Rig.paper_2016()
    op = cmsim.OperatingPoint(1000.0, 50.0)
    fast = prepare_run(rig, op, 0.01, fs_hz=75_000.0, seed=1, warmup_s=0.005)   # 1 step/sample
    lawson = prepare_run(rig, op, DURATION, fs_hz=FS, seed=1, warmup_s=0.01,
                         scheme="lawson-ode3")
    assert kernel_layout(fast) is None and kernel_layout(lawson) is None
    for setup, run in zip((fast, lawson), simulate_batch([fast, lawson])):
        _same(run, integrate_prepared(setup))


def test_a_run_up_batches_with_its_own_profile():
    rig = cmsim.Rig.paper_2016()
    runs = [prepare_run(rig, cmsim.OperatingPoint(rpm, 50.0), DURATION, fs_hz=FS, seed=3,
                        warmup_s=0.01, profile=SpeedProfile.ramp(rpm, rpm + 300.0, DURATION,
                                                                 start_s=0.01))
            for rpm in (800.0, 1200.0)]
    _near_reference(runs, simulate_batch(runs))
