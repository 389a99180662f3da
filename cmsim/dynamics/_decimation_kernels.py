"""The anti-alias FIR of :class:`~cmsim.dynamics.decimation.AntiAliasFilter`: a numba kernel.

:func:`fir_decimate_jit` computes the decimated outputs of a FIR over the columns of a
row-major block, each output summed tap by tap from 0.0 in the order
:func:`scipy.signal.upfirdn` uses (its result bit for bit: there is no reassociation, and
without fastmath no fused multiply-add), but with eight independent sums in flight instead of
one, so the adds do not wait for each other: two outputs × four columns (one vector of four
lanes), then eight outputs of each column left over. A column left over costs about 0.6 of a
group of four (its loads are not contiguous), so a block of 4g + 1 columns is filtered as it
is and one of 4g + 2 or 4g + 3 is cheaper padded with zero columns to a whole group
(:meth:`~cmsim.dynamics.decimation.AntiAliasFilter.block_width`).

The numba rule of every kernel module of :mod:`cmsim.dynamics` (in full in
:mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``, float64/int64 arrays and
scalars only, no Python objects, no random numbers, no allocation in the hot path.
"""

from __future__ import annotations

from numba import njit

#: Columns the kernel's main loop takes at once (the rest one by one).
FIR_LANES = 4


@njit(cache=True, error_model="numpy", _nrt=False)
def fir_decimate_jit(x, h_flip, step, out):
    """``out[m, c] = Σ_j x[m·step + j, c]·h_flip[j]`` (j = 0 … N − 1, summed in that order).

    ``x`` (L, C) C-contiguous, ``h_flip`` (N,) the taps reversed, ``out`` (n_out, C) with
    ``(n_out − 1)·step + N <= L``.
    """
    n_taps = h_flip.shape[0]
    n_out = out.shape[0]
    n_cols = x.shape[1]
    full = n_cols - n_cols % FIR_LANES
    for c0 in range(0, full, FIR_LANES):
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
    for c in range(full, n_cols):
        m = 0
        while m < n_out:
            # outputs past the end read the first one's window again and are not written
            i0 = m * step
            i1 = i0 + step if m + 1 < n_out else i0
            i2 = i0 + 2 * step if m + 2 < n_out else i0
            i3 = i0 + 3 * step if m + 3 < n_out else i0
            i4 = i0 + 4 * step if m + 4 < n_out else i0
            i5 = i0 + 5 * step if m + 5 < n_out else i0
            i6 = i0 + 6 * step if m + 6 < n_out else i0
            i7 = i0 + 7 * step if m + 7 < n_out else i0
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
                a0 += x[i0 + j, c] * hj
                a1 += x[i1 + j, c] * hj
                a2 += x[i2 + j, c] * hj
                a3 += x[i3 + j, c] * hj
                a4 += x[i4 + j, c] * hj
                a5 += x[i5 + j, c] * hj
                a6 += x[i6 + j, c] * hj
                a7 += x[i7 + j, c] * hj
            out[m, c] = a0
            if m + 1 < n_out:
                out[m + 1, c] = a1
            if m + 2 < n_out:
                out[m + 2, c] = a2
            if m + 3 < n_out:
                out[m + 3, c] = a3
            if m + 4 < n_out:
                out[m + 4, c] = a4
            if m + 5 < n_out:
                out[m + 5, c] = a5
            if m + 6 < n_out:
                out[m + 6, c] = a6
            if m + 7 < n_out:
                out[m + 7, c] = a7
            m += 8


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
