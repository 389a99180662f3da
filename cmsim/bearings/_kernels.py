"""Numba kernels of the ball bearing (Fukata et al. 1985; paper 001 eqs. 8-9).

This module isolates the numba convention: ``@njit(cache=True)``, float64 arrays and scalars
only, no Python objects, no random numbers. Functions called inside the time loop are inlined
at numba-IR level (``inline="always"``): a numba call with array arguments costs about 25 ns.
Public wrappers with validation and docs live in :mod:`cmsim.bearings.forces`.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, error_model="numpy")
def ball_forces_jit(x, y, cos_cage, sin_cage, cos_off, sin_off, k, p, c):
    """Resultant ball force (fx, fy) on the housing for inner-ring offset (x, y).

    Ball i sits at θ_i = θ_cage + off_i; δ_i = x cos θ_i + y sin θ_i − c (eq. 8);
    F = k Σ H(δ_i) δ_i^p (cos θ_i, sin θ_i) (eq. 9). ``cos_off``/``sin_off`` hold the ball
    offsets (spacing plus any jitter), length n_balls.
    """
    n = cos_off.shape[0]
    xr = x * cos_cage + y * sin_cage
    yr = y * cos_cage - x * sin_cage
    fxr, fyr = ball_forces_cage_frame_jit(xr, yr, cos_off.reshape((1, n)),
                                          sin_off.reshape((1, n)), 0, n, k, p, c)
    return fxr * cos_cage - fyr * sin_cage, fyr * cos_cage + fxr * sin_cage


@njit(cache=True, inline="always", error_model="numpy")
def ball_forces_cage_frame_jit(xr, yr, cos_off, sin_off, row, n_balls, k, p, c):
    """Eq. 9 in the cage frame, where ball i sits at angle off_i (row ``row`` of 2-D tables).

    (xr, yr) is the inner-ring offset turned by −θ_cage; the returned force is in the same
    frame. Rotating the offset once instead of every ball halves the cost. Exponents other
    than 1.5 take a separate (not inlined) loop: with two alternative inlined loops in one
    body numba stops vectorising and the common case runs 2× slower.
    """
    if p == 1.5:
        return _ball_loop_ball_jit(xr, yr, cos_off, sin_off, row, n_balls, k, c)
    return _ball_loop_general_jit(xr, yr, cos_off, sin_off, row, n_balls, k, p, c)


@njit(cache=True, inline="always", error_model="numpy")
def _ball_loop_ball_jit(xr, yr, cos_off, sin_off, row, n_balls, k, c):
    """Eq. 9 for p = 1.5. Branch-free (the Heaviside is max(δ, 0)), so the loop vectorises
    when the caller is compiled with fastmath."""
    fx = 0.0
    fy = 0.0
    for i in range(n_balls):
        co = cos_off[row, i]
        so = sin_off[row, i]
        d = max(xr * co + yr * so - c, 0.0)
        f = d * math.sqrt(d)
        fx += f * co
        fy += f * so
    return k * fx, k * fy


@njit(cache=True, error_model="numpy")
def _ball_loop_general_jit(xr, yr, cos_off, sin_off, row, n_balls, k, p, c):
    """Eq. 9 for any exponent p (rollers: 1.1)."""
    fx = 0.0
    fy = 0.0
    for i in range(n_balls):
        co = cos_off[row, i]
        so = sin_off[row, i]
        d = max(xr * co + yr * so - c, 0.0)
        f = d ** p
        fx += f * co
        fy += f * so
    return k * fx, k * fy


@njit(cache=True, error_model="numpy")
def ball_tangent_stiffness_jit(x, y, cos_cage, sin_cage, cos_off, sin_off, k, p, c):
    """Tangent stiffness (kxx, kxy, kyy) = ∂(fx, fy)/∂(x, y) of :func:`ball_forces_jit`, N/m."""
    kxx = 0.0
    kxy = 0.0
    kyy = 0.0
    for i in range(cos_off.shape[0]):
        ci = cos_cage * cos_off[i] - sin_cage * sin_off[i]
        si = sin_cage * cos_off[i] + cos_cage * sin_off[i]
        d = x * ci + y * si - c
        if d > 0.0:
            g = k * p * d ** (p - 1.0)
            kxx += g * ci * ci
            kxy += g * ci * si
            kyy += g * si * si
    return kxx, kxy, kyy


@njit(cache=True, error_model="numpy")
def loaded_ball_count_jit(x, y, cos_cage, sin_cage, cos_off, sin_off, c):
    """Number of balls with positive overlap."""
    n = 0
    for i in range(cos_off.shape[0]):
        ci = cos_cage * cos_off[i] - sin_cage * sin_off[i]
        si = sin_cage * cos_off[i] + cos_cage * sin_off[i]
        if x * ci + y * si - c > 0.0:
            n += 1
    return n
