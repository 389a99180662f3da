"""The one line detector (:func:`cmsim.spectra.line_detector.detect_lines`).

Tier: closed form — a sinusoid in white noise reads its amplitude; the stronger of two
neighbouring lines claims the bins they share. Reference — the numba kernels make every
choice of the plain-Python loop they replaced (peaks strongest first, ties in frequency
order, each line's excess summed as numpy sums a slice), to the bit, on spectra whose lines
hold more than the 128 values numpy sums in one block.
"""

import math

import numpy as np
import pytest

from cmsim.spectra.floor import segment_psd
from cmsim.spectra.line_detector import LINE_TOLERANCE, detect_lines, median_floor


def _reference(freq, psd, min_db=6.0, half_width_hz=25.0, tolerance=LINE_TOLERANCE,
               max_lines=300, lowest_hz=2.0):
    """The detector as a plain Python loop (its lines, without the floor)."""
    df = float(freq[1] - freq[0])
    med = median_floor(freq, psd, half_width_hz)
    ratio, thr, n = psd / med, 10.0 ** (min_db / 10.0), psd.size
    peaks = [j for j in range(2, n - 2) if ratio[j] > thr and freq[j] >= lowest_hz
             and psd[j] >= psd[j - 1] and psd[j] >= psd[j + 1]]
    owner, spans = np.full(n, -1), []
    for i in sorted(peaks, key=lambda j: -psd[j]):
        if owner[i] >= 0:
            continue
        most = max(2, math.ceil(tolerance * freq[i] / df))
        lo = hi = i
        while lo - 1 >= 0 and owner[lo - 1] < 0 and i - lo + 1 <= most and (
                i - lo + 1 <= 2 or ratio[lo - 1] > thr):
            lo -= 1
        while hi + 1 < n and owner[hi + 1] < 0 and hi + 1 - i <= most and (
                hi + 1 - i <= 2 or ratio[hi + 1] > thr):
            hi += 1
        owner[lo:hi + 1] = len(spans)
        spans.append((i, slice(lo, hi + 1)))
    _, floor = detect_lines(freq, psd, min_db=min_db, half_width_hz=half_width_hz,
                            tolerance=tolerance, max_lines=max_lines, lowest_hz=lowest_hz)
    above = np.maximum(psd - floor, 0.0)
    lines = [(float(freq[i]), math.sqrt(2.0 * float(np.sum(above[b])) * df), b)
             for i, b in spans if float(np.sum(above[b])) * df > 0]
    lines.sort(key=lambda ln: -ln[1])
    return lines[:max_lines]


def test_a_sinusoid_in_white_noise_reads_its_amplitude():
    fs, n, amp = 8000.0, 8000, 0.5
    rng = np.random.default_rng(3)
    t = np.arange(20 * n) / fs
    x = amp * np.cos(2 * np.pi * 1234.0 * t) + 0.1 * rng.standard_normal(t.size)
    freq, psd = segment_psd(list(x.reshape(20, n)), fs)
    lines, floor = detect_lines(freq, psd)
    assert len(lines) == 1 and lines[0].frequency_hz == 1234.0
    assert lines[0].amplitude == pytest.approx(amp, rel=0.02)
    assert np.median(floor) == pytest.approx(2 * 0.1 ** 2 / fs, rel=0.05)


def test_the_stronger_of_two_neighbours_claims_the_bins_they_share():
    freq = np.arange(3001) * 1.0
    psd = np.ones(freq.size)
    psd[1000:1011] = 50.0                 # a wide line (its reach ±5 bins at 1 kHz)...
    psd[1004] = 1e4
    psd[1011] = 1e3                       # ...and a weaker one whose main lobe it reaches
    lines, _ = detect_lines(freq, psd)
    assert [ln.frequency_hz for ln in lines] == [1004.0, 1011.0]
    first, second = (ln.bins for ln in lines)
    assert (first.start, first.stop) == (1000, 1010)     # bin 1009 is the stronger's
    assert (second.start, second.stop) == (1010, 1014)


@pytest.mark.parametrize("fs, n, segments", [(12000.0, 6000, 8), (25600.0, 256000, 2)])
def test_the_kernels_make_every_choice_of_the_python_loop_to_the_bit(fs, n, segments):
    rng = np.random.default_rng(int(n))
    t = np.arange(n * segments) / fs
    x = rng.standard_normal(t.size)
    for fr in rng.uniform(10.0, 60.0, 10):        # combs of shaft orders, equal peaks too
        x += rng.uniform(0.01, 0.2) * np.cos(2 * np.pi * fr * np.arange(1, 40)[:, None]
                                             * t).sum(axis=0)
    freq, psd = segment_psd(list(x.reshape(segments, n)), fs)
    psd[::97] = psd[::97] * 50.0                  # lone bins, and plateaus of equal peaks
    mid = psd.size // 2
    psd[mid:mid + 6] = psd[mid:mid + 6].max()
    wide = int(0.8 * psd.size)                    # a line 200 bins wide (a long record's)
    psd[wide:wide + 200] = 100.0 * np.median(psd)
    lines, _ = detect_lines(freq, psd)
    want = _reference(freq, psd)
    assert len(lines) == len(want) > 50
    assert max(ln.bins.stop - ln.bins.start for ln in lines) > (128 if n > 10000 else 4)
    assert [(ln.frequency_hz, ln.amplitude, ln.bins) for ln in lines] == want
