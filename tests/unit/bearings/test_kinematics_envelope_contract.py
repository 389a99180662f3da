"""Closed-form details of the bearing kinematics and the envelope chain that the formula tests
leave open (written against the mutants of ``benchmarks/mutation/run_mutmut.py``).

Tier (a) closed form: the cage ratios with a contact angle, ball positions with an offset,
the exact one-step correlation and start of the slip process, the digital Butterworth gain
of the zero-phase filter at a known frequency for two orders, the DC
removal of the envelope, and the flat-top reading of a modulation between two bins.
"""

import math

import numpy as np
import pytest

from cmsim.bearings.kinematics import (ball_angles, ball_pass_cycles_per_rev, cage_angle,
                                       slip_jitter)
from cmsim.errors import ParameterError
from cmsim.frequencies import cage_speed_ratios
from cmsim.rig import Rig
from cmsim.spectra.envelope import bandpass, envelope, envelope_spectrum

BRG = Rig.paper_2016().bearings[0]


def test_cage_ratios_with_a_contact_angle():
    d, dm, a = 7.94e-3, 39.04e-3, 0.3
    g = d / dm * math.cos(a)
    k_in, k_out = cage_speed_ratios(d, dm, a)
    assert k_in == pytest.approx((1 - g) / 2, rel=1e-14)
    assert k_out == pytest.approx((1 + g) / 2, rel=1e-14)
    assert cage_speed_ratios(d, dm) == pytest.approx(((1 - d / dm) / 2, (1 + d / dm) / 2),
                                                     rel=1e-14)


def test_ball_angles_offset_and_default_outer_ring():
    th = np.array([0.0, 1.0, 2.5])
    k_in, _ = cage_speed_ratios(BRG.ball_diameter_m, BRG.pitch_diameter_m,
                                BRG.effective_contact_angle_rad)
    np.testing.assert_allclose(cage_angle(BRG, th), k_in * th, rtol=1e-14)
    b = ball_angles(BRG, th, offset_rad=0.1)
    spacing = 2 * math.pi * np.arange(BRG.n_balls) / BRG.n_balls
    np.testing.assert_allclose(b, k_in * th[:, None] + spacing + 0.1, rtol=1e-14)
    assert ball_pass_cycles_per_rev(BRG) == pytest.approx(BRG.n_balls * k_in, rel=1e-14)


def test_slip_jitter_recursion_is_exact():
    """x[0] = σ·z0 and x[i] = a·x[i−1] + σ·√(1 − a²)·z_i with a = exp(−dt/τ), same draws."""
    dt, tau, rms = 1e-4, 2e-3, 0.03
    x = slip_jitter(2, 50, dt, rms, tau, np.random.default_rng(5))
    z = np.random.default_rng(5).standard_normal((2, 50))
    a = math.exp(-dt / tau)
    want = np.empty_like(z)
    want[:, 0] = rms * z[:, 0]
    for i in range(1, 50):
        want[:, i] = a * want[:, i - 1] + rms * math.sqrt(1 - a * a) * z[:, i]
    np.testing.assert_allclose(x, want, rtol=1e-13, atol=1e-16)
    zero = slip_jitter(3, 4, dt, 0.0, tau, np.random.default_rng(5))
    assert zero.shape == (3, 4) and not np.any(zero)


FS = 20_000.0


@pytest.mark.parametrize("order", [2, 6])
def test_butterworth_gain_of_the_zero_phase_filters(order):
    """Digital Butterworth (bilinear): |H|² = 1/(1 + (tan(πf/fs)/tan(πfc/fs))^(2n)) per pass;
    the zero-phase filter applies it twice, so the amplitude gain is |H|²."""
    n = 40_000
    t = np.arange(n) / FS
    f = 3_000.0
    x = np.sin(2 * math.pi * f * t)
    mid = slice(n // 4, 3 * n // 4)

    def w(freq):
        return math.tan(math.pi * freq / FS)

    fc = 2_000.0
    lp = bandpass(x, FS, (0.0, fc), filter_order=order)
    assert np.max(np.abs(lp[mid])) == pytest.approx(1 / (1 + (w(f) / w(fc)) ** (2 * order)),
                                                    rel=0.01)
    fc = 4_500.0
    hp = bandpass(x, FS, (fc, FS / 2), filter_order=order)
    assert np.max(np.abs(hp[mid])) == pytest.approx(1 / (1 + (w(fc) / w(f)) ** (2 * order)),
                                                    rel=0.01)


@pytest.mark.parametrize("order", [0, 13, 2.0, True])
def test_filter_order_bounds(order):
    with pytest.raises(ParameterError, match="^filter_order must be an integer"):
        bandpass(np.ones(100), FS, (100.0, 200.0), filter_order=order)


def test_filter_order_limits_are_accepted():
    x = np.random.default_rng(1).standard_normal(4000)
    for order in (1, 12):
        assert bandpass(x, FS, (100.0, 2000.0), filter_order=order).shape == x.shape


def test_envelope_removes_the_mean_and_reads_the_modulation():
    n = 40_000
    t = np.arange(n) / FS
    env = envelope(3.0 + np.sin(2 * math.pi * 1000.0 * t), FS)
    assert np.median(env) == pytest.approx(1.0, rel=1e-3)
    fm = 105.25                                               # between two bins (0.5 Hz)
    x = (1 + 0.5 * np.cos(2 * math.pi * fm * t)) * np.sin(2 * math.pi * 5000.0 * t)
    s = envelope_spectrum(x, FS, (3000.0, 7000.0))
    assert s.kind == "envelope"
    f, a = s
    i = np.argmax(a[f > 20.0])
    assert f[f > 20.0][i] == pytest.approx(fm, abs=0.5)
    assert a[f > 20.0][i] == pytest.approx(0.5, rel=0.01)      # flat-top: no scalloping loss
    with pytest.raises(ParameterError, match="resolution"):
        envelope_spectrum(x, FS, resolution_hz=0.01)


def test_default_filter_order_is_four():
    x = np.random.default_rng(3).standard_normal(8000)
    band = (1_000.0, 3_000.0)
    np.testing.assert_array_equal(bandpass(x, FS, band), bandpass(x, FS, band, filter_order=4))
    assert not np.allclose(bandpass(x, FS, band), bandpass(x, FS, band, filter_order=5))
    np.testing.assert_array_equal(envelope(x, FS, band), envelope(x, FS, band, filter_order=4))
    np.testing.assert_array_equal(envelope_spectrum(x, FS, band).amplitude,
                                  envelope_spectrum(x, FS, band, filter_order=4).amplitude)
    assert not np.allclose(envelope_spectrum(x, FS, band).amplitude,
                           envelope_spectrum(x, FS, band, filter_order=5).amplitude)


@pytest.mark.parametrize("band", [(0.8, 50.0), (0.8, 20.0)], ids=["high-pass", "band-pass"])
def test_a_low_edge_below_one_hertz_still_filters(band):
    """A pass band starting at 0.8 Hz removes a constant offset (only lo = 0 keeps it)."""
    fs = 100.0
    t = np.arange(40_000) / fs
    x = 5.0 + np.sin(2 * math.pi * 10.0 * t)
    y = bandpass(x, fs, band)
    mid = slice(10_000, 30_000)
    assert abs(y[mid].mean()) < 0.01
    assert np.std(y[mid]) * math.sqrt(2) == pytest.approx(1.0, rel=0.02)
    kept = bandpass(x, fs, (0.0, 20.0))
    assert kept[mid].mean() == pytest.approx(5.0, rel=1e-3)


def test_band_errors_name_the_argument():
    with pytest.raises(ParameterError, match=r"^band_hz must satisfy 0 <= lo < hi <= fs/2"):
        bandpass(np.ones(100), FS, (300.0, 200.0))
    with pytest.raises(ParameterError, match=r"^band_hz must be a pair"):
        envelope(np.ones(100), FS, band_hz=5.0)
