"""Amplitude spectra: a sinusoid of amplitude A reads A.

The one-sided amplitude spectrum of a record x (n samples at fs) windowed by w is

    A(f_j) = 2·|Σ w_i x_i e^{-2πi j i/n}| / Σ w_i      (0 < f_j < fs/2),

i.e. the power spectrum of :func:`scipy.signal.periodogram` / :func:`scipy.signal.welch` with
``scaling="spectrum"`` (coherent-gain corrected) converted to amplitude. The DC and Nyquist
bins are not doubled. The default flat-top window keeps the amplitude of any tone, on or
between bins, within about 0.1 % (its scalloping loss); its price is a main lobe about ±2
bins wide. Hann has up to 15 % (1.42 dB) scalloping loss between bins and boxcar up to 36 %;
use them for frequency resolution, not for amplitudes of off-bin tones.

Noise levels are not preserved by this scaling (the per-bin level of white noise depends on
the window's equivalent noise bandwidth, ENBW, and on the record length);
:meth:`Spectrum.band_rms` divides by the ENBW, so the RMS of a band (Parseval) can still be
read from the spectrum.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.signal

from cmsim.errors import ParameterError, check_choice, check_range
from cmsim.spectra._checks import (DETRENDS, WINDOWS, positive_int, readonly, sampling_rate,
                                   signal_1d)

__all__ = ["Spectrum", "amplitude_spectrum", "welch_amplitude", "SPECTRUM_KINDS"]

#: Values of :attr:`Spectrum.kind`.
SPECTRUM_KINDS = ("amplitude", "welch", "envelope")


@dataclass(frozen=True, eq=False)
class Spectrum:
    """A one-sided amplitude spectrum (a sinusoid of amplitude A reads A).

    Unpacks as ``freq_hz, amplitude = spectrum``.

    Attributes
    ----------
    freq_hz : numpy.ndarray, shape (n_freq,)
        Bin frequencies from 0 to fs/2, Hz.
    amplitude : numpy.ndarray, shape (n_freq,)
        Peak amplitude per bin, in the unit of the signal.
    resolution_hz : float
        Bin spacing fs/n_fft, Hz.
    enbw_hz : float
        Equivalent noise bandwidth of the window, Hz (flat-top ≈ 3.77 bins, Hann 1.5, boxcar 1).
    window : str
        Window name, one of :data:`~cmsim.spectra._checks.WINDOWS`.
    kind : str
        One of :data:`SPECTRUM_KINDS`.
    n_fft : int
        FFT length (record or segment length), samples.
    n_averages : int
        Number of averaged segments (1 for a single FFT).
    """

    freq_hz: np.ndarray
    amplitude: np.ndarray
    resolution_hz: float
    enbw_hz: float
    window: str
    kind: str
    n_fft: int
    n_averages: int = 1

    def __post_init__(self):
        object.__setattr__(self, "freq_hz", readonly(self.freq_hz))
        object.__setattr__(self, "amplitude", readonly(self.amplitude))
        if self.freq_hz.shape != self.amplitude.shape or self.freq_hz.ndim != 1:
            raise ParameterError("freq_hz and amplitude must be 1-D arrays of the same shape")
        check_choice("kind", self.kind, SPECTRUM_KINDS)

    def __iter__(self):
        yield self.freq_hz
        yield self.amplitude

    def band_rms(self, f_lo_hz=0.0, f_hi_hz=math.inf):
        """RMS of the signal in the band [f_lo_hz, f_hi_hz] (Parseval, window-corrected).

        Parameters
        ----------
        f_lo_hz, f_hi_hz : float
            Band edges, Hz.

        Returns
        -------
        float
            sqrt(Σ power per bin / (ENBW / bin spacing)), in the unit of the signal. Unbiased for
            white noise; for a tone wholly inside the band it returns A/√2 to within the
            window's leakage.
        """
        f_lo = check_range("f_lo_hz", f_lo_hz, 0.0, unit="Hz")
        f_hi = float(f_hi_hz)
        if not f_hi > f_lo:
            raise ParameterError(f"f_hi_hz must exceed f_lo_hz = {f_lo:g} Hz, got {f_hi_hz!r}")
        power = 0.5 * self.amplitude ** 2
        power[0] = self.amplitude[0] ** 2          # DC bin is not doubled
        if self.n_fft % 2 == 0:
            power[-1] = self.amplitude[-1] ** 2    # nor is the Nyquist bin
        sel = (self.freq_hz >= f_lo) & (self.freq_hz <= f_hi)
        return float(np.sqrt(power[sel].sum() * self.resolution_hz / self.enbw_hz))


@lru_cache(maxsize=64)
def _window(window, n):
    """The (periodic) window of :func:`scipy.signal.get_window`, read-only and kept: a
    comparison reads thousands of segments of a few lengths."""
    w = scipy.signal.get_window(window, n)
    w.setflags(write=False)
    return w


def _enbw_hz(window, n, fs):
    w = _window(window, n)
    return float(fs * np.sum(w ** 2) / np.sum(w) ** 2)


def _power_to_amplitude(power, n_fft):
    """Amplitude from a one-sided 'spectrum'-scaled power: sqrt(2P), DC/Nyquist sqrt(P)."""
    amp = np.sqrt(2.0 * np.maximum(power, 0.0))
    amp[0] = math.sqrt(max(power[0], 0.0))
    if n_fft % 2 == 0:
        amp[-1] = math.sqrt(max(power[-1], 0.0))
    return amp


def _detrend_arg(detrend):
    check_choice("detrend", detrend, DETRENDS)
    return False if detrend is None else detrend


def amplitude_spectrum(x, fs, window="flattop", detrend="constant", *, resolution_hz=None):
    """One-sided, window-corrected amplitude spectrum of a whole record.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit; finite, n >= 8.
    fs : float
        Sampling rate, Hz (> 0).
    window : {"flattop", "hann", "boxcar"}
        Window. ``"flattop"`` (default) reads any tone within 0.1 %.
    detrend : {"constant", "linear", None}
        Trend removed before windowing.
    resolution_hz : float, optional
        Largest bin spacing the caller accepts, Hz. If the record is too short
        (fs/n > resolution_hz) a :class:`ParameterError` says how long it must be.

    Returns
    -------
    Spectrum
        ``kind="amplitude"``; ``freq_hz`` has n//2 + 1 bins spaced fs/n.

    Examples
    --------
    >>> import numpy as np
    >>> fs = 1000.0
    >>> t = np.arange(1000) / fs
    >>> f, a = amplitude_spectrum(2.0 * np.sin(2 * np.pi * 50.3 * t), fs)
    >>> round(float(a.max()), 2)
    2.0
    """
    x = signal_1d(x)
    fs = sampling_rate(fs)
    check_choice("window", window, WINDOWS)
    det = _detrend_arg(detrend)
    n = x.size
    df = fs / n
    if resolution_hz is not None:
        res = check_range("resolution_hz", resolution_hz, 0.0, lo_open=True, unit="Hz")
        if df > res * (1.0 + 1e-12):
            need = math.ceil(fs / res)
            raise ParameterError(
                f"record too short for resolution_hz={res:g} Hz: it needs at least {need} "
                f"samples ({need / fs:g} s) at fs={fs:g} Hz, got {n} samples ({n / fs:g} s)")
    # scipy.signal.periodogram(scaling="spectrum") converted to amplitude, without its
    # per-call window and STFT set-up (a quarter of a comparison's feature time)
    if det == "constant":
        x = x - x.mean()
    elif det:
        x = scipy.signal.detrend(x, type=det)
    w = _window(window, n)
    amp = np.abs(np.fft.rfft(w * x)) / w.sum()
    amp[1:n // 2 + n % 2] *= 2.0                  # not DC, nor the Nyquist bin of an even n
    return Spectrum(freq_hz=np.fft.rfftfreq(n, 1.0 / fs), amplitude=amp, resolution_hz=df,
                    enbw_hz=_enbw_hz(window, n, fs), window=window, kind="amplitude",
                    n_fft=n)


def welch_amplitude(x, fs, nperseg, window="flattop", detrend="constant", *, overlap=0.5,
                    average="mean"):
    """Averaged amplitude spectrum (Welch), same amplitude convention as one FFT.

    The power spectra of overlapping segments (:func:`scipy.signal.welch`,
    ``scaling="spectrum"``) are averaged and converted to amplitude, so a steady tone of
    amplitude A still reads A, and the noise floor's variance drops with the number of
    segments.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit; finite.
    fs : float
        Sampling rate, Hz (> 0).
    nperseg : int
        Segment length, samples (8 <= nperseg <= n); bin spacing is fs/nperseg.
    window : {"flattop", "hann", "boxcar"}
        Window of each segment.
    detrend : {"constant", "linear", None}
        Trend removed from each segment.
    overlap : float
        Overlap between segments as a fraction of nperseg, in [0, 0.95].
    average : {"mean", "median"}
        How segment power spectra are averaged (median resists transients).

    Returns
    -------
    Spectrum
        ``kind="welch"``, ``n_averages`` = number of segments.
    """
    x = signal_1d(x)
    fs = sampling_rate(fs)
    check_choice("window", window, WINDOWS)
    check_choice("average", average, ("mean", "median"))
    det = _detrend_arg(detrend)
    nperseg = positive_int("nperseg", nperseg, lo=8)
    if nperseg > x.size:
        raise ParameterError(
            f"record too short: nperseg={nperseg} (resolution {fs / nperseg:g} Hz) needs at "
            f"least {nperseg} samples, got {x.size}")
    ov = check_range("overlap", overlap, 0.0, 0.95)
    noverlap = int(round(ov * nperseg))
    f, p = scipy.signal.welch(x, fs, window=window, nperseg=nperseg, noverlap=noverlap,
                              detrend=det, scaling="spectrum", average=average,
                              return_onesided=True)
    n_seg = 1 + (x.size - nperseg) // (nperseg - noverlap)
    return Spectrum(freq_hz=f, amplitude=_power_to_amplitude(p, nperseg),
                    resolution_hz=fs / nperseg, enbw_hz=_enbw_hz(window, nperseg, fs),
                    window=window, kind="welch", n_fft=nperseg, n_averages=n_seg)
