"""Numba kernels of the equations of motion and the fixed-step Runge-Kutta integrator.

This module isolates the numba convention: ``@njit(cache=True)``, float64/int64 arrays and
scalars only, grouped in two named tuples owned by this module — :class:`KernelParams` ``P``
(the model, read only) and :class:`Work` ``W`` (scratch) —, no Python objects, no random
numbers. :mod:`cmsim.dynamics.model` fills ``P`` (its fields are documented on the class).

Right-hand side contract: ``rhs_jit(t, y, dydt, row, P, diag, want_diag, W)`` with ``y = [q, v]``
(shape ``(2n,)``), ``q`` the DOF deviations from the nominal rigid rotation (translations in m,
rotations in rad, rotations of shaft 2 counted positive in its own sense of motion), ``v`` their
rates; it writes row ``row`` of the 2-D array ``dydt`` with ``[v, M⁻¹(f_ext + g(t, q, v) − K q
− C v)]`` where ``g`` holds the bearing and mesh forces. With ``want_diag`` it also writes the
output forces into ``diag``.

Hot-path code never slices arrays and never takes arrays out of tuples inside loops (numba
takes an atomic reference count for each), and the integrator and force kernels are compiled
without numba's reference-counting runtime (``_nrt=False``, so they allocate nothing: the
caller passes every buffer). Small kernels are inlined at numba-IR level (a call with array
arguments costs about 25 ns).
The bearing forces are compiled with fastmath so the ball loop vectorises; the finiteness
checks live in the integrator, which is compiled without it.

Trigonometry by rotation. The cage angles and the two gears' involute origin angles advance
by small increments from one call to the next. Each keeps an *anchor* in ``W`` (an angle and
its exact cosine and sine); a call rotates the anchor by the small difference with a Taylor
series (error below 1e-15 for |difference| <= :data:`ANCHOR_RAD`) and re-anchors with exact
``cos``/``sin`` only when the difference grows past it — about once per hundred steps instead
of twelve transcendental calls per step. The line of action's angle is likewise a short
``atan`` series about its nominal value. Results agree with direct trigonometry to rounding.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from cmsim.bearings._kernels import ball_forces_cage_frame_jit
from cmsim.mesh_stiffness._hybrid_kernels import (HP_SIZE, WORK_PER_N, WORK_PER_N2,
                                                  hybrid_forces_jit)
from cmsim.mesh_stiffness._kernels import mesh_line_jit, pair_contact_jit, table_lookup2_jit

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
# m_int entries: DOF index of each gear's x, number of slots, mesh on, elastic-force mode,
# per-tooth tables on, eccentricity on, speed/torque profile on, DOF of the output torque,
# off-size balls present
MI_G1, MI_G2, MI_SLOTS, MI_ON, MI_MODE, MI_TEETH, MI_ECC, MI_PROFILE, MI_TDOF = range(9)
MI_FAULTY_BALLS = 9     # 1 when any bearing has off-size balls
MI_MUTAB = 10           # 1 when the friction coefficient follows ``mu_tab`` along the path
MI_CTAB = 11            # 1 when the pair damping follows ``c_tab`` along the path
MI_SIZE = 12
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
# columns of the profile table ``prof``: input-shaft angle Θ (rad), speed Ω (rad/s),
# acceleration (rad/s²), output torque (N·m), on the uniform grid MP_PT0 + i·MP_PDT
PR_THETA, PR_OMEGA, PR_ALPHA, PR_TORQUE = 0, 1, 2, 3
PR_SIZE = 4
# columns of an angle anchor (``W.cage``, ``W.psi``): angle, its cos and sin, valid flag
AN_ANGLE, AN_COS, AN_SIN, AN_VALID = 0, 1, 2, 3
AN_SIZE = 4
#: Largest angle (rad) a rotation anchor is carried by its Taylor series before re-anchoring.
ANCHOR_RAD = 0.05


class KernelParams(NamedTuple):
    """Model arrays ``P`` of the kernels (all float64 unless stated; SI units).

    Attributes
    ----------
    minv : (n,) inverse of the diagonal mass matrix.
    springs : (e, 2) stiffness and damping of each two-node spring-damper (Annex A).
    fext : (n,) constant external load (output torque, radial load).
    omega : (n,) nominal rotation speed of each DOF, rad/s (0 for translations).
    b_int : int64 (nb, BI_SIZE) bearing DOF indices and ball counts.
    b_par : (nb, BP_SIZE) bearing parameters (``BP_*`` columns).
    b_cos, b_sin : (nb, max_balls) cos and sin of each ball's offset in its cage.
    jitter : (nb, max_balls + 1, n_grid) slip grid (a dummy (nb, ·, 1) when slip is off).
    m_int : int64 (MI_SIZE,) mesh integers (``MI_*``).
    m_par : (MP_SIZE,) mesh parameters (``MP_*``).
    geo : (GEO_SIZE,) tooth geometry vector of :mod:`cmsim.mesh_stiffness._kernels`.
    tab_k, tab_e : (m,) pair stiffness (N/m) and unloaded separation (m) on a uniform grid.
    teeth1, teeth2 : (Z, 2) cos and sin of multiples of each gear's angular pitch.
    spring_ends : int64 (e, 3) DOF indices (a, b) of each spring; ``[0, 2]`` = ground count.
    hp, hd1, hc1, hd2, hc2 : hybrid contact parameters and influence tables
        (:meth:`cmsim.mesh_stiffness.hybrid.HybridMeshModel.kernel_args`; placeholders in
        table mode).
    b_def : (m, DF_SIZE) race and ball defects (``DF_*`` columns; (0, DF_SIZE) if none).
    b_ang : (nb, max_balls) nominal angle of each ball in its cage, rad.
    b_off : (nb, max_balls) extra overlap of each ball (off-size balls), m.
    tk1, tk2 : (Z, m) per-tooth factor on the pair stiffness on the mesh table's grid
        ((1, 1) when ``MI_TEETH`` is off); te1, te2 : the same for extra separation, m.
    ecc : (2, 2) eccentricity (amplitude m, phase rad − the gear's reference phase) of each
        gear's geometric centre.
    prof : (n_t, PR_SIZE) input speed and output torque profile (``PR_*``; (1, PR_SIZE)
        when ``MI_PROFILE`` is off).
    mu_tab : (m,) mesh friction coefficient against the pair's position on the mesh table's
        grid (a lubrication model's f(s) at the operating point; (1,) and unused when
        ``MI_MUTAB`` is off: the constant ``MP_MU``).
    c_tab : (m,) viscous damping of a loaded pair against its position on the mesh table's
        grid, N·s/m (e.g. structural + mixed-lubrication contact damping, paper 004 eq. 14-16;
        (1,) and unused when ``MI_CTAB`` is off: the stiffness-proportional β·k).
    track : (m, n_grid) share of each defect row's depth the races meet at t = i·``MP_TDT``
        (ones for race defects; a ball defect off its rolling track meets them partly or not
        at all, and a wandering spin axis moves it; (m, 1) when constant).
        Nominal rotations are ``omega[i]·τ(t)`` with the equivalent time τ = Θ(t)/Ω_ref
        (τ = t at constant speed).
    """

    minv: np.ndarray
    springs: np.ndarray
    fext: np.ndarray
    omega: np.ndarray
    b_int: np.ndarray
    b_par: np.ndarray
    b_cos: np.ndarray
    b_sin: np.ndarray
    jitter: np.ndarray
    m_int: np.ndarray
    m_par: np.ndarray
    geo: np.ndarray
    tab_k: np.ndarray
    tab_e: np.ndarray
    teeth1: np.ndarray
    teeth2: np.ndarray
    spring_ends: np.ndarray
    hp: np.ndarray
    hd1: np.ndarray
    hc1: np.ndarray
    hd2: np.ndarray
    hc2: np.ndarray
    b_def: np.ndarray
    b_ang: np.ndarray
    b_off: np.ndarray
    tk1: np.ndarray
    tk2: np.ndarray
    te1: np.ndarray
    te2: np.ndarray
    ecc: np.ndarray
    prof: np.ndarray
    mu_tab: np.ndarray
    c_tab: np.ndarray
    track: np.ndarray

    def frozen(self):
        """The same arrays as C-contiguous read-only views (copies only where not contiguous).

        Numba compiles one specialisation of the integrator per combination of array flags,
        and a read-only array (a frozen rig's, one loaded from a file) differs in type from a
        writeable one: mixed flags cost a full recompile (about a minute) for each new mix.
        The kernels never write into ``P``, so every model hands them read-only arrays.
        """
        out = []
        for a in self:
            v = np.ascontiguousarray(a).view()
            v.setflags(write=False)
            out.append(v)
        return KernelParams(*out)


def no_faults(nb, max_balls):
    """Neutral fault fields ``(b_def, b_off, tk1, tk2, te1, te2, ecc)`` of :class:`KernelParams`."""
    return (np.zeros((0, DF_SIZE)), np.zeros((nb, max_balls)), np.ones((1, 1)),
            np.ones((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((2, 2)))


def no_profile():
    """Neutral ``prof`` field of :class:`KernelParams` (constant speed and torque)."""
    return np.zeros((1, PR_SIZE))


class Work(NamedTuple):
    """Scratch arrays ``W`` of :func:`rhs_jit` (see :func:`make_work`)."""

    g: np.ndarray          # (n,) force vector
    cage: np.ndarray       # (nb, AN_SIZE) cage-angle anchors
    slip_cos: np.ndarray   # (nb, max_balls) ball offsets with slip
    slip_sin: np.ndarray
    cage_slip: np.ndarray  # (nb,) cage slip angle
    slots: np.ndarray      # (slots, SG_SIZE) per-slot mesh geometry
    hwork: np.ndarray      # hybrid solver work
    hdelta: np.ndarray     # (slots,) hybrid δ, ρ1, ρ2, χ1, χ2, forces
    hrho1: np.ndarray
    hrho2: np.ndarray
    hchi1: np.ndarray
    hchi2: np.ndarray
    hout: np.ndarray
    hext: np.ndarray       # (slots,) extra compliance of weakened teeth in the hybrid solve
    hstat: np.ndarray      # (2,) hybrid counters [solves, non-converged solves]
    psi: np.ndarray        # (2, AN_SIZE) anchors of the gears' involute origin angles
    def_gain: np.ndarray   # (max(m, 1),) ``track`` of each defect row at the current time


@njit(cache=True, inline="always", error_model="numpy")
def _rotate_small(c0, s0, d):
    """cos and sin of (a + d) from those of a, for |d| <= ANCHOR_RAD (Taylor, < 1e-15)."""
    d2 = d * d
    cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0 - d2 * (1.0 / 40320.0))))
    sd = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0))))
    return c0 * cd - s0 * sd, s0 * cd + c0 * sd


@njit(cache=True, inline="always", error_model="numpy")
def _anchored_cos_sin(anchor, row, angle):
    """cos and sin of ``angle`` by rotating the anchor in ``anchor[row]`` (module docstring)."""
    d = angle - anchor[row, AN_ANGLE]
    if anchor[row, AN_VALID] == 0.0 or d > ANCHOR_RAD or d < -ANCHOR_RAD:
        c = math.cos(angle)
        s = math.sin(angle)
        anchor[row, AN_ANGLE] = angle
        anchor[row, AN_COS] = c
        anchor[row, AN_SIN] = s
        anchor[row, AN_VALID] = 1.0
        return c, s
    return _rotate_small(anchor[row, AN_COS], anchor[row, AN_SIN], d)


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
def _track_gains(track, tdt, t, gain):
    """Fill ``gain`` (m,) with each defect row's ``track`` value at ``t`` (linear on its
    grid, held at the ends); only called when the grid varies (a constant one is copied
    into ``W.def_gain`` once, by :func:`make_work`)."""
    u = min(max(t / tdt, 0.0), track.shape[1] - 1.0)
    i = min(int(u), track.shape[1] - 2)
    f = u - i
    for r in range(track.shape[0]):
        gain[r] = track[r, i] + f * (track[r, i + 1] - track[r, i])


@njit(cache=True, error_model="numpy", _nrt=False)
def _slip_offsets(t, b_int, b_cos, b_sin, jitter, jdt, jit_cos, jit_sin, cage_slip):
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
def _faulty_bearing_forces(t, y, n, g, omega, b_int, b_par, ball_cos, ball_sin, anchor,
                           cage_slip, diag, want_diag, b_ang, b_off, b_def, gain):
    """Forces of the bearings with defects or off-size balls (``BI_FAULTY``).

    ``BI_FAULTY`` = 1 (race or ball defects only): :func:`_bearing_forces` has applied the
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
        cc, sc = _anchored_cos_sin(anchor, ib, angle)
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
def _bearing_forces(t, y, n, g, omega, b_int, b_par, ball_cos, ball_sin, anchor, cage_slip,
                    diag, want_diag):
    """Fukata forces of all bearings with balls at offsets ``ball_cos/sin`` from the cage
    and cages shifted by the slip angles ``cage_slip`` (zeros without slip); ``t`` is the
    equivalent time τ of the nominal rotation (``KernelParams``).

    Written flat on purpose: with helper functions inlined, a jitter branch, or arrays taken
    out of ``P`` inside the loop, numba stops vectorising the ball loop (2-3× slower).
    Bearings with race or ball defects (``BI_FAULTY`` = 1) get the healthy law here and
    their defects' change from :func:`_faulty_bearing_forces`; bearings with an off-size ball
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
        cc, sc = _anchored_cos_sin(anchor, ib, angle)
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
def _mesh_forces(t, sr, y, n, g, P, W, diag, want_diag):
    """Forces of the tooth pairs in the potential-contact zone: exact rigid-body geometry,
    elastic force from the table (``MI_MODE`` 0) or from the on-line hybrid contact solve
    (1, paper 001 model A), stiffness-proportional hysteretic damping (``MP_BETA``) or Koster
    squeeze damping, smoothed Coulomb friction. ``t`` is the equivalent time τ of the
    nominal rotation and ``sr`` the speed over the reference speed (1 at constant speed).

    Faults: per-tooth stiffness factors and separations (``MI_TEETH``; on the on-line solve a
    factor f of a pair becomes the extra compliance (1/f − 1)/k of its own λ, k the run's
    table stiffness at s, so a pair alone in contact is f times as stiff), and eccentric gears
    (``MI_ECC``: the contact geometry uses each gear's geometric centre, turning about its
    shaft; moments and contact velocities use the shaft centre).

    Pass 1 stores each slot's geometry in ``S`` (columns ``SG_*``); in hybrid mode the
    interferences of all slots are then solved together (out-of-zone slots enter with a
    large negative interference, so they stay unloaded); pass 2 applies the forces.
    Inlined into the integrator, so taking the arrays out of ``P`` and ``W`` costs nothing."""
    m_int, mp, geo, tab_k, tab_e = P.m_int, P.m_par, P.geo, P.tab_k, P.tab_e
    teeth1, teeth2, hp, hd1, hc1, hd2, hc2 = P.teeth1, P.teeth2, P.hp, P.hd1, P.hc1, P.hd2, P.hc2
    tk1, tk2, te1, te2, ecc = P.tk1, P.tk2, P.te1, P.te2, P.ecc
    S, hw, hdelta, hrho1, hrho2 = W.slots, W.hwork, W.hdelta, W.hrho1, W.hrho2
    hchi1, hchi2, hout, hstat, psi_anchor = W.hchi1, W.hchi2, W.hout, W.hstat, W.psi
    hext = W.hext
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
    # physical involute origins of the reference pair (tooth 0 on both gears)
    psi1 = mp[MP_OM1] * t + y[i1 + 2] + mp[MP_PSI10]
    psi2 = mp[MP_PSI20] - (mp[MP_OM2] * t + y[i2 + 2])
    trig_done = False
    cp1 = sp1 = cp2 = sp2 = 0.0
    # geometric centres (the shaft centres unless a gear is eccentric)
    gx1 = c1x
    gy1 = c1y
    gx2 = c2x
    gy2 = c2y
    if m_int[MI_ECC] != 0:
        cp1, sp1 = _anchored_cos_sin(psi_anchor, 0, psi1)
        cp2, sp2 = _anchored_cos_sin(psi_anchor, 1, psi2)
        trig_done = True
        gx1 += ecc[0, 0] * (cp1 * ecc[0, 1] - sp1 * ecc[0, 2])
        gy1 += ecc[0, 0] * (sp1 * ecc[0, 1] + cp1 * ecc[0, 2])
        gx2 += ecc[1, 0] * (cp2 * ecc[1, 1] - sp2 * ecc[1, 2])
        gy2 += ecc[1, 0] * (sp2 * ecc[1, 1] + cp2 * ecc[1, 2])
    phi_t1, length, cos_t1, sin_t1 = _mesh_frame(gx1, gy1, gx2, gy2, rb1, rb2, mp)
    teeth_on = m_int[MI_TEETH] != 0
    # interference: nominal rolling cancels exactly (rb1·Ω1 = rb2·Ω2)
    delta_inv = (rb1 * (y[i1 + 2] + mp[MP_PSI10] - phi_t1)
                 + rb2 * (mp[MP_PSI20] - y[i2 + 2] - (phi_t1 + math.pi))
                 - length)
    s_ref = rb1 * (psi1 - phi_t1)
    m0f = math.floor((s_ref - mp[MP_SLO]) / pb)
    m0 = int(m0f)
    w1 = mp[MP_OM1] * sr + y[n + i1 + 2]
    w2 = -(mp[MP_OM2] * sr + y[n + i2 + 2])
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
            cp1, sp1 = _anchored_cos_sin(psi_anchor, 0, psi1)
            cp2, sp2 = _anchored_cos_sin(psi_anchor, 1, psi2)
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
    if hybrid:
        it = hybrid_forces_jit(hdelta, hrho1, hrho2, hchi1, hchi2, hp, hd1, hc1, hd2, hc2, hext,
                               hw, hout)
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
    """Placeholders ``(hp, hd1, hc1, hd2, hc2)`` of the hybrid fields when the mesh uses a
    table."""
    return (np.zeros(HP_SIZE), np.zeros(2), np.zeros((1, 2, 2)), np.zeros(2),
            np.zeros((1, 2, 2)))


def make_work(P):
    """Fresh scratch arrays :class:`Work` for :func:`rhs_jit` with model ``P``."""
    nb, max_balls = P.b_cos.shape
    slots = max(int(P.m_int[MI_SLOTS]), 1)
    return Work(np.empty(P.minv.shape[0]), np.zeros((nb, AN_SIZE)),
                np.empty((nb, max_balls)), np.empty((nb, max_balls)), np.zeros(nb),
                np.zeros((slots, SG_SIZE)),
                np.zeros(WORK_PER_N2 * slots * slots + WORK_PER_N * slots), np.zeros(slots),
                np.zeros(slots), np.zeros(slots), np.ones(slots), np.ones(slots),
                np.zeros(slots), np.zeros(slots), np.zeros(2), np.zeros((2, AN_SIZE)),
                P.track[:, 0].copy() if P.track.shape[0] else np.ones(1))


@njit(cache=True, inline="always", error_model="numpy")
def profile_at(prof, t0, dt, t):
    """(Θ, Ω, dΩ/dt, torque) of the profile table at time ``t`` (linear, clamped)."""
    m = prof.shape[0]
    u = (t - t0) / dt
    if u <= 0.0:
        i = 0
        f = 0.0
    elif u >= m - 1:
        i = m - 2
        f = 1.0
    else:
        i = int(u)
        f = u - i
    if m == 1:
        return prof[0, 0], prof[0, 1], prof[0, 2], prof[0, 3]
    a = prof[i]
    b = prof[i + 1]
    return (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]),
            a[3] + f * (b[3] - a[3]))


@njit(cache=True, inline="always", error_model="numpy")
def rhs_jit(t, y, dydt, row, P, diag, want_diag, W):
    """Equations of motion (module docstring); writes ``dydt[row]`` and optionally ``diag``."""
    minv = P.minv
    fext = P.fext
    n = minv.shape[0]
    g = W.g
    for i in range(n):
        g[i] = fext[i]
    # nominal rotation: τ = t, Ω/Ω_ref = 1, no acceleration at constant speed
    tau = t
    sr = 1.0
    ar = 0.0
    if P.m_int[MI_PROFILE] != 0:
        theta, omega_in, alpha_in, torque = profile_at(P.prof, P.m_par[MP_PT0],
                                                       P.m_par[MP_PDT], t)
        inv_ref = 1.0 / P.m_par[MP_OMREF]
        tau = theta * inv_ref
        sr = omega_in * inv_ref
        ar = alpha_in * inv_ref
        if P.m_int[MI_TDOF] >= 0:
            g[P.m_int[MI_TDOF]] = -torque
    if P.jitter.shape[2] > 1:
        _slip_offsets(t, P.b_int, P.b_cos, P.b_sin, P.jitter, P.m_par[MP_JDT], W.slip_cos,
                      W.slip_sin, W.cage_slip)
        ball_cos = W.slip_cos
        ball_sin = W.slip_sin
    else:
        ball_cos = P.b_cos
        ball_sin = P.b_sin
    if P.b_int.shape[0] > 0:
        _bearing_forces(tau, y, n, g, P.omega, P.b_int, P.b_par, ball_cos, ball_sin, W.cage,
                        W.cage_slip, diag, want_diag)
        if P.b_def.shape[0] > 0 or P.m_int[MI_FAULTY_BALLS] != 0:
            if P.track.shape[1] > 1:
                _track_gains(P.track, P.m_par[MP_TDT], t, W.def_gain)
            _faulty_bearing_forces(tau, y, n, g, P.omega, P.b_int, P.b_par, ball_cos,
                                   ball_sin, W.cage, W.cage_slip, diag, want_diag, P.b_ang,
                                   P.b_off, P.b_def, W.def_gain)
    if P.m_int[MI_ON] != 0:
        _mesh_forces(tau, sr, y, n, g, P, W, diag, want_diag)
    linear_accel_jit(y, g, minv, P.springs, P.spring_ends, dydt, row)
    if ar != 0.0:
        # deviation coordinates: the nominal rotation's acceleration acts as an inertia load
        for i in range(n):
            dydt[row, n + i] -= P.omega[i] * ar


class IntegratorBuffers(NamedTuple):
    """Buffers ``B`` of :func:`integrate_jit`."""

    k: np.ndarray        # (s, dim) stage slopes
    y: np.ndarray        # (dim,) state
    yi: np.ndarray       # (dim,) stage state
    scratch: np.ndarray  # (n_diag,) output forces of the current step


def make_integrator_buffers(tableau_b, dim, n_diag):
    """Buffers of :func:`integrate_jit` for a scheme of ``len(tableau_b)`` stages."""
    return IntegratorBuffers(np.zeros((tableau_b.shape[0], dim)), np.empty(dim),
                             np.empty(dim), np.empty(n_diag))


@njit(cache=True, error_model="numpy", _nrt=False)
def integrate_jit(y0, t0, h, n_out, substeps, m_offset, rk_a, rk_b, rk_c, P, W, B, out_y,
                  out_diag, max_disp, max_rot, trans_mask):
    """Fixed-step explicit Runge-Kutta with output every ``substeps`` steps.

    The scheme is data: ``rk_a`` (s, s) strictly lower triangular, ``rk_b`` (s,), ``rk_c`` (s,).
    ``W`` is the :class:`Work` of :func:`make_work`, ``B`` the :class:`IntegratorBuffers` of
    :func:`make_integrator_buffers`. Sample ``m`` of ``out_y`` is the state at
    ``t0 + (m_offset + m)·substeps·h``; ``out_diag[m]`` holds the output forces at that
    instant (from the first stage of the following step, so they cost nothing extra). A long
    run may be integrated in chunks, each starting from the last state of the one before
    with the same ``W`` and the count of samples before it in ``m_offset``: the chunks then
    reproduce one call bit for bit.

    Returns
    -------
    int
        −1 on success, else the index of the first output sample that was non-finite or
        exceeded ``max_disp`` on a translational DOF (``trans_mask``) or ``max_rot`` on a
        rotational one.
    """
    k = B.k
    y = B.y
    yi = B.yi
    scratch = B.scratch
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
            t = t0 + ((m_offset + m) * substeps + sub) * h
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
