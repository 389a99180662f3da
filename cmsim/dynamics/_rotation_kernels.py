"""Trigonometry by rotation: cos and sin of slowly advancing angles (numba kernels).

The cage angles and the two gears' involute origin angles advance by small increments from
one call to the next. Each keeps an *anchor* (an angle and its exact cosine and sine, columns
``AN_*``); a call rotates the anchor by the small difference with a Taylor series (error below
1e-15 for |difference| <= :data:`ANCHOR_RAD`) and re-anchors with exact ``cos``/``sin`` only
when the difference grows past it — about once per hundred steps instead of twelve
transcendental calls per step. Results agree with direct trigonometry to rounding.

The numba rule of every kernel module of :mod:`cmsim.dynamics` (in full in
:mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``, float64/int64 arrays and
scalars only, no Python objects, no random numbers, no allocation in the hot path.
"""

from __future__ import annotations

import math

from numba import njit

# columns of an angle anchor (``W.cage``, ``W.psi``): angle, its cos and sin, valid flag
AN_ANGLE, AN_COS, AN_SIN, AN_VALID = 0, 1, 2, 3
AN_SIZE = 4
#: Largest angle (rad) a rotation anchor is carried by its Taylor series before re-anchoring.
ANCHOR_RAD = 0.05


@njit(cache=True, inline="always", error_model="numpy")
def rotate_small_jit(c0, s0, d):
    """cos and sin of (a + d) from those of a, for |d| <= ANCHOR_RAD (Taylor, < 1e-15)."""
    d2 = d * d
    cd = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0 - d2 * (1.0 / 40320.0))))
    sd = d * (1.0 - d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0))))
    return c0 * cd - s0 * sd, s0 * cd + c0 * sd


@njit(cache=True, inline="always", error_model="numpy")
def anchored_cos_sin_jit(anchor, row, angle):
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
    return rotate_small_jit(anchor[row, AN_COS], anchor[row, AN_SIN], d)
