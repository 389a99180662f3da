"""THE line rule and THE demodulation-band rule: every feature extractor reads lines with these.

Line rule (:func:`line_window`, :func:`line_bins`, :func:`line_amplitude`)
    Defined in :mod:`cmsim.spectra.lines` (below :mod:`cmsim.measured`, whose metadata
    checks read lines by it too) and re-exported here: a line of nominal frequency f is the
    largest bin within f·(1 ± tolerance) ± 1.5 bins, the tolerance
    :data:`EXACT_TOLERANCE` (0) or :data:`SLIP_TOLERANCE` (2 %).

Band rule (:func:`demodulation_band`)
    The band for envelope analysis is the best band of the kurtogram
    (:func:`cmsim.spectra.kurtogram.residual_kurtogram`) of the signal's linear-prediction
    residual (:func:`~cmsim.spectra.kurtogram.prediction_residual`: the discrete part — mesh
    harmonics and sidebands, shaft orders, the mains — removed first, as the bearing
    diagnostics tutorial's procedure does; a gearbox's beating mesh harmonics otherwise make
    a wide band round them the most "impulsive" one, over the band where the impacts ring),
    of width at least
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

import numpy as np

from cmsim.errors import ParameterError
from cmsim.spectra.kurtogram import FAULT_BANDWIDTH_FACTOR, residual_kurtogram
from cmsim.spectra.lines import (EXACT_TOLERANCE, LINE_HALF_WIDTH_BINS, SLIP_TOLERANCE,
                                 line_amplitude, line_amplitudes_at, line_bins, line_window)

__all__ = ["line_window", "line_bins", "line_amplitude", "line_amplitudes_at",
           "demodulation_band", "highest_fault_hz",
           "LINE_HALF_WIDTH_BINS", "EXACT_TOLERANCE", "SLIP_TOLERANCE",
           "FAULT_BANDWIDTH_FACTOR", "MAX_FAULT_FRACTION", "NARROW_BAND_FRACTION",
           "FALLBACK_BAND"]

#: Highest defect fundamental the band rule asks a band for, × fs (3 × 0.15 = 0.45: the
#: band still fits below fs/2).
MAX_FAULT_FRACTION = 0.15

#: Narrowest demodulation band, × fs (the narrow-band guard).
NARROW_BAND_FRACTION = 0.02

#: Band used when the kurtogram has none wide enough, × fs.
FALLBACK_BAND = (0.05, 0.45)


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
        lo, hi = residual_kurtogram(x, fs, max_fault_hz=f_max if f_max > 0 else None,
                                    narrow_levels=False).band_hz
    except ParameterError:
        return FALLBACK_BAND[0] * fs, FALLBACK_BAND[1] * fs
    if hi - lo < NARROW_BAND_FRACTION * fs:
        mid = 0.5 * (lo + hi)
        half = 0.5 * NARROW_BAND_FRACTION * fs
        lo, hi = max(mid - half, 0.0), min(mid + half, 0.5 * fs)
    if lo < 1e-6 * fs:
        lo = 0.0
    return float(lo), float(hi)

