"""Right-hand side of the equations of motion and the fixed-step Runge-Kutta integrator.

The numba kernels that assemble eq. 1 of paper 001 from the bearing forces
(:mod:`cmsim.dynamics._bearing_kernels`), the mesh forces (:mod:`cmsim.dynamics._mesh_kernels`)
and the linear springs, and integrate it. The arrays travel in two named tuples owned by this
module — :class:`KernelParams` ``P`` (the model, read only) and :class:`Work` ``W``
(scratch) —; :mod:`cmsim.dynamics.model` fills ``P`` (its fields are documented on the class).

Right-hand side contract: ``rhs_jit(t, y, dydt, row, P, diag, want_diag, W)`` with ``y = [q, v]``
(shape ``(2n,)``), ``q`` the DOF deviations from the nominal rigid rotation (translations in m,
rotations in rad, rotations of shaft 2 counted positive in its own sense of motion), ``v`` their
rates; it writes row ``row`` of the 2-D array ``dydt`` with ``[v, M⁻¹(f_ext + g(t, q, v) − K q
− C v)]`` where ``g`` holds the bearing and mesh forces. With ``want_diag`` it also writes the
output forces into ``diag``. The finiteness checks live in the integrator, which is compiled
without fastmath.

This is one of the kernel modules of :mod:`cmsim.dynamics` (rotation anchors, bearing forces,
mesh forces, right-hand side and integrator): they share the numba convention —
``@njit(cache=True)``, float64/int64 arrays and scalars only, no Python objects, no random
numbers; hot-path code never slices arrays and never takes arrays out of tuples inside loops
(numba takes an atomic reference count for each); the force and integrator kernels are compiled
without numba's reference-counting runtime (``_nrt=False``: they allocate nothing, the caller
passes every buffer); the integrator releases the GIL (``nogil=True``: a healthy and a
changed run go side by side on two threads); small kernels are inlined at numba-IR level
(``inline="always"``: a call with array arguments costs about 25 ns). """

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import literal_unroll, njit

from cmsim.dynamics._bearing_kernels import (DF_SIZE, bearing_forces_jit, cage_slip_jit,
                                             faulty_bearing_forces_jit, slip_offsets_jit,
                                             track_gains_jit)
from cmsim.dynamics._mesh_kernels import (MI_BALL_SLIP, MI_FAULTY_BALLS, MI_ON, MI_PROFILE,
                                          MI_SLOTS, MI_TDOF,
                                          MP_JDT, MP_OMREF, MP_PDT, MP_PT0, MP_TDT, SG_SIZE,
                                          mesh_forces_jit)
from cmsim.dynamics._rotation_kernels import AN_SIZE
from cmsim.mesh_stiffness._hybrid_kernels import WORK_PER_N, WORK_PER_N2

# columns of the profile table ``prof``: input-shaft angle Θ (rad), speed Ω (rad/s),
# acceleration (rad/s²), output torque (N·m), on the uniform grid MP_PT0 + i·MP_PDT
PR_THETA, PR_OMEGA, PR_ALPHA, PR_TORQUE = 0, 1, 2, 3
PR_SIZE = 4


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
    ecc : (2, 4) eccentricity of each gear's geometric centre: amplitude m, cos and sin of
        its phase rad − the gear's reference phase, and the mass on that centre, kg.
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
            np.ones((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((2, 4)))


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
def nominal_rotation_jit(t, P, g):
    """``(τ, Ω/Ω_ref, (dΩ/dt)/Ω_ref)`` of the nominal rotation at time ``t`` (``t, 1, 0`` at
    constant speed); with a profile, also its output torque into ``g``."""
    if P.m_int[MI_PROFILE] == 0:
        return t, 1.0, 0.0
    theta, omega_in, alpha_in, torque = profile_at(P.prof, P.m_par[MP_PT0], P.m_par[MP_PDT], t)
    inv_ref = 1.0 / P.m_par[MP_OMREF]
    if P.m_int[MI_TDOF] >= 0:
        g[P.m_int[MI_TDOF]] = -torque
    return theta * inv_ref, omega_in * inv_ref, alpha_in * inv_ref


@njit(cache=True, inline="always", error_model="numpy")
def slip_at_jit(t, P, W):
    """The balls' and cages' slip at time ``t`` into ``W``; True when the balls move off their
    nominal offsets (``W.slip_cos``, ``W.slip_sin`` then hold them), False when they keep
    ``P.b_cos``, ``P.b_sin`` (a cage-only slip, or none)."""
    if P.jitter.shape[2] > 1 and P.m_int[MI_BALL_SLIP] != 0:
        slip_offsets_jit(t, P.b_int, P.b_cos, P.b_sin, P.jitter, P.m_par[MP_JDT], W.slip_cos,
                         W.slip_sin, W.cage_slip)
        return True
    if P.jitter.shape[2] > 1:
        # cages only: the per-ball grid (all zero) is not read
        cage_slip_jit(t, P.b_int, P.b_cos, P.jitter, P.m_par[MP_JDT], W.cage_slip)
    return False


@njit(cache=True, inline="always", error_model="numpy")
def defect_forces_jit(t, tau, y, n, g, P, W, ball_cos, ball_sin, diag, want_diag):
    """The change race and ball defects and off-size balls make to the bearing forces (none
    without them), at time ``t`` and equivalent time ``tau``."""
    if P.b_def.shape[0] > 0 or P.m_int[MI_FAULTY_BALLS] != 0:
        if P.track.shape[1] > 1:
            track_gains_jit(P.track, P.m_par[MP_TDT], t, W.def_gain)
        faulty_bearing_forces_jit(tau, y, n, g, P.omega, P.b_int, P.b_par, ball_cos, ball_sin,
                                  W.cage, W.cage_slip, diag, want_diag, P.b_ang, P.b_off,
                                  P.b_def, W.def_gain)


@njit(cache=True, inline="always", error_model="numpy")
def rhs_jit(t, y, dydt, row, P, diag, want_diag, W):
    """Equations of motion (module docstring); writes ``dydt[row]`` and optionally ``diag``."""
    minv = P.minv
    fext = P.fext
    n = minv.shape[0]
    g = W.g
    for i in range(n):
        g[i] = fext[i]
    tau, sr, ar = nominal_rotation_jit(t, P, g)
    if slip_at_jit(t, P, W):
        ball_cos = W.slip_cos
        ball_sin = W.slip_sin
    else:
        ball_cos = P.b_cos
        ball_sin = P.b_sin
    if P.b_int.shape[0] > 0:
        bearing_forces_jit(tau, y, n, g, P.omega, P.b_int, P.b_par, ball_cos, ball_sin, W.cage,
                           W.cage_slip, diag, want_diag)
        defect_forces_jit(t, tau, y, n, g, P, W, ball_cos, ball_sin, diag, want_diag)
    if P.m_int[MI_ON] != 0:
        mesh_forces_jit(tau, sr, y, n, g, P, W, diag, want_diag)
    linear_accel_jit(y, g, minv, P.springs, P.spring_ends, dydt, row)
    if ar != 0.0:
        # deviation coordinates: the nominal rotation's acceleration acts as an inertia load
        for i in range(n):
            dydt[row, n + i] -= P.omega[i] * ar


#: The fields of :class:`Work` by position (what :func:`static_residual_jit` resets).
_WORK_INDICES = tuple(range(len(Work._fields)))


@njit(cache=True, error_model="numpy")
def static_residual_jit(t, q, mass, P, W, W0, y, dydt, diag, out):
    """``out = M·q̈`` at rest (velocities zero) at time ``t`` for displacements ``q``: the
    kernel's right-hand side with the scratch ``W`` first reset to ``W0`` (fresh scratch of
    :func:`make_work`, so that each call reads as with new arrays) — one numba call per
    residual of a quasi-static solve instead of seventeen allocations. ``y`` (2n,),
    ``dydt`` (1, 2n), ``diag`` buffers."""
    for i in literal_unroll(_WORK_INDICES):        # every field of Work, whatever its shape
        W[i][...] = W0[i]
    n = q.shape[0]
    for i in range(n):
        y[i] = q[i]
        y[n + i] = 0.0
    rhs_jit(t, y, dydt, 0, P, diag, False, W)
    for i in range(n):
        out[i] = mass[i] * dydt[0, n + i]


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


#: States of one chain's block in a :class:`LinearPropagator` (a chain of at most 4 DOFs):
#: a fixed size, so the block products unroll and vectorise.
CHAIN_STATES = 8


class LinearPropagator(NamedTuple):
    """Exact propagator ``X`` of the linear part an exponential scheme integrates in closed form.

    An exponential (Lawson) scheme splits ``y' = L y + N(t, y)`` where ``L`` is the linear
    spring-damper part of some chains of DOFs (:mod:`cmsim.dynamics.exponential` chooses
    them) and ``N`` everything else, and runs the Runge-Kutta tableau on
    ``w = e^{−(t − t_n)L} y``. ``L`` is block diagonal, one block per chain of ``m`` DOFs
    (``2m <=`` :data:`CHAIN_STATES`): ``idx[b, :2m]`` are chain ``b``'s state entries (its
    DOFs' positions, then their velocities), ``size[b] = 2m``. ``ahead[i, b] = e^{c_i h L_b}``
    for each stage node ``c_i`` and ``ahead[s, b] = e^{h L_b}``; ``back[i, b] =
    e^{−c_i h L_b}``, each padded with zeros to :data:`CHAIN_STATES`. No chains (see
    :func:`no_propagator`) is the plain Runge-Kutta scheme, bit for bit.
    """

    idx: np.ndarray      # int64 (chains, CHAIN_STATES) state entries of each chain
    size: np.ndarray     # int64 (chains,) states of each chain
    ahead: np.ndarray    # (s + 1, chains, CHAIN_STATES, CHAIN_STATES)
    back: np.ndarray     # (s, chains, CHAIN_STATES, CHAIN_STATES)
    tmp: np.ndarray      # (CHAIN_STATES,) scratch


def no_propagator(stages):
    """The neutral :class:`LinearPropagator` of a plain ``stages``-stage scheme."""
    return LinearPropagator(np.zeros((0, CHAIN_STATES), dtype=np.int64),
                            np.zeros(0, dtype=np.int64),
                            np.zeros((stages + 1, 0, CHAIN_STATES, CHAIN_STATES)),
                            np.zeros((stages, 0, CHAIN_STATES, CHAIN_STATES)),
                            np.zeros(CHAIN_STATES))


@njit(cache=True, inline="always", error_model="numpy")
def _propagate_row_jit(X, which, x, row):
    """``x[row, idx] = back[which] @ x[row, idx]`` chain by chain, from the velocity entries
    only (the slope ``N`` has no position entries there: ``L`` carries the chains'
    kinematics)."""
    tmp = X.tmp
    for b in range(X.size.shape[0]):
        size = X.size[b]
        half = size // 2
        for i in range(CHAIN_STATES):
            tmp[i] = 0.0
        for i in range(half, size):
            tmp[i] = x[row, X.idx[b, i]]
        for i in range(size):
            acc = 0.0
            for j in range(CHAIN_STATES):
                acc += X.back[which, b, i, j] * tmp[j]
            x[row, X.idx[b, i]] = acc


@njit(cache=True, inline="always", error_model="numpy")
def _propagate_jit(X, which, x):
    """``x[idx] = ahead[which] @ x[idx]`` chain by chain (a state)."""
    tmp = X.tmp
    for b in range(X.size.shape[0]):
        size = X.size[b]
        for i in range(CHAIN_STATES):
            tmp[i] = 0.0
        for i in range(size):
            tmp[i] = x[X.idx[b, i]]
        for i in range(size):
            acc = 0.0
            for j in range(CHAIN_STATES):
                acc += X.ahead[which, b, i, j] * tmp[j]
            x[X.idx[b, i]] = acc


@njit(cache=True, error_model="numpy", _nrt=False, nogil=True)
def integrate_jit(y0, t0, h, n_out, substeps, m_offset, rk_a, rk_b, rk_c, X, P, W, B, out_y,
                  out_diag, max_disp, max_rot, trans_mask):
    """Fixed-step explicit Runge-Kutta with output every ``substeps`` steps.

    The scheme is data: ``rk_a`` (s, s) strictly lower triangular, ``rk_b`` (s,), ``rk_c`` (s,),
    and ``X`` the :class:`LinearPropagator` of its exponential (Lawson) form — stage ``i``
    evaluates ``N`` at ``e^{c_i h L} W_i`` and its slope is ``e^{−c_i h L} N``, the step ends
    with ``e^{hL}`` — or :func:`no_propagator` for the plain scheme; ``P`` then holds the
    springs of ``N`` only.
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
    n_ex = X.size.shape[0]
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
            # one call of the inlined right-hand side, its stage and its outputs switch as
            # values (c_0 = 0): a second call with a constant False compiled it all twice
            for st in range(ns):
                if st > 0:
                    for i in range(dim):
                        acc = y[i]
                        for jj in range(st):
                            if rk_a[st, jj] != 0.0:          # (a zero weight adds nothing)
                                acc += h * rk_a[st, jj] * k[jj, i]
                        yi[i] = acc
                    if n_ex > 0:
                        _propagate_jit(X, st, yi)
                want = sub == 0 and st == 0
                rhs_jit(t + rk_c[st] * h, yi if st > 0 else y, k, st, P, scratch, want, W)
                if want:
                    for i in range(scratch.shape[0]):
                        out_diag[m, i] = scratch[i]
                    if m == n_out - 1:
                        return -1
                if st == 0:
                    # L carries the exact chains' kinematics: N has no position entries
                    # there (c_0 = 0: no propagation)
                    for b in range(n_ex):
                        for i in range(X.size[b] // 2):
                            k[0, X.idx[b, i]] = 0.0
                elif n_ex > 0:
                    _propagate_row_jit(X, st, k, st)
            for i in range(dim):
                acc = 0.0
                for st in range(ns):
                    if rk_b[st] != 0.0:
                        acc += rk_b[st] * k[st, i]
                y[i] += h * acc
            if n_ex > 0:
                _propagate_jit(X, ns, y)
    return -1
