"""Single-pair mesh stiffness by the potential-energy method (mesh_stiffness.potential_energy).

Tiers:

* (a) closed form — the beam integrals of a uniform rectangular cantilever, the Hertz term
  π E b / (4(1 − ν²)), ISO 6336-1 method B evaluated by hand for the paper's pair;
* (b) literature, "order of" — the paper pair's single-pair stiffness against ISO 6336 c′·b
  and its mean mesh stiffness against ISO c_γ·b (≈ 1.18e8 N/m, papers/NOTES.md). ISO 6336 is
  an empirical fit, so the tolerances are wide (factors, not per cent).

All tests run in well under a second.
"""

import math
import warnings

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.mesh_stiffness.geometry import ToothProfile
from cmsim.mesh_stiffness.potential_energy import (active_contact_limits_m, cantilever_compliance,
                                                   hertz_stiffness, iso6336_stiffness,
                                                   mesh_stiffness_potential_energy,
                                                   pair_compliance_potential_energy,
                                                   pair_stiffness_potential_energy,
                                                   sainsot_coefficients, tooth_compliance)
from cmsim.rig import GearPair, Rig, SpurGear

E, NU, B = 210e9, 0.3, 6.35e-3


@pytest.fixture(scope="module")
def pair():
    return Rig.paper_2016().gears


@pytest.fixture(scope="module")
def curve(pair):
    s0, s1 = active_contact_limits_m(pair)
    s = np.linspace(s0, s1, 301)
    return s, pair_compliance_potential_energy(pair, s)


@pytest.mark.parametrize("alpha1", [0.0, 0.3, -0.2])
def test_uniform_cantilever_matches_closed_form(alpha1):
    h, e = 2.0e-3, 1.5e-3
    d = np.array([1e-3, 3e-3, 5e-3])
    kb, ks, ka = cantilever_compliance(lambda u: np.full_like(u, h), d, e, alpha1, E, NU, B)
    inertia, area, shear_mod = 2.0 / 3.0 * h ** 3 * B, 2.0 * h * B, E / (2 * (1 + NU))
    c, s = math.cos(alpha1), math.sin(alpha1)
    # ∫₀ᵈ (c (d − u) − e s)² du = c² d³/3 − c s e d² + s² e² d
    bending = (c * c * d ** 3 / 3 - c * s * e * d ** 2 + s * s * e * e * d) / (E * inertia)
    assert np.allclose(kb, bending, rtol=1e-10, atol=0.0)
    assert np.allclose(ks, 1.2 * c * c * d / (shear_mod * area), rtol=1e-12, atol=0.0)
    assert np.allclose(ka, s * s * d / (E * area), rtol=1e-12, atol=1e-30)
    if alpha1 == 0.0:                                   # the textbook cantilever d³/(3EI)
        assert np.allclose(kb, d ** 3 / (3 * E * inertia), rtol=1e-6)


@pytest.mark.parametrize("n_nodes", [3, 11, 1001])
def test_simpson_rule_is_exact_on_a_cubic_bending_integrand(n_nodes):
    # h(u) = (a + b u)^(-1/3): 1/I is linear in u, so the bending integrand is a cubic,
    # which the composite Simpson rule integrates exactly on any odd number of nodes
    a, b, alpha1, e = 1.0 / 2e-3 ** 3, 4.0e10 / 1e-3, 0.25, 1.2e-3
    d = np.array([1e-3, 4e-3])
    kb = cantilever_compliance(lambda u: (a + b * u) ** (-1.0 / 3.0), d, e, alpha1, E, NU, B,
                               n_nodes=n_nodes)[0]
    c, s = math.cos(alpha1), math.sin(alpha1)
    p = c * d - e * s                        # the moment arm is p − c u
    m0 = p * p * d - p * c * d ** 2 + c * c * d ** 3 / 3          # ∫₀ᵈ (p − c u)² du
    m1 = p * p * d ** 2 / 2 - 2 * p * c * d ** 3 / 3 + c * c * d ** 4 / 4   # ∫₀ᵈ u (…)² du
    assert np.allclose(kb, 1.5 / (E * B) * (a * m0 + b * m1), rtol=1e-12, atol=0.0)


def test_tapered_cantilever_converges():
    # h(u) = h0 (1 − u/(2L)): a coarse and a fine Simpson rule agree
    L = 5e-3
    fine = cantilever_compliance(lambda u: 2e-3 * (1 - u / (2 * L)), [L], 1e-3, 0.3, E, NU, B,
                                 n_nodes=20001)[0][0]
    coarse = cantilever_compliance(lambda u: 2e-3 * (1 - u / (2 * L)), [L], 1e-3, 0.3, E, NU,
                                   B, n_nodes=201)[0][0]
    assert coarse == pytest.approx(fine, rel=1e-6)
    # thinner towards the load → more compliant than the uniform beam of the root thickness
    uniform = cantilever_compliance(lambda u: np.full_like(u, 2e-3), [L], 1e-3, 0.3, E, NU,
                                    B)[0][0]
    assert fine > 1.5 * uniform


def test_hertz_term(pair, curve):
    expected = math.pi * E * B / (4 * (1 - NU ** 2))
    assert hertz_stiffness(pair) == pytest.approx(expected, rel=1e-12)
    assert 1.0 / curve[1].hertz == pytest.approx(expected, rel=1e-12)


def test_single_pair_curve_shape(pair, curve):
    s, comp = curve
    k = comp.stiffness
    assert np.all(np.isfinite(k)) and np.all(k > 0.0)
    # smooth: second differences tiny compared with k (no kinks, no noise)
    assert np.max(np.abs(np.diff(k, 2))) < 1e-3 * k.max()
    # identical gears: symmetric about mid-path, maximum at mid-path
    assert np.allclose(k, k[::-1], rtol=1e-9)
    s_max = s[np.argmax(k)]
    assert abs(s_max - 0.5 * (s[0] + s[-1])) < 0.05 * (s[-1] - s[0])
    assert k.min() < 0.8 * k.max()                     # noticeably softer at the tips
    # the driving tooth gets more compliant as the contact climbs to its tip
    assert np.all(np.diff(comp.driving.bending) > 0.0)
    assert np.all(np.diff(comp.driven.bending) < 0.0)
    assert np.allclose(comp.total, comp.as_dict()["total"])
    assert np.allclose(pair_stiffness_potential_energy(pair, s[::50]), k[::50], rtol=1e-12)


def test_single_pair_maximum_of_order_iso(pair, curve):
    iso = iso6336_stiffness(pair)
    ratio = curve[1].stiffness.max() / iso["c_prime_n_per_m"]
    assert 0.6 < ratio < 1.8


def test_mean_mesh_stiffness_of_order_iso(pair):
    s0, _ = active_contact_limits_m(pair)
    pb = pair.driving.base_pitch_m
    s = np.linspace(s0, s0 + pb, 400, endpoint=False)
    k = mesh_stiffness_potential_energy(pair, s)
    iso = iso6336_stiffness(pair)
    ratio = k.mean() / iso["c_gamma_n_per_m"]
    assert 0.7 < ratio < 1.5
    # two pairs in contact are stiffer than any single pair
    single = pair_stiffness_potential_energy(pair, s[:1])[0]
    assert k.max() > 1.4 * k.min()
    assert k[0] > single
    assert np.allclose(mesh_stiffness_potential_energy(pair, s + 3 * pb), k, rtol=1e-12)


def test_iso6336_by_hand(pair):
    iso = iso6336_stiffness(pair)
    q = 0.04723 + 0.15551 / 28 + 0.25791 / 28
    c_prime = 0.8 * 1.0 * (1 + 0.5 * (1.2 - 1.25)) / q
    assert iso["c_prime_n_per_mm_um"] == pytest.approx(c_prime, rel=1e-12)
    assert iso["c_prime_n_per_m"] == pytest.approx(c_prime * 6.35 * 1e6, rel=1e-12)
    assert iso["c_gamma_n_per_m"] == pytest.approx(1.18e8, rel=0.01)     # NOTES.md


def test_components_at_pitch_point(pair):
    length = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)
    c = pair_compliance_potential_energy(pair, [0.5 * length])
    for comp in ("bending", "shear", "axial", "foundation"):
        a, b = getattr(c.driving, comp)[0], getattr(c.driven, comp)[0]
        assert a > 0.0 and a == pytest.approx(b, rel=1e-12)
    # axial compression is the smallest of the four (a correction of a few per cent)
    tooth = c.driving
    assert tooth.axial[0] < min(tooth.bending[0], tooth.shear[0], tooth.foundation[0])
    assert tooth.axial[0] < 0.05 * c.total[0]


def test_shifted_unequal_pair_runs_and_is_not_symmetric():
    g1 = SpurGear(n_teeth=18, module_m=3.175e-3, face_width_m=6.35e-3, profile_shift=0.3,
                  bore_radius_m=0.012)
    g2 = SpurGear(n_teeth=40, module_m=3.175e-3, face_width_m=6.35e-3, profile_shift=-0.1,
                  bore_radius_m=0.03)
    pair = GearPair(g1, g2)
    s0, s1 = active_contact_limits_m(pair)
    k = pair_stiffness_potential_energy(pair, np.linspace(s0, s1, 51))
    assert np.all(k > 0.0)
    assert not np.allclose(k, k[::-1], rtol=1e-3)


def test_bad_input(pair):
    s0, s1 = active_contact_limits_m(pair)
    with pytest.raises(ParameterError, match="GearPair"):
        pair_stiffness_potential_energy("pair", [s0])
    with pytest.raises(ParameterError, match="contact_position_m"):
        pair_stiffness_potential_energy(pair, [s0, np.nan])
    with pytest.raises(ParameterError, match="contact_position_m must lie"):
        pair_stiffness_potential_energy(pair, [0.0])           # at T1, below the form circle
    with pytest.raises(ParameterError, match="length_m"):
        cantilever_compliance(lambda u: u * 0 + 1e-3, [-1e-3], 0.0, 0.0, E, NU, B)
    with pytest.raises(ParameterError, match="half_thickness_m"):
        cantilever_compliance(lambda u: u * 0 - 1e-3, [1e-3], 0.0, 0.0, E, NU, B)
    with pytest.raises(ParameterError, match="youngs_modulus_pa"):
        cantilever_compliance(lambda u: u * 0 + 1e-3, [1e-3], 0.0, 0.0, -1.0, NU, B)
    t = ToothProfile.from_gear(pair.driving)
    with pytest.raises(ParameterError, match="involute"):
        tooth_compliance(t, [t.base_radius_m])


def test_sainsot_extrapolation_warns(pair):
    t = ToothProfile.from_gear(pair.driving)
    with pytest.warns(UserWarning, match="extrapolated"):
        sainsot_coefficients(0.3, 2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                         # the paper gear is in range
        coef = sainsot_coefficients(t.root_half_angle_rad, t.root_radius_m / 0.02)
    assert coef["L"] == pytest.approx(6.888, abs=2e-3)
