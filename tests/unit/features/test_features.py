"""The feature extractor (cmsim.features) on signals whose features are known.

Test tier: closed form (sinusoids of known amplitude at k·GMF and k·GMF ± n·f_rate read back
within 1 % from a flat-top spectrum; a resonance hit at BPFO shows BPFO, not BPFI/BSF/FTF,
in the envelope; a sine has kurtosis 3/2 and crest factor √2; Gaussian noise kurtosis 3).
"""

import math

import numpy as np
import pytest

from cmsim.features import (N_ENVELOPE_HARMONICS, N_GMF_HARMONICS, FeatureRow, extract_features,
                            relative_features, run_features, statistics)
from cmsim.frequencies import RigFrequencies, bearing_frequencies, rig_frequencies
from cmsim.rig import OperatingPoint, Rig
from cmsim.run import Run

FS = 8192.0


def _gear_freqs():
    """fr1 = 10 Hz, fr2 = 7.5 Hz, GMF = 200.3 Hz (between bins), one bearing on shaft 1."""
    brg = bearing_frequencies(10.0, 9, 7.94e-3, 39.04e-3)          # BPF = BPFO = 35.8 Hz
    return RigFrequencies(fr1_hz=10.0, fr2_hz=7.5, gmf_hz=200.3, bearings={"1b1": brg})


def test_gmf_harmonics_and_sidebands_read_within_1_percent():
    f = _gear_freqs()
    t = np.arange(int(4 * FS)) / FS
    bpf = f.bearing("1b1").bpf_hz
    carriers = {k: 1.0 / k for k in range(1, N_GMF_HARMONICS + 1)}
    lines = {("fr1", -1): 0.11, ("fr1", 2): 0.07, ("fr2", 1): 0.05, ("fr2", -2): 0.03,
             ("bpf_1b1", 1): 0.09, ("bpf_1b1", -1): 0.04}
    rate = {"fr1": f.fr1_hz, "fr2": f.fr2_hz, "bpf_1b1": bpf}
    rng = np.random.default_rng(0)
    x = np.zeros_like(t)
    for k, a in carriers.items():
        x += a * np.cos(2 * np.pi * k * f.gmf_hz * t + rng.uniform(0, 2 * np.pi))
        for (r, n), b in lines.items():
            x += b * a * np.cos(2 * np.pi * (k * f.gmf_hz + n * rate[r]) * t
                                + rng.uniform(0, 2 * np.pi))
    row = extract_features(x, FS, f)
    d = row.to_dict()
    for k, a in carriers.items():
        assert d[f"gmf{k}_amp"] == pytest.approx(a, rel=0.01)
        for (r, n), b in lines.items():
            key = f"gmf{k}_sb_{r}_{'m' if n < 0 else 'p'}{abs(n)}"
            assert d[key] == pytest.approx(b * a, rel=0.01), key
        # absent sidebands read (almost) nothing
        assert d[f"gmf{k}_sb_fr1_p1"] < 1e-3 * a
    assert row.dominant_gmf_harmonic == 1


def _ball_pass_rig():
    """(bearing frequencies, rig frequencies, fs) of a 6205 at 1797 rpm (BPFO 107.4 Hz)."""
    rpm = 1797.0
    brg = bearing_frequencies(rpm / 60, 9, 7.94e-3, 39.04e-3)
    return brg, RigFrequencies(fr1_hz=rpm / 60, bearings={"DE": brg}), 20_000.0


def _ringing_at_bpfo(brg, fs, n):
    """Unit impacts at the ball pass, each ringing a 3.5-kHz, 5 %-damped resonance."""
    wn = 2 * np.pi * 3500.0
    th = np.arange(int(0.01 * fs)) / fs
    h = np.exp(-0.05 * wn * th) * np.sin(wn * th)
    hits = np.zeros(n)
    hits[np.round(np.arange(0.0, n / fs, 1.0 / brg.bpfo_hz) * fs).astype(int)] = 1.0
    return np.convolve(hits, h)[:n]


def test_envelope_family_at_bpfo_dominates():
    """A measured-style record: one bearing given by name, no gears."""
    brg, f, fs = _ball_pass_rig()
    n = int(2 * fs)
    x = _ringing_at_bpfo(brg, fs, n) + 0.2 * np.random.default_rng(1).standard_normal(n)
    x *= 1.0 + 0.5 * np.cos(2 * np.pi * f.fr1_hz * np.arange(n) / fs)   # load-zone modulation
    row = extract_features(x, fs, f, bearing="DE")
    d = row.to_dict()
    bpfo = d["env_bpfo_DE_h1"]
    for fam in ("bpfi", "bsf", "ftf"):
        for hh in range(1, N_ENVELOPE_HARMONICS + 1):
            assert bpfo > 3.0 * d[f"env_{fam}_DE_h{hh}"], (fam, hh)
    assert d["env_bpfo_DE_h2"] > 3.0 * d["env_bpfi_DE_h1"]
    lo, hi = row.envelope_band_hz
    assert hi - lo >= 3.0 * brg.bpfi_hz and lo < 3500.0 < hi
    # no gears: GMF columns present and NaN, no TSA residual
    assert all(math.isnan(d[f"gmf{k}_amp"]) for k in range(1, N_GMF_HARMONICS + 1))
    assert math.isnan(d["gmf1_sb_fr1_m1"]) and math.isnan(d["tsa_residual_kurtosis"])
    assert row.dominant_gmf_harmonic is None


def test_statistics_of_a_sine_and_of_noise():
    t = np.arange(10_000) / 10_000.0
    x = 3.0 + 2.0 * np.sin(2 * np.pi * 50.0 * t)                  # mean removed first
    rms, kurt, crest = statistics(x)
    assert rms == pytest.approx(2.0 / math.sqrt(2.0), rel=1e-9)
    assert kurt == pytest.approx(1.5, rel=1e-9)
    assert crest == pytest.approx(math.sqrt(2.0), rel=1e-6)
    row = extract_features(x, 10_000.0, _gear_freqs(), envelope=False)
    assert (row.rms, row.kurtosis, row.crest) == pytest.approx((rms, kurt, crest), rel=1e-12)
    noise = np.random.default_rng(2).standard_normal(200_000)
    assert statistics(noise)[1] == pytest.approx(3.0, abs=0.05)


def test_tsa_residual_kurtosis_sees_a_non_synchronous_impulse():
    """Gear tones are synchronous with fr1 and leave the residual Gaussian (kurtosis ≈ 3);
    impulses not locked to the shaft stay in the residual and raise its kurtosis."""
    f = _gear_freqs()
    n = int(4 * FS)
    t = np.arange(n) / FS
    rng = np.random.default_rng(3)
    x = np.cos(2 * np.pi * 20 * f.fr1_hz * t) + 0.1 * rng.standard_normal(n)
    base = extract_features(x, FS, f, envelope=False).tsa_residual_kurtosis
    assert base == pytest.approx(3.0, abs=0.3)
    y = x.copy()
    y[rng.choice(n, 7, replace=False)] += 3.0
    assert extract_features(y, FS, f, envelope=False).tsa_residual_kurtosis > 2 * base


def test_columns_are_stable_and_scalar():
    f = _gear_freqs()
    t = np.arange(int(2 * FS)) / FS
    a = extract_features(np.sin(2 * np.pi * 200.3 * t), FS, f, top_n=3).to_dict()
    b = extract_features(np.random.default_rng(4).standard_normal(t.size), FS, f,
                         top_n=3).to_dict()
    assert list(a) == list(b)
    assert all(isinstance(v, (float, str)) for v in a.values())
    assert {"rms", "kurtosis", "crest", "tsa_residual_kurtosis", "gmf1_amp", "gmf6_amp",
            "gmf1_sb_fr1_m1", "gmf6_sb_fr2_p2", "gmf3_sb_bpf_1b1_m2", "env_bpfo_1b1_h1",
            "env_ftf_1b1_h3", "peak1_hz", "peak3_label"} <= set(a)
    assert a["peak1_label"] == "1GMF"
    assert a["peak1_hz"] == pytest.approx(200.3, abs=FS / t.size)


def test_run_features_takes_frequencies_and_bearing_from_the_run():
    rig, op = Rig.paper_2016(), OperatingPoint(speed_rpm=1000.0, torque_nm=50.0)
    f = rig_frequencies(rig, op)
    fs = 20_000.0
    t = np.arange(int(fs)) / fs
    x = 5.0 * np.sin(2 * np.pi * 3 * f.gmf_hz * t)
    run = Run(t, {"F_2b1_loa": x}, {"rig": rig.to_dict(), "fs_hz": fs,
                                     "operating_point": {"speed_rpm": 1000.0,
                                                         "torque_nm": 50.0}})
    row = run_features(run, "F_2b1_loa", envelope=False)
    assert isinstance(row, FeatureRow) and row.bearing == "2b1"
    assert row.to_dict()["gmf3_amp"] == pytest.approx(5.0, rel=0.01)
    assert row.dominant_gmf_harmonic == 3
    assert "gmf1_sb_bpf_2b1_p1" in row.to_dict()
    with pytest.raises(TypeError):
        run_features(run, "F_2b1_loa", n_harmonic=3)


def test_sideband_energies_read_an_amplitude_modulation_and_ignore_a_small_wobble():
    """A carrier at each GMF harmonic amplitude-modulated at the shaft rate with index m:
    sidebands of m/2 each, so sb1 = 10·log10(m²/2) dB; the ±2, ±3 bands hold only the
    noise. A 0.2 % speed wobble at 1.3 Hz (it would smear the 5th harmonic over ±3.6 Hz,
    into the sideband bands) is tracked out: sb1 within 1.5 dB up to order 140. Beyond
    MAX_SIDEBAND_ORDER (150) no column is read."""
    fs, fr, z = 20000.0, 16.0, 28
    freqs = RigFrequencies(fr1_hz=fr, fr2_hz=fr * z / 40, gmf_hz=z * fr, bearings={})
    t = np.arange(int(0.5 * fs)) / fs
    rng = np.random.default_rng(3)
    m = {k: 0.02 * k for k in range(1, 9)}

    def signal(wobble):
        phase = 2 * np.pi * fr * (t - wobble / (2 * np.pi * 1.3) * np.cos(2 * np.pi * 1.3 * t))
        x = sum((1 + m[k] * np.cos(phase)) * np.cos(k * z * phase + rng.uniform(0, 6))
                for k in m)
        return x + 1e-4 * rng.standard_normal(t.size)

    clean, wobbly = (relative_features(signal(w), fs, freqs, []) for w in (0.0, 0.002))
    assert all(math.isnan(clean[f"sb1_fr1_k{k}_db"]) for k in (6, 7, 8))       # 168+ orders
    assert all(math.isnan(clean[f"sb1_fr2_k{k}_db"]) for k in (4, 5, 6, 7, 8))  # 160+
    for k in range(1, 6):
        expected = 10 * math.log10(m[k] ** 2 / 2)
        assert clean[f"sb1_fr1_k{k}_db"] == pytest.approx(expected, abs=0.3), k
        assert clean[f"sb23_fr1_k{k}_db"] < expected - 30, k
        assert wobbly[f"sb1_fr1_k{k}_db"] == pytest.approx(expected, abs=1.5), k



def test_band_families_stand_out_in_the_band_where_the_impacts_ring():
    """Impacts at the ball pass ringing an 8-kHz resonance, under white noise of their RMS and
    a 1.5-kHz noise band three times louder: the BPFO family stands out in the bank's bands
    holding 8 kHz and in no other, no other family does there, and the noise alone lifts no
    line anywhere."""
    from scipy.signal import butter, sosfilt

    from cmsim.discrepancy.evaluator import weight
    from cmsim.features import N_ENVELOPE_BANDS, band_column, band_family_columns
    from cmsim.features.envelope import band_bank

    brg, f, fs = _ball_pass_rig()
    n = int(0.5 * fs)
    rng = np.random.default_rng(3)
    wn = 2 * np.pi * 8000.0
    th = np.arange(int(0.02 * fs)) / fs
    ring = np.exp(-0.01 * wn * th) * np.sin(wn * th)
    hits = np.zeros(n)
    hits[np.round(np.arange(0.0, n / fs, 1.0 / brg.bpfo_hz) * fs).astype(int)] = 1.0
    impacts = np.convolve(hits, ring)[:n]
    hum = sosfilt(butter(4, (1200.0, 1800.0), "bandpass", fs=fs, output="sos"),
                  rng.standard_normal(n))
    noise = 3.0 * np.std(impacts) / np.std(hum) * hum + np.std(impacts) * rng.standard_normal(n)
    bf = {"DE": brg}
    spall = band_family_columns(impacts + noise, fs, f.fr1_hz, bf)
    healthy = band_family_columns(noise, fs, f.fr1_hz, bf)
    bands = band_bank(fs)
    assert len(bands) == N_ENVELOPE_BANDS
    assert len(spall) == N_ENVELOPE_BANDS * 3 and all(band_column(k) for k in spall)
    ringing = [j for j, (lo, hi) in enumerate(bands) if lo < 8000.0 < hi]
    assert ringing == [4, 5]
    for j in range(N_ENVELOPE_BANDS):
        bpfo = spall[f"env_bpfo_DE_h1_bb{j}_db"]
        if j in ringing:
            assert bpfo > 25.0, (j, bpfo)
            for fam in ("bpfi", "bsf2"):
                assert spall[f"env_{fam}_DE_h1_bb{j}_db"] < bpfo - 15.0, (j, fam)
        else:
            assert bpfo < 12.0, (j, bpfo)
    assert max(healthy.values()) < 12.0
    # they stand out against a baseline; the chi2 does not weigh them (where a structure
    # rings is not what a calibrated path knows)
    assert all(weight(k) == 0.0 for k in spall) and weight("env_bpfo_DE_h1_db") == 1.0
    # within a fault's own signature one line's six bands weigh one line
    assert sum(weight(f"env_bpfo_DE_h1_bb{j}_db", signature=True)
               for j in range(N_ENVELOPE_BANDS)) == pytest.approx(1.0)
    assert not band_column("sb1_fr1_k3_db") and not band_column("env_bpfo_DE_band_db")


def test_a_segment_is_the_nearest_length_with_a_fast_fft():
    """0.5 s at the common rates is 0.5 s; at SpectraQuest's 12904.6 Hz it is 6480 samples
    (6452 = 4 · 1613 has a large prime factor); every length is 2^a 3^b 5^c, the nearest to
    round(seg_s · fs) (the smaller on a tie), within 3.3 % of it."""
    from cmsim.features import segment_samples, segments
    for fs in (10_000.0, 12_000.0, 20_000.0, 25_600.0, 48_000.0, 51_200.0):
        assert segment_samples(fs, 0.5) == round(0.5 * fs)
    assert segment_samples(12_904.558781928758, 0.5) == 6480
    def smooth(m):
        for p in (2, 3, 5):
            while m % p == 0:
                m //= p
        return m == 1

    rng = np.random.default_rng(5)
    for fs in rng.uniform(1e3, 1e5, 200):
        n0, n = round(0.5 * fs), segment_samples(fs, 0.5)
        d = abs(n - n0)
        assert smooth(n) and d <= 0.033 * n0
        nearer = [c for c in range(n0 - d, n0 + d + 1)
                  if smooth(c) and (abs(c - n0) < d or (abs(c - n0) == d and c < n))]
        assert nearer == []
    spans = segments(64_000, 12_904.558781928758, 0.5)
    assert all(b - a == 6480 for a, b in spans) and len(spans) == 64_000 // 6480
