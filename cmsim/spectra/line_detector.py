"""THE line detector: the narrow lines of a power spectrum and the broadband floor between
them, wherever lines are not known in advance.

Where a line's frequency is known (a defect, a mesh harmonic) it is read with the line rule
(:mod:`cmsim.spectra.lines`); where it is not — what a machine's baseline holds beyond the
model's lines, which lines a model force makes — it is found here:

* a **line** is a local maximum standing :data:`LINE_MIN_DB` over the running median of the
  PSD over ± :data:`FLOOR_HALF_WIDTH_HZ` (a median is blind to lines narrower than half its
  window); its bins are its Hann main lobe (± 2 bins) and the bins beside it still standing
  that high, as far as :data:`LINE_TOLERANCE` of its frequency reaches (a speed wobble moves
  the k-th harmonic k times as far), none that a stronger line holds;
* its **amplitude** is that of the sinusoid of its excess power over the floor: Σ (P − floor)·df
  = A²/2 over its bins (a Hann line spreads its power over its main lobe);
* the **floor** is the running mean of the PSD with the lines' bins replaced by the median:
  unbiased (a running median alone sits 0.3-1.6 dB under the mean of a noisy estimate), and
  the power of a line too weak to be called stays in the broadband.

The machine's calibration (:mod:`cmsim.machine.calibration`) reads a baseline's and a model
force's lines with it, and a cause's change on a baseline (:mod:`cmsim.machine.change`)
finds the lines the healthy model makes with it — four spectra per record of a
machine-calibrated dataset, every entry of a signature library: the claim of each line's
bins and their sums run in numba (:mod:`cmsim.spectra._line_kernels`, the same lines to the
bit as the plain loop).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cmsim.spectra._line_kernels import line_spans_jit, span_sums_jit
from cmsim.spectra.floor import median_window_bins, running_median_floor

__all__ = ["DetectedLine", "detect_lines", "line_free", "span_sums", "LINE_MIN_DB",
           "FLOOR_HALF_WIDTH_HZ", "LINE_TOLERANCE", "MAX_LINES"]

#: Least height of a narrow line over the running median, dB (the median of a PSD averaged
#: over ~10 segments exceeds this by chance in about one bin in a thousand).
LINE_MIN_DB = 6.0
#: Half-width of the running median, Hz.
FLOOR_HALF_WIDTH_HZ = 25.0
#: Relative reach of a line's bins beyond its main lobe (a speed wobble moves every line in
#: proportion to its frequency: ±9 Hz at 2.3 kHz, within the Hann main lobe below 1 kHz at
#: 2-Hz bins).
LINE_TOLERANCE = 0.004
#: Most lines kept (the strongest).
MAX_LINES = 300


class DetectedLine(NamedTuple):
    """A narrow line of a power spectrum (a named tuple: a spectrum of a model force holds a
    few hundred, made afresh for every change a machine's library lays).

    Attributes
    ----------
    frequency_hz : float
        Frequency of its peak bin, Hz.
    amplitude : float
        Amplitude of the sinusoid of its excess power over the floor (the spectrum's unit
        without the /√Hz).
    bins : slice
        Its bins.
    """

    frequency_hz: float
    amplitude: float
    bins: slice


def median_floor(freq, psd, half_width_hz=FLOOR_HALF_WIDTH_HZ):
    """Running median of the PSD over ± ``half_width_hz`` (end bins repeated): blind to lines,
    biased low on a noisy estimate (what detection needs, not the level)."""
    return running_median_floor(freq, psd, half_width_hz, mode="nearest")


def detect_lines(freq, psd, *, min_db=LINE_MIN_DB, half_width_hz=FLOOR_HALF_WIDTH_HZ,
                 tolerance=LINE_TOLERANCE, max_lines=MAX_LINES, lowest_hz=2.0):
    """The narrow lines of a PSD, strongest first, and its broadband floor (module docstring).

    Parameters
    ----------
    freq : numpy.ndarray, shape (m,)
        Uniform frequency grid from 0, Hz.
    psd : numpy.ndarray, shape (m,)
        One-sided power spectral density (e.g. :func:`~cmsim.spectra.floor.segment_psd`).
    min_db : float
        Least height of a line over the running median, dB.
    half_width_hz : float
        Half-width of the running windows, Hz.
    tolerance : float
        Relative reach of a line's bins beyond its main lobe.
    max_lines : int
        Most lines returned.
    lowest_hz : float
        No line below this frequency, Hz.

    Returns
    -------
    (list of DetectedLine, numpy.ndarray)
        The lines and the floor (same shape as ``psd``, > 0).

    Examples
    --------
    >>> f = np.arange(0.0, 500.0, 1.0)
    >>> p = np.ones_like(f); p[100] = 1001.0
    >>> lines, floor = detect_lines(f, p)
    >>> [(ln.frequency_hz, round(ln.amplitude, 3)) for ln in lines], round(float(floor[50]), 3)
    ([(100.0, 44.721)], 1.0)
    """
    psd = np.asarray(psd, dtype=float)
    df = float(freq[1] - freq[0])
    med = median_floor(freq, psd, half_width_hz)
    ratio = psd / med
    thr = 10.0 ** (min_db / 10.0)
    owner, peak, lo, hi = line_spans_jit(np.asarray(freq, dtype=float), psd, ratio, thr,
                                         float(lowest_hz), float(tolerance), df)
    k = median_window_bins(freq, half_width_hz)
    masked = np.where(owner >= 0, med, psd)
    floor = np.maximum(np.convolve(np.pad(masked, k // 2, mode="edge"), np.ones(k) / k,
                                   mode="valid"), 1e-300)
    excess = span_sums_jit(np.maximum(psd - floor, 0.0), lo, hi) * df
    keep = np.flatnonzero(excess > 0)             # in the order claimed, then strongest first
    amplitude = np.sqrt(2.0 * excess[keep])
    best = np.argsort(-amplitude, kind="stable")[:max_lines]
    return [DetectedLine(float(freq[peak[keep[j]]]), float(amplitude[j]),
                         slice(int(lo[keep[j]]), int(hi[keep[j]]))) for j in best], floor


def span_sums(values, spans):
    """The sum of ``values`` over each span, as numpy sums the slice (to the bit).

    Parameters
    ----------
    values : numpy.ndarray, shape (m,)
        Values per bin (float64).
    spans : sequence of slice
        Bins of each span (steps of 1), e.g. the ``bins`` of detected lines.

    Returns
    -------
    numpy.ndarray, shape (len(spans),)

    Examples
    --------
    >>> span_sums(np.arange(10.0), [slice(0, 3), slice(5, 10)]).tolist()
    [3.0, 35.0]
    """
    lo = np.fromiter((b.start for b in spans), dtype=np.int64, count=len(spans))
    hi = np.fromiter((b.stop for b in spans), dtype=np.int64, count=len(spans))
    return span_sums_jit(np.ascontiguousarray(values, dtype=float), lo, hi)


def line_free(freq, psd, *, min_db=LINE_MIN_DB, half_width_hz=FLOOR_HALF_WIDTH_HZ):
    """Mask of the bins of a PSD outside its narrow lines (bins standing ``min_db`` over the
    running median, with their Hann main lobe, ± 2 bins).

    Parameters
    ----------
    freq, psd : numpy.ndarray, shape (m,)
        Uniform frequency grid from 0 (Hz) and the PSD on it.
    min_db : float
        Least height of a line over the running median, dB.
    half_width_hz : float
        Half-width of the running median, Hz.

    Returns
    -------
    numpy.ndarray of bool, shape (m,)
    """
    peak = np.asarray(psd) > 10.0 ** (min_db / 10.0) * median_floor(freq, psd, half_width_hz)
    line = peak.copy()
    for k in (1, 2):
        line[k:] |= peak[:-k]
        line[:-k] |= peak[k:]
    return ~line
