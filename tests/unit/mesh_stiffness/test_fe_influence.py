"""Influence coefficients of the hybrid method (mesh_stiffness.influence, cache).

Tiers:

* (a) closed form / exact properties — flank points lie on the rack-generated involute with
  the inward normal tangent to the base circle; Maxwell-Betti reciprocity
  λ(d, a, b) = λ(−d, b, a) of the FE tables;
* method checks (paper 001 §3: the local term is analytical, the FE sees the depth-h
  point) — λ at depth h hardly depends on how the unit load is spread (point vs Hertz
  pressure), and FE + local term hardly depends on h;
* cache — a second request reads the disk instead of recomputing, keys follow every input,
  writes are atomic.

One gear body is assembled here (≈ 10 s) and reused; the default table it produces is cached
for the whole test session.
"""

import math
import os

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.mesh_stiffness import cache
from cmsim.mesh_stiffness.fe_mesh import MeshSpec
from cmsim.mesh_stiffness.fe_model import GearBodyModel
from cmsim.mesh_stiffness.geometry import ToothProfile, involute_half_angle
from cmsim.mesh_stiffness.influence import (InfluenceTable, compute_influence_table,
                                            flank_points, influence_table, roll_range_m)
from cmsim.mesh_stiffness.local_deflection import (contact_modulus, hertz_half_width,
                                                   local_approach)
from cmsim.rig import Rig


@pytest.fixture(scope="module")
def gear():
    return Rig.paper_2016().gears.driving


@pytest.fixture(scope="module")
def body(gear):
    return GearBodyModel.from_gear(gear)


@pytest.fixture(scope="module")
def table(gear, body):
    return influence_table(gear, body=body)


def test_flank_points_are_on_the_involute(gear):
    lo, hi = roll_range_m(gear)
    rho = np.linspace(lo, hi, 25)
    rb = gear.base_radius_m
    for offset in (0, 2, -1):
        p, n = flank_points(gear, rho, offset)
        rot = 2 * math.pi * offset / gear.n_teeth          # undo the tooth rotation
        x = math.cos(rot) * p[:, 0] - math.sin(rot) * p[:, 1]
        y = math.sin(rot) * p[:, 0] + math.cos(rot) * p[:, 1]
        r = np.hypot(x, y)
        assert np.allclose(r, np.sqrt(rb ** 2 + rho ** 2), rtol=1e-13, atol=0)
        theta = np.arctan2(x, y)
        assert np.allclose(theta, involute_half_angle(r, rb, gear.base_half_thickness_angle_rad),
                           rtol=0, atol=1e-13)
        # unit normal, tangent to the base circle: the foot point is at distance ρ, radius r_b
        assert np.allclose(np.hypot(n[:, 0], n[:, 1]), 1.0, atol=1e-14)
        foot = p + rho[:, None] * n
        assert np.allclose(np.hypot(foot[:, 0], foot[:, 1]), rb, rtol=1e-12, atol=0)
    # inward: the point one module along the normal is inside the tooth (closer to the axis)
    prof = ToothProfile.from_gear(gear)
    p, n = flank_points(gear, rho, 0)
    inner = p + 0.3 * gear.module_m * n
    assert np.all(np.abs(inner[:, 0]) < prof.half_thickness_at(inner[:, 1]))


def test_table_shape_and_physics(table):
    j = table.max_offset
    c = table.coefficients_m_per_n
    assert j == 3 and c.shape == (7, table.roll_m.size, table.roll_m.size)
    diag = table.diagonal_m_per_n
    # a load higher up the tooth bends it more
    assert np.all(np.diff(diag) > 0)
    # the coupling to the other teeth is positive (the web twists) and smaller than λ(0)
    for d in range(1, j + 1):
        assert np.all(c[j + d] > 0) and np.all(c[j - d] > 0)
        assert np.max(c[j + d].diagonal() / diag) < 0.5
    # ... and it decreases with the tooth offset
    assert np.all(c[j + 1].diagonal() > c[j + 2].diagonal())
    assert np.all(c[j + 2].diagonal() > c[j + 3].diagonal())


def test_maxwell_betti_reciprocity(table):
    assert table.reciprocity_error() < 2e-3


def test_point_and_hertz_loads_give_the_same_lambda(gear, body, table):
    rho = table.roll_m[[5, 35, 65]]
    point = compute_influence_table(body, rho, table.depth_m, max_offset=1)
    assert np.allclose(point.diagonal_m_per_n, table.diagonal_m_per_n[[5, 35, 65]],
                       rtol=1e-10, atol=0)
    for a, tol in ((0.05e-3, 2e-3), (0.2e-3, 1e-2)):
        hertz = compute_influence_table(body, rho, table.depth_m, max_offset=1, load="hertz",
                                        hertz_half_width_m=a)
        rel = hertz.coefficients_m_per_n / point.coefficients_m_per_n - 1
        assert np.max(np.abs(rel)) < tol


def test_total_compliance_hardly_depends_on_depth(gear, body, table):
    """λ(h) + local(h) for h = 0.1 … 0.4 m changes by < 2 % (the split is consistent)."""
    rho = table.roll_m[[5, 35, 65]]
    force = 1000.0
    e_star = contact_modulus(gear.youngs_modulus_pa, gear.poisson_ratio,
                             gear.youngs_modulus_pa, gear.poisson_ratio)
    a = hertz_half_width(force, rho, rho, gear.face_width_m, e_star)
    totals, fe = [], []
    for h in (0.1, 0.2, 0.4):
        depth = h * gear.module_m
        t = compute_influence_table(body, rho, depth, max_offset=0)
        local = local_approach(force, a, depth, gear.youngs_modulus_pa, gear.poisson_ratio,
                               gear.face_width_m) / force
        totals.append(t.diagonal_m_per_n + local)
        fe.append(t.diagonal_m_per_n)
    totals, fe = np.array(totals), np.array(fe)
    assert np.max(np.abs(totals / totals[1] - 1)) < 0.02
    # while the FE part alone moves by much more (the ln h that the local term takes over)
    assert np.min(np.abs(fe[0] / fe[2] - 1)) > 0.05


def test_coefficient_lookup(table):
    r = table.roll_m
    j = table.max_offset
    assert math.isclose(table.coefficient(0, r[7], r[20]), table.diagonal_m_per_n[7],
                        rel_tol=1e-14)
    assert math.isclose(table.coefficient(2, r[7], r[20]),
                        table.coefficients_m_per_n[j + 2, 7, 20], rel_tol=1e-14)
    mid = 0.5 * (r[7] + r[8])
    expect = 0.5 * (table.coefficients_m_per_n[j - 1, 7, 20]
                    + table.coefficients_m_per_n[j - 1, 8, 20])
    assert math.isclose(table.coefficient(-1, mid, r[20]), expect, rel_tol=1e-12)
    assert table.coefficient(j + 1, r[3], r[3]) == 0.0
    # clamped outside the grid
    assert math.isclose(table.coefficient(0, r[0] - 1e-3, 0.0), table.diagonal_m_per_n[0],
                        rel_tol=1e-14)


def test_second_request_reads_the_cache(gear, table, monkeypatch):
    assert table.meta["cache"] in ("miss", "hit")

    def boom(*args, **kwargs):
        raise AssertionError("the FE model was rebuilt instead of read from the cache")

    monkeypatch.setattr(GearBodyModel, "from_gear", boom)
    again = influence_table(gear)
    assert again.meta["cache"] == "hit"
    assert np.array_equal(again.coefficients_m_per_n, table.coefficients_m_per_n)
    assert again.meta["key"] == table.meta["key"]
    # nothing half-written is left beside the entry
    leftovers = [p for p in os.listdir(cache.cache_dir()) if p.endswith(".tmp")]
    assert leftovers == []


def test_cache_key_follows_inputs(gear):
    from dataclasses import replace

    from cmsim.mesh_stiffness.influence import _gear_inputs
    base = {"gear": _gear_inputs(gear), "depth_m": 1e-4}
    k0 = cache.cache_key("influence", base)
    assert cache.cache_key("influence", dict(base)) == k0
    stiffer = {"gear": _gear_inputs(replace(gear, youngs_modulus_pa=2.0e11)), "depth_m": 1e-4}
    assert cache.cache_key("influence", stiffer) != k0
    heavier = {"gear": _gear_inputs(replace(gear, mass_kg=2.0)), "depth_m": 1e-4}
    assert cache.cache_key("influence", heavier) == k0          # mass does not change λ
    assert cache.cache_key("influence", dict(base, depth_m=1.1e-4)) != k0
    with pytest.raises(ParameterError):
        cache.cache_key("influence", {"x": float("nan")})


def test_cache_round_trip_and_atomic_write(tmp_path, monkeypatch):
    monkeypatch.setenv("CMSIM_CACHE_DIR", str(tmp_path / "c"))
    assert cache.load_entry("t", "k") is None
    path = cache.save_entry("t", "k", {"a": np.arange(3.0)}, {"x": 1})
    assert path.parent == tmp_path / "c"
    arrays, meta = cache.load_entry("t", "k")
    assert np.array_equal(arrays["a"], np.arange(3.0)) and meta == {"x": 1}
    # a write that fails half-way leaves the old entry intact and no temporary file
    import cmsim._io

    def half_write(fh, **arrays):
        fh.write(b"PK partial")
        raise OSError("disk full")

    monkeypatch.setattr(cmsim._io.np, "savez", half_write)
    with pytest.raises(OSError, match="disk full"):
        cache.save_entry("t", "k", {"a": np.arange(5.0)}, {"x": 2})
    monkeypatch.undo()
    monkeypatch.setenv("CMSIM_CACHE_DIR", str(tmp_path / "c"))
    assert sorted(os.listdir(tmp_path / "c")) == ["t-k.npz"]
    arrays, meta = cache.load_entry("t", "k")
    assert np.array_equal(arrays["a"], np.arange(3.0)) and meta == {"x": 1}
    # a corrupt entry reads as a miss
    (tmp_path / "c" / "t-z.npz").write_bytes(b"not an npz")
    assert cache.load_entry("t", "z") is None


def test_cache_dir_default(monkeypatch):
    monkeypatch.delenv("CMSIM_CACHE_DIR", raising=False)
    assert cache.cache_dir() == cache.Path.home() / ".cache" / "cmsim"


def test_table_validation(table):
    with pytest.raises(ParameterError, match="uniform"):
        InfluenceTable(np.array([0.0, 1.0, 3.0]), np.zeros((1, 3, 3)), 1e-4, 2e11, 0.3, 0.01)
    with pytest.raises(ParameterError, match="shape"):
        InfluenceTable(np.array([0.0, 1.0]), np.zeros((2, 2, 2)), 1e-4, 2e11, 0.3, 0.01)
    with pytest.raises(ParameterError, match="body"):
        influence_table(Rig.paper_2016().gears.driving, spec=MeshSpec().scaled(2.0),
                        use_cache=False, body=object())


def test_a_cache_miss_says_what_it_builds_on_stderr(gear, body, monkeypatch, capsys):
    """The FE build (≈ 10-50 s, once per design or crack) announces its stages on stderr:
    the body (mesh, assembly, factorisation) and the influence solve, each with its time
    (issue 28); nothing on stdout. The body is the fixture's, so nothing is re-meshed."""
    monkeypatch.setattr(GearBodyModel, "from_gear", classmethod(lambda cls, *a, **k: body))
    influence_table(gear, use_cache=False, max_offset=1)
    cap = capsys.readouterr()
    assert cap.out == ""
    lines = cap.err.splitlines()
    assert lines[0] == (f"cmsim: FE body of the {gear.n_teeth}-tooth gear: meshing, "
                        f"assembling, factorising...")
    assert any(": influence coefficients, " in line and ": done in " in line for line in lines)
    assert len(lines) == 4
