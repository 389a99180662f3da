"""Numba kernels of the top-level modules: the housing path of :mod:`cmsim.sensors`.

:func:`housing_path_jit` interpolates forces by an integer factor k through a FIR, runs the
housing modes (one biquad each, added in parallel) over the interpolated samples and keeps
every k-th sample of their sum, for several forces in one call, a block of
:data:`HOUSING_BLOCK` input samples at a time (its interpolated samples stay in the cache and
are never stored whole).

* The interpolation is :func:`scipy.signal.resample_poly`'s (``up = k``, ``down = 1``, with
  :func:`cmsim.sensors.interpolation_filter` for its window, its output cut to the input's
  instants) with the same sums in the same order: fast sample
  m = j·k + t is ``0.0 + Σ_i x[i]·h[m + half − i·k]`` over the inputs i near j, i
  increasing. Each phase t reads its taps as one row (zero where the filter has none) and
  the signal padded with zeros; like the zero taps ``resample_poly`` pads its own filter
  with, the products these add are ±0.0 and change nothing (a running sum of them is never
  −0.0). Each tap adds its products to a whole block of one phase's outputs (the taps
  outside, the outputs inside: a contiguous loop the vectoriser takes), each output's sum
  still in the order above.
* Each biquad is the direct form II transposed of :func:`scipy.signal.sosfilt` written with
  the same operations in the same order, and the modes are summed in the order
  ``((0 + y₁) + y₂) + …`` of adding one ``sosfilt`` output after another.

So the result is theirs bit for bit.

The numba rule (as in :mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``,
float64/int64 arrays and scalars only, no Python objects, no random numbers, no allocation in
the hot path.
"""

from __future__ import annotations

from numba import njit

#: Input samples per block of :func:`housing_path_jit` (scratch ``xk`` of k rows of this
#: many samples).
HOUSING_BLOCK = 512


@njit(cache=True, error_model="numpy", _nrt=False)
def _interpolate_block(x, taps, j0, j1, xk):
    """``xk[t, j − j0] = Σ_d x[j + d]·taps[t, d]`` (d increasing, from 0.0) for j in [j0, j1):
    fast sample j·k + t, ``x`` being the signal padded as :func:`housing_path_jit` says.

    The taps run in the outer loop and the block's outputs in the inner one: each tap adds
    its products to the whole block, a contiguous run the vectoriser takes whole (one product
    per output per tap, in the order of the sums above, so the same numbers)."""
    n_phases, n_taps = taps.shape
    m = j1 - j0
    for t in range(n_phases):
        g = taps[t]
        row = xk[t]
        for r in range(m):
            row[r] = 0.0
        for d in range(n_taps):
            gd = g[d]
            src = x[j0 + d: j0 + d + m]
            for r in range(m):
                row[r] += src[r] * gd


@njit(cache=True, error_model="numpy", _nrt=False)
def housing_path_jit(x, taps, sos, state, xk, out):
    """``out[c, j] = Σ_s y_s[j·k]``: the modes ``sos`` (n_modes, 6) driven from rest by
    signal c interpolated by k = ``taps.shape[0]``.

    ``taps`` (k, D) holds in row t the FIR's taps of fast sample j·k + t for the inputs
    j − b … j − b + D − 1 (zero outside the filter), ``x`` (C, n + D − 1) each signal after
    b zeros and before D − 1 − b (k = 1, D = 1, ``taps = [[1.0]]``: the signal itself).
    ``state`` (C, n_modes, 2) holds the biquads' delays (zeroed here); ``xk``
    (C, k, :data:`HOUSING_BLOCK`) a block's fast samples; ``out`` is (C, n). The signals'
    biquads run interleaved, sample by sample, so one's adds need not wait for its previous
    ones.
    """
    n_cols, n = out.shape
    k = taps.shape[0]
    n_modes = sos.shape[0]
    for c in range(n_cols):
        for s in range(n_modes):
            state[c, s, 0] = 0.0
            state[c, s, 1] = 0.0
    for j0 in range(0, n, HOUSING_BLOCK):
        j1 = min(j0 + HOUSING_BLOCK, n)
        for c in range(n_cols):
            _interpolate_block(x[c], taps, j0, j1, xk[c])
        for jj in range(j1 - j0):
            for t in range(k):
                keep = t == 0
                for c in range(n_cols):
                    v = xk[c, t, jj]
                    acc = 0.0
                    for s in range(n_modes):
                        y = sos[s, 0] * v + state[c, s, 0]
                        state[c, s, 0] = sos[s, 1] * v - sos[s, 4] * y + state[c, s, 1]
                        state[c, s, 1] = sos[s, 2] * v - sos[s, 5] * y
                        if keep:
                            acc = acc + y
                    if keep:
                        out[c, j0 + jj] = acc
