"""Rigid-body tooth contact geometry and the pair stiffness table.

Tier (a) closed form: conjugate involutes (interference linear in rotation, the backlash
relation for a centre-distance change), continuity at the tip roundings, and moment arms.
"""

import math

import numpy as np
import pytest

from cmsim.mesh_stiffness.contact import (active_path_m, contact_geometry, corner_zone_m,
                                          pair_contacts, potential_slots, table_range_m,
                                          tip_rounding)
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.errors import ParameterError
from cmsim.rig import GearPair, Rig, SpurGear


@pytest.fixture
def pair():
    return Rig.paper_2016().gears


def involute(a):
    return math.tan(a) - a


def _in_path(c, pair):
    s0, s1 = active_path_m(pair)
    return (c["position_m"] > s0) & (c["position_m"] < s1)


def test_nominal_mesh_is_tight_and_linear_in_rotation(pair):
    """Conjugate involutes: δ = rb1·Δθ1 − rb2·Δθ2 for every pair on the involute path."""
    rb1, rb2 = pair.driving.base_radius_m, pair.driven.base_radius_m
    for th1, th2 in ((0.0, 0.0), (1e-4, 0.0), (0.0, 2e-4), (3e-4, -1e-4)):
        c = pair_contacts(pair, 0.05 + th1, 0.05 + th2)
        on = _in_path(c, pair)
        assert on.sum() >= 1
        np.testing.assert_allclose(c["delta_m"][on], rb1 * th1 - rb2 * th2, atol=1e-12)


def test_centre_distance_change_follows_backlash_relation(pair):
    """Moving gear 2 by Δa along the line of centres: Δδ = −(rb1 + rb2)(inv α' − inv α)."""
    rb = pair.driving.base_radius_m + pair.driven.base_radius_m
    a0 = pair.working_centre_distance_m
    for da in (-20e-6, 30e-6, 100e-6):
        alpha0 = math.acos(rb / a0)
        alpha1 = math.acos(rb / (a0 + da))
        expected = -rb * (involute(alpha1) - involute(alpha0))
        c = pair_contacts(pair, 0.1, 0.1, centre2_m=(0.0, da))
        on = _in_path(c, pair)
        np.testing.assert_allclose(c["delta_m"][on], expected, rtol=1e-9, atol=1e-14)


def test_translation_along_line_of_action(pair):
    """Gear 2 moved by d along the force direction n (away from gear 1): δ drops by d."""
    alpha = pair.working_pressure_angle_rad
    n = np.array([-math.cos(alpha), math.sin(alpha)])
    for d in (1e-6, 10e-6):
        c = pair_contacts(pair, 0.2, 0.2, centre2_m=tuple(d * n))
        on = _in_path(c, pair)
        np.testing.assert_allclose(c["delta_m"][on], -d, rtol=1e-6)


def test_interference_continuous_across_tip_roundings(pair):
    """The rounding arc is tangent to the involute: overlap and normal are continuous."""
    rb1 = pair.driving.base_radius_m
    s0, s1 = active_path_m(pair)
    alpha = pair.working_pressure_angle_rad
    for edge in (s0, s1):
        vals = []
        for side in (-1, 1):
            s = edge + side * 1e-9
            theta = (s - rb1 * math.tan(alpha)) / rb1 + 1e-5  # 1e-5 rad of wind-up
            c = pair_contacts(pair, theta, theta - 1e-5, n_slots=1,
                              slot_start_m=s - 0.5 * pair.driving.base_pitch_m)
            vals.append((c["delta_m"][0], c["normal"][0]))
        assert vals[0][0] == pytest.approx(vals[1][0], abs=1e-10)
        np.testing.assert_allclose(vals[0][1], vals[1][1], atol=1e-6)
        assert vals[0][0] == pytest.approx(rb1 * 1e-5, rel=1e-3)


def test_corner_contact_normal_is_tangent_to_base_circle(pair):
    """Outside the path the normal is the driving flank's normal (gear-2 tip) or the driven
    flank's normal (gear-1 tip); either is tangent to that gear's base circle."""
    s0, s1 = active_path_m(pair)
    rb1, rb2 = pair.driving.base_radius_m, pair.driven.base_radius_m
    a0 = pair.working_centre_distance_m
    alpha = pair.working_pressure_angle_rad
    for s, centre, rb in ((s0 - 0.5e-3, np.zeros(2), rb1), (s1 + 0.5e-3, np.array([0, a0]), rb2)):
        theta = (s - rb1 * math.tan(alpha)) / rb1
        c = pair_contacts(pair, theta + 5e-4, theta, n_slots=1,
                          slot_start_m=s - 0.5 * pair.driving.base_pitch_m)
        p, nrm = c["point_m"][0], c["normal"][0]
        arm = abs((p - centre)[0] * nrm[1] - (p - centre)[1] * nrm[0])
        assert arm == pytest.approx(rb, rel=1e-9)
        assert np.linalg.norm(nrm) == pytest.approx(1.0)


def test_tip_rounding_closed_form(pair):
    g = pair.driving
    t = tip_rounding(g)
    rho = g.tip_rounding_m
    assert t.centre_radius_m + rho == pytest.approx(g.tip_radius_m)
    # rounding start radius lies between base and tip circles and below the tip
    r_start = math.hypot(g.base_radius_m, t.start_roll_m)
    assert g.base_radius_m < r_start < g.tip_radius_m
    geo = contact_geometry(pair)
    assert geo.shape == (14,)


def test_contact_ratio_and_zone(pair):
    s0, s1 = active_path_m(pair)
    pb = pair.driving.base_pitch_m
    assert (s1 - s0) / pb == pytest.approx(1.60, abs=0.01)  # NOTES: ≈1.60 with tip rounding
    before, after = corner_zone_m(pair)
    assert 0 < before < pb and 0 < after < pb
    lo, hi = table_range_m(pair)
    assert potential_slots(pair) == math.ceil((hi - lo) / pb)


def test_constant_table_mesh_stiffness(pair):
    table = MeshStiffnessTable.constant(pair, 1e8)
    s, k, count = table.mesh_stiffness(pair)
    assert set(np.unique(count)) == {1, 2}
    assert np.mean(count) == pytest.approx(1.60, abs=0.02)
    np.testing.assert_allclose(k, 1e8 * count)


def test_table_round_trip_and_validation(pair, tmp_path):
    table = MeshStiffnessTable.potential_energy(pair)
    path = tmp_path / "t.npz"
    table.save(path)
    back = MeshStiffnessTable.load(path)
    np.testing.assert_array_equal(back.stiffness_n_per_m, table.stiffness_n_per_m)
    assert back.method == "potential-energy"
    with pytest.raises(ParameterError, match="uniform"):
        MeshStiffnessTable(np.array([0.0, 1.0, 3.0]), np.ones(3), np.zeros(3), 0.04, "constant")
    with pytest.raises(ParameterError, match="method"):
        MeshStiffnessTable(np.arange(3.0), np.ones(3), np.zeros(3), 0.04, "magic")


def test_gear_pair_validation():
    g = Rig.paper_2016().gears.driving
    with pytest.raises(ParameterError, match="n_teeth"):
        SpurGear(n_teeth=-3, module_m=3e-3, face_width_m=5e-3)
    with pytest.raises(ParameterError, match="centre_distance_m"):
        GearPair(g, g, centre_distance_m=0.05)
    with pytest.raises(ParameterError, match="contact ratio"):
        GearPair(g, g, centre_distance_m=g.tip_radius_m * 2 - 1e-4)
