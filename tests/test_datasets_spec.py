"""Sweep specs as lists of named variations (issue 9): cases, names, seeds, rigs, errors.

Test tier: behaviour contracts (no physics, no simulation): a variation names an
operating-point field, a named rig transformation or a dotted rig field; the cases are the
Cartesian product of the variations (first slowest) times the repeats; each case has a name
from its values, a stable id, its own seed, its rig and its operating point; unknown names are
refused with the allowed ones listed. Runs in about a second.
"""

import json

import pytest

from cmsim.datasets import RIG_TRANSFORMS, SweepSpec, Variation
from cmsim.datasets.variation import RigTransform
from cmsim.errors import ParameterError
from cmsim.rig import OperatingPoint, Rig

BASE = Rig.paper_2016()
AT_1000 = {"speed_rpm": 1000.0, "torque_nm": 10.0}


def test_rig_field_variation_clearance():
    spec = SweepSpec([Variation("clearance_m", [15e-6, -1e-6])], fixed=AT_1000)
    cases = spec.cases()
    assert [c.name for c in cases] == ["000_c15um", "001_c-1um"]
    for case, c in zip(cases, (15e-6, -1e-6)):
        rig = spec.case_rig(case)
        assert [b.clearance_m for b in rig.bearings] == pytest.approx([c] * 4, rel=1e-12)
        assert rig == BASE.with_clearance(c)
        assert spec.case_operating_point(case) == OperatingPoint(1000.0, 10.0)
        assert case.params == {"clearance_m": pytest.approx(c, rel=1e-12)}


def test_operating_point_variation_torque():
    spec = SweepSpec([("torque_nm", [10, 40.0])], fixed={"speed_rpm": 1500})
    cases = spec.cases()
    assert [c.name for c in cases] == ["000_T10Nm", "001_T40Nm"]
    ops = [spec.case_operating_point(c) for c in cases]
    assert [op.torque_nm for op in ops] == pytest.approx([10.0, 40.0], rel=1e-12)
    assert {op.speed_rpm for op in ops} == {1500.0}
    assert all(spec.case_rig(c) == BASE for c in cases)      # the rig is untouched


def test_dotted_rig_field_changes_only_that_component():
    spec = SweepSpec([Variation("shafts.0.bearing_1.clearance_m", [5e-6]),
                      Variation("lubricant.dynamic_viscosity_pa_s", [0.04])], fixed=AT_1000)
    (case,) = spec.cases()
    assert case.name == ("000_shafts-0-bearing_1-clearance_m5e-06"
                         "_lubricant-dynamic_viscosity_pa_s0.04")
    rig = spec.case_rig(case)
    assert rig.shafts[0].bearing_1.clearance_m == pytest.approx(5e-6, rel=1e-12)
    others = [rig.shafts[0].bearing_2, *rig.shafts[1].bearings]
    assert [b.clearance_m for b in others] == [b.clearance_m for b in BASE.bearings[1:]]
    assert rig.lubricant.dynamic_viscosity_pa_s == pytest.approx(0.04, rel=1e-12)
    ints = SweepSpec([Variation("shafts.1.bearing_2.n_balls", [8, 10])], fixed=AT_1000)
    assert [ints.case_rig(c).shafts[1].bearing_2.n_balls for c in ints.cases()] == [8, 10]


def test_product_of_three_variations():
    spec = SweepSpec([Variation("speed_rpm", [1000, 1500]),
                      Variation("torque_nm", [10, 50, 100]),
                      Variation("friction", [0.0, 0.03])], seed=5)
    cases = spec.cases()
    assert len(cases) == len(spec) == 2 * 3 * 2
    assert [c.index for c in cases] == list(range(12))
    assert len({c.name for c in cases}) == 12 and len({c.seed for c in cases}) == 12
    assert len({c.id for c in cases}) == 12
    # first variation slowest, last fastest
    assert [c.params["speed_rpm"] for c in cases[:6]] == [1000.0] * 6
    assert [c.params["friction"] for c in cases[:4]] == [0.0, 0.03, 0.0, 0.03]
    assert cases[-1].name == "011_n1500rpm_T100Nm_f0.03"
    last = spec.case_rig(cases[-1])
    assert last.mesh_contact.friction_coefficient == pytest.approx(0.03, rel=1e-12)
    # the same grid through the older keywords: same names and seeds
    old = SweepSpec(speeds_rpm=[1000, 1500], torques_nm=[10, 50, 100], frictions=[0.0, 0.03],
                    seed=5)
    assert old == spec
    assert [(c.name, c.seed) for c in old.cases()] == [(c.name, c.seed) for c in cases]


def test_a_new_axis_needs_no_new_loop(monkeypatch):
    """A fourth axis (a dotted rig field) and a newly registered transformation both multiply
    the cases through the same public call."""
    three = [("speed_rpm", [1000]), ("torque_nm", [10, 50]), ("clearance_m", [15e-6, 0.0])]
    four = three + [("mesh_contact.damping_ratio", [0.05, 0.1, 0.2])]
    assert len(SweepSpec(three).cases()) == 4
    spec4 = SweepSpec(four)
    assert len(spec4.cases()) == 12
    assert sorted({spec4.case_rig(c).mesh_contact.damping_ratio for c in spec4.cases()}) \
        == pytest.approx([0.05, 0.1, 0.2], rel=1e-12)

    def thicker_oil(rig, factor):
        return Rig.from_dict({**rig.to_dict(), "lubricant": {
            "dynamic_viscosity_pa_s": rig.lubricant.dynamic_viscosity_pa_s * factor}})

    monkeypatch.setitem(RIG_TRANSFORMS, "oil_factor",
                        RigTransform(apply=thicker_oil, token=lambda v: f"oil{v:g}x"))
    spec5 = SweepSpec(four + [("oil_factor", [1.0, 10.0])])
    cases = spec5.cases()
    assert len(cases) == 24 and cases[1].name.endswith("_oil10x")
    assert spec5.case_rig(cases[1]).lubricant.dynamic_viscosity_pa_s == pytest.approx(
        10 * BASE.lubricant.dynamic_viscosity_pa_s, rel=1e-12)


def test_repeats_seeds_and_stable_ids():
    spec = SweepSpec([("torque_nm", [10, 20])], fixed={"speed_rpm": 1000}, repeats=3, seed=2)
    cases = spec.cases()
    assert [c.name for c in cases][:3] == ["000_T10Nm_r0", "001_T10Nm_r1", "002_T10Nm_r2"]
    assert len({c.seed for c in cases}) == 6
    assert spec.case_rig(cases[0]) == spec.case_rig(cases[1])
    # seeds come from (base seed, index) alone
    assert [c.seed for c in cases] == [spec.run_seed(i) for i in range(6)]
    # an id depends on the values, not on the position in the grid
    wider = SweepSpec([("torque_nm", [5, 10, 20])], fixed={"speed_rpm": 1000}, repeats=3)
    assert cases[0].id == wider.cases()[3].id and cases[0].index != wider.cases()[3].index
    shared = SweepSpec([("torque_nm", [10, 20])], fixed={"speed_rpm": 1000}, seed=4,
                       seed_policy="shared")
    assert [c.seed for c in shared.cases()] == [4, 4]


def test_round_trip_through_json_both_forms():
    new = SweepSpec([("clearance_m", [15e-6, -1e-6]), ("shafts.0.bearing_1.n_balls", [9, 10])],
                    fixed={"speed_rpm": 1000.0, "radial_load_n": 20.0}, repeats=2,
                    mesh="potential-energy", duration_s=0.2, seed=1)
    data = json.loads(json.dumps(new.to_dict()))
    assert data["variations"][1] == {"name": "shafts.0.bearing_1.n_balls", "values": [9, 10]}
    assert data["mesh"] == "potential-energy"
    assert SweepSpec.from_dict(data) == new
    old = SweepSpec(speeds_rpm=[1000], torques_nm=[10, 20], clearances_m=[1.5e-5, -1e-6],
                    radial_load_n=3.0)
    data = json.loads(json.dumps(old.to_dict()))
    assert data["torques_nm"] == [10.0, 20.0] and data["frictions"] == [None]
    assert data["radial_load_n"] == 3.0 and "variations" not in data
    assert SweepSpec.from_dict(data) == old
    with pytest.raises(ParameterError, match="unknown sweep spec keys.*'speed'"):
        SweepSpec.from_dict({"variations": [], "speed": 3})


@pytest.mark.parametrize("variations, words", [
    ([("speed", [1000])], ["'speed'", "speed_rpm", "clearance_m", "friction", "lubricant"]),
    ([("lubricant.viscosity", [1.0])], ["'lubricant.viscosity'", "dynamic_viscosity_pa_s"]),
    ([("shafts.2.bearing_1.clearance_m", [1e-6])], ["shafts", "0..1"]),
    ([("gears", [1.0])], ["'gears'", "component"]),
    ([("gears.driving.n_teeth.x", [1.0])], ["n_teeth", "not a component"]),
])
def test_unknown_variation_is_refused_with_the_allowed_names(variations, words):
    with pytest.raises(ParameterError) as err:
        SweepSpec(variations, fixed=AT_1000)
    for word in words:
        assert word in str(err.value)


@pytest.mark.parametrize("kwargs, word", [
    (dict(variations=[("torque_nm", [10, float("nan")])]), r"torque_nm\[1\]"),
    (dict(variations=[("torque_nm", [10, 10.0])]), "repeat"),
    (dict(variations=[("torque_nm", [])]), "at least one"),
    (dict(variations=[("torque_nm", [-1.0])]), r"case 000_T-1Nm: torque_nm"),
    (dict(variations=[("friction", [1.5])]), r"friction\[0\]"),
    (dict(variations=[("torque_nm", [1]), ("torque_nm", [2])]), "more than once"),
    (dict(variations=[("speed_rpm", [1000])], fixed={"speed_rpm": 900}), "both varied"),
    (dict(variations=[("torque_nm", [10])], fixed={}), "speed_rpm must be varied"),
    (dict(variations=[("clearance_m", [True])]), r"clearance_m\[0\]"),
    (dict(variations=["torque_nm"]), "a variation is"),
    (dict(variations=[("torque_nm", [10])], repeats=0), "repeats"),
    (dict(variations=[("torque_nm", [10])], mesh="fe"), "mesh must be one of"),
    (dict(variations=[("shafts.0.bearing_1.n_balls", [1])]), "n_balls"),
])
def test_bad_specs_name_the_setting(kwargs, word):
    kwargs.setdefault("fixed", {"speed_rpm": 1000.0})
    with pytest.raises(ParameterError, match=word):
        SweepSpec(**kwargs)


def test_friction_needs_a_rig_with_gears():
    from cmsim.rig import Rotor
    rig = Rig.rotor_on_bearings(BASE.bearings[0], Rotor(mass_kg=5.0, inertia_kg_m2=0.01))
    with pytest.raises(ParameterError, match="'friction' needs a rig with gears"):
        SweepSpec([("friction", [0.03])], fixed={"speed_rpm": 1000.0}, rig=rig)
    spec = SweepSpec([("radial_load_n", [100.0, 200.0])], fixed={"speed_rpm": 1000.0}, rig=rig)
    assert [c.name for c in spec.cases()] == ["000_Fr100N", "001_Fr200N"]


def test_mesh_objects_are_keyed_by_content():
    from cmsim.mesh_stiffness.table import MeshStiffnessTable
    a = MeshStiffnessTable.constant(BASE.gears, 1.0e8)
    b = MeshStiffnessTable.constant(BASE.gears, 1.1e8)
    spec_a = SweepSpec([("torque_nm", [10])], fixed={"speed_rpm": 1000.0}, mesh=a)
    spec_b = SweepSpec([("torque_nm", [10])], fixed={"speed_rpm": 1000.0}, mesh=b)
    assert spec_a.to_dict()["mesh"]["type"] == "MeshStiffnessTable"
    assert spec_a.to_dict()["mesh"] != spec_b.to_dict()["mesh"] and spec_a != spec_b
    assert SweepSpec([("torque_nm", [10])], fixed={"speed_rpm": 1000.0},
                     mesh="hybrid-tables").mesh is None          # the default, by name
