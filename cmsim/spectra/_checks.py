"""Input checks shared by the spectra modules.

Every public function of :mod:`cmsim.spectra` validates its inputs here, at the boundary, and
raises :class:`~cmsim.errors.ParameterError` naming the parameter and the allowed range (a
choice among options is :func:`cmsim.errors.check_choice`, shared with the other packages).
"""

from __future__ import annotations

import numpy as np

from cmsim.errors import ParameterError, check_range

#: Windows accepted by the amplitude-spectrum functions.
WINDOWS = ("flattop", "hann", "boxcar")

#: Detrend options: ``"constant"`` removes the mean, ``"linear"`` a straight line,
#: ``None`` nothing.
DETRENDS = ("constant", "linear", None)

#: Fewest samples accepted in a signal.
MIN_SAMPLES = 8


def readonly(a):
    """A float64 copy of ``a`` that cannot be written (results behave as values)."""
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


def signal_1d(x, name="x", min_samples=MIN_SAMPLES):
    """Return ``x`` as a finite float64 1-D array of at least ``min_samples`` samples."""
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a 1-D array of numbers") from None
    if arr.ndim != 1:
        raise ParameterError(f"{name} must be 1-D, got shape {arr.shape}")
    if arr.size < min_samples:
        raise ParameterError(f"{name} needs at least {min_samples} samples, got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} must contain only finite values (found NaN or inf)")
    return arr


def spectrum_arrays(freq, amp, min_samples=2):
    """Return ``(freq, amp)`` of an amplitude spectrum: same shape, ``freq`` strictly
    increasing, ``amp >= 0``."""
    freq = signal_1d(freq, name="freq", min_samples=min_samples)
    amp = signal_1d(amp, name="amp", min_samples=min_samples)
    if freq.shape != amp.shape:
        raise ParameterError(f"freq and amp must have the same shape, got {freq.shape} "
                             f"and {amp.shape}")
    if np.any(np.diff(freq) <= 0.0):
        raise ParameterError("freq must be strictly increasing")
    if np.any(amp < 0.0):
        raise ParameterError("amp must be >= 0 (an amplitude spectrum)")
    return freq, amp


def sampling_rate(fs, name="fs"):
    """Return ``fs`` as a float > 0 (Hz)."""
    return check_range(name, fs, 0.0, lo_open=True, unit="Hz")


def positive_int(name, value, lo=1, hi=None):
    """Return ``value`` as an int in ``[lo, hi]``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ParameterError(f"{name} must be an integer >= {lo}, got {value!r}")
    if value < lo or (hi is not None and value > hi):
        rng = f"[{lo}, {hi}]" if hi is not None else f">= {lo}"
        raise ParameterError(f"{name} must be an integer in {rng}, got {value}")
    return int(value)


def band(name, band_hz, fs):
    """Return ``(lo, hi)`` with ``0 <= lo < hi <= fs/2`` (Hz)."""
    try:
        lo, hi = (float(v) for v in band_hz)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a pair (lo, hi) in Hz, got {band_hz!r}") from None
    nyq = 0.5 * fs
    if not (np.isfinite(lo) and np.isfinite(hi)) or not 0.0 <= lo < hi <= nyq:
        raise ParameterError(f"{name} must satisfy 0 <= lo < hi <= fs/2 = {nyq:g} Hz, "
                             f"got ({lo:g}, {hi:g})")
    return lo, hi
