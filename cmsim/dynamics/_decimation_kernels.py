"""The anti-alias FIR of :class:`~cmsim.dynamics.decimation.AntiAliasFilter`: a numba kernel.

:func:`fir_decimate_jit` computes the decimated outputs of a FIR over the columns of a
row-major block, each output summed tap by tap from 0.0 in the order
:func:`scipy.signal.upfirdn` uses (its result bit for bit: there is no reassociation, and
without fastmath no fused multiply-add), but with eight independent sums in flight (two
outputs × four columns) instead of one, so the adds do not wait for each other.

The numba rule of every kernel module of :mod:`cmsim.dynamics` (in full in
:mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``, float64/int64 arrays and
scalars only, no Python objects, no random numbers, no allocation in the hot path.
"""

from __future__ import annotations

from numba import njit

#: Columns the kernel takes at once; the block's width must be a multiple of it.
FIR_LANES = 4


@njit(cache=True, error_model="numpy", _nrt=False)
def fir_decimate_jit(x, h_flip, step, out):
    """``out[m, c] = Σ_j x[m·step + j, c]·h_flip[j]`` (j = 0 … N − 1, summed in that order).

    ``x`` (L, C) C-contiguous with C a multiple of :data:`FIR_LANES`, ``h_flip`` (N,) the
    taps reversed, ``out`` (n_out, C) with ``(n_out − 1)·step + N <= L``.
    """
    n_taps = h_flip.shape[0]
    n_out = out.shape[0]
    for c0 in range(0, x.shape[1], FIR_LANES):
        m = 0
        while m < n_out:
            i0 = m * step
            i1 = i0 + step if m + 1 < n_out else i0
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
                a0 += x[i0 + j, c0] * hj
                a1 += x[i0 + j, c0 + 1] * hj
                a2 += x[i0 + j, c0 + 2] * hj
                a3 += x[i0 + j, c0 + 3] * hj
                b0 += x[i1 + j, c0] * hj
                b1 += x[i1 + j, c0 + 1] * hj
                b2 += x[i1 + j, c0 + 2] * hj
                b3 += x[i1 + j, c0 + 3] * hj
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


@njit(cache=True, error_model="numpy", _nrt=False)
def gather_columns_jit(states, diag, lo, q_cols, d_cols, buf, row0):
    """Copy rows ``lo:`` of the columns ``q_cols`` of ``states`` and ``d_cols`` of ``diag``
    side by side into ``buf`` from row ``row0`` on (one pass over the rows, each read once)."""
    nq = q_cols.shape[0]
    nd = d_cols.shape[0]
    for r in range(states.shape[0] - lo):
        for j in range(nq):
            buf[row0 + r, j] = states[lo + r, q_cols[j]]
        for j in range(nd):
            buf[row0 + r, nq + j] = diag[lo + r, d_cols[j]]
