"""Triangle mesh of a whole spur gear body, graded towards the loaded flanks.

The body runs from the bore to the rack-generated tooth outlines of all ``Z`` teeth
(:class:`~cmsim.mesh_stiffness.geometry.ToothProfile`, rotated copies). Tooth 0 has its
centreline on +y; teeth are numbered by their *offset* ``j`` in the direction its right flank
faces (clockwise, towards +x), so tooth ``j`` has its centreline at the polar angle
``π/2 − j·2π/Z``. The right flank of every tooth is the one that gets loaded.

Mesh generator
--------------
No mesh generator ships with scikit-fem, and the maintained constrained-Delaunay packages
(Triangle, via ``triangle``/``meshpy``; Gmsh) carry licences (non-commercial, GPL) that do not
sit with an MIT package, so the mesh is made here with the force-equilibrium smoothing of
Persson & Strang [1] ("DistMesh", :mod:`cmsim.mesh_stiffness.distmesh`) on top of
:func:`scipy.spatial.Delaunay`:

* the boundary (gear outline and bore circle) is sampled at the local target size ``h(x)``
  and these points are fixed, so every boundary node lies exactly on the true curve;
* interior points start on layers parallel to the outline, each ``(√3/2)·h`` inside the
  previous one and sampled at spacing ``h`` with alternating half-step phase (nearly
  equilateral triangles from the start), until the size reaches ``h_body``; a hexagonal
  lattice of size ``h_body`` fills the web; points closer than ``0.75·h`` to an accepted one
  are dropped. They are then moved by the repulsive bar forces of [1] (at most
  ``max_iterations`` steps; points pushed out of the body are dropped);
* triangles whose centroid is outside the body (signed distance from the folded tooth
  outline and the bore) are dropped, and the result is checked: one closed loop of boundary
  facets per curve through every boundary point, all triangles positively oriented.

The target size is ``h(x) = min_s(h_s + g·dist(x, S_s))`` over sources ``S_s``: the active
flank of tooth 0 (``h_flank``), the active flanks of the neighbouring teeth (``h_neighbour``),
all outlines (``h_tooth``), capped by ``h_body``; ``g`` is the growth rate. Everything is
deterministic (no random numbers). The paper gear's default mesh (≈ 8 800 nodes, 15 500
triangles, smallest angle ≈ 22°) takes ≈ 8 s.

Root crack
----------
:class:`~cmsim.mesh_stiffness.root_crack.RootCrack` cuts a straight root crack into tooth 0
(mouth at the loaded fillet's 30° tangent point, angle ν, length q, as
:mod:`cmsim.faults.crack`): its nodes (spacing ``h_crack``, mesh refined to ``h_crack``
along it and half of it at the tip) are fixed points of the DistMesh smoothing, the mouth
replaces the nearest outline node, free points inside the diametral circle of a crack
segment are dropped (so every segment is a Delaunay edge), and after triangulation every
crack node but the tip is duplicated and the triangles on the tooth-tip side of the crack
are renumbered to the duplicates (traction-free faces; contact of the faces when the crack
closes is not modelled). The crack is checked: every segment is an edge, both faces are
chains of boundary facets, no triangle touches both faces.

gmsh
----
Decision: cmsim keeps this in-house mesher as its only mesher and does not depend on gmsh.
Measured side by side (``benchmarks/bench_mesher.py``, gmsh 4.15.2 from PyPI in a separate
environment, the same outline and the same size function rebuilt from gmsh's distance
fields, sizes scaled so the triangle counts match within 0.4 %; best of 3, interleaved, on a
loaded machine — compare ratios):

===================  =======  ======  =========  =========  ===============
mesher, case         time, s  nodes   triangles  min angle  minSICN (mean)
===================  =======  ======  =========  =========  ===============
in-house, healthy    9.31     8 774   15 516     21.8°      0.557 (0.957)
gmsh, healthy        0.51     8 660   15 576     31.4°      0.699 (0.969)
in-house, cracked    17.88    9 046   16 006     22.1°      0.517 (0.957)
gmsh, cracked        0.49     8 929   16 060     28.8°      0.623 (0.969)
===================  =======  ======  =========  =========  ===============

gmsh is 18× (healthy) to 37× (cracked) faster with better-shaped triangles, and its
``Crack`` plugin gives faces that scikit-fem uses as they are (every crack segment a
boundary facet on both faces, faces sharing only the tip). The crack roughly doubles the
in-house mesh time. Still the in-house mesher stays: gmsh is GPL-2+ (its only exception
covers Netgen, METIS, OpenCASCADE and ParaView, not a package importing it), which would
encumber this MIT package, and every mesh is built once per gear design or crack and then
cached (:mod:`cmsim.mesh_stiffness.cache`), so the 9-18 s are paid once. Earlier
measurement of the whole influence build (mesh + assembly/factorisation + 40 load cases):
healthy 29.4 s, cracked bodies (q/q_max = 0.02 … 1) 22.5 - 30.1 s on the same loaded cores;
the mesh is ≈ 75 % of a build.

All lengths in m.

References
----------
.. [1] P.-O. Persson, G. Strang, "A simple mesh generator in MATLAB", SIAM Review 46 (2004)
   329-345.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.spatial import cKDTree

from cmsim.errors import ParameterError, check_range, check_type
from cmsim.mesh_stiffness.distmesh import (check_boundary_loops, distmesh_smooth, hex_lattice,
                                           orient, thin_points, triangulate)
from cmsim.mesh_stiffness.geometry import ToothProfile
from cmsim.mesh_stiffness.root_crack import RootCrack
from cmsim.rig import SpurGear

__all__ = ["MeshSpec", "GearMesh", "gear_mesh", "tooth_rotation_rad"]

@dataclass(frozen=True)
class MeshSpec:
    """Target element sizes of the gear mesh, as fractions of the module.

    Attributes
    ----------
    h_flank : float
        Size on the active flank of the loaded tooth (tooth 0), in modules (0.02).
    h_neighbour : float
        Size on the active flanks of teeth ±1..±``n_neighbours``, in modules (0.05).
    h_tooth : float
        Size on every other part of the outline, in modules (0.1).
    h_body : float
        Largest size (web, bore), in modules (0.35).
    growth : float
        Growth of the size with the distance from a source, dimensionless (0.25).
    n_neighbours : int
        How many teeth on each side of tooth 0 get ``h_neighbour`` on their flank (3).
    max_iterations : int
        DistMesh smoothing iterations at most (40).
    """

    h_flank: float = 0.02
    h_neighbour: float = 0.05
    h_tooth: float = 0.1
    h_body: float = 0.35
    growth: float = 0.25
    n_neighbours: int = 3
    max_iterations: int = 40

    def __post_init__(self):
        check_range("h_flank", self.h_flank, 1e-3, 1.0, lo_open=False, unit="modules")
        check_range("h_neighbour", self.h_neighbour, self.h_flank, 1.0, unit="modules")
        check_range("h_tooth", self.h_tooth, self.h_flank, 1.0, unit="modules")
        check_range("h_body", self.h_body, self.h_tooth, 5.0, unit="modules")
        check_range("growth", self.growth, 0.05, 1.0)
        if not isinstance(self.n_neighbours, (int, np.integer)) or self.n_neighbours < 0:
            raise ParameterError(f"n_neighbours must be an integer >= 0, got {self.n_neighbours!r}")
        if not isinstance(self.max_iterations, (int, np.integer)) or self.max_iterations < 1:
            raise ParameterError(
                f"max_iterations must be an integer >= 1, got {self.max_iterations!r}")

    def scaled(self, factor):
        """Same grading with every size multiplied by ``factor`` (refinement studies)."""
        factor = check_range("factor", factor, 0.1, 10.0)
        return replace(self, h_flank=self.h_flank * factor,
                       h_neighbour=self.h_neighbour * factor, h_tooth=self.h_tooth * factor,
                       h_body=self.h_body * factor)

    def as_dict(self):
        """Plain dict of the fields (for cache keys and provenance)."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


@dataclass(frozen=True, eq=False)
class GearMesh:
    """A triangulated gear body.

    Attributes
    ----------
    points_m : ndarray, shape (n_points, 2)
        Node coordinates, m (gear centre at the origin, tooth 0 on +y).
    triangles : ndarray of int, shape (n_triangles, 3)
        Counter-clockwise node indices.
    bore_nodes : ndarray of int, shape (n_bore,)
        Nodes on the bore circle.
    profile : ToothProfile
        The tooth outline the mesh was built from.
    spec : MeshSpec
        The size specification.
    crack : RootCrack or None
        The root crack cut into tooth 0, if any.
    crack_nodes : ndarray of int, shape (n_crack + 1,) or None
        Nodes of one crack face (the side towards the gear centre), from the mouth on the
        fillet to the tip.
    crack_twin_nodes : ndarray of int, shape (n_crack,) or None
        Their duplicates on the other face (towards the tooth tip), mouth first; the tip
        node is shared.
    """

    points_m: np.ndarray = field(repr=False)
    triangles: np.ndarray = field(repr=False)
    bore_nodes: np.ndarray = field(repr=False)
    profile: ToothProfile = field(repr=False)
    spec: MeshSpec
    crack: "RootCrack | None" = None
    crack_nodes: np.ndarray = field(default=None, repr=False)
    crack_twin_nodes: np.ndarray = field(default=None, repr=False)

    @property
    def n_points(self):
        """Number of nodes."""
        return self.points_m.shape[0]

    @property
    def n_triangles(self):
        """Number of triangles."""
        return self.triangles.shape[0]

    def min_angle_deg(self):
        """Smallest interior angle of any triangle, degrees."""
        p = self.points_m[self.triangles]
        angles = []
        for k in range(3):
            a = p[:, (k + 1) % 3] - p[:, k]
            b = p[:, (k + 2) % 3] - p[:, k]
            cosang = np.sum(a * b, axis=1) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
            angles.append(np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0))))
        return float(np.min(angles))

    def to_skfem(self):
        """The mesh as :class:`skfem.MeshTri` with the boundary ``"bore"`` tagged."""
        from skfem import MeshTri
        r_bore = self.profile.gear.bore_radius_m
        tol = 1e-9 * r_bore
        mesh = MeshTri(np.ascontiguousarray(self.points_m.T),
                       np.ascontiguousarray(self.triangles.T))
        return mesh.with_boundaries(
            {"bore": lambda x: np.hypot(x[0], x[1]) < r_bore + tol})


def tooth_rotation_rad(gear, offset):
    """Rotation (counter-clockwise, rad) that carries tooth 0 onto tooth ``offset``.

    Tooth ``j`` sits in the direction tooth 0's right flank faces (clockwise), so the
    rotation is ``−j·2π/Z``.
    """
    return -offset * 2.0 * math.pi / gear.n_teeth


def _rotate(points, angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.column_stack([c * points[:, 0] - s * points[:, 1],
                            s * points[:, 0] + c * points[:, 1]])


def _densify(points, spacing):
    """Linear resampling of a polyline so that no segment exceeds ``spacing``."""
    seg = np.diff(points, axis=0)
    lengths = np.hypot(seg[:, 0], seg[:, 1])
    out = [points[:1]]
    for k in range(seg.shape[0]):
        n = max(1, int(math.ceil(lengths[k] / spacing)))
        t = (np.arange(1, n + 1) / n)[:, None]
        out.append(points[k] + t * seg[k])
    return np.concatenate(out)


def active_flank_points(profile, spacing):
    """Dense points of the right involute of tooth 0 (form radius to tip-rounding start), m."""
    pts = profile.segment("involute", "right")
    return _densify(pts, spacing)


class _CurveDistance:
    """Distance to a densely sampled curve with two k-d trees (internal).

    A k-d tree over a finely sampled curve is slow for far query points (many samples sit
    at nearly the same distance), so far points use a tree over every ``stride``-th sample;
    the nearest-sample error there is below ``(stride·spacing)² / (8·d)``.
    """

    def __init__(self, points, spacing, stride=16):
        self.points = points
        self.fine = cKDTree(points)
        self.stride = stride
        self.coarse = cKDTree(points[::stride])
        self.switch = 4.0 * stride * spacing

    def query(self, q, upper=np.inf):
        """(distance, index of the nearest sample); ``inf`` and 0 beyond ``upper``."""
        dist, idx = self.coarse.query(q, distance_upper_bound=upper)
        idx = np.where(np.isfinite(dist), idx * self.stride, 0)
        near = dist < self.switch
        if np.any(near):
            d2, i2 = self.fine.query(q[near])
            dist[near], idx[near] = d2, i2
        return dist, np.minimum(idx, self.points.shape[0] - 1)


class _Geometry:
    """Signed distance to the gear body and the target size function (internal)."""

    def __init__(self, gear, profile, spec):
        self.gear, self.profile, self.spec = gear, profile, spec
        m = gear.module_m
        self.pitch = 2.0 * math.pi / gear.n_teeth
        self.r_bore = gear.bore_radius_m
        dense = _densify(profile.points_m, 5e-3 * m)
        tangent = np.gradient(dense, axis=0)
        tangent /= np.linalg.norm(tangent, axis=1)[:, None]
        self.outline = dense
        self.normal = np.column_stack([tangent[:, 1], -tangent[:, 0]])   # outward (CCW loop)
        self.outline_tree = _CurveDistance(dense, 5e-3 * m)
        # size sources: (distance helper, base size, points)
        flank = active_flank_points(profile, 0.25 * spec.h_flank * m)
        neigh = [_rotate(flank, tooth_rotation_rad(gear, j))
                 for j in range(-spec.n_neighbours, spec.n_neighbours + 1) if j != 0]
        spacing = 0.25 * spec.h_flank * m
        self.sources = [(_CurveDistance(flank, spacing), spec.h_flank * m, flank)]
        if neigh:
            neigh = np.concatenate(neigh)
            self.sources.append((_CurveDistance(neigh, spacing), spec.h_neighbour * m, neigh))
        self.h_tooth = spec.h_tooth * m
        self.h_body = spec.h_body * m
        self.g = spec.growth
        #: distances beyond this are not needed exactly (sizes are capped, signs are known)
        self.reach = max(2.0 * m, (self.h_body - self.h_tooth) / self.g)

    def fold(self, p):
        """Rotate points into the sector of tooth 0 (polar angle within ±π/Z of +y)."""
        phi = np.arctan2(p[:, 0], p[:, 1])            # angle from +y, clockwise positive
        k = np.round(phi / self.pitch)
        ang = k * self.pitch                          # rotate back counter-clockwise by k·pitch
        c, s = np.cos(ang), np.sin(ang)
        return np.column_stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1]])

    def distance(self, p):
        """Signed distance to the body boundary, m (negative inside the material).

        Exact within ``self.reach`` of the tooth outlines; farther away only the sign is
        meaningful (inside the tip circle = inside the body), which is all DistMesh needs.
        """
        q = self.fold(p)
        dist, idx = self.outline_tree.query(q, self.reach)
        far = ~np.isfinite(dist)
        sign = np.sign(np.sum((q - self.outline[idx]) * self.normal[idx], axis=1))
        d_out = np.where(sign == 0, 0.0, sign * dist)
        r = np.hypot(p[:, 0], p[:, 1])
        d_out = np.where(far, np.where(r < self.gear.tip_radius_m, -self.reach, self.reach),
                         d_out)
        return np.maximum(d_out, self.r_bore - r)

    def outline_distance(self, p):
        """Unsigned distance to the tooth outlines, m (``inf`` beyond ``self.reach``)."""
        return self.outline_tree.query(self.fold(p), self.reach)[0]

    def size(self, p):
        """Target element size h(x), m."""
        h = np.minimum(self.h_tooth + self.g * self.outline_distance(p), self.h_body)
        for tree, h0, _ in self.sources:
            reach = (self.h_body - h0) / self.g
            h = np.minimum(h, h0 + self.g * tree.query(p, reach)[0])
        return h


def _sample_by_size(curve, h_mid, closed, phase=0.0):
    """Parameters (cumulative index positions) of points spaced h along a polyline."""
    seg = np.hypot(*np.diff(curve, axis=0).T)
    w = np.concatenate([[0.0], np.cumsum(seg / h_mid)])
    n = max(3 if closed else 1, int(round(w[-1])))
    targets = (np.arange(n) + phase) * (w[-1] / n)
    return np.interp(targets, w, np.arange(curve.shape[0], dtype=float))


def _at(curve, u):
    i = np.minimum(np.floor(u).astype(np.int64), curve.shape[0] - 2)
    f = (u - i)[:, None]
    return curve[i] * (1.0 - f) + curve[i + 1] * f


def _outline_loop(gear, profile, spacing):
    """Dense closed outline of all teeth (counter-clockwise) and its outward normals."""
    dense = _densify(profile.points_m, spacing)[:-1]
    loop = np.concatenate([_rotate(dense, -tooth_rotation_rad(gear, k))
                           for k in range(gear.n_teeth)])
    closed = np.vstack([loop, loop[:1]])
    tangent = np.roll(closed, -1, axis=0)[:-1] - np.roll(closed, 1, axis=0)[:-1]
    tangent[0] = closed[1] - loop[-1]
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    return loop, np.column_stack([tangent[:, 1], -tangent[:, 0]])


def _boundary_points(gear, profile, geo):
    """Fixed nodes on the outline (one loop) and on the bore (one loop), m."""
    loop, _ = _outline_loop(gear, profile, 5e-3 * gear.module_m)
    closed = np.vstack([loop, loop[:1]])
    h_mid = geo.size(0.5 * (closed[1:] + closed[:-1]))
    outline = _at(closed, _sample_by_size(closed, h_mid, closed=True))
    n_bore = max(12, int(math.ceil(2 * math.pi * geo.r_bore / geo.h_body)))
    ang = 2 * math.pi * np.arange(n_bore) / n_bore
    bore = geo.r_bore * np.column_stack([np.cos(ang), np.sin(ang)])
    return outline, bore


def _interior_points(gear, profile, geo, fixed):
    """Initial interior points: layers parallel to the outline, then a lattice in the web.

    Each layer lies ``(√3/2)·h`` inside the previous one and is sampled at spacing ``h``
    with a half-step phase shift, which gives nearly equilateral triangles; layers stop
    where the sizes reach ``h_body``. Points closer than ``0.75·h`` to an accepted point are
    dropped.
    """
    loop, normal = _outline_loop(gear, profile, 1e-2 * gear.module_m)
    accepted = [fixed]
    tree = cKDTree(fixed)
    depth = np.zeros(loop.shape[0])
    active = np.ones(loop.shape[0], dtype=bool)
    h_prev = geo.size(loop)
    for layer in range(1, 200):
        depth = depth + 0.5 * math.sqrt(3.0) * h_prev
        curve = loop - depth[:, None] * normal
        # a strand stops where the sizes reach h_body, where it leaves the body, and where
        # it folds behind a convex corner (it is then nearer another part of the outline)
        h_prev = geo.size(curve)
        active &= (h_prev < 0.999 * geo.h_body) & (geo.distance(curve) < -0.5 * h_prev)
        active &= geo.outline_distance(curve) > 0.8 * depth
        if not np.any(active):
            break
        closed = np.vstack([curve, curve[:1]])
        u = _sample_by_size(closed, 0.5 * (h_prev + np.roll(h_prev, -1)), closed=True,
                            phase=0.5 * (layer % 2))
        idx = np.minimum(np.round(u).astype(np.int64), loop.shape[0] - 1)
        cand = _at(closed, u)[active[idx]]
        cand = thin_points(cand, geo.size(cand), tree)
        if cand.size:
            accepted.append(cand)
            tree = cKDTree(np.concatenate(accepted))
    r = gear.tip_radius_m
    lattice = hex_lattice(np.array([-r, -r]), np.array([r, r]), geo.h_body)
    h_l = geo.size(lattice)
    ok = geo.distance(lattice) < -0.5 * h_l
    lattice = thin_points(lattice[ok], h_l[ok], tree)
    accepted.append(lattice)
    return np.concatenate(accepted[1:])


def _clear_crack(p, nf, nodes, geo):
    """Drop free points inside the diametral circle of any crack segment, re-triangulate.

    A segment whose diametral circle holds no other point is an edge of the Delaunay
    triangulation, so afterwards every crack segment is a mesh edge (checked by
    :func:`_cut_crack`).
    """
    mid = 0.5 * (nodes[1:] + nodes[:-1])
    rad = 0.5 * np.hypot(*(nodes[1:] - nodes[:-1]).T)
    d, i = cKDTree(mid).query(p[nf:])
    keep = np.ones(p.shape[0], dtype=bool)
    keep[nf:] = d > 1.15 * rad[i]
    p = p[keep]
    return p, triangulate(p, geo)


def _cut_crack(p, tri, nodes, direction):
    """Split the mesh along the crack: duplicate every crack node but the tip.

    Triangles around a duplicated node that lie on the tooth-tip side of the crack line
    (centroid test) are renumbered to the duplicates, so the two faces share no edge and
    move independently (traction-free faces).

    Returns
    -------
    (points, triangles, twins)
    """
    edges = {tuple(e) for e in np.sort(np.vstack([tri[:, [0, 1]], tri[:, [1, 2]],
                                                  tri[:, [2, 0]]]), axis=1)}
    for a, b in zip(nodes[:-1], nodes[1:]):
        if (min(a, b), max(a, b)) not in edges:
            raise ParameterError("cracked gear mesh failed: a crack segment is not a mesh edge "
                                 "(try another h_crack)")
    split = nodes[:-1]
    twins = p.shape[0] + np.arange(split.size)
    remap = np.arange(p.shape[0] + split.size)
    remap[split] = twins
    centroid = p[tri].mean(axis=1) - p[nodes[0]]
    side = direction[0] * centroid[:, 1] - direction[1] * centroid[:, 0]
    touch = np.isin(tri, split).any(axis=1)
    upper = touch & (side < 0.0)
    tri = tri.copy()
    tri[upper] = remap[tri[upper]]
    return np.vstack([p, p[split]]), tri, twins


def _check_crack_faces(tri, nodes, twins):
    """Raise unless both crack faces are chains of boundary facets sharing only the tip."""
    edges = np.sort(np.vstack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    bnd = {tuple(e) for e in uniq[count == 1]}
    other = np.append(twins, nodes[-1])
    for face in (nodes, other):
        for a, b in zip(face[:-1], face[1:]):
            if (min(a, b), max(a, b)) not in bnd:
                raise ParameterError("cracked gear mesh failed: the crack faces are not "
                                     "boundary facets")
    if np.any(np.isin(tri, nodes[:-1]).any(axis=1) & np.isin(tri, twins).any(axis=1)):
        raise ParameterError("cracked gear mesh failed: a triangle touches both crack faces")


def gear_mesh(gear, spec=MeshSpec(), crack=None):
    """Triangulate the body of ``gear`` from the bore to the tooth outlines.

    Parameters
    ----------
    gear : SpurGear
        The gear (tooth outline from :meth:`ToothProfile.from_gear`, bore radius).
    spec : MeshSpec
        Target sizes.
    crack : RootCrack, optional
        A root crack to cut into tooth 0: its nodes are fixed points of the mesh (the mouth
        on the outline), the mesh is refined around it (``h_crack`` along it, half of it at
        the tip) and the nodes of the faces are duplicated (the tip node is shared).

    Returns
    -------
    GearMesh

    Raises
    ------
    ParameterError
        If ``gear`` is not a SpurGear or the triangulation does not follow the boundary
        (or the crack).
    """
    check_type("gear", gear, SpurGear)
    check_type("spec", spec, MeshSpec)
    if crack is not None:
        check_type("crack", crack, RootCrack)
    profile = ToothProfile.from_gear(gear, n_points=800)
    geo = _Geometry(gear, profile, spec)
    cnodes = np.zeros((0, 2))
    if crack is not None:
        cnodes = crack.nodes_m(profile)
        hc = crack.h_crack * gear.module_m
        dense = _densify(cnodes[[0, -1]], 0.25 * hc)
        geo.sources.append((_CurveDistance(dense, 0.25 * hc), hc, dense))
        geo.sources.append((_CurveDistance(cnodes[-1:], hc), 0.5 * hc, cnodes[-1:]))
    outline, bore = _boundary_points(gear, profile, geo)
    i_mouth = -1
    if crack is not None:              # the mouth replaces the nearest outline node
        i_mouth = int(np.argmin(np.hypot(*(outline - cnodes[0]).T)))
        outline[i_mouth] = cnodes[0]
    fixed = np.vstack([outline, bore, cnodes[1:]])
    interior = _interior_points(gear, profile, geo, fixed)
    p, tri = distmesh_smooth(fixed, interior, geo, spec.max_iterations)
    crack_idx = np.concatenate([[i_mouth], outline.shape[0] + bore.shape[0]
                                + np.arange(cnodes.shape[0] - 1)]).astype(np.int64)
    if crack is not None:
        p, tri = _clear_crack(p, fixed.shape[0], cnodes, geo)
    tri, area2 = orient(p, tri)
    if np.any(area2 <= 1e-12 * geo.h_body ** 2):
        tri = tri[area2 > 1e-12 * geo.h_body ** 2]
    used = check_boundary_loops(tri, outline.shape[0], bore.shape[0], p.shape[0])
    # renumber without unused interior points
    new = -np.ones(p.shape[0], dtype=np.int64)
    new[used] = np.arange(np.count_nonzero(used))
    p, tri = p[used], new[tri]
    bore_nodes = new[outline.shape[0] + np.arange(bore.shape[0])]
    nodes = twins = None
    if crack is not None:
        nodes = new[crack_idx]
        p, tri, twins = _cut_crack(p, tri, nodes, crack.path_m(profile)[1])
        _check_crack_faces(tri, nodes, twins)
        for arr in (nodes, twins):
            arr.setflags(write=False)
    p.setflags(write=False)
    tri.setflags(write=False)
    bore_nodes.setflags(write=False)
    return GearMesh(points_m=p, triangles=tri, bore_nodes=bore_nodes, profile=profile,
                    spec=spec, crack=crack, crack_nodes=nodes, crack_twin_nodes=twins)
