"""Ball bearings: Annex B stiffness, Fukata forces, cage kinematics.

Tier (a) closed form: an exact Hertz point-contact derivation (complete elliptic integrals),
hand-counted ball loads, and the kinematics of paper 002 Table 1.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from cmsim.bearings import (ball_pass_cycles_per_rev, bearing_contact_stiffness, bearing_force,
                            bearing_tangent_stiffness, cage_ratios, loaded_balls, slip_jitter)
from cmsim.bearings.hertz import raceway_contact
from cmsim.errors import ParameterError
from cmsim.rig import Rig, RollingBearing

STEEL_E_PA = 207.5e9  # the steel behind eq. B.5's constant 2.79e-4 (Harris)
STEEL_NU = 0.3


def exact_hertz_stiffness(curvature_sum, curvature_difference, e_pa=STEEL_E_PA, nu=STEEL_NU):
    """Q = k δ^1.5 of a steel point contact from Hertz theory with elliptic integrals.

    Ellipticity κ solves F(ρ) = [(κ²+1)E − 2K] / [(κ²−1)E] with modulus m = 1 − 1/κ²;
    δ = δ*·(Σρ/2)·[(3Q/2Σρ)·2(1−ν²)/E]^(2/3), δ* = (2K/π)(π/(2κ²E))^(1/3) (Harris 2001).
    """
    def residual(kappa):
        m = 1.0 - 1.0 / kappa ** 2
        big_k, big_e = ellipk(m), ellipe(m)
        return ((kappa ** 2 + 1) * big_e - 2 * big_k) / ((kappa ** 2 - 1) * big_e) \
            - curvature_difference
    kappa = brentq(residual, 1.0 + 1e-9, 100.0)
    m = 1.0 - 1.0 / kappa ** 2
    delta_star = 2 * ellipk(m) / math.pi * (math.pi / (2 * kappa ** 2 * ellipe(m))) ** (1 / 3)
    # δ = c·Q^(2/3)  ->  k = c^(-3/2)
    c = delta_star * curvature_sum / 2 * (3 / (2 * curvature_sum) * 2 * (1 - nu ** 2) / e_pa) ** (2 / 3)
    return c ** -1.5


@pytest.fixture
def b209():
    return Rig.paper_2016().bearings[0]


def test_annex_b_curvatures_of_209(b209):
    d = b209.ball_diameter_m
    inner = raceway_contact(d, b209.inner_raceway_diameter_m / 2, b209.inner_groove_radius_m,
                            inner=True)
    outer = raceway_contact(d, b209.outer_raceway_diameter_m / 2, b209.outer_groove_radius_m,
                            inner=False)
    # NOTES.md: Σρ_i ≈ 0.2017 /mm, F_i ≈ 0.9408, Σρ_o ≈ 0.1377 /mm, F_o ≈ 0.9134
    assert inner.curvature_sum_per_m == pytest.approx(201.7, rel=1e-3)
    assert inner.curvature_difference == pytest.approx(0.9408, abs=2e-4)
    assert outer.curvature_sum_per_m == pytest.approx(137.7, rel=1e-3)
    assert outer.curvature_difference == pytest.approx(0.9134, abs=2e-4)


def test_annex_b_stiffness_against_exact_hertz(b209):
    """k_RE from Table 7 + eq. B.6/B.7 agrees with elliptic-integral Hertz theory to 1.5 %."""
    d = b209.ball_diameter_m
    contacts = [raceway_contact(d, b209.inner_raceway_diameter_m / 2, b209.inner_groove_radius_m,
                                inner=True),
                raceway_contact(d, b209.outer_raceway_diameter_m / 2, b209.outer_groove_radius_m,
                                inner=False)]
    exact = [exact_hertz_stiffness(c.curvature_sum_per_m, c.curvature_difference)
             for c in contacts]
    k_exact = exact[0] * exact[1] / (exact[0] ** (2 / 3) + exact[1] ** (2 / 3)) ** 1.5
    k_annex = bearing_contact_stiffness(b209)
    assert k_annex == pytest.approx(1.18e10, rel=0.01)
    assert k_annex == pytest.approx(k_exact, rel=0.015)
    for c, k in zip(contacts, exact):
        assert c.stiffness_n_per_m15 == pytest.approx(k, rel=0.015)


def test_stiffness_override_and_roller_exponent(b209):
    from dataclasses import replace
    assert bearing_contact_stiffness(replace(b209, stiffness_n_per_m_p=2e9)) == 2e9
    with pytest.raises(ParameterError, match="stiffness_n_per_m_p"):
        bearing_contact_stiffness(replace(b209, load_exponent=1.1))


def test_hertz_law_single_ball(b209):
    """Offset along ball 1 with clearance so large only that ball touches: F = k (δ − c)^1.5.

    The neighbours at ±40° stay free while (c + overlap)·cos 40° < c, i.e. overlap < 0.305 c.
    """
    from dataclasses import replace
    brg = replace(b209, clearance_m=100e-6)
    k = bearing_contact_stiffness(brg)
    c = brg.clearance_m
    for overlap in (1e-6, 5e-6, 2e-5):
        x = c + overlap
        fx, fy = bearing_force(brg, x, 0.0, 0.0)
        assert loaded_balls(brg, x, 0.0, 0.0) == 1
        assert fx == pytest.approx(k * overlap ** 1.5, rel=1e-12)
        assert fy == pytest.approx(0.0, abs=1e-9 * fx)


@pytest.mark.parametrize("clearance_ratio, n_loaded", [(0.0, 5), (0.5, 3), (0.9, 1)])
def test_loaded_balls_and_force_by_hand(b209, clearance_ratio, n_loaded):
    """Balls at 0°, ±40°, ±80° … ; offset δ0 along ball 1: ball i loaded iff cos θ_i > c/δ0."""
    from dataclasses import replace
    delta0 = 20e-6
    brg = replace(b209, clearance_m=clearance_ratio * delta0)
    k = bearing_contact_stiffness(brg)
    angles = np.radians(40.0 * np.arange(9))
    overlaps = delta0 * np.cos(angles) - brg.clearance_m
    by_hand = k * np.sum(np.where(overlaps > 0, np.clip(overlaps, 0, None) ** 1.5 * np.cos(angles), 0))
    fx, fy = bearing_force(brg, delta0, 0.0, 0.0)
    assert loaded_balls(brg, delta0, 0.0, 0.0) == n_loaded
    assert fx == pytest.approx(by_hand, rel=1e-12)
    assert fy == pytest.approx(0.0, abs=1e-9 * fx)


def test_preload_loads_all_balls_at_rest(b209):
    from dataclasses import replace
    brg = replace(b209, clearance_m=-1e-6)
    assert loaded_balls(brg, 0.0, 0.0, 0.3) == 9
    fx, fy = bearing_force(brg, 0.0, 0.0, 0.3)
    assert math.hypot(fx, fy) < 1e-6  # symmetric: no net force
    kmat = bearing_tangent_stiffness(brg, 0.0, 0.0, 0.3)
    assert kmat[0, 0] > 0 and kmat[1, 1] > 0


def test_tangent_stiffness_is_the_force_derivative(b209):
    x, y, cage = 25e-6, -8e-6, 0.37
    kmat = bearing_tangent_stiffness(b209, x, y, cage)
    h = 1e-10
    for j, (dx, dy) in enumerate(((h, 0.0), (0.0, h))):
        fp = np.array(bearing_force(b209, x + dx, y + dy, cage))
        fm = np.array(bearing_force(b209, x - dx, y - dy, cage))
        np.testing.assert_allclose((fp - fm) / (2 * h), kmat[:, j], rtol=1e-5)


def test_ball_pass_cycles_per_gear_turn(b209):
    """Paper §6.2.1: 3.6342 bearing cycles per gear turn (free contact angle ≈ 9.94°)."""
    assert math.degrees(b209.free_contact_angle_rad) == pytest.approx(9.94, abs=0.01)
    assert ball_pass_cycles_per_rev(b209) == pytest.approx(3.6342, abs=5e-4)


def test_contact_angle_follows_the_operating_clearance(b209):
    """The kinematic contact angle is acos(1 − c/2A) of the operating clearance c (the paper's
    c = P_d gives its 9.94° and 3.6342 cycles); under preload the balls sit at the groove
    bottoms (α = 0: 9/2·(1 − d/D) = 3.6207 cycles), and the model's cage turns at that rate."""
    from dataclasses import replace

    from cmsim.dynamics.rig_model import rig_model
    from cmsim.dynamics._bearing_kernels import BP_CAGE
    assert b209.operating_contact_angle_rad == pytest.approx(b209.free_contact_angle_rad,
                                                             rel=1e-9)
    preloaded = replace(b209, clearance_m=-1e-6)
    assert preloaded.effective_contact_angle_rad == 0.0
    half_gamma = 0.5 * b209.ball_diameter_m / b209.pitch_diameter_m
    assert ball_pass_cycles_per_rev(preloaded) == pytest.approx(
        b209.n_balls * (0.5 - half_gamma), rel=1e-12)
    assert ball_pass_cycles_per_rev(preloaded) == pytest.approx(3.6207, abs=5e-4)
    # a mounted clearance below the raceways' P_d gives a smaller angle, cos α = 1 − c/(2A)
    # with A = r_i + r_o − d; a larger one cannot exceed the free angle
    tighter = replace(b209, clearance_m=0.0075e-3)
    a = b209.inner_groove_radius_m + b209.outer_groove_radius_m - b209.ball_diameter_m
    assert math.cos(tighter.effective_contact_angle_rad) == pytest.approx(
        1 - 0.0075e-3 / (2 * a), rel=1e-12)
    assert 0 < tighter.effective_contact_angle_rad < b209.free_contact_angle_rad
    loose = replace(b209, clearance_m=0.03e-3)
    assert loose.effective_contact_angle_rad == pytest.approx(b209.free_contact_angle_rad)
    # an explicit angle wins
    assert replace(preloaded, contact_angle_rad=0.2).effective_contact_angle_rad == 0.2
    rig = Rig.paper_2016()
    for r, brg in ((rig, b209), (rig.with_clearance(-1e-6), preloaded)):
        k_in, _ = cage_ratios(brg)
        assert rig_model(r).bearing_params[0, BP_CAGE] == pytest.approx(k_in, rel=1e-12)


@pytest.mark.parametrize("ratio", [0.5, -0.5, 1.0])
def test_cage_speed_with_both_rings_rotating(b209, ratio):
    """Paper 002 Table 1: n_c = n_i K1 + n_o K2 (same sense) and n_i K1 − |n_o| K2 (counter),
    K1 = (1 − d/D cos α)/2, K2 = (1 + d/D cos α)/2."""
    from dataclasses import replace
    from cmsim.bearings.kinematics import ball_angles, cage_angle
    from cmsim.dynamics._bearing_kernels import BP_CAGE
    from cmsim.dynamics.rig_model import rig_model
    brg = replace(b209, outer_ring_speed_ratio=ratio)
    d, pd = brg.ball_diameter_m, brg.pitch_diameter_m
    cos_a = math.cos(brg.effective_contact_angle_rad)
    gamma = d / pd * cos_a
    k1, k2 = (1 - gamma) / 2, (1 + gamma) / 2
    assert cage_ratios(brg) == pytest.approx((k1, k2), rel=1e-12)
    # rolling without slip, from the contact radii: the ball centre moves at the mean of the
    # two raceway contact speeds, the cage carries it at radius D/2
    w_i = 2 * math.pi * 1000.0 / 60.0
    w_o = ratio * w_i
    r_in, r_out = (pd - d * cos_a) / 2, (pd + d * cos_a) / 2
    w_c = 0.5 * (w_i * r_in + w_o * r_out) / (pd / 2)
    t = np.linspace(0.0, 0.1, 7)
    np.testing.assert_allclose(cage_angle(brg, w_i * t, w_o * t), w_c * t, rtol=1e-12,
                               atol=1e-15)
    balls = ball_angles(brg, w_i * t, w_o * t)
    assert balls.shape == (t.size, brg.n_balls)
    np.testing.assert_allclose(balls[:, 3] - balls[:, 0], 3 * 2 * math.pi / brg.n_balls)
    np.testing.assert_allclose(balls[:, 0], w_c * t, rtol=1e-12, atol=1e-15)
    assert ball_pass_cycles_per_rev(brg) == pytest.approx(brg.n_balls * abs(w_c / w_i),
                                                          rel=1e-12)
    # the dynamics turns its cages at the same rate (bearing 1b1 of a rig with this bearing)
    rig = Rig.paper_2016()
    s1 = replace(rig.shafts[0], bearing_1=brg)
    model = rig_model(replace(rig, shafts=(s1, rig.shafts[1])))
    assert model.bearing_params[0, BP_CAGE] == pytest.approx(w_c / w_i, rel=1e-12)
    if ratio == 1.0:  # rings turning together: the cage turns with them
        assert cage_angle(brg, 2.0, 2.0) == pytest.approx(2.0, rel=1e-12)
    if ratio < 0:     # counter-rotating outer ring slows the cage below K_in
        assert abs(w_c) < k1 * w_i


def test_slip_jitter_statistics():
    rng = np.random.default_rng(7)
    dt, tau, rms = 1e-4, 5e-3, 0.01
    j = slip_jitter(3, 200_000, dt, rms, tau, rng)
    assert j.shape == (3, 200_000)
    assert np.std(j) == pytest.approx(rms, rel=0.05)
    lag = int(tau / dt)
    r = np.mean(j[:, :-lag] * j[:, lag:]) / np.var(j)
    assert r == pytest.approx(math.exp(-1), abs=0.05)
    again = slip_jitter(3, 200_000, dt, rms, tau, np.random.default_rng(7))
    np.testing.assert_array_equal(again, j)


@pytest.mark.parametrize("field, value, match", [
    ("n_balls", 2, "n_balls"),
    ("clearance_m", 0.02, "clearance_m"),
    ("inner_groove_radius_m", 6.0e-3, "inner_groove_radius_m"),
    ("ball_diameter_m", float("nan"), "ball_diameter_m"),
])
def test_bad_bearing_input(b209, field, value, match):
    from dataclasses import asdict
    kwargs = asdict(b209)
    kwargs[field] = value
    with pytest.raises(ParameterError, match=match):
        RollingBearing(**kwargs)
