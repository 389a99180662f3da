"""Numba kernel of :func:`cmsim.spectra.kurtogram.spectral_kurtosis`: the STFT's second and
fourth moments per bin.

numpy read them as ``p2.mean(axis=0)`` and ``(p2 ** 2).mean(axis=0)`` of ``p2 = |z|²``: three
temporaries of the STFT's size and two reductions across its rows, 0.2-0.4 ms a level on the
few bins of a short window (most of a kurtogram's cost; a comparison reads one per simulated
chain, over a thousand a record). numpy reduces a C-contiguous array over its first axis row
by row, each bin's sum in the rows' order; the kernel sums in that order, squares as numpy
does, and divides by the count as ``mean`` does, so the moments are the same to the bit.
``@njit(cache=True)``, complex128 arrays only.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def stft_moments_jit(z):
    """(⟨|z|²⟩, ⟨|z|⁴⟩) over the rows of ``z`` (segments × bins, complex128, C-contiguous)."""
    m, k = z.shape
    s2 = np.zeros(k)
    s4 = np.zeros(k)
    for i in range(m):
        for j in range(k):
            re = z[i, j].real
            im = z[i, j].imag
            p = re * re + im * im
            s2[j] += p
            s4[j] += p * p
    return s2 / m, s4 / m
