"""A cause's change laid on a machine's baseline (cmsim.machine.change).

Tier (a) closed form: a machine with a flat path and a white background, baseline segments of
white noise and known lines, forces made of known sinusoids. What the model adds arrives
through the path's gain, in power, on the baseline's level; what it takes away is taken from
the baseline's own line in proportion (the path cancels); noise, rotating forces and a speed
fluctuation add what their closed forms say; a change with nothing in it is no change.
"""

import itertools
from dataclasses import replace
import math

import numpy as np
import pytest
from scipy.special import jv

from cmsim.machine import Background, Machine, TransferPath
from cmsim.machine.change import (SHARED_LINE_DB, Change, _notch_lines, _scale_lines,
                                  apply_change, warp_speed)
from cmsim.rig import OperatingPoint, Rig
from cmsim.spectra.floor import segment_psd

FS = 4096.0
N = 4096                      # 1-s segments: 1-Hz bins
K = 8
GAIN = 0.5                    # flat path, sensor unit per N
NOISE = 1e-4                  # white background PSD, unit²/Hz
SHAFT_HZ = 25.0


@pytest.fixture(scope="module")
def machine():
    rig = Rig.paper_2016()
    f = (0.0, FS / 2)
    return Machine(name="flat", rig=rig, channel="acc", model_signal="accel_1b1_y",
                   fs_hz=FS, op=OperatingPoint(60.0 * SHAFT_HZ, 50.0),
                   path=TransferPath("F_1b1_y", f, (GAIN, GAIN)),
                   background=Background(f, (NOISE, NOISE)), shaft_gain={1: 2.0})


def _baseline(rng, lines=()):
    t = np.arange(N) / FS
    segs = rng.standard_normal((K, N)) * math.sqrt(NOISE * FS / 2)
    for f0, a in lines:
        segs += a * np.cos(2 * np.pi * f0 * t + rng.uniform(0, 2 * np.pi, (K, 1)))
    return segs


def _power(segs, f0, half=3):
    """Power of the PSD's bins within ± half of ``f0`` (unit²)."""
    freq, psd = segment_psd(list(segs), FS)
    sel = np.abs(freq - f0) <= half
    return float(psd[sel].sum() * (freq[1] - freq[0]))


def _forces(rng, healthy_lines, cause_lines, edge=256):
    t = (np.arange(K * N + 2 * edge) - edge) / FS
    noise = 1e-3 * rng.standard_normal(t.size)            # a common broadband, same seed
    h = noise + sum(a * np.cos(2 * np.pi * f0 * t) for f0, a in healthy_lines)
    c = noise + sum(a * np.cos(2 * np.pi * f0 * t) for f0, a in cause_lines)
    return h, c, edge


def test_a_change_with_nothing_in_it_is_the_baseline(machine):
    segs = _baseline(np.random.default_rng(1), [(300.0, 0.05)])
    out = apply_change(machine, segs, Change(), np.random.default_rng(2))
    assert np.allclose(out, segs, rtol=0, atol=1e-12)


def test_what_the_model_adds_arrives_through_the_path_gain(machine):
    """A line at 700 Hz the cause makes (2 N) and the healthy model does not: the baseline
    gains a line of G·2 N = 1.0 (power 0.5) there."""
    rng = np.random.default_rng(3)
    segs = _baseline(rng)
    h, c, edge = _forces(rng, [(300.0, 1.0)], [(300.0, 1.0), (700.0, 2.0)])
    out = apply_change(machine, segs, Change(force=c, healthy=h, edge=edge), rng)
    added = _power(out, 700.0) - _power(segs, 700.0)
    assert added == pytest.approx(0.5 * (GAIN * 2.0) ** 2, rel=0.1)


def test_what_the_model_takes_away_leaves_the_baseline_s_line_in_proportion(machine):
    """A healthy model line at 300 Hz halved by the cause (power ×1/4); the baseline shows
    its own line there at another level (0.2, not G·1 N = 0.5): the baseline's line excess
    falls to a quarter, whatever the path's gain (the path cancels)."""
    rng = np.random.default_rng(5)
    segs = _baseline(rng, [(300.0, 0.2)])
    h, c, edge = _forces(rng, [(300.0, 1.0)], [(300.0, 0.5)])
    out = apply_change(machine, segs, Change(force=c, healthy=h, edge=edge), rng)
    floor = NOISE * 7                                       # 7 bins of the white floor
    before, after = _power(segs, 300.0) - floor, _power(out, 300.0) - floor
    assert after / before == pytest.approx(0.25, rel=0.1)


def test_a_line_the_baseline_never_showed_is_not_taken_away(machine):
    """The same halving where the baseline has no line: its bins there are its noise, which
    no cause removes."""
    rng = np.random.default_rng(7)
    segs = _baseline(rng)
    h, c, edge = _forces(rng, [(300.0, 1.0)], [(300.0, 0.5)])
    out = apply_change(machine, segs, Change(force=c, healthy=h, edge=edge), rng)
    assert _power(out, 300.0) == pytest.approx(_power(segs, 300.0), rel=0.01)   # not 1/4


def test_white_noise_adds_its_density(machine):
    """White noise of 3 times the background's RMS: the PSD grows by 9 times the
    background's density."""
    rng = np.random.default_rng(9)
    segs = _baseline(rng)
    out = apply_change(machine, segs, Change(white_noise=3.0), rng)
    _, p0 = segment_psd(list(segs), FS)
    _, p1 = segment_psd(list(out), FS)
    assert float(np.mean(p1 - p0)) == pytest.approx(9.0 * NOISE, rel=0.05)


def test_a_rotating_force_adds_its_power_through_the_shaft_gain(machine):
    """A 0.3-N force at 1× through the machine's gain there (2 per N): a line of amplitude
    0.6 (power 0.18) added to the baseline's own 1× line (0.1, power 0.005)."""
    rng = np.random.default_rng(11)
    segs = _baseline(rng, [(SHAFT_HZ, 0.1)])
    out = apply_change(machine, segs, Change(rotating=((1, 0.3, 0.0),), shaft_hz=SHAFT_HZ),
                       rng)
    assert _power(out, SHAFT_HZ, 1) - _power(segs, SHAFT_HZ, 1) == pytest.approx(
        0.5 * (2.0 * 0.3) ** 2, rel=0.05)


def test_a_speed_fluctuation_modulates_the_baseline_s_lines():
    """A 400-Hz tone read at a speed fluctuating by a = 0.5 % at 10 Hz: phase modulated with
    index β = a·f0/f = 0.2; the first sidebands stand J1(β)/J0(β) of the carrier."""
    t = np.arange(N) / FS
    x = np.cos(2 * np.pi * 400.0 * t)
    y = warp_speed(x, FS, 0.005, 10.0, 0.3)
    spec = np.abs(np.fft.rfft(y * np.hanning(N)))
    freq = np.fft.rfftfreq(N, 1 / FS)
    amp = {f: spec[np.argmin(np.abs(freq - f))] for f in (390.0, 400.0, 410.0)}
    beta = 0.005 * 400.0 / 10.0
    want = jv(1, beta) / jv(0, beta)
    assert amp[410.0] / amp[400.0] == pytest.approx(want, rel=0.05)
    assert amp[390.0] / amp[400.0] == pytest.approx(want, rel=0.05)


def test_forces_of_another_length_are_refused(machine):
    from cmsim.errors import ParameterError

    with pytest.raises(ParameterError, match="same length"):
        Change(force=np.zeros(10), healthy=np.zeros(11))
    with pytest.raises(ParameterError, match="hold"):
        apply_change(machine, np.zeros((2, 64)), Change(force=np.zeros(10),
                                                        healthy=np.zeros(10)),
                     np.random.default_rng(0))


def _resonant(rng, f0, line_hz, line_amp):
    """Segments of white noise through a resonance at ``f0`` (Q = 10) over a white floor
    40 dB under its peak, plus a line at ``line_hz`` that does not pass the resonance."""
    from scipy.signal import iirpeak, lfilter

    b, a = iirpeak(f0, 10.0, fs=FS)
    x = lfilter(b, a, rng.standard_normal(K * N + 4096))[4096:].reshape(K, N)
    x += 0.01 * rng.standard_normal((K, N))
    t = np.arange(N) / FS
    return x + line_amp * np.cos(2 * np.pi * line_hz * t + rng.uniform(0, 2 * np.pi, (K, 1)))


def _bands_db(segs, edges):
    freq, psd = segment_psd(list(segs), FS)
    return np.array([10 * np.log10(psd[(freq >= lo) & (freq < hi)].sum())
                     for lo, hi in itertools.pairwise(edges)])


def test_a_moved_structure_read_from_the_baseline_s_floor_moves_its_resonance(machine):
    """A resonance at 800 Hz moving to 960 Hz (a = 1.2), a line at 300 Hz reaching the sensor
    another way. Read from the baseline's floor with the lines held, the refiltered baseline
    has the record's spectrum within 2 dB in every sixth-octave band from 400 Hz to 1.6 kHz
    (1.3 dB at most; the record is 10 dB over the baseline around 960 Hz and under it around
    800), and the line keeps its level. The
    machine's calibrated path is flat: read from it, nothing moves; with the lines following
    the floor, the line on the resonance's skirt drops with it."""
    edges = 400.0 * 2.0 ** (np.arange(13) / 6.0)
    segs = _resonant(np.random.default_rng(21), 800.0, 300.0, 0.5)
    record = _resonant(np.random.default_rng(22), 960.0, 300.0, 0.5)
    moved = apply_change(machine, segs, Change(frequency_factor=1.2, structure="floor",
                                               lines_follow_path=False),
                         np.random.default_rng(3))
    want = _bands_db(record, edges)
    got = _bands_db(moved, edges)
    assert np.max(np.abs(got - want)) < 2.0
    assert np.max(want - _bands_db(segs, edges)) > 8.0        # the change it reproduces
    assert _power(moved, 300.0) == pytest.approx(_power(segs, 300.0), rel=0.02)
    flat = apply_change(machine, segs, Change(frequency_factor=1.2),
                        np.random.default_rng(3))
    assert np.max(np.abs(_bands_db(flat, edges) - _bands_db(segs, edges))) < 0.1
    follow = apply_change(machine, segs, Change(frequency_factor=1.2, structure="floor"),
                          np.random.default_rng(3))
    assert 10 * math.log10(_power(segs, 300.0) / _power(follow, 300.0)) > 1.0


def test_a_change_s_structure_is_checked(machine):
    from cmsim.errors import ParameterError

    with pytest.raises(ParameterError, match="structure"):
        Change(frequency_factor=1.2, structure="housing")


def test_a_mesh_harmonic_s_smeared_hump_is_no_part_of_the_structure_read_from_the_floor(machine):
    """A hump of noise 100 Hz wide at a mesh harmonic (1.5 kHz: a gear's sidebands smeared
    by the speed's wobble, which the floor's running median reads as broadband) far over the
    resonance's skirt. Read from the floor with the lines held and the mesh harmonic known,
    the hump keeps its power and the resonance at 800 Hz still moves to 960 Hz as the record
    has it (within 2 dB from 400 Hz to 1.6 kHz); with no mesh harmonic known the hump is
    read as the structure and moved: it loses more than 3 dB."""
    from scipy.signal import butter, sosfilt

    def with_hump(segs, rng):
        sos = butter(4, (1450.0, 1550.0), "bandpass", fs=FS, output="sos")
        hump = sosfilt(sos, rng.standard_normal(K * N + 4096))[4096:].reshape(K, N)
        return segs + 3.0 * hump

    edges = 400.0 * 2.0 ** (np.arange(13) / 6.0)
    segs = with_hump(_resonant(np.random.default_rng(31), 800.0, 300.0, 0.5),
                     np.random.default_rng(41))
    record = with_hump(_resonant(np.random.default_rng(32), 960.0, 300.0, 0.5),
                       np.random.default_rng(42))
    change = Change(frequency_factor=1.2, structure="floor", lines_follow_path=False,
                    pin_hz=(1500.0,), shaft_hz=SHAFT_HZ, input_hz=SHAFT_HZ)
    moved = apply_change(machine, segs, change, np.random.default_rng(3))
    assert np.max(np.abs(_bands_db(moved, edges) - _bands_db(record, edges))) < 2.0
    assert _power(moved, 1500.0, 100) == pytest.approx(_power(segs, 1500.0, 100), rel=0.05)
    blind = apply_change(machine, segs, replace(change, pin_hz=()), np.random.default_rng(3))
    assert 10 * math.log10(_power(segs, 1500.0, 100) / _power(blind, 1500.0, 100)) > 3.0


def _scale_lines_loop(scale, spans, psd_h, psd_c, psd_b, floor_b, gain2):
    """The model's lines laid on the baseline's, one line at a time (the module docstring's
    rule as first written)."""
    for b in spans:
        p_h, p_c = float(psd_h[b].sum()), float(psd_c[b].sum())
        p_b, f_b = float(psd_b[b].sum()), float(floor_b[b].sum())
        if p_b <= 0.0 or p_h <= 0.0:
            continue
        g2 = float(np.mean(gain2[b]))
        if p_c >= p_h:
            target = p_b + g2 * (p_c - p_h)
        elif p_b - f_b >= (10.0 ** (SHARED_LINE_DB / 10.0) - 1.0) * f_b:
            share = min(1.0, g2 * p_h / (p_b - f_b))
            target = f_b + (p_b - f_b) * (1.0 - share * (1.0 - p_c / p_h))
        else:
            continue
        scale[b] *= math.sqrt(target / p_b)


def _notch_loop(notch, f_long, df_long, freq, df, spans):
    for bins in spans:
        lo, hi = freq[bins.start] - 0.5 * df, freq[bins.stop - 1] + 0.5 * df
        near = slice(max(int((lo - df) / df_long), 0),
                     min(int((hi + df) / df_long) + 2, f_long.size))
        edge_w = np.clip(np.maximum(lo - f_long[near], f_long[near] - hi) / df, 0.0, 1.0)
        notch[near] = np.minimum(notch[near], 0.5 - 0.5 * np.cos(np.pi * edge_w))


def test_the_lines_are_laid_and_notched_all_at_once_as_one_at_a_time():
    """Every line of the healthy model at once, to the bit what the loop over them made:
    lines the model adds to, lines it weakens that the baseline shows or never showed, lines
    over an empty baseline; notches overlapping each other and the spectrum's ends."""
    rng = np.random.default_rng(11)
    freq = np.arange(2049) * 2.0
    widths = rng.integers(5, 30, 60)                        # disjoint, some touching
    starts = 1 + np.concatenate([[0], np.cumsum(widths + rng.integers(0, 4, 60))[:-1]])
    spans = [slice(int(s), int(s + w)) for s, w in zip(starts, widths)
             if s + w <= freq.size - 3]
    spans.append(slice(freq.size - 3, freq.size))           # at the top end
    rng.shuffle(spans)                                      # in no order of frequency
    psd_h = rng.lognormal(0.0, 1.0, freq.size)
    psd_c = psd_h * rng.choice([0.3, 0.9, 1.0, 2.0], freq.size)
    floor_b = rng.lognormal(-1.0, 0.3, freq.size)
    psd_b = floor_b * rng.choice([1.0, 3.0, 30.0], freq.size)
    psd_b[spans[3]] = 0.0                                    # a baseline with nothing there
    gain2 = rng.lognormal(0.0, 0.5, freq.size)
    got = rng.lognormal(0.0, 0.1, freq.size)
    want, before = got.copy(), got.copy()
    _scale_lines(got, spans, psd_h, psd_c, psd_b, floor_b, gain2)
    _scale_lines_loop(want, spans, psd_h, psd_c, psd_b, floor_b, gain2)
    assert np.array_equal(got, want) and np.sum(got != before) > 500
    f_long = np.fft.rfftfreq(8 * 4096 + 200, 1.0 / 4096.0)
    got, want = np.ones(f_long.size), np.ones(f_long.size)
    _notch_lines(got, f_long, f_long[1], freq, 2.0, spans)
    _notch_loop(want, f_long, f_long[1], freq, 2.0, spans)
    assert np.array_equal(got, want) and np.sum(got < 1.0) > 1000


def test_an_order_the_baseline_does_not_pin_takes_the_path_s_shape_at_its_pinned_level():
    """A path whose gain rises as f² (0.01 at 25 Hz, 0.04 at 50, 0.09 at 75), the 2× order
    pinned at 2 per N (50 times the path there): 1× and 3× read the path's shape at that
    level (0.5 and 4.5), an order as near to 2× and 4× the lower's (2× for 3×); unpinned
    everywhere, the path's own."""
    f = np.array([0.0, 25.0, 50.0, 75.0, 100.0, FS / 2])
    path = TransferPath("F_1b1_y", tuple(f), tuple(np.maximum(0.01 * (f / 25.0) ** 2, 1e-4)))
    m = Machine(name="f2", rig=Rig.paper_2016(), channel="acc", model_signal="accel_1b1_y",
                fs_hz=FS, op=OperatingPoint(60.0 * SHAFT_HZ, 50.0), path=path,
                background=Background((0.0, FS / 2), (NOISE, NOISE)), shaft_gain={2: 2.0})
    assert m.rotating_gain(2, SHAFT_HZ) == 2.0
    assert m.rotating_gain(1, SHAFT_HZ) == pytest.approx(0.5, rel=1e-6)
    assert m.rotating_gain(3, SHAFT_HZ) == pytest.approx(4.5, rel=1e-6)
    both = replace(m, shaft_gain={2: 2.0, 4: 1.6})         # 4× pinned at 10 times the path
    assert both.rotating_gain(3, SHAFT_HZ) == pytest.approx(4.5, rel=1e-6)
    assert replace(m, shaft_gain={}).rotating_gain(3, SHAFT_HZ) == pytest.approx(0.09,
                                                                                rel=1e-6)
