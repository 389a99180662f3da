"""Numba kernels of the equations of motion and the fixed-step Runge-Kutta integrator.

This module isolates the numba convention: ``@njit(cache=True)``, float64/int64 arrays and
scalars only (grouped in one plain tuple ``P``), no Python objects, no random numbers. The
model arrays are built and documented in :mod:`cmsim.dynamics.model`.

Right-hand side contract: ``rhs_jit(t, y, dydt, row, P, diag, want_diag, W)`` with ``y = [q, v]``
(shape ``(2n,)``), ``q`` the DOF deviations from the nominal rigid rotation (translations in m,
rotations in rad, rotations of shaft 2 counted positive in its own sense of motion), ``v`` their
rates; it writes row ``row`` of the 2-D array ``dydt`` with ``[v, M⁻¹(f_ext + g(t, q, v) − K q
− C v)]`` where ``g`` holds the bearing and mesh forces. With ``want_diag`` it also writes the
output forces into ``diag``. ``W`` holds the scratch arrays of :func:`make_work` (force
vector, cage and slip trigonometry, per-slot mesh geometry, the hybrid solver's buffers).

Hot-path code never slices arrays and never takes arrays out of tuples inside loops (numba
takes an atomic reference count for each), and the integrator and force kernels are compiled
without numba's reference-counting runtime (``_nrt=False``, so they allocate nothing: the
caller passes every buffer), which halved the cost of a step. Small kernels are inlined at
numba-IR level (a call with array arguments costs about 25 ns).
The bearing forces are compiled with fastmath so the ball loop vectorises; the finiteness
checks live in the integrator, which is compiled without it.

``P`` = (minv, springs, fext, omega, b_int, b_par, b_cos, b_sin, jitter, m_int, m_par, geo, tab_k,
tab_e, teeth1, teeth2, spring_ends, hp, diag1, cpl1, diag2, cpl2) with the linear K and C as two-node spring-dampers
(``springs`` (e, 2) = k, c; ``spring_ends`` (e, 3), see :func:`linear_accel_jit`) and ``teeth1/2``
the cos and sin of multiples of the angular pitch, shape (Z, 2); the last five are the hybrid
contact model's parameters and influence tables
(:meth:`cmsim.mesh_stiffness.hybrid.HybridMeshModel.kernel_args`; placeholders in table
mode); index constants below.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cmsim.bearings._kernels import ball_forces_cage_frame_jit
from cmsim.mesh_stiffness._hybrid_kernels import (HP_SIZE, WORK_PER_N, WORK_PER_N2,
                                                  hybrid_forces_jit)
from cmsim.mesh_stiffness._kernels import mesh_frame_jit, pair_contact_jit, table_lookup2_jit

# b_int columns: DOF indices, number of balls, index of the first bearing sharing the same
# nominal cage rotation (its cos/sin are computed once)
BI_X, BI_Y, BI_T, BI_NB, BI_GROUP = 0, 1, 2, 3, 4
BI_SIZE = 5
# b_par columns: stiffness, exponent, clearance, cage angle per physical inner-ring angle,
# physical sense of the shaft (+1 CCW, −1 CW), viscous damping to ground, initial cage phase
BP_K, BP_P, BP_C, BP_CAGE, BP_SENSE, BP_DAMP, BP_PHASE = 0, 1, 2, 3, 4, 5, 6
BP_SIZE = 7
# m_int entries: DOF index of each gear's x, number of slots, mesh on, elastic-force mode
MI_G1, MI_G2, MI_SLOTS, MI_ON, MI_MODE = 0, 1, 2, 3, 4
MI_SIZE = 5
MODE_TABLE, MODE_HYBRID = 0, 1
# columns of the per-slot scratch ``W[6]`` of the mesh kernel
SG_ON, SG_NX, SG_NY, SG_PX, SG_PY, SG_REQ, SG_ELASTIC, SG_GAP = range(8)
SG_SIZE = 8
# m_par entries
(MP_A0, MP_PSI10, MP_PSI20, MP_PB, MP_SLO, MP_OM1, MP_OM2, MP_MU, MP_V0, MP_CHYST, MP_KOSTER,
 MP_DTHR, MP_TAB0, MP_TABD, MP_JDT, MP_DIAGB, MP_ZBEFORE, MP_ZAFTER) = range(18)
MP_SIZE = 18


@njit(cache=True, inline="always", error_model="numpy")
def _jitter_at(jitter, ib, iball, t, jdt):
    ng = jitter.shape[2]
    u = t / jdt
    if u <= 0.0:
        return jitter[ib, iball, 0]
    if u >= ng - 1:
        return jitter[ib, iball, ng - 1]
    i = int(u)
    f = u - i
    return jitter[ib, iball, i] + f * (jitter[ib, iball, i + 1] - jitter[ib, iball, i])


@njit(cache=True, error_model="numpy", _nrt=False)
def _slip_offsets(t, P, W):
    """Fill ``W[3]``, ``W[4]`` (n_bearings, max_balls) with cos, sin of the ball offsets
    with slip at time ``t``, and ``W[5]`` with each cage's slip angle."""
    b_int = P[4]
    b_cos = P[6]
    b_sin = P[7]
    jitter = P[8]
    jdt = P[10][MP_JDT]
    jit_cos = W[3]
    jit_sin = W[4]
    cage_slip = W[5]
    row = b_cos.shape[1]
    for ib in range(b_int.shape[0]):
        cage_slip[ib] = _jitter_at(jitter, ib, row, t, jdt)
        for i in range(b_int[ib, BI_NB]):
            j = _jitter_at(jitter, ib, i, t, jdt)
            j2 = j * j
            cj = 1.0 - j2 * (0.5 - j2 * (1.0 / 24.0))
            sj = j * (1.0 - j2 * (1.0 / 6.0 - j2 * (1.0 / 120.0)))
            jit_cos[ib, i] = b_cos[ib, i] * cj - b_sin[ib, i] * sj
            jit_sin[ib, i] = b_sin[ib, i] * cj + b_cos[ib, i] * sj


@njit(cache=True, fastmath=True, error_model="numpy", _nrt=False)
def _bearing_forces(t, y, n, g, omega, b_int, b_par, ball_cos, ball_sin, cos_nom, sin_nom,
                    cage_slip, diag, want_diag):
    """Fukata forces of all bearings with balls at offsets ``ball_cos/sin`` from the cage
    and cages shifted by the slip angles ``W[5]`` (zeros without slip).

    Written flat on purpose: with helper functions inlined, a jitter branch, or arrays taken
    out of ``P`` inside the loop, numba stops vectorising the ball loop (2-3× slower).
    The cage angle's nominal part (rate·Ω·t) is computed once per group of bearings turning
    alike; the small dynamic deviation (rate·q_θ) is applied as a rotation (Taylor series).
    Each bearing works in its cage frame: the inner-ring offset is turned by −θ_cage once
    instead of turning every ball. Arrays come as arguments, not in the tuple ``P``: a
    non-inlined call copies its arguments, and ``P`` holds 17 arrays.
    """
    for ib in range(b_int.shape[0]):
        ix = b_int[ib, BI_X]
        iy = b_int[ib, BI_Y]
        it = b_int[ib, BI_T]
        rate = b_par[ib, BP_CAGE] * b_par[ib, BP_SENSE]
        grp = b_int[ib, BI_GROUP]
        if grp == ib:
            nominal = rate * omega[it] * t + b_par[ib, BP_PHASE] + cage_slip[ib]
            cos_nom[ib] = math.cos(nominal)
            sin_nom[ib] = math.sin(nominal)
        dev = rate * y[it]
        d2 = dev * dev
        cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0)))
        sd = dev * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0))))
        cc = cos_nom[grp] * cd - sin_nom[grp] * sd
        sc = sin_nom[grp] * cd + cos_nom[grp] * sd
        xr = y[ix] * cc + y[iy] * sc
        yr = y[iy] * cc - y[ix] * sc
        fxr, fyr = ball_forces_cage_frame_jit(xr, yr, ball_cos, ball_sin, ib, b_int[ib, BI_NB],
                                              b_par[ib, BP_K], b_par[ib, BP_P], b_par[ib, BP_C])
        fx = fxr * cc - fyr * sc
        fy = fyr * cc + fxr * sc
        g[ix] -= fx
        g[iy] -= fy
        if want_diag:
            diag[2 * ib] = fx + b_par[ib, BP_DAMP] * y[n + ix]
            diag[2 * ib + 1] = fy + b_par[ib, BP_DAMP] * y[n + iy]


@njit(cache=True, error_model="numpy", _nrt=False)
def _mesh_forces(t, y, n, g, m_int, mp, geo, tab_k, tab_e, teeth1, teeth2, diag, want_diag,
                 hp, hd1, hc1, hd2, hc2, S, hw, hdelta, hrho1, hrho2, hchi1, hchi2, hout,
                 hstat):
    """Forces of the tooth pairs in the potential-contact zone: exact rigid-body geometry,
    elastic force from the table (``MI_MODE`` 0) or from the on-line hybrid contact solve
    (1, paper 001 model A), hysteretic or Koster squeeze damping, smoothed Coulomb friction.

    Pass 1 stores each slot's geometry in ``S`` (columns ``SG_*``); in hybrid mode the
    interferences of all slots are then solved together (out-of-zone slots enter with a
    large negative interference, so they stay unloaded); pass 2 applies the forces."""
    z1 = teeth1.shape[0]
    z2 = teeth2.shape[0]
    i1 = m_int[MI_G1]
    i2 = m_int[MI_G2]
    n_slots = m_int[MI_SLOTS]
    hybrid = m_int[MI_MODE] == MODE_HYBRID
    rb1 = geo[0]
    rb2 = geo[1]
    pb = mp[MP_PB]
    c1x = y[i1]
    c1y = y[i1 + 1]
    c2x = y[i2]
    c2y = mp[MP_A0] + y[i2 + 1]
    phi_t1, length, cos_t1, sin_t1 = mesh_frame_jit(c1x, c1y, c2x, c2y, rb1, rb2)
    # physical involute origins of the reference pair (tooth 0 on both gears)
    psi1 = mp[MP_OM1] * t + y[i1 + 2] + mp[MP_PSI10]
    psi2 = mp[MP_PSI20] - (mp[MP_OM2] * t + y[i2 + 2])
    trig_done = False
    cp1 = sp1 = cp2 = sp2 = 0.0
    # interference: nominal rolling cancels exactly (rb1·Ω1 = rb2·Ω2)
    delta_inv = (rb1 * (y[i1 + 2] + mp[MP_PSI10] - phi_t1)
                 + rb2 * (mp[MP_PSI20] - y[i2 + 2] - (phi_t1 + math.pi))
                 - length)
    s_ref = rb1 * (psi1 - phi_t1)
    m0f = math.floor((s_ref - mp[MP_SLO]) / pb)
    m0 = int(m0f)
    w1 = mp[MP_OM1] + y[n + i1 + 2]
    w2 = -(mp[MP_OM2] + y[n + i2 + 2])
    lo = length - geo[3] - mp[MP_ZBEFORE]
    hi = geo[2] + mp[MP_ZAFTER]
    # tooth numbers of the first slot's pair, m0 mod Z (float floor: integer % is slow)
    k1 = int(m0f - z1 * math.floor(m0f / z1))
    k2 = int(m0f - z2 * math.floor(m0f / z2))
    # ---- pass 1: geometry, and the elastic force in table mode
    for j in range(n_slots):
        if j > 0:
            # next slot: one tooth earlier on both gears
            k1 = k1 - 1 if k1 > 0 else z1 - 1
            k2 = k2 - 1 if k2 > 0 else z2 - 1
        pair = m0 - j
        s = s_ref - pair * pb
        if s < lo or s > hi:
            S[j, SG_ON] = 0.0
            if hybrid:
                hdelta[j] = -1.0
                hrho1[j] = hp[0]
                hrho2[j] = hp[4]
                hchi1[j] = 1.0
                hchi2[j] = 1.0
            continue
        S[j, SG_ON] = 1.0
        # involute origins of this pair: gear-1 tooth `pair` pitches back, gear-2 tooth on;
        # only a corner (rounded-tip) contact needs them
        if not trig_done and (s < length - geo[3] or s > geo[2]):
            cp1 = math.cos(psi1)
            sp1 = math.sin(psi1)
            cp2 = math.cos(psi2)
            sp2 = math.sin(psi2)
            trig_done = True
        c1n = cp1 * teeth1[k1, 0] + sp1 * teeth1[k1, 1]
        s1n = sp1 * teeth1[k1, 0] - cp1 * teeth1[k1, 1]
        c2n = cp2 * teeth2[k2, 0] - sp2 * teeth2[k2, 1]
        s2n = sp2 * teeth2[k2, 0] + cp2 * teeth2[k2, 1]
        delta, nx, ny, px, py, s_eq, chi1, chi2 = pair_contact_jit(
            s, delta_inv, c1n, s1n, c2n, s2n, c1x, c1y, c2x, c2y, cos_t1, sin_t1, length, geo)
        S[j, SG_NX] = nx
        S[j, SG_NY] = ny
        S[j, SG_PX] = px
        S[j, SG_PY] = py
        S[j, SG_REQ] = chi1 * chi2 / (chi1 + chi2) if chi1 > 0.0 and chi2 > 0.0 else 0.0
        if hybrid:
            hdelta[j] = delta
            hrho1[j] = s_eq
            hrho2[j] = length - s_eq
            hchi1[j] = max(chi1, 1e-9)
            hchi2[j] = max(chi2, 1e-9)
        else:
            k_pair, e_pair = table_lookup2_jit(s_eq, mp[MP_TAB0], mp[MP_TABD], tab_k, tab_e)
            overlap = delta - e_pair
            S[j, SG_ELASTIC] = k_pair * overlap if overlap > 0.0 else 0.0
            S[j, SG_GAP] = -overlap
    if hybrid:
        it = hybrid_forces_jit(hdelta, hrho1, hrho2, hchi1, hchi2, hp, hd1, hc1, hd2, hc2, hw,
                               hout)
        hstat[0] += 1.0
        if it < 0:
            hstat[1] += 1.0
        loaded = False
        for j in range(n_slots):
            if hout[j] > 0.0:
                loaded = True
        for j in range(n_slots):
            S[j, SG_ELASTIC] = hout[j]
            # gap of an unloaded pair under the other pairs' loads, Σ_k C_jk F_k − δ_j (the
            # solver leaves the coupling matrix C in the first n² entries of its work)
            gap = -hdelta[j]
            if loaded and hout[j] == 0.0:
                for k in range(n_slots):
                    gap += hw[j * n_slots + k] * hout[k]
            S[j, SG_GAP] = gap
    # ---- pass 2: damping, friction, forces and moments
    for j in range(n_slots):
        if S[j, SG_ON] == 0.0:
            if want_diag:
                diag[int(mp[MP_DIAGB]) + j] = 0.0
            continue
        nx = S[j, SG_NX]
        ny = S[j, SG_NY]
        px = S[j, SG_PX]
        py = S[j, SG_PY]
        # relative velocity of the contact points (gear 1 minus gear 2)
        rx1 = px - c1x
        ry1 = py - c1y
        rx2 = px - c2x
        ry2 = py - c2y
        dvx = (y[n + i1] - w1 * ry1) - (y[n + i2] - w2 * ry2)
        dvy = (y[n + i1 + 1] + w1 * rx1) - (y[n + i2 + 1] + w2 * rx2)
        approach = dvx * nx + dvy * ny
        elastic = S[j, SG_ELASTIC]
        if elastic > 0.0:
            fn = elastic + mp[MP_CHYST] * approach
            if fn < 0.0:
                fn = 0.0
        elif approach > 0.0:
            gap = max(S[j, SG_GAP], mp[MP_DTHR])
            x = S[j, SG_REQ] / (2.0 * gap)
            fn = mp[MP_KOSTER] * x * math.sqrt(x) * approach
        else:
            fn = 0.0
        if want_diag:
            diag[int(mp[MP_DIAGB]) + j] = fn
        if fn == 0.0:
            continue
        # tangent t = (ny, −nx); sliding velocity of gear 1 relative to gear 2 along t
        slide = dvx * ny - dvy * nx
        ff = mp[MP_MU] * fn * slide / math.sqrt(slide * slide + mp[MP_V0] * mp[MP_V0])
        # force on gear 2: fn·n + ff·t ; on gear 1: the opposite
        f2x = fn * nx + ff * ny
        f2y = fn * ny - ff * nx
        g[i2] += f2x
        g[i2 + 1] += f2y
        g[i1] -= f2x
        g[i1 + 1] -= f2y
        # moments (counter-clockwise positive); shaft-2 rotation counts clockwise
        g[i1 + 2] -= rx1 * f2y - ry1 * f2x
        g[i2 + 2] -= rx2 * f2y - ry2 * f2x


@njit(cache=True, inline="always", error_model="numpy")
def linear_accel_jit(y, g, minv, springs, ends, dydt, row):
    """Row ``row`` of ``dydt`` = ``[v, M⁻¹(g − K q − C v)]`` for ``y = [q, v]`` (eq. 1, linear).

    K and C are sums of spring-dampers (Annex A): ``ends[e] = (a, b)`` DOF indices,
    ``springs[e] = (k, c)``; ground connections have ``b = a`` and are listed last with
    their own count in ``ends[0, 2]`` (so both loops are branch-free). ``g`` is overwritten.
    """
    n = minv.shape[0]
    n_springs = ends.shape[0]
    n_ground = ends[0, 2]
    for e in range(n_springs - n_ground):
        a = ends[e, 0]
        b = ends[e, 1]
        f = springs[e, 0] * (y[a] - y[b]) + springs[e, 1] * (y[n + a] - y[n + b])
        g[b] += f
        g[a] -= f
    for e in range(n_springs - n_ground, n_springs):
        a = ends[e, 0]
        g[a] -= springs[e, 0] * y[a] + springs[e, 1] * y[n + a]
    for i in range(n):
        dydt[row, i] = y[n + i]
        dydt[row, n + i] = minv[i] * g[i]


def no_hybrid():
    """Placeholders of the five hybrid entries of ``P`` when the mesh uses a table."""
    return (np.zeros(HP_SIZE), np.zeros(2), np.zeros((1, 2, 2)), np.zeros(2),
            np.zeros((1, 2, 2)))


def make_work(P):
    """Scratch arrays ``W`` for :func:`rhs_jit`.

    ``W`` = (g, cos_nom, sin_nom, slip_cos, slip_sin, cage_slip, slot geometry (slots,
    SG_SIZE), hybrid solver work, hybrid δ, ρ1, ρ2, χ1, χ2, forces (slots,), hybrid counters
    [solves, non-converged solves])."""
    nb, max_balls = P[6].shape
    slots = max(int(P[9][MI_SLOTS]), 1)
    return (np.empty(P[0].shape[0]), np.empty(nb), np.empty(nb), np.empty((nb, max_balls)),
            np.empty((nb, max_balls)), np.zeros(nb), np.zeros((slots, SG_SIZE)),
            np.zeros(WORK_PER_N2 * slots * slots + WORK_PER_N * slots), np.zeros(slots),
            np.zeros(slots), np.zeros(slots), np.ones(slots), np.ones(slots), np.zeros(slots),
            np.zeros(2))


@njit(cache=True, inline="always", error_model="numpy")
def rhs_jit(t, y, dydt, row, P, diag, want_diag, W):
    """Equations of motion (module docstring); writes ``dydt[row]`` and optionally ``diag``."""
    minv = P[0]
    fext = P[2]
    n = minv.shape[0]
    g = W[0]
    for i in range(n):
        g[i] = fext[i]
    if P[8].shape[2] > 1:
        _slip_offsets(t, P, W)
        ball_cos = W[3]
        ball_sin = W[4]
    else:
        ball_cos = P[6]
        ball_sin = P[7]
    if P[4].shape[0] > 0:
        _bearing_forces(t, y, n, g, P[3], P[4], P[5], ball_cos, ball_sin, W[1], W[2], W[5],
                        diag, want_diag)
    if P[9][MI_ON] != 0:
        _mesh_forces(t, y, n, g, P[9], P[10], P[11], P[12], P[13], P[14], P[15], diag,
                     want_diag, P[17], P[18], P[19], P[20], P[21], W[6], W[7], W[8], W[9],
                     W[10], W[11], W[12], W[13], W[14])
    linear_accel_jit(y, g, minv, P[1], P[16], dydt, row)


def make_integrator_buffers(tableau_b, dim, n_diag):
    """Buffers of :func:`integrate_jit`: stage slopes (s, dim), state, stage state, diag."""
    return (np.zeros((tableau_b.shape[0], dim)), np.empty(dim), np.empty(dim), np.empty(n_diag))


@njit(cache=True, error_model="numpy", _nrt=False)
def integrate_jit(y0, t0, h, n_out, substeps, rk_a, rk_b, rk_c, P, W, B, out_y, out_diag,
                  max_disp, max_rot, trans_mask):
    """Fixed-step explicit Runge-Kutta with output every ``substeps`` steps.

    The scheme is data: ``rk_a`` (s, s) strictly lower triangular, ``rk_b`` (s,), ``rk_c`` (s,).
    ``W`` is the scratch tuple of :func:`make_work`, ``B`` that of
    :func:`make_integrator_buffers`. Sample ``m`` of ``out_y`` is the state at
    ``t0 + m·substeps·h``; ``out_diag[m]`` holds the output forces at that instant (from the
    first stage of the following step, so they cost nothing extra).

    Returns
    -------
    int
        −1 on success, else the index of the first output sample that was non-finite or
        exceeded ``max_disp`` on a translational DOF (``trans_mask``) or ``max_rot`` on a
        rotational one.
    """
    k = B[0]
    y = B[1]
    yi = B[2]
    scratch = B[3]
    ns = rk_b.shape[0]
    dim = y0.shape[0]
    n = dim // 2
    for i in range(dim):
        y[i] = y0[i]
    for m in range(n_out):
        for i in range(dim):
            out_y[m, i] = y[i]
        for i in range(n):
            limit = max_disp if trans_mask[i] else max_rot
            if not (math.isfinite(y[i]) and math.isfinite(y[n + i]) and abs(y[i]) <= limit):
                return m
        for sub in range(substeps):
            t = t0 + (m * substeps + sub) * h
            rhs_jit(t, y, k, 0, P, scratch, sub == 0, W)
            if sub == 0:
                for i in range(scratch.shape[0]):
                    out_diag[m, i] = scratch[i]
                if m == n_out - 1:
                    return -1
            for st in range(1, ns):
                for i in range(dim):
                    acc = y[i]
                    for jj in range(st):
                        acc += h * rk_a[st, jj] * k[jj, i]
                    yi[i] = acc
                rhs_jit(t + rk_c[st] * h, yi, k, st, P, scratch, False, W)
            for i in range(dim):
                acc = 0.0
                for st in range(ns):
                    acc += rk_b[st] * k[st, i]
                y[i] += h * acc
    return -1
