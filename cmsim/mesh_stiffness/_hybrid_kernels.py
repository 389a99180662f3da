"""Numba kernels of the hybrid contact solve (paper 001 eq. 2).

This module isolates the numba convention: ``@njit(cache=True)``, float64 scalars and arrays
only, no Python objects, no allocation in the solve (the caller passes ``work`` and ``out``).
The kernels are callable from other numba code (the time integrator's right-hand side).
The Python side (:mod:`cmsim.mesh_stiffness.hybrid`) builds the parameter vector and holds
the documentation of the method.

Problem. For n potential contacts on consecutive tooth pairs (index i = slot; the pair in
slot i + 1 sits one base pitch further along the line of action, i.e. one tooth further in
the sense its gear-1 flank faces and one tooth back for gear 2) with rigid interferences δ_i,
find F_i >= 0 with

    r_i(F) = u_L,i(F_i) + Σ_k C_ik F_k − δ_i >= 0,    F_i r_i = 0,

where C_ik = λ¹(i − k; ρ1_i, ρ1_k) + λ²(k − i; ρ2_i, ρ2_k) from the two gears' influence
tables (diagonal: 1-D linear interpolation in ρ; other teeth: bilinear), and u_L,i the sum of
the two bodies' Weber-Banaschek approaches (exact half-plane form, see
:mod:`cmsim.mesh_stiffness.local_deflection`) for the Hertz half-width of radii χ1_i, χ2_i.

Method. The map F ↦ u_L(F) + C F is strictly monotone for the tables of real gears (C is
diagonally dominant, u_L increasing), so the complementarity problem has one solution. It is
found by (1) a linear complementarity solve (active-set pivoting on the few unknowns) with
the local terms replaced by their secant compliances at the force estimate δ_i/C_ii, then
(2) Newton's method on the active set: a contact whose force a full Newton step would make
non-positive is dropped, one whose gap becomes negative is added, and the iteration stops
when the Newton step squared is below ``tol`` times the largest force squared (Newton
converges quadratically, so the error left after that step is of order ``tol``).

Parameter vector ``hp`` (see :func:`cmsim.mesh_stiffness.hybrid.HybridMeshModel`):
0-3 gear 1 table: first roll, roll step, number of rolls, J; 4-7 the same for gear 2;
8, 9 depths h1, h2; 10, 11 E1, ν1; 12, 13 E2, ν2; 14 face width b; 15 contact modulus E*;
16 relative tolerance; 17 maximum Newton iterations.
"""

from __future__ import annotations

import math

from numba import njit

HP_SIZE = 18
#: ``work`` must hold at least ``WORK_PER_N2 n² + WORK_PER_N n`` floats.
WORK_PER_N2 = 3
WORK_PER_N = 8


@njit(cache=True, inline="always")
def _grid_pos(x, x0, dx, n):
    u = (x - x0) / dx
    if u <= 0.0:
        return 0, 0.0
    if u >= n - 1.0:
        return n - 2, 1.0
    i = int(u)
    return i, u - i


@njit(cache=True)
def influence_jit(d, ri, rk, x0, dx, n, jmax, diag, cpl):
    """λ of one gear for tooth offset ``d``, response roll ``ri``, load roll ``rk``, m/N."""
    if d == 0:
        i, f = _grid_pos(ri, x0, dx, n)
        return diag[i] + f * (diag[i + 1] - diag[i])
    if d > jmax or d < -jmax:
        return 0.0
    t = d + jmax
    i, fi = _grid_pos(ri, x0, dx, n)
    k, fk = _grid_pos(rk, x0, dx, n)
    a = cpl[t, i, k] + fk * (cpl[t, i, k + 1] - cpl[t, i, k])
    b = cpl[t, i + 1, k] + fk * (cpl[t, i + 1, k + 1] - cpl[t, i + 1, k])
    return a + fi * (b - a)


@njit(cache=True, inline="always")
def _body_local(force, a, h, e, nu, b):
    """Approach u and du/dF of one body (exact half-plane Weber-Banaschek), F > 0."""
    s = math.sqrt(a * a + h * h)
    q = h / (s + h)
    ash = math.asinh(h / a)
    k = 2.0 / (math.pi * e * b)
    u = k * force * ((1.0 - nu * nu) * ash - nu * (1.0 + nu) * q)
    aqp = -h * a * a / (s * (s + h) * (s + h))
    du = k * ((1.0 - nu * nu) * (ash - 0.5 * h / s) - nu * (1.0 + nu) * (q + 0.5 * aqp))
    return u, du


@njit(cache=True)
def local_approach_jit(force, chi1, chi2, hp):
    """Local approach of both bodies u_L(F) and its derivative, m and m/N (F > 0)."""
    b = hp[14]
    r = chi1 * chi2 / (chi1 + chi2)
    a = math.sqrt(4.0 * force * r / (math.pi * b * hp[15]))
    u1, d1 = _body_local(force, a, hp[8], hp[10], hp[11], b)
    u2, d2 = _body_local(force, a, hp[9], hp[12], hp[13], b)
    return u1 + u2, d1 + d2


@njit(cache=True)
def coupling_matrix_jit(rho1, rho2, hp, diag1, cpl1, diag2, cpl2, c):
    """Fill ``c`` (flat, n·n, row-major) with C_ik = λ¹(i − k) + λ²(k − i), m/N."""
    n = rho1.shape[0]
    n1 = int(hp[2])
    j1 = int(hp[3])
    n2 = int(hp[6])
    j2 = int(hp[7])
    for i in range(n):
        for k in range(n):
            c[i * n + k] = (influence_jit(i - k, rho1[i], rho1[k], hp[0], hp[1], n1, j1,
                                          diag1, cpl1)
                            + influence_jit(k - i, rho2[i], rho2[k], hp[4], hp[5], n2, j2,
                                            diag2, cpl2))


@njit(cache=True)
def _solve_active(mat, rhs, act, n, blk, xb, x):
    """Solve mat[A, A] x[A] = rhs[A] on the active set A (act[i] > 0.5); mat flat n·n.

    ``blk`` (>= m·m) and ``xb`` (>= m) are scratch. Gauss elimination with partial
    pivoting. Returns False if the block is singular.
    """
    m = 0
    for i in range(n):
        if act[i] > 0.5:
            xb[m] = i
            m += 1
    for r in range(m):
        ir = int(xb[r])
        for c in range(m):
            blk[r * m + c] = mat[ir * n + int(xb[c])]
    # right-hand side kept in x (permuted along with the rows)
    for r in range(m):
        x[r] = rhs[int(xb[r])]
    for col in range(m):
        piv = col
        big = abs(blk[col * m + col])
        for r in range(col + 1, m):
            v = abs(blk[r * m + col])
            if v > big:
                big = v
                piv = r
        if big == 0.0:
            return False
        if piv != col:
            for c in range(m):
                t = blk[col * m + c]
                blk[col * m + c] = blk[piv * m + c]
                blk[piv * m + c] = t
            t = x[col]
            x[col] = x[piv]
            x[piv] = t
        for r in range(col + 1, m):
            f = blk[r * m + col] / blk[col * m + col]
            if f != 0.0:
                for c in range(col, m):
                    blk[r * m + c] -= f * blk[col * m + c]
                x[r] -= f * x[col]
    for col in range(m - 1, -1, -1):
        s = x[col]
        for c in range(col + 1, m):
            s -= blk[col * m + c] * x[c]
        x[col] = s / blk[col * m + col]
    # scatter back to full length (from the top so the compact entries are not overwritten)
    for r in range(m - 1, -1, -1):
        v = x[r]
        x[int(xb[r])] = v
        if int(xb[r]) != r:
            x[r] = 0.0
    for i in range(n):
        if act[i] < 0.5:
            x[i] = 0.0
    return True


@njit(cache=True)
def _gap(c, f, delta, i, n):
    """Σ_k C_ik F_k − δ_i (the gap a contact would have with no force of its own)."""
    s = -delta[i]
    for k in range(n):
        s += c[i * n + k] * f[k]
    return s


@njit(cache=True)
def _add_worst_gap(c, f, delta, act, n, limit):
    """Index of the inactive contact with the most negative gap below ``limit``, or −1."""
    worst = -1
    wv = limit
    for i in range(n):
        if act[i] < 0.5:
            g = _gap(c, f, delta, i, n)
            if g < wv:
                wv = g
                worst = i
    return worst, wv


@njit(cache=True)
def hybrid_forces_jit(delta, rho1, rho2, chi1, chi2, hp, diag1, cpl1, diag2, cpl2, extra, work,
                      out):
    """Contact forces of n consecutive tooth pairs (paper 001 eq. 2), N.

    Parameters
    ----------
    delta : ndarray, shape (n,)
        Rigid-body interferences δ_i, m (> 0: overlap).
    rho1, rho2 : ndarray, shape (n,)
        Roll lengths of the contact points on gear 1 and gear 2 (table abscissae), m.
    chi1, chi2 : ndarray, shape (n,)
        Radii of curvature of the two surfaces at each contact (> 0), m.
    hp : ndarray, shape (HP_SIZE,)
        Parameter vector (module docstring).
    diag1, cpl1, diag2, cpl2 : ndarray
        Influence tables of the two gears: shapes (n1,), (2 J1 + 1, n1, n1), (n2,),
        (2 J2 + 1, n2, n2), m/N.
    extra : ndarray, shape (n,)
        Compliance added to each contact's own λ (a weakened tooth in that pair, e.g. a root
        crack: :mod:`cmsim.faults`), m/N; zeros for healthy teeth.
    work : ndarray, shape (>= 3 n² + 8 n,)
        Scratch space.
    out : ndarray, shape (n,)
        Receives the forces F_i >= 0, N.

    Returns
    -------
    int
        Newton iterations used (>= 0), or −1 if not converged within ``hp[17]`` iterations
        (``out`` then holds the last iterate, clipped at 0).
    """
    n = delta.shape[0]
    nn = n * n
    c = work[0:nn]
    mat = work[nn:2 * nn]
    cmp = work[2 * nn:3 * nn]
    o = 3 * nn
    f = work[o:o + n]
    df = work[o + n:o + 2 * n]
    dul = work[o + 2 * n:o + 3 * n]
    act = work[o + 3 * n:o + 4 * n]
    rhs = work[o + 4 * n:o + 5 * n]
    xb = work[o + 5 * n:o + 6 * n]
    sec = work[o + 6 * n:o + 7 * n]
    tol = hp[16]
    maxit = int(hp[17])
    dmax = 0.0
    for i in range(n):
        out[i] = 0.0
        dmax = max(dmax, delta[i])
    if dmax <= 0.0:
        return 0
    gap_tol = -tol * dmax
    coupling_matrix_jit(rho1, rho2, hp, diag1, cpl1, diag2, cpl2, c)
    for i in range(n):
        c[i * n + i] += extra[i]
    # ---- stage 1: linear complementarity with secant local compliances
    fscale = 0.0
    for i in range(n):
        f[i] = max(delta[i], 0.0) / c[i * n + i]
        act[i] = 1.0 if delta[i] > 0.0 else 0.0
        fscale = max(fscale, f[i])
    for i in range(n):
        fi = max(f[i], 1e-3 * fscale)
        u, d = local_approach_jit(fi, chi1[i], chi2[i], hp)
        sec[i] = u / fi
    for piv in range(2 * n + 2):
        m = 0
        for i in range(n):
            for k in range(n):
                mat[i * n + k] = c[i * n + k]
            mat[i * n + i] += sec[i]
            rhs[i] = delta[i]
            if act[i] > 0.5:
                m += 1
        if m == 0:
            for i in range(n):
                f[i] = 0.0
        else:
            _solve_active(mat, rhs, act, n, cmp, xb, df)
            for i in range(n):
                f[i] = df[i]
        worst = -1
        wv = 0.0
        for i in range(n):
            if act[i] > 0.5 and f[i] <= 0.0 and (worst < 0 or f[i] < wv):
                wv = f[i]
                worst = i
        if worst >= 0:
            act[worst] = 0.0
            continue
        worst, wv = _add_worst_gap(c, f, delta, act, n, gap_tol)
        if worst >= 0:
            act[worst] = 1.0
            continue
        break
    fscale = 0.0
    for i in range(n):
        fscale = max(fscale, f[i])
    if fscale <= 0.0:
        return 0
    # ---- stage 2: Newton on the active set
    for it in range(maxit):
        fmax = 0.0
        for i in range(n):
            if act[i] > 0.5:
                fmax = max(fmax, f[i])
        if fmax <= 0.0:
            worst, wv = _add_worst_gap(c, f, delta, act, n, gap_tol)
            if worst < 0:
                return it
            act[worst] = 1.0
            f[worst] = -wv / c[worst * n + worst]
            continue
        for i in range(n):
            if act[i] > 0.5:
                u, d = local_approach_jit(f[i], chi1[i], chi2[i], hp)
                rhs[i] = -(u + _gap(c, f, delta, i, n))
                dul[i] = d
            else:
                rhs[i] = 0.0
                dul[i] = 0.0
            for k in range(n):
                mat[i * n + k] = c[i * n + k]
            mat[i * n + i] += dul[i]
        if not _solve_active(mat, rhs, act, n, cmp, xb, df):
            break
        step = 0.0
        drop = -1
        ratio = 0.0
        for i in range(n):
            if act[i] > 0.5:
                step = max(step, abs(df[i]))
                if f[i] + df[i] <= 0.0:
                    r = (f[i] + df[i]) / f[i]
                    if drop < 0 or r < ratio:
                        ratio = r
                        drop = i
        if drop >= 0:
            act[drop] = 0.0
            f[drop] = 0.0
            continue
        for i in range(n):
            if act[i] > 0.5:
                f[i] += df[i]
        if step * step <= tol * fmax * fmax:      # quadratic convergence: error ~ step²
            worst, wv = _add_worst_gap(c, f, delta, act, n, gap_tol)
            if worst >= 0:
                act[worst] = 1.0
                f[worst] = -wv / c[worst * n + worst]
                continue
            for i in range(n):
                out[i] = f[i] if act[i] > 0.5 else 0.0
            return it + 1
    for i in range(n):
        out[i] = max(f[i], 0.0) if act[i] > 0.5 else 0.0
    return -1
