"""The ratio of one comb of lines to where a record's metadata puts it.

The reading under :mod:`cmsim.measured.consistency`: a line's prominence over its local
floor (:func:`line_prominence_db`), the lines only one of two neighbouring fundamentals
predicts against the other's (:func:`exclusive_contrast_db`), and the ratio found from them
step by step — the stated lines missing under a comb twice as high, or lines between the
stated ones standing as high as they (:func:`family_ratio`; the rule and its thresholds in
:mod:`cmsim.measured.consistency`'s docstring) — with the lowest fundamental that explains a
comb found at a harmonic (:func:`lowest_fundamental`, for :mod:`cmsim.measured.inference`).
How the families' ratios decide a record's stated sample rate and speed stays in
:mod:`cmsim.measured.consistency`.
"""

from __future__ import annotations

import numpy as np

from cmsim.spectra.amplitude import amplitude_spectrum
from cmsim.spectra.lines import line_window

__all__ = ["log_spectrum", "line_prominence_db", "exclusive_contrast_db", "family_ratio", "lowest_fundamental",
           "shaft_comb_db", "LINE_TOLERANCE", "LINE_WINDOW_BINS", "SUBCOMB_MARGIN_DB",
           "MISSING_MARGIN_DB", "CLEAR_LINE_DB", "REFUSE_LINE_DB", "LARGEST_FACTOR", "STEPS",
           "COMB_HARMONICS", "COMB_TOLERANCE"]

#: Least half-width of the window a line is looked for in, relative to its frequency (a
#: speed stated more precisely still meets a line's own wobble).
LINE_TOLERANCE = 0.01

#: Bins beyond the tolerance on each side of the window (the one line rule,
#: :func:`cmsim.spectra.lines.line_window`, at 2 bins: a stated rate four times the true one
#: puts the low lines a few bins from 0, where the rule's 1.5 bins miss the Hann lobe's top).
LINE_WINDOW_BINS = 2.0

#: Lines between the stated ones standing within this of the stated lines, dB, make the
#: lower fundamental the family's ratio.
SUBCOMB_MARGIN_DB = 5.0

#: Stated lines this far below the lines of a fundamental m times higher, dB, make that
#: fundamental the family's ratio.
MISSING_MARGIN_DB = 5.5

#: Least prominence, dB over the local floor, of a family's lines for it to speak.
CLEAR_LINE_DB = 15.0

#: Least prominence, dB, of a strong contradiction's lines for it to refuse a record.
REFUSE_LINE_DB = 20.0

#: Largest factor between the stated and the found fundamental that is tested.
LARGEST_FACTOR = 4

#: Factors a fundamental is moved by, one step at a time (4 = 2·2).
STEPS = (2,)


def log_spectrum(x, fs_hz):
    """``(freq, log10 amplitude)`` of ``x``'s Hann amplitude spectrum (at least 1e-300): the
    spectrum every line of these checks is read on.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal.
    fs_hz : float
        Sample rate, Hz (1 for cycles per sample).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
    """
    freq, amp = amplitude_spectrum(np.asarray(x, dtype=float), fs_hz, window="hann")
    return freq, np.log10(np.maximum(amp, 1e-300))


def line_prominence_db(freq, log_amp, f_hz, tolerance=LINE_TOLERANCE):
    """Prominence of the line nearest ``f_hz``: the largest bin within ±``tolerance`` ±
    :data:`LINE_WINDOW_BINS` (:func:`cmsim.spectra.lines.line_window`) over the median of
    its ±10 % (>= 25 bins), dB; NaN outside the spectrum.

    Parameters
    ----------
    freq : numpy.ndarray, shape (n,)
        Bin frequencies, Hz (uniform from 0).
    log_amp : numpy.ndarray, shape (n,)
        log10 of the amplitude.
    f_hz : float
        Line frequency, Hz.
    tolerance : float
        Relative half-width of the window (the speed's uncertainty, a bearing's slip).
    """
    df = freq[1]
    sel = line_window(freq, f_hz, tolerance, LINE_WINDOW_BINS)
    idx = np.flatnonzero(sel) if sel is not None else np.empty(0, int)
    if idx.size == 0 or idx[0] < 2 or idx[-1] >= log_amp.size - 1:
        return float("nan")
    j = int(idx[0] + np.argmax(log_amp[idx]))
    w = max(25, int(round(0.1 * f_hz / df)))
    return float(20.0 * (log_amp[j] - np.median(log_amp[max(j - w, 1):j + w + 1])))


#: Harmonics of a shaft and their tolerance (or a speed's, if wider) on which its own comb is
#: read (:func:`shaft_comb_db`): narrow enough that a defect line 1 % from a harmonic does
#: not pass for it (CWRU's IR007_0: 40 dB at its 1797 rpm, 13 dB at 3200 rpm, where the 1 %
#: windows of the verdicts found its defect lines).
COMB_HARMONICS = 6
COMB_TOLERANCE = 2e-3


def shaft_comb_db(freq, log_amp, shaft_hz, tolerance=COMB_TOLERANCE):
    """Mean prominence (:func:`line_prominence_db`) of a shaft's first
    :data:`COMB_HARMONICS` harmonics, dB; NaN when none is in the spectrum.

    Parameters
    ----------
    freq, log_amp : numpy.ndarray
        The spectrum, as :func:`line_prominence_db` reads it (:func:`log_spectrum`).
    shaft_hz : float
        The shaft's rate, Hz.
    tolerance : float
        Relative half-width of each line's window.
    """
    return _mean([line_prominence_db(freq, log_amp, k * shaft_hz, tolerance)
                  for k in range(1, COMB_HARMONICS + 1)])


def _mean(values):
    v = [x for x in values if x == x]
    return float(np.mean(v)) if v else float("nan")


def exclusive_contrast_db(freq, log_amp, low_hz, m, harmonics, n_exclusive=2,
                          tolerance=LINE_TOLERANCE):
    """Lines a comb at ``low_hz`` predicts and one at ``m·low_hz`` does not, against the
    lines of the higher comb.

    Parameters
    ----------
    freq, log_amp : numpy.ndarray, shape (n,)
        Spectrum (:func:`line_prominence_db`).
    low_hz : float
        The lower fundamental, Hz.
    m : int
        Factor to the higher fundamental (2 or 3).
    harmonics : int
        Harmonics of the higher comb read.
    n_exclusive : int
        Exclusive lines read (the first ones).
    tolerance : float
        Relative half-width of each line's window.

    Returns
    -------
    exclusive_db : float
        Mean prominence of the first exclusive lines j·low (j not a multiple of m), dB.
    higher_db : float
        Mean prominence of the higher comb's lines k·m·low, dB.
    higher_peak_db : float
        Prominence of the higher comb's strongest line, dB.
    """
    exclusive = [line_prominence_db(freq, log_amp, j * low_hz, tolerance)
                 for j in range(1, m * harmonics) if j % m][:n_exclusive]
    higher = [line_prominence_db(freq, log_amp, k * m * low_hz, tolerance)
              for k in range(1, harmonics + 1)]
    peak = max((h for h in higher if h == h), default=float("nan"))
    return _mean(exclusive), _mean(higher), peak


def _lower_fits(exclusive_db, higher_db, higher_peak_db):
    """The lower fundamental's own line stands clear and as high as the higher comb: the
    lower fundamental is the true one."""
    return exclusive_db >= CLEAR_LINE_DB and exclusive_db - higher_db > -SUBCOMB_MARGIN_DB


def _higher_fits(exclusive_db, higher_db, higher_peak_db):
    """The higher comb has a clear line and the lower one's own lines are missing: the
    higher fundamental is the true one. Lines that stand :data:`REFUSE_LINE_DB` high are
    not missing, however much higher the others stand (a simulated record's ball-pass
    comb: its odd harmonics 30 dB under the even ones, 46 dB over the floor)."""
    return (higher_peak_db >= CLEAR_LINE_DB and exclusive_db < REFUSE_LINE_DB
            and exclusive_db - higher_db < -MISSING_MARGIN_DB)


def _steps(freq, log_amp, stated_hz, harmonics, tolerance, lower=True):
    """``(ratio, first step)`` of a family: the ratio found step by step (module
    docstring) and the contrast of its first step, ``(exclusive_db, higher_db,
    higher_peak_db)`` (None at ratio 1); ``lower`` False: no lower fundamental."""
    ratio, first = 1.0, None
    moved = True
    while moved:
        moved = False
        for m in STEPS:            # missing lines first: a lower comb predicts them too
            if ratio >= 1.0 and ratio * m <= LARGEST_FACTOR:
                c = exclusive_contrast_db(freq, log_amp, stated_hz * ratio, m, harmonics,
                                          tolerance=tolerance)
                if _higher_fits(*c):
                    first = first or c
                    ratio *= m
                    moved = True
                    continue
            if lower and ratio <= 1.0 and ratio / m >= 1.0 / LARGEST_FACTOR:
                c = exclusive_contrast_db(freq, log_amp, stated_hz * ratio / m, m, harmonics,
                                          tolerance=tolerance)
                if _lower_fits(*c):
                    first = first or c
                    ratio /= m
                    moved = True
    return ratio, first


def family_ratio(freq, log_amp, stated_hz, harmonics, tolerance=LINE_TOLERANCE):
    """Found / stated fundamental of one family, and its lines' level there.

    Parameters
    ----------
    freq, log_amp : numpy.ndarray, shape (n,)
        Spectrum (:func:`line_prominence_db`).
    stated_hz : float
        Fundamental the metadata predicts, Hz.
    harmonics : int
        Harmonics read.
    tolerance : float
        Relative half-width of each line's window.

    Returns
    -------
    (float, float)
        Ratio (a power of 2 within [1/4, 4], or 1) and mean prominence of the
        lines at the found fundamental, dB.
    """
    ratio, _ = _steps(freq, log_amp, stated_hz, harmonics, tolerance)
    return ratio, _mean(line_prominence_db(freq, log_amp, k * stated_hz * ratio, tolerance)
                        for k in range(1, harmonics + 1))


def lowest_fundamental(freq, log_amp, f_hz, harmonics, *, lo_hz):
    """The ratio to the lowest fundamental whose comb explains a comb found at ``f_hz``: the
    best-fitting comb of a spectrum is often at a harmonic of the true fundamental (its
    even or every third line standing highest), never below it.

    Parameters
    ----------
    freq, log_amp : numpy.ndarray, shape (n,)
        Spectrum (:func:`line_prominence_db`).
    f_hz : float
        Fundamental of the comb found, Hz.
    harmonics : int
        Harmonics read.
    lo_hz : float
        Lowest fundamental considered, Hz.

    Returns
    -------
    float
        1, or 1/m for a product m of 2s and 3s (``f_hz`` × ratio >= ``lo_hz``).
    """
    ratio = 1.0
    moved = True
    while moved:
        moved = False
        for m in (2, 3):
            low = f_hz * ratio / m
            if low >= lo_hz and _lower_fits(*exclusive_contrast_db(freq, log_amp, low, m,
                                                                   harmonics)):
                ratio /= m
                moved = True
                break
    return ratio
