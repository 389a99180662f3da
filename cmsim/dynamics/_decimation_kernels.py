"""The anti-alias FIR of :class:`~cmsim.dynamics.decimation.AntiAliasFilter`: a numba kernel.

:func:`fir_decimate_jit` computes the decimated outputs of a FIR over the columns of a
row-major block, each output summed tap by tap from 0.0 in the order
:func:`scipy.signal.upfirdn` uses (its result bit for bit: there is no reassociation, and
without fastmath no fused multiply-add), but with eight independent sums in flight instead of
one, so the adds do not wait for each other: two outputs × four columns, then eight outputs of
each column left over (as cheap per column, so a block of any width is read as it is). The
block is read through its flat view with unsigned indices: a signed index costs a
negative-index test on every load, which made the loop three times slower.

The numba rule of every kernel module of :mod:`cmsim.dynamics` (in full in
:mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``, float64/int64 arrays and
scalars only, no Python objects, no random numbers, no allocation in the hot path.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Columns the kernel's main loop takes at once (the rest one by one).
FIR_LANES = 4


@njit(cache=True, error_model="numpy", _nrt=False)
def fir_decimate_jit(x, n_cols, h_flip, step, out):
    """``out[m, c] = Σ_j x[(m·step + j)·n_cols + c]·h_flip[j]`` (j = 0 … N − 1, summed in that
    order).

    ``x`` the flat view of a C-contiguous (L, n_cols) block, ``h_flip`` (N,) the taps
    reversed, ``out`` (n_out, n_cols) with ``(n_out − 1)·step + N <= L``.
    """
    n_taps = h_flip.shape[0]
    n_out = out.shape[0]
    row = np.uint64(n_cols)
    stride = np.uint64(step) * row                 # from one output's window to the next
    one = np.uint64(1)
    two = np.uint64(2)
    three = np.uint64(3)
    full = n_cols - n_cols % FIR_LANES
    for c0 in range(0, full, FIR_LANES):
        m = 0
        while m < n_out:
            a = np.uint64(m) * stride + np.uint64(c0)
            b = a + stride if m + 1 < n_out else a
            a0 = 0.0
            a1 = 0.0
            a2 = 0.0
            a3 = 0.0
            b0 = 0.0
            b1 = 0.0
            b2 = 0.0
            b3 = 0.0
            for j in range(n_taps):
                hj = h_flip[j]
                a0 += x[a] * hj
                a1 += x[a + one] * hj
                a2 += x[a + two] * hj
                a3 += x[a + three] * hj
                b0 += x[b] * hj
                b1 += x[b + one] * hj
                b2 += x[b + two] * hj
                b3 += x[b + three] * hj
                a += row
                b += row
            out[m, c0] = a0
            out[m, c0 + 1] = a1
            out[m, c0 + 2] = a2
            out[m, c0 + 3] = a3
            if m + 1 < n_out:
                out[m + 1, c0] = b0
                out[m + 1, c0 + 1] = b1
                out[m + 1, c0 + 2] = b2
                out[m + 1, c0 + 3] = b3
            m += 2
    s2 = np.uint64(2) * stride
    s3 = np.uint64(3) * stride
    s4 = np.uint64(4) * stride
    s5 = np.uint64(5) * stride
    s6 = np.uint64(6) * stride
    s7 = np.uint64(7) * stride
    for c in range(full, n_cols):
        m = 0
        while m + 8 <= n_out:
            a = np.uint64(m) * stride + np.uint64(c)
            a0 = 0.0
            a1 = 0.0
            a2 = 0.0
            a3 = 0.0
            a4 = 0.0
            a5 = 0.0
            a6 = 0.0
            a7 = 0.0
            for j in range(n_taps):
                hj = h_flip[j]
                a0 += x[a] * hj
                a1 += x[a + stride] * hj
                a2 += x[a + s2] * hj
                a3 += x[a + s3] * hj
                a4 += x[a + s4] * hj
                a5 += x[a + s5] * hj
                a6 += x[a + s6] * hj
                a7 += x[a + s7] * hj
                a += row
            out[m, c] = a0
            out[m + 1, c] = a1
            out[m + 2, c] = a2
            out[m + 3, c] = a3
            out[m + 4, c] = a4
            out[m + 5, c] = a5
            out[m + 6, c] = a6
            out[m + 7, c] = a7
            m += 8
        for m in range(m, n_out):
            a = np.uint64(m) * stride + np.uint64(c)
            acc = 0.0
            for j in range(n_taps):
                acc += x[a] * h_flip[j]
                a += row
            out[m, c] = acc


@njit(cache=True, error_model="numpy", _nrt=False)
def gather_columns_jit(states, diag, lo, q_cols, d_cols, buf, row0):
    """Copy rows ``lo:`` of the columns ``q_cols`` of ``states`` and ``d_cols`` of ``diag``
    side by side into ``buf`` from row ``row0`` on (one pass over the rows, each read once;
    unsigned indices into the blocks' flat views, as :func:`fir_decimate_jit`)."""
    nq = q_cols.shape[0]
    nd = d_cols.shape[0]
    s_flat = states.reshape(states.size)
    d_flat = diag.reshape(diag.size)
    b_flat = buf.reshape(buf.size)
    s_row = np.uint64(states.shape[1])
    d_row = np.uint64(diag.shape[1])
    b_row = np.uint64(buf.shape[1])
    s = np.uint64(lo) * s_row
    d = np.uint64(lo) * d_row
    b = np.uint64(row0) * b_row
    for _ in range(states.shape[0] - lo):
        for j in range(nq):
            b_flat[b + np.uint64(j)] = s_flat[s + np.uint64(q_cols[j])]
        for j in range(nd):
            b_flat[b + np.uint64(nq + j)] = d_flat[d + np.uint64(d_cols[j])]
        s += s_row
        d += d_row
        b += b_row
