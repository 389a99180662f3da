"""DistMesh: force-equilibrium smoothing of points on a Delaunay triangulation.

The mesh generator of the gear bodies (:func:`cmsim.mesh_stiffness.fe_mesh.gear_mesh`), after
Persson & Strang [1]: fixed boundary points, free interior points moved by the repulsive
forces of bars longer than their share of the local target size, re-triangulated
(:func:`scipy.spatial.Delaunay`) when a point has moved more than a fraction of its size;
triangles whose centroid is outside the body are dropped. The body is any object with
``distance(points)`` (signed, negative inside) and ``size(points)`` (target element size).
Everything is deterministic (no random numbers). All lengths in m.

References
----------
.. [1] P.-O. Persson, G. Strang, "A simple mesh generator in MATLAB", SIAM Review 46 (2004)
   329-345.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from cmsim.errors import ParameterError

__all__ = ["distmesh_smooth", "triangulate", "orient", "check_boundary_loops", "hex_lattice",
           "thin_points"]

#: DistMesh constants [1]: internal pressure factor, pseudo time step, stop tolerance.
_FSCALE, _DELTAT, _DPTOL = 1.2, 0.2, 2e-3
#: Re-triangulate when a point moved more than this fraction of its local size.
_TTOL = 0.1


def hex_lattice(lo, hi, h):
    """Points of a hexagonal lattice of spacing ``h`` over the box [lo, hi], shape (n, 2).

    Parameters
    ----------
    lo, hi : ndarray, shape (2,)
        Corners of the box, m.
    h : float
        Lattice spacing, m (rows ``(√3/2)·h`` apart, every other row shifted by ``h/2``).
    """
    dy = h * math.sqrt(3.0) / 2.0
    ny = int(math.ceil((hi[1] - lo[1]) / dy)) + 1
    nx = int(math.ceil((hi[0] - lo[0]) / h)) + 1
    if nx * ny > 5_000_000:
        raise ParameterError("mesh too fine for the lattice initialisation (> 5e6 candidates)")
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    x = lo[0] + h * (i + 0.5 * (j % 2))
    y = lo[1] + dy * j
    return np.column_stack([x.ravel(), y.ravel()])


def thin_points(candidates, h, accepted_tree, factor=0.75):
    """Keep candidates at least ``factor·h`` from accepted points and from each other.

    Parameters
    ----------
    candidates : ndarray, shape (n, 2)
        Candidate points, m (greedy among themselves, in order).
    h : ndarray, shape (n,)
        Target size at each candidate, m.
    accepted_tree : scipy.spatial.cKDTree
        The points already accepted.
    factor : float
        Smallest distance as a fraction of ``h``.
    """
    if candidates.shape[0] == 0:
        return candidates
    d = accepted_tree.query(candidates, workers=-1)[0]
    ok = d >= factor * h
    candidates, h = candidates[ok], h[ok]
    # greedy among themselves, in order
    pairs = cKDTree(candidates).query_pairs(factor * float(np.max(h)) if h.size else 0.0,
                                            output_type="ndarray")
    if pairs.size:
        dist = np.hypot(*(candidates[pairs[:, 0]] - candidates[pairs[:, 1]]).T)
        close = dist < factor * np.minimum(h[pairs[:, 0]], h[pairs[:, 1]])
        keep = np.ones(candidates.shape[0], dtype=bool)
        for a, b in pairs[close][np.argsort(pairs[close][:, 0], kind="stable")]:
            if keep[a] and keep[b]:
                keep[b] = False
        candidates = candidates[keep]
    return candidates


def triangulate(p, geo):
    """Delaunay triangles of ``p`` whose centroid lies inside the body (``geo.distance < 0``).

    Parameters
    ----------
    p : ndarray, shape (n, 2)
        Points, m.
    geo : object
        The body: ``geo.distance(points)``, signed distance (negative inside), m.
    """
    tri = Delaunay(p).simplices
    centroids = p[tri].mean(axis=1)
    return tri[geo.distance(centroids) < 0.0]


def distmesh_smooth(fixed, interior, geo, max_iterations):
    """Persson-Strang smoothing of the interior points with the boundary points fixed.

    Parameters
    ----------
    fixed : ndarray, shape (nf, 2)
        Points that do not move (boundary nodes, crack nodes), m; they stay first.
    interior : ndarray, shape (ni, 2)
        Free points, moved by the bar forces (dropped when pushed out of the body), m.
    geo : object
        The body: ``geo.distance(points)`` (signed, negative inside) and ``geo.size(points)``
        (target element size), m.
    max_iterations : int
        Smoothing steps at most.

    Returns
    -------
    (ndarray, ndarray)
        Points (n, 2), m, and the triangles inside the body (m, 3).
    """
    nf = fixed.shape[0]
    p = np.vstack([fixed, interior])
    p_old = np.full_like(p, np.inf)
    tri, h_pt = None, None
    for _ in range(max_iterations):
        if tri is None or np.max(np.hypot(*(p - p_old).T) / h_pt) > _TTOL:
            p_old = p.copy()
            tri = triangulate(p, geo)
            bars = np.vstack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
            bars = np.unique(np.sort(bars, axis=1), axis=0)
            h_pt = geo.size(p)
            d_pt = geo.distance(p)
            hbars = 0.5 * (h_pt[bars[:, 0]] + h_pt[bars[:, 1]])
            near = np.nonzero(d_pt[nf:] > -3.0 * h_pt[nf:])[0] + nf
        vec = p[bars[:, 0]] - p[bars[:, 1]]
        length = np.hypot(vec[:, 0], vec[:, 1])
        l0 = hbars * _FSCALE * math.sqrt(np.sum(length ** 2) / np.sum(hbars ** 2))
        force = np.maximum(l0 - length, 0.0)
        fvec = (force / length)[:, None] * vec
        ftot = np.zeros_like(p)
        np.add.at(ftot, bars[:, 0], fvec)
        np.add.at(ftot, bars[:, 1], -fvec)
        ftot[:nf] = 0.0
        step = _DELTAT * ftot
        p = p + step
        # interior points pushed out of the body (or onto the boundary) are dropped
        bad = near[geo.distance(p[near]) > -0.1 * h_pt[near]]
        if bad.size:
            keep = np.ones(p.shape[0], dtype=bool)
            keep[bad] = False
            p = p[keep]
            tri = None
            continue
        if np.max(np.hypot(*step[nf:].T) / h_pt[nf:]) < _DPTOL:
            break
    return p, triangulate(p, geo)


def orient(p, tri):
    """Triangles turned counter-clockwise and twice their areas, m².

    Parameters
    ----------
    p : ndarray, shape (n, 2)
        Points, m.
    tri : ndarray of int, shape (m, 3)
        Triangles.
    """
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    tri = tri.copy()
    neg = area2 < 0
    tri[neg] = tri[neg][:, [0, 2, 1]]
    return tri, np.abs(area2)


def check_boundary_loops(tri, n_outline, n_bore, n_points):
    """Raise unless the boundary facets form the two expected closed loops.

    Parameters
    ----------
    tri : ndarray of int, shape (m, 3)
        Triangles.
    n_outline, n_bore : int
        Points of the outer loop (indices 0..n_outline−1) and of the bore loop (next
        n_bore), each joined to the next one round its loop.
    n_points : int
        All points.

    Returns
    -------
    ndarray of bool, shape (n_points,)
        The points some triangle uses.
    """
    edges = np.sort(np.vstack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    bnd = uniq[count == 1]
    expected = set()
    for start, n in ((0, n_outline), (n_outline, n_bore)):
        idx = start + np.arange(n)
        nxt = start + (np.arange(n) + 1) % n
        expected |= {(min(a, b), max(a, b)) for a, b in zip(idx, nxt)}
    found = {tuple(e) for e in bnd}
    if found != expected:
        raise ParameterError(
            f"gear mesh generation failed: {len(found ^ expected)} boundary facets do not "
            "follow the outline (try a finer MeshSpec)")
    used = np.zeros(n_points, dtype=bool)
    used[tri.ravel()] = True
    return used
