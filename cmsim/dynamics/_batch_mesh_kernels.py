"""Tooth-pair forces of a batch of runs, the run the inner axis: numba kernels.

The batch kernel (:mod:`cmsim.dynamics._batch_kernels`) advances B runs of one kernel layout
together. This module gives it the tooth contacts of all B runs in passes over the runs,
each a loop over the runs written branch-free (selects, clamped look-ups): the gear centres
and involute origins, the line of action, the interference, then per slot the involute
contact, the per-tooth and pair-stiffness look-ups, and the pair forces with their damping
and friction. What branches per run stays in short loops over the few runs that need it:
re-anchoring the involute origins' cos and sin (eccentric gears, rounded-tip corner
contacts), the ``atan2`` fallback of the line of action's angle.

What it gains (``benchmarks/bench_batch.py``): each run's contacts without building its
views of the stacked model (34 arrays) and scratch (17) at every call, and the passes that
read few rows (the line of action, the interference) vectorised. LLVM does not vectorise the
passes that read and write many rows: numba marks no array ``noalias``, and the runtime
overlap checks a vectorised loop would need cost, at 8-128 runs, what the vector body
saves (measured with the checks' limits raised).

Every run's numbers are those of the single-run kernel :func:`cmsim.dynamics._mesh_kernels.
mesh_forces_jit` in table mode (``MODE_TABLE``), operation for operation and in the same
order (no fastmath): a branch the single-run kernel takes is a select here, which picks the
same value, and a look-up clamps its index only where the single-run kernel returns the
table's end instead. So a run's samples do not depend on its companions (the batch's
contract), and they are those the batch kernel gave with the single-run kernels called run
by run. The hybrid contact solve (``MODE_HYBRID``) stays run by run.

Layouts: ``mp`` (MP_SIZE, B) and ``geo`` (GEO_SIZE, B) are the runs' ``m_par`` and ``geo``
with the run last; ``r`` (R_SIZE, B) holds the per-run values of one call (``R_*`` rows) and
``sg`` (slots, BS_SIZE, B) the per-slot values (the ``SG_*`` columns of the single-run
kernel's ``W.slots``, then the ``BS_*`` ones). The other arrays are the runs' :class:`KernelParams` fields stacked
run first (``S``).

The numba rule of every kernel module of :mod:`cmsim.dynamics` (in full in
:mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``, float64/int64 arrays and
scalars only, no Python objects, no random numbers, no allocation in the hot path.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, §3-4, eqs. 2 and 10.
"""

from __future__ import annotations

import math

from numba import njit

from cmsim.dynamics._mesh_kernels import (MI_CTAB, MI_ECC, MI_G1, MI_G2, MI_MUTAB, MI_TEETH,
                                          MP_A0, MP_BETA, MP_COST0, MP_DIAGB,
                                          MP_DTHR, MP_KOSTER, MP_MU, MP_OM1, MP_OM2, MP_PB,
                                          MP_PHIT0, MP_PSI10, MP_PSI20, MP_SINT0, MP_SLO,
                                          MP_TAB0, MP_TABD, MP_V0, MP_ZAFTER, MP_ZBEFORE,
                                          SG_ELASTIC, SG_GAP, SG_KPAIR, SG_NX, SG_NY, SG_ON,
                                          SG_PX, SG_PY, SG_REQ, SG_S, SG_SIZE)
from cmsim.dynamics._rotation_kernels import anchored_cos_sin_jit
from cmsim.mesh_stiffness._kernels import mesh_line_jit, pair_contact_jit

# rows of the per-run scratch ``r``: shaft centres, geometric centres, involute origins, the
# line of action (angle, length, cos, sin; R_OK 0 where its angle needs atan2), interference
# and reference position, the first slot's pair and teeth, the gears' angular speeds, the
# zone's ends, the involute origins' cos and sin (R_TRIG 1 once turned)
(R_C1X, R_C1Y, R_C2X, R_C2Y, R_GX1, R_GY1, R_GX2, R_GY2, R_PSI1, R_PSI2, R_PHI, R_LEN, R_COS,
 R_SIN, R_OK, R_DINV, R_SREF, R_M0, R_K1, R_K2, R_W1, R_W2, R_LO, R_HI, R_TRIG, R_CP1, R_SP1,
 R_CP2, R_SP2) = range(29)
R_SIZE = 29
# columns of ``sg`` after the single-run kernel's SG_* ones: the slot's teeth, corner contact
# flag, overlap, radii of curvature, and the path tables' damping and friction coefficients
(BS_K1, BS_K2, BS_CORNER, BS_DELTA, BS_CHI1, BS_CHI2, BS_CPAIR, BS_MU) = range(SG_SIZE,
                                                                          SG_SIZE + 8)
BS_SIZE = SG_SIZE + 8



@njit(cache=True, inline="always", error_model="numpy")
def _grid_place(u, m):
    """``(i, f)`` of grid position ``u`` on a table of ``m`` >= 2 points: the interval
    ``i`` (clamped to [0, m − 2]) and ``f = u − i``, as :func:`_clamped_lookup` finds them,
    so one place serves every table of that length read at ``u``."""
    uc = u if u > 0.0 else 0.0
    uc = uc if uc < m - 1 else m - 1.0
    i = int(uc)
    i = i if i < m - 2 else m - 2
    i = i if i > 0 else 0
    return i, u - i


@njit(cache=True, inline="always", error_model="numpy")
def _read_at(a, i0, m, u, i, f):
    """Table ``a[i0:i0 + m]`` (flat) at grid position ``u`` whose place is ``(i, f)``
    (:func:`_grid_place`): ``a[i0 + i] + f·(a[i0 + i + 1] − a[i0 + i])``, ``a[i0]`` for
    ``u <= 0`` and ``a[i0 + m − 1]`` for ``u >= m − 1``, as
    :func:`cmsim.mesh_stiffness._kernels.table_lookup2_jit` returns them; branch free."""
    v = a[i0 + i] + f * (a[i0 + i + 1] - a[i0 + i])
    v = a[i0 + m - 1] if u >= m - 1 else v
    return a[i0] if u <= 0.0 else v


@njit(cache=True, inline="always", error_model="numpy")
def _clamped_lookup(a, i0, m, u):
    """``a[i0 + i] + f·(a[i0 + i + 1] − a[i0 + i])`` at grid position ``u`` (``i``, ``f`` its
    whole and fractional parts), ``a[i0]`` for ``u <= 0`` and ``a[i0 + m − 1]`` for ``u >=
    m − 1``, as :func:`cmsim.mesh_stiffness._kernels.table_lookup2_jit` returns them; branch
    free (the index clamped, the ends selected), so a loop over runs vectorises. ``a`` is
    flat, ``m`` >= 2. Many tables of one length read at one ``u`` in separate loops (the
    slip grids of every ball): :func:`_grid_place` once, then :func:`_read_at` each (the
    same numbers; within one loop LLVM finds the common place itself)."""
    i, f = _grid_place(u, m)
    return _read_at(a, i0, m, u, i, f)


@njit(cache=True, error_model="numpy", _nrt=False)
def _centres(y, n, i1, i2, tau, sr, mp, r):
    """Shaft centres, involute origins ψ1, ψ2 and angular speeds of every run (the first
    lines of :func:`~cmsim.dynamics._mesh_kernels.mesh_forces_jit`)."""
    x1 = y[i1]
    y1 = y[i1 + 1]
    q1 = y[i1 + 2]
    x2 = y[i2]
    y2 = y[i2 + 1]
    q2 = y[i2 + 2]
    v1 = y[n + i1 + 2]
    v2 = y[n + i2 + 2]
    a0 = mp[MP_A0]
    om1 = mp[MP_OM1]
    om2 = mp[MP_OM2]
    p10 = mp[MP_PSI10]
    p20 = mp[MP_PSI20]
    c1x = r[R_C1X]
    c1y = r[R_C1Y]
    c2x = r[R_C2X]
    c2y = r[R_C2Y]
    psi1 = r[R_PSI1]
    psi2 = r[R_PSI2]
    w1 = r[R_W1]
    w2 = r[R_W2]
    trig = r[R_TRIG]
    for l in range(x1.shape[0]):
        c1x[l] = x1[l]
        c1y[l] = y1[l]
        c2x[l] = x2[l]
        c2y[l] = a0[l] + y2[l]
        psi1[l] = om1[l] * tau[l] + q1[l] + p10[l]
        psi2[l] = p20[l] - (om2[l] * tau[l] + q2[l])
        w1[l] = om1[l] * sr[l] + v1[l]
        w2[l] = -(om2[l] * sr[l] + v2[l])
        trig[l] = 0.0


@njit(cache=True, inline="always", error_model="numpy")
def _turn_origins(r, l, psi_anchor):
    """cos and sin of run ``l``'s involute origins ψ1, ψ2 through its anchors (``psi_anchor``
    (B, 2, AN_SIZE)), kept in ``r`` (``R_TRIG`` 1) and returned ``(cp1, sp1, cp2, sp2)``."""
    cp1, sp1 = anchored_cos_sin_jit(psi_anchor[l], 0, r[R_PSI1, l])
    cp2, sp2 = anchored_cos_sin_jit(psi_anchor[l], 1, r[R_PSI2, l])
    r[R_TRIG, l] = 1.0
    r[R_CP1, l] = cp1
    r[R_SP1, l] = sp1
    r[R_CP2, l] = cp2
    r[R_SP2, l] = sp2
    return cp1, sp1, cp2, sp2


@njit(cache=True, error_model="numpy", _nrt=False)
def _eccentric_centres(r, ecc, psi_anchor, g, i1, i2):
    """The geometric centres of eccentric gears (``MI_ECC``), run by run: the involute
    origins turned through each run's anchors (``psi_anchor`` (B, 2, AN_SIZE)); and the
    mass on each offset centre loading its shaft with m·Ω² along the offset (``g`` (n, B)),
    before the pair forces, as the single-run kernel adds them."""
    for l in range(r.shape[1]):
        cp1, sp1, cp2, sp2 = _turn_origins(r, l, psi_anchor)
        e = ecc[l]
        r[R_GX1, l] += e[0, 0] * (cp1 * e[0, 1] - sp1 * e[0, 2])
        r[R_GY1, l] += e[0, 0] * (sp1 * e[0, 1] + cp1 * e[0, 2])
        r[R_GX2, l] += e[1, 0] * (cp2 * e[1, 1] - sp2 * e[1, 2])
        r[R_GY2, l] += e[1, 0] * (sp2 * e[1, 1] + cp2 * e[1, 2])
        f1 = e[0, 3] * r[R_W1, l] * r[R_W1, l]
        f2 = e[1, 3] * r[R_W2, l] * r[R_W2, l]
        g[i1, l] += f1 * (r[R_GX1, l] - r[R_C1X, l])
        g[i1 + 1, l] += f1 * (r[R_GY1, l] - r[R_C1Y, l])
        g[i2, l] += f2 * (r[R_GX2, l] - r[R_C2X, l])
        g[i2 + 1, l] += f2 * (r[R_GY2, l] - r[R_C2Y, l])


@njit(cache=True, error_model="numpy", _nrt=False)
def _copy_centres(r):
    """Geometric centres = shaft centres (no eccentric gear)."""
    for src, dst in ((R_C1X, R_GX1), (R_C1Y, R_GY1), (R_C2X, R_GX2), (R_C2Y, R_GY2)):
        a = r[src]
        b = r[dst]
        for l in range(a.shape[0]):
            b[l] = a[l]


@njit(cache=True, error_model="numpy", _nrt=False)
def _line_of_action(r, mp, geo):
    """Line of action of every run (as :func:`~cmsim.dynamics._mesh_kernels._mesh_frame`): its
    ``atan`` series for all, ``R_OK`` 0 where the run needs ``atan2`` instead."""
    gx1 = r[R_GX1]
    gy1 = r[R_GY1]
    gx2 = r[R_GX2]
    gy2 = r[R_GY2]
    rb1 = geo[0]
    rb2 = geo[1]
    cost0 = mp[MP_COST0]
    sint0 = mp[MP_SINT0]
    phit0 = mp[MP_PHIT0]
    phi = r[R_PHI]
    length = r[R_LEN]
    cos_r = r[R_COS]
    sin_r = r[R_SIN]
    ok = r[R_OK]
    for l in range(gx1.shape[0]):
        ln, cos_t1, sin_t1 = mesh_line_jit(gx1[l], gy1[l], gx2[l], gy2[l], rb1[l], rb2[l])
        cross = cost0[l] * sin_t1 - sint0[l] * cos_t1
        dot = cost0[l] * cos_t1 + sint0[l] * sin_t1
        u = cross / dot
        u2 = u * u
        phi[l] = phit0[l] + u * (1.0 - u2 * (1.0 / 3.0 - u2 * (1.0 / 5.0 - u2 * (1.0 / 7.0))))
        ok[l] = 1.0 if dot > 0.0 and u < 1e-2 and u > -1e-2 else 0.0
        length[l] = ln
        cos_r[l] = cos_t1
        sin_r[l] = sin_t1


@njit(cache=True, error_model="numpy", _nrt=False)
def _atan2_fallback(r):
    """The line of action's angle by ``atan2`` for the runs the series does not cover."""
    for l in range(r.shape[1]):
        if r[R_OK, l] == 0.0:
            r[R_PHI, l] = math.atan2(r[R_SIN, l], r[R_COS, l])


@njit(cache=True, error_model="numpy", _nrt=False)
def _interference(y, i1, i2, z1, z2, r, mp, geo):
    """Interference, reference position, first slot's pair and teeth, and the zone's ends
    of every run (as :func:`~cmsim.dynamics._mesh_kernels.mesh_forces_jit` and
    :func:`~cmsim.dynamics._mesh_kernels._slot_geometry`)."""
    q1 = y[i1 + 2]
    q2 = y[i2 + 2]
    rb1 = geo[0]
    rb2 = geo[1]
    g2 = geo[2]
    g3 = geo[3]
    p10 = mp[MP_PSI10]
    p20 = mp[MP_PSI20]
    slo = mp[MP_SLO]
    pb = mp[MP_PB]
    zb = mp[MP_ZBEFORE]
    za = mp[MP_ZAFTER]
    phi = r[R_PHI]
    length = r[R_LEN]
    psi1 = r[R_PSI1]
    dinv = r[R_DINV]
    sref = r[R_SREF]
    m0 = r[R_M0]
    k1 = r[R_K1]
    k2 = r[R_K2]
    lo = r[R_LO]
    hi = r[R_HI]
    for l in range(q1.shape[0]):
        dinv[l] = (rb1[l] * (q1[l] + p10[l] - phi[l])
                   + rb2[l] * (p20[l] - q2[l] - (phi[l] + math.pi))
                   - length[l])
        s_ref = rb1[l] * (psi1[l] - phi[l])
        sref[l] = s_ref
        m0f = math.floor((s_ref - slo[l]) / pb[l])
        m0[l] = m0f
        k1[l] = m0f - z1 * math.floor(m0f / z1)
        k2[l] = m0f - z2 * math.floor(m0f / z2)
        lo[l] = length[l] - g3[l] - zb[l]
        hi[l] = g2[l] + za[l]


@njit(cache=True, inline="always", error_model="numpy")
def _tooth_index(k, z):
    """Tooth number ``k`` (a whole float) as an index, clamped into ``[0, z)``."""
    i = int(k) if k > 0.0 else 0
    return i if i < z else z - 1


@njit(cache=True, error_model="numpy", _nrt=False)
def _involute_slots(z1, z2, r, mp, geo, sg):
    """Every slot of every run as an involute (flank-to-flank) contact: teeth, position,
    normal, contact point, overlap and radii of curvature; ``BS_CORNER`` 1 where the pair is
    in the zone but at a rounded tip (:func:`_corner_slots` redoes those). Out-of-zone slots
    get ``SG_ON`` 0 and values nothing reads. Slot ``j`` holds the pair ``m0 − j`` (one
    tooth earlier on both gears per slot)."""
    k1 = r[R_K1]
    k2 = r[R_K2]
    m0 = r[R_M0]
    sref = r[R_SREF]
    dinv = r[R_DINV]
    length = r[R_LEN]
    cos_t = r[R_COS]
    sin_t = r[R_SIN]
    gx1 = r[R_GX1]
    gy1 = r[R_GY1]
    lo = r[R_LO]
    hi = r[R_HI]
    pb = mp[MP_PB]
    rb1 = geo[0]
    g2 = geo[2]
    g3 = geo[3]
    for j in range(sg.shape[0]):
        sj = sg[j]
        # loops that write one to three arrays each: LLVM vectorises a loop only where it
        # can check at run time that its writes alias none of its reads, and gives up on
        # the twelve outputs of one loop
        k1_out = sj[BS_K1]
        k2_out = sj[BS_K2]
        if j > 0:
            for l in range(k1.shape[0]):
                k1[l] = k1[l] - 1.0 if k1[l] > 0.0 else z1 - 1.0
            for l in range(k2.shape[0]):
                k2[l] = k2[l] - 1.0 if k2[l] > 0.0 else z2 - 1.0
        for l in range(k1.shape[0]):
            k1_out[l] = k1[l]
        for l in range(k2.shape[0]):
            k2_out[l] = k2[l]
        s_out = sj[SG_S]
        for l in range(s_out.shape[0]):
            s_out[l] = sref[l] - (m0[l] - j) * pb[l]
        on = sj[SG_ON]
        corner = sj[BS_CORNER]
        for l in range(on.shape[0]):
            s = s_out[l]
            inside = not (s < lo[l] or s > hi[l])
            on[l] = 1.0 if inside else 0.0
            corner[l] = 1.0 if inside and (s < length[l] - g3[l] or s > g2[l]) else 0.0
        nx_out = sj[SG_NX]
        ny_out = sj[SG_NY]
        delta_out = sj[BS_DELTA]
        for l in range(nx_out.shape[0]):
            nx_out[l] = -sin_t[l]
        for l in range(ny_out.shape[0]):
            ny_out[l] = cos_t[l]
        for l in range(delta_out.shape[0]):
            delta_out[l] = dinv[l]
        chi1_out = sj[BS_CHI1]
        chi2_out = sj[BS_CHI2]
        for l in range(chi1_out.shape[0]):
            sc = s_out[l] - 0.5 * dinv[l]
            chi1_out[l] = sc
            chi2_out[l] = length[l] - sc
        px_out = sj[SG_PX]
        py_out = sj[SG_PY]
        for l in range(px_out.shape[0]):
            sc = s_out[l] - 0.5 * dinv[l]
            px_out[l] = gx1[l] + rb1[l] * cos_t[l] + sc * (-sin_t[l])
            py_out[l] = gy1[l] + rb1[l] * sin_t[l] + sc * cos_t[l]


@njit(cache=True, error_model="numpy", _nrt=False)
def _corner_slots(z1, z2, r, sg, geo_runs, teeth1, teeth2, psi_anchor):
    """The slots whose pair is at a rounded tip (``BS_CORNER``), run by run and slot by slot:
    the involute origins turned at the run's first such slot of the call (its anchors
    ``psi_anchor`` (B, 2, AN_SIZE)), then :func:`~cmsim.mesh_stiffness._kernels.
    pair_contact_jit`."""
    for l in range(r.shape[1]):
        for j in range(sg.shape[0]):
            sj = sg[j]
            if sj[BS_CORNER, l] == 0.0:
                continue
            if r[R_TRIG, l] == 0.0:
                _turn_origins(r, l, psi_anchor)
            cp1 = r[R_CP1, l]
            sp1 = r[R_SP1, l]
            cp2 = r[R_CP2, l]
            sp2 = r[R_SP2, l]
            k1 = _tooth_index(sj[BS_K1, l], z1)
            k2 = _tooth_index(sj[BS_K2, l], z2)
            t1 = teeth1[l]
            t2 = teeth2[l]
            c1n = cp1 * t1[k1, 0] + sp1 * t1[k1, 1]
            s1n = sp1 * t1[k1, 0] - cp1 * t1[k1, 1]
            c2n = cp2 * t2[k2, 0] - sp2 * t2[k2, 1]
            s2n = sp2 * t2[k2, 0] + cp2 * t2[k2, 1]
            delta, nx, ny, px, py, _s_eq, chi1, chi2 = pair_contact_jit(
                sj[SG_S, l], r[R_DINV, l], c1n, s1n, c2n, s2n, r[R_GX1, l], r[R_GY1, l],
                r[R_GX2, l], r[R_GY2, l], r[R_COS, l], r[R_SIN, l], r[R_LEN, l], geo_runs[l])
            sj[SG_NX, l] = nx
            sj[SG_NY, l] = ny
            sj[SG_PX, l] = px
            sj[SG_PY, l] = py
            sj[BS_DELTA, l] = delta
            sj[BS_CHI1, l] = chi1
            sj[BS_CHI2, l] = chi2


@njit(cache=True, error_model="numpy", _nrt=False)
def _slot_loads(z1, z2, mp, sg, teeth_on, own1, own2, m_t, tk1, te1, tk2, te2, m_tab,
                tab_k, tab_e):
    """Every slot's elastic force, gap, pair stiffness and equivalent radius of every run
    (the table-mode end of :func:`~cmsim.dynamics._mesh_kernels._slot_geometry`): per-tooth
    factor and separation, the pair stiffness table. The tables flat: ``tk1`` …
    (B·Z·m_t,), ``tab_k``, ``tab_e`` (B·m_tab,). Gathers: a scalar loop (LLVM versions no
    loop whose reads it cannot bound). A tooth whose flag in ``own1``/``own2`` is 0
    has the nominal tables (factor 1, separation 0: what their look-up returns, to the
    bit), so it reads none: a faulty gear has one or a few teeth of its own, and reading
    every tooth's tables (230 kB a record) was the largest share of the contacts' time."""
    x0 = mp[MP_TAB0]
    dx = mp[MP_TABD]
    for j in range(sg.shape[0]):
        sj = sg[j]
        k1r = sj[BS_K1]
        k2r = sj[BS_K2]
        delta_r = sj[BS_DELTA]
        chi1_r = sj[BS_CHI1]
        chi2_r = sj[BS_CHI2]
        s_r = sj[SG_S]
        req_out = sj[SG_REQ]
        el_out = sj[SG_ELASTIC]
        gap_out = sj[SG_GAP]
        kp_out = sj[SG_KPAIR]
        on = sj[SG_ON]
        for l in range(x0.shape[0]):
            if on[l] == 0.0:              # out of the zone: nothing reads its loads
                continue
            u = (s_r[l] - x0[l]) / dx[l]
            delta = delta_r[l]
            f_teeth = 1.0
            if teeth_on:
                k1 = _tooth_index(k1r[l], z1)
                k2 = _tooth_index(k2r[l], z2)
                fa, ea, fb, eb = 1.0, 0.0, 1.0, 0.0
                if own1[l * z1 + k1] != 0.0:
                    fa = _clamped_lookup(tk1, (l * z1 + k1) * m_t, m_t, u)
                    ea = _clamped_lookup(te1, (l * z1 + k1) * m_t, m_t, u)
                if own2[l * z2 + k2] != 0.0:
                    fb = _clamped_lookup(tk2, (l * z2 + k2) * m_t, m_t, u)
                    eb = _clamped_lookup(te2, (l * z2 + k2) * m_t, m_t, u)
                f_teeth = fa * fb
                delta -= ea + eb
            chi1 = chi1_r[l]
            chi2 = chi2_r[l]
            req_out[l] = chi1 * chi2 / (chi1 + chi2) if chi1 > 0.0 and chi2 > 0.0 else 0.0
            k_pair = _clamped_lookup(tab_k, l * m_tab, m_tab, u)
            e_pair = _clamped_lookup(tab_e, l * m_tab, m_tab, u)
            k_pair *= f_teeth
            overlap = delta - e_pair
            el_out[l] = k_pair * overlap if overlap > 0.0 else 0.0
            gap_out[l] = -overlap
            kp_out[l] = k_pair


@njit(cache=True, error_model="numpy", _nrt=False)
def _path_table(col, mp, sg, table):
    """Column ``col`` of every slot = each run's ``table`` (B, m) at the slot's position (a
    pair's damping or friction coefficient along the path); a scalar loop (gathers)."""
    m = table.shape[1]
    flat = table.reshape(-1)
    x0 = mp[MP_TAB0]
    dx = mp[MP_TABD]
    for j in range(sg.shape[0]):
        out = sg[j, col]
        s_r = sg[j, SG_S]
        for l in range(out.shape[0]):
            out[l] = _clamped_lookup(flat, l * m, m, (s_r[l] - x0[l]) / dx[l])


@njit(cache=True, error_model="numpy", _nrt=False)
def _slot_forces(y, n, i1, i2, g, r, mp, sg, ctab_on, mutab_on, diag, want_diag):
    """Every slot's normal force with its damping and smoothed Coulomb friction, and their
    forces and moments on both gears, for every run, slot after slot (as
    :func:`~cmsim.dynamics._mesh_kernels._apply_pair_forces`: a run whose force is zero
    keeps its forces untouched). Columns ``BS_CPAIR``, ``BS_MU`` hold the path tables'
    values where ``ctab_on``, ``mutab_on``."""
    c1x = r[R_C1X]
    c1y = r[R_C1Y]
    c2x = r[R_C2X]
    c2y = r[R_C2Y]
    w1 = r[R_W1]
    w2 = r[R_W2]
    u1x = y[n + i1]
    u1y = y[n + i1 + 1]
    u2x = y[n + i2]
    u2y = y[n + i2 + 1]
    beta = mp[MP_BETA]
    dthr = mp[MP_DTHR]
    koster = mp[MP_KOSTER]
    mu_c = mp[MP_MU]
    v0 = mp[MP_V0]
    g1x = g[i1]
    g1y = g[i1 + 1]
    g1t = g[i1 + 2]
    g2x = g[i2]
    g2y = g[i2 + 1]
    g2t = g[i2 + 2]
    d0 = int(mp[MP_DIAGB, 0])
    for j in range(sg.shape[0]):
        sj = sg[j]
        on = sj[SG_ON]
        nx_r = sj[SG_NX]
        ny_r = sj[SG_NY]
        px_r = sj[SG_PX]
        py_r = sj[SG_PY]
        el_r = sj[SG_ELASTIC]
        gap_r = sj[SG_GAP]
        kp_r = sj[SG_KPAIR]
        req_r = sj[SG_REQ]
        cp_r = sj[BS_CPAIR]
        mu_r = sj[BS_MU]
        d_out = diag[d0 + j]
        for l in range(on.shape[0]):
            if on[l] == 0.0:
                # out of the zone: no force (the single-run kernel's zero), forces untouched
                if want_diag:
                    d_out[l] = 0.0
                continue
            nx = nx_r[l]
            ny = ny_r[l]
            rx1 = px_r[l] - c1x[l]
            ry1 = py_r[l] - c1y[l]
            rx2 = px_r[l] - c2x[l]
            ry2 = py_r[l] - c2y[l]
            dvx = (u1x[l] - w1[l] * ry1) - (u2x[l] - w2[l] * ry2)
            dvy = (u1y[l] + w1[l] * rx1) - (u2y[l] + w2[l] * rx2)
            approach = dvx * nx + dvy * ny
            elastic = el_r[l]
            c_pair = cp_r[l] if ctab_on else beta[l] * kp_r[l]
            fe = elastic + c_pair * approach
            fe = 0.0 if fe < 0.0 else fe
            gap = max(gap_r[l], dthr[l])
            x = req_r[l] / (2.0 * gap)
            fk = koster[l] * x * math.sqrt(x) * approach
            fn = fe if elastic > 0.0 else (fk if approach > 0.0 else 0.0)
            if want_diag:
                d_out[l] = fn
            slide = dvx * ny - dvy * nx
            mu = mu_r[l] if mutab_on else mu_c[l]
            ff = mu * fn * slide / math.sqrt(slide * slide + v0[l] * v0[l])
            # force on gear 2: fn·n + ff·t ; on gear 1: the opposite
            f2x = fn * nx + ff * ny
            f2y = fn * ny - ff * nx
            loaded = fn != 0.0
            g2x[l] = g2x[l] + f2x if loaded else g2x[l]
            g2y[l] = g2y[l] + f2y if loaded else g2y[l]
            g1x[l] = g1x[l] - f2x if loaded else g1x[l]
            g1y[l] = g1y[l] - f2y if loaded else g1y[l]
            # moments (counter-clockwise positive); shaft-2 rotation counts clockwise
            g1t[l] = g1t[l] - (rx1 * f2y - ry1 * f2x) if loaded else g1t[l]
            g2t[l] = g2t[l] - (rx2 * f2y - ry2 * f2x) if loaded else g2t[l]


@njit(cache=True, inline="always", error_model="numpy")
def mesh_forces_batch_jit(y, n, g, S, mp, geo, tau, sr, psi_anchor, r, sg, own1, own2,
                          diag, want_diag):
    """Tooth-pair forces of every run in table mode (the single-run
    :func:`~cmsim.dynamics._mesh_kernels.mesh_forces_jit` for ``MODE_TABLE``, run by run the
    same numbers): ``y`` (dim, B) the states, ``g`` (n, B) their forces, ``diag`` (n_diag,
    B), ``tau``, ``sr`` (B,) each run's equivalent time and relative speed, ``psi_anchor``
    (B, 2, AN_SIZE) the involute origins' anchors; ``S`` the stacked KernelParams (run
    first), ``mp``, ``geo``, ``r``, ``sg`` as the module docstring lays them out;
    ``own1``, ``own2`` (B·Z) 1 where a run's tooth has per-tooth tables of its own
    (:func:`cmsim.dynamics.batch._faulty_teeth`)."""
    m_int = S.m_int[0]
    i1 = m_int[MI_G1]
    i2 = m_int[MI_G2]
    z1 = S.teeth1.shape[1]
    z2 = S.teeth2.shape[1]
    teeth_on = m_int[MI_TEETH] != 0
    _centres(y, n, i1, i2, tau, sr, mp, r)
    _copy_centres(r)
    if m_int[MI_ECC] != 0:
        _eccentric_centres(r, S.ecc, psi_anchor, g, i1, i2)
    _line_of_action(r, mp, geo)
    _atan2_fallback(r)
    _interference(y, i1, i2, z1, z2, r, mp, geo)
    # the tables flat (C-contiguous views, nothing copied); per-tooth tables are (1, 1)
    # placeholders when MI_TEETH is off, and never read then
    m_t = S.tk1.shape[2]
    tk1 = S.tk1.reshape(-1)
    te1 = S.te1.reshape(-1)
    tk2 = S.tk2.reshape(-1)
    te2 = S.te2.reshape(-1)
    m_tab = S.tab_k.shape[1]
    tab_k = S.tab_k.reshape(-1)
    tab_e = S.tab_e.reshape(-1)
    _involute_slots(z1, z2, r, mp, geo, sg)
    _corner_slots(z1, z2, r, sg, S.geo, S.teeth1, S.teeth2, psi_anchor)
    _slot_loads(z1, z2, mp, sg, teeth_on, own1, own2, m_t, tk1, te1, tk2, te2, m_tab,
                tab_k, tab_e)
    ctab_on = m_int[MI_CTAB] != 0
    mutab_on = m_int[MI_MUTAB] != 0
    if ctab_on:
        _path_table(BS_CPAIR, mp, sg, S.c_tab)
    if mutab_on:
        _path_table(BS_MU, mp, sg, S.mu_tab)
    _slot_forces(y, n, i1, i2, g, r, mp, sg, ctab_on, mutab_on, diag, want_diag)
