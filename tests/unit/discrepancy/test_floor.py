"""The record's floor as the path-free model's sensor noise (issue 25).

Tier: closed form — white noise of a known density under strong lines: the floor reads the
density and not the lines, and the noise drawn through it has that density back.
"""

import math

import numpy as np
import pytest

from cmsim.discrepancy.evaluator import record_floor

FS = 12000.0


def test_floor_reads_the_noise_between_the_lines_and_gives_it_back():
    rng = np.random.default_rng(3)
    sigma = 0.2                                   # white: one-sided density 2σ²/fs
    t = np.arange(int(10 * FS)) / FS
    lines = sum(5.0 * np.cos(2 * math.pi * k * 81.0 * t) for k in range(1, 40))
    x = sigma * rng.standard_normal(t.size) + lines
    n = int(0.5 * FS)
    floor = record_floor(x, FS, n)
    density = np.asarray(floor.psd)              # one-sided PSD
    assert np.median(density) == pytest.approx(2 * sigma ** 2 / FS, rel=0.1)
    noise = floor.noise(n, FS, np.random.default_rng(0))
    assert float(np.std(noise)) == pytest.approx(sigma, rel=0.1)
