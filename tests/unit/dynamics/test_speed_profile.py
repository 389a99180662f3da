"""Non-stationary speed: a run-up follows its profile (issue 16, "Non-stationary speed").

Tier (a) closed form: the exact shaft angle of a piecewise-linear speed, a constant-speed
profile reproducing the stationary run, and the order spectrum of a 300 → 1500 rpm run-up
(resampled with a once-per-revolution tacho) showing the GMF order as one sharp line and the
ball-pass order where the cage kinematics put it.
"""

import math

import numpy as np
import pytest

import cmsim
from cmsim.bearings.kinematics import ball_pass_cycles_per_rev
from cmsim.dynamics import simulate
from cmsim.dynamics.profiles import SpeedProfile, kernel_profile
from cmsim.errors import ParameterError
from cmsim.spectra.order import order_spectrum

RIG = cmsim.Rig.paper_2016()


def test_profile_angle_is_the_exact_integral():
    prof = SpeedProfile((0.0, 1.0, 3.0), (600.0, 1200.0, 1200.0))
    w0, w1 = 600 * math.pi / 30, 1200 * math.pi / 30
    # ramp: ∫ = (w0 + w1)/2 · 1 s; then constant
    assert prof.angle_rad_at(1.0) == pytest.approx(0.5 * (w0 + w1))
    assert prof.angle_rad_at(2.5) == pytest.approx(0.5 * (w0 + w1) + 1.5 * w1)
    assert prof.angle_rad_at(0.5) == pytest.approx(0.5 * w0 + 0.125 * (w1 - w0))
    # beyond the end the last speed holds
    assert prof.speed_rpm_at(10.0) == pytest.approx(1200.0)
    kp = kernel_profile(prof, 10.0, 3.0, 1e-3)
    t = np.arange(kp.table.shape[0]) * kp.dt_s
    np.testing.assert_allclose(kp.table[:, 0], prof.angle_rad_at(t), rtol=1e-12)
    assert kp.table[10, 2] == pytest.approx((w1 - w0) / 1.0, rel=1e-9)     # dΩ/dt on the ramp
    np.testing.assert_allclose(kp.table[:, 3], 10.0)


def test_bad_profiles_are_refused():
    with pytest.raises(ParameterError, match="speeds_rpm"):
        SpeedProfile((0.0, 1.0), (300.0, -5.0))
    with pytest.raises(ParameterError, match="times_s"):
        SpeedProfile((0.5, 1.0), (300.0, 500.0))
    with pytest.raises(ParameterError, match="duration_s"):
        SpeedProfile.ramp(300, 1500, 0.0)


def test_constant_profile_reproduces_the_stationary_run():
    op = cmsim.OperatingPoint(1000.0, 50.0)
    kw = dict(seed=2, mesh="potential-energy")
    a = simulate(RIG, op, 0.1, **kw)
    b = simulate(RIG, op, 0.1, profile=SpeedProfile((0.0,), (1000.0,)), **kw)
    for name in ("dte_um", "F_1b1_loa", "theta_2G1"):
        np.testing.assert_allclose(b[name], a[name], rtol=1e-9,
                                   atol=1e-9 * np.max(np.abs(a[name])))


@pytest.fixture(scope="module")
def runup():
    prof = SpeedProfile.ramp(300.0, 1500.0, 1.0)
    return simulate(RIG, cmsim.OperatingPoint(300.0, 50.0), 1.0, profile=prof, seed=1,
                    warmup_s=0.0, mesh="potential-energy")


def test_runup_follows_the_profile(runup):
    th = runup["theta_1b1"]
    t = runup.t
    prof = SpeedProfile.ramp(300.0, 1500.0, 1.0)
    # total rotation = nominal angle + a small dynamic deviation
    assert np.max(np.abs(th - prof.angle_rad_at(t))) < 1e-3
    speed = np.gradient(th, t) * 30 / math.pi
    assert speed[len(t) // 2] == pytest.approx(900.0, rel=0.01)
    assert runup.meta["speed_profile"]["speeds_rpm"] == [300.0, 1500.0]


def test_runup_order_spectrum_has_sharp_gmf_and_ball_pass_orders(runup):
    th = runup["theta_1b1"]
    tacho = np.where(np.mod(th, 2 * math.pi) < 0.2, 5.0, 0.0)
    bpo = ball_pass_cycles_per_rev(RIG.bearings[0])
    for name in ("F_1b1_loa", "dte_um"):
        sp = order_spectrum(runup[name] - runup[name].mean(), runup.fs_hz, tacho=tacho,
                            window="hann")
        o, a = sp.order, sp.amplitude

        def peak(order, half_bins):
            j = int(np.argmin(np.abs(o - order)))
            lo = max(j - half_bins, 0)
            k = lo + int(np.argmax(a[lo:j + half_bins + 1]))
            return k, a[k], np.median(a[max(k - 40, 0):k + 40])

        k, amp, floor = peak(28.0, 1)
        assert abs(o[k] - 28.0) <= sp.resolution_order / 2     # on the GMF order
        assert amp > 50 * floor                                 # sharp: no smearing in order
        assert a[k - 3] < 0.05 * amp and a[k + 3] < 0.05 * amp    # Hann main lobe: ±2 bins
        k, amp, floor = peak(bpo, 1)
        assert abs(o[k] - bpo) <= sp.resolution_order         # ball pass where the cage puts it
        if name == "F_1b1_loa":
            assert amp > 10 * floor


def test_ramp_loads_the_mesh_with_the_driven_inertia():
    """Constant-acceleration ramps up and down: the mean mesh torque on gear 2 is the load
    plus the driven side's inertia (gear 2, its bearings' nodes, the output inertia 2J2)
    times its angular acceleration, with the sign of the acceleration (closed form: Newton on
    the driven shaft; the output-side torsional springs only pass torque on). A constant-speed
    run cannot see this term, and the order-spectrum test checks only frequencies."""
    torque, ratio = 5.0, RIG.gears.driving.n_teeth / RIG.gears.driven.n_teeth
    prof = SpeedProfile((0.0, 0.05, 0.15, 0.25), (1000.0, 1000.0, 3000.0, 1000.0))
    run = simulate(RIG, cmsim.OperatingPoint(1000.0, torque), 0.25, profile=prof, seed=1,
                   warmup_s=0.0, mesh="potential-energy")
    names = run.meta["dof_names"]
    j_driven = sum(m for name, m in zip(names, RIG.dof_masses) if name.startswith("theta_2"))
    mesh_torque = run["Fmesh_total"] * RIG.gears.driven.base_radius_m
    alpha_in = 2000.0 * math.pi / 30.0 / 0.1                    # rad/s², 2000 rpm in 0.1 s
    for (a, b), sign in (((0.01, 0.05), 0.0), ((0.07, 0.15), 1.0), ((0.17, 0.25), -1.0)):
        window = (run.t >= a) & (run.t < b)        # 20 ms after each kink: transient gone
        expected = torque + sign * j_driven * alpha_in * ratio
        assert mesh_torque[window].mean() == pytest.approx(expected, rel=0.01), (a, b)
    assert j_driven * alpha_in > 0.3 * torque                 # the term is not lost in 1 %
