"""A batch of runs of one rig integrated in lockstep: numba kernels, the record the inner axis.

B runs that share their kernel layout (:func:`cmsim.dynamics.batch.kernel_layout`: the same
DOFs, bearings, slots, fault and profile switches and table sizes) and differ in their values
(operating point, clearances, faults, slip, profile) advance together, one step of all B at
a time. Their states are ``(dim, B)`` arrays, the run index innermost, so the parts of the
right-hand side that are the same arithmetic on different numbers run as loops over the B
runs that numba vectorises (SIMD lanes): the linear springs and dampers, the healthy Hertz
ball sums of every bearing, the Runge-Kutta stage combinations. The tooth contacts from
their tables (:mod:`cmsim.dynamics._batch_mesh_kernels`), the slip and the speed profile
run in passes over the runs as well, branch-free where the single-run kernel branches, and
so does the change race and ball defects make (:func:`_defect_changes`: the single-run
kernel's functions on each run's numbers as they lie). The parts that branch per run in
depth — a bearing with an off-size ball, taken ball by ball, and the on-line hybrid contact
solve — call the single-run kernels of :mod:`cmsim.dynamics._rhs_kernels` on each run's
views (:func:`lane_params`, :func:`lane_work`: some thirty arrays re-viewed per run and
right-hand side, which costs more than a defect's arithmetic), so their physics is written
once.

Independence of the runs (the contract :mod:`cmsim.dynamics.batch` tests): every operation on
run ``l`` reads only run ``l``'s numbers, in the same order whatever B is and wherever the run
sits in the batch (no fastmath: no reassociation, no fused multiply-add a vector body would
use and its scalar remainder not), so a run's samples are bit-identical in any batch. They
agree with the single-run kernel to rounding (its healthy ball loop is compiled with
fastmath, which reorders the ball sum).

A run that diverges (a non-finite state, or a displacement or rotation beyond its limit at an
output sample) is flagged in ``status`` with the sample index and restarted from its start
state, so the others finish; its samples are not used.

The numba rule of every kernel module of :mod:`cmsim.dynamics` (in full in
:mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``, float64/int64 arrays and
scalars only, no Python objects, no random numbers, no allocation in the hot path.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmsim.dynamics._batch_mesh_kernels import _grid_place, _read_at, mesh_forces_batch_jit
from cmsim.dynamics._bearing_kernels import (BI_DEF0, BI_FAULTY, BI_NB, BI_NDEF, BI_T, BI_X,
                                             BI_Y, BP_C, BP_CAGE, BP_DAMP, BP_K, BP_P, BP_PHASE,
                                             BP_SENSE, BP_SPIN, _defect_correction,
                                             track_gains_jit)
from cmsim.dynamics._mesh_kernels import (MI_BALL_SLIP, MI_FAULTY_BALLS, MI_MODE, MI_ON,
                                          MI_PROFILE, MI_TDOF, MODE_TABLE, MP_JDT, MP_OMREF,
                                          MP_PDT, MP_PT0, MP_TDT, mesh_forces_jit)
from cmsim.dynamics._rhs_kernels import KernelParams, Work, defect_forces_jit, profile_at
from cmsim.dynamics._rotation_kernels import (AN_ANGLE, AN_COS, AN_SIN, AN_VALID, ANCHOR_RAD,
                                              anchored_cos_sin_jit, rotate_small_jit)


class LaneParams(NamedTuple):
    """The model values the vectorised loops read, the run innermost (SI units)."""

    minv: np.ndarray      # (n, B) inverse masses
    springs: np.ndarray   # (e, 2, B) stiffness and damping of each spring-damper
    fext: np.ndarray      # (n, B) constant external load
    omega: np.ndarray     # (n, B) nominal rotation speeds, rad/s
    b_par: np.ndarray     # (nb, BP_SIZE, B) bearing parameters
    b_cos: np.ndarray     # (nb, max_balls, B) cos of each ball's nominal offset
    b_sin: np.ndarray     # (nb, max_balls, B) sin
    m_par: np.ndarray     # (MP_SIZE, B) mesh parameters
    geo: np.ndarray       # (GEO_SIZE, B) tooth geometry


class BatchBuffers(NamedTuple):
    """Buffers of :func:`integrate_batch_jit` (the run innermost)."""

    k: np.ndarray         # (s, dim, B) stage slopes
    y: np.ndarray         # (dim, B) state; the start state on entry to the first chunk
    yi: np.ndarray        # (dim, B) stage state
    y0: np.ndarray        # (dim, B) start states (a diverged run restarts from it)
    diag: np.ndarray      # (n_diag, B) output forces of the current step
    tau: np.ndarray       # (B,) equivalent time of the nominal rotation, s
    sr: np.ndarray        # (B,) speed over the reference speed
    ar: np.ndarray        # (B,) acceleration over the reference speed, 1/s
    ang: np.ndarray       # (B,) the current bearing's cage angle, rad
    cc: np.ndarray        # (B,) cos, sin of the current bearing's cage angle
    sc: np.ndarray
    xr: np.ndarray        # (B,) the inner ring's offset in the cage frame, m
    yr: np.ndarray
    fx: np.ndarray        # (B,) the ball sums in the cage frame
    fy: np.ndarray
    ok: np.ndarray        # (B,) 1 where a run's state is finite and within its limits
    y1: np.ndarray        # (dim,) one run's state, contiguous
    g1: np.ndarray        # (n,) its forces
    d1: np.ndarray        # (n_diag,) its output forces
    mesh: np.ndarray      # (R_SIZE, B) the tooth contacts' per-run values
    slots: np.ndarray     # (slots, BS_SIZE, B) their per-slot geometry
    slip_u: np.ndarray    # (B,) each run's place on its slip grid at this time
    slip_i: np.ndarray    # (B,) int64 its interval
    slip_f: np.ndarray    # (B,) its fraction of the interval
    own1: np.ndarray      # (B·Z1,) 1 where a run's tooth of gear 1 has tables of its own
    own2: np.ndarray      # (B·Z2,) the same for gear 2 (0: nominal, its look-ups skipped)


@njit(cache=True, inline="always", error_model="numpy")
def lane_params(S, l):
    """Run ``l``'s :class:`~cmsim.dynamics._rhs_kernels.KernelParams` from the stacked ``S``
    (each field with the run first): views, nothing copied."""
    return KernelParams(S.minv[l], S.springs[l], S.fext[l], S.omega[l], S.b_int[l],
                        S.b_par[l], S.b_cos[l], S.b_sin[l], S.jitter[l], S.m_int[l],
                        S.m_par[l], S.geo[l], S.tab_k[l], S.tab_e[l], S.teeth1[l],
                        S.teeth2[l], S.spring_ends[l], S.hp[l], S.hd1[l], S.hc1[l], S.hd2[l],
                        S.hc2[l], S.b_def[l], S.b_ang[l], S.b_off[l], S.tk1[l], S.tk2[l],
                        S.te1[l], S.te2[l], S.ecc[l], S.prof[l], S.mu_tab[l], S.c_tab[l],
                        S.track[l])


@njit(cache=True, inline="always", error_model="numpy")
def lane_work(V, l):
    """Run ``l``'s :class:`~cmsim.dynamics._rhs_kernels.Work` from the stacked ``V`` (the
    force vector, the cage anchors and the slip arrays with the run last, the rest with the
    run first)."""
    return Work(V.g[:, l], V.cage[:, :, l], V.slip_cos[:, :, l], V.slip_sin[:, :, l],
                V.cage_slip[:, l], V.slots[l], V.hwork[l], V.hdelta[l], V.hrho1[l],
                V.hrho2[l], V.hchi1[l], V.hchi2[l], V.hout[l], V.hext[l], V.hstat[l], V.psi[l],
                V.def_gain[l])


@njit(cache=True, error_model="numpy", _nrt=False)
def _cage_frames(ib, it, ix, iy, y, b_par, omega, cage_slip, anchor, tau, ang, cc, sc, xr, yr,
                 fx, fy):
    """Pass 1 of bearing ``ib`` (shaft DOF ``it``, DOFs ``ix``, ``iy``) for every run: the cage
    angle ``ang``, its cos ``cc`` and sin ``sc`` and the inner ring's offset ``xr``, ``yr``
    in the cage frame (all (B,)); the sums ``fx``, ``fy`` zeroed.

    Each run's angle turns its own anchor (``anchor`` (nb, AN_SIZE, B), as
    :func:`~cmsim.dynamics._rotation_kernels.anchored_cos_sin_jit` does): the few runs whose
    angle left the anchor's range are re-anchored first (exact cos and sin), then every run
    rotates its anchor by the small difference in one vectorised loop — a re-anchored run by
    exactly zero, which returns its exact values, so each run gets the single-run kernel's
    numbers. The arrays are passed one by one (a call that unpacks a tuple of 19 arrays
    costs more than a bearing's ball sums at one run), and each loop writes few of them."""
    rate_a = b_par[ib, BP_CAGE]
    sense = b_par[ib, BP_SENSE]
    phase = b_par[ib, BP_PHASE]
    w = omega[it]
    q = y[it]
    slip = cage_slip[ib]
    for l in range(ang.shape[0]):
        ang[l] = rate_a[l] * sense[l] * (w[l] * tau[l] + q[l]) + phase[l] + slip[l]
    a0 = anchor[ib, AN_ANGLE]
    valid = anchor[ib, AN_VALID]
    for l in range(ang.shape[0]):
        d = ang[l] - a0[l]
        if valid[l] == 0.0 or d > ANCHOR_RAD or d < -ANCHOR_RAD:
            anchored_cos_sin_jit(anchor[:, :, l], ib, ang[l])
    c0 = anchor[ib, AN_COS]
    s0 = anchor[ib, AN_SIN]
    for l in range(ang.shape[0]):
        c, s = rotate_small_jit(c0[l], s0[l], ang[l] - a0[l])
        cc[l] = c
        sc[l] = s
    qx = y[ix]
    qy = y[iy]
    for l in range(ang.shape[0]):
        xr[l] = qx[l] * cc[l] + qy[l] * sc[l]
        yr[l] = qy[l] * cc[l] - qx[l] * sc[l]
    for l in range(ang.shape[0]):
        fx[l] = 0.0
        fy[l] = 0.0


@njit(cache=True, error_model="numpy", _nrt=False)
def _ball_sums(ib, n_balls, b_par, ball_cos, ball_sin, xr, yr, fx, fy, hertz):
    """Pass 2: the Fukata ball sums ``fx``, ``fy`` (B,) of bearing ``ib`` (paper 001 eq. 9) for
    every run, the runs innermost, from the inner ring's offsets ``xr``, ``yr`` (B,) in the
    cage frame. ``hertz`` (every run's exponent is 1.5): δ·√δ, vectorised; otherwise each run
    takes its own law (δ·√δ for 1.5, δ^p else), so its sum never depends on the others'.

    Written for the vectoriser: plain arrays (not inlined), each ball's rows taken out of the
    tables before the loop over the runs (it then checks their overlap once and runs whole
    vectors; it unrolls by four, so a batch of 32 runs fills its vector body)."""
    c = b_par[ib, BP_C]
    p = b_par[ib, BP_P]
    for i in range(n_balls):
        bc = ball_cos[ib, i]
        bs = ball_sin[ib, i]
        if hertz:
            for l in range(xr.shape[0]):
                d = max(xr[l] * bc[l] + yr[l] * bs[l] - c[l], 0.0)
                f = d * math.sqrt(d)
                fx[l] += f * bc[l]
                fy[l] += f * bs[l]
        else:
            for l in range(xr.shape[0]):
                d = max(xr[l] * bc[l] + yr[l] * bs[l] - c[l], 0.0)
                f = d * math.sqrt(d) if p[l] == 1.5 else d ** p[l]
                fx[l] += f * bc[l]
                fy[l] += f * bs[l]


@njit(cache=True, inline="always", error_model="numpy")
def _bearing_forces(y, n, g, S, L, V, B, diag, want_diag, ball_cos, ball_sin):
    """The healthy law of every bearing for every run (as
    :func:`cmsim.dynamics._bearing_kernels.bearing_forces_jit`, which leaves the bearings with
    an off-size ball, ``BI_FAULTY`` = 2, to the defect kernel)."""
    for ib in range(S.b_int.shape[1]):
        if S.b_int[0, ib, BI_FAULTY] == 2:
            continue
        ix = S.b_int[0, ib, BI_X]
        iy = S.b_int[0, ib, BI_Y]
        _cage_frames(ib, S.b_int[0, ib, BI_T], ix, iy, y, L.b_par, L.omega, V.cage_slip,
                     V.cage, B.tau, B.ang, B.cc, B.sc, B.xr, B.yr, B.fx, B.fy)
        hertz = True
        for l in range(y.shape[1]):
            hertz = hertz and L.b_par[ib, BP_P, l] == 1.5
        _ball_sums(ib, S.b_int[0, ib, BI_NB], L.b_par, ball_cos, ball_sin, B.xr, B.yr, B.fx,
                   B.fy, hertz)
        _bearing_out(ib, ix, iy, n, y, g, L.b_par, B.cc, B.sc, B.fx, B.fy, diag,
                     want_diag)


@njit(cache=True, error_model="numpy", _nrt=False)
def _bearing_out(ib, ix, iy, n, y, g, b_par, cc, sc, sum_x, sum_y, diag, want_diag):
    """Pass 3: bearing ``ib``'s ball sums turned back to the housing frame, on its DOFs'
    forces and, with ``want_diag``, the output forces (plus its viscous damping)."""
    k = b_par[ib, BP_K]
    damp = b_par[ib, BP_DAMP]
    gx = g[ix]
    gy = g[iy]
    vx = y[n + ix]
    vy = y[n + iy]
    for l in range(gx.shape[0]):
        fxr = k[l] * sum_x[l]
        fyr = k[l] * sum_y[l]
        fx = fxr * cc[l] - fyr * sc[l]
        fy = fyr * cc[l] + fxr * sc[l]
        gx[l] -= fx
        gy[l] -= fy
        if want_diag:
            diag[2 * ib, l] = fx + damp[l] * vx[l]
            diag[2 * ib + 1, l] = fy + damp[l] * vy[l]


@njit(cache=True, error_model="numpy", _nrt=False)
def _defect_changes(t, ib, it, ix, iy, n_balls, d0, nd, n, y, g, omega, b_par, ball_cos,
                    ball_sin, anchor, cage_slip, tau, b_ang, b_def, gain, track, tdt, diag,
                    want_diag):
    """The change the race and ball defects of bearing ``ib`` (``BI_FAULTY`` 1: its healthy
    law already applied) make to its forces, for every run: run by run the arithmetic of
    :func:`cmsim.dynamics._bearing_kernels.faulty_bearing_forces_jit` (the same numbers in
    the same order, so bit for bit the single-run kernel's change), without building each
    run's parameter views. The cage angle's cos and sin come from the anchor the healthy
    pass has just set at the same angle. ``track`` (B, m, n_grid) and ``tdt`` (B,): each
    run's share of a ball defect the races meet, read at ``t`` into ``gain`` (B, m) where it
    varies."""
    rate_a = b_par[ib, BP_CAGE]
    sense = b_par[ib, BP_SENSE]
    phase = b_par[ib, BP_PHASE]
    spin = b_par[ib, BP_SPIN]
    k = b_par[ib, BP_K]
    p = b_par[ib, BP_P]
    c = b_par[ib, BP_C]
    w = omega[it]
    q = y[it]
    qx = y[ix]
    qy = y[iy]
    slip = cage_slip[ib]
    for l in range(q.shape[0]):
        if track.shape[2] > 1:
            track_gains_jit(track[l], tdt[l], t, gain[l])
        rate = rate_a[l] * sense[l]
        turned = w[l] * tau[l] + q[l]
        angle = rate * turned + phase[l] + slip[l]
        cc, sc = anchored_cos_sin_jit(anchor[:, :, l], ib, angle)
        xr = qx[l] * cc + qy[l] * sc
        yr = qy[l] * cc - qx[l] * sc
        shaft = sense[l] * turned
        forward = 1.0 if w[l] >= 0.0 else -1.0
        fxr, fyr = _defect_correction(
            xr, yr, ball_cos[:, :, l], ball_sin[:, :, l], ib, n_balls, k[l], p[l], c[l],
            b_ang[l], b_def[l], d0, nd, angle, shaft, spin[l] * (shaft - angle),
            forward * (1.0 if rate >= 0.0 else -1.0),
            forward * (1.0 if rate - sense[l] >= 0.0 else -1.0),
            forward * (1.0 if sense[l] - rate >= 0.0 else -1.0), gain[l])
        fx = fxr * cc - fyr * sc
        fy = fyr * cc + fxr * sc
        g[ix, l] -= fx
        g[iy, l] -= fy
        if want_diag:
            diag[2 * ib, l] += fx
            diag[2 * ib + 1, l] += fy


@njit(cache=True, error_model="numpy", _nrt=False)
def _copy_flat(src, dst):
    """``dst[...] = src`` for two C-contiguous arrays of one shape, as one loop."""
    a = src.reshape(-1)
    b = dst.reshape(-1)
    for j in range(a.shape[0]):
        b[j] = a[j]


@njit(cache=True, error_model="numpy", _nrt=False)
def _springs(y, n, g, ends, springs):
    """The linear spring-dampers of every run into ``g`` (eq. 1, ``− K q − C v``; ground
    springs last, as :func:`cmsim.dynamics._rhs_kernels.linear_accel_jit` lays them out);
    ``springs`` (e, 2, B). Rows out of the arrays before the loops over the runs, as
    :func:`_ball_sums`."""
    n_springs = ends.shape[0]
    n_ground = ends[0, 2]
    for e in range(n_springs - n_ground):
        ga = g[ends[e, 0]]
        gb = g[ends[e, 1]]
        qa = y[ends[e, 0]]
        qb = y[ends[e, 1]]
        va = y[n + ends[e, 0]]
        vb = y[n + ends[e, 1]]
        k = springs[e, 0]
        c = springs[e, 1]
        for l in range(ga.shape[0]):
            f = k[l] * (qa[l] - qb[l]) + c[l] * (va[l] - vb[l])
            gb[l] += f
            ga[l] -= f
    for e in range(n_springs - n_ground, n_springs):
        ga = g[ends[e, 0]]
        qa = y[ends[e, 0]]
        va = y[n + ends[e, 0]]
        k = springs[e, 0]
        c = springs[e, 1]
        for l in range(ga.shape[0]):
            ga[l] -= k[l] * qa[l] + c[l] * va[l]


@njit(cache=True, error_model="numpy", _nrt=False)
def _accelerations(y, n, g, minv, omega, ar, dydt, row):
    """Row ``row`` of ``dydt`` (s, dim, B) = ``[v, M⁻¹ g − ω·(dΩ/dt)/Ω_ref]`` for every run
    (the inertia load of the nominal rotation's acceleration only where it is not zero, as
    the single-run kernel applies it)."""
    _copy_flat(y[n:], dydt[row, :n])
    for i in range(n):
        out_v = dydt[row, n + i]
        gi = g[i]
        mi = minv[i]
        wi = omega[i]
        for l in range(gi.shape[0]):
            out_v[l] = mi[l] * gi[l] - wi[l] * ar[l] if ar[l] != 0.0 else mi[l] * gi[l]


@njit(cache=True, error_model="numpy", _nrt=False)
def _constant_speed(t, tau, sr, ar):
    """``τ = t``, ``Ω/Ω_ref = 1``, no acceleration for every run (no speed profile)."""
    for l in range(tau.shape[0]):
        tau[l] = t
        sr[l] = 1.0
        ar[l] = 0.0


@njit(cache=True, error_model="numpy", _nrt=False)
def _profiles(t, prof, mp, tdof, g, tau, sr, ar):
    """Every run's nominal rotation ``τ``, ``Ω/Ω_ref``, ``(dΩ/dt)/Ω_ref`` at time ``t`` from
    its speed and torque profile ``prof`` (B, n_t, PR_SIZE), and its output torque into row
    ``tdof`` of ``g`` (n, B) unless ``tdof`` < 0 (as
    :func:`cmsim.dynamics._rhs_kernels.nominal_rotation_jit` run by run)."""
    for l in range(tau.shape[0]):
        theta, omega_in, alpha_in, torque = profile_at(prof[l], mp[MP_PT0, l], mp[MP_PDT, l],
                                                       t)
        inv_ref = 1.0 / mp[MP_OMREF, l]
        if tdof >= 0:
            g[tdof, l] = -torque
        tau[l] = theta * inv_ref
        sr[l] = omega_in * inv_ref
        ar[l] = alpha_in * inv_ref


@njit(cache=True, error_model="numpy", _nrt=False)
def _slip_batch(t, b_int, jitter, rows, ng, jdt, b_cos, b_sin, slip_cos, slip_sin, cage_slip,
                balls, ju, ji, jf):
    """Every run's cage slip angles ``cage_slip`` (nb, B) at time ``t`` and, with ``balls``,
    its balls' offsets with slip ``slip_cos``, ``slip_sin`` (nb, max_balls, B) (as
    :func:`cmsim.dynamics._bearing_kernels.slip_offsets_jit` and ``cage_slip_jit`` run by
    run). ``jitter`` is the runs' slip grids flat ((B, nb, rows, ng) run first, rows =
    max_balls + 1, the cage last), ``jdt`` (B,) their spacing; ``ju``, ``ji``, ``jf`` (B,)
    scratch for each run's place on its grids."""
    nb = b_int.shape[0]
    # every grid of a run is read at one place: found once (the same numbers as a lookup
    # each)
    for l in range(ju.shape[0]):
        ju[l] = t / jdt[l]
        ji[l], jf[l] = _grid_place(ju[l], ng)
    for ib in range(nb):
        cs = cage_slip[ib]
        for l in range(cs.shape[0]):
            cs[l] = _read_at(jitter, ((l * nb + ib) * rows + rows - 1) * ng, ng, ju[l], ji[l],
                             jf[l])
        if not balls:
            continue
        for i in range(b_int[ib, BI_NB]):
            bc = b_cos[ib, i]
            bs = b_sin[ib, i]
            oc = slip_cos[ib, i]
            os_ = slip_sin[ib, i]
            for l in range(cs.shape[0]):
                j = _read_at(jitter, ((l * nb + ib) * rows + i) * ng, ng, ju[l], ji[l], jf[l])
                j2 = j * j
                cj = 1.0 - j2 * (0.5 - j2 * (1.0 / 24.0))
                sj = j * (1.0 - j2 * (1.0 / 6.0 - j2 * (1.0 / 120.0)))
                oc[l] = bc[l] * cj - bs[l] * sj
                os_[l] = bs[l] * cj + bc[l] * sj


@njit(cache=True, inline="always", error_model="numpy")
def rhs_batch_jit(t, y, dydt, row, S, L, V, B, diag, want_diag):
    """The equations of motion of every run at time ``t`` (the single-run contract of
    :func:`cmsim.dynamics._rhs_kernels.rhs_jit`, with ``y`` (dim, B)); writes ``dydt[row]``
    (dim, B) and, with ``want_diag``, ``diag`` (n_diag, B)."""
    n = L.minv.shape[0]
    n_runs = y.shape[1]
    g = V.g
    _copy_flat(L.fext, g)
    if S.m_int[0, MI_PROFILE] != 0:
        _profiles(t, S.prof, L.m_par, S.m_int[0, MI_TDOF], g, B.tau, B.sr, B.ar)
    else:
        _constant_speed(t, B.tau, B.sr, B.ar)
    # the same switches for every run of a batch (as slip_at_jit)
    slip = S.jitter.shape[3] > 1
    moved = slip and S.m_int[0, MI_BALL_SLIP] != 0
    if slip:
        _slip_batch(t, S.b_int[0], S.jitter.reshape(-1), S.jitter.shape[2], S.jitter.shape[3],
                    L.m_par[MP_JDT], L.b_cos, L.b_sin, V.slip_cos, V.slip_sin, V.cage_slip,
                    moved, B.slip_u, B.slip_i, B.slip_f)
    if S.b_int.shape[1] > 0:
        if moved:
            _bearing_forces(y, n, g, S, L, V, B, diag, want_diag, V.slip_cos, V.slip_sin)
        else:
            _bearing_forces(y, n, g, S, L, V, B, diag, want_diag, L.b_cos, L.b_sin)
    mesh_on = S.m_int[0, MI_ON] != 0
    table = S.m_int[0, MI_MODE] == MODE_TABLE
    # race and ball defects: a pass per faulty bearing over the runs; an off-size ball
    # (the whole bearing ball by ball) through the single-run kernel run by run
    faulty = S.m_int[0, MI_FAULTY_BALLS] != 0
    if S.b_def.shape[1] > 0 and not faulty:
        for ib in range(S.b_int.shape[1]):
            if S.b_int[0, ib, BI_FAULTY] == 1:
                _defect_changes(t, ib, S.b_int[0, ib, BI_T], S.b_int[0, ib, BI_X],
                                S.b_int[0, ib, BI_Y], S.b_int[0, ib, BI_NB],
                                S.b_int[0, ib, BI_DEF0], S.b_int[0, ib, BI_NDEF], n, y, g,
                                L.omega, L.b_par, V.slip_cos if moved else L.b_cos,
                                V.slip_sin if moved else L.b_sin, V.cage, V.cage_slip, B.tau,
                                S.b_ang, S.b_def, V.def_gain, S.track, L.m_par[MP_TDT], diag,
                                want_diag)
    if faulty or (mesh_on and not table):
        # what branches per run in depth, through the single-run kernels (the same
        # arithmetic in the same order) on each run's column of the state and the forces:
        # off-size balls, the hybrid contact solve
        for l in range(n_runs):
            P = lane_params(S, l)
            W = lane_work(V, l)
            yl = y[:, l]
            gl = g[:, l]
            dl = diag[:, l]
            if faulty and moved:
                defect_forces_jit(t, B.tau[l], yl, n, gl, P, W, W.slip_cos, W.slip_sin, dl,
                                  want_diag)
            elif faulty:
                defect_forces_jit(t, B.tau[l], yl, n, gl, P, W, P.b_cos, P.b_sin, dl,
                                  want_diag)
            if mesh_on and not table:
                mesh_forces_jit(B.tau[l], B.sr[l], yl, n, gl, P, W, dl, want_diag)
    if mesh_on and table:
        # the tooth contacts of every run in passes over the runs (the same numbers)
        mesh_forces_batch_jit(y, n, g, S, L.m_par, L.geo, B.tau, B.sr, V.psi, B.mesh,
                              B.slots, B.own1, B.own2, diag, want_diag)
    _springs(y, n, g, S.spring_ends[0], L.springs)
    _accelerations(y, n, g, L.minv, L.omega, B.ar, dydt, row)


@njit(cache=True, error_model="numpy", _nrt=False)
def _stage_state(y, k, st, h, rk_a, yi):
    """``yi = y + h Σ_j a_st,j k_j`` for every run (the terms in the single-run kernel's
    order; a zero weight adds nothing, as there). The arrays flat (C-contiguous (dim, B)
    views): one loop per term over every state of every run, not one per state."""
    out = yi.reshape(-1)
    yf = y.reshape(-1)
    for j in range(out.shape[0]):
        out[j] = yf[j]
    for jj in range(st):
        if rk_a[st, jj] == 0.0:
            continue
        w = h * rk_a[st, jj]
        kj = k[jj].reshape(-1)
        for j in range(out.shape[0]):
            out[j] += w * kj[j]


@njit(cache=True, error_model="numpy", _nrt=False)
def _step(y, k, h, rk_b, acc):
    """``y += h Σ_s b_s k_s`` for every run (in the single-run kernel's order: the sum from
    zero, then one add), the sum built in ``acc`` (dim, B) one stage at a time over every
    state of every run (flat), so each loop vectorises."""
    a = acc.reshape(-1)
    yf = y.reshape(-1)
    for j in range(a.shape[0]):
        a[j] = 0.0
    for st in range(rk_b.shape[0]):
        if rk_b[st] == 0.0:
            continue
        b = rk_b[st]
        ks = k[st].reshape(-1)
        for j in range(a.shape[0]):
            a[j] += b * ks[j]
    for j in range(a.shape[0]):
        yf[j] += h * a[j]


@njit(cache=True, error_model="numpy", _nrt=False)
def _check_states(y, n, max_disp, max_rot, trans_mask, ok):
    """``ok[l]`` 1 where run ``l``'s state is finite and within its limits (translations,
    ``trans_mask``, within ``max_disp[l]``; rotations within ``max_rot``), 0 elsewhere: one
    loop over the runs per DOF, no branch in it. The limits are finite, so a displacement
    within its limit is finite too."""
    for l in range(ok.shape[0]):
        ok[l] = 1.0
    for i in range(n):
        q = y[i]
        v = y[n + i]
        trans = trans_mask[i]
        for l in range(ok.shape[0]):
            limit = max_disp[l] if trans else max_rot
            good = (abs(q[l]) <= limit) & (abs(v[l]) < math.inf)
            ok[l] = ok[l] if good else 0.0


@njit(cache=True, error_model="numpy", _nrt=False)
def integrate_batch_jit(t0, h, n_out, substeps, m_offset, rk_a, rk_b, rk_c, S, L, V, B, out_y,
                        out_diag, y_cols, d_cols, max_disp, max_rot, trans_mask, status):
    """Fixed-step explicit Runge-Kutta of a batch of runs, output every ``substeps`` steps.

    The scheme is data (``rk_a``, ``rk_b``, ``rk_c``, as
    :func:`cmsim.dynamics._rhs_kernels.integrate_jit`). ``S`` holds the runs'
    :class:`~cmsim.dynamics._rhs_kernels.KernelParams` stacked (run first), ``L`` the
    :class:`LaneParams`, ``V`` their :class:`~cmsim.dynamics._rhs_kernels.Work` stacked
    (:func:`lane_work`), ``B`` the :class:`BatchBuffers` (``B.y`` the state to start from).
    Sample ``m`` of run ``l`` goes to ``out_y[l, m]`` (the state at ``t0 + (m_offset +
    m)·substeps·h``: its columns ``y_cols``, int64) and ``out_diag[l, m]`` (its output forces:
    columns ``d_cols``); only the columns a caller reads are copied (a record's filter reads
    a few of them, and copying a whole state per sample was 5 % of a step). Chunks started
    from the last state of the one before (``B.y``) with the same ``V`` reproduce one call
    bit for bit.

    ``status[l]`` (int64, −1 on entry for a run not diverged) becomes the index ``m_offset +
    m`` of run ``l``'s first output sample that was non-finite or beyond ``max_disp[l]``
    (translations, ``trans_mask``) or ``max_rot`` (rotations); the run then restarts from
    ``B.y0`` and its samples mean nothing.
    """
    k = B.k
    y = B.y
    yi = B.yi
    diag = B.diag
    ns = rk_b.shape[0]
    dim, n_runs = y.shape
    n = dim // 2
    for m in range(n_out):
        _check_states(y, n, max_disp, max_rot, trans_mask, B.ok)
        for l in range(n_runs):
            for c in range(y_cols.shape[0]):
                out_y[l, m, c] = y[y_cols[c], l]
            if status[l] < 0 and B.ok[l] == 0.0:
                status[l] = m_offset + m
                for j in range(dim):
                    y[j, l] = B.y0[j, l]
        for sub in range(substeps):
            t = t0 + ((m_offset + m) * substeps + sub) * h
            # one call of the inlined right-hand side, its stage and its outputs switch as
            # values: two calls (the first stage's, the others' with a constant False) made
            # numba compile the whole right-hand side twice and six of its kernels twice more
            for st in range(ns):
                want = sub == 0 and st == 0
                if st > 0:
                    _stage_state(y, k, st, h, rk_a, yi)
                rhs_batch_jit(t + rk_c[st] * h, yi if st > 0 else y, k, st, S, L, V, B, diag,
                              want)
                if want:
                    for l in range(n_runs):
                        for c in range(d_cols.shape[0]):
                            out_diag[l, m, c] = diag[d_cols[c], l]
                    if m == n_out - 1:
                        return
            _step(y, k, h, rk_b, yi)

