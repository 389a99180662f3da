"""THE line rule: every reader of a spectral line at a nominal frequency uses it.

Line rule (:func:`line_window`, :func:`line_bins`, :func:`line_amplitude`)
    A spectral line of nominal frequency f is the largest bin within

        f·(1 − tolerance) − 1.5·Δf  ≤  f_bin  ≤  f·(1 + tolerance) + 1.5·Δf   (Δf: bin spacing).

    The ±:data:`LINE_HALF_WIDTH_BINS` bins hold a tone between bins (a flat-top main lobe
    spans about ±2 bins, a Hann one ±1; the peak bin is within half a bin of the tone); the
    relative ``tolerance`` holds what moves the line away from its nominal frequency beyond
    that. It is one of two named values:

    * :data:`EXACT_TOLERANCE` = 0 — the 1.5 bins hold every displacement: the lines of a
      simulation at constant speed, gear-mesh lines and their shaft-rate sidebands (tied to
      the shaft by the teeth), and the bearing lines of the sim-to-real windows (0.34 s:
      1.5 bins = 4.4 Hz at 12 kHz hold the ≤ 1.4 % measured below, up to the 290-Hz lines;
      a tolerance on top only lets more noise bins compete: its envelope rule falls from
      77.4 to 65.6 % balanced accuracy on CWRU with 1 %).
    * :data:`SLIP_TOLERANCE` = 2 % — bearing lines of a measured record read at a nominal
      speed, where the bins are narrower than the displacement (a 10-s record: 0.1 Hz), and
      both sides of a model-record comparison: rolling elements slip by 1-2 % (Randall &
      Antoni 2011, §2.1) and a stored speed is a nominal one. Measured offsets: the race
      defect lines of the shared records sit −1.4 % to +0.35 % from their values at the
      documented speed (MFPT −0.6 to −1.4 %, the datasets README: "about 1 % lower"; CWRU
      within ±0.35 %). 2 % is also the tolerance the comparison's features were calibrated
      with (``cmsim compare``: a narrower 1.5 % window names 2 of the 5 real faults it named).

It lives here, under :mod:`cmsim.measured` and :mod:`cmsim.features`, so that the checks of
a measured record's metadata (:mod:`cmsim.measured.consistency`) and the features read lines
alike; :mod:`cmsim.features.lines` re-exports it beside the band rule.

References
----------
.. [1] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", MSSP 25
   (2011) 485-520 (slip of 1-2 %).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["line_window", "line_bins", "line_amplitude", "line_amplitudes_at",
           "LINE_HALF_WIDTH_BINS", "EXACT_TOLERANCE",
           "AVOID_HALF_WIDTH_BINS", "leakage_bins",
           "SLIP_TOLERANCE"]

#: Half-width of a line's window beyond its relative tolerance, bins.
LINE_HALF_WIDTH_BINS = 1.5

#: Relative tolerance of a line whose frequency is known exactly (see the module docstring).
EXACT_TOLERANCE = 0.0

#: Half width of an avoided line's window (:func:`line_amplitude`'s ``avoid_hz``), bins: a
#: Hann window's main lobe (2 bins) with the line anywhere in its bin.
AVOID_HALF_WIDTH_BINS = 2.5

#: Relative tolerance of a line read at a nominal speed: bearing slip and speed error.
SLIP_TOLERANCE = 0.02


def line_window(freq, f_hz, tolerance=EXACT_TOLERANCE, half_width_bins=LINE_HALF_WIDTH_BINS):
    """Mask of the bins of the line at ``f_hz`` (see the module docstring).

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz, uniformly spaced from 0.
    f_hz : float
        Nominal frequency of the line, Hz.
    tolerance : float
        Relative tolerance (:data:`EXACT_TOLERANCE`, :data:`SLIP_TOLERANCE`), >= 0.
    half_width_bins : float
        Bins beyond the tolerance on each side (:data:`LINE_HALF_WIDTH_BINS`; a reader
        that must hold a wider main lobe, e.g. a flat-top window's, may widen it).

    Returns
    -------
    numpy.ndarray of bool, shape (n_bins,), or None
        None when the line is not in the spectrum (f <= 0, not finite, or its window holds
        no bin).
    """
    span = line_bins(freq, f_hz, tolerance, half_width_bins)
    if span is None:
        return None
    sel = np.zeros(len(freq), dtype=bool)
    sel[span] = True
    return sel


def line_bins(freq, f_hz, tolerance=EXACT_TOLERANCE, half_width_bins=LINE_HALF_WIDTH_BINS):
    """The bins of :func:`line_window` as a slice, found by bisection on the sorted bins (a
    reader of hundreds of lines per spectrum spent most of its time on full-length masks).

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz, uniformly spaced from 0.
    f_hz : float
        Nominal frequency of the line, Hz.
    tolerance : float
        Relative tolerance, >= 0.
    half_width_bins : float
        Bins beyond the tolerance on each side.

    Returns
    -------
    slice or None
        None when the line is not in the spectrum.
    """
    if not (math.isfinite(f_hz) and f_hz > 0.0):
        return None
    lo, hi = (int(i) for i in _window_edges(freq, f_hz, tolerance, half_width_bins))
    return slice(lo, hi) if hi > lo else None


def _window_edges(freq, f_hz, tolerance, half_width_bins):
    """First bin >= f − half and first bin > f + half of the line windows at ``f_hz`` (a
    float or an array of them): the one window rule of :func:`line_bins` and
    :func:`line_amplitudes_at`."""
    half = tolerance * f_hz + half_width_bins * float(freq[1] - freq[0])
    return (np.searchsorted(freq, f_hz - half, side="left"),
            np.searchsorted(freq, f_hz + half, side="right"))


def line_amplitudes_at(freq, amp, f_hz, tolerance=EXACT_TOLERANCE):
    """:func:`line_amplitude` of many lines of one spectrum at once (no lines avoided): the
    windows found in one bisection of the bins, each line's the largest bin of its own (a
    feature row reads dozens to hundreds; a call each cost 4.6 µs a line, most of it the call).

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz, uniformly spaced from 0.
    amp : numpy.ndarray, shape (n_bins,)
        Amplitude spectrum, any unit.
    f_hz : array_like, shape (k,)
        Nominal frequencies of the lines, Hz.
    tolerance : float
        Relative tolerance, >= 0.

    Returns
    -------
    numpy.ndarray, shape (k,)
        Each line's amplitude, as :func:`line_amplitude` reads it; NaN where it does.

    Examples
    --------
    >>> f = np.arange(0.0, 1000.0, 1.0)
    >>> a = np.zeros_like(f); a[102] = 2.0; a[203] = 2.0
    >>> line_amplitudes_at(f, a, [101.0, 200.0, -5.0], SLIP_TOLERANCE).tolist()
    [2.0, 2.0, nan]
    """
    amp = np.asarray(amp)
    f = np.asarray(f_hz, dtype=float)
    out = np.full(f.shape, math.nan)
    ok = np.isfinite(f) & (f > 0.0)
    lo, hi = _window_edges(freq, np.where(ok, f, 1.0), tolerance, LINE_HALF_WIDTH_BINS)
    for i in np.flatnonzero(ok & (hi > lo)):
        out[i] = amp[lo[i]:hi[i]].max()
    return out


def leakage_bins(level):
    """Half width, bins, of a line's window in a Hann-windowed spectrum out to where its
    sidelobes fall under the floor: the kernel's envelope 1/(π·d·(d² − 1)) (d in bins from
    the tone) times ``level`` reaches 1 at d, and the tone lies anywhere in its bin (half a
    bin more); never under :data:`AVOID_HALF_WIDTH_BINS` (the main lobe).

    Parameters
    ----------
    level : float or numpy.ndarray
        The line's amplitude over the floor (a ratio, not dB).

    Returns
    -------
    float or numpy.ndarray

    Examples
    --------
    >>> float(leakage_bins(1.0)), round(float(leakage_bins(10 ** (48 / 20))), 2)
    (2.5, 4.89)
    """
    level = np.asarray(level, dtype=float)
    # d·(d² − 1) = level/π: its one real root over 1 (Cardano; a level under
    # 2π/(3√3) leaves the main lobe)
    q = np.maximum(level, 0.0) / math.pi
    disc = np.sqrt(np.maximum(q * q / 4.0 - 1.0 / 27.0, 0.0))
    d = np.where(q * q / 4.0 >= 1.0 / 27.0,
                 np.cbrt(q / 2.0 + disc) + np.cbrt(q / 2.0 - disc), 0.0)
    out = np.maximum(d + 0.5, AVOID_HALF_WIDTH_BINS)
    return float(out) if out.ndim == 0 else out


def line_amplitude(freq, amp, f_hz, tolerance=EXACT_TOLERANCE, avoid_hz=(),
                   avoid_bins=AVOID_HALF_WIDTH_BINS):
    """Amplitude of the line at ``f_hz``: the largest bin of its window (outside the exact
    windows of the lines at ``avoid_hz``).

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz, uniformly spaced from 0.
    amp : numpy.ndarray, shape (..., n_bins)
        Amplitude spectrum (or several along the leading axes), any unit.
    f_hz : float
        Nominal frequency of the line, Hz.
    tolerance : float
        Relative tolerance (:data:`EXACT_TOLERANCE`, :data:`SLIP_TOLERANCE`), >= 0.
    avoid_hz : sequence of float
        Lines of another source whose bins (their :data:`EXACT_TOLERANCE` windows,
        :data:`AVOID_HALF_WIDTH_BINS` wide) the window leaves out: a slipping bearing line
        read beside a shaft's harmonic, which has no slip.
    avoid_bins : float or sequence of float
        Their windows' half width, bins: one for all, or one each (a strong line's leakage,
        :func:`leakage_bins`).

    Returns
    -------
    float or numpy.ndarray of shape amp.shape[:-1]
        NaN when the line is not in the spectrum (or every bin of its window is avoided).

    Examples
    --------
    >>> f = np.arange(0.0, 1000.0, 1.0)
    >>> a = np.zeros_like(f); a[102] = 2.0; a[203] = 2.0
    >>> line_amplitude(f, a, 101.0), line_amplitude(f, a, 100.0)
    (2.0, 0.0)
    >>> line_amplitude(f, a, 200.0), line_amplitude(f, a, 200.0, SLIP_TOLERANCE)
    (0.0, 2.0)
    >>> line_amplitude(f, a, 105.0, SLIP_TOLERANCE)    # 105·(1 ± 0.02) ± 1.5 bins
    2.0
    >>> line_amplitude(f, a, 105.0, SLIP_TOLERANCE, avoid_hz=[101.0])
    0.0
    """
    amp = np.asarray(amp)
    sel = line_bins(freq, f_hz, tolerance)
    if sel is not None and len(avoid_hz):
        keep = np.ones(sel.stop - sel.start, dtype=bool)
        widths = np.broadcast_to(np.asarray(avoid_bins, dtype=float), (len(avoid_hz),))
        for f, w in zip(avoid_hz, widths):
            other = line_bins(freq, f, EXACT_TOLERANCE, float(w))
            if other is not None:
                keep[max(other.start - sel.start, 0):max(other.stop - sel.start, 0)] = False
        sel = np.arange(sel.start, sel.stop)[keep] if keep.any() else None
    if sel is None:
        return math.nan if amp.ndim == 1 else np.full(amp.shape[:-1], math.nan)
    peak = amp[..., sel].max(axis=-1)
    return float(peak) if amp.ndim == 1 else peak
