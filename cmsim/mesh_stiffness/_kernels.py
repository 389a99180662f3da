"""Numba kernels of the rigid-body tooth contact geometry (exact involutes, rounded tips).

This module isolates the numba convention: ``@njit(cache=True)``, float64 scalars and arrays
only, no Python objects. The kernels are inlined at numba-IR level into the time loop
(``inline="always"``): a numba call with array arguments costs about 25 ns. Python-side construction of the geometry vector lives in
:mod:`cmsim.mesh_stiffness.contact`.

Frame and conventions (DESIGN.md): y along the line of centres from gear 1 to gear 2, x normal
to it; gear 1 (driving) turns counter-clockwise, gear 2 clockwise. Angles ``psi`` are the
physical polar angles at which a drive-flank involute leaves its base circle. A drive flank of
either gear is ``r_b u(φ) + r_b (ψ − φ) τ(φ)`` over tangent points φ < ψ, with
``u = (cos φ, sin φ)`` and ``τ = (−sin φ, cos φ)``; the outward normal is ``+τ``.
The line of action is tangent to base circle 1 at polar angle ``phi_t1 = γ − α_w`` (γ: direction
of the line of centres) and to base circle 2 at ``phi_t1 + π``; positions ``s`` along it are
measured from that tangent point T1 towards T2, and the force of gear 1 on gear 2 along it is
``F τ(phi_t1)``.

Geometry vector ``geo`` (see :func:`cmsim.mesh_stiffness.contact.contact_geometry`):
0 rb1, 1 rb2, 2 s_end (roll length where gear 1's tip rounding starts), 3 roll length on gear 2
where its tip rounding starts, 4 radius of gear 1's tip-rounding centre, 5 its polar offset from
ψ1, 6 gear 1 tip-rounding radius, 7-9 the same for gear 2, 10-11 cos and sin of offset 5,
12-13 cos and sin of offset 8.
"""

from __future__ import annotations

import math

from numba import njit

GEO_SIZE = 14


@njit(cache=True, inline="always", error_model="numpy")
def mesh_line_jit(c1x, c1y, c2x, c2y, rb1, rb2):
    """Length T1T2 = a·sin α_w (m) and the cos and sin of T1's polar angle γ − α_w for the
    gear centres C1, C2 (a: instantaneous centre distance, γ: direction C1→C2)."""
    dx = c2x - c1x
    dy = c2y - c1y
    a = math.sqrt(dx * dx + dy * dy)
    inv_a = 1.0 / a
    ca = (rb1 + rb2) * inv_a
    sa = math.sqrt(1.0 - ca * ca)
    cg = dx * inv_a
    sg = dy * inv_a
    return a * sa, cg * ca + sg * sa, sg * ca - cg * sa


@njit(cache=True, inline="always", error_model="numpy")
def mesh_frame_jit(c1x, c1y, c2x, c2y, rb1, rb2):
    """Line of action for the gear centres C1, C2.

    Returns
    -------
    phi_t1 : float
        Polar angle of the tangent point T1 on base circle 1, γ − α_w, rad.
    length : float
        Distance T1T2 = a·sin α_w, m (a: instantaneous centre distance).
    cos_t1, sin_t1 : float
        cos and sin of ``phi_t1``.
    """
    length, cos_t1, sin_t1 = mesh_line_jit(c1x, c1y, c2x, c2y, rb1, rb2)
    return math.atan2(sin_t1, cos_t1), length, cos_t1, sin_t1


@njit(cache=True, inline="always", error_model="numpy")
def pair_contact_jit(s, delta_inv, cp1, sp1, cp2, sp2, c1x, c1y, c2x, c2y, cos_t1, sin_t1,
                     length, geo):
    """Rigid-body interference of one tooth pair and where and along what it acts.

    Parameters
    ----------
    s : float
        Position of the pair's gear-1 flank on the line of action, from T1, m.
    delta_inv : float
        Involute-involute interference s1 + s2 − T1T2 (the same for every pair), m.
    cp1, sp1, cp2, sp2 : float
        cos and sin of the involute origin angles ψ1, ψ2 of this pair's drive flanks.
    c1x, c1y, c2x, c2y : float
        Gear centres, m.
    cos_t1, sin_t1, length : float
        Line of action from :func:`mesh_frame_jit`.
    geo : ndarray, shape (14,)
        Tooth geometry vector (module docstring).

    Returns
    -------
    delta : float
        Overlap along the contact normal (> 0: in contact), m.
    nx, ny : float
        Unit normal; the force of gear 1 on gear 2 is ``F (nx, ny)``.
    px, py : float
        Contact point, m.
    s_eq : float
        Equivalent position on the line of action (the roll length of gear 1's contact
        point): the roll length ρ1 of the hybrid contact solve, m. Stiffness tables are read
        at ``s``, not here: a corner contact's s_eq lies inside the involute path.
    chi1, chi2 : float
        Radii of curvature of the two surfaces at the contact, m.

    Notes
    -----
    Corner contact uses no trigonometry but one ``atan2``: the normal from the rounding
    centre Q to an involute is tangent to its base circle at φ = arg(w) − atan(λ/r_b)
    (w = Q − C, λ = sqrt(|w|² − r_b²)), so e^{iφ} = w (r_b − iλ)/|w|², and the roll angle
    ψ − φ = arg(e^{iψ} · conj(w) · (r_b + iλ)) comes out wrapped.
    """
    rb1 = geo[0]
    rb2 = geo[1]
    s_end = geo[2]
    s_start = length - geo[3]
    if s >= s_start and s <= s_end:
        sc = s - 0.5 * delta_inv
        nx = -sin_t1
        ny = cos_t1
        px = c1x + rb1 * cos_t1 + sc * nx
        py = c1y + rb1 * sin_t1 + sc * ny
        return delta_inv, nx, ny, px, py, s, sc, length - sc
    if s < s_start:
        # rounded tip of gear 2 against the drive flank of gear 1
        ux = cp2 * geo[12] - sp2 * geo[13]
        uy = sp2 * geo[12] + cp2 * geo[13]
        wx = c2x + geo[7] * ux - c1x
        wy = c2y + geo[7] * uy - c1y
        rb, cp, sp, rho = rb1, cp1, sp1, geo[9]
    else:
        # rounded tip of gear 1 against the drive flank of gear 2
        ux = cp1 * geo[10] - sp1 * geo[11]
        uy = sp1 * geo[10] + cp1 * geo[11]
        wx = c1x + geo[4] * ux - c2x
        wy = c1y + geo[4] * uy - c2y
        rb, cp, sp, rho = rb2, cp2, sp2, geo[6]
    w2 = wx * wx + wy * wy
    lam = math.sqrt(max(w2 - rb * rb, 0.0))
    ar = cp * wx + sp * wy
    ai = sp * wx - cp * wy
    roll = rb * math.atan2(ar * lam + ai * rb, ar * rb - ai * lam)
    inv_w2 = 1.0 / w2
    cphi = (wx * rb + wy * lam) * inv_w2
    sphi = (wy * rb - wx * lam) * inv_w2
    tx = -sphi
    ty = cphi
    delta = rho - (lam - roll)
    if s < s_start:
        px = c1x + rb * cphi + roll * tx
        py = c1y + rb * sphi + roll * ty
        return delta, tx, ty, px, py, roll, roll, rho
    px = c2x + rb * cphi + roll * tx
    py = c2y + rb * sphi + roll * ty
    return delta, -tx, -ty, px, py, length - roll, rho, roll


@njit(cache=True, inline="always", error_model="numpy")
def table_lookup2_jit(x, x0, dx, values_a, values_b):
    """Linear interpolation of two tables on the same uniform grid, clamped at both ends."""
    n = values_a.shape[0]
    u = (x - x0) / dx
    if u <= 0.0:
        return values_a[0], values_b[0]
    if u >= n - 1:
        return values_a[n - 1], values_b[n - 1]
    i = int(u)
    f = u - i
    return (values_a[i] + f * (values_a[i + 1] - values_a[i]),
            values_b[i] + f * (values_b[i + 1] - values_b[i]))
