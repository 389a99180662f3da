"""Amplitude spectra read the amplitude of a sinusoid, on and between bins; Welch keeps Parseval.

Test tier: closed form (a tone of amplitude A reads A; the RMS of white noise of standard
deviation σ is σ).
"""

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.spectra import Spectrum, amplitude_spectrum, welch_amplitude

FS = 10_000.0
N = 10_000          # 1 s, bins every 1 Hz


def _tone(freq_hz, amplitude, n=N, fs=FS, phase=0.7):
    t = np.arange(n) / fs
    return amplitude * np.sin(2 * np.pi * freq_hz * t + phase)


@pytest.mark.parametrize("freq_hz", [50.0, 466.0, 1234.0, 3000.0],
                         ids=["50", "466", "1234", "3000"])
@pytest.mark.parametrize("offset_bins", [0.0, 0.17, 0.33, 0.5], ids=["on", "0.17", "0.33", "0.5"])
@pytest.mark.parametrize("amplitude", [1e-6, 0.37, 25.0])
def test_flattop_reads_tone_amplitude_within_1_percent(freq_hz, offset_bins, amplitude):
    f0 = freq_hz + offset_bins * FS / N
    f, a = amplitude_spectrum(_tone(f0, amplitude), FS)
    i = int(np.argmax(a))
    assert a[i] == pytest.approx(amplitude, rel=0.01)
    assert abs(f[i] - f0) <= FS / N


def test_boxcar_reads_bin_centred_tone_exactly_but_hann_loses_between_bins():
    f, a = amplitude_spectrum(_tone(100.0, 2.0), FS, window="boxcar")
    assert a.max() == pytest.approx(2.0, rel=1e-9)
    f, a = amplitude_spectrum(_tone(100.5, 2.0), FS, window="hann")
    # documented scalloping loss of Hann half-way between bins: 1.42 dB (15 %)
    assert a.max() / 2.0 == pytest.approx(10 ** (-1.42 / 20), abs=0.01)


def test_spectrum_axis_dc_and_unpacking():
    x = 3.0 + _tone(200.0, 1.0)
    s = amplitude_spectrum(x, FS, detrend=None)
    assert isinstance(s, Spectrum)
    assert s.freq_hz.shape == (N // 2 + 1,)
    assert s.resolution_hz == pytest.approx(1.0)
    assert s.amplitude[0] == pytest.approx(3.0, rel=1e-3)        # DC not doubled
    f, a = s
    assert a[200] == pytest.approx(1.0, rel=0.01)
    with pytest.raises(ValueError):
        s.amplitude[0] = 1.0                                     # read-only value object
    assert amplitude_spectrum(x, FS).amplitude[0] < 1e-9         # default removes the mean


def test_welch_reads_tone_amplitude_and_white_noise_rms():
    rng = np.random.default_rng(1)
    sigma = 0.8
    x = sigma * rng.standard_normal(200_000)
    s = welch_amplitude(x, FS, nperseg=1024)
    assert s.kind == "welch" and s.n_averages > 300
    assert s.band_rms() == pytest.approx(sigma, rel=0.02)        # Parseval through the ENBW
    # half the band holds half the power
    assert s.band_rms(0.0, FS / 4) == pytest.approx(sigma / np.sqrt(2), rel=0.03)
    tone = _tone(1234.56, 0.5, n=x.size)
    s = welch_amplitude(tone + 0.01 * x, FS, nperseg=2048, window="flattop")
    assert s.amplitude.max() == pytest.approx(0.5, rel=0.01)
    assert s.band_rms(1200.0, 1270.0) == pytest.approx(0.5 / np.sqrt(2), rel=0.01)


def test_single_fft_parseval_for_noise_and_tone():
    rng = np.random.default_rng(2)
    x = rng.standard_normal(N)
    for window in ("flattop", "hann", "boxcar"):
        s = amplitude_spectrum(x, FS, window=window)
        assert s.band_rms() == pytest.approx(x.std(), rel=0.05)
    s = amplitude_spectrum(_tone(321.3, 2.0), FS, window="hann")
    assert s.band_rms() == pytest.approx(2.0 / np.sqrt(2), rel=0.01)


@pytest.mark.parametrize("call, name", [
    (lambda: amplitude_spectrum(np.ones(100), 0.0), "fs"),
    (lambda: amplitude_spectrum(np.ones(100), -5.0), "fs"),
    (lambda: amplitude_spectrum(np.r_[np.ones(50), np.nan], 100.0), "x"),
    (lambda: amplitude_spectrum(np.ones(3), 100.0), "x"),
    (lambda: amplitude_spectrum(np.ones((10, 10)), 100.0), "x"),
    (lambda: amplitude_spectrum(np.ones(100), 100.0, window="hamming"), "window"),
    (lambda: amplitude_spectrum(np.ones(100), 100.0, detrend="quadratic"), "detrend"),
    (lambda: amplitude_spectrum(np.ones(100), 100.0, resolution_hz=0.5), "resolution_hz"),
    (lambda: welch_amplitude(np.ones(100), 100.0, nperseg=256), "nperseg"),
    (lambda: welch_amplitude(np.ones(100), 100.0, nperseg=32, overlap=1.0), "overlap"),
    (lambda: welch_amplitude(np.ones(100), 100.0, nperseg=32.0), "nperseg"),
])
def test_bad_inputs_name_the_parameter(call, name):
    with pytest.raises(ParameterError, match=name):
        call()


def test_record_too_short_message_gives_needed_length():
    with pytest.raises(ParameterError, match=r"at least 200 samples \(2 s\)"):
        amplitude_spectrum(np.ones(100), 100.0, resolution_hz=0.5)
    s = amplitude_spectrum(np.ones(200), 100.0, resolution_hz=0.5)
    assert s.resolution_hz <= 0.5


@pytest.mark.parametrize("n", [1000, 1001, 4096])
@pytest.mark.parametrize("window", ["flattop", "hann", "boxcar"])
@pytest.mark.parametrize("detrend", ["constant", "linear", None])
def test_the_single_fft_spectrum_is_scipy_s_periodogram_in_amplitude(n, window, detrend):
    """The spectrum is computed without scipy's per-call set-up; it must stay the periodogram
    (``scaling="spectrum"``) in amplitude: √(2P), at DC and Nyquist √P."""
    import scipy.signal
    x = np.random.default_rng(n).standard_normal(n) + 3.0 + np.linspace(0.0, 2.0, n)
    f, p = scipy.signal.periodogram(x, FS, window=window, detrend=detrend or False,
                                    scaling="spectrum")
    want = np.sqrt(2.0 * p)
    want[0] = np.sqrt(p[0])
    if n % 2 == 0:
        want[-1] = np.sqrt(p[-1])
    got = amplitude_spectrum(x, FS, window=window, detrend=detrend)
    np.testing.assert_allclose(got.freq_hz, f, rtol=0, atol=1e-9)
    np.testing.assert_allclose(got.amplitude, want, rtol=1e-10, atol=1e-12 * want.max())
