"""Numba kernels of the ball bearing (Fukata et al. 1985; paper 001 eqs. 8-9).

This module isolates the numba convention: ``@njit(cache=True)``, float64 arrays and scalars
only, no Python objects, no random numbers. Public wrappers with validation and docs live in
:mod:`cmsim.bearings.forces`.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def ball_forces_jit(x, y, cos_cage, sin_cage, cos_off, sin_off, k, p, c):
    """Resultant ball force (fx, fy) on the housing for inner-ring offset (x, y).

    Ball i sits at θ_i = θ_cage + off_i; δ_i = x cos θ_i + y sin θ_i − c (eq. 8);
    F = k Σ H(δ_i) δ_i^p (cos θ_i, sin θ_i) (eq. 9). ``cos_off``/``sin_off`` hold the ball
    offsets (spacing plus any jitter), length n_balls.
    """
    n = cos_off.shape[0]
    return ball_forces_row_jit(x, y, cos_cage, sin_cage, cos_off.reshape((1, n)),
                               sin_off.reshape((1, n)), 0, n, k, p, c)


@njit(cache=True, fastmath=True)
def ball_forces_row_jit(x, y, cos_cage, sin_cage, cos_off, sin_off, row, n_balls, k, p, c):
    """:func:`ball_forces_jit` on row ``row`` of 2-D offset tables (no array views).

    Branch-free: the Heaviside of eq. 9 is max(δ, 0), so the loop vectorises.
    """
    fx = 0.0
    fy = 0.0
    co = cos_off
    so = sin_off
    if p == 1.5:
        for i in range(n_balls):
            ci = cos_cage * co[row, i] - sin_cage * so[row, i]
            si = sin_cage * co[row, i] + cos_cage * so[row, i]
            d = max(x * ci + y * si - c, 0.0)
            f = d * math.sqrt(d)
            fx += f * ci
            fy += f * si
    else:
        for i in range(n_balls):
            ci = cos_cage * co[row, i] - sin_cage * so[row, i]
            si = sin_cage * co[row, i] + cos_cage * so[row, i]
            d = max(x * ci + y * si - c, 0.0)
            f = d ** p
            fx += f * ci
            fy += f * si
    return k * fx, k * fy


@njit(cache=True)
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


@njit(cache=True)
def loaded_ball_count_jit(x, y, cos_cage, sin_cage, cos_off, sin_off, c):
    """Number of balls with positive overlap."""
    n = 0
    for i in range(cos_off.shape[0]):
        ci = cos_cage * cos_off[i] - sin_cage * sin_off[i]
        si = sin_cage * cos_off[i] + cos_cage * sin_off[i]
        if x * ci + y * si - c > 0.0:
            n += 1
    return n
