"""Envelope spectra, spectral kurtosis and the kurtogram.

Test tier: closed form (the envelope of A(1 + μ cos 2πf_m t)·sin 2πf_c t is A(1 + μ cos 2πf_m t);
SK = 0 for Gaussian noise and −1 for a steady tone; an impulse train exciting a resonance shows
its repetition rate in the envelope spectrum of the resonance band; a band narrower than
3 × the fault rate is not selected however large its SK).
"""

import numpy as np
import pytest
from scipy.signal import welch

from cmsim.errors import ParameterError
from cmsim.spectra import (bandpass, envelope, envelope_spectrum, kurtogram,
                           spectral_kurtosis)
from cmsim.spectra.kurtogram import DEFAULT_MIN_BANDWIDTH_HZ

FS = 20_000.0


def _impulse_train(rep_hz=97.3, resonance_hz=3000.0, zeta=0.05, seconds=1.0, noise=0.3,
                   seed=3):
    """Decaying resonance hit at rep_hz, plus two gear tones and white noise."""
    n = int(FS * seconds)
    t = np.arange(n) / FS
    wn = 2 * np.pi * resonance_hz
    th = np.arange(int(0.02 * FS)) / FS
    h = np.exp(-zeta * wn * th) * np.sin(wn * np.sqrt(1 - zeta ** 2) * th)
    hits = np.zeros(n)
    hits[np.round(np.arange(0.0, seconds, 1.0 / rep_hz) * FS).astype(int)] = 1.0
    x = np.convolve(hits, h)[:n]
    x /= np.abs(x).max()
    gear = 0.5 * np.sin(2 * np.pi * 466.67 * t) + 0.3 * np.sin(2 * np.pi * 933.33 * t)
    rng = np.random.default_rng(seed)
    return x + gear + noise * rng.standard_normal(n)


def test_kurtogram_finds_resonance_and_envelope_shows_repetition_rate():
    rep = 97.3
    x = _impulse_train(rep)
    kg = kurtogram(x, FS)
    lo, hi = kg.band_hz
    assert lo < 3000.0 < hi
    assert kg.kurtosis_max > 1.0
    assert kg.bandwidth_hz > 2 * rep                      # wide enough to carry the modulation
    s = envelope_spectrum(x, FS, kg.band_hz)
    sel = s.freq_hz > 5.0
    f_top = s.freq_hz[sel][np.argmax(s.amplitude[sel])]
    assert abs(f_top - rep) <= s.resolution_hz
    # without the band the envelope is dominated by the gear tones, not the repetition rate
    s_all = envelope_spectrum(x, FS, None)
    assert s_all.kind == "envelope"
    f_all = s_all.freq_hz[sel][np.argmax(s_all.amplitude[sel])]
    assert abs(f_all - rep) > 10 * s.resolution_hz


def test_envelope_of_am_signal_reads_modulation_amplitude():
    n = 40_000
    t = np.arange(n) / FS
    a, mu, fm, fc = 2.0, 0.3, 60.6, 3000.0
    x = a * (1 + mu * np.cos(2 * np.pi * fm * t)) * np.sin(2 * np.pi * fc * t)
    env = envelope(x, FS, (2500.0, 3500.0))
    mid = slice(n // 10, -n // 10)                          # away from the Hilbert edge effects
    assert np.allclose(env[mid], a * (1 + mu * np.cos(2 * np.pi * fm * t[mid])), atol=0.02)
    s = envelope_spectrum(x, FS, (2500.0, 3500.0))
    i = np.argmin(np.abs(s.freq_hz - fm))
    assert s.amplitude[i - 2: i + 3].max() == pytest.approx(a * mu, rel=0.02)


def test_bandpass_keeps_band_and_removes_outside():
    t = np.arange(20_000) / FS
    inside, outside = np.sin(2 * np.pi * 3000 * t), np.sin(2 * np.pi * 500 * t)
    y = bandpass(inside + outside, FS, (2000.0, 4000.0))
    mid = slice(2000, -2000)
    assert np.std(y[mid] - inside[mid]) < 0.02
    assert np.allclose(bandpass(inside, FS, (0.0, FS / 2)), inside)
    low = bandpass(inside + outside, FS, (0.0, 1000.0))
    assert np.std(low[mid] - outside[mid]) < 0.02


def test_spectral_kurtosis_of_noise_and_tone():
    rng = np.random.default_rng(5)
    n = 100_000
    x = rng.standard_normal(n)
    f, sk = spectral_kurtosis(x, FS, 256)
    assert np.isnan(sk[0]) and np.isnan(sk[-1])
    assert abs(np.nanmean(sk)) < 0.05
    t = np.arange(n) / FS
    f, sk = spectral_kurtosis(np.sin(2 * np.pi * 2500.0 * t) + 0.01 * x, FS, 256)
    assert sk[np.argmin(np.abs(f - 2500.0))] == pytest.approx(-1.0, abs=0.05)


def test_kurtogram_respects_min_freq_and_custom_lengths():
    x = _impulse_train()
    kg = kurtogram(x, FS, nperseg=(32, 64, 128), min_freq_hz=4000.0)
    assert kg.nperseg == (32, 64, 128)
    assert kg.band_hz[0] >= 4000.0
    assert kg.bandwidth_hz == pytest.approx(2 * FS / kg.best_nperseg)


def _fault_plus_narrow_disturbance(rep_hz=97.3, seconds=4.0):
    """Impulses at rep_hz on a 3 kHz resonance plus a 6 kHz tone switched on in 12 random
    bursts of 75 ms: a strong narrow-band disturbance, very impulsive at fine resolution."""
    x = _impulse_train(rep_hz, seconds=seconds)
    n = x.size
    t = np.arange(n) / FS
    gate = np.zeros(n)
    for start in np.random.default_rng(7).choice(n - 2000, 12, replace=False):
        gate[start: start + 1500] = 1.0
    return x + 0.5 * gate * np.sin(2 * np.pi * 6000.0 * t)


def test_kurtogram_min_bandwidth_from_fault_rate_keeps_the_bearing_band():
    rep = 97.3
    x = _fault_plus_narrow_disturbance(rep)
    kg = kurtogram(x, FS, max_fault_hz=rep)
    assert kg.bandwidth_hz >= 3.0 * rep
    assert kg.band_hz[0] < 3000.0 < kg.band_hz[1]
    s = envelope_spectrum(x, FS, kg.band_hz)
    sel = s.freq_hz > 5.0
    assert abs(s.freq_hz[sel][np.argmax(s.amplitude[sel])] - rep) <= s.resolution_hz
    # the default (no fault rate given) also keeps bands >= DEFAULT_MIN_BANDWIDTH_HZ
    assert kurtogram(x, FS).bandwidth_hz >= DEFAULT_MIN_BANDWIDTH_HZ


def test_kurtogram_min_bandwidth_removes_the_narrow_levels():
    """Without the constraint the 39 Hz band on the disturbance wins (its SK is the largest);
    with it, those levels are not considered (their SK is still returned for plotting)."""
    rep = 97.3
    x = _fault_plus_narrow_disturbance(rep)
    free = kurtogram(x, FS, min_bandwidth_hz=0.0)
    assert free.bandwidth_hz < 3.0 * rep
    assert abs(free.centre_hz - 6000.0) <= free.bandwidth_hz
    kept = kurtogram(x, FS, max_fault_hz=rep)
    assert kept.nperseg == free.nperseg
    assert kept.kurtosis_max < free.kurtosis_max
    assert kept.best_nperseg < free.best_nperseg
    assert kurtogram(x, FS, min_bandwidth_hz=3.0 * rep).band_hz == kept.band_hz
    # the band rule's kurtogram skips them: the same band, without their cost
    lean = kurtogram(x, FS, max_fault_hz=rep, narrow_levels=False)
    assert lean.band_hz == kept.band_hz and lean.kurtosis_max == kept.kurtosis_max
    assert lean.nperseg == tuple(n for n in kept.nperseg if 2.0 * FS / n >= 3.0 * rep)
    assert len(lean.nperseg) < len(kept.nperseg)


@pytest.mark.parametrize("band, order", [((2000.0, 4000.0), 4), ((0.0, 1500.0), 4),
                                         ((6000.0, FS / 2), 2), ((150.0, 400.0), 8),
                                         ((3000.0, 3500.0), 1)])
@pytest.mark.parametrize("n", [20_000, 6_453, 40])
def test_bandpass_is_scipys_sosfiltfilt_to_the_bit(band, order, n):
    """The band-pass keeps its filter's initial conditions instead of solving them at every
    call (``sosfiltfilt``): the same padding, the same two passes, the same bits; a signal
    no longer than the padding is refused, as scipy refuses it."""
    from scipy.signal import butter, sosfiltfilt
    x = _impulse_train(seconds=1.0)[:n] + 0.7      # an offset: the padding's odd extension
    lo, hi = band
    kind = ("lowpass", hi) if lo == 0.0 else ("highpass", lo) if hi >= FS / 2 else \
        ("bandpass", band)
    sos = butter(order, kind[1], btype=kind[0], fs=FS, output="sos")
    try:
        want = sosfiltfilt(sos, x)
    except ValueError:
        with pytest.raises(ParameterError, match="band-pass filter needs more than"):
            bandpass(x, FS, band, filter_order=order)
        return
    got = bandpass(x, FS, band, filter_order=order)
    assert np.array_equal(got, want)
    assert np.array_equal(bandpass(x, FS, band, filter_order=order), want)   # kept, again


@pytest.mark.parametrize("call, name", [
    (lambda: envelope_spectrum(np.ones(1000), 1000.0, (100.0, 600.0)), "band_hz"),
    (lambda: envelope_spectrum(np.ones(1000), 1000.0, (300.0, 200.0)), "band_hz"),
    (lambda: envelope_spectrum(np.ones(1000), 1000.0, 200.0), "band_hz"),
    (lambda: bandpass(np.ones(1000), 1000.0, (10.0, 100.0), filter_order=0), "filter_order"),
    (lambda: spectral_kurtosis(np.ones(100), 1000.0, 64), "nperseg"),
    (lambda: kurtogram(np.ones(500), 1000.0), "x too short"),
    (lambda: kurtogram(np.ones(5000), 1000.0, min_freq_hz=600.0), "min_freq_hz"),
    (lambda: kurtogram(np.ones(5000), 1000.0, nperseg=(16, 4.5)), "nperseg"),
    (lambda: kurtogram(np.ones(5000), 1000.0, min_bandwidth_hz=-1.0), "min_bandwidth_hz"),
    (lambda: kurtogram(np.ones(5000), 1000.0, max_fault_hz=0.0), "max_fault_hz"),
    (lambda: kurtogram(np.ones(5000), 1000.0, min_bandwidth_hz=400.0), "min_bandwidth_hz"),
])
def test_bad_inputs_name_the_parameter(call, name):
    with pytest.raises(ParameterError, match=name):
        call()


def test_kurtogram_band_edges_within_rounding_snap_to_zero_and_nyquist():
    """A best band whose lower edge is 2e-13 Hz (rounding of centre − bandwidth/2) is the
    band from 0 (found on the MFPT IR_vload7_300lb record by the envelope baseline)."""
    from cmsim.spectra.kurtogram import Kurtogram
    fields = Kurtogram.__dataclass_fields__
    kw = {name: None for name in fields}
    kw.update(fs=48828.0, centre_hz=1000.0 + 2e-13, bandwidth_hz=2000.0)
    k = Kurtogram(**kw)
    assert k.band_hz == (0.0, 2000.0 + 2e-13)
    kw.update(centre_hz=24414.0 - 500.0 - 1e-12, bandwidth_hz=1000.0)
    assert Kurtogram(**kw).band_hz[1] == 24414.0


def _gearbox_with_a_bearing_defect(seed):
    """Six mesh harmonics of 540 Hz, amplitude- (60 %) and phase-modulated at the 24.5-Hz
    shaft rate (their beating in a wide band looks impulsive), over weak impacts at 118.7 Hz
    ringing a 4-kHz resonance, and white noise; 12 kHz, 0.5 s."""
    fs, n = 12_000.0, 6000
    t = np.arange(n) / fs
    fr, gmf = 24.5, 22 * 24.5
    env = 1.0 + 0.6 * np.cos(2 * np.pi * fr * t)
    pm = 0.25 * np.sin(2 * np.pi * fr * t)
    gear = sum(0.7 ** k * np.cos(2 * np.pi * (k + 1) * gmf * t + (k + 1) * pm)
               for k in range(6)) * env
    wn, zeta = 2 * np.pi * 4000.0, 0.05
    th = np.arange(int(0.01 * fs)) / fs
    h = np.exp(-zeta * wn * th) * np.sin(wn * np.sqrt(1 - zeta ** 2) * th)
    hits = np.zeros(n)
    hits[np.round(np.arange(0.003, 0.5, 1 / 118.7) * fs).astype(int)] = 1.0
    impacts = np.convolve(hits, h)[:n]
    rng = np.random.default_rng(seed)
    return fs, gear + 0.35 * impacts / np.abs(impacts).max() + 0.1 * rng.standard_normal(n)


def test_the_band_rule_reads_past_a_gearbox_discrete_part_to_the_impacts():
    """Closed form of the linear predictor: steady lines are predictable, impacts are not.
    The mesh lines stand > 30 dB over their neighbourhood in the signal and < 6 dB in the
    residual of a 128th-order predictor; the kurtogram of the signal itself picks the
    beating mesh harmonics' band, the band rule (the residual's) the resonance where the
    impacts ring."""
    from cmsim.features.lines import demodulation_band
    from cmsim.spectra.kurtogram import prediction_residual

    fs, x = _gearbox_with_a_bearing_defect(seed=0)
    e = prediction_residual(x, orders=(128,))
    gmf = 22 * 24.5
    for v, least, most in ((x, 30.0, np.inf), (e, -np.inf, 6.0)):
        f, p = welch(v, fs, nperseg=1024)
        for k in (1, 2, 3):
            i = np.argmin(np.abs(f - k * gmf))
            floor = np.median(p[(np.abs(f - k * gmf) > 60) & (np.abs(f - k * gmf) < 250)])
            assert least < 10 * np.log10(p[i] / floor) < most, k
    for seed in range(3):
        fs, x = _gearbox_with_a_bearing_defect(seed)
        lo, hi = kurtogram(x, fs, max_fault_hz=118.7).band_hz
        assert hi < 3000.0                                  # the mesh band wins on the signal
        lo, hi = demodulation_band(x, fs, 118.7)
        assert lo < 4000.0 < hi                             # the band rule reads the impacts


@pytest.mark.parametrize("nperseg", [16, 24, 96, 1536])
def test_the_stft_moments_kernel_is_numpys_to_the_bit(nperseg):
    """The kurtogram's second and fourth STFT moments come from a numba pass over the
    segments; numpy's ``mean(axis=0)`` of |z|² and |z|⁴ sums each bin row by row in the same
    order, so every spectral kurtosis (and the band a comparison reads) is the same."""
    from cmsim.spectra._kurtogram_kernels import stft_moments_jit

    rng = np.random.default_rng(nperseg)
    frames = rng.standard_normal((24_300 // (nperseg // 4), nperseg)) * rng.uniform(0.1, 10.0)
    z = np.fft.rfft(frames * np.hanning(nperseg), axis=1)
    p2 = z.real * z.real + z.imag * z.imag
    m2, m4 = stft_moments_jit(z)
    assert np.array_equal(m2, p2.mean(axis=0))
    assert np.array_equal(m4, (p2 ** 2).mean(axis=0))


@pytest.mark.parametrize("n", [6_000, 6_480, 24_300, 300])
def test_the_predictor_reads_the_biased_autocorrelation(n):
    """The predictor's normal equations are those of the biased autocorrelation
    r_k = Σ x_i x_(i+k) / n, read from a zero-padded FFT only as long as the lags need:
    the residual of each order is that of the direct sums' predictor within rounding."""
    import scipy.linalg

    from cmsim.spectra.kurtogram import prediction_residual

    rng = np.random.default_rng(n)
    t = np.arange(n) / FS
    x = np.sin(2 * np.pi * 1234.5 * t) + 0.3 * rng.standard_normal(n)
    for p in (16, 128):
        p_eff = min(p, n // 20)
        xc = x - x.mean()
        r = np.array([xc[: n - k] @ xc[k:] for k in range(p_eff + 1)]) / n
        a = scipy.linalg.solve_toeplitz(r[:p_eff], r[1:p_eff + 1])
        want = np.convolve(xc, np.r_[1.0, -a], mode="valid")
        got = prediction_residual(x, orders=(p,))
        assert got.size == want.size
        assert np.allclose(got, want, rtol=0.0, atol=1e-9 * np.abs(want).max())
