"""The segment PSD and the running-median floor shared by calibration and the path-free
comparison.

Tier: closed form — white noise reads its density; a line drops out of the floor; the
edge mode decides whether a strong DC bin leaks into the floor's first bins.
"""

import numpy as np
import pytest

from cmsim.spectra.floor import median_window_bins, running_median_floor, segment_psd

FS = 8000.0


def test_white_noise_reads_its_one_sided_density():
    rng = np.random.default_rng(1)
    sigma = 0.3
    segs = [sigma * rng.standard_normal(4000) for _ in range(20)]
    freq, psd = segment_psd(segs, FS)
    assert freq[1] == pytest.approx(FS / 4000)
    assert np.mean(psd[1:-1]) == pytest.approx(2 * sigma ** 2 / FS, rel=0.03)


def test_a_line_drops_out_of_the_floor():
    freq = np.arange(2001) * 2.0
    psd = np.ones(freq.size)
    psd[1000] = 1e6
    floor = running_median_floor(freq, psd, 25.0)
    assert median_window_bins(freq, 25.0) == 25
    assert np.all(floor == 1.0)


@pytest.mark.parametrize("mode, first", [("mirror", 1.0), ("nearest", 1e6)])
def test_the_edge_mode_decides_whether_the_dc_bin_fills_the_first_window(mode, first):
    freq = np.arange(2001) * 2.0
    psd = np.ones(freq.size)
    psd[0] = 1e6
    floor = running_median_floor(freq, psd, 250.0, mode=mode)
    assert floor[0] == first
    assert np.all(floor[5:] == 1.0)
