"""Order tracking: resample a signal at uniform shaft angle and take its order spectrum.

The shaft angle θ(t) (in revolutions) comes from one of

* a constant speed (``speed_rpm`` scalar): θ = f_r·t;
* a speed profile (``speed_rpm`` array on the signal's time grid, or on ``speed_time_s``):
  θ = ∫ f_r dt (:func:`scipy.integrate.cumulative_trapezoid`);
* a tacho pulse train (``tacho``): θ = k/pulses_per_rev at the k-th rising threshold
  crossing, located by linear interpolation between samples. The angle is only known between
  the first and the last pulse, so the resampled record is limited to that span.

Times at the uniform angles θ_j = j/samples_per_rev follow from a monotone interpolation of
t(θ) (:class:`scipy.interpolate.PchipInterpolator`) and the signal is evaluated there with a
cubic spline (:class:`scipy.interpolate.CubicSpline`). If the angular sampling is coarser than
the time sampling at the slowest speed, the signal is first low-pass filtered at order
0.4·samples_per_rev (zero-phase Butterworth at 0.4·samples_per_rev·f_min Hz) to prevent
aliasing. In the order spectrum a component locked to the shaft angle (constant order) is one
line even when the speed varies, while its time-domain spectrum is smeared over the speed range.

References
----------
.. [1] K. R. Fyfe, E. D. S. Munck, "Analysis of computed order tracking", MSSP 11 (1997)
   187-205.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.integrate
import scipy.interpolate
import scipy.signal

from cmsim.errors import ParameterError, check_choice, check_range
from cmsim.spectra._checks import WINDOWS, positive_int, readonly, sampling_rate, signal_1d
from cmsim.spectra.amplitude import amplitude_spectrum

__all__ = ["OrderSpectrum", "tacho_pulse_times", "shaft_angle", "angle_resample",
           "order_spectrum"]

#: Largest angle-domain record, as a multiple of the time-domain length (guards against a
#: default samples_per_rev blowing up at near-zero speed).
MAX_UPSAMPLING = 32


@dataclass(frozen=True, eq=False)
class OrderSpectrum:
    """Amplitude spectrum versus shaft order (a tone of amplitude A at order q reads A).

    Unpacks as ``order, amplitude = spectrum``.

    Attributes
    ----------
    order : numpy.ndarray, shape (n_bins,)
        Shaft orders (cycles per revolution), 0 to samples_per_rev/2.
    amplitude : numpy.ndarray, shape (n_bins,)
        Amplitude per bin, unit of the signal.
    resolution_order : float
        Bin spacing 1/n_revolutions, orders.
    window : str
        Window used.
    n_revolutions : int
        Number of whole shaft revolutions analysed.
    samples_per_rev : int
        Angular sampling, samples per revolution.
    """

    order: np.ndarray
    amplitude: np.ndarray
    resolution_order: float
    window: str
    n_revolutions: int
    samples_per_rev: int

    def __post_init__(self):
        object.__setattr__(self, "order", readonly(self.order))
        object.__setattr__(self, "amplitude", readonly(self.amplitude))

    def __iter__(self):
        yield self.order
        yield self.amplitude


def tacho_pulse_times(tacho, fs, threshold=None):
    """Times of the rising threshold crossings of a tacho signal.

    Parameters
    ----------
    tacho : array_like, shape (n,)
        Tacho (key-phasor) signal, any unit.
    fs : float
        Sampling rate, Hz.
    threshold : float, optional
        Crossing level, unit of ``tacho``; default halfway between its min and max.

    Returns
    -------
    numpy.ndarray, shape (n_pulses,)
        Crossing times, s, from the first sample (t = 0), linearly interpolated between samples.
    """
    tacho = signal_1d(tacho, name="tacho")
    fs = sampling_rate(fs)
    lo, hi = float(tacho.min()), float(tacho.max())
    if hi <= lo:
        raise ParameterError("tacho is constant: no pulses to detect")
    thr = 0.5 * (lo + hi) if threshold is None else check_range(
        "threshold", threshold, lo, hi, lo_open=True, hi_open=True, unit="(between tacho min and max)")
    below = tacho[:-1] < thr
    i = np.flatnonzero(below & (tacho[1:] >= thr))
    frac = (thr - tacho[i]) / (tacho[i + 1] - tacho[i])
    return (i + frac) / fs


def shaft_angle(n, fs, *, speed_rpm=None, speed_time_s=None, tacho=None, pulses_per_rev=1):
    """Knots (θ, t) of the shaft angle from a speed, a speed profile or a tacho.

    Give exactly one of ``speed_rpm`` and ``tacho``.

    Parameters
    ----------
    n : int
        Number of signal samples (time grid t_i = i/fs).
    fs : float
        Sampling rate, Hz.
    speed_rpm : float or array_like, optional
        Constant shaft speed (> 0), or speed profile, rpm, shape (n,) on the signal time grid
        or shape (m,) on ``speed_time_s``; every value must be > 0.
    speed_time_s : array_like, shape (m,), optional
        Increasing times of the speed profile samples, s.
    tacho : array_like, shape (n,), optional
        Tacho pulse train sampled with the signal.
    pulses_per_rev : int
        Tacho pulses per shaft revolution.

    Returns
    -------
    angle_rev : numpy.ndarray, shape (k,)
        Shaft angle at the knots, revolutions, strictly increasing.
    time_s : numpy.ndarray, shape (k,)
        Knot times, s.
    """
    fs = sampling_rate(fs)
    if (speed_rpm is None) == (tacho is None):
        raise ParameterError("give exactly one of speed_rpm and tacho")
    t = np.arange(n) / fs
    if tacho is not None:
        if speed_time_s is not None:
            raise ParameterError("speed_time_s goes with speed_rpm, not with tacho")
        tacho = signal_1d(tacho, name="tacho")
        if tacho.size != n:
            raise ParameterError(f"tacho must have the signal's {n} samples, got {tacho.size}")
        ppr = positive_int("pulses_per_rev", pulses_per_rev, lo=1)
        tp = tacho_pulse_times(tacho, fs)
        if tp.size < 2 * ppr + 1:
            raise ParameterError(f"tacho has {tp.size} pulses; need at least {2 * ppr + 1} "
                                 f"(two revolutions at pulses_per_rev={ppr})")
        return np.arange(tp.size) / ppr, tp
    speed = np.asarray(speed_rpm, dtype=float)
    if speed.ndim == 0:
        f = check_range("speed_rpm", speed, 0.0, lo_open=True, unit="rpm") / 60.0
        return f * t, t
    speed = signal_1d(speed, name="speed_rpm", min_samples=2)
    if np.any(speed <= 0.0):
        raise ParameterError(f"speed_rpm must be > 0 rpm everywhere, min is {speed.min():g}")
    if speed_time_s is None:
        if speed.size != n:
            raise ParameterError(f"speed_rpm must be a scalar or have the signal's {n} samples "
                                 f"(or give speed_time_s), got {speed.size}")
        f = speed / 60.0
    else:
        ts = signal_1d(speed_time_s, name="speed_time_s", min_samples=2)
        if ts.size != speed.size or np.any(np.diff(ts) <= 0.0):
            raise ParameterError("speed_time_s must be increasing and match speed_rpm in size")
        if ts[0] > t[0] + 0.5 / fs or ts[-1] < t[-1] - 0.5 / fs:
            raise ParameterError(f"speed_time_s must cover the record [0, {t[-1]:g}] s, "
                                 f"got [{ts[0]:g}, {ts[-1]:g}] s")
        f = scipy.interpolate.make_interp_spline(ts, speed / 60.0, k=1)(t)
    return scipy.integrate.cumulative_trapezoid(f, t, initial=0.0), t


def angle_resample(x, fs, *, speed_rpm=None, speed_time_s=None, tacho=None, pulses_per_rev=1,
                   samples_per_rev=None):
    """Resample ``x`` at uniform shaft angle, starting at a whole revolution.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit.
    fs : float
        Sampling rate, Hz.
    speed_rpm, speed_time_s, tacho, pulses_per_rev
        Speed information, see :func:`shaft_angle`.
    samples_per_rev : int, optional
        Angular sampling (>= 8); default the power of two >= fs / (slowest shaft rate), which
        keeps every frequency of ``x`` at every speed.

    Returns
    -------
    angle_rev : numpy.ndarray, shape (m,)
        Uniform shaft angles, revolutions (the first one an integer).
    x_angle : numpy.ndarray, shape (m,)
        Signal at those angles, unit of ``x``.
    """
    x = signal_1d(x)
    fs = sampling_rate(fs)
    theta, tk = shaft_angle(x.size, fs, speed_rpm=speed_rpm, speed_time_s=speed_time_s,
                            tacho=tacho, pulses_per_rev=pulses_per_rev)
    rate = np.diff(theta) / np.diff(tk)          # rev/s between knots
    f_min = float(rate.min())
    if samples_per_rev is None:
        spr = 2 ** math.ceil(math.log2(max(8.0, fs / f_min)))
    else:
        spr = positive_int("samples_per_rev", samples_per_rev, lo=8)
    th0, th1 = math.ceil(theta[0] - 1e-9), theta[-1]
    m = int(math.floor((th1 - th0) * spr + 1e-9)) + 1
    if m < 2 * spr:
        raise ParameterError(f"record covers {th1 - theta[0]:.3g} shaft revolutions; "
                             "angle resampling needs at least 2")
    if m > MAX_UPSAMPLING * x.size:
        raise ParameterError(
            f"samples_per_rev={spr} would give {m} angle samples from {x.size} time samples; "
            f"choose samples_per_rev <= {int(MAX_UPSAMPLING * x.size / (th1 - th0))}")
    if spr * f_min < fs * (1.0 - 1e-9):        # angular sampling coarser than time sampling
        cutoff_hz = 0.4 * spr * f_min
        sos = scipy.signal.butter(8, cutoff_hz, btype="lowpass", fs=fs, output="sos")
        x = scipy.signal.sosfiltfilt(sos, x)
    angle = th0 + np.arange(m) / spr
    t_at = scipy.interpolate.PchipInterpolator(theta, tk)(angle)
    x_at = scipy.interpolate.CubicSpline(np.arange(x.size) / fs, x)(t_at)
    return angle, x_at


def order_spectrum(x, fs, *, speed_rpm=None, speed_time_s=None, tacho=None, pulses_per_rev=1,
                   samples_per_rev=None, window="flattop"):
    """Amplitude spectrum versus shaft order over the whole revolutions of the record.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit.
    fs : float
        Sampling rate, Hz.
    speed_rpm, speed_time_s, tacho, pulses_per_rev
        Speed information, see :func:`shaft_angle`.
    samples_per_rev : int, optional
        Angular sampling, see :func:`angle_resample`; orders up to samples_per_rev/2.
    window : {"flattop", "hann", "boxcar"}
        Window; amplitudes follow the :mod:`~cmsim.spectra.amplitude` convention.

    Returns
    -------
    OrderSpectrum
        Order resolution 1/n_revolutions.
    """
    check_choice("window", window, WINDOWS)
    angle, xa = angle_resample(x, fs, speed_rpm=speed_rpm, speed_time_s=speed_time_s,
                               tacho=tacho, pulses_per_rev=pulses_per_rev,
                               samples_per_rev=samples_per_rev)
    spr = int(round(1.0 / (angle[1] - angle[0])))
    n_rev = xa.size // spr
    s = amplitude_spectrum(xa[: n_rev * spr], float(spr), window=window)
    return OrderSpectrum(order=s.freq_hz, amplitude=s.amplitude, resolution_order=1.0 / n_rev,
                         window=window, n_revolutions=n_rev, samples_per_rev=spr)
