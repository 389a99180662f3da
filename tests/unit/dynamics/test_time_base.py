"""Time base of a run: first sample, warm-up, spacing, and θ − Ω·t against the state.

Tier (a) closed form. An off-by-one sample in ``run.t`` (or in the nominal rotation Ω·t added
to the recorded deviation) shifts every absolute angle by Ω/fs, which at 1000 rpm and 20 kHz
is 1.4e-3 rad — 14 times the static twist of the input coupling checked below:

* ``t = (n_warm + k)/fs`` with ``t[0]`` = the recorded ``warmup_s``, on both the direct path
  (``substeps=1``) and the decimated one;
* with no warm-up the first sample is the quasi-static start state ``meta["initial_state"]``
  (the rotations at t = 0, where the nominal rotation is zero);
* a run with a warm-up is the tail of the same run recorded from t = 0 (same seed);
* θ_1b1 − Ω·t is the input coupling's static twist −T·(Z1/Z2)/k_c (mean over a run).
"""

import math

import numpy as np
import pytest

import cmsim
from cmsim.dynamics import simulate

RIG = cmsim.Rig.paper_2016()
OP = cmsim.OperatingPoint(1000.0, 40.0)
FS = 75_000.0                          # the paper's rate: substeps=1 is stable
KW = dict(mesh="potential-energy", seed=3)


@pytest.fixture(scope="module")
def from_zero():
    return simulate(RIG, OP, 0.04, warmup_s=0.0, substeps=1, fs_hz=FS, **KW)


@pytest.fixture(scope="module")
def warm():
    return simulate(RIG, OP, 0.02, warmup_s=0.02, substeps=1, fs_hz=FS, **KW)


def test_time_vector(warm, from_zero):
    for run, warm_s, n in ((warm, 0.02, 1500), (from_zero, 0.0, 3000)):
        assert run.meta["warmup_s"] == pytest.approx(warm_s, abs=1e-12)
        assert run.t[0] == pytest.approx(warm_s, abs=1e-12)
        assert run.t.size == n
        np.testing.assert_allclose(np.diff(run.t), 1.0 / FS, rtol=1e-9)
        assert run.fs_hz == pytest.approx(FS, rel=1e-9)


def test_first_sample_is_the_start_state(from_zero):
    q0 = np.array(from_zero.meta["initial_state"])
    names = from_zero.meta["dof_names"]
    for name in ("x_1G1", "y_2b1", "theta_1G1", "theta_2J2", "theta_1b1"):
        assert from_zero[name][0] == pytest.approx(q0[names.index(name)], rel=1e-12, abs=1e-15)


def test_warm_run_is_the_tail_of_the_run_from_zero(warm, from_zero):
    k = int(round(0.02 * FS))
    np.testing.assert_allclose(warm.t, from_zero.t[k:], rtol=0, atol=1e-12)
    for name in ("theta_1G1", "theta_2J2", "x_1G1", "dte", "F_1b1_loa"):
        a, b = warm[name], from_zero[name][k:]
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.abs(b).max(), err_msg=name)


@pytest.mark.parametrize("fs, substeps", [(FS, 1), (25_600.0, 3)])
def test_rotation_minus_nominal_is_the_coupling_twist(fs, substeps):
    run = simulate(RIG, OP, 0.05, warmup_s=0.02, fs_hz=fs, substeps=substeps, **KW)
    assert run.meta["substeps"] == substeps
    assert run.t[0] == pytest.approx(run.meta["warmup_s"], abs=1e-12)
    assert run.t[0] >= 0.02 - 1e-12
    omega = OP.omega_rad_s
    twist = (run["theta_1b1"] - omega * run.t).mean()
    z1, z2 = RIG.gears.driving.n_teeth, RIG.gears.driven.n_teeth
    want = -OP.torque_nm * z1 / z2 / RIG.input_coupling.stiffness_nm_per_rad
    assert twist == pytest.approx(want, rel=0.02)
    assert abs(omega / fs) > 10 * abs(want)          # a one-sample shift would show
    np.testing.assert_allclose(np.diff(run.t), 1.0 / fs, rtol=1e-9)
    # the driven shaft at Ω·Z1/Z2: θ_2G1 − Ω2·t = (Z1/Z2)·(θ_1G1 − Ω·t − DTE)
    dev2 = run["theta_2G1"] - omega * z1 / z2 * run.t
    dev1 = run["theta_1G1"] - omega * run.t
    np.testing.assert_allclose(dev2, z1 / z2 * (dev1 - run["dte"]), rtol=0, atol=1e-8)
    assert math.isfinite(run.meta["integration_fs_hz"])
    assert run.meta["integration_fs_hz"] == pytest.approx(fs * substeps, rel=1e-12)
