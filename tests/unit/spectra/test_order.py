"""Order tracking and time-synchronous averaging.

Test tier: closed form (a tone at constant order q while the shaft accelerates is a single line
at q in the order spectrum; averaging N revolutions of periodic signal plus white noise leaves
the noise reduced by sqrt(N)).
"""

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.spectra import (amplitude_spectrum, angle_resample, order_spectrum,
                           tacho_pulse_times, time_synchronous_average)

FS = 5000.0
T = 2.0
F0, F1 = 10.0, 20.0                         # shaft accelerates 10 → 20 Hz over T


def _run_up(order=7.0, fs=FS):
    t = np.arange(int(fs * T)) / fs
    fr = F0 + (F1 - F0) * t / T
    theta = F0 * t + 0.5 * (F1 - F0) / T * t ** 2        # revolutions
    return t, fr, theta, np.sin(2 * np.pi * order * theta)


def _single_line(o):
    i = int(np.argmax(o.amplitude))
    second = np.max(np.where(np.abs(o.order - o.order[i]) > 0.5, o.amplitude, 0.0))
    return o.order[i], o.amplitude[i], second


def test_constant_order_tone_is_one_line_with_speed_profile():
    t, fr, theta, x = _run_up()
    o = order_spectrum(x, FS, speed_rpm=60.0 * fr)
    q, a, second = _single_line(o)
    assert q == pytest.approx(7.0, abs=o.resolution_order)
    assert a == pytest.approx(1.0, rel=0.01)
    assert second < 1e-3
    assert o.n_revolutions == 29 and o.resolution_order == pytest.approx(1 / 29)
    # the time-domain spectrum of the same record is smeared over 70-140 Hz
    s = amplitude_spectrum(x, FS)
    assert s.amplitude.max() < 0.5
    band = (s.freq_hz > 70) & (s.freq_hz < 140)
    assert np.sum(s.amplitude[band] > 0.05) > 50


def test_constant_order_tone_with_tacho_and_coarse_profile():
    t, fr, theta, x = _run_up()
    tacho = ((theta % 1.0) < 0.25).astype(float)          # one pulse per revolution
    o = order_spectrum(x, FS, tacho=tacho)
    q, a, second = _single_line(o)
    assert q == pytest.approx(7.0, abs=o.resolution_order)
    assert a == pytest.approx(1.0, rel=0.01)
    assert second < 0.02
    # speed profile every 50 ms instead of every sample
    o = order_spectrum(x, FS, speed_rpm=60.0 * np.r_[fr[::250], F1],
                       speed_time_s=np.r_[t[::250], T])
    q, a, second = _single_line(o)
    assert q == pytest.approx(7.0, abs=o.resolution_order)
    assert a == pytest.approx(1.0, rel=0.01)


def test_tacho_pulse_times_are_interpolated_between_samples():
    fs = 1000.0
    t = np.arange(1000) / fs
    ramp = np.sin(2 * np.pi * 3.0 * t - 0.1)                # rising zero crossings
    times = tacho_pulse_times(ramp, fs, threshold=0.0)
    expected = (0.1 / (2 * np.pi) + np.arange(3)) / 3.0
    assert np.allclose(times, expected, atol=1e-5)


def test_constant_speed_order_axis():
    fs, f_shaft = 2048.0, 16.0
    t = np.arange(int(4 * fs)) / fs
    x = 0.5 * np.sin(2 * np.pi * 28 * f_shaft * t) + 0.1 * np.sin(2 * np.pi * 3.6342 * f_shaft * t)
    o = order_spectrum(x, fs, speed_rpm=60 * f_shaft)
    assert o.samples_per_rev == 128
    i28 = np.argmin(np.abs(o.order - 28))
    assert o.amplitude[i28] == pytest.approx(0.5, rel=0.01)
    i36 = np.argmin(np.abs(o.order - 3.6342))
    assert o.amplitude[i36 - 2: i36 + 3].max() == pytest.approx(0.1, rel=0.01)
    angle, xa = angle_resample(x, fs, speed_rpm=60 * f_shaft, samples_per_rev=128)
    assert angle[0] == pytest.approx(0.0) and np.allclose(np.diff(angle), 1 / 128)
    assert np.allclose(xa, x[: xa.size], atol=1e-9)         # same grid: samples reproduced


def test_tsa_reduces_noise_by_sqrt_n_revolutions():
    fs, f_shaft, n_rev, sigma = 10_000.0, 10.0, 64, 1.0
    spr = int(fs / f_shaft)
    t = np.arange(n_rev * spr) / fs
    theta = f_shaft * t

    def gear(th):
        return ((1 + 0.2 * np.cos(2 * np.pi * th)) * np.sin(2 * np.pi * 28 * th)
                + 0.3 * np.sin(2 * np.pi * 56 * th + 0.5))

    rng = np.random.default_rng(11)
    x = gear(theta) + sigma * rng.standard_normal(t.size)
    avg = time_synchronous_average(x, fs, speed_rpm=60 * f_shaft, samples_per_rev=spr)
    assert avg.n_revolutions == n_rev
    truth = gear(avg.angle_rev)
    err = np.std(avg.average - truth)
    assert err == pytest.approx(sigma / np.sqrt(avg.n_revolutions), rel=0.15)
    # the residual is the noise (minus its average): rms σ·sqrt(1 − 1/N)
    assert np.std(avg.residual) == pytest.approx(sigma * np.sqrt(1 - 1 / avg.n_revolutions),
                                                 rel=0.03)
    assert avg.residual.shape == (avg.n_revolutions * spr,)
    few = time_synchronous_average(x, fs, speed_rpm=60 * f_shaft, samples_per_rev=spr,
                                   n_revolutions=4)
    assert np.std(few.average - truth) > 3 * err           # 4 revolutions average less


def test_tsa_with_tacho_on_run_up_keeps_gear_waveform():
    t, fr, theta, _ = _run_up()
    x = np.sin(2 * np.pi * 28 * theta) + 0.5 * np.cos(2 * np.pi * 3 * theta)
    tacho = ((theta % 1.0) < 0.25).astype(float)
    avg = time_synchronous_average(x, FS, tacho=tacho, samples_per_rev=256)
    truth = np.sin(2 * np.pi * 28 * avg.angle_rev) + 0.5 * np.cos(2 * np.pi * 3 * avg.angle_rev)
    assert np.max(np.abs(avg.average - truth)) < 0.05


@pytest.mark.parametrize("call, name", [
    (lambda: order_spectrum(np.ones(1000), 1000.0), "speed_rpm"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, speed_rpm=600.0, tacho=np.ones(1000)),
     "speed_rpm"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, speed_rpm=-600.0), "speed_rpm"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, speed_rpm=np.r_[600.0, 0.0]), "speed_rpm"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, speed_rpm=np.full(10, 600.0)), "speed_rpm"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, speed_rpm=np.full(3, 600.0),
                            speed_time_s=[0.0, 0.1, 0.2]), "speed_time_s"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, speed_rpm=60.0), "revolutions"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, speed_rpm=600.0, samples_per_rev=4),
     "samples_per_rev"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, tacho=np.ones(1000)), "tacho"),
    (lambda: order_spectrum(np.ones(1000), 1000.0, speed_rpm=600.0, window="kaiser"), "window"),
    (lambda: time_synchronous_average(np.ones(1000), 1000.0, speed_rpm=600.0,
                                      n_revolutions=50), "n_revolutions"),
])
def test_bad_inputs_name_the_parameter(call, name):
    with pytest.raises(ParameterError, match=name):
        call()
