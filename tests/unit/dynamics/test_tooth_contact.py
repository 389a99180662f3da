"""The default mesh is the paper's model B: hybrid tables at the run's torque.

Tier: regression and structure. Checks that

* the mean mesh stiffness of a hybrid table (which feeds the modal analysis and the mesh
  damping) equals the loaded mean of the quasi-static mesh cycle that built it (the figure
  ``cmsim mesh-table`` prints) within 1 % at 10 / 50 / 100 N·m, both for freshly built tables
  and for the shipped package data;
* the paper rig's shipped tables match its parameters, so ``resolve_mesh`` never runs the FE
  build for it; other rigs build once and then load from the on-disk cache;
* torques below the grid use the 5 N·m table, above it a table is built on demand;
* bad ``mesh`` values are refused with an error naming ``mesh``.
"""

import warnings
from dataclasses import replace

import numpy as np
import pytest

from cmsim.dynamics import tooth_contact
from cmsim.dynamics.tooth_contact import (MESH_CHOICES, TORQUE_GRID_NM, hybrid_table_set,
                                          resolve_mesh, tables_key)
from cmsim.dynamics.torque_tables import torque_tables
from cmsim.errors import ModelWarning, ParameterError
from cmsim.mesh_stiffness import influence
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.mesh_stiffness.table_set import MeshTableSet
from cmsim.rig import Rig, Rotor

RIG = Rig.paper_2016()


def _no_fe(*args, **kwargs):
    raise AssertionError("the FE builder was called")


@pytest.fixture
def fresh(monkeypatch, tmp_path):
    """Empty in-memory memo and an empty on-disk cache."""
    monkeypatch.setattr(tooth_contact, "_SETS", {})
    monkeypatch.setattr(tooth_contact, "_ABOVE", {})
    monkeypatch.setenv("CMSIM_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


@pytest.fixture
def no_fe(monkeypatch):
    monkeypatch.setattr(HybridMeshModel, "from_pair", classmethod(_no_fe))
    monkeypatch.setattr(influence, "compute_influence_table", _no_fe)


def test_built_tables_mean_stiffness_is_the_mesh_cycle_figure():
    tables = torque_tables(RIG, [10.0, 50.0, 100.0])
    for table, row in zip(tables.tables, tables.summary):
        k_cycle = row["mean_stiffness_n_per_m"]
        assert table.mean_mesh_stiffness(RIG.gears) == pytest.approx(k_cycle, rel=0.01)
        assert table.meta["mean_mesh_stiffness_n_per_m"] == pytest.approx(k_cycle, rel=1e-12)
    # the nominal involute path alone misses the contact extended by load (-6 % at 100 N m)
    nominal = replace(tables.tables[2], meta={})
    assert nominal.mean_mesh_stiffness(RIG.gears) < 0.97 * tables.summary[2][
        "mean_stiffness_n_per_m"]


def test_shipped_tables_match_the_paper_rig_and_their_mesh_cycle():
    tables = tooth_contact._shipped_set(tables_key(RIG))
    assert tables is not None, ("the shipped tables do not match Rig.paper_2016(): rebuild "
                                "them with python -m cmsim.dynamics.tooth_contact")
    assert np.allclose(tables.torques_nm, TORQUE_GRID_NM, rtol=0, atol=1e-12)
    rows = {row["torque_nm"]: row for row in tables.summary}
    for q in (10.0, 50.0, 100.0):
        k = tables.at(q).mean_mesh_stiffness(RIG.gears)
        assert k == pytest.approx(rows[q]["mean_stiffness_n_per_m"], rel=0.01)
    paper = {10.0: 1.08e8, 50.0: 1.16e8, 100.0: 1.19e8}          # papers/NOTES.md
    for q, k in paper.items():
        assert rows[q]["mean_stiffness_n_per_m"] == pytest.approx(k, rel=0.03)


def test_default_mesh_on_the_paper_rig_needs_no_fe_build(fresh, no_fe, monkeypatch):
    monkeypatch.setattr(tooth_contact.table_builder, "torque_tables", _no_fe)
    table, model = resolve_mesh(RIG, None, 100.0)
    assert model is None and table.method == "hybrid" and table.torque_nm == 100.0
    same, _ = resolve_mesh(RIG, "hybrid-tables", 100.0)
    assert same is table
    # linear in torque between grid points, mean stiffness included
    mid, _ = resolve_mesh(RIG, None, 45.0)
    k40, k50 = (resolve_mesh(RIG, None, q)[0].mean_mesh_stiffness(RIG.gears)
                for q in (40.0, 50.0))
    assert k40 < mid.mean_mesh_stiffness(RIG.gears) < k50
    # below the grid: the 5 N m table (also at 0 N m)
    low = hybrid_table_set(RIG).tables[0]
    assert resolve_mesh(RIG, None, 0.0)[0] is low
    assert resolve_mesh(RIG, None, 2.0)[0] is low
    assert not any(fresh.glob("*")) if fresh.exists() else True


def test_other_rigs_build_the_table_their_torque_needs_once(fresh, monkeypatch):
    """A rig without a shipped or cached set (here the paper's rig at another clearance,
    which moves the tables by up to 9-23 % of their peak near the loaded range's ends)
    builds one table per torque it runs at, caches it on disk and reuses it; the mesh
    friction (≤ 0.05 % on the tables) does not change the key. A whole set, once built
    (hybrid_table_set), serves every torque of the grid."""
    assert tables_key(replace(RIG, mesh_contact=replace(
        RIG.mesh_contact, friction_coefficient=0.03))) == tables_key(RIG)
    rig = RIG.with_clearance(5e-6)
    assert tables_key(rig) != tables_key(RIG)
    shipped = tooth_contact._shipped_set(tables_key(RIG))
    calls = []

    def fake_builder(rig_, torques, **kwargs):
        calls.append(list(torques))
        if kwargs.get("progress"):
            kwargs["progress"](1, 1, shipped.summary[0])
        if len(torques) == 1:
            return MeshTableSet((replace(shipped.tables[-1], torque_nm=torques[0]),))
        return MeshTableSet(shipped.tables, shipped.summary, {"method": "hybrid"})

    monkeypatch.setattr(tooth_contact.table_builder, "torque_tables", fake_builder)
    monkeypatch.setattr(HybridMeshModel, "from_pair", classmethod(lambda cls, pair: None))
    seen = []
    table, _ = resolve_mesh(rig, None, 50.0, progress=lambda i, n, row: seen.append(i))
    assert calls == [[50.0]] and seen and table.torque_nm == 50.0
    assert any(fresh.glob("hybrid-table-*.npz"))
    monkeypatch.setattr(tooth_contact, "_ABOVE", {})
    again, _ = resolve_mesh(rig, None, 50.0, progress=False)
    assert len(calls) == 1                                  # from the disk cache
    assert np.array_equal(again.stiffness_n_per_m, table.stiffness_n_per_m)
    resolve_mesh(rig, None, 2.0, progress=False)            # below the grid: 5 N m
    assert calls[-1] == [5.0]
    above, _ = resolve_mesh(rig, None, 250.0, progress=False)
    assert calls[-1] == [250.0] and above.torque_nm == 250.0
    # a whole set, built and cached, then serves the grid's torques without new builds
    hybrid_table_set(rig, progress=False)
    assert calls[-1] == list(TORQUE_GRID_NM)
    monkeypatch.setattr(tooth_contact, "_SETS", {})
    n = len(calls)
    resolve_mesh(rig, None, 77.0, progress=False)
    assert len(calls) == n


def test_explicit_meshes_and_potential_energy():
    pe, model = resolve_mesh(RIG, "potential-energy", 50.0)
    assert model is None and pe.method == "potential-energy"
    assert pe.mean_mesh_stiffness(RIG.gears) == pytest.approx(1.305e8, rel=0.01)
    own = MeshStiffnessTable.constant(RIG.gears, 1e8)
    assert resolve_mesh(RIG, own, 50.0) == (own, None)
    tables = hybrid_table_set(RIG)
    assert resolve_mesh(RIG, tables, 100.0)[0] is tables.at(100.0)


def test_potential_energy_table_is_cached_with_its_warnings(fresh, monkeypatch):
    """The potential-energy table (every machine's twin mesh) is built once per gear pair
    and read from the disk cache by a later process, equal to the bit; a build that warned
    (Sainsot's fillet-foundation formula beyond its fit: a 60-tooth pinion on a 20-mm bore)
    warns again when a later process reads it, once, and another pair gets its own entry."""
    monkeypatch.setattr(tooth_contact, "_PE_CACHE", {})
    pair = replace(RIG.gears, driving=replace(RIG.gears.driving, n_teeth=60))
    with pytest.warns(ModelWarning, match="tooth foundation") as built:
        table = tooth_contact.default_mesh_table(pair)
    assert len(list(fresh.glob("potential-energy-*.npz"))) == 1
    monkeypatch.setattr(tooth_contact, "_PE_CACHE", {})      # a later process
    builds = []
    monkeypatch.setattr(MeshStiffnessTable, "potential_energy",
                        classmethod(lambda cls, p, n_points=257: builds.append(p)))
    with pytest.warns(ModelWarning) as read:
        again = tooth_contact.default_mesh_table(pair)
    assert not builds and [str(w.message) for w in read] == [str(w.message) for w in built]
    assert np.array_equal(again.stiffness_n_per_m, table.stiffness_n_per_m)
    assert np.array_equal(again.position_m, table.position_m)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                       # memoised: said once
        assert tooth_contact.default_mesh_table(pair) is again
    monkeypatch.undo()
    monkeypatch.setattr(tooth_contact, "_PE_CACHE", {})
    monkeypatch.setenv("CMSIM_CACHE_DIR", str(fresh))
    tooth_contact.default_mesh_table(RIG.gears)
    assert len(list(fresh.glob("potential-energy-*.npz"))) == 2


def test_gearless_rigs_and_bad_values():
    bearing_rig = Rig.rotor_on_bearings(RIG.bearings[0], Rotor(mass_kg=4.0,
                                                               inertia_kg_m2=0.01))
    assert resolve_mesh(bearing_rig, None, 0.0) == (None, None)
    assert resolve_mesh(bearing_rig, "potential-energy", 0.0) == (None, None)
    with pytest.raises(ParameterError, match="mesh"):
        resolve_mesh(bearing_rig, "hybrid", 0.0)
    for bad in ("fem", "table", 3.0):
        with pytest.raises(ParameterError, match="mesh") as err:
            resolve_mesh(RIG, bad, 10.0)
        assert all(c in str(err.value) for c in MESH_CHOICES)
    with pytest.raises(ParameterError, match="torque_nm"):
        resolve_mesh(RIG, None, -1.0)
