"""Peak finding and labelling as k·GMF ± m·BPF ± n·fr and bearing defect families.

Test tier: closed form (an AM carrier A(1 + μ cos 2πf_m t) has sidebands of amplitude μA/2 at
f_c ± f_m, i.e. 20·log10(μ/2) dB re carrier; tones placed at known lattice points get the
corresponding indices).
"""

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.rig import OperatingPoint, Rig
from cmsim.spectra import (amplitude_spectrum, find_peaks, label_peaks, labelled_peaks,
                           rig_frequencies)

FS = 10_000.0
GMF, BPF, FR = 466.67, 60.6, 1000 / 60


def _tones(spec, seconds=2.0, noise=1e-3, seed=0):
    t = np.arange(int(FS * seconds)) / FS
    rng = np.random.default_rng(seed)
    x = noise * rng.standard_normal(t.size)
    for f, a in spec:
        x += a * np.sin(2 * np.pi * f * t + 0.3 * f)
    return t, x


def _row(df, label):
    rows = df[df["label"] == label]
    assert len(rows) == 1, f"{label!r} not found once in {list(df['label'])}"
    return rows.iloc[0]


def test_am_sidebands_are_labelled_with_indices_and_amplitude():
    t = np.arange(int(FS * 2.0)) / FS
    rng = np.random.default_rng(1)
    x = ((1 + 0.3 * np.cos(2 * np.pi * BPF * t)) * np.sin(2 * np.pi * GMF * t)
         + 0.4 * np.sin(2 * np.pi * 2 * GMF * t) + 1e-3 * rng.standard_normal(t.size))
    f, a = amplitude_spectrum(x, FS)
    df = label_peaks(f, a, {"GMF": GMF, "BPF": BPF, "fr": FR})
    assert list(df.columns[:10]) == ["frequency_hz", "amplitude", "db_re_carrier", "db_re_max",
                                     "snr_db", "label", "family", "k", "m", "n"]
    assert sorted(df["label"]) == sorted(["1GMF-1BPF", "1GMF", "1GMF+1BPF", "2GMF"])
    for label, m in (("1GMF+1BPF", 1), ("1GMF-1BPF", -1)):
        r = _row(df, label)
        assert (r["k"], r["m"], r["n"]) == (1, m, 0)
        assert r["family"] == "GMF"
        assert r["amplitude"] == pytest.approx(0.15, rel=0.01)
        assert r["db_re_carrier"] == pytest.approx(20 * np.log10(0.15), abs=0.1)
        assert abs(r["error_hz"]) <= f[1] - f[0]
    carrier = _row(df, "1GMF")
    assert carrier["amplitude"] == pytest.approx(1.0, rel=0.01)
    assert carrier["db_re_carrier"] == pytest.approx(0.0, abs=0.05)
    h2 = _row(df, "2GMF")
    assert (h2["k"], h2["m"], h2["n"]) == (2, 0, 0)
    assert h2["db_re_max"] == pytest.approx(20 * np.log10(0.4), abs=0.1)


def test_combination_and_unlabelled_peaks():
    fam = {"GMF": GMF, "BPF": BPF, "fr": FR}
    spec = [(GMF, 1.0), (3 * GMF, 0.5), (3 * GMF - BPF - 2 * FR, 0.05), (BPF - 3 * FR, 0.02),
            (2 * FR, 0.03), (777.7, 0.04)]
    t, x = _tones(spec)
    f, a = amplitude_spectrum(x, FS)
    df = label_peaks(f, a, fam)
    r = _row(df, "3GMF-1BPF-2fr")
    assert (r["k"], r["m"], r["n"], r["family"]) == (3, -1, -2, "GMF")
    assert r["db_re_carrier"] == pytest.approx(20 * np.log10(0.05 / 0.5), abs=0.1)
    r = _row(df, "1BPF-3fr")
    assert (r["k"], r["m"], r["n"], r["family"]) == (0, 1, -3, "BPF")
    r = _row(df, "2fr")
    assert (r["k"], r["m"], r["n"], r["family"]) == (0, 0, 2, "fr")
    unl = df[df["label"] == "?"]
    assert len(unl) == 1 and unl.iloc[0]["family"] == "unlabelled"
    assert unl.iloc[0]["frequency_hz"] == pytest.approx(777.7, abs=f[1])
    assert np.isnan(unl.iloc[0]["expected_hz"])
    assert len(df) == len(spec)


def test_bearing_defect_families():
    fam = {"fr": 29.95, "BPFO": 107.36, "BPFI": 162.19, "BSF": 70.58, "FTF": 11.93}
    spec = [(162.19, 1.0), (162.19 + 29.95, 0.3), (162.19 - 29.95, 0.3), (2 * 70.58, 0.2),
            (70.58 + 11.93, 0.1), (107.36, 0.5), (2 * 107.36, 0.25)]
    t, x = _tones(spec, seconds=4.0)
    f, a = amplitude_spectrum(x, FS)
    df = label_peaks(f, a, fam)
    assert sorted(df["label"]) == sorted(["1BPFI", "1BPFI+1fr", "1BPFI-1fr", "2BSF",
                                          "1BSF+1FTF", "1BPFO", "2BPFO"])
    r = _row(df, "1BPFI-1fr")
    assert (r["k"], r["m"], r["n"], r["family"]) == (1, 0, -1, "BPFI")
    assert r["db_re_carrier"] == pytest.approx(20 * np.log10(0.3), abs=0.1)
    assert _row(df, "1BSF+1FTF")["family"] == "BSF"


def test_ties_go_to_the_template_order_and_fewer_sidebands():
    # BPF == BPFO (fixed outer ring): the line reads as the model's ball-pass frequency
    fam = {"GMF": GMF, "BPF": BPF, "fr": FR, "BPFO": BPF}
    t, x = _tones([(BPF, 1.0), (GMF, 1.0)])
    f, a = amplitude_spectrum(x, FS)
    df = label_peaks(f, a, fam)
    assert set(df["label"]) == {"1BPF", "1GMF"}
    assert _row(df, "1BPF")["family"] == "BPF"


def test_tolerance_and_max_sideband_limit_matches():
    fam = {"GMF": GMF, "BPF": BPF, "fr": FR}
    t, x = _tones([(GMF, 1.0), (GMF + 4 * FR, 0.1), (GMF + 3.0, 0.1)])
    f, a = amplitude_spectrum(x, FS)
    df = label_peaks(f, a, fam)
    assert "?" in set(df["label"])                          # 4fr > max_sideband = 3
    assert _row(label_peaks(f, a, fam, max_sideband=4), "1GMF+4fr")["n"] == 4
    wide = label_peaks(f, a, fam, tolerance_hz=5.0)
    assert "1GMF" in set(wide["label"]) and "?" not in set(
        wide.loc[wide["frequency_hz"] < GMF + 10, "label"])


def test_find_peaks_on_noise_floor():
    rng = np.random.default_rng(7)
    x = rng.standard_normal(20_000)
    f, a = amplitude_spectrum(x, FS)
    assert len(find_peaks(f, a)) <= 2                       # 15 dB above a running median
    t, y = _tones([(1000.0, 0.3)], noise=1.0)             # ≈ 22 dB above the median bin
    f, a = amplitude_spectrum(y, FS)
    pk = find_peaks(f, a)
    hit = pk[np.abs(pk["frequency_hz"] - 1000.0) < 1.0]
    assert len(hit) == 1
    assert hit.iloc[0]["amplitude"] == pytest.approx(0.3, rel=0.15)
    median_noise = np.median(a[1:])
    assert hit.iloc[0]["floor"] == pytest.approx(median_noise, rel=0.3)
    assert len(find_peaks(f, a, max_peaks=1)) == 1


def test_labelled_peaks_for_paper_rig_amplitude_and_order():
    freqs = rig_frequencies(Rig.paper_2016(), OperatingPoint(speed_rpm=1000.0))
    gmf, bpf = freqs["gmf_hz"], freqs["1b1"]["bpf_hz"]
    t = np.arange(int(FS * 3.0)) / FS
    x = ((1 + 0.2 * np.cos(2 * np.pi * bpf * t)) * np.sin(2 * np.pi * gmf * t)
         + 0.3 * np.sin(2 * np.pi * 2 * gmf * t))
    df = labelled_peaks(x, FS, freqs, kind="amplitude")
    assert {"1GMF", "1GMF+1BPF", "1GMF-1BPF", "2GMF"} <= set(df["label"])
    assert _row(df, "1GMF+1BPF")["amplitude"] == pytest.approx(0.1, rel=0.01)
    do = labelled_peaks(x, FS, freqs, kind="order")
    r = _row(do, "1GMF-1BPF")
    assert r["order"] == pytest.approx(28 - 3.6342, abs=0.02)
    assert "frequency_hz" not in do.columns


def test_labelled_peaks_envelope_finds_bpfo():
    fam = {"fr": 29.95, "BPFO": 107.36, "BPFI": 162.19}
    t = np.arange(int(20_000 * 2.0)) / 20_000.0
    carrier = np.sin(2 * np.pi * 3000.0 * t)
    x = (1 + 0.5 * np.cos(2 * np.pi * 107.36 * t)) * carrier
    df = labelled_peaks(x, 20_000.0, fam, kind="envelope", band_hz=(2000.0, 4000.0))
    r = _row(df, "1BPFO")
    assert r["amplitude"] == pytest.approx(0.5, rel=0.02)
    # impacts at BPFO ringing a 3 kHz resonance: the kurtogram chooses the band
    wn = 2 * np.pi * 3000.0
    th = np.arange(200) / 20_000.0
    h = np.exp(-0.05 * wn * th) * np.sin(wn * th)
    hits = np.zeros(t.size)
    hits[np.round(np.arange(0.0, 2.0, 1 / 107.36) * 20_000).astype(int)] = 1.0
    rng = np.random.default_rng(4)
    y = np.convolve(hits, h)[: t.size] + 0.05 * rng.standard_normal(t.size)
    auto = labelled_peaks(y, 20_000.0, fam, kind="envelope")
    top = auto.sort_values("amplitude").iloc[-1]
    assert top["label"] == "1BPFO"
    assert {"2BPFO", "3BPFO"} <= set(auto["label"])


@pytest.mark.parametrize("call, name", [
    (lambda f, a: label_peaks(f, a, {"GMX": 100.0}), "families"),
    (lambda f, a: label_peaks(f, a, {"GMF": -100.0}), "families"),
    (lambda f, a: label_peaks(f, a, {}), "families"),
    (lambda f, a: label_peaks(f, a, {"GMF": 100.0}, tolerance_hz=0.0), "tolerance_hz"),
    (lambda f, a: label_peaks(f, a, {"GMF": 100.0}, max_sideband=-1), "max_sideband"),
    (lambda f, a: label_peaks(f, -a, {"GMF": 100.0}), "amp"),
    (lambda f, a: label_peaks(f[::-1], a, {"GMF": 100.0}), "freq"),
    (lambda f, a: find_peaks(f, a, threshold_db=0.0), "threshold_db"),
    (lambda f, a: labelled_peaks(np.ones(1000), 1000.0, {"GMF": 100.0}, kind="cepstrum"),
     "kind"),
    (lambda f, a: labelled_peaks(np.ones(1000), 1000.0, {"GMF": 100.0}, kind="order"), "fr"),
])
def test_bad_inputs_name_the_parameter(call, name):
    f, a = amplitude_spectrum(np.sin(np.arange(1000) * 0.3), 1000.0)
    with pytest.raises(ParameterError, match=name):
        call(f, a)


def test_a_simple_label_slightly_off_beats_a_complex_exact_one():
    """GMF 100 Hz, BPF 33 Hz, fr 10 Hz, a line at 199 Hz, tolerance 1.5 Hz: 2GMF (1 Hz off,
    |k|+|m|+|n| = 2) and 1GMF+3BPF (exact, 4) both fit; the simpler one names the line. With
    a 0.5 Hz tolerance only 1GMF+3BPF fits, so that label is reachable and the rule, not the
    lattice, decides."""
    fs, seconds = 2000.0, 8.0
    t = np.arange(int(fs * seconds)) / fs
    f, a = amplitude_spectrum(np.sin(2 * np.pi * 199.0 * t), fs)
    fam = {"GMF": 100.0, "BPF": 33.0, "fr": 10.0}
    wide = label_peaks(f, a, fam, tolerance_hz=1.5)
    r = _row(wide, "2GMF")
    assert (r["k"], r["m"], r["n"]) == (2, 0, 0)
    assert r["error_hz"] == pytest.approx(-1.0, abs=0.05)
    narrow = label_peaks(f, a, fam, tolerance_hz=0.5)
    assert (_row(narrow, "1GMF+3BPF")["k"], _row(narrow, "1GMF+3BPF")["m"]) == (1, 3)


def test_one_speed_factor_names_high_mesh_sidebands_on_their_own_lattice_point():
    """A gearbox 0.4 % faster than its nominal speed (GMF 960 Hz, fr 30 Hz): its lines sit at
    1.004 × the lattice. With the speed known to 0.5 %, a window of 0.005·f at each line
    (24 Hz at 4.8 kHz) reaches the next sideband, 30 Hz away, and the simplest label in it
    would win (5GMF−2fr read as 5GMF−1fr); one factor for every line puts each peak on its
    own point, and the factor is read back."""
    fs, seconds, true = 12_000.0, 4.0, 1.004
    fam = {"GMF": 960.0, "fr": 30.0}
    lines = [(1, 0), (1, -1), (1, 1), (2, 0), (3, 0), (3, 2), (4, 0), (4, -3), (5, 0),
             (5, -2), (5, 1), (5, 3)]
    t = np.arange(int(fs * seconds)) / fs
    x = sum((1.0 if n == 0 else 0.4) * np.sin(2 * np.pi * true * (k * 960.0 + n * 30.0) * t
                                             + k + n) for k, n in lines)
    f, a = amplitude_spectrum(x, fs, window="flattop")
    df = label_peaks(f, a, fam, relative_tolerance=0.005)
    named = {(int(r.k), int(r.n)) for r in df.itertuples() if r.label != "?"}
    assert named == set(lines)
    assert df.attrs["speed_scale"] == pytest.approx(true, abs=2e-5)
    assert np.nanmax(np.abs(df["error_hz"])) < f[1]
    each = label_peaks(f, a, fam, relative_tolerance=0.005, max_harmonic=5)
    assert set(each["label"]) == set(df["label"])
    # the old rule, a window of 0.005·f at each line, names 5GMF-2fr after 5GMF-1fr: the
    # same spectrum without the factor search fails the check above
    row = df[np.isclose(df["frequency_hz"], true * 4740.0, atol=0.5)].iloc[0]
    assert row["label"] == "5GMF-2fr"


def test_slip_widens_the_bearing_terms_only():
    """A BPFO line 1 % below its nominal (the balls slip) is named with a 1.5 % slip
    tolerance; a line 1 % off the mesh frequency is not (a mesh line does not slip; no
    bearing label lies within its slip of 495 Hz)."""
    fs, seconds = 4000.0, 8.0
    fam = {"GMF": 500.0, "BPFO": 89.8, "fr": 29.95}
    t = np.arange(int(fs * seconds)) / fs
    x = np.sin(2 * np.pi * 0.99 * 89.8 * t) + np.sin(2 * np.pi * 0.99 * 500.0 * t)
    f, a = amplitude_spectrum(x, fs, window="flattop")
    df = label_peaks(f, a, fam, slip_tolerance=0.015)
    assert list(df["label"]) == ["1BPFO", "?"]
    assert df.attrs["speed_scale"] == 1.0


def test_a_slipping_familys_harmonics_are_read_on_its_own_fundamental():
    """An outer race's envelope lines 1.2 % under the nominal BPFO, speed known to 3 %, slip
    1 %: in windows of 4 % the BPFI lattice (1.465 × BPFO) holds the high harmonics with a
    simpler label (10·BPFO read 7BPFI); the family's factor, read from its fundamental and
    harmonics, names every line k·BPFO."""
    fs, seconds = 4000.0, 3.0
    fam = {"fr": 25.0, "BPFO": 81.12, "BPFI": 118.88}
    t = np.arange(int(fs * seconds)) / fs
    bpfo = 0.988 * 81.12
    x = sum(np.sin(2 * np.pi * k * bpfo * t + k) / k ** 0.5 for k in range(1, 11))
    f, a = amplitude_spectrum(x, fs, window="flattop")
    df = label_peaks(f, a, fam, relative_tolerance=0.03, slip_tolerance=0.01)
    assert list(df.sort_values("frequency_hz")["label"]) == [f"{k}BPFO" for k in range(1, 11)]
    assert df.attrs["families_read"] == ["BPFO"]
    assert df.attrs["families"]["BPFO"] == pytest.approx(bpfo, rel=2e-4)


def test_the_other_gear_shafts_sidebands_are_named():
    """A 32:80 gearbox (fr 30 Hz, fr2 12 Hz): the output gear modulates the mesh at its own
    shaft's rate, 12 Hz, which no multiple of the input's 30 Hz reaches."""
    fs, seconds = 4000.0, 4.0
    fam = {"GMF": 960.0, "fr": 30.0, "fr2": 12.0}
    lines = {960.0: "1GMF", 948.0: "1GMF-1fr2", 972.0: "1GMF+1fr2", 984.0: "1GMF+2fr2",
             990.0: "1GMF+1fr", 12.0: "1fr2", 48.0: "4fr2"}
    t = np.arange(int(fs * seconds)) / fs
    x = sum(np.sin(2 * np.pi * f * t + f) for f in lines)
    f, a = amplitude_spectrum(x, fs, window="flattop")
    df = label_peaks(f, a, fam)
    got = {round(r.frequency_hz): r.label for r in df.itertuples()}
    assert got == {round(k): v for k, v in lines.items()}
