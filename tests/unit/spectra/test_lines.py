"""THE line rule's window: every bin within the tolerance and half-width of the line.

Test tier: closed form — the window of a line at f with relative tolerance t holds exactly
the bins within t·f + 1.5 bins of f (its definition as a mask over every bin); a line's
amplitude is the largest bin there; a line outside the spectrum has no window.
"""

import math

import numpy as np
import pytest

from cmsim.spectra.lines import (EXACT_TOLERANCE, LINE_HALF_WIDTH_BINS, SLIP_TOLERANCE,
                                 line_amplitude, line_window)


@pytest.mark.parametrize("n, fs", [(1000, 12_000.0), (1001, 20_000.0), (6000, 25_600.0)])
def test_the_window_is_every_bin_within_the_tolerance_and_half_width(n, fs):
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    amp = np.random.default_rng(n).random(freq.size)
    df = freq[1]
    rng = np.random.default_rng(7)
    # random frequencies, and lines whose window edge falls exactly on a bin
    lines = list(rng.uniform(-10.0, fs / 2 + 50.0, 400))
    lines += [freq[i] + LINE_HALF_WIDTH_BINS * df for i in rng.integers(0, freq.size, 50)]
    lines += [freq[i] - LINE_HALF_WIDTH_BINS * df for i in rng.integers(0, freq.size, 50)]
    for f0 in lines:
        for tol in (0.0, 0.02):
            half = tol * f0 + LINE_HALF_WIDTH_BINS * df
            mask = (freq >= f0 - half) & (freq <= f0 + half)
            got = line_window(freq, f0, tol)
            if f0 <= 0.0 or not mask.any():
                assert got is None
                assert math.isnan(line_amplitude(freq, amp, f0, tol))
                continue
            np.testing.assert_array_equal(got, mask)
            assert line_amplitude(freq, amp, f0, tol) == amp[mask].max()


def test_a_line_s_amplitude_over_several_spectra_at_once():
    freq = np.arange(0.0, 100.0, 1.0)
    amp = np.zeros((3, freq.size))
    amp[:, 40] = [1.0, 2.0, 3.0]
    np.testing.assert_array_equal(line_amplitude(freq, amp, 40.5), [1.0, 2.0, 3.0])
    assert np.isnan(line_amplitude(freq, amp, 500.0)).all()


@pytest.mark.parametrize("tolerance", [EXACT_TOLERANCE, SLIP_TOLERANCE, 0.1])
def test_many_lines_at_once_read_what_each_reads_alone(tolerance):
    """A feature row's lines are read in one call; each is the one line rule's reading, to
    the bit, including lines past either end of the spectrum, at 0 Hz, negative or NaN."""
    from cmsim.spectra.lines import line_amplitudes_at

    rng = np.random.default_rng(7)
    freq = np.arange(3241) * 2.0
    amp = rng.exponential(size=freq.size)
    f = np.concatenate([rng.uniform(-50.0, freq[-1] + 50.0, 400),
                        [0.0, -3.0, np.nan, np.inf, freq[-1], freq[-1] + 2.9, 1.0]])
    want = [line_amplitude(freq, amp, v, tolerance) for v in f]
    got = line_amplitudes_at(freq, amp, f, tolerance)
    assert np.array_equal(got, np.array(want), equal_nan=True)
    assert np.isnan(got[-7:-3]).all() and not np.isnan(got[-3:]).any()
