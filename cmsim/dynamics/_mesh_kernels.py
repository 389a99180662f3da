"""Tooth-pair forces of the equations of motion (paper 001 §3-4, eq. 2 and 10): numba kernels.

:func:`mesh_forces_jit` gives the forces of the tooth pairs in the potential-contact zone:
exact rigid-body geometry, the elastic force from the pair stiffness table or from the
on-line hybrid contact solve (model A), stiffness-proportional or Koster squeeze damping and
smoothed Coulomb friction. The layouts of the mesh integers ``m_int`` (``MI_*``) and
parameters ``m_par`` (``MP_*``, which also carry the run's slip, defect-track and profile grid
spacings) of :class:`~cmsim.dynamics._rhs_kernels.KernelParams`, and of the per-slot scratch
(``SG_*``), are defined here. The gears' involute origin angles come from their anchors
(:mod:`cmsim.dynamics._rotation_kernels`); the line of action's angle is a short ``atan``
series about its nominal value.

The numba rule of every kernel module of :mod:`cmsim.dynamics` (in full in
:mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``, float64/int64 arrays and
scalars only, no Python objects, no random numbers, no allocation in the hot path.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, §3-4, eqs. 2 and 10.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from cmsim.dynamics._rotation_kernels import anchored_cos_sin_jit
from cmsim.mesh_stiffness._hybrid_kernels import HP_SIZE, hybrid_forces_jit
from cmsim.mesh_stiffness._kernels import mesh_line_jit, pair_contact_jit, table_lookup2_jit

# m_int entries: DOF index of each gear's x, number of slots, mesh on, elastic-force mode,
# per-tooth tables on, eccentricity on, speed/torque profile on, DOF of the output torque,
# off-size balls present
MI_G1, MI_G2, MI_SLOTS, MI_ON, MI_MODE, MI_TEETH, MI_ECC, MI_PROFILE, MI_TDOF = range(9)
MI_FAULTY_BALLS = 9     # 1 when any bearing has off-size balls
MI_MUTAB = 10           # 1 when the friction coefficient follows ``mu_tab`` along the path
MI_CTAB = 11            # 1 when the pair damping follows ``c_tab`` along the path
MI_BALL_SLIP = 12       # 1 when the slip grid moves the balls (0: cages only, or no slip)
MI_SIZE = 13
MODE_TABLE, MODE_HYBRID = 0, 1
# columns of the per-slot scratch ``W.slots`` of the mesh kernel
SG_ON, SG_NX, SG_NY, SG_PX, SG_PY, SG_REQ, SG_ELASTIC, SG_GAP, SG_KPAIR, SG_S = range(10)
SG_SIZE = 10
# m_par entries. MP_BETA: stiffness-proportional mesh damping coefficient β (s): a loaded
# pair of stiffness k_j gets the viscous coefficient β·k_j, so the mesh as a whole has
# 2ξ√(k̄·M_eq) on average whatever the number of pairs in contact. MP_COST1, MP_SINT1: cos
# and sin of the nominal line-of-action angle.
(MP_A0, MP_PSI10, MP_PSI20, MP_PB, MP_SLO, MP_OM1, MP_OM2, MP_MU, MP_V0, MP_BETA, MP_KOSTER,
 MP_DTHR, MP_TAB0, MP_TABD, MP_JDT, MP_DIAGB, MP_ZBEFORE, MP_ZAFTER, MP_PHIT0, MP_COST0,
 MP_SINT0, MP_PT0, MP_PDT, MP_OMREF, MP_TDT) = range(25)
MP_SIZE = 25


@njit(cache=True, inline="always", error_model="numpy")
def _mesh_frame(c1x, c1y, c2x, c2y, rb1, rb2, mp):
    """Line of action for the gear centres C1, C2 (as
    :func:`cmsim.mesh_stiffness._kernels.mesh_frame_jit`, with its angle from an ``atan``
    series about the nominal angle instead of ``atan2``)."""
    length, cos_t1, sin_t1 = mesh_line_jit(c1x, c1y, c2x, c2y, rb1, rb2)
    cross = mp[MP_COST0] * sin_t1 - mp[MP_SINT0] * cos_t1
    dot = mp[MP_COST0] * cos_t1 + mp[MP_SINT0] * sin_t1
    u = cross / dot
    if dot > 0.0 and u < 1e-2 and u > -1e-2:
        u2 = u * u
        phi = mp[MP_PHIT0] + u * (1.0 - u2 * (1.0 / 3.0 - u2 * (1.0 / 5.0 - u2 * (1.0 / 7.0))))
    else:
        phi = math.atan2(sin_t1, cos_t1)
    return phi, length, cos_t1, sin_t1


@njit(cache=True, inline="always", error_model="numpy")
def _tooth_lookup(tk, te, k, s, x0, dx):
    """Factor and extra separation of tooth ``k`` at table position ``s`` (linear, clamped)."""
    m = tk.shape[1]
    u = (s - x0) / dx
    if u <= 0.0:
        return tk[k, 0], te[k, 0]
    if u >= m - 1:
        return tk[k, m - 1], te[k, m - 1]
    i = int(u)
    f = u - i
    return (tk[k, i] + f * (tk[k, i + 1] - tk[k, i]),
            te[k, i] + f * (te[k, i + 1] - te[k, i]))


@njit(cache=True, inline="always", error_model="numpy")
def mesh_forces_jit(t, sr, y, n, g, P, W, diag, want_diag):
    """Forces of the tooth pairs in the potential-contact zone: exact rigid-body geometry,
    elastic force from the table (``MI_MODE`` 0) or from the on-line hybrid contact solve
    (1, paper 001 model A), stiffness-proportional hysteretic damping (``MP_BETA``) or Koster
    squeeze damping, smoothed Coulomb friction. ``t`` is the equivalent time τ of the
    nominal rotation and ``sr`` the speed over the reference speed (1 at constant speed).

    Faults: per-tooth stiffness factors and separations (``MI_TEETH``; on the on-line solve a
    factor f of a pair becomes the extra compliance (1/f − 1)/k of its own λ, k the run's
    table stiffness at s, so a pair alone in contact is f times as stiff), and eccentric gears
    (``MI_ECC``: the contact geometry uses each gear's geometric centre, turning about its
    shaft; moments and contact velocities use the shaft centre; the mass on that centre,
    ``ecc[:, 3]``, loads its shaft with m·Ω² along the offset).

    Pass 1 (:func:`_slot_geometry`) stores each slot's geometry in ``W.slots`` (columns
    ``SG_*``); in hybrid mode the interferences of all slots are then solved together
    (:func:`_hybrid_slot_forces`; out-of-zone slots enter with a large negative interference,
    so they stay unloaded); pass 2 (:func:`_apply_pair_forces`) applies the forces.
    Inlined into the integrator, so taking the arrays out of ``P`` and ``W`` costs nothing."""
    m_int, mp, geo = P.m_int, P.m_par, P.geo
    i1 = m_int[MI_G1]
    i2 = m_int[MI_G2]
    rb1 = geo[0]
    rb2 = geo[1]
    c1x = y[i1]
    c1y = y[i1 + 1]
    c2x = y[i2]
    c2y = mp[MP_A0] + y[i2 + 1]
    # physical involute origins of the reference pair (tooth 0 on both gears)
    psi1 = mp[MP_OM1] * t + y[i1 + 2] + mp[MP_PSI10]
    psi2 = mp[MP_PSI20] - (mp[MP_OM2] * t + y[i2 + 2])
    w1 = mp[MP_OM1] * sr + y[n + i1 + 2]
    w2 = -(mp[MP_OM2] * sr + y[n + i2 + 2])
    trig_done = False
    cp1 = sp1 = cp2 = sp2 = 0.0
    # geometric centres (the shaft centres unless a gear is eccentric)
    gx1 = c1x
    gy1 = c1y
    gx2 = c2x
    gy2 = c2y
    if m_int[MI_ECC] != 0:
        ecc = P.ecc
        cp1, sp1 = anchored_cos_sin_jit(W.psi, 0, psi1)
        cp2, sp2 = anchored_cos_sin_jit(W.psi, 1, psi2)
        trig_done = True
        gx1 += ecc[0, 0] * (cp1 * ecc[0, 1] - sp1 * ecc[0, 2])
        gy1 += ecc[0, 0] * (sp1 * ecc[0, 1] + cp1 * ecc[0, 2])
        gx2 += ecc[1, 0] * (cp2 * ecc[1, 1] - sp2 * ecc[1, 2])
        gy2 += ecc[1, 0] * (sp2 * ecc[1, 1] + cp2 * ecc[1, 2])
        # the mass on each offset centre turns about its shaft: m·Ω²·(offset) on the shaft
        f1 = ecc[0, 3] * w1 * w1
        f2 = ecc[1, 3] * w2 * w2
        g[i1] += f1 * (gx1 - c1x)
        g[i1 + 1] += f1 * (gy1 - c1y)
        g[i2] += f2 * (gx2 - c2x)
        g[i2 + 1] += f2 * (gy2 - c2y)
    phi_t1, length, cos_t1, sin_t1 = _mesh_frame(gx1, gy1, gx2, gy2, rb1, rb2, mp)
    # interference: nominal rolling cancels exactly (rb1·Ω1 = rb2·Ω2)
    delta_inv = (rb1 * (y[i1 + 2] + mp[MP_PSI10] - phi_t1)
                 + rb2 * (mp[MP_PSI20] - y[i2 + 2] - (phi_t1 + math.pi))
                 - length)
    s_ref = rb1 * (psi1 - phi_t1)
    _slot_geometry(P, W, s_ref, delta_inv, psi1, psi2, trig_done, cp1, sp1, cp2, sp2, gx1, gy1,
                   gx2, gy2, cos_t1, sin_t1, length)
    if m_int[MI_MODE] == MODE_HYBRID:
        _hybrid_slot_forces(P, W)
    _apply_pair_forces(y, n, g, P, W, diag, want_diag, c1x, c1y, c2x, c2y, w1, w2)


@njit(cache=True, inline="always", error_model="numpy")
def _slot_geometry(P, W, s_ref, delta_inv, psi1, psi2, trig_done, cp1, sp1, cp2, sp2, gx1, gy1,
                   gx2, gy2, cos_t1, sin_t1, length):
    """Pass 1 of :func:`mesh_forces_jit`: the contact geometry of every slot in ``W.slots``,
    with the elastic force in table mode or the hybrid solve's inputs in hybrid mode.

    Slot ``j`` holds the pair ``m0 − j`` (one tooth earlier on both gears per slot), at
    ``s = s_ref − pair·p_b`` on the line of action; the gears' involute origins (``cp1`` …
    ``sp2``, unless ``trig_done``) are turned only when a corner (rounded-tip) contact needs
    them."""
    m_int, mp, geo, tab_k, tab_e = P.m_int, P.m_par, P.geo, P.tab_k, P.tab_e
    teeth1, teeth2, hp = P.teeth1, P.teeth2, P.hp
    tk1, tk2, te1, te2 = P.tk1, P.tk2, P.te1, P.te2
    S, hdelta, hrho1, hrho2 = W.slots, W.hdelta, W.hrho1, W.hrho2
    hchi1, hchi2, hext, psi_anchor = W.hchi1, W.hchi2, W.hext, W.psi
    z1 = teeth1.shape[0]
    z2 = teeth2.shape[0]
    n_slots = m_int[MI_SLOTS]
    hybrid = m_int[MI_MODE] == MODE_HYBRID
    teeth_on = m_int[MI_TEETH] != 0
    pb = mp[MP_PB]
    m0f = math.floor((s_ref - mp[MP_SLO]) / pb)
    m0 = int(m0f)
    lo = length - geo[3] - mp[MP_ZBEFORE]
    hi = geo[2] + mp[MP_ZAFTER]
    # tooth numbers of the first slot's pair, m0 mod Z (float floor: integer % is slow)
    k1 = int(m0f - z1 * math.floor(m0f / z1))
    k2 = int(m0f - z2 * math.floor(m0f / z2))
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
                hext[j] = 0.0
                hrho1[j] = hp[0]
                hrho2[j] = hp[4]
                hchi1[j] = 1.0
                hchi2[j] = 1.0
            continue
        S[j, SG_ON] = 1.0
        S[j, SG_S] = s
        # involute origins of this pair: gear-1 tooth `pair` pitches back, gear-2 tooth on;
        # only a corner (rounded-tip) contact needs them
        if not trig_done and (s < length - geo[3] or s > geo[2]):
            cp1, sp1 = anchored_cos_sin_jit(psi_anchor, 0, psi1)
            cp2, sp2 = anchored_cos_sin_jit(psi_anchor, 1, psi2)
            trig_done = True
        c1n = cp1 * teeth1[k1, 0] + sp1 * teeth1[k1, 1]
        s1n = sp1 * teeth1[k1, 0] - cp1 * teeth1[k1, 1]
        c2n = cp2 * teeth2[k2, 0] - sp2 * teeth2[k2, 1]
        s2n = sp2 * teeth2[k2, 0] + cp2 * teeth2[k2, 1]
        delta, nx, ny, px, py, s_eq, chi1, chi2 = pair_contact_jit(
            s, delta_inv, c1n, s1n, c2n, s2n, gx1, gy1, gx2, gy2, cos_t1, sin_t1, length, geo)
        f_teeth = 1.0
        if teeth_on:
            fa, ea = _tooth_lookup(tk1, te1, k1, s, mp[MP_TAB0], mp[MP_TABD])
            fb, eb = _tooth_lookup(tk2, te2, k2, s, mp[MP_TAB0], mp[MP_TABD])
            f_teeth = fa * fb
            delta -= ea + eb
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
            hext[j] = 0.0
            if f_teeth < 1.0:
                k_pair, e_pair = table_lookup2_jit(s, mp[MP_TAB0], mp[MP_TABD], tab_k, tab_e)
                if k_pair > 0.0:
                    hext[j] = (1.0 / max(f_teeth, 1e-6) - 1.0) / k_pair
        else:
            # tables are functions of the pair's position s on the line of action (a corner
            # contact's s_eq falls inside the involute path, where the stiffer involute values
            # sit: read there, B doubled the corner forces, issue 9 model A/B/C)
            k_pair, e_pair = table_lookup2_jit(s, mp[MP_TAB0], mp[MP_TABD], tab_k, tab_e)
            k_pair *= f_teeth
            overlap = delta - e_pair
            S[j, SG_ELASTIC] = k_pair * overlap if overlap > 0.0 else 0.0
            S[j, SG_GAP] = -overlap
            S[j, SG_KPAIR] = k_pair


@njit(cache=True, inline="always", error_model="numpy")
def _hybrid_slot_forces(P, W):
    """The on-line hybrid contact solve of all slots together (paper 001 eq. 2, model A):
    each slot's elastic force, secant stiffness F/δ (its share of the mesh damping) and the
    gap of an unloaded pair under the other pairs' loads, into ``W.slots``."""
    S, hw, hdelta, hout, hstat = W.slots, W.hwork, W.hdelta, W.hout, W.hstat
    n_slots = P.m_int[MI_SLOTS]
    it = hybrid_forces_jit(hdelta, W.hrho1, W.hrho2, W.hchi1, W.hchi2, P.hp, P.hd1, P.hc1,
                           P.hd2, P.hc2, W.hext, hw, hout)
    hstat[0] += 1.0
    if it < 0:
        hstat[1] += 1.0
    loaded = False
    for j in range(n_slots):
        if hout[j] > 0.0:
            loaded = True
    for j in range(n_slots):
        S[j, SG_ELASTIC] = hout[j]
        # secant stiffness of a loaded pair, F/δ, for its share of the mesh damping
        S[j, SG_KPAIR] = hout[j] / hdelta[j] if hout[j] > 0.0 and hdelta[j] > 0.0 else 0.0
        # gap of an unloaded pair under the other pairs' loads, Σ_k C_jk F_k − δ_j (the
        # solver leaves the coupling matrix C in the first n² entries of its work)
        gap = -hdelta[j]
        if loaded and hout[j] == 0.0:
            for k in range(n_slots):
                gap += hw[j * n_slots + k] * hout[k]
        S[j, SG_GAP] = gap


@njit(cache=True, inline="always", error_model="numpy")
def _apply_pair_forces(y, n, g, P, W, diag, want_diag, c1x, c1y, c2x, c2y, w1, w2):
    """Pass 2 of :func:`mesh_forces_jit`: each loaded (or squeezing) slot's normal force with
    its damping, its smoothed Coulomb friction, and their forces and moments on both gears
    (``w1``, ``w2``: the gears' angular speeds, counter-clockwise positive)."""
    m_int, mp, S = P.m_int, P.m_par, W.slots
    i1 = m_int[MI_G1]
    i2 = m_int[MI_G2]
    for j in range(m_int[MI_SLOTS]):
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
            if m_int[MI_CTAB] != 0:
                c_pair, _ = table_lookup2_jit(S[j, SG_S], mp[MP_TAB0], mp[MP_TABD], P.c_tab,
                                              P.c_tab)
            else:
                c_pair = mp[MP_BETA] * S[j, SG_KPAIR]
            fn = elastic + c_pair * approach
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
        mu = mp[MP_MU]
        if m_int[MI_MUTAB] != 0:
            mu, _ = table_lookup2_jit(S[j, SG_S], mp[MP_TAB0], mp[MP_TABD], P.mu_tab, P.mu_tab)
        ff = mu * fn * slide / math.sqrt(slide * slide + mp[MP_V0] * mp[MP_V0])
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


def no_hybrid():
    """Placeholders ``(hp, hd1, hc1, hd2, hc2)`` of the hybrid fields when the mesh uses a
    table."""
    return (np.zeros(HP_SIZE), np.zeros(2), np.zeros((1, 2, 2)), np.zeros(2),
            np.zeros((1, 2, 2)))
