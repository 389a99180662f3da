"""Time-synchronous averaging (TSA) of a gear signal over shaft revolutions.

The signal is resampled at uniform shaft angle (:func:`cmsim.spectra.order.angle_resample`),
cut into N whole revolutions and averaged. Components locked to the shaft (mesh harmonics,
tooth-to-tooth variations) survive; everything else — noise, components of other shafts,
bearing components that are not synchronous — is attenuated, noise by about 1/sqrt(N) in
amplitude. The residual (angle-domain signal minus the average repeated N times) holds what is
not synchronous.

References
----------
.. [1] P. D. McFadden, "A revised model for the extraction of periodic waveforms by time
   domain averaging", MSSP 1 (1987) 83-95.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError
from cmsim.spectra._checks import positive_int, readonly
from cmsim.spectra.order import angle_resample

__all__ = ["SynchronousAverage", "time_synchronous_average"]


@dataclass(frozen=True, eq=False)
class SynchronousAverage:
    """Result of a time-synchronous average.

    Attributes
    ----------
    angle_rev : numpy.ndarray, shape (samples_per_rev,)
        Shaft angle over one revolution, revolutions in [0, 1).
    average : numpy.ndarray, shape (samples_per_rev,)
        Averaged revolution, unit of the signal.
    residual : numpy.ndarray, shape (n_revolutions * samples_per_rev,)
        Angle-domain signal minus the repeated average, unit of the signal.
    n_revolutions : int
        Number of averaged revolutions N.
    samples_per_rev : int
        Angular samples per revolution.
    """

    angle_rev: np.ndarray
    average: np.ndarray
    residual: np.ndarray
    n_revolutions: int
    samples_per_rev: int

    def __post_init__(self):
        for name in ("angle_rev", "average", "residual"):
            object.__setattr__(self, name, readonly(getattr(self, name)))


def time_synchronous_average(x, fs, *, speed_rpm=None, speed_time_s=None, tacho=None,
                             pulses_per_rev=1, samples_per_rev=None, n_revolutions=None):
    """Average ``x`` over whole shaft revolutions in the angle domain.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit.
    fs : float
        Sampling rate, Hz.
    speed_rpm, speed_time_s, tacho, pulses_per_rev
        Speed of the shaft to synchronise on, see :func:`cmsim.spectra.order.shaft_angle`.
        Revolution 0 starts at t = 0 (speed) or at the first tacho pulse.
    samples_per_rev : int, optional
        Angular sampling; see :func:`cmsim.spectra.order.angle_resample`.
    n_revolutions : int, optional
        Number of revolutions to average (>= 2); default all whole revolutions in the record.

    Returns
    -------
    SynchronousAverage
    """
    angle, xa = angle_resample(x, fs, speed_rpm=speed_rpm, speed_time_s=speed_time_s,
                               tacho=tacho, pulses_per_rev=pulses_per_rev,
                               samples_per_rev=samples_per_rev)
    spr = int(round(1.0 / (angle[1] - angle[0])))
    available = xa.size // spr
    if n_revolutions is None:
        n_rev = available
    else:
        n_rev = positive_int("n_revolutions", n_revolutions, lo=2)
        if n_rev > available:
            raise ParameterError(f"n_revolutions={n_rev} exceeds the {available} whole "
                                 "revolutions in the record")
    if n_rev < 2:
        raise ParameterError("the record holds fewer than 2 whole revolutions to average")
    blocks = xa[: n_rev * spr].reshape(n_rev, spr)
    avg = blocks.mean(axis=0)
    return SynchronousAverage(angle_rev=np.arange(spr) / spr, average=avg,
                              residual=(blocks - avg).ravel(), n_revolutions=n_rev,
                              samples_per_rev=spr)
