"""Housing accelerometers and tacho: cmsim.sensors.

Test tier: closed form. A single housing mode H(s) = s²/(m(s² + 2ζω_n s + ω_n²)) reads its
closed-form magnitude for steady tones (peak 1/(2ζm) at ω_n) and rings after a force impulse
at ω_d = ω_n·sqrt(1 − ζ²) with the envelope exp(−ζω_n t); white noise of rms σ reads σ; tones
above the sensor Nyquist frequency are ≥ 60 dB down after decimation (the filter is designed
for 80) while pass-band tones keep amplitude and timing; the tacho gives one pulse per 2π of
shaft rotation, at the instants the rotation crosses each multiple of 2π, also under a speed
ramp; impacts at a fault rate ringing the housing show that rate in the envelope spectrum of
the band the kurtogram picks.
"""

import json
import math

import numpy as np
import pytest
from scipy.signal import sosfreqz

from cmsim.cli import main
from cmsim.errors import ParameterError
from cmsim.rig import HousingPath, Rig, RollingBearing, Rotor
from cmsim.run import Run
from cmsim.sensors import (STEPS_PER_MODE_PERIOD, TACHO_LEVEL_V, TACHO_PULSE_WIDTH_RAD, add_sensors, decimate,
                           housing_acceleration, housing_sos, tacho_signal)
from cmsim.spectra import amplitude_spectrum, envelope_spectrum, kurtogram, tacho_pulse_times

FS = 75_000.0
ONE_MODE = HousingPath((3000.0,), (0.03,), (2.0,))


def _run(signals, fs=FS, seed=None, rig=None):
    n = len(next(iter(signals.values())))
    meta = {"fs_hz": fs}
    if seed is not None:
        meta["seed"] = seed
    if rig is not None:
        meta["rig"] = rig.to_dict()
    return Run(np.arange(n) / fs, signals, meta)


def _tone_response(path, f, fs=FS, seconds=0.5):
    """Complex amplitude of the steady response to sin(2πft) (last half of the record)."""
    n = int(fs * seconds)
    t = np.arange(n) / fs
    a = housing_acceleration(np.sin(2 * np.pi * f * t), fs, path)
    t2, a2 = t[n // 2:], a[n // 2:]
    cycles = math.floor(t2.size * f / fs)                   # whole periods only
    m = int(round(cycles * fs / f))
    return 2 * np.mean(a2[:m] * np.exp(-2j * np.pi * f * t2[:m])) * 1j


# ---------------------------------------------------------------------- housing path
@pytest.mark.parametrize("f", [10.0, 30.0, 60.0, 120.0])
def test_a_shaft_rate_tone_far_under_the_modes_reads_closed_form_accelerance(f):
    """Far under the modes the accelerance is (f/f_n)² under the mass line: the images the
    force's interpolation leaves at multiples of its rate pass the mass line and fold back
    onto the tone (a 55-dB interpolator read 30 Hz 18 dB high under the default rig's
    modes at 12 kHz)."""
    path, fs = Rig.paper_2016().housing, 12_000.0
    measured = _tone_response(path, f, fs=fs, seconds=2.0)
    exact = path.accelerance(f)
    assert abs(measured) == pytest.approx(abs(exact), rel=0.02)


@pytest.mark.parametrize("ratio", [0.5, 0.9, 0.97, 1.0, 1.03, 1.1, 2.0])
def test_single_mode_tone_reads_closed_form_accelerance(ratio):
    f = ratio * 3000.0
    measured = _tone_response(ONE_MODE, f)
    exact = ONE_MODE.accelerance(f)
    assert abs(measured) == pytest.approx(abs(exact), rel=0.01)
    assert abs(np.angle(measured / exact)) < 0.02


def test_single_mode_peak_frequency_and_gain():
    """Peak of the discrete response: at the closed-form peak (ω_n/sqrt(1−2ζ²)), 1/(2ζm)."""
    fs_filter = 2 * FS                        # the rate housing_acceleration filters at
    assert math.ceil(STEPS_PER_MODE_PERIOD * 3000.0 / FS) == 2
    f = np.linspace(2500.0, 3500.0, 20001)
    _, h = sosfreqz(housing_sos(ONE_MODE, fs_filter), worN=f, fs=fs_filter)
    exact = np.abs(ONE_MODE.accelerance(f))
    peak_f = f[np.argmax(np.abs(h))]
    assert peak_f == pytest.approx(3000.0 / math.sqrt(1 - 2 * 0.03 ** 2), rel=5e-4)
    assert np.abs(h).max() == pytest.approx(exact.max(), rel=1e-3)
    assert abs(ONE_MODE.accelerance(3000.0)) == pytest.approx(1 / (2 * 0.03 * 2.0), rel=1e-3)
    assert np.max(np.abs(np.abs(h) - exact) / exact) < 0.01


def test_default_path_reads_closed_form_at_every_mode():
    path = HousingPath()
    for f in path.natural_frequencies_hz:
        measured = _tone_response(path, f)
        assert abs(measured) == pytest.approx(abs(path.accelerance(f)), rel=0.01)


def test_impulse_rings_at_damped_frequency_with_modal_decay():
    """a(t) = −(J/m)e^{−σt}[2σ cos ω_d t + (ω_n² − 2σ²)/ω_d sin ω_d t], σ = ζω_n, for t > 0."""
    fn, zeta, m = 3000.0, 0.03, 2.0
    fs = 400_000.0                            # bilinear warping of the bandwidth ~1e-3
    path = HousingPath((fn,), (zeta,), (m,))
    n = int(0.02 * fs)
    force = np.zeros(n)
    impulse_ns = 1e-3
    force[100] = impulse_ns * fs              # a force of J/T during one sample: impulse J
    a = housing_acceleration(force, fs, path)
    t = (np.arange(n) - 100) / fs
    wn = 2 * np.pi * fn
    sigma, wd = zeta * wn, wn * math.sqrt(1 - zeta ** 2)
    after = t > 2 / fn                        # skip the feed-through sample and 2 periods
    exact = -(impulse_ns / m) * np.exp(-sigma * t) * (
        2 * sigma * np.cos(wd * t) + (wn ** 2 - 2 * sigma ** 2) / wd * np.sin(wd * t))
    scale = np.abs(exact[after]).max()
    assert np.max(np.abs(a[after] - exact[after])) < 0.02 * scale
    # frequency from zero crossings, decay from peaks 20 periods apart
    s = a[after]
    up = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    f_ring = (up.size - 1) / ((up[-1] - up[0]) / fs)
    assert f_ring == pytest.approx(wd / (2 * np.pi), rel=1e-3)
    period = int(round(fs / fn))
    p0 = np.abs(s[:period]).max()
    p20 = np.abs(s[20 * period:21 * period]).max()
    zeta_measured = math.log(p0 / p20) / (2 * np.pi * 20) * (wd / wn)
    assert zeta_measured == pytest.approx(zeta, rel=0.03)


def test_constant_force_gives_no_acceleration():
    a = housing_acceleration(np.full(5000, 800.0), FS, HousingPath())
    assert np.max(np.abs(a)) < 1e-9


def test_mode_above_nyquist_is_refused_by_name_and_a_slow_force_is_interpolated():
    with pytest.raises(ParameterError, match=r"natural_frequencies_hz\[2\]"):
        housing_sos(HousingPath(), 10_000.0)
    fs = 12_000.0                             # 5.5 kHz is 0.46 fs: filtered at 14 × 12 kHz
    measured = _tone_response(HousingPath(), 1000.0, fs=fs)
    assert abs(measured) == pytest.approx(abs(HousingPath().accelerance(1000.0)), rel=0.01)


@pytest.mark.parametrize("kwargs, match", [
    (dict(damping_ratios=(0.03, 0.03)), "damping_ratios must have one value per mode"),
    (dict(modal_masses_kg=(2.0, -1.0, 2.0)), r"modal_masses_kg\[1\]"),
    (dict(natural_frequencies_hz=(1e3, float("nan"), 3e3)), r"natural_frequencies_hz\[1\]"),
    (dict(damping_ratios=(0.03, 0.0, 0.03)), r"damping_ratios\[1\]"),
    (dict(natural_frequencies_hz=3000.0), "must be a list of numbers"),
])
def test_bad_housing_path_is_refused(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        HousingPath(**kwargs)


def test_housing_path_is_saved_with_the_rig(tmp_path):
    path = HousingPath((1800.0, 3300.0), (0.02, 0.05), (1.5, 4.0))
    rig = Rig.paper_2016()
    assert rig.housing == HousingPath()
    changed = Rig(**{**rig.__dict__, "housing": path})
    changed.save(tmp_path / "rig.toml")
    loaded = Rig.load(tmp_path / "rig.toml")
    assert loaded.housing == path and loaded == changed
    data = rig.to_dict()
    del data["housing"]                       # rig files written before the housing existed
    assert Rig.from_dict(data).housing == HousingPath()


# ---------------------------------------------------------------------- decimation
@pytest.mark.parametrize("fs_out", [12_000.0, 25_000.0])
def test_decimation_attenuates_above_sensor_nyquist_and_keeps_the_band(fs_out):
    n = int(FS * 0.5)
    t = np.arange(n) / FS
    nyq = 0.5 * fs_out
    above = [nyq, 1.08 * nyq, 1.5 * nyq, 2.7 * nyq, 0.45 * FS]
    inside = [0.05 * nyq, 0.4 * nyq, 0.8 * nyq]
    x = np.column_stack([np.sin(2 * np.pi * f * t + 0.3) for f in above + inside])
    y, offset, info = decimate(x, FS, fs_out)
    assert info["method"] == ("resample_poly" if fs_out == 12_000.0 else "AntiAliasFilter")
    to = offset + np.arange(y.shape[0]) / fs_out
    for j, f in enumerate(above):
        gain_db = 20 * np.log10(np.std(y[:, j]) / np.std(x[:, j]))
        assert gain_db < -60.0, f"{f:g} Hz only {gain_db:.1f} dB down"
    for j, f in enumerate(inside, start=len(above)):
        assert np.max(np.abs(y[:, j] - np.sin(2 * np.pi * f * to + 0.3))) < 1e-3


def test_decimation_refuses_upsampling_and_odd_ratios():
    x = np.zeros((1000, 1))
    with pytest.raises(ParameterError, match="fs_out_hz"):
        decimate(x, 10_000.0, 20_000.0)
    with pytest.raises(ParameterError, match="fraction"):
        decimate(x, 75_000.0, 75_000.0 / math.pi)


# ---------------------------------------------------------------------- add_sensors
def test_add_sensors_maps_force_direction_to_accelerometer_direction():
    n = 20_000
    t = np.arange(n) / FS
    fx = 50.0 * np.sin(2 * np.pi * 2500.0 * t)
    run = _run({"F_1b1_x": fx, "F_1b1_y": np.full(n, 300.0), "F_1b2_x": np.zeros(n),
                "F_1b2_y": np.zeros(n)})
    out = add_sensors(run, path=ONE_MODE)
    assert set(out.names) == set(run.names) | {"accel_1b1_x", "accel_1b1_y", "accel_1b2_x",
                                                 "accel_1b2_y"}
    assert out.schema()["accel_1b1_x"].unit == "m/s²"
    assert np.allclose(out["accel_1b1_x"], housing_acceleration(fx, FS, ONE_MODE), atol=0.0)
    assert np.max(np.abs(out["accel_1b1_y"])) < 1e-9        # static y force: no acceleration
    assert np.max(np.abs(out["accel_1b2_x"])) < 1e-12
    only = add_sensors(run, path=ONE_MODE, bearings=["1b2"])
    assert "accel_1b1_x" not in only.signals and "accel_1b2_y" in only.signals
    with pytest.raises(ParameterError, match="2b1"):
        add_sensors(run, bearings=["2b1"])
    x_only = add_sensors(run, path=ONE_MODE, directions="x")
    assert {"accel_1b1_x", "accel_1b2_x"} <= set(x_only.signals)
    assert not {"accel_1b1_y", "accel_1b2_y"} & set(x_only.signals)
    np.testing.assert_array_equal(x_only["accel_1b1_x"], out["accel_1b1_x"])
    with pytest.raises(ParameterError, match="directions"):
        add_sensors(run, path=ONE_MODE, directions=("z",))
    # an accelerometer needs only the force along its direction (a dataset records no more)
    x_forces = _run({"F_1b1_x": fx, "F_1b2_x": np.zeros(n)})
    np.testing.assert_array_equal(
        add_sensors(x_forces, path=ONE_MODE, directions="x")["accel_1b1_x"], out["accel_1b1_x"])
    with pytest.raises(ParameterError, match="F_1b1_y"):
        add_sensors(x_forces, path=ONE_MODE, bearings=["1b1"])


def test_add_sensors_takes_the_path_from_the_run_rig_and_records_the_sensor(tmp_path):
    rig = Rig.paper_2016()
    rig = Rig(**{**rig.__dict__, "housing": ONE_MODE})
    n = 30_000
    rng = np.random.default_rng(1)
    forces = {f"F_{b}_{d}": rng.standard_normal(n) for b in rig.bearing_names for d in "xy"}
    run = _run(forces, rig=rig, seed=7)
    out = add_sensors(run, fs_hz=12_000.0, noise_rms=0.01)
    expected = housing_acceleration(forces["F_2b1_y"], FS, ONE_MODE)
    ref = add_sensors(run, path=ONE_MODE, fs_hz=12_000.0, noise_rms=0.01)
    assert np.array_equal(out["accel_2b1_y"], ref["accel_2b1_y"])
    assert np.std(out["accel_2b1_y"]) < np.std(expected)   # decimated: part of the band gone
    sensor = out.meta["sensor"]
    assert sensor["seed"] == 7 and sensor["noise_rms_m_s2"] == pytest.approx(0.01)
    assert sensor["housing"]["natural_frequencies_hz"] == [3000.0]
    assert sensor["anti_alias"]["stopband_hz"] == pytest.approx(6000.0)
    assert out.fs_hz == pytest.approx(12_000.0)
    assert np.allclose(np.diff(out.t), 1 / 12_000.0, rtol=1e-9)
    loaded = Run.load(out.save(tmp_path / "run.npz"))
    assert loaded.meta["sensor"] == out.meta["sensor"]


@pytest.mark.parametrize("fs_out", [None, 12_000.0])
def test_sensor_noise_has_the_requested_rms_and_follows_the_seed(fs_out):
    n = 150_000
    run = _run({"F_1b1_x": np.zeros(n), "F_1b1_y": np.zeros(n)})
    a = add_sensors(run, noise_rms=0.3, fs_hz=fs_out, seed=5)
    b = add_sensors(run, noise_rms=0.3, fs_hz=fs_out, seed=5)
    c = add_sensors(run, noise_rms=0.3, fs_hz=fs_out, seed=6)
    x = a["accel_1b1_x"]
    assert np.std(x) == pytest.approx(0.3, rel=0.03)
    assert abs(np.mean(x)) < 0.02
    assert abs(np.corrcoef(x, a["accel_1b1_y"])[0, 1]) < 0.05
    assert np.array_equal(x, b["accel_1b1_x"])
    assert not np.allclose(x, c["accel_1b1_x"])
    with pytest.raises(ParameterError, match="noise_rms"):
        add_sensors(run, noise_rms=-1.0)


def test_decimated_force_above_sensor_nyquist_leaves_no_alias():
    """A 9 kHz force rings the housing at 75 kHz; recorded at 12 kHz it is ≥ 60 dB down."""
    n = int(FS * 0.4)
    t = np.arange(n) / FS
    run = _run({"F_1b1_x": 100.0 * np.sin(2 * np.pi * 9000.0 * t), "F_1b1_y": np.zeros(n)})
    full = add_sensors(run)["accel_1b1_x"]
    low = add_sensors(run, fs_hz=12_000.0)["accel_1b1_x"]   # start: housing rings at 2.5-5.5 kHz
    assert 20 * np.log10(np.std(low[low.size // 2:]) / np.std(full[n // 2:])) < -60.0


# ---------------------------------------------------------------------- tacho
def _pulse_count_and_times(theta, fs):
    tacho = tacho_signal(theta)
    return tacho, tacho_pulse_times(tacho, fs)


def test_tacho_pulses_at_the_shaft_rate():
    fs, rpm = 12_000.0, 1797.0
    t = np.arange(int(fs * 2.0)) / fs
    theta = 0.1 + 2 * np.pi * rpm / 60.0 * t
    tacho, times = _pulse_count_and_times(theta, fs)
    assert set(np.unique(tacho)) <= {0.0, TACHO_LEVEL_V}
    revs = math.floor(theta[-1] / (2 * np.pi))
    assert times.size == revs                                # one per 2π crossed
    assert 1.0 / np.mean(np.diff(times)) == pytest.approx(rpm / 60.0, rel=1e-3)
    high = np.mean(tacho > 0)
    assert high == pytest.approx(TACHO_PULSE_WIDTH_RAD / (2 * np.pi), rel=0.02)


def test_tacho_once_per_revolution_under_a_speed_ramp():
    """Run-up 300 → 1500 rpm in 2 s: a pulse within one sample after each multiple of 2π."""
    fs = 20_000.0
    t = np.arange(int(fs * 2.0)) / fs
    f0, f1, dur = 5.0, 25.0, 2.0
    theta = 2 * np.pi * (f0 * t + 0.5 * (f1 - f0) / dur * t ** 2) + 1e-6 * np.sin(900 * t)
    run = _run({"F_1b1_x": np.zeros(t.size), "F_1b1_y": np.zeros(t.size),
                "theta_1b1": theta}, fs=fs)
    out = add_sensors(run)
    times = tacho_pulse_times(out["tacho"], fs)
    k = np.arange(1, math.floor(theta[-1] / (2 * np.pi)) + 1)
    a, b = 0.5 * (f1 - f0) / dur, f0                     # a t² + b t = k  →  crossing time
    exact = (-b + np.sqrt(b * b + 4 * a * k)) / (2 * a)
    assert times.size == k.size
    assert np.max(np.abs(times - exact)) < 1.0 / fs
    rate = 1.0 / np.diff(times)                          # pulse rate follows the speed
    speed = f0 + (f1 - f0) / dur * 0.5 * (times[1:] + times[:-1])
    assert np.max(np.abs(rate / speed - 1)) < 0.01
    assert out.meta["sensor"]["tacho"]["pulses_per_rev"] == 1


def test_tacho_refuses_a_rate_too_low_for_the_pulse():
    t = np.arange(1000) / 1000.0
    with pytest.raises(ParameterError, match="fs_hz"):
        tacho_signal(2 * np.pi * 60.0 * t)


# ---------------------------------------------------------------------- envelope analysis
def test_impacts_ringing_the_housing_show_the_fault_rate_in_the_envelope_spectrum():
    """Impacts at 107 Hz (BPFO-like, 1 % timing jitter) on top of shaft and gear tones and a
    random force, through the default housing, recorded at 12 kHz with sensor noise: in the
    band the kurtogram picks, and in a band around the first housing mode, the envelope
    spectrum's largest line is a harmonic of 107 Hz and the 107 Hz line stands far above the
    floor; the raw spectrum hardly shows 107 Hz (the housing barely moves at low frequency)."""
    fault_hz, seconds = 107.0, 2.0
    n = int(FS * seconds)
    t = np.arange(n) / FS
    rng = np.random.default_rng(11)
    force = 400.0 + 30.0 * np.sin(2 * np.pi * 29.95 * t) + 20.0 * np.sin(2 * np.pi * 466.7 * t)
    force += 2.0 * rng.standard_normal(n)
    hits = np.arange(0.01, seconds, 1.0 / fault_hz)
    hits = hits + 0.01 / fault_hz * rng.standard_normal(hits.size)
    width = int(1e-4 * FS)                                      # 0.1 ms half-sine impacts
    pulse = np.sin(np.pi * np.arange(width) / width)
    for th in hits:
        i = int(th * FS)
        force[i:i + width] += 15.0 * pulse[:max(0, min(width, n - i))]
    run = _run({"F_1b1_x": np.zeros(n), "F_1b1_y": force})
    out = add_sensors(run, fs_hz=12_000.0, noise_rms=0.05, seed=3)
    acc = out["accel_1b1_y"]
    kg = kurtogram(acc, out.fs_hz, max_fault_hz=3 * fault_hz)
    mode = HousingPath().natural_frequencies_hz[0]
    for band in (kg.band_hz, (mode - 500.0, mode + 500.0)):
        spec = envelope_spectrum(acc, out.fs_hz, band, window="hann")
        sel = (spec.freq_hz > 20.0) & (spec.freq_hz < 500.0)
        f, a = spec.freq_hz[sel], spec.amplitude[sel]
        tol = 2 * (spec.freq_hz[1] - spec.freq_hz[0])
        top = f[np.argmax(a)]
        assert abs(top / fault_hz - round(top / fault_hz)) * fault_hz < tol, (band, top)
        assert a[np.abs(f - fault_hz) < tol].max() > 10 * np.median(a), band
    raw = amplitude_spectrum(acc, out.fs_hz, window="hann")
    near = np.abs(raw.freq_hz - fault_hz) < 1.0
    assert raw.amplitude[near].max() < 0.01 * raw.amplitude.max()


# ---------------------------------------------------------------------- command line
def _cwru_like_rig():
    brg = RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3)
    return Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01))


def test_cli_simulate_with_sensors_writes_accelerations_and_tacho(tmp_path, capsys):
    rig_file = tmp_path / "rig.toml"
    _cwru_like_rig().save(rig_file)
    out = tmp_path / "run.npz"
    status = main(["simulate", "--rig", str(rig_file), "--speed-rpm", "1797",
                   "--radial-load-n", "50", "--duration-s", "0.2", "--fs-hz", "48000",
                   "--sensor-fs-hz", "12000", "--sensor-noise", "0.01", "--seed", "4",
                   "--out", str(out), "--json"])
    assert status == 0
    res = json.loads(capsys.readouterr().out)
    assert res["fs_hz"] == pytest.approx(12_000.0) and res["accel_1b1_y_rms_m_s2"] > 0.005
    run = Run.load(out)
    assert {"accel_1b1_x", "accel_1b1_y", "accel_1b2_x", "accel_1b2_y", "tacho"} <= set(run.names)
    times = tacho_pulse_times(run["tacho"], run.fs_hz)
    assert 1 / np.mean(np.diff(times)) == pytest.approx(1797 / 60, rel=0.01)
    assert run.meta["sensor"]["seed"] == 4 and run.meta["sensor"]["noise_rms_m_s2"] == 0.01
    plain = tmp_path / "plain.npz"
    assert main(["simulate", "--rig", str(rig_file), "--speed-rpm", "1797", "--radial-load-n",
                 "50", "--duration-s", "0.05", "--out", str(plain)]) == 0
    assert not any(k.startswith("accel_") or k == "tacho" for k in Run.load(plain).names)
