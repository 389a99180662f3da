"""The integration step follows the fastest excitation as well as the highest mode (issue 26).

Tier (a) closed form: GMF = Z1·fr and the ball-pass rates are kinematics, so the least
integration rate that resolves the first RESOLVED_HARMONICS harmonics of the mesh with
STEPS_PER_PERIOD steps each is known before anything is simulated. At 100 000 rpm the paper's
mesh runs at 46.7 kHz, above the Nyquist frequency of the default 75 kHz: a step chosen from
the highest mode alone (75 kHz, 1.6 steps per mesh period) folded its third harmonic back to
10 kHz without any warning.
"""

import pytest

import cmsim
from cmsim.dynamics import simulate
from cmsim.dynamics.step import (RESOLVED_HARMONICS, STEPS_PER_PERIOD, Excitation,
                                 fastest_excitation, integration_substeps)
from cmsim.errors import ParameterError
from cmsim.features import N_GMF_HARMONICS
from cmsim.rig.presets import cwru_6205_rig

RIG = cmsim.Rig.paper_2016()
FAST = cmsim.OperatingPoint(100_000.0, 50.0)
GMF_FAST = 28 * 100_000.0 / 60.0


def test_fastest_excitation_is_the_mesh_on_a_gear_rig_and_a_ball_pass_without_gears():
    e = fastest_excitation(RIG, FAST)
    assert e.name == "GMF" and e.hz == pytest.approx(GMF_FAST)
    cwru = cwru_6205_rig()
    e = fastest_excitation(cwru, cmsim.OperatingPoint(1797.0))
    assert e.name.startswith("BPFI") and e.hz == pytest.approx(162.19, abs=0.01)


def test_a_run_up_counts_at_its_fastest_speed():
    e = fastest_excitation(RIG, cmsim.OperatingPoint(1000.0), speed_ratio=3.0)
    assert e.hz == pytest.approx(3 * 28 * 1000.0 / 60.0) and e.speed_rpm == 3000.0


def test_resolved_harmonics_are_the_ones_the_features_measure():
    assert RESOLVED_HARMONICS == N_GMF_HARMONICS


def test_automatic_step_follows_the_faster_of_mode_and_excitation():
    slow = Excitation("GMF", 466.67, 1000.0)
    assert integration_substeps(75_000.0, slow, 15_935.0) == 1          # the paper's step
    assert integration_substeps(25_600.0, slow, 15_935.0) == 3
    fast = Excitation("GMF", GMF_FAST, 100_000.0)
    n = integration_substeps(75_000.0, fast, 15_935.0)
    assert 75_000.0 * n >= STEPS_PER_PERIOD * RESOLVED_HARMONICS * GMF_FAST
    assert 75_000.0 * (n - 1) < STEPS_PER_PERIOD * RESOLVED_HARMONICS * GMF_FAST


def test_a_given_step_that_does_not_resolve_the_mesh_is_refused_with_the_least_that_does():
    fast = Excitation("GMF", GMF_FAST, 100_000.0)
    with pytest.raises(ParameterError, match=r"substeps must be an integer in \[18, 1000\]") \
            as err:
        integration_substeps(75_000.0, fast, substeps=1)
    assert err.value.param == "substeps" and "speed_rpm at most 5699" in str(err.value)
    assert integration_substeps(75_000.0, fast, substeps=18) == 18


def test_more_substeps_than_allowed_names_the_sample_rate_that_works():
    fast = Excitation("GMF", GMF_FAST, 100_000.0)
    with pytest.raises(ParameterError, match=r"fs_hz must be >= 1316") as err:
        integration_substeps(1000.0, fast)
    assert err.value.param == "fs_hz"


def test_simulate_at_100000_rpm_integrates_fast_enough_for_the_mesh():
    """The issue's run: the step resolves six mesh harmonics, the meta says what set it, and
    a step the caller fixes below that is refused instead of run."""
    run = simulate(RIG, FAST, 0.005, warmup_s=0.002, seed=0)
    assert run.meta["fastest_excitation"]["name"] == "GMF"
    assert run.meta["integration_fs_hz"] >= STEPS_PER_PERIOD * RESOLVED_HARMONICS * GMF_FAST
    with pytest.raises(ParameterError) as err:
        simulate(RIG, FAST, 0.005, warmup_s=0.002, seed=0, substeps=1)
    assert err.value.param == "substeps"
