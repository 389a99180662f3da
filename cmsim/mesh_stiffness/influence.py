"""Flexibility influence coefficients λ of a gear body from the FE model (hybrid method).

λ_ik is the displacement, along the inward flank normal, of the point at depth ``h`` below
flank point i when a unit normal force acts at flank point k (paper 001 eq. 2; Vedmar &
Andersson [1]). The displacement between the flank point itself and that depth point is the
analytical local term (:mod:`cmsim.mesh_stiffness.local_deflection`), so the FE mesh never
has to resolve the Hertz contact.

Table layout
------------
Flank points are parameterised by their roll length ρ = sqrt(r² − r_b²) (the involute's
radius of curvature), on a uniform grid from the form radius to the start of the tip
rounding. The load acts on the right flank of tooth 0; the response is measured on the right
flanks of teeth ``d = −J..J`` (``d > 0``: in the direction the loaded flank faces, see
:mod:`cmsim.mesh_stiffness.fe_mesh`). By the gear's rotational symmetry λ depends only on
the tooth offset ``d = j_i − j_k`` of the two points, so one FE solve per load position
fills ``coefficients_m_per_n[J + d, a, b]`` (response at ρ_a on tooth d, load at ρ_b on
tooth 0).

Choices (defaults)
------------------
* ``max_offset`` J = 3: the paper pair has a contact ratio of 1.6 and at most 3 potential
  contacts (:func:`~cmsim.mesh_stiffness.contact.potential_slots`), so offsets ±2 are what
  it uses; ±3 covers a fourth contact (reduced centre distance, higher contact ratios).
  The coupling does not vanish with distance: with the bore clamped, a load on one tooth
  twists the web and turns every tooth, so λ(±3) is still ≈ 20 % of λ(0) for the paper
  gear. Offsets beyond J give 0; they never occur with <= J + 1 simultaneous contacts.
* depth h = 0.15 m: well above the Hertz half-width (a ≲ 0.2 mm at 100 N·m for the paper
  gear) and the finest elements (0.02 m), well below the tooth thickness (>= 0.7 m at the
  tip-rounding start), so the half-plane assumption of the local term holds. With the
  plane-strain body, the total compliance (FE at depth h + local term) changes by about 1 %
  when h goes from 0.1 m to 0.4 m, the residue of the flank curvature (O(h/ρ)) and of the
  point load (O((a/h)²)); with a plane-stress body about twice as much.
* loads are **point loads** (consistent nodal forces of a Dirac load just inside the flank);
  ``load="hertz"`` spreads it as an elliptic pressure of given half-width instead. At depth
  h the two differ by O((a/h)²): 0.1 % for a = 0.05 mm and 0.7 % for a = 0.2 mm (tested).

References
----------
.. [1] L. Vedmar, A. Andersson, "A method to determine dynamic loads on spur gear teeth and
   on bearings", J. Sound Vib. 267 (2003) 1065-1084.
.. [2] A. Fernandez-del-Rincon et al., MSSP 2016 (paper 001), §3 and eq. 2.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from cmsim.errors import ParameterError, check_choice, check_range, check_type
from cmsim.mesh_stiffness import cache
from cmsim.mesh_stiffness.fe_mesh import MeshSpec, tooth_rotation_rad
from cmsim.mesh_stiffness.fe_model import PLANE_MODES, GearBodyModel
from cmsim.mesh_stiffness.geometry import ToothProfile
from cmsim.mesh_stiffness.root_crack import RootCrack
from cmsim.progress import stage
from cmsim.rig import SpurGear

__all__ = ["InfluenceTable", "influence_table", "compute_influence_table", "flank_points",
           "roll_range_m", "LOAD_MODES", "DEFAULT_DEPTH_MODULES", "INFLUENCE_FORMAT_VERSION"]

#: How the unit force is applied in the FE model.
LOAD_MODES = ("point", "hertz")
#: Default depth h of the measuring points, in modules.
DEFAULT_DEPTH_MODULES = 0.15
#: Default roll-grid spacing, in modules.
DEFAULT_ROLL_STEP_MODULES = 0.08
#: Bumped whenever the computation changes what a cached table contains.
INFLUENCE_FORMAT_VERSION = 1
#: Load points sit this far inside the flank (fraction of the finest element size), so that
#: they fall inside an element although boundary facets are chords of the curved flank.
_LOAD_INSET = 0.1


def roll_range_m(gear):
    """(ρ_form, ρ_tip-rounding start): roll lengths bounding the involute flank, m."""
    prof = ToothProfile.from_gear(gear)
    rb = gear.base_radius_m
    return (math.sqrt(prof.form_radius_m ** 2 - rb ** 2),
            math.sqrt(prof.tip_round_start_radius_m ** 2 - rb ** 2))


def flank_points(gear, roll_m, offset=0):
    """Points of the right involute flank of tooth ``offset`` and their inward normals.

    In the frame of :mod:`~cmsim.mesh_stiffness.fe_mesh` (tooth 0 on +y, polar angles θ
    measured clockwise from +y) the normal through the flank point at roll ρ touches the base
    circle at θ_T = ψ_b − ρ/r_b; the point is T + ρ t and the inward normal −t, with
    t = (cos θ_T, −sin θ_T) the clockwise tangent of the base circle at T.

    Parameters
    ----------
    gear : SpurGear
    roll_m : array_like, shape (n,)
        Roll lengths ρ, m.
    offset : int
        Tooth offset j.

    Returns
    -------
    points_m : ndarray, shape (n, 2)
    inward_normals : ndarray, shape (n, 2)
    """
    rho = np.atleast_1d(np.asarray(roll_m, dtype=float))
    rb = gear.base_radius_m
    th = gear.base_half_thickness_angle_rad - rho / rb
    c, s = np.cos(th), np.sin(th)
    pts = np.column_stack([rb * s + rho * c, rb * c - rho * s])
    nrm = np.column_stack([-c, s])
    a = tooth_rotation_rad(gear, offset)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return pts @ rot.T, nrm @ rot.T


@dataclass(frozen=True, eq=False)
class InfluenceTable:
    """Influence coefficients of one gear design (per unit normal force, m/N).

    Attributes
    ----------
    roll_m : ndarray, shape (n,)
        Uniform grid of roll lengths ρ, m.
    coefficients_m_per_n : ndarray, shape (2J + 1, n, n)
        ``[J + d, a, b]``: inward-normal displacement of the depth-h point below ρ_a on tooth
        d per newton of normal load at ρ_b on tooth 0, m/N.
    depth_m : float
        Depth h of the measuring points, m.
    youngs_modulus_pa, poisson_ratio, face_width_m : float
        Material and face width of the gear (for the local term).
    meta : dict
        Inputs, timings and FE statistics.
    """

    roll_m: np.ndarray = field(repr=False)
    coefficients_m_per_n: np.ndarray = field(repr=False)
    depth_m: float
    youngs_modulus_pa: float
    poisson_ratio: float
    face_width_m: float
    meta: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        r = np.ascontiguousarray(self.roll_m, dtype=float)
        c = np.ascontiguousarray(self.coefficients_m_per_n, dtype=float)
        if r.ndim != 1 or r.size < 2 or np.any(np.diff(r) <= 0):
            raise ParameterError("roll_m must be an increasing 1-D grid of >= 2 points")
        if np.ptp(np.diff(r)) > 1e-9 * (r[1] - r[0]):
            raise ParameterError("roll_m must be uniform")
        if c.ndim != 3 or c.shape[1:] != (r.size, r.size) or c.shape[0] % 2 != 1:
            raise ParameterError("coefficients_m_per_n must have shape (2J+1, n, n)")
        if not np.all(np.isfinite(c)):
            raise ParameterError("coefficients_m_per_n must be finite")
        for name, arr in (("roll_m", r), ("coefficients_m_per_n", c)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def max_offset(self):
        """J: the largest tooth offset tabulated."""
        return (self.coefficients_m_per_n.shape[0] - 1) // 2

    @property
    def diagonal_m_per_n(self):
        """λ(ρ, ρ) on the same tooth, m/N, shape (n,)."""
        j = self.max_offset
        return np.ascontiguousarray(np.diagonal(self.coefficients_m_per_n[j]))

    def coefficient(self, offset, roll_i_m, roll_k_m):
        """λ for a response at ρ_i on tooth ``offset`` and a load at ρ_k on tooth 0, m/N.

        Same tooth (``offset == 0``): linear interpolation of :attr:`diagonal_m_per_n` at ρ_i
        (only one contact per tooth exists). Other teeth: bilinear in (ρ_i, ρ_k). Rolls are
        clamped to the grid; offsets beyond J give 0.
        """
        j = int(offset)
        if abs(j) > self.max_offset:
            return 0.0
        r = self.roll_m
        if j == 0:
            return float(np.interp(roll_i_m, r, self.diagonal_m_per_n))
        tab = self.coefficients_m_per_n[self.max_offset + j]
        ui = _grid_pos(roll_i_m, r)
        uk = _grid_pos(roll_k_m, r)
        i0, k0 = min(int(ui), r.size - 2), min(int(uk), r.size - 2)
        fi, fk = ui - i0, uk - k0
        return float((1 - fi) * ((1 - fk) * tab[i0, k0] + fk * tab[i0, k0 + 1])
                     + fi * ((1 - fk) * tab[i0 + 1, k0] + fk * tab[i0 + 1, k0 + 1]))

    def reciprocity_error(self):
        """Largest |λ(d, a, b) − λ(−d, b, a)| over d ≠ 0, relative to max λ(0) (Betti check)."""
        c, j = self.coefficients_m_per_n, self.max_offset
        worst = 0.0
        for d in range(1, j + 1):
            worst = max(worst, float(np.max(np.abs(c[j + d] - c[j - d].T))))
        return worst / float(np.max(self.diagonal_m_per_n))


def _grid_pos(x, grid):
    u = (float(x) - grid[0]) / (grid[1] - grid[0])
    return min(max(u, 0.0), grid.size - 1.0)


def _hertz_load_vectors(model, points, directions, half_width):
    """Load vectors of unit elliptic pressures of half-width ``a`` centred at ``points``."""
    from skfem import FacetBasis, Functional, LinearForm, asm

    mesh = model.mesh
    bf = mesh.boundary_facets()
    mid = mesh.p[:, mesh.facets[:, bf]].mean(axis=1).T
    flen = np.linalg.norm(mesh.p[:, mesh.facets[0, bf]] - mesh.p[:, mesh.facets[1, bf]],
                          axis=0)
    out = np.zeros((model.n_dofs, points.shape[0]))
    for k, (pc, dc) in enumerate(zip(points, directions)):
        sel = bf[np.linalg.norm(mid - pc, axis=1) < half_width + flen]
        fb = FacetBasis(mesh, model.basis.elem, facets=sel, intorder=16)

        def pressure(x, pc=pc):
            r2 = ((x[0] - pc[0]) ** 2 + (x[1] - pc[1]) ** 2) / half_width ** 2
            return np.sqrt(np.maximum(1.0 - r2, 0.0))

        @LinearForm
        def traction(v, w, dc=dc, pressure=pressure):
            return pressure(w.x) * (dc[0] * v[0] + dc[1] * v[1])

        @Functional
        def resultant(w, pressure=pressure):
            return pressure(w.x)

        vec = asm(traction, fb)
        total = asm(resultant, fb)
        out[:, k] = vec / total
    return out


def compute_influence_table(body, roll_m, depth_m, max_offset=3, load="point",
                            hertz_half_width_m=None):
    """Influence coefficients from an assembled gear-body model (no caching).

    Parameters
    ----------
    body : GearBodyModel
    roll_m : ndarray, shape (n,)
        Uniform roll grid within the involute flank, m.
    depth_m : float
        h, m.
    max_offset : int
        J >= 0.
    load : {'point', 'hertz'}
    hertz_half_width_m : float, optional
        Half-width of the pressure for ``load="hertz"``, m.

    Returns
    -------
    InfluenceTable
    """
    check_type("body", body, GearBodyModel)
    check_choice("load", load, LOAD_MODES)
    gear, model = body.gear, body.model
    h = check_range("depth_m", depth_m, 0.0, 2.0 * gear.module_m, lo_open=True, unit="m")
    if isinstance(max_offset, bool) or not isinstance(max_offset, (int, np.integer)) \
            or not 0 <= max_offset < gear.n_teeth // 2:
        raise ParameterError(f"max_offset must be an integer in [0, Z/2), got {max_offset!r}")
    rho = np.asarray(roll_m, dtype=float)
    t0 = time.perf_counter()
    pts, nrm = flank_points(gear, rho, 0)
    if load == "point":
        inset = _LOAD_INSET * body.gear_mesh.spec.h_flank * gear.module_m
        loads = model.point_load_vectors(pts + inset * nrm, nrm)
    else:
        a = check_range("hertz_half_width_m", hertz_half_width_m, 0.0, h, lo_open=True,
                        unit="m")
        loads = _hertz_load_vectors(model, pts, nrm, a)
    disp = model.solve(loads)
    offsets = np.arange(-max_offset, max_offset + 1)
    probe_pts, probe_nrm = [], []
    for d in offsets:
        p, n = flank_points(gear, rho, int(d))
        probe_pts.append(p + h * n)
        probe_nrm.append(n)
    probe_pts = np.concatenate(probe_pts)
    probe_nrm = np.concatenate(probe_nrm)
    u = model.probe(probe_pts) @ disp                       # (2 m, n_load)
    m = probe_pts.shape[0]
    lam = u[:m] * probe_nrm[:, :1] + u[m:] * probe_nrm[:, 1:]
    coeff = lam.reshape(offsets.size, rho.size, rho.size)
    meta = {"depth_m": h, "load": load, "hertz_half_width_m": hertz_half_width_m,
            "plane": model.plane, "mesh_spec": body.gear_mesh.spec.as_dict(),
            "n_dofs": model.n_dofs, "n_triangles": body.gear_mesh.n_triangles,
            "crack": None if body.gear_mesh.crack is None else body.gear_mesh.crack.as_dict(),
            "mesh_seconds": body.mesh_seconds, "factor_seconds": model.factor_seconds,
            "solve_seconds": time.perf_counter() - t0}
    return InfluenceTable(roll_m=rho, coefficients_m_per_n=coeff, depth_m=h,
                          youngs_modulus_pa=gear.youngs_modulus_pa,
                          poisson_ratio=gear.poisson_ratio, face_width_m=gear.face_width_m,
                          meta=meta)


def _gear_inputs(gear):
    """The SpurGear fields that change the FE result (not mass or inertia)."""
    keys = ("n_teeth", "module_m", "face_width_m", "pressure_angle_rad", "profile_shift",
            "rack_addendum_coef", "rack_dedendum_coef", "rack_tip_radius_coef",
            "tip_radius_coef", "bore_radius_m", "youngs_modulus_pa", "poisson_ratio")
    return {k: getattr(gear, k) for k in keys}


def influence_table(gear, depth_m=None, spec=MeshSpec(), plane="strain", roll_step_m=None,
                    max_offset=3, load="point", hertz_half_width_m=None, use_cache=True,
                    body=None, crack=None):
    """Influence coefficients of ``gear``, computed once per design and cached on disk.

    Parameters
    ----------
    gear : SpurGear
    depth_m : float, optional
        h, m (default :data:`DEFAULT_DEPTH_MODULES` modules).
    spec : MeshSpec
        FE mesh sizes.
    plane : {'stress', 'strain'}
        2-D idealisation of the body (:mod:`cmsim.mesh_stiffness.fe_model`).
    roll_step_m : float, optional
        Target roll-grid spacing, m (default :data:`DEFAULT_ROLL_STEP_MODULES` modules);
        the grid spans :func:`roll_range_m` uniformly.
    max_offset : int
        J, tooth offsets −J..J (module docstring).
    load : {'point', 'hertz'}
    hertz_half_width_m : float, optional
        For ``load="hertz"``.
    use_cache : bool
        Read and write the cache (:mod:`cmsim.mesh_stiffness.cache`).
    body : GearBodyModel, optional
        An already assembled model of ``gear`` with ``spec``, ``plane`` and ``crack`` to use
        on a cache miss (saves the mesh generation and factorisation).
    crack : RootCrack, optional
        A root crack cut into the loaded tooth 0 (:mod:`~cmsim.mesh_stiffness.root_crack`):
        the table then holds the cracked tooth's own coefficients (offset 0) and its
        coupling to the healthy teeth ±1..±J (load on the cracked tooth). Part of the
        cache key.

    Returns
    -------
    InfluenceTable
        ``meta["cache"]`` is ``"hit"``, ``"miss"`` or ``"off"``.
    """
    check_type("gear", gear, SpurGear)
    check_choice("plane", plane, PLANE_MODES)
    m = gear.module_m
    h = DEFAULT_DEPTH_MODULES * m if depth_m is None else depth_m
    step = DEFAULT_ROLL_STEP_MODULES * m if roll_step_m is None else roll_step_m
    step = check_range("roll_step_m", step, 1e-3 * m, m, unit="m")
    lo, hi = roll_range_m(gear)
    rho = np.linspace(lo, hi, int(math.ceil((hi - lo) / step)) + 1)
    inputs = {"version": INFLUENCE_FORMAT_VERSION, "gear": _gear_inputs(gear),
              "depth_m": float(h), "spec": spec.as_dict(), "plane": plane,
              "roll_m": [float(rho[0]), float(rho[-1]), int(rho.size)],
              "max_offset": int(max_offset), "load": load,
              "hertz_half_width_m": hertz_half_width_m}
    if crack is not None:
        check_type("crack", crack, RootCrack)
        inputs["crack"] = crack.as_dict()
    key = cache.cache_key("influence", inputs)
    if use_cache:
        hit = cache.load_entry("influence", key)
        if hit is not None:
            arrays, meta = hit
            meta = dict(meta, cache="hit")
            return InfluenceTable(roll_m=arrays["roll_m"],
                                  coefficients_m_per_n=arrays["coefficients_m_per_n"],
                                  depth_m=meta["depth_m"],
                                  youngs_modulus_pa=gear.youngs_modulus_pa,
                                  poisson_ratio=gear.poisson_ratio,
                                  face_width_m=gear.face_width_m, meta=meta)
    t0 = time.perf_counter()
    what = f"FE body of the {gear.n_teeth}-tooth gear" + (
        "" if crack is None else f" with a {crack.depth_m * 1e3:.3g} mm root crack")
    if body is None:
        with stage(f"{what}: meshing, assembling, factorising"
                   + (" (once: the table is cached)" if use_cache else "")):
            body = GearBodyModel.from_gear(gear, spec, plane, crack)
    elif (not isinstance(body, GearBodyModel) or body.gear != gear
          or body.gear_mesh.spec != spec or body.model.plane != plane
          or body.gear_mesh.crack != crack):
        raise ParameterError("body must be a GearBodyModel of this gear, spec, plane and "
                             "crack")
    with stage(f"{what}: influence coefficients, {rho.size} loads"):
        table = compute_influence_table(body, rho, h, max_offset, load, hertz_half_width_m)
    meta = dict(table.meta, build_seconds=time.perf_counter() - t0, key=key,
                cache="miss" if use_cache else "off")
    if use_cache:
        cache.save_entry("influence", key, {"roll_m": table.roll_m,
                                            "coefficients_m_per_n": table.coefficients_m_per_n},
                         dict(meta, cache="stored"))
    return replace(table, meta=meta)
