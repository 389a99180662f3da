"""Specs as lists of named variations (issue 9), one spec for sweeps and datasets (issue 24).

Test tier: behaviour contracts (no physics, no simulation): a variation names an
operating-point field, a named rig transformation or a dotted rig field; a grid's records are
the Cartesian product of the variations (first slowest) times the repeats; each record has an
id from its values, its own seed, its rig and its operating point; unknown names are refused
with the allowed ones listed; the TOML form reads into the same spec, with the same seed
rule and the ranges of ``cmsim.rig.RANGES``. Runs in about a second.
"""

import json

import pytest

from cmsim.datasets import RIG_TRANSFORMS, DatasetSpec, Variation
from cmsim.datasets.variation import RigTransform
from cmsim.errors import ParameterError
from cmsim.rig import OperatingPoint, Rig

BASE = Rig.paper_2016()
AT_1000 = {"speed_rpm": 1000.0, "torque_nm": 10.0}


def plans(spec):
    """Every record of a spec, as drawn (:meth:`DatasetSpec.record`)."""
    return [spec.record(i) for i in range(len(spec))]


def test_rig_field_variation_clearance():
    spec = DatasetSpec([Variation("clearance_m", [15e-6, -1e-6])], fixed=AT_1000)
    cases = plans(spec)
    assert [c.record_id for c in cases] == ["000_c15um", "001_c-1um"]
    for case, c in zip(cases, (15e-6, -1e-6)):
        rig = spec.record_rig(case)
        assert [b.clearance_m for b in rig.bearings] == pytest.approx([c] * 4, rel=1e-12)
        assert rig == BASE.with_clearance(c)
        assert spec.record_operating_point(case) == OperatingPoint(1000.0, 10.0)
        assert case.params["clearance_m"] == pytest.approx(c, rel=1e-12)


def test_operating_point_variation_torque():
    spec = DatasetSpec([("torque_nm", [10, 40.0])], fixed={"speed_rpm": 1500})
    cases = plans(spec)
    assert [c.record_id for c in cases] == ["000_T10Nm", "001_T40Nm"]
    ops = [spec.record_operating_point(c) for c in cases]
    assert [op.torque_nm for op in ops] == pytest.approx([10.0, 40.0], rel=1e-12)
    assert {op.speed_rpm for op in ops} == {1500.0}
    assert all(spec.record_rig(c) == BASE for c in cases)      # the rig is untouched


def test_dotted_rig_field_changes_only_that_component():
    spec = DatasetSpec([Variation("shafts.0.bearing_1.clearance_m", [5e-6]),
                      Variation("lubricant.dynamic_viscosity_pa_s", [0.04])], fixed=AT_1000)
    (case,) = plans(spec)
    assert case.record_id == ("000_shafts-0-bearing_1-clearance_m5e-06"
                         "_lubricant-dynamic_viscosity_pa_s0.04")
    rig = spec.record_rig(case)
    assert rig.shafts[0].bearing_1.clearance_m == pytest.approx(5e-6, rel=1e-12)
    others = [rig.shafts[0].bearing_2, *rig.shafts[1].bearings]
    assert [b.clearance_m for b in others] == [b.clearance_m for b in BASE.bearings[1:]]
    assert rig.lubricant.dynamic_viscosity_pa_s == pytest.approx(0.04, rel=1e-12)
    ints = DatasetSpec([Variation("shafts.1.bearing_2.n_balls", [8, 10])], fixed=AT_1000)
    assert [ints.record_rig(c).shafts[1].bearing_2.n_balls for c in plans(ints)] == [8, 10]


def test_product_of_three_variations():
    spec = DatasetSpec([Variation("speed_rpm", [1000, 1500]),
                      Variation("torque_nm", [10, 50, 100]),
                      Variation("friction", [0.0, 0.03])], seed=5)
    cases = plans(spec)
    assert len(cases) == len(spec) == 2 * 3 * 2
    assert [c.index for c in cases] == list(range(12))
    assert len({c.record_id for c in cases}) == 12 and len({c.sim_seed for c in cases}) == 12
    # first variation slowest, last fastest
    assert [c.params["speed_rpm"] for c in cases[:6]] == [1000.0] * 6
    assert [c.params["friction"] for c in cases[:4]] == [0.0, 0.03, 0.0, 0.03]
    assert cases[-1].record_id == "011_n1500rpm_T100Nm_f0.03"
    last = spec.record_rig(cases[-1])
    assert last.mesh_contact.friction_coefficient == pytest.approx(0.03, rel=1e-12)


def test_a_new_axis_needs_no_new_loop(monkeypatch):
    """A fourth axis (a dotted rig field) and a newly registered transformation both multiply
    the cases through the same public call."""
    three = [("speed_rpm", [1000]), ("torque_nm", [10, 50]), ("clearance_m", [15e-6, 0.0])]
    four = three + [("mesh_contact.damping_ratio", [0.05, 0.1, 0.2])]
    assert len(plans(DatasetSpec(three))) == 4
    spec4 = DatasetSpec(four)
    assert len(plans(spec4)) == 12
    assert sorted({spec4.record_rig(c).mesh_contact.damping_ratio for c in plans(spec4)}) \
        == pytest.approx([0.05, 0.1, 0.2], rel=1e-12)

    def thicker_oil(rig, factor):
        return Rig.from_dict({**rig.to_dict(), "lubricant": {
            "dynamic_viscosity_pa_s": rig.lubricant.dynamic_viscosity_pa_s * factor}})

    monkeypatch.setitem(RIG_TRANSFORMS, "oil_factor",
                        RigTransform(apply=thicker_oil, token=lambda v: f"oil{v:g}x"))
    spec5 = DatasetSpec(four + [("oil_factor", [1.0, 10.0])])
    cases = plans(spec5)
    assert len(cases) == 24 and cases[1].record_id.endswith("_oil10x")
    assert spec5.record_rig(cases[1]).lubricant.dynamic_viscosity_pa_s == pytest.approx(
        10 * BASE.lubricant.dynamic_viscosity_pa_s, rel=1e-12)


def test_repeats_and_seeds():
    spec = DatasetSpec([("torque_nm", [10, 20])], fixed={"speed_rpm": 1000}, repeats=3, seed=2)
    cases = plans(spec)
    assert [c.record_id for c in cases][:3] == ["000_T10Nm_r0", "001_T10Nm_r1", "002_T10Nm_r2"]
    assert [c.repeat for c in cases] == [0, 1, 2, 0, 1, 2]
    assert len({c.sim_seed for c in cases}) == 6
    assert spec.record_rig(cases[0]) == spec.record_rig(cases[1])
    # seeds come from (base seed, index) alone: a record drawn on its own is the same
    assert [c.sim_seed for c in cases] == [spec.record(i).sim_seed for i in range(6)]
    assert [spec.record_id(i) for i in range(6)] == [c.record_id for c in cases]
    shared = DatasetSpec([("torque_nm", [10, 20])], fixed={"speed_rpm": 1000}, seed=4,
                         seed_policy="shared")
    assert [c.sim_seed for c in plans(shared)] == [4, 4]


def test_stored_form_and_unknown_keys():
    new = DatasetSpec([("clearance_m", [15e-6, -1e-6]), ("shafts.0.bearing_1.n_balls", [9, 10])],
                      fixed={"speed_rpm": 1000.0, "radial_load_n": 20.0}, repeats=2,
                      mesh="potential-energy", duration_s=0.2, seed=1)
    data = json.loads(json.dumps(new.to_dict()))
    assert data["settings"][-1] == {"name": "shafts.0.bearing_1.n_balls", "kind": "choice",
                                    "values": [9, 10]}
    assert data["settings"][0] == {"name": "speed_rpm", "kind": "constant", "values": [1000.0]}
    assert data["mesh"] == "potential-energy" and data["repeats"] == 2
    assert len(new) == 8
    with pytest.raises(ParameterError, match="dataset.speed: unknown key"):
        DatasetSpec.from_dict({"dataset": {"speed": 3}})


@pytest.mark.parametrize("variations, words", [
    ([("speed", [1000])], ["'speed'", "speed_rpm", "clearance_m", "friction", "lubricant"]),
    ([("lubricant.viscosity", [1.0])], ["'lubricant.viscosity'", "dynamic_viscosity_pa_s"]),
    ([("shafts.2.bearing_1.clearance_m", [1e-6])], ["shafts", "0..1"]),
    ([("gears", [1.0])], ["'gears'", "component"]),
    ([("gears.driving.n_teeth.x", [1.0])], ["n_teeth", "not a component"]),
])
def test_unknown_variation_is_refused_with_the_allowed_names(variations, words):
    with pytest.raises(ParameterError) as err:
        DatasetSpec(variations, fixed=AT_1000)
    for word in words:
        assert word in str(err.value)


@pytest.mark.parametrize("kwargs, word", [
    (dict(variations=[("torque_nm", [10, float("nan")])]), r"torque_nm\[1\]"),
    (dict(variations=[("torque_nm", [10, 10.0])]), "repeat"),
    (dict(variations=[("torque_nm", [])]), "at least one"),
    (dict(variations=[("torque_nm", [-1.0])]), r"record 000_T-1Nm: torque_nm"),
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
        DatasetSpec(**kwargs)


def test_friction_needs_a_rig_with_gears():
    from cmsim.rig import Rotor
    rig = Rig.rotor_on_bearings(BASE.bearings[0], Rotor(mass_kg=5.0, inertia_kg_m2=0.01))
    with pytest.raises(ParameterError, match="'friction' needs a rig with gears"):
        DatasetSpec([("friction", [0.03])], fixed={"speed_rpm": 1000.0}, rig=rig)
    spec = DatasetSpec([("radial_load_n", [100.0, 200.0])], fixed={"speed_rpm": 1000.0}, rig=rig)
    assert [c.record_id for c in plans(spec)] == ["000_Fr100N", "001_Fr200N"]


def test_mesh_objects_are_keyed_by_content():
    from cmsim.mesh_stiffness.table import MeshStiffnessTable
    a = MeshStiffnessTable.constant(BASE.gears, 1.0e8)
    b = MeshStiffnessTable.constant(BASE.gears, 1.1e8)
    spec_a = DatasetSpec([("torque_nm", [10])], fixed={"speed_rpm": 1000.0}, mesh=a)
    spec_b = DatasetSpec([("torque_nm", [10])], fixed={"speed_rpm": 1000.0}, mesh=b)
    assert spec_a.to_dict()["mesh"]["type"] == "MeshStiffnessTable"
    assert spec_a.to_dict()["mesh"] != spec_b.to_dict()["mesh"] and spec_a != spec_b
    assert DatasetSpec([("torque_nm", [10])], fixed={"speed_rpm": 1000.0},
                       mesh="hybrid-tables").mesh is None          # the default, by name


# ---------------------------------------------------------------------- one spec, two forms
TOML_GRID = {"dataset": {"name": "g", "seed": 9},
             "operating": {"sampling": "grid", "speed_rpm": [1000.0, 1500.0],
                           "torque_nm": [10.0, 50.0], "clearance_m": 15e-6},
             "sensor": {"channels": "all", "fs_hz": 75_000.0, "duration_s": 0.1}}


def test_a_toml_grid_is_the_python_grid():
    """The TOML form and the keywords build the same spec: same records, ids and seeds."""
    toml = DatasetSpec.from_dict(TOML_GRID)
    python = DatasetSpec([("speed_rpm", [1000.0, 1500.0]), ("torque_nm", [10.0, 50.0])],
                         fixed={"clearance_m": 15e-6}, name="g", seed=9, duration_s=0.1)
    assert len(toml) == len(python) == 4 and toml.channels is None
    for a, b in zip(plans(toml), plans(python)):
        assert (a.record_id, a.sim_seed) == (b.record_id, b.sim_seed)
        assert toml.record_rig(a) == python.record_rig(b)
        assert toml.record_operating_point(a) == python.record_operating_point(b)
    assert [p.record_id for p in plans(toml)] == ["000_n1000rpm_T10Nm", "001_n1000rpm_T50Nm",
                                                  "002_n1500rpm_T10Nm", "003_n1500rpm_T50Nm"]


def test_more_records_than_grid_points_cycle_the_grid():
    data = {**TOML_GRID, "dataset": {"records": 6, "seed": 9}}
    spec = DatasetSpec.from_dict(data)
    ps = plans(spec)
    assert [p.params["torque_nm"] for p in ps] == [10.0, 50.0, 10.0, 50.0, 10.0, 50.0]
    assert ps[4].params["speed_rpm"] == 1000.0 and len({p.sim_seed for p in ps}) == 6


def test_toml_takes_any_setting_a_variation_names():
    data = {**TOML_GRID, "operating": {**TOML_GRID["operating"],
                                       "lubricant.dynamic_viscosity_pa_s": [0.004, 0.04]}}
    spec = DatasetSpec.from_dict(data)
    assert len(spec) == 8
    assert spec.record(7).record_id.endswith("_lubricant-dynamic_viscosity_pa_s0.04")
    assert spec.record_rig(spec.record(1)).lubricant.dynamic_viscosity_pa_s == \
        pytest.approx(0.04, rel=1e-12)
    bad = {**TOML_GRID, "operating": {**TOML_GRID["operating"], "lubricant.viscosity": 1.0}}
    with pytest.raises(ParameterError, match="operating.lubricant.viscosity"):
        DatasetSpec.from_dict(bad)


@pytest.mark.parametrize("name, value", [("friction", 0.31), ("clearance_m", 1.1e-3),
                                         ("speed_rpm", 2e5), ("torque_nm", -1.0)])
def test_both_forms_read_the_ranges_of_the_rig(name, value):
    """A value outside cmsim.rig.RANGES is refused the same way by the TOML form and by a
    variation (friction up to 0.3 in both; it was 1.0 for a sweep)."""
    from cmsim.rig import RANGES
    assert not RANGES[name].contains(value)
    op = {**TOML_GRID["operating"], name: [value]}
    with pytest.raises(ParameterError, match=f"operating.{name}"):
        DatasetSpec.from_dict({**TOML_GRID, "operating": op})
    fixed = {"speed_rpm": 1000.0} if name != "speed_rpm" else {}
    with pytest.raises(ParameterError, match=name):
        DatasetSpec([(name, [value])], fixed=fixed)


@pytest.mark.parametrize("key, value, word", [
    ("sensor.fs_hz", 1e8, "sensor.fs_hz"),
    ("sensor.duration_s", 0.0, "sensor.duration_s"),
    ("simulation.substeps", 0, "simulation.substeps"),
    ("dataset.seed", 2 ** 40, "dataset.seed"),
    ("dataset.seed_policy", "each", "dataset.seed_policy"),
    ("dataset.repeats", 0, "dataset.repeats"),
    ("sensor.channels", ["accel_9b9_y"], "sensor.channels[0]"),
])
def test_toml_errors_name_the_key(key, value, word):
    table, sub = key.split(".")
    data = {**TOML_GRID, table: {**TOML_GRID.get(table, {}), sub: value}}
    with pytest.raises(ParameterError, match=word.replace("[", r"\[").replace("]", r"\]")):
        DatasetSpec.from_dict(data)
