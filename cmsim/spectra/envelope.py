"""Envelope analysis: band-pass, Hilbert envelope, amplitude spectrum of the envelope.

A bearing defect excites a structural resonance once per ball pass; the resonance band carries
the impacts as an amplitude modulation. Band-pass filtering around the resonance (zero-phase
Butterworth, :func:`scipy.signal.sosfiltfilt`), taking the modulus of the analytic signal
(:func:`scipy.signal.hilbert`) and removing its mean leaves a signal whose spectrum shows the
repetition rate (BPFO, BPFI, ...) and its harmonics. The band is best chosen with
:func:`cmsim.spectra.kurtogram.kurtogram`.

References
----------
.. [1] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", MSSP 25
   (2011) 485-520, §3.
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache

import numpy as np
import scipy.signal

from cmsim.errors import ParameterError
from cmsim.spectra._checks import band, positive_int, sampling_rate, signal_1d
from cmsim.spectra.amplitude import amplitude_spectrum

__all__ = ["bandpass", "envelope", "envelope_spectrum"]


def bandpass(x, fs, band_hz, *, filter_order=4):
    """Zero-phase Butterworth band-pass (low-pass if lo = 0, high-pass if hi = fs/2).

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit.
    fs : float
        Sampling rate, Hz.
    band_hz : tuple of float
        (lo, hi) pass band, Hz, 0 <= lo < hi <= fs/2. (0, fs/2) returns ``x`` unchanged.
    filter_order : int
        Butterworth order per edge (1-12); :func:`scipy.signal.sosfiltfilt` doubles it.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Filtered signal, same unit as ``x``.
    """
    x = signal_1d(x)
    fs = sampling_rate(fs)
    lo, hi = band("band_hz", band_hz, fs)
    order = positive_int("filter_order", filter_order, lo=1, hi=12)
    nyq = 0.5 * fs
    if lo <= 0.0 and hi >= nyq:
        return x.copy()
    return _filtfilt(_butter_sos(order, lo, hi, fs), x)


def _filtfilt(design, x):
    """:func:`scipy.signal.sosfiltfilt` of ``x`` (its default odd padding), the same bits,
    with the design's initial conditions kept (``sosfiltfilt`` solves them again at every
    call: half its time on a 0.5-s segment, and a machine's library filters tens of
    thousands of them)."""
    sos, zi, edge = design
    if x.size <= edge:
        raise ParameterError(f"the signal has {x.size} samples; the band-pass filter needs "
                             f"more than {edge}", param="x")
    ext = np.concatenate((2 * x[:1] - x[edge:0:-1], x, 2 * x[-1:] - x[-2:-(edge + 2):-1]))
    y, _ = scipy.signal.sosfilt(sos, ext, zi=zi * ext[0])
    y, _ = scipy.signal.sosfilt(sos, y[::-1], zi=zi * y[-1])
    return y[::-1][edge:-edge]


@lru_cache(maxsize=256)
def _butter_sos(order, lo, hi, fs):
    """The Butterworth sections of :func:`bandpass` with their steady-state initial conditions
    and the padding ``sosfiltfilt`` gives them, ``(sos, zi, edge)``, kept (a comparison
    demodulates about a thousand segments in a few dozen bands; the design cost half the
    filtering)."""
    if lo <= 0.0:
        sos = scipy.signal.butter(order, hi, btype="lowpass", fs=fs, output="sos")
    elif hi >= 0.5 * fs:
        sos = scipy.signal.butter(order, lo, btype="highpass", fs=fs, output="sos")
    else:
        sos = scipy.signal.butter(order, (lo, hi), btype="bandpass", fs=fs, output="sos")
    zi = scipy.signal.sosfilt_zi(sos)
    taps = 2 * sos.shape[0] + 1 - min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    zi.setflags(write=False)                  # the kept design (sosfilt reads its sections
    return sos, zi, 3 * taps                  # through a writable buffer: never handed out)


def envelope(x, fs, band_hz=None, *, filter_order=4):
    """Envelope |analytic signal| of ``x`` after an optional band-pass.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit.
    fs : float
        Sampling rate, Hz.
    band_hz : tuple of float, optional
        Pass band (lo, hi), Hz; ``None`` uses the whole band.
    filter_order : int
        Butterworth order, see :func:`bandpass`.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Envelope (>= 0), same unit as ``x``; its mean is *not* removed.
    """
    x = signal_1d(x)
    fs = sampling_rate(fs)
    xf = x if band_hz is None else bandpass(x, fs, band_hz, filter_order=filter_order)
    return np.abs(scipy.signal.hilbert(xf - xf.mean()))


def envelope_spectrum(x, fs, band_hz=None, *, filter_order=4, window="flattop",
                      resolution_hz=None):
    """Amplitude spectrum of the (mean-removed) envelope of the band-passed signal.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit; finite.
    fs : float
        Sampling rate, Hz (> 0).
    band_hz : tuple of float, optional
        Demodulation band (lo, hi), Hz, e.g. ``kurtogram.band_hz``; ``None`` = whole band.
    filter_order : int
        Butterworth order, see :func:`bandpass`.
    window : {"flattop", "hann", "boxcar"}
        Window of the envelope spectrum.
    resolution_hz : float, optional
        Largest acceptable bin spacing, Hz (raises if the record is too short).

    Returns
    -------
    Spectrum
        ``kind="envelope"``; a modulation m·cos(2π f_m t) of a carrier of amplitude A reads
        about m·A at f_m.
    """
    env = envelope(x, fs, band_hz, filter_order=filter_order)
    s = amplitude_spectrum(env, fs, window=window, detrend="constant",
                           resolution_hz=resolution_hz)
    return replace(s, kind="envelope")
