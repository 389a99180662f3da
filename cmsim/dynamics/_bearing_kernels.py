"""Bearing forces of the equations of motion (paper 001 eq. 9, Annex B): numba kernels.

Fukata ball forces of every bearing in its cage frame (:func:`bearing_forces_jit`, the
healthy law, compiled with fastmath so the ball loop vectorises), the change that race and
ball defects and off-size balls make (:func:`faulty_bearing_forces_jit`), the balls' and
cages' slip at time t (:func:`slip_offsets_jit`) and the share of each defect the races meet
(:func:`track_gains_jit`). The column layouts of the bearing tables ``b_int`` (``BI_*``),
``b_par`` (``BP_*``) and ``b_def`` (``DF_*``) of :class:`~cmsim.dynamics._rhs_kernels.KernelParams`
are defined here. The cage angle's cos and sin come from its anchor
(:mod:`cmsim.dynamics._rotation_kernels`).

The numba rule of every kernel module of :mod:`cmsim.dynamics` (in full in
:mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``, float64/int64 arrays and
scalars only, no Python objects, no random numbers, no allocation in the hot path.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, eq. 9 and Annex B.
.. [2] N. Sawalhi, R. B. Randall, MSSP 22 (2008) 1924-1951 (defects).
"""

from __future__ import annotations

import math

from numba import njit

from cmsim.bearings._kernels import ball_forces_cage_frame_jit
from cmsim.dynamics._rotation_kernels import anchored_cos_sin_jit

# b_int columns: DOF indices, number of balls, first row and count of the bearing's defects
# in ``b_def``, 1 when the bearing has defects or off-size balls (its balls then take the
# exact per-ball loop)
BI_X, BI_Y, BI_T, BI_NB, BI_DEF0, BI_NDEF, BI_FAULTY = 0, 1, 2, 3, 4, 5, 6
BI_SIZE = 7
# b_par columns: stiffness, exponent, clearance, cage angle per physical inner-ring angle,
# physical sense of the shaft (+1 CCW, −1 CW), viscous damping to ground, initial cage phase,
# ball spin angle per inner-ring angle relative to the cage ((D − d cos α)/d)
BP_K, BP_P, BP_C, BP_CAGE, BP_SENSE, BP_DAMP, BP_PHASE, BP_SPIN = 0, 1, 2, 3, 4, 5, 6, 7
BP_SIZE = 8
# b_def columns (the FaultArrays.bearing_defects layout of cmsim.faults): bearing, kind,
# centre angle, half-width, depth, entry ramp, exit ramp, ball index; a ball defect's offset
# from the rolling track (sine of its latitude), the spin axis' wander time (s) and the
# track's half-width (contact band + half the defect, in ball radii); read when the run's
# ``track`` grid is built (cmsim.dynamics.model), not by the kernels
DF_BRG, DF_KIND, DF_CENTRE, DF_HALF, DF_DEPTH, DF_ENTRY, DF_EXIT, DF_BALL = range(8)
DF_AXIS, DF_WANDER, DF_TRACK = 8, 9, 10
DF_SIZE = 11
DEF_OUTER, DEF_INNER, DEF_BALL = 1, 2, 3


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


@njit(cache=True, inline="always", error_model="numpy")
def track_gains_jit(track, tdt, t, gain):
    """Fill ``gain`` (m,) with each defect row's ``track`` value at ``t`` (linear on its
    grid, held at the ends); only called when the grid varies (a constant one is copied
    into ``W.def_gain`` once, by :func:`make_work`)."""
    u = min(max(t / tdt, 0.0), track.shape[1] - 1.0)
    i = min(int(u), track.shape[1] - 2)
    f = u - i
    for r in range(track.shape[0]):
        gain[r] = track[r, i] + f * (track[r, i + 1] - track[r, i])


@njit(cache=True, inline="always", error_model="numpy")
def cage_slip_jit(t, b_int, b_cos, jitter, jdt, cage_slip):
    """Fill ``cage_slip`` with each cage's slip angle at time ``t`` (a slip that moves the
    cages only: the balls keep their nominal offsets, exactly what
    :func:`slip_offsets_jit` gives from all-zero ball rows)."""
    row = b_cos.shape[1]
    for ib in range(b_int.shape[0]):
        cage_slip[ib] = _jitter_at(jitter, ib, row, t, jdt)


@njit(cache=True, error_model="numpy", _nrt=False)
def slip_offsets_jit(t, b_int, b_cos, b_sin, jitter, jdt, jit_cos, jit_sin, cage_slip):
    """Fill ``jit_cos``, ``jit_sin`` (n_bearings, max_balls) with cos, sin of the ball offsets
    with slip at time ``t``, and ``cage_slip`` with each cage's slip angle."""
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


@njit(cache=True, inline="always", error_model="numpy")
def _wrap(a):
    """``a`` wrapped to [−π, π)."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) * (0.5 / math.pi))


@njit(cache=True, inline="always", error_model="numpy")
def _defect_profile(u, half, entry, exit_):
    """Trapezoid depth profile (0..1) at ``u`` (the ball's position across the defect,
    increasing with time): ramps of widths ``entry`` and ``exit_`` inside [−half, half]."""
    if u <= -half or u >= half:
        return 0.0
    a = (u + half) / entry if entry > 0.0 else 1.0
    b = (half - u) / exit_ if exit_ > 0.0 else 1.0
    return min(1.0, a, b)


@njit(cache=True, inline="always", error_model="numpy")
def _defect_loss(theta, i, b_def, d0, nd, shaft_angle, spin_angle, dirn_cage, dirn_inner,
                 dirn_spin, gain):
    """Overlap ball ``i`` (housing angle ``theta``) loses in the defects rows d0..d0+nd, m:
    an outer-race defect is fixed in the housing, an inner-race one turns with the shaft, a
    ball defect turns with the ball's spin and meets the outer race at spin phase 0 and the
    inner race at π (Sawalhi & Randall 2008, MSSP 22); row r's depth is scaled by
    ``gain[r]`` (the share of a ball defect inside the rolling track, ``W.def_gain``)."""
    loss = 0.0
    for r in range(d0, d0 + nd):
        if gain[r] <= 0.0:
            continue
        kind = int(b_def[r, DF_KIND])
        if kind == DEF_OUTER:
            u = dirn_cage * _wrap(theta - b_def[r, DF_CENTRE])
        elif kind == DEF_INNER:
            u = dirn_inner * _wrap(theta - shaft_angle - b_def[r, DF_CENTRE])
        else:
            if int(b_def[r, DF_BALL]) != i:
                continue
            # both races: the spin phase modulo π
            v = spin_angle - b_def[r, DF_CENTRE]
            u = dirn_spin * (v - math.pi * math.floor(v / math.pi + 0.5))
        loss += gain[r] * b_def[r, DF_DEPTH] * _defect_profile(
            u, b_def[r, DF_HALF], b_def[r, DF_ENTRY], b_def[r, DF_EXIT])
    return loss


@njit(cache=True, inline="always", error_model="numpy")
def _contact(d, p, hertz):
    """Ball contact law δ^p for δ > 0 (δ·sqrt(δ) for Hertz), 0 otherwise."""
    if d <= 0.0:
        return 0.0
    return d * math.sqrt(d) if hertz else d ** p


@njit(cache=True, error_model="numpy", _nrt=False)
def _faulty_ball_loop(xr, yr, ball_cos, ball_sin, ib, n_balls, k, p, c, b_ang, b_off, b_def,
                      d0, nd, cage_angle, shaft_angle, spin_angle, dirn_cage, dirn_inner,
                      dirn_spin, gain):
    """Eq. 9 ball by ball with defects and off-size balls (cage frame, as
    :func:`cmsim.bearings._kernels.ball_forces_cage_frame_jit`): ball i's overlap is
    x_r cos φ_i + y_r sin φ_i − c + Δd_i − Σ depth·profile (:func:`_defect_loss`). Used for
    bearings with an off-size ball, where every ball differs from the healthy law."""
    fx = 0.0
    fy = 0.0
    hertz = p == 1.5
    for i in range(n_balls):
        co = ball_cos[ib, i]
        so = ball_sin[ib, i]
        d = xr * co + yr * so - c + b_off[ib, i]
        if d <= 0.0:
            continue                   # a defect only takes overlap away: still unloaded
        d -= _defect_loss(cage_angle + b_ang[ib, i], i, b_def, d0, nd, shaft_angle,
                          spin_angle, dirn_cage, dirn_inner, dirn_spin, gain)
        f = _contact(d, p, hertz)
        fx += f * co
        fy += f * so
    return k * fx, k * fy


@njit(cache=True, inline="always", error_model="numpy")
def _defect_correction(xr, yr, ball_cos, ball_sin, ib, n_balls, k, p, c, b_ang, b_def, d0,
                       nd, cage_angle, shaft_angle, spin_angle, dirn_cage, dirn_inner,
                       dirn_spin, gain):
    """Change the defects of bearing ``ib`` make to its healthy ball-force sum (cage frame).

    Only the balls that can sit in a defect are visited: a race defect is shorter than the
    ball spacing (:mod:`cmsim.faults.bearing` refuses longer ones), so at most the ball
    nearest its centre is inside it; a ball defect is on its own ball. Each such ball's
    overlap loss sums every defect row (:func:`_defect_loss`), so coinciding defects combine
    exactly as in :func:`_faulty_ball_loop`; a ball seen by two rows is counted once.
    """
    fx = 0.0
    fy = 0.0
    hertz = p == 1.5
    pitch = 2.0 * math.pi / n_balls
    for r in range(d0, d0 + nd):
        i = _defect_ball(r, b_def, b_ang[ib, 0], pitch, n_balls, cage_angle, shaft_angle)
        seen = False
        for r2 in range(d0, r):                  # this ball was corrected by an earlier row
            if _defect_ball(r2, b_def, b_ang[ib, 0], pitch, n_balls, cage_angle,
                            shaft_angle) == i:
                seen = True
        if seen:
            continue
        co = ball_cos[ib, i]
        so = ball_sin[ib, i]
        d = xr * co + yr * so - c
        if d <= 0.0:
            continue
        loss = _defect_loss(cage_angle + b_ang[ib, i], i, b_def, d0, nd, shaft_angle,
                            spin_angle, dirn_cage, dirn_inner, dirn_spin, gain)
        if loss > 0.0:
            f = _contact(d - loss, p, hertz) - _contact(d, p, hertz)
            fx += f * co
            fy += f * so
    return k * fx, k * fy


@njit(cache=True, inline="always", error_model="numpy")
def _defect_ball(r, b_def, ang0, pitch, n_balls, cage_angle, shaft_angle):
    """Index of the ball nearest defect row ``r`` (its own ball for a ball defect)."""
    kind = int(b_def[r, DF_KIND])
    if kind == DEF_BALL:
        return int(b_def[r, DF_BALL])
    centre = b_def[r, DF_CENTRE] + (shaft_angle if kind == DEF_INNER else 0.0)
    a = (centre - cage_angle - ang0) / pitch
    m = math.floor(a + 0.5)
    return int(m - n_balls * math.floor(m / n_balls))


@njit(cache=True, inline="always", error_model="numpy")
def faulty_bearing_forces_jit(t, y, n, g, omega, b_int, b_par, ball_cos, ball_sin, anchor,
                              cage_slip, diag, want_diag, b_ang, b_off, b_def, gain):
    """Forces of the bearings with defects or off-size balls (``BI_FAULTY``).

    ``BI_FAULTY`` = 1 (race or ball defects only): :func:`bearing_forces_jit` has applied the
    healthy law, and the defects' change is added (:func:`_defect_correction`, the few balls
    in a defect); = 2 (an off-size ball): the whole bearing ball by ball
    (:func:`_faulty_ball_loop`). Kept apart so that the healthy ball loop stays vectorised.
    """
    for ib in range(b_int.shape[0]):
        mode = b_int[ib, BI_FAULTY]
        if mode == 0:
            continue
        ix = b_int[ib, BI_X]
        iy = b_int[ib, BI_Y]
        it = b_int[ib, BI_T]
        rate = b_par[ib, BP_CAGE] * b_par[ib, BP_SENSE]
        turned = omega[it] * t + y[it]
        angle = rate * turned + b_par[ib, BP_PHASE] + cage_slip[ib]
        cc, sc = anchored_cos_sin_jit(anchor, ib, angle)
        xr = y[ix] * cc + y[iy] * sc
        yr = y[iy] * cc - y[ix] * sc
        sense = b_par[ib, BP_SENSE]
        shaft = sense * turned
        forward = 1.0 if omega[it] >= 0.0 else -1.0
        dirn_cage = forward * (1.0 if rate >= 0.0 else -1.0)
        dirn_inner = forward * (1.0 if rate - sense >= 0.0 else -1.0)
        dirn_spin = forward * (1.0 if sense - rate >= 0.0 else -1.0)
        if mode == 1:
            fxr, fyr = _defect_correction(
                xr, yr, ball_cos, ball_sin, ib, b_int[ib, BI_NB], b_par[ib, BP_K],
                b_par[ib, BP_P], b_par[ib, BP_C], b_ang, b_def, b_int[ib, BI_DEF0],
                b_int[ib, BI_NDEF], angle, shaft, b_par[ib, BP_SPIN] * (shaft - angle),
                dirn_cage, dirn_inner, dirn_spin, gain)
        else:
            fxr, fyr = _faulty_ball_loop(
                xr, yr, ball_cos, ball_sin, ib, b_int[ib, BI_NB], b_par[ib, BP_K],
                b_par[ib, BP_P], b_par[ib, BP_C], b_ang, b_off, b_def, b_int[ib, BI_DEF0],
                b_int[ib, BI_NDEF], angle, shaft, b_par[ib, BP_SPIN] * (shaft - angle),
                dirn_cage, dirn_inner, dirn_spin, gain)
        fx = fxr * cc - fyr * sc
        fy = fyr * cc + fxr * sc
        if mode == 1:                  # a change to the healthy forces already applied
            g[ix] -= fx
            g[iy] -= fy
            if want_diag:
                diag[2 * ib] += fx
                diag[2 * ib + 1] += fy
            continue
        g[ix] -= fx
        g[iy] -= fy
        if want_diag:
            diag[2 * ib] = fx + b_par[ib, BP_DAMP] * y[n + ix]
            diag[2 * ib + 1] = fy + b_par[ib, BP_DAMP] * y[n + iy]


@njit(cache=True, fastmath=True, error_model="numpy", _nrt=False)
def bearing_forces_jit(t, y, n, g, omega, b_int, b_par, ball_cos, ball_sin, anchor, cage_slip,
                       diag, want_diag):
    """Fukata forces of all bearings with balls at offsets ``ball_cos/sin`` from the cage
    and cages shifted by the slip angles ``cage_slip`` (zeros without slip); ``t`` is the
    equivalent time τ of the nominal rotation (``KernelParams``).

    Written flat on purpose: with helper functions inlined, a jitter branch, or arrays taken
    out of ``P`` inside the loop, numba stops vectorising the ball loop (2-3× slower).
    Bearings with race or ball defects (``BI_FAULTY`` = 1) get the healthy law here and
    their defects' change from :func:`faulty_bearing_forces_jit`; bearings with an off-size ball
    (``BI_FAULTY`` = 2) are left to it whole.
    The cage angle (nominal rate·Ω·t, phase, slip and the dynamic deviation rate·q_θ) is
    turned into cos and sin by rotating the bearing's anchor (module docstring). Each bearing
    works in its cage frame: the inner-ring offset is turned by −θ_cage once instead of
    turning every ball. Arrays come as arguments, not in the tuple ``P``: a non-inlined call
    copies its arguments.
    """
    for ib in range(b_int.shape[0]):
        if b_int[ib, BI_FAULTY] == 2:
            continue
        ix = b_int[ib, BI_X]
        iy = b_int[ib, BI_Y]
        it = b_int[ib, BI_T]
        rate = b_par[ib, BP_CAGE] * b_par[ib, BP_SENSE]
        angle = rate * (omega[it] * t + y[it]) + b_par[ib, BP_PHASE] + cage_slip[ib]
        cc, sc = anchored_cos_sin_jit(anchor, ib, angle)
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
