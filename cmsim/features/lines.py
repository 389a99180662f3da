"""THE line rule and THE demodulation-band rule: every feature extractor reads lines with these.

Line rule (:func:`line_window`, :func:`line_amplitude`)
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

Band rule (:func:`demodulation_band`)
    The band for envelope analysis is the kurtogram's best band
    (:func:`cmsim.spectra.kurtogram.kurtogram`) of width at least
    :data:`~cmsim.spectra.kurtogram.FAULT_BANDWIDTH_FACTOR` × the highest defect fundamental
    of the bearings read (max of BPFO, BPFI, 2·BSF, FTF: :func:`highest_fault_hz`; a band of
    width B carries modulations up to about B/2 on both sides of its carrier, so a defect
    line and its first sidebands need B >= 2·f, and 3 leaves a margin), that fundamental
    capped at :data:`MAX_FAULT_FRACTION`·fs so that such a band fits below fs/2. Then:

    * *narrow-band guard*: a band narrower than :data:`NARROW_BAND_FRACTION`·fs is widened to
      it about its centre (a Butterworth band-pass that narrow, relative to fs, is
      ill-conditioned);
    * a lower edge within 10⁻⁶·fs of 0 is 0 (the low-pass it is: a 10⁻¹³ Hz edge asks for a
      singular band-pass design);
    * *fallback*: when the kurtogram has no band that wide (a short record), the band
      :data:`FALLBACK_BAND` × fs.

References
----------
.. [1] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", MSSP 25
   (2011) 485-520 (slip of 1-2 %; the band of largest spectral kurtosis).
.. [2] J. Antoni, R. B. Randall, MSSP 20 (2006) 308-331 (the kurtogram).
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.errors import ParameterError
from cmsim.spectra.kurtogram import FAULT_BANDWIDTH_FACTOR, kurtogram

__all__ = ["line_window", "line_amplitude", "demodulation_band", "highest_fault_hz",
           "LINE_HALF_WIDTH_BINS", "EXACT_TOLERANCE", "SLIP_TOLERANCE",
           "FAULT_BANDWIDTH_FACTOR", "MAX_FAULT_FRACTION", "NARROW_BAND_FRACTION",
           "FALLBACK_BAND"]

#: Half-width of a line's window beyond its relative tolerance, bins.
LINE_HALF_WIDTH_BINS = 1.5

#: Relative tolerance of a line whose frequency is known exactly (see the module docstring).
EXACT_TOLERANCE = 0.0

#: Relative tolerance of a line read at a nominal speed: bearing slip and speed error.
SLIP_TOLERANCE = 0.02

#: Highest defect fundamental the band rule asks a band for, × fs (3 × 0.15 = 0.45: the
#: band still fits below fs/2).
MAX_FAULT_FRACTION = 0.15

#: Narrowest demodulation band, × fs (the narrow-band guard).
NARROW_BAND_FRACTION = 0.02

#: Band used when the kurtogram has none wide enough, × fs.
FALLBACK_BAND = (0.05, 0.45)


def line_window(freq, f_hz, tolerance=EXACT_TOLERANCE):
    """Mask of the bins of the line at ``f_hz`` (see the module docstring).

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz, uniformly spaced from 0.
    f_hz : float
        Nominal frequency of the line, Hz.
    tolerance : float
        Relative tolerance (:data:`EXACT_TOLERANCE`, :data:`SLIP_TOLERANCE`), >= 0.

    Returns
    -------
    numpy.ndarray of bool, shape (n_bins,), or None
        None when the line is not in the spectrum (f <= 0, not finite, or its window holds
        no bin).
    """
    if not (math.isfinite(f_hz) and f_hz > 0.0):
        return None
    half = tolerance * f_hz + LINE_HALF_WIDTH_BINS * float(freq[1] - freq[0])
    sel = (freq >= f_hz - half) & (freq <= f_hz + half)
    return sel if np.any(sel) else None


def line_amplitude(freq, amp, f_hz, tolerance=EXACT_TOLERANCE):
    """Amplitude of the line at ``f_hz``: the largest bin of its window.

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

    Returns
    -------
    float or numpy.ndarray of shape amp.shape[:-1]
        NaN when the line is not in the spectrum.

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
    """
    amp = np.asarray(amp)
    sel = line_window(freq, f_hz, tolerance)
    if sel is None:
        return math.nan if amp.ndim == 1 else np.full(amp.shape[:-1], math.nan)
    peak = amp[..., sel].max(axis=-1)
    return float(peak) if amp.ndim == 1 else peak


def highest_fault_hz(bearings):
    """The highest defect fundamental of some bearings: max of BPFO, BPFI, 2·BSF, FTF, Hz.

    Parameters
    ----------
    bearings : iterable of cmsim.frequencies.BearingFrequencies

    Returns
    -------
    float
        0 when there is no bearing.
    """
    return max((max(b.bpfo_hz, b.bpfi_hz, 2.0 * b.bsf_hz, b.ftf_hz) for b in bearings),
               default=0.0)


def demodulation_band(x, fs_hz, max_fault_hz):
    """THE demodulation band of a signal (see the module docstring).

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, any unit.
    fs_hz : float
        Sample rate, Hz.
    max_fault_hz : float
        Highest defect fundamental of the bearings read, Hz (:func:`highest_fault_hz`);
        <= 0 leaves the kurtogram's default least width.

    Returns
    -------
    (float, float)
        Band (lo, hi), Hz, 0 <= lo < hi <= fs/2.
    """
    fs = float(fs_hz)
    f_max = min(float(max_fault_hz), MAX_FAULT_FRACTION * fs)
    try:
        lo, hi = kurtogram(x, fs, max_fault_hz=f_max if f_max > 0 else None).band_hz
    except ParameterError:
        return FALLBACK_BAND[0] * fs, FALLBACK_BAND[1] * fs
    if hi - lo < NARROW_BAND_FRACTION * fs:
        mid = 0.5 * (lo + hi)
        half = 0.5 * NARROW_BAND_FRACTION * fs
        lo, hi = max(mid - half, 0.0), min(mid + half, 0.5 * fs)
    if lo < 1e-6 * fs:
        lo = 0.0
    return float(lo), float(hi)

