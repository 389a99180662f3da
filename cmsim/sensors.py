"""Sensors at the end of the chain: housing accelerometers and a once-per-revolution tacho.

The model emits the forces the bearings transmit to the housing (``F_<bearing>_<x|y>``, N); a
condition-monitoring engineer measures housing accelerations. :func:`add_sensors` turns a
:class:`~cmsim.run.Run` into what an acquisition system records:

1. **housing transfer path** — each bearing force through the rig's
   :class:`~cmsim.rig.HousingPath` (a sum of damped housing modes, accelerance in (m/s²)/N),
   ``accel_<bearing>_x`` from ``F_<bearing>_x`` and ``accel_<bearing>_y`` from
   ``F_<bearing>_y`` (:func:`housing_acceleration`);
2. **anti-alias decimation** to the sensor sample rate ``fs_hz`` (:func:`decimate`): an
   integer ratio goes through :class:`cmsim.dynamics.decimation.AntiAliasFilter` (linear-phase
   FIR, ≥ 80 dB from the sensor Nyquist frequency on), a rational one (75 kHz → 12 kHz =
   4/25) through :func:`scipy.signal.resample_poly` with a Kaiser-window FIR designed to the
   same specification (pass band flat to 0.8 × Nyquist, ≥ 80 dB from Nyquist on); every
   signal of the run goes through the same filter, so the record keeps one time axis;
3. **sensor noise** — white Gaussian, ``noise_rms`` m/s² at the sensor rate, drawn from
   ``numpy.random.default_rng(seed)`` (the seed is recorded in ``meta["sensor"]``);
4. **tacho** — a once-per-revolution pulse train from the input shaft's total rotation
   ``theta_1b1`` (:func:`tacho_signal`): :data:`TACHO_LEVEL_V` (5 V, TTL) while the shaft is
   within :data:`TACHO_PULSE_WIDTH_RAD` (18°, a strip of reflective tape) past each multiple
   of 2π, 0 V otherwise. Being a function of the angle, not of time, it is right at any speed
   profile: a run-up gives pulses closer and closer together, one per revolution.

The housing modes are discretised with the bilinear transform prewarped at each mode's
natural frequency, at the run's sample rate times an integer k that gives at least
:data:`STEPS_PER_MODE_PERIOD` samples per period of the highest mode (the force is
interpolated by k with a polyphase Nyquist filter, the acceleration kept at the original
instants): the resonance frequency and the peak accelerance 1/(2ζm) are exact, and elsewhere
the frequency axis of mode k is stretched by at most ω_k·T/sin(ω_k·T) − 1 ≈ (ω_k·T)²/6
(< 0.7 %; tones read the closed-form H(jω) within 1 %, down to the shaft rates far under
the modes: :data:`INTERPOLATION_KAISER_BETA`). The filter is causal, as a structure
is, and starts at rest under the first force sample (a static force gives no acceleration:
H(0) = 0).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
from fractions import Fraction

import numpy as np
from scipy.signal import firwin, kaiserord, resample_poly, sosfilt

from cmsim._kernels import HOUSING_BLOCK, housing_modes_jit
from cmsim.dynamics.decimation import AntiAliasFilter
from cmsim.errors import ParameterError, check_range
from cmsim.rig import HousingPath
from cmsim.run import Run

__all__ = ["housing_sos", "housing_acceleration", "decimate", "sensor_rate_ratio",
           "tacho_signal", "add_sensors",
           "TACHO_LEVEL_V", "TACHO_PULSE_WIDTH_RAD", "ANTI_ALIAS_DB", "ANTI_ALIAS_PASSBAND",
           "STEPS_PER_MODE_PERIOD", "INTERPOLATION_KAISER_BETA", "INTERPOLATION_ZERO_CROSSINGS",
           "interpolation_filter", "slow_rate_modes"]

#: High level of the tacho pulse, V (TTL output of an optical or magnetic key-phasor).
TACHO_LEVEL_V = 5.0
#: Angular width of the tacho pulse after each multiple of 2π, rad (18°: one tape strip).
TACHO_PULSE_WIDTH_RAD = 2.0 * math.pi / 20.0
#: Stop-band attenuation of the sensor's anti-alias filter from its Nyquist frequency on, dB.
ANTI_ALIAS_DB = 80.0
#: Pass-band edge of the anti-alias filter as a fraction of the sensor Nyquist frequency
#: (fs = 2.56·f_max, the usual acquisition-system rule).
ANTI_ALIAS_PASSBAND = 0.8
#: Least samples per period of the highest housing mode at which the modes are filtered; a
#: force sampled slower is interpolated by an integer factor first (75 kHz and a 5.5 kHz mode:
#: ×3). The bilinear map then stretches the frequency axis by at most (2π/32)²/6 = 0.64 %.
STEPS_PER_MODE_PERIOD = 32
#: Kaiser β and zero crossings each side of the sinc that interpolates a force by k before
#: the modes are filtered. The images it leaves at multiples of the force's rate pass the
#: modes' mass line (1/m) and fold back onto the tone when the acceleration is kept at the
#: original instants; a tone far under the modes is read s²/(m ω_n²), (f/f_n)² under it:
#: the β = 5, ten crossings of :func:`scipy.signal.resample_poly` (~55 dB) read a 30-Hz
#: tone under 2.5-5.5 kHz modes 18 dB high and a 10-Hz one 38 dB; β = 14 with 32 crossings
#: (~135 dB) reads them within 0.1 dB (and the top of the band, 0.9 of the Nyquist
#: frequency, within 0.04 dB instead of 0.8), for 2× the time (~5 ms per second at 12 kHz).
INTERPOLATION_KAISER_BETA = 14.0
INTERPOLATION_ZERO_CROSSINGS = 32
#: Largest denominator of the ratio sensor rate / run rate (up/down of the polyphase filter).
MAX_RATIO_DENOMINATOR = 1000

_FORCE = re.compile(r"F_(?P<b>\d+b\d+)_(?P<d>x|y)")


def housing_sos(path, fs_hz):
    """Second-order sections of the housing modes, one section per mode (added in parallel).

    Mode k, H_k(s) = s² / (m_k (s² + 2ζ_k ω_k s + ω_k²)), is mapped by the bilinear transform
    s = c·(1 − z⁻¹)/(1 + z⁻¹) with c = ω_k / tan(ω_k T / 2), so that H_k(e^{jω_k T}) equals
    H_k(jω_k) exactly.

    Parameters
    ----------
    path : HousingPath
        Housing modes.
    fs_hz : float
        Sample rate of the force, Hz; every mode must lie below fs_hz/2.

    Returns
    -------
    numpy.ndarray, shape (n_modes, 6)
        ``[b0, b1, b2, 1, a1, a2]`` per mode (scipy's ``sos`` layout), b in (m/s²)/N.

    Raises
    ------
    ParameterError
        If a mode is at or above the Nyquist frequency of ``fs_hz``.
    """
    fs = check_range("fs_hz", fs_hz, 0.0, lo_open=True, unit="Hz")
    sos = np.empty((path.n_modes, 6))
    for k, (f, z, m) in enumerate(zip(path.natural_frequencies_hz, path.damping_ratios,
                                      path.modal_masses_kg)):
        if f >= 0.5 * fs:
            raise ParameterError(
                f"housing mode natural_frequencies_hz[{k}] = {f:g} Hz is not below the "
                f"Nyquist frequency {0.5 * fs:g} Hz of the force (fs_hz = {fs:g}); simulate "
                f"at fs_hz > {2 * f:g} Hz or drop the mode",
                param=f"natural_frequencies_hz[{k}]", allowed=f"< {0.5 * fs:g} Hz")
        w = 2.0 * math.pi * f
        c = w / math.tan(0.5 * w / fs)
        a0 = c * c + 2.0 * z * w * c + w * w
        sos[k] = (c * c / m / a0, -2.0 * c * c / m / a0, c * c / m / a0,
                  1.0, (2.0 * w * w - 2.0 * c * c) / a0, (c * c - 2.0 * z * w * c + w * w) / a0)
    return sos


def housing_acceleration(force_n, fs_hz, path):
    """Housing acceleration produced by a bearing force through the housing modes.

    Parameters
    ----------
    force_n : array_like, shape (n,) or (n, C)
        Force transmitted by the bearing to the housing along one direction, N, sampled at
        ``fs_hz``; or C such forces side by side (filtered in one pass, each as alone).
    fs_hz : float
        Sample rate, Hz.
    path : HousingPath
        Housing modes (:attr:`cmsim.rig.Rig.housing`).

    Returns
    -------
    numpy.ndarray, shape of ``force_n``
        Acceleration along the same direction, m/s², same instants. The filter starts at rest
        under ``force_n[0]`` (a constant force gives zero acceleration). Modes above the
        force's Nyquist frequency are allowed (the force is interpolated) but are excited
        only by what the samples hold.

    Examples
    --------
    >>> fs, f = 75_000.0, 2500.0
    >>> t = np.arange(30_000) / fs
    >>> a = housing_acceleration(np.sin(2 * np.pi * f * t), fs, HousingPath((f,), (0.03,), (2.0,)))
    >>> round(float(np.abs(a[-1500:]).max()), 1)    # 1 / (2 ζ m) = 8.33 (m/s²)/N
    8.3
    """
    x = np.asarray(force_n, dtype=float)
    if x.ndim not in (1, 2) or x.shape[0] < 1:
        raise ParameterError(f"force_n must be a 1-D array with samples (or 2-D, one force "
                             f"per column), got shape {x.shape}", param="force_n")
    if not np.all(np.isfinite(x)):
        raise ParameterError("force_n must be finite (no NaN or inf)", param="force_n")
    fs = check_range("fs_hz", fs_hz, 0.0, lo_open=True, unit="Hz")
    # H(0) = 0: remove the first force sample, so the record starts at rest and the
    # zero padding of the interpolation continues that constant force; every mode's biquad
    # over the force interpolated by k, their sum kept at the original instants, run at the
    # force's own rate (cmsim._kernels)
    num, den, lead, k, h, sos = slow_rate_modes(path, fs)
    n, before = x.shape[0], num.shape[1] - 1 - lead
    signals = np.zeros((int(np.prod(x.shape[1:])), n + num.shape[1] - 1))
    signals[:, before:before + n] = (x - x[0]).reshape(n, -1).T
    init = _first_outputs(signals[:, before:before + n], sos, k, h)
    out = np.empty((signals.shape[0], n))
    housing_modes_jit(signals, num, den, init, np.empty((num.shape[0], HOUSING_BLOCK)),
                      np.empty((num.shape[0], 2)), out)
    return out[0] if x.ndim == 1 else out.T


def _interpolated(x, h, k, n_fast):
    """The first ``n_fast`` samples of forces ``x`` (C, n) interpolated by k through ``h``
    (:func:`interpolation_filter`), :func:`scipy.signal.resample_poly`'s: fast sample
    m = Σ_i x[i]·h[m + half − i·k], the inputs before the first and after the last zero.
    Only the inputs those samples reach are interpolated."""
    half = (h.size - 1) // 2
    reach = min(x.shape[1], (n_fast - 1 + half) // k + 1)
    return resample_poly(x[:, :reach], k, 1, axis=1, window=h / k)[:, :n_fast]


@functools.lru_cache(maxsize=16)
def slow_rate_modes(path, fs_hz):
    """The housing modes at a force's own rate (:mod:`cmsim._kernels`): mode s is
    ``num[s](z) / (1 + den[s, 0]·z⁻¹ + den[s, 1]·z⁻²)`` with its input read ``lead`` samples
    ahead, the same system as its biquad at k·fs over the force interpolated by
    :func:`interpolation_filter` and kept every k-th sample. The numerator is the mode's
    impulse response in that form times the denominator, whose poles are the biquad's to the
    k-th power; it ends once the interpolation's span has passed (what rounding leaves
    beyond is checked under 1e-12 of its largest).

    Parameters
    ----------
    path : HousingPath
        Housing modes.
    fs_hz : float
        The force's sample rate, Hz.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, int, int, numpy.ndarray, numpy.ndarray)
        ``num`` (modes, taps), ``den`` (modes, 2), ``lead``, the factor k, the
        interpolation filter and the modes' biquads at k·fs (read-only). With k = 1 the
        biquads themselves (their double zero at DC exact).
    """
    k = max(1, math.ceil(STEPS_PER_MODE_PERIOD * max(path.natural_frequencies_hz) / fs_hz))
    sos = housing_sos(path, fs_hz * k)
    if k == 1:
        num, den, h = sos[:, :3].copy(), sos[:, 4:].copy(), np.ones(1)
        for a in (num, den, h, sos):
            a.setflags(write=False)
        return num, den, 0, 1, h, sos
    h = interpolation_filter(k)
    lead = ((h.size - 1) // 2) // k
    n_taps = 2 * lead + 3
    # each impulse response over its numerator's span and far enough past it to check its end
    n_slow = n_taps + 64
    unit = np.zeros((1, n_slow))
    unit[0, lead] = 1.0                               # a unit input at input ``lead``
    impulse = _interpolated(unit, h, k, n_slow * k)[0]
    num, den = np.empty((len(sos), n_taps)), np.empty((len(sos), 2))
    for s, section in enumerate(sos):
        resp = sosfilt(section[None, :], impulse)[::k]
        a = np.real(np.poly(np.roots([1.0, section[4], section[5]]) ** k))
        full = np.convolve(resp, a)[:n_slow]
        if np.max(np.abs(full[n_taps:])) > 1e-12 * np.max(np.abs(full)):
            raise AssertionError("a housing mode's form at the force's rate did not end "
                                 "with the interpolation's span")
        num[s], den[s] = full[:n_taps], a[1:]
    for a in (num, den, h, sos):
        a.setflags(write=False)
    return num, den, lead, k, h, sos


def _first_outputs(x, sos, k, h):
    """(C, modes, 2): each mode's first two outputs over forces ``x`` (C, n) as the
    interpolated form gives them (to rounding: its sums run in another order), each biquad
    of ``sos`` at rest at the first sample (the interpolated samples before it, its
    look-ahead into the first inputs, never fed)."""
    fast = _interpolated(x, h, k, k + 1)              # fast samples 0 … k
    out = np.zeros((x.shape[0], len(sos), 2))
    for s, section in enumerate(sos):
        y = sosfilt(section[None, :].copy(), fast, axis=1)   # it takes a writable sos
        out[:, s, 0] = y[:, 0]
        if x.shape[1] > 1:
            out[:, s, 1] = y[:, k]
    return out


def interpolation_filter(k):
    """The FIR that interpolates a force by ``k`` before the modes are filtered: windowed
    sinc, cut-off at the force's Nyquist frequency, :data:`INTERPOLATION_ZERO_CROSSINGS` on
    each side, Kaiser β = :data:`INTERPOLATION_KAISER_BETA`, gain ``k`` (a Nyquist filter:
    it keeps the input samples)."""
    half = INTERPOLATION_ZERO_CROSSINGS * k
    return k * firwin(2 * half + 1, 1.0 / k, window=("kaiser", INTERPOLATION_KAISER_BETA))


def _kaiser_lowpass(fs_hz, fs_out_hz):
    """Linear-phase FIR at ``fs_hz``: flat to 0.8 × and ≥ 80 dB from the Nyquist of fs_out."""
    nyq_out = 0.5 * fs_out_hz
    width = (1.0 - ANTI_ALIAS_PASSBAND) * nyq_out / (0.5 * fs_hz)
    numtaps, beta = kaiserord(ANTI_ALIAS_DB, width)
    numtaps += 1 - numtaps % 2                       # odd: symmetric about its centre tap
    cutoff = 0.5 * (1.0 + ANTI_ALIAS_PASSBAND) * nyq_out
    return firwin(numtaps, cutoff, window=("kaiser", beta), fs=fs_hz)


def sensor_rate_ratio(fs_hz, fs_out_hz):
    """(fs, fs_out, up, down): a sensor rate checked against the run's, fs_out = fs·up/down
    with down <= :data:`MAX_RATIO_DENOMINATOR` (checkable before a run is made).

    Raises
    ------
    ParameterError
        If fs_out_hz > fs_hz or the ratio is not such a fraction.
    """
    fs = check_range("fs_hz", fs_hz, 0.0, lo_open=True, unit="Hz")
    fs_out = check_range("fs_out_hz", fs_out_hz, 0.0, fs, lo_open=True,
                         unit="Hz (at most the run's sample rate)")
    ratio = Fraction(fs_out / fs).limit_denominator(MAX_RATIO_DENOMINATOR)
    up, down = ratio.numerator, ratio.denominator
    if abs(up * fs / down - fs_out) > 1e-9 * fs_out:
        raise ParameterError(
            f"fs_out_hz = {fs_out:g} Hz (the sensor rate) is not a fraction up/down (down <= "
            f"{MAX_RATIO_DENOMINATOR}) of the run's fs_hz = {fs:g} Hz", param="fs_out_hz",
            allowed=f"{fs:g}·up/down Hz")
    return fs, fs_out, up, down


def decimate(x, fs_hz, fs_out_hz):
    """Low-pass and resample the columns of ``x`` to a lower sensor sample rate.

    Parameters
    ----------
    x : array_like, shape (n, C)
        Samples at ``fs_hz``, row i at time i/fs_hz from the first row.
    fs_hz : float
        Input sample rate, Hz.
    fs_out_hz : float
        Sensor sample rate, Hz, <= fs_hz; fs_out_hz/fs_hz must be a fraction up/down with
        down <= 1000 (75 kHz → 12 kHz is 4/25).

    Returns
    -------
    y : numpy.ndarray, shape (m, C)
        Samples at ``fs_out_hz``; only instants whose filter window lies inside the input.
    offset_s : float
        Time of ``y[0]`` after ``x[0]``, s.
    info : dict
        JSON-ready description: ``method``, ``up``, ``down``, ``numtaps``, ``passband_hz``,
        ``stopband_hz`` (the sensor Nyquist frequency), ``attenuation_db``.

    Raises
    ------
    ParameterError
        If fs_out_hz > fs_hz, the ratio is not such a fraction, or the record is shorter than
        the filter.
    """
    fs, fs_out, up, down = sensor_rate_ratio(fs_hz, fs_out_hz)
    x = np.asarray(x, dtype=float)
    if up == down:
        return x.copy(), 0.0, {"method": "none", "up": 1, "down": 1}
    if up == 1:
        aa = AntiAliasFilter(int(down), fs, attenuation_db=ANTI_ALIAS_DB,
                             passband=ANTI_ALIAS_PASSBAND)
        y = aa.apply(x)
        info = {"method": "AntiAliasFilter", "up": 1, **aa.to_dict(), "down": int(down)}
        offset = aa.half_length / fs
    else:
        h = _kaiser_lowpass(fs * up, fs_out)
        half = (h.size - 1) // 2                      # upsampled samples each side
        # output n is input time n·down/up samples; keep n whose window lies inside x
        first = math.ceil(half / down)
        last = ((x.shape[0] - 1) * up - half) // down
        full = resample_poly(x, up, down, axis=0, window=h)
        y = full[first:last + 1] if last >= first else np.empty((0,) + x.shape[1:])
        offset = first * down / (up * fs)
        info = {"method": "resample_poly", "up": int(up), "down": int(down),
                "numtaps": int(h.size), "passband_hz": ANTI_ALIAS_PASSBAND * 0.5 * fs_out,
                "stopband_hz": 0.5 * fs_out, "attenuation_db": ANTI_ALIAS_DB}
    if y.shape[0] < 2:
        raise ParameterError(f"record of {x.shape[0]} samples is too short for the "
                             f"anti-alias filter to {fs_out:g} Hz; simulate longer",
                             param="duration_s")
    return y, offset, info


def tacho_signal(theta_rad, *, level_v=TACHO_LEVEL_V, pulse_width_rad=TACHO_PULSE_WIDTH_RAD):
    """Once-per-revolution pulse train from a shaft's total rotation.

    Parameters
    ----------
    theta_rad : array_like, shape (n,)
        Total rotation of the shaft, rad (nominal rotation plus vibration, increasing).
    level_v : float
        Pulse level, V.
    pulse_width_rad : float
        Pulse width, rad of shaft rotation, in (0, π).

    Returns
    -------
    numpy.ndarray, shape (n,)
        ``level_v`` while theta mod 2π < ``pulse_width_rad``, 0 otherwise: a rising edge
        within one sample after each crossing of a multiple of 2π.

    Raises
    ------
    ParameterError
        If the shaft turns more than half a pulse width between two samples (the pulse
        would span fewer than 2 samples and could be missed).
    """
    theta = np.asarray(theta_rad, dtype=float)
    width = check_range("pulse_width_rad", pulse_width_rad, 0.0, math.pi, lo_open=True,
                        hi_open=True, unit="rad")
    if theta.size > 1:
        step = float(np.max(np.abs(np.diff(theta))))
        if step > 0.5 * width:
            raise ParameterError(
                f"the shaft turns up to {step:.3g} rad per sample, more than half the tacho "
                f"pulse width {width:.3g} rad: raise the sensor fs_hz", param="fs_hz")
    return np.where(np.mod(theta, 2.0 * math.pi) < width, float(level_v), 0.0)


def _force_bearings(run, directions=("x", "y")):
    """Bearings with ``F_<b>_<d>`` in the run for every direction d of ``directions``, in the
    run's order."""
    found = {}
    for name in run.signals:
        m = _FORCE.fullmatch(name)
        if m:
            found.setdefault(m["b"], set()).add(m["d"])
    order = list(run.meta.get("rig") and run.rig.bearing_names or sorted(found))
    return [b for b in order if found.get(b, set()) >= set(directions)]


def add_sensors(run, *, path=None, noise_rms=0.0, fs_hz=None, seed=None, bearings=None,
                directions=("x", "y")):
    """The run as an acquisition system records it: housing accelerations and a tacho.

    Parameters
    ----------
    run : Run
        A run with bearing forces ``F_<bearing>_x``, ``F_<bearing>_y`` (N; those of
        ``directions``) and, for the tacho, the input shaft's total rotation ``theta_1b1``
        (rad).
    path : HousingPath, optional
        Housing transfer path; default the run's rig's :attr:`~cmsim.rig.Rig.housing` (the
        documented defaults of :class:`~cmsim.rig.HousingPath` for a run without a rig).
    noise_rms : float
        RMS of white Gaussian sensor noise at the sensor rate, m/s² (>= 0).
    fs_hz : float, optional
        Sensor sample rate, Hz (<= the run's rate); default the run's own rate. Errors about
        it name it ``fs_out_hz`` (as :func:`decimate` does), not the run's ``fs_hz``.
    seed : int, optional
        Seed of the noise generator; default the run's ``meta["seed"]`` (else 0).
    bearings : sequence of str, optional
        Bearings to instrument (``"1b1"``, ...); default every bearing with the forces of
        ``directions``.
    directions : sequence of {"x", "y"}
        Accelerometer directions on each bearing (default both).

    Returns
    -------
    Run
        At the run's own rate: the run plus ``accel_<bearing>_<x|y>`` (m/s²) and ``tacho``
        (V). At a lower ``fs_hz``: every signal of the run and the new ones brought to
        ``fs_hz`` through the same anti-alias filter (edges without a full filter window are
        dropped, so ``t`` starts a little later). ``meta["fs_hz"]`` is the new rate and
        ``meta["sensor"]`` describes the sensor (path, noise, seed, anti-alias filter, tacho).

    Raises
    ------
    ParameterError
        For a bearing without forces in the run, a negative ``noise_rms``, or a sensor rate
        the run cannot be brought to.
    """
    if not isinstance(run, Run):
        raise ParameterError(f"run must be a cmsim Run, got {type(run).__name__}", param="run")
    noise = check_range("noise_rms", noise_rms, 0.0, unit="m/s^2")
    fs_in = run.fs_hz
    fs_out = fs_in if fs_hz is None else check_range("fs_out_hz", fs_hz, 0.0, lo_open=True,
                                                     unit="Hz (the sensor rate)")
    if path is None:
        rig = run.rig
        path = rig.housing if rig is not None else HousingPath()
    elif not isinstance(path, HousingPath):
        raise ParameterError(f"path must be a HousingPath, got {type(path).__name__}",
                             param="path")
    directions = [directions] if isinstance(directions, str) else list(directions)
    if not directions or any(d not in ("x", "y") for d in directions):
        raise ParameterError(f"directions must name x and/or y, got {directions!r}",
                             param="directions", allowed="x, y")
    if bearings is None:
        chosen = _force_bearings(run, directions)
    else:
        chosen = [bearings] if isinstance(bearings, str) else list(bearings)
        for b in chosen:
            if any(f"F_{b}_{d}" not in run.signals for d in directions):
                available = _force_bearings(run, directions)
                forces = ", ".join(f"F_{b}_{d}" for d in directions)
                raise ParameterError(f"bearing {b!r} has no forces {forces} in the run; "
                                     f"available: {available}", param="bearings",
                                     allowed=str(available))
    if not chosen:
        raise ParameterError("the run has no bearing forces F_<bearing>_<x|y> to feel "
                             "through the housing", param="run")
    if seed is None:
        seed = int(run.meta.get("seed", 0) or 0)
    pairs = [(b, d) for b in chosen for d in ("x", "y") if d in directions]
    accel = housing_acceleration(np.column_stack([run[f"F_{b}_{d}"] for b, d in pairs]),
                                 fs_in, path)
    new = {f"accel_{b}_{d}": accel[:, i].copy() for i, (b, d) in enumerate(pairs)}

    signals = {**run.signals, **new}
    t = np.asarray(run.t, dtype=float)
    if fs_out != fs_in:
        names = list(signals)
        y, offset, aa = decimate(np.column_stack([signals[k] for k in names]), fs_in, fs_out)
        signals = {k: np.ascontiguousarray(y[:, i]) for i, k in enumerate(names)}
        t = t[0] + offset + np.arange(y.shape[0]) / fs_out
    else:
        aa = {"method": "none", "up": 1, "down": 1}
    rng = np.random.default_rng(seed)
    if noise > 0.0:
        for name in new:
            signals[name] = signals[name] + noise * rng.standard_normal(t.size)
    tacho_meta = None
    if "theta_1b1" in signals:
        try:
            signals["tacho"] = tacho_signal(signals["theta_1b1"])
        except ParameterError as exc:      # the rate named is the tacho's: the sensor's
            if fs_out == fs_in:
                raise
            raise ParameterError(str(exc).replace("the sensor fs_hz", "fs_out_hz (the "
                                                  "sensor rate)"), param="fs_out_hz") from None
        tacho_meta = {"from": "theta_1b1", "level_v": TACHO_LEVEL_V,
                      "pulse_width_rad": TACHO_PULSE_WIDTH_RAD, "pulses_per_rev": 1}
    sensor = {"housing": {k: list(v) for k, v in dataclasses.asdict(path).items()},
              "discretisation": "bilinear, prewarped at each mode", "fs_hz": fs_out,
              "noise_rms_m_s2": noise, "seed": int(seed), "bearings": chosen,
              "anti_alias": aa, "tacho": tacho_meta}
    meta = {**run.meta, "fs_hz": fs_out, "sensor": sensor}
    if "duration_s" in meta:
        meta["duration_s"] = t.size / fs_out
    return Run(t, signals, meta, run.source)
