"""FE model of the gear body (mesh_stiffness.fe_mesh, fe_model).

Tiers:

* (a) closed form — a clamped rectangular cantilever with a tip load against the
  Timoshenko beam (shear coefficient 5/6), plane-stress/plane-strain Lamé constants;
* mesh checks — every boundary node of the gear mesh lies on the rack-generated outline or
  on the bore, quality (smallest angle) and grading (fine on tooth 0's loaded flank);
* convergence — the single-tooth compliance changes by less than 2 % between the default
  mesh and one 1.4 times coarser (the table's FE is cached once per test session).

The gear builds take about 10 s each (two in this module, one shared through the cache).
"""

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree
from skfem import MeshTri

from cmsim.errors import ParameterError
from cmsim.mesh_stiffness.fe_mesh import MeshSpec
from cmsim.mesh_stiffness.fe_model import ElasticModel2D, GearBodyModel, lame_parameters
from cmsim.mesh_stiffness.geometry import ToothProfile
from cmsim.mesh_stiffness.influence import compute_influence_table, influence_table
from cmsim.rig import Rig

E, NU, B = 210e9, 0.3, 6.35e-3


@pytest.fixture(scope="module")
def gear():
    return Rig.paper_2016().gears.driving


def test_lame_parameters_plane_stress_and_strain():
    lam_s, mu_s = lame_parameters(E, NU, "stress")
    lam_e, mu_e = lame_parameters(E, NU, "strain")
    assert math.isclose(mu_s, E / (2 * (1 + NU)), rel_tol=1e-14)
    assert math.isclose(mu_e, mu_s, rel_tol=1e-14)
    assert math.isclose(lam_s, E * NU / (1 - NU ** 2), rel_tol=1e-14)
    assert math.isclose(lam_e, E * NU / ((1 + NU) * (1 - 2 * NU)), rel_tol=1e-14)
    with pytest.raises(ParameterError, match="plane"):
        lame_parameters(E, NU, "axisymmetric")


@pytest.mark.parametrize("x_over_l", [0.5, 0.8])
def test_cantilever_matches_timoshenko_beam(x_over_l):
    """v(x) = P x²(3L − x)/(6EI) + P x/(κGA), κ = 5/6, plane stress, L/H = 10."""
    length, height, load = 0.04, 0.004, 100.0
    mesh = MeshTri.init_tensor(np.linspace(0, length, 41), np.linspace(0, height, 5))
    mesh = mesh.with_boundaries({"left": lambda x: x[0] < 1e-12})
    model = ElasticModel2D.from_mesh(mesh, E, NU, B, "stress", "left")
    f = load * model.point_load_vectors(np.array([[length - 1e-9, height / 2]]),
                                        np.array([[0.0, -1.0]]))
    u = model.solve(f)[:, 0]
    x = x_over_l * length
    v = -(model.probe(np.array([[x, height / 2]])) @ u)[1]
    inertia, area, shear = B * height ** 3 / 12, B * height, E / (2 * (1 + NU))
    beam = load * x ** 2 * (3 * length - x) / (6 * E * inertia) + load * x / (5 / 6 * shear * area)
    # the fully clamped end and the point load cost the beam model < 0.5 % here
    assert abs(v / beam - 1.0) < 0.01


def test_elastic_model_rejects_bad_input():
    mesh = MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    mesh = mesh.with_boundaries({"left": lambda x: x[0] < 1e-12})
    with pytest.raises(ParameterError, match="fixed_boundary"):
        ElasticModel2D.from_mesh(mesh, E, NU, B, "stress", "bore")
    with pytest.raises(ParameterError, match="poisson_ratio"):
        ElasticModel2D.from_mesh(mesh, E, 0.5, B, "stress", "left")
    model = ElasticModel2D.from_mesh(mesh, E, NU, B, "stress", "left")
    with pytest.raises(ParameterError, match="outside the mesh"):
        model.probe(np.array([[2.0, 0.5]]))
    with pytest.raises(ParameterError, match="rows"):
        model.solve(np.zeros(3))


@pytest.fixture(scope="module")
def coarse_body(gear):
    return GearBodyModel.from_gear(gear, MeshSpec().scaled(1.4))


@pytest.fixture(scope="module")
def coarse_mesh(coarse_body):
    return coarse_body.gear_mesh


def test_gear_mesh_follows_the_outline(gear, coarse_mesh):
    m = coarse_mesh
    prof = ToothProfile.from_gear(gear, n_points=800)
    # boundary nodes: edges used by exactly one triangle
    t = m.triangles
    edges = np.sort(np.vstack([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    nodes = np.unique(uniq[count == 1])
    p = m.points_m[nodes]
    r = np.hypot(p[:, 0], p[:, 1])
    on_bore = np.abs(r - gear.bore_radius_m) < 1e-12
    # fold the others into tooth 0's sector and measure the distance to its outline
    q = p[~on_bore]
    phi = np.arctan2(q[:, 0], q[:, 1])
    k = np.round(phi / (2 * math.pi / gear.n_teeth)) * 2 * math.pi / gear.n_teeth
    qf = np.column_stack([np.cos(k) * q[:, 0] - np.sin(k) * q[:, 1],
                          np.sin(k) * q[:, 0] + np.cos(k) * q[:, 1]])
    dense = np.concatenate([np.linspace(a, b, 20, endpoint=False)
                            for a, b in zip(prof.points_m[:-1], prof.points_m[1:])])
    assert np.max(cKDTree(dense).query(qf)[0]) < 1e-6          # 1 µm ≪ the 90 µm elements
    assert np.count_nonzero(on_bore) == m.bore_nodes.size
    assert m.min_angle_deg() > 15.0
    # every triangle is counter-clockwise
    a, b_, c = (m.points_m[t[:, j]] for j in range(3))
    area2 = (b_[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b_[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert np.all(area2 > 0)


def test_gear_mesh_is_graded_towards_the_loaded_flank(gear, coarse_mesh):
    m = coarse_mesh
    t = m.triangles
    centroid = m.points_m[t].mean(axis=1)
    edge = np.linalg.norm(m.points_m[t[:, 0]] - m.points_m[t[:, 1]], axis=1)
    flank = ToothProfile.from_gear(gear).segment("involute", "right")
    d = cKDTree(flank).query(centroid)[0]
    spec = MeshSpec().scaled(1.4)
    near = d < 0.03 * gear.module_m
    far = np.hypot(centroid[:, 0], centroid[:, 1]) < 0.03
    assert np.median(edge[near]) < 1.5 * spec.h_flank * gear.module_m
    assert np.median(edge[far]) > 0.6 * spec.h_body * gear.module_m
    assert np.median(edge[far]) > 8 * np.median(edge[near])


def test_mesh_spec_validation():
    with pytest.raises(ParameterError, match="h_body"):
        MeshSpec(h_body=0.01)
    with pytest.raises(ParameterError, match="n_neighbours"):
        MeshSpec(n_neighbours=-1)
    assert math.isclose(MeshSpec().scaled(2.0).h_flank, 0.04, rel_tol=1e-12)


def test_single_tooth_compliance_converges(gear, coarse_body):
    """λ(ρ, ρ) at three heights: the 1.4× coarser mesh differs by < 2 % from the default."""
    fine = influence_table(gear)                     # default mesh, cached for the session
    idx = np.array([10, 35, 60])
    rho = fine.roll_m[idx]
    coarse = compute_influence_table(coarse_body, rho, fine.depth_m, max_offset=1)
    rel = coarse.diagonal_m_per_n / fine.diagonal_m_per_n[idx] - 1.0
    assert np.max(np.abs(rel)) < 0.02
    # the neighbour coupling converges too
    rel_c = coarse.coefficients_m_per_n[2].diagonal() / fine.coefficients_m_per_n[
        fine.max_offset + 1][idx, idx] - 1.0
    assert np.max(np.abs(rel_c)) < 0.02
    # and the tooth is as compliant as a tooth should be: 2-15 nm/N per tooth (ISO q' for a
    # tooth pair is 1/(c' b) = 1.25e-8 m/N, half of it per tooth, plus the body)
    assert np.all((fine.diagonal_m_per_n > 2e-9) & (fine.diagonal_m_per_n < 1.5e-8))
