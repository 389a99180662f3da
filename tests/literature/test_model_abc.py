"""On-line hybrid contact in the dynamics (model A), torque tables and the §6.1 A/B/C study.

* Kernel integration: at a quasi-static state of the rig, the pair forces the dynamics
  computes on-line equal the hybrid solve of the same contacts done independently from the
  gear positions (slot order, roll lengths and curvatures passed correctly).
* Torque tables (paper §6.1 workflow): mean stiffness of the order of the paper's and rising
  with torque, loaded contact ratio rising with torque, interpolation in torque, save/load.
* Table lookup at corner contacts: on model A's quasi-static state, with a pair in the
  approach corner (outside the involute path), the table model's pair forces equal the
  on-line solve's (the table is read at the pair's position s; read at s_eq it gave 2.7x).
* Paper 001 §6.1, 1000 rpm / 100 N·m: tables at the run's torque (B) reproduce the on-line
  solve (A) in DTE and in GMF harmonics 1-5 of the 1b1 LOA force (measured within 1.5 %);
  tables at 10 N·m (C) overestimate the DTE fluctuation (+13 %) and the 2nd harmonic (+15 %).
"""

import json
import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from cmsim.dynamics.model import build_model
from cmsim.dynamics.quasistatic import quasi_static_state
from cmsim.dynamics.tooth_contact import resolve_mesh
from cmsim.dynamics.torque_tables import torque_tables
from cmsim.errors import ParameterError
from cmsim.mesh_stiffness.contact import active_path_m
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.mesh_stiffness.mesh_cycle import slot_contacts
from cmsim.mesh_stiffness.table_set import MeshTableSet
from cmsim.rig import OperatingPoint, Rig, Rotor
from cmsim.studies.model_abc import gmf_harmonics, model_abc_study


@pytest.fixture(scope="module")
def rig():
    return Rig.paper_2016()


@pytest.fixture(scope="module")
def mesh_model(rig):
    return HybridMeshModel.from_pair(rig.gears)


@pytest.fixture(scope="module")
def tables(rig, mesh_model):
    return torque_tables(rig, [10.0, 50.0, 100.0], mesh_model=mesh_model)


@pytest.fixture(scope="module")
def study(mesh_model):
    return model_abc_study(duration_s=0.4, seed=1, mesh_model=mesh_model)


@pytest.mark.parametrize("t", [0.0, 3.1e-4])
def test_online_forces_equal_independent_hybrid_solve(rig, mesh_model, t):
    op = OperatingPoint(1000.0, 100.0)
    # no mesh damping: a corner contact has a normal approach velocity even in the nominal
    # motion, and the hysteretic term would add to the elastic force compared here
    undamped = replace(rig, mesh_contact=replace(rig.mesh_contact, damping_ratio=0.0))
    model = build_model(undamped, op, resolve_mesh(undamped, mesh_model, op.torque_nm))
    q = quasi_static_state(model, t)
    # nominal rotation at rest relative to it: velocities of the nominal motion only
    _, diag = model.rhs(t, np.concatenate([q, np.zeros(model.n_dof)]), want_diag=True)
    pair_forces = np.array([diag[model.output_force_names.index(f"Fmesh_{j}")]
                            for j in range(sum(d.startswith("Fmesh")
                                               for d in model.output_force_names))])
    ix1, ix2 = model.index("x_1G1"), model.index("x_2G1")
    th1 = model.omega[ix1 + 2] * t + q[ix1 + 2]
    th2 = model.omega[ix2 + 2] * t + q[ix2 + 2]
    c = slot_contacts(rig.gears, th1, th2, q[ix1:ix1 + 2], q[ix2:ix2 + 2],
                      n_slots=pair_forces.size)
    ref = mesh_model.forces(c["delta_m"], c["s_eq_m"], c["length_m"] - c["s_eq_m"],
                            np.maximum(c["chi1_m"], 1e-9), np.maximum(c["chi2_m"], 1e-9))
    assert np.count_nonzero(ref) >= 1
    # (an approaching unloaded pair also carries a tiny Koster squeeze-film force)
    assert np.allclose(pair_forces, ref, rtol=1e-9, atol=1e-6 * ref.max())
    # and the pairs carry the torque: Σ F ≈ T / r_b (friction-free rig)
    assert math.isclose(pair_forces.sum(), 100.0 / rig.gears.driving.base_radius_m,
                        rel_tol=0.02)


@pytest.mark.parametrize("phase", [3, 4])
def test_table_forces_equal_online_forces_at_a_corner_contact(rig, mesh_model, tables, phase):
    # instants 3/24 and 4/24 of a mesh period: the entering pair is in the approach corner
    # (s = 6.98 and 7.37 mm, involute path from 7.70 mm) and carries 190 and 760 N
    op = OperatingPoint(1000.0, 100.0)
    undamped = replace(rig, mesh_contact=replace(rig.mesh_contact, damping_ratio=0.0))
    model_a = build_model(undamped, op, resolve_mesh(undamped, mesh_model, op.torque_nm))
    model_b = build_model(undamped, op, (tables.at(100.0), None))
    t = phase / (24.0 * 1000.0 / 60.0 * rig.gears.driving.n_teeth)
    y = np.concatenate([quasi_static_state(model_a, t), np.zeros(model_a.n_dof)])
    names = [n for n in model_a.output_force_names if n.startswith("Fmesh")]
    fa, fb = (np.array([m.rhs(t, y, want_diag=True)[1][m.output_force_names.index(n)]
                        for n in names])
              for m in (model_a, model_b))
    ix1, ix2 = model_a.index("x_1G1"), model_a.index("x_2G1")
    c = slot_contacts(rig.gears, model_a.omega[ix1 + 2] * t + y[ix1 + 2],
                      model_a.omega[ix2 + 2] * t + y[ix2 + 2], y[ix1:ix1 + 2],
                      y[ix2:ix2 + 2], n_slots=len(names))
    corner = int(np.argmin(c["position_m"]))
    assert c["position_m"][corner] < active_path_m(rig.gears)[0]
    assert fa[corner] > 100.0
    assert fb == pytest.approx(fa, rel=0.05, abs=1.0)


def test_mesh_model_must_match_the_rig(rig, mesh_model):
    rotor_rig = Rig.rotor_on_bearings(rig.shafts[0].bearing_1,
                                      Rotor(mass_kg=4.0, inertia_kg_m2=0.01))
    with pytest.raises(ParameterError, match="without gears"):
        resolve_mesh(rotor_rig, mesh_model, 0.0)
    wider = replace(rig, gears=replace(rig.gears, centre_distance_m=0.0891))
    with pytest.raises(ParameterError, match="different gear pair"):
        resolve_mesh(wider, mesh_model, 10.0)
    with pytest.raises(ParameterError, match="HybridMeshModel"):
        resolve_mesh(rig, "no-such-mesh", 10.0)


def test_build_model_takes_a_resolved_mesh(rig, mesh_model):
    """build_model takes the (table, on-line model) pair of resolve_mesh and checks it."""
    op = OperatingPoint(1000.0, 10.0)
    table = resolve_mesh(rig, "potential-energy", 10.0)[0]
    with pytest.raises(ParameterError, match="resolve_mesh"):
        build_model(rig, op, "potential-energy")
    with pytest.raises(ParameterError, match="MeshStiffnessTable"):
        build_model(rig, op)
    rotor_rig = Rig.rotor_on_bearings(rig.shafts[0].bearing_1,
                                      Rotor(mass_kg=4.0, inertia_kg_m2=0.01))
    with pytest.raises(ParameterError, match="without gears"):
        build_model(rotor_rig, OperatingPoint(1000.0, 0.0, radial_load_n=100.0), (table, None))
    wider = replace(rig, gears=replace(rig.gears, centre_distance_m=0.0891))
    with pytest.raises(ParameterError, match="different gear pair"):
        build_model(wider, op, (table, mesh_model))
    assert build_model(rig, op, (table, None)).mesh_table is table


def test_torque_tables_follow_the_paper(tables):
    s = {row["torque_nm"]: row for row in tables.summary}
    paper = {10.0: 1.08e8, 50.0: 1.16e8, 100.0: 1.19e8}     # papers/NOTES.md
    for q, k in paper.items():
        assert s[q]["mean_stiffness_n_per_m"] == pytest.approx(k, rel=0.05)
    means = [s[q]["mean_stiffness_n_per_m"] for q in (10.0, 50.0, 100.0)]
    ratios = [s[q]["loaded_contact_ratio"] for q in (10.0, 50.0, 100.0)]
    assert means[0] < means[1] < means[2]
    assert ratios[0] < ratios[1] < ratios[2]
    assert 1.6 < ratios[0] and ratios[2] < 2.0
    # the bearings deflect under the mesh load: centroids move apart along the LOA
    r1 = np.hypot(*s[100.0]["centre1_um"])
    assert r1 > np.hypot(*s[10.0]["centre1_um"]) > 1.0
    assert all(row["peak_to_peak_stiffness_n_per_m"] > 0.2 * row["mean_stiffness_n_per_m"]
               for row in tables.summary)


def test_table_set_interpolates_and_round_trips(tables, tmp_path):
    mid = tables.at(30.0)
    a, b = tables.tables[0], tables.tables[1]
    assert np.allclose(mid.stiffness_n_per_m,
                       0.5 * (a.stiffness_n_per_m + b.stiffness_n_per_m))
    assert tables.at(100.0) is tables.tables[2]
    assert tables.at(500.0) is tables.tables[2]                  # no extrapolation
    path = tmp_path / "t.npz"
    tables.save(path)
    back = MeshTableSet.load(path)
    assert np.array_equal(back.torques_nm, tables.torques_nm)
    assert np.array_equal(back.tables[1].stiffness_n_per_m, tables.tables[1].stiffness_n_per_m)
    assert back.summary == tables.summary
    single = tmp_path / "one.npz"
    tables.tables[0].save(single)
    assert MeshTableSet.load(single).tables[0].torque_nm == 10.0


def test_torque_tables_reject_bad_input(rig):
    with pytest.raises(ParameterError, match="torques_nm"):
        torque_tables(rig, [10.0, -5.0])
    with pytest.raises(ParameterError, match="distinct"):
        torque_tables(rig, [10.0, 10.0])
    with pytest.raises(ParameterError, match="method"):
        torque_tables(rig, [10.0], method="fem")


def test_gmf_harmonics_reads_sinusoid_amplitudes():
    fs, f0 = 20_000.0, 466.0
    t = np.arange(8000) / fs
    x = 3.0 * np.sin(2 * np.pi * f0 * t) + 0.5 * np.cos(2 * np.pi * 3 * f0 * t + 0.3)
    h = gmf_harmonics(x, fs, f0, 4)
    assert h == pytest.approx([3.0, 0.0, 0.5, 0.0], abs=0.01)


def test_model_b_reproduces_model_a(study):
    a, b = study.metrics["A"], study.metrics["B"]
    assert a["hybrid_unconverged"] == 0
    assert b["dte_mean_um"] == pytest.approx(a["dte_mean_um"], rel=0.01)
    assert b["dte_std_um"] == pytest.approx(a["dte_std_um"], rel=0.03)
    assert b["dte_peak_to_peak_um"] == pytest.approx(a["dte_peak_to_peak_um"], rel=0.03)
    ha, hb = np.array(a["gmf_harmonics_n"]), np.array(b["gmf_harmonics_n"])
    # the dominant harmonic (the 5th, near a mesh resonance) is the same; harmonics 1-5
    # measured within 1.5 % (B/A = 1.00 1.01 1.00 0.99 1.01), the 6th (10 N) within 4 %
    assert np.argmax(ha) == np.argmax(hb) == 4
    assert hb[:5] == pytest.approx(ha[:5], rel=0.05)
    assert hb[5] == pytest.approx(ha[5], rel=0.15)


def test_model_c_overestimates(study):
    a, b, c = (study.metrics[m] for m in "ABC")
    # measured: DTE std +13 %, peak-to-peak +7 %, 2nd harmonic +15 % against A; the 4th and
    # 5th harmonics come out 6 % below A (the paper: above), see the study's Findings
    assert c["dte_std_um"] > 1.08 * a["dte_std_um"]
    assert c["dte_std_um"] > 1.08 * b["dte_std_um"]
    assert c["dte_peak_to_peak_um"] > 1.04 * a["dte_peak_to_peak_um"]
    ha, hc = np.array(a["gmf_harmonics_n"]), np.array(c["gmf_harmonics_n"])
    assert hc[1] > 1.08 * ha[1]


def test_cli_mesh_table_and_table_driven_simulation(tmp_path):
    out = tmp_path / "tables.npz"
    res = subprocess.run([sys.executable, "-m", "cmsim.cli", "mesh-table", "--torque-nm", "10",
                          "100", "--out", str(out), "--json"], capture_output=True, text=True,
                         check=True)
    data = json.loads(res.stdout)
    rows = data["tables"]
    assert [r["torque_nm"] for r in rows] == [10.0, 100.0]
    for r in rows:
        assert {"mean_stiffness_n_per_m", "peak_to_peak_stiffness_n_per_m",
                "loaded_contact_ratio"} <= set(r)
    assert rows[1]["loaded_contact_ratio"] > rows[0]["loaded_contact_ratio"]
    sim = subprocess.run([sys.executable, "-m", "cmsim.cli", "simulate", "--speed-rpm", "1000",
                          "--torque-nm", "100", "--duration-s", "0.05", "--mesh-table", str(out),
                          "--table-torque-nm", "10", "--json"], capture_output=True, text=True,
                         check=True)
    info = json.loads(sim.stdout)
    assert info["mesh_table"]["method"] == "hybrid"
    assert info["mesh_table"]["torque_nm"] == 10.0
    # the 10 N·m table's loaded mean stiffness (paper: 1.08e8 N/m), not the 100 N·m one
    assert info["mesh_table"]["mean_mesh_stiffness_n_per_m"] == pytest.approx(1.08e8, rel=0.02)
    hyb = subprocess.run([sys.executable, "-m", "cmsim.cli", "simulate", "--speed-rpm", "1000",
                          "--torque-nm", "100", "--duration-s", "0.05", "--mesh", "hybrid",
                          "--json"], capture_output=True, text=True, check=True)
    assert json.loads(hyb.stdout)["mesh"] == "hybrid"
    bad = subprocess.run([sys.executable, "-m", "cmsim.cli", "simulate", "--speed-rpm", "1000",
                          "--mesh", "hybrid", "--mesh-table", str(out)], capture_output=True,
                         text=True)
    assert bad.returncode == 2 and "--mesh-table" in bad.stderr
