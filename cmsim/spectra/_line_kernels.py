"""Numba kernels of :func:`cmsim.spectra.line_detector.detect_lines`: the greedy claim of each
line's bins, strongest peak first, and the excess power over each line's bins.

In Python each of a spectrum's few hundred peaks cost a loop of numpy scalar reads and a
``np.sum`` (6.7 ms a spectrum of 3 000 bins, 446 peaks; a machine-calibrated dataset record
reads four). The kernels keep the Python version's every choice: peaks in order of their PSD,
ties in order of frequency (a stable sort), and each line's excess summed as numpy sums a
contiguous float64 slice (pairwise in blocks of 8 up to 128 values, halves above), so the lines
and their amplitudes are the same to the bit. ``@njit(cache=True)``, float64 and int64 arrays
only.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: numpy's pairwise summation: values summed in 8 running partial sums up to this many,
#: halved above (numpy/_core/src/umath/loops_utils.h.src, ``PW_BLOCKSIZE``).
_PW_BLOCKSIZE = 128


@njit(cache=True)
def line_spans_jit(freq, psd, ratio, thr, lowest_hz, tolerance, df):
    """The lines' peaks and bins: (owner (n,) — the line of each bin or -1, peak, lo, hi (k,)
    — line j peaks at bin ``peak[j]`` and holds bins ``lo[j]:hi[j]``), lines in the order
    claimed (strongest peak first).

    A peak is a local maximum of ``psd`` at bins 2 to n − 3 with ``ratio`` over ``thr`` and a
    frequency of ``lowest_hz`` or more; its bins are its main lobe (± 2) and the contiguous
    bins beside it still over ``thr``, at most ``max(2, ⌈tolerance·f/df⌉)`` each side, none
    that a stronger line holds.
    """
    n = psd.size
    cand = np.empty(max(n - 4, 0), dtype=np.int64)
    m = 0
    for j in range(2, n - 2):
        if (ratio[j] > thr and freq[j] >= lowest_hz and psd[j] >= psd[j - 1]
                and psd[j] >= psd[j + 1]):
            cand[m] = j
            m += 1
    cand = cand[:m]
    order = cand[np.argsort(-psd[cand], kind="mergesort")]
    owner = np.full(n, -1, dtype=np.int64)
    peak = np.empty(m, dtype=np.int64)
    lo_out = np.empty(m, dtype=np.int64)
    hi_out = np.empty(m, dtype=np.int64)
    k = 0
    for i in order:
        if owner[i] >= 0:                # a local maximum within a stronger line's bins
            continue
        most = max(2, math.ceil(tolerance * freq[i] / df))
        lo = i
        hi = i
        while (lo - 1 >= 0 and owner[lo - 1] < 0 and i - (lo - 1) <= most
               and (i - (lo - 1) <= 2 or ratio[lo - 1] > thr)):
            lo -= 1
        while (hi + 1 < n and owner[hi + 1] < 0 and hi + 1 - i <= most
               and (hi + 1 - i <= 2 or ratio[hi + 1] > thr)):
            hi += 1
        owner[lo:hi + 1] = k
        peak[k] = i
        lo_out[k] = lo
        hi_out[k] = hi + 1
        k += 1
    return owner, peak[:k], lo_out[:k], hi_out[:k]


@njit(cache=True)
def _pairwise_sum(a, start, n):
    """numpy's sum of the ``n`` values of ``a`` from ``start`` (contiguous float64)."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[start + i]
        return res
    if n <= _PW_BLOCKSIZE:
        r0 = a[start]
        r1 = a[start + 1]
        r2 = a[start + 2]
        r3 = a[start + 3]
        r4 = a[start + 4]
        r5 = a[start + 5]
        r6 = a[start + 6]
        r7 = a[start + 7]
        i = 8
        while i < n - (n % 8):
            r0 += a[start + i]
            r1 += a[start + i + 1]
            r2 += a[start + i + 2]
            r3 += a[start + i + 3]
            r4 += a[start + i + 4]
            r5 += a[start + i + 5]
            r6 += a[start + i + 6]
            r7 += a[start + i + 7]
            i += 8
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < n:
            res += a[start + i]
            i += 1
        return res
    n2 = n // 2
    n2 -= n2 % 8
    return _pairwise_sum(a, start, n2) + _pairwise_sum(a, start + n2, n - n2)


@njit(cache=True)
def span_sums_jit(values, lo, hi):
    """Σ ``values[lo[j]:hi[j]]`` of each span j, summed as numpy sums the slice."""
    out = np.empty(lo.size)
    for j in range(lo.size):
        out[j] = _pairwise_sum(values, lo[j], hi[j] - lo[j])
    return out
