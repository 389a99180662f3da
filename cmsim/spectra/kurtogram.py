"""Spectral kurtosis and an STFT-based kurtogram that picks the band for envelope analysis.

Variant: the *STFT-based* kurtogram of Antoni & Randall (2006), not the filter-bank "fast
kurtogram" (1/3-binary tree) of Antoni (2007). For each window length N_w the spectral
kurtosis (SK) is estimated from the Hann-windowed STFT (:class:`scipy.signal.ShortTimeFFT`,
75 % overlap, only segments fully inside the record) with the unbiased estimator

    SK(f) = (M + 1)/(M − 1) · ⟨|X(t, f)|⁴⟩ / ⟨|X(t, f)|²⟩² − 2          (M segments),

which is ≈ 0 for stationary Gaussian noise, ≈ −1 for a steady tone and large positive for
impulsive (bearing-fault-like) components. The window lengths are dyadic, 2^k, plus the
intermediate 1.5·2^k (so that consecutive bandwidths differ by factors 1.5 and 4/3, like the
1/3 levels of the fast kurtogram). Each (N_w, f) cell is a band centred on f with bandwidth
2·fs/N_w — the −6 dB width of the Hann window's response. The cell with the largest SK whose
band lies inside (0, fs/2) is returned as the demodulation band.

Minimum bandwidth. A band narrower than the fault rate it must carry cannot hold the
modulation: the envelope of a band of width B shows modulation frequencies up to about B/2,
and the fault line plus its first sidebands (f_c ± f_fault) need B ≥ 2·f_fault. Long windows
(N_w = 4096 at 32 kHz: 16 Hz) would otherwise win on a strong narrow-band disturbance, whose
SK can exceed that of the bearing impacts. Levels with 2·fs/N_w below ``min_bandwidth_hz`` are
therefore not considered; by default ``min_bandwidth_hz`` = :data:`FAULT_BANDWIDTH_FACTOR` ×
``max_fault_hz`` (3 × the highest characteristic frequency of interest, e.g. BPFI) when that
is given, else :data:`DEFAULT_MIN_BANDWIDTH_HZ`.

References
----------
.. [1] J. Antoni, R. B. Randall, "The spectral kurtosis: application to the vibratory
   surveillance and diagnostics of rotating machines", MSSP 20 (2006) 308-331.
.. [2] J. Antoni, "Fast computation of the kurtogram for the detection of transient faults",
   MSSP 21 (2007) 108-124.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.fft
import scipy.linalg
import scipy.signal

from cmsim.errors import ParameterError, check_range
from cmsim.spectra._checks import positive_int, sampling_rate, signal_1d
from cmsim.spectra._kurtogram_kernels import stft_moments_jit

__all__ = ["Kurtogram", "spectral_kurtosis", "kurtogram", "prediction_residual",
           "residual_kurtogram",
           "FAULT_BANDWIDTH_FACTOR", "DEFAULT_MIN_BANDWIDTH_HZ", "PREDICTION_ORDERS"]

#: Fewest STFT segments accepted for one SK estimate.
MIN_SEGMENTS = 16

#: Bandwidth of one STFT cell in bins of fs/N_w (−6 dB width of the Hann window).
HANN_BANDWIDTH_BINS = 2.0

#: Default least band, in multiples of the highest fault frequency of interest.
FAULT_BANDWIDTH_FACTOR = 3.0

#: Default least band without a fault frequency, Hz (3 × 162 Hz, the BPFI of a 6205 bearing
#: at 1800 rpm; below it a band cannot carry a typical rolling-bearing modulation).
DEFAULT_MIN_BANDWIDTH_HZ = 500.0

#: Orders of the linear predictor tried by :func:`prediction_residual` (the one whose residual
#: is most impulsive is kept; each capped at n/20 samples).
PREDICTION_ORDERS = (16, 32, 64, 128)


def prediction_residual(x, orders=PREDICTION_ORDERS):
    """What a linear predictor of ``x`` cannot predict: ``x`` without its discrete part.

    A forward predictor of order p (Yule-Walker: the Toeplitz system of the biased
    autocorrelation) predicts steady lines — gear-mesh harmonics and their sidebands, shaft
    orders, the mains — and leaves the random and impulsive part (bearing impacts are not
    predictable from the past). Of ``orders`` the one whose residual has the largest kurtosis
    is kept (Sawalhi & Randall 2007; Smith & Randall 2015's benchmark method). The residual
    is whitened as well; the spectral kurtosis of a band does not depend on a gain across it,
    so the kurtogram of the residual still finds the band where impacts ring, without the
    beating of lines in wide bands that makes a gearbox's mesh band look impulsive.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit; finite, n >= 64.
    orders : sequence of int
        Predictor orders tried (each capped at n // 20).

    Returns
    -------
    numpy.ndarray, shape (n - p,)
        The residual, without the p samples the predictor starts on.

    References
    ----------
    .. [1] N. Sawalhi, R. B. Randall, H. Endo, MSSP 21 (2007) 2616-2633 (AR prediction before
       the spectral kurtosis).
    .. [2] W. A. Smith, R. B. Randall, MSSP 64-65 (2015) 100-131.
    """
    x = signal_1d(x, min_samples=64)
    x = x - x.mean()
    n = x.size
    p_max = min(max(orders), n // 20)
    # the biased autocorrelation's first p_max + 1 lags: a circular one of n + p_max zero-
    # padded samples or more holds them unwrapped (2n = 48 600 = 2³·3⁵·5² at 0.5 s of
    # 48.8 kHz took three times as long as 24 576 = 2¹³·3, the next fast length)
    nfft = scipy.fft.next_fast_len(n + p_max + 1, real=True)
    spec = np.fft.rfft(x, nfft)
    r = np.fft.irfft(spec.real * spec.real + spec.imag * spec.imag, nfft)[:p_max + 1] / n
    if not r[0] > 0:
        return x.copy()
    best, best_k = x, -np.inf
    for p in sorted({min(int(o), p_max) for o in orders if o >= 1}):
        try:
            a = scipy.linalg.solve_toeplitz(r[:p], r[1:p + 1])
        except (np.linalg.LinAlgError, ValueError):
            continue
        e = np.convolve(x, np.r_[1.0, -a], mode="valid")
        e2 = e * e                        # (e²)², not e ** 4: numpy's pow is 40 times slower
        m2 = float(np.mean(e2))
        k = float(np.mean(e2 * e2)) / m2 ** 2 if m2 > 0 else -np.inf
        if k > best_k:
            best, best_k = e, k
    return best


def residual_kurtogram(x, fs, **kwargs):
    """The kurtogram the band rule reads: that of :func:`prediction_residual` of ``x``.

    Every default envelope band of cmsim is its best band
    (:func:`cmsim.features.lines.demodulation_band`, the spectrum of a run, peak labels).

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit; finite.
    fs : float
        Sampling rate, Hz.
    **kwargs
        Keywords of :func:`kurtogram`.

    Returns
    -------
    Kurtogram
    """
    return kurtogram(prediction_residual(x), fs, **kwargs)


@lru_cache(maxsize=64)
def _hann_stft(nperseg, hop, fs):
    """The Hann STFT of a window length, hop and rate, kept (its set-up cost as much as the
    transform of a short record, and a band rule reads thousands of them)."""
    return scipy.signal.ShortTimeFFT(scipy.signal.get_window("hann", nperseg), hop, fs,
                                     fft_mode="onesided")


def _stft_moments(x, fs, nperseg, overlap):
    """|X|² and |X|⁴ averaged over the fully contained STFT segments."""
    hop = max(1, int(round(nperseg * (1.0 - overlap))))
    sft = _hann_stft(nperseg, hop, fs)
    p0 = sft.lower_border_end[1]
    p1 = sft.upper_border_begin(x.size)[1]
    if p1 - p0 < MIN_SEGMENTS:
        raise ParameterError(
            f"record too short for nperseg={nperseg}: {max(p1 - p0, 0)} full STFT segments, "
            f"need >= {MIN_SEGMENTS} (at least about {nperseg * (1 + MIN_SEGMENTS * (1 - overlap)):.0f} "
            f"samples, got {x.size})")
    # the same segments as sft.stft(x, p0=p0, p1=p1) (segment p starts at p·hop − m_num_mid),
    # transformed in one vectorised rfft instead of one FFT call per segment
    start = p0 * hop - sft.m_num_mid
    frames = np.lib.stride_tricks.sliding_window_view(x - x.mean(), nperseg)
    frames = frames[start: start + (p1 - p0 - 1) * hop + 1: hop]
    m2, m4 = stft_moments_jit(np.fft.rfft(frames * sft.win, axis=1))
    return sft.f, m2, m4, p1 - p0


def spectral_kurtosis(x, fs, nperseg=256, *, overlap=0.75):
    """Spectral kurtosis of ``x`` from a Hann STFT of window length ``nperseg``.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit; finite.
    fs : float
        Sampling rate, Hz (> 0).
    nperseg : int
        STFT window length, samples (>= 8); needs at least 16 full segments in the record.
    overlap : float
        Segment overlap as a fraction of ``nperseg``, in [0, 0.9].

    Returns
    -------
    freq_hz : numpy.ndarray, shape (nperseg//2 + 1,)
        Bin frequencies, Hz.
    sk : numpy.ndarray, shape (nperseg//2 + 1,)
        Spectral kurtosis (dimensionless); NaN at DC and fs/2, where the STFT is real.

    References
    ----------
    .. [1] J. Antoni, R. B. Randall, MSSP 20 (2006) 308-331, eq. (11).
    """
    x = signal_1d(x)
    fs = sampling_rate(fs)
    nperseg = positive_int("nperseg", nperseg, lo=8)
    ov = check_range("overlap", overlap, 0.0, 0.9)
    f, m2, m4, m = _stft_moments(x, fs, nperseg, ov)
    with np.errstate(invalid="ignore", divide="ignore"):
        sk = (m + 1.0) / (m - 1.0) * m4 / m2 ** 2 - 2.0
    sk[0] = np.nan
    if nperseg % 2 == 0:
        sk[-1] = np.nan
    sk[~np.isfinite(sk)] = np.nan
    return f, sk


@dataclass(frozen=True, eq=False)
class Kurtogram:
    """Spectral kurtosis for several STFT window lengths and the best band.

    Attributes
    ----------
    fs : float
        Sampling rate of the analysed signal, Hz.
    nperseg : tuple of int, shape (n_levels,)
        STFT window lengths, samples, increasing (bandwidth decreasing).
    freq_hz : tuple of numpy.ndarray
        Per level, the bin frequencies, Hz, shape (nperseg[i]//2 + 1,).
    kurtosis : tuple of numpy.ndarray
        Per level, the spectral kurtosis at ``freq_hz[i]`` (NaN where undefined).
    centre_hz : float
        Centre of the band with the largest spectral kurtosis, Hz.
    bandwidth_hz : float
        Its bandwidth 2·fs/N_w, Hz.
    kurtosis_max : float
        Its spectral kurtosis.
    best_nperseg : int
        Its STFT window length, samples.
    """

    fs: float
    nperseg: tuple
    freq_hz: tuple
    kurtosis: tuple
    centre_hz: float
    bandwidth_hz: float
    kurtosis_max: float
    best_nperseg: int

    @property
    def band_hz(self):
        """Best band (lo, hi), Hz, ready for :func:`~cmsim.spectra.envelope.envelope_spectrum`."""
        lo = max(0.0, self.centre_hz - 0.5 * self.bandwidth_hz)
        hi = min(0.5 * self.fs, self.centre_hz + 0.5 * self.bandwidth_hz)
        # a band edge within rounding of 0 or Nyquist is that edge (a 2e-13 Hz lower edge
        # would ask the band-pass filter for a singular design)
        tiny = 1e-9 * self.fs
        if lo < tiny:
            lo = 0.0
        if hi > 0.5 * self.fs - tiny:
            hi = 0.5 * self.fs
        return (lo, hi)

    def bandwidth_of(self, nperseg):
        """Bandwidth of a cell of window length ``nperseg``, Hz."""
        return HANN_BANDWIDTH_BINS * self.fs / nperseg


def _default_lengths(n):
    """Dyadic and 1.5×dyadic window lengths from 16 up to n/64 (and at most 4096).

    n/64 keeps about 250 overlapping segments per SK estimate: longer windows give SK
    estimates too noisy (and too sensitive to beating between steady lines) to compare.
    """
    top = min(4096, n // 64)
    out = []
    k = 4
    while 2 ** k <= top:
        out.append(2 ** k)
        if 3 * 2 ** (k - 1) <= top:
            out.append(3 * 2 ** (k - 1))
        k += 1
    return tuple(sorted(out))


def kurtogram(x, fs, nperseg=None, *, overlap=0.75, min_freq_hz=0.0, min_bandwidth_hz=None,
              max_fault_hz=None, narrow_levels=True):
    """STFT-based kurtogram and the band of largest spectral kurtosis.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit; finite, n >= 1024 with the default window lengths.
    fs : float
        Sampling rate, Hz (> 0).
    nperseg : sequence of int, optional
        STFT window lengths to scan; default 16, 24, 32, 48, ... up to min(4096, n/64).
    overlap : float
        STFT segment overlap fraction, in [0, 0.9].
    min_freq_hz : float
        Bands whose lower edge is below this frequency are ignored, Hz (e.g. to skip the
        shaft-rate region); the upper edge must stay below fs/2.
    min_bandwidth_hz : float, optional
        Least bandwidth 2·fs/N_w of a candidate band, Hz (>= 0); levels finer than this are
        not considered (their SK is still computed and returned for plotting). Default
        ``FAULT_BANDWIDTH_FACTOR * max_fault_hz`` when ``max_fault_hz`` is given, else
        :data:`DEFAULT_MIN_BANDWIDTH_HZ`. Pass 0 to consider every level.
    max_fault_hz : float, optional
        Highest characteristic (fault) frequency the band must pass, Hz (> 0), e.g.
        ``max(bpfo, bpfi, 2·bsf)`` of the bearing; sets the default ``min_bandwidth_hz``.
    narrow_levels : bool
        False leaves out the levels finer than ``min_bandwidth_hz`` (the band is the same:
        it is never one of theirs; a band rule that reads only the band skips most of the
        kurtogram's cost, since the longest windows are the narrowest bands).

    Returns
    -------
    Kurtogram

    References
    ----------
    .. [1] J. Antoni, R. B. Randall, MSSP 20 (2006) 308-331.
    """
    x = signal_1d(x, min_samples=128)
    fs = sampling_rate(fs)
    ov = check_range("overlap", overlap, 0.0, 0.9)
    f_min = check_range("min_freq_hz", min_freq_hz, 0.0, 0.5 * fs, hi_open=True, unit="Hz")
    if min_bandwidth_hz is not None:
        bw_min = check_range("min_bandwidth_hz", min_bandwidth_hz, 0.0, 0.5 * fs, unit="Hz")
    elif max_fault_hz is not None:
        bw_min = FAULT_BANDWIDTH_FACTOR * check_range("max_fault_hz", max_fault_hz, 0.0,
                                                      0.5 * fs, lo_open=True, unit="Hz")
    else:
        bw_min = min(DEFAULT_MIN_BANDWIDTH_HZ, 0.25 * fs)
    if nperseg is None:
        lengths = _default_lengths(x.size)
    else:
        try:
            lengths = tuple(sorted(positive_int("nperseg", v, lo=8) for v in nperseg))
        except TypeError:
            raise ParameterError(f"nperseg must be a sequence of integers >= 8, "
                                 f"got {nperseg!r}") from None
    if not lengths:
        raise ParameterError(f"x too short for a kurtogram: {x.size} samples, need >= 1024")
    if not narrow_levels:
        lengths = tuple(nw for nw in lengths if HANN_BANDWIDTH_BINS * fs / nw >= bw_min)
    freqs, kurts = [], []
    best = (-np.inf, np.nan, np.nan, 0)
    for nw in lengths:
        f, sk = spectral_kurtosis(x, fs, nw, overlap=ov)
        bw = HANN_BANDWIDTH_BINS * fs / nw
        ok = (bw >= bw_min) & np.isfinite(sk) & (f - 0.5 * bw >= f_min) & (f - 0.5 * bw >= 0.0) \
            & (f + 0.5 * bw <= 0.5 * fs)
        if np.any(ok):
            i = int(np.argmax(np.where(ok, sk, -np.inf)))
            if sk[i] > best[0]:
                best = (float(sk[i]), float(f[i]), bw, nw)
        freqs.append(f)
        kurts.append(sk)
    if best[3] == 0:
        raise ParameterError(f"no kurtogram band of width >= min_bandwidth_hz={bw_min:g} Hz "
                             f"fits between min_freq_hz={f_min:g} Hz and fs/2={0.5 * fs:g} Hz "
                             f"for nperseg={lengths}")
    return Kurtogram(fs=fs, nperseg=lengths, freq_hz=tuple(freqs), kurtosis=tuple(kurts),
                     centre_hz=best[1], bandwidth_hz=best[2], kurtosis_max=best[0],
                     best_nperseg=best[3])
