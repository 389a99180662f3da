"""A record's power spectral density over equal segments, and its broadband floor between
the lines (a running median).

The calibration of a machine (:mod:`cmsim.machine.calibration`) and the path-free comparison
(:func:`cmsim.discrepancy.evaluator.record_floor`) read the floor the same way: the PSD of
Hann-windowed segments, each its own periodogram (no overlap), averaged; under a running
median the lines (shaft, defect and mesh families) drop out and what is left is what lies
between them. The median's edges are a choice: ``"mirror"`` reflects the spectrum at DC and
Nyquist, ``"nearest"`` repeats the end bin — which reads a window reaching past DC at the
DC bin's level (3-5× too high below ~300 Hz with a ±250-Hz window on a record whose low
end rises).
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import median_filter

__all__ = ["segment_psd", "median_window_bins", "running_median_floor"]


def segment_psd(segs, fs):
    """One-sided PSD averaged over equal segments, each Hann-windowed with its mean removed.

    Parameters
    ----------
    segs : sequence of numpy.ndarray
        Segments of equal length n.
    fs : float
        Sample rate, Hz.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Frequencies (``rfftfreq(n, 1/fs)``), Hz, and the PSD, unit²/Hz (every bin doubled).
    """
    n = segs[0].size
    w = np.hanning(n)
    p = np.mean([np.abs(np.fft.rfft((s - s.mean()) * w)) ** 2 for s in segs], axis=0)
    return np.fft.rfftfreq(n, 1.0 / fs), 2.0 * p / (fs * np.sum(w ** 2))


def median_window_bins(freq, half_width_hz):
    """Odd number of bins of a ± ``half_width_hz`` running window on the grid ``freq`` (at
    least 5)."""
    return max(5, 2 * int(round(half_width_hz / (freq[1] - freq[0]))) + 1)


def running_median_floor(freq, psd, half_width_hz, *, mode="mirror"):
    """Running median of ``psd`` over ± ``half_width_hz`` (at least 1e-300): blind to lines
    narrower than half the window; biased low on a noisy estimate (the median of a χ²
    variable lies under its mean).

    Parameters
    ----------
    freq : numpy.ndarray
        Uniform frequency grid, Hz.
    psd : numpy.ndarray
        Power spectral density on it.
    half_width_hz : float
        Half-width of the window, Hz.
    mode : str
        Edge handling of :func:`scipy.ndimage.median_filter` (module docstring).

    Returns
    -------
    numpy.ndarray
    """
    return np.maximum(median_filter(psd, size=median_window_bins(freq, half_width_hz),
                                    mode=mode), 1e-300)
