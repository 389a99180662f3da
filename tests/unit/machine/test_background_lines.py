"""A machine's background lines, synthesised as one complex matrix product.

Tier: closed form — the sum of cosines at every sample, against the cosines themselves, for
record lengths that are and are not squares, one sample, and a 10-s record at 25.6 kHz;
the phases are drawn in the lines' order, one per line, as single draws would be.
"""

import math

import numpy as np
import pytest

from cmsim.machine import Background, BackgroundLine
from cmsim.machine.background import sum_of_cosines


@pytest.mark.parametrize("n, fs", [(1, 1000.0), (7, 100.0), (12000, 12000.0),
                                   (12345, 25600.0), (256000, 25600.0)])
def test_the_product_is_the_sum_of_the_cosines(n, fs):
    rng = np.random.default_rng(n)
    f = rng.uniform(0.0, 0.5 * fs, 40)
    a = rng.uniform(0.01, 1.0, 40)
    ph = rng.uniform(0.0, 2 * math.pi, 40)
    t = np.arange(n) / fs
    want = (a[:, None] * np.cos(2 * np.pi * f[:, None] * t + ph[:, None])).sum(axis=0)
    got = sum_of_cosines(f, a, ph, n, fs)
    assert got.shape == (n,)
    assert np.max(np.abs(got - want)) <= 1e-10 * np.sum(a)


def test_the_lines_phases_are_drawn_in_their_order():
    lines = [BackgroundLine("fixed", 50.0, 1.0), BackgroundLine("input", 2.0, 0.5),
             BackgroundLine("output", 3.0, 0.25)]
    bg = Background(freq_hz=(0.0, 5000.0), psd=(1e-9, 1e-9), lines=tuple(lines))
    shafts = (25.0, 10.0)
    got = bg.deterministic(4000, 10000.0, shafts, np.random.default_rng(9), gain=2.0)
    rng = np.random.default_rng(9)
    t = np.arange(4000) / 10000.0
    want = sum(2.0 * ln.amplitude * np.cos(2 * np.pi * ln.frequency_hz(shafts) * t
                                           + rng.uniform(0.0, 2 * math.pi)) for ln in lines)
    np.testing.assert_allclose(got, want, atol=1e-12)
    quiet = Background(freq_hz=(0.0, 5000.0), psd=(1e-9, 1e-9))
    assert np.array_equal(quiet.deterministic(10, 1000.0, shafts, rng), np.zeros(10))


def test_records_of_one_machine_share_its_lines_phases_and_differ_in_noise():
    """``sensor_signal(line_seed=)``: the lines' phases from their own seed, the noise from
    the record's. With a silent background noise two records of one line seed are the same,
    and another line seed moves the lines."""
    from cmsim.machine import Machine, TransferPath
    from cmsim.rig import OperatingPoint, Rig
    bg = Background(freq_hz=(0.0, 6000.0), psd=(0.0, 0.0),
                    lines=(BackgroundLine("fixed", 1000.0, 1.0), BackgroundLine("input", 3.0, 0.5)))
    m = Machine(name="m", rig=Rig.paper_2016(), channel="DE", model_signal="accel_1b1_y",
                fs_hz=12000.0, op=OperatingPoint(1500.0, 10.0),
                path=TransferPath("F_1b1_y", (0.0, 6000.0), (1e-3, 1e-3), "g"), background=bg)
    force = np.zeros(2400)
    a = m.sensor_signal(force, 0, 2000, seed=1, line_seed=5)
    b = m.sensor_signal(force, 0, 2000, seed=2, line_seed=5)
    c = m.sensor_signal(force, 0, 2000, seed=1, line_seed=6)
    assert np.array_equal(a, b) and np.max(np.abs(a - c)) > 0.1
    # without a line seed, the lines' phases follow the record's seed, after its noise
    d = m.sensor_signal(force, 0, 2000, seed=1)
    e = m.sensor_signal(force, 0, 2000, seed=2)
    assert np.max(np.abs(d - e)) > 0.1
