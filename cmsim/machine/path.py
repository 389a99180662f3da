"""A machine's transfer path from a model bearing force to its sensor: a minimum-phase filter.

The path is known by its magnitude on a frequency grid (``gain`` in sensor unit per newton,
e.g. g/N); :meth:`TransferPath.apply` filters a force with the minimum-phase FIR of that
magnitude, in the time domain, so an impact stays an impact: the causal response of a
structure whose phase follows from its magnitude (Oppenheim & Schafer 2010, §5.6: the
minimum-phase system of a given magnitude, obtained by folding the real cepstrum). A
structure's accelerance between a force and a nearby accelerometer is close to minimum
phase; its excess phase (a pure delay, non-collocated zeros) changes neither a spectrum nor
an envelope spectrum, which is all that the features compare.

References
----------
.. [1] A. V. Oppenheim, R. W. Schafer, *Discrete-Time Signal Processing*, 3rd ed., Pearson
   2010, §5.6 and §13.4.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import oaconvolve

from cmsim.errors import ParameterError

__all__ = ["TransferPath", "minimum_phase_fir", "smooth_log", "FIR_TAPS"]

#: Taps of the FIR a path is applied with (a 1 %-damped mode at 500 Hz rings for ~2/(ζω) =
#: 64 ms, 770 samples at 12 kHz; 4096 taps keep 0.34 s at 12 kHz).
FIR_TAPS = 4096


def minimum_phase_fir(freq_hz, gain, fs_hz, n_taps=FIR_TAPS):
    """The minimum-phase FIR whose magnitude is ``gain`` at ``freq_hz``.

    Parameters
    ----------
    freq_hz : array_like, shape (m,)
        Increasing frequencies, Hz, from 0 (or near it) up to the Nyquist frequency of the
        data the path was measured on.
    gain : array_like, shape (m,)
        Magnitude at those frequencies (> 0), any unit.
    fs_hz : float
        Sample rate of the filter, Hz; above the last of ``freq_hz`` the last gain is held.
    n_taps : int
        Length of the FIR.

    Returns
    -------
    numpy.ndarray, shape (n_taps,)

    Examples
    --------
    >>> h = minimum_phase_fir([0.0, 6000.0], [2.0, 2.0], 12000.0, 64)
    >>> round(float(h[0]), 6), round(float(np.abs(h[1:]).max()), 6)
    (2.0, 0.0)
    """
    n_fft = 4 * int(n_taps)
    f = np.fft.rfftfreq(n_fft, 1.0 / float(fs_hz))
    log_mag = np.interp(f, np.asarray(freq_hz, dtype=float),
                        np.log(np.maximum(np.asarray(gain, dtype=float), 1e-30)))
    full = np.concatenate([log_mag, log_mag[-2:0:-1]])           # even, real: log|H|
    cep = np.fft.ifft(full).real
    fold = np.zeros(n_fft)
    fold[0] = 1.0
    fold[1:n_fft // 2] = 2.0
    fold[n_fft // 2] = 1.0
    h = np.fft.ifft(np.exp(np.fft.fft(cep * fold))).real[:int(n_taps)]
    taper = np.ones(int(n_taps))                                 # no truncation click
    k = int(n_taps) // 8
    taper[-k:] = 0.5 * (1.0 + np.cos(np.pi * np.arange(1, k + 1) / k))
    return h * taper


@dataclass(frozen=True)
class TransferPath:
    """Magnitude of a transfer path from a model force to a sensor signal.

    Attributes
    ----------
    source : str
        The model force it is applied to (``F_1b1_y``).
    freq_hz : tuple of float
        Frequency grid, Hz, increasing from 0.
    gain : tuple of float
        Magnitude on the grid, sensor unit per N (> 0).
    unit : str
        The sensor unit (``"g"``, ``"m/s^2"``, or ``""`` when unknown).
    """

    source: str
    freq_hz: tuple
    gain: tuple
    unit: str = ""

    def __post_init__(self):
        f = np.asarray(self.freq_hz, dtype=float)
        g = np.asarray(self.gain, dtype=float)
        if f.ndim != 1 or f.size < 2 or f.shape != g.shape:
            raise ParameterError("a transfer path needs freq_hz and gain of the same length "
                                 ">= 2", param="path")
        if not (np.all(np.isfinite(f)) and np.all(np.diff(f) > 0) and f[0] >= 0):
            raise ParameterError("path freq_hz must increase from >= 0", param="path")
        if not (np.all(np.isfinite(g)) and np.all(g > 0)):
            raise ParameterError("path gain must be finite and > 0", param="path")
        object.__setattr__(self, "freq_hz", tuple(float(x) for x in f))
        object.__setattr__(self, "gain", tuple(float(x) for x in g))

    def magnitude(self, freq_hz, frequency_factor=1.0):
        """|H| at ``freq_hz`` (interpolated in log magnitude), with every frequency of the
        path scaled by ``frequency_factor`` (a stiffer or softer housing)."""
        f = np.asarray(freq_hz, dtype=float)
        grid = np.asarray(self.freq_hz) * frequency_factor
        return np.exp(np.interp(f, grid, np.log(self.gain)))

    def fir(self, fs_hz, frequency_factor=1.0):
        """The minimum-phase FIR of the path at ``fs_hz`` (:func:`minimum_phase_fir`), its
        frequencies scaled by ``frequency_factor`` (kept on the path, per rate and factor: a
        comparison applies one path hundreds of times)."""
        key = (float(fs_hz), float(frequency_factor))
        kept = self.__dict__.setdefault("_firs", {})
        if key not in kept:
            grid = np.asarray(self.freq_hz) * frequency_factor
            kept[key] = minimum_phase_fir(grid, self.gain, fs_hz)
            kept[key].setflags(write=False)
        return kept[key]

    def apply(self, force, fs_hz, frequency_factor=1.0):
        """The sensor signal of a force, causal, same length and instants; the filter starts
        at rest under the first sample (as :func:`cmsim.sensors.housing_acceleration`), so a
        record does not start with the step from zero to its first force.

        Parameters
        ----------
        force : array_like, shape (n,)
            Model force, N, sampled at ``fs_hz``.
        fs_hz : float
            Sample rate, Hz.
        frequency_factor : float
            Scale of the path's frequencies (1: as calibrated).

        Returns
        -------
        numpy.ndarray, shape (n,)
            Sensor unit.
        """
        x = np.asarray(force, dtype=float)
        x = x - x[0]
        return oaconvolve(x, self.fir(fs_hz, frequency_factor))[: x.size]

    def to_dict(self):
        """Plain dict for the machine file."""
        return {"source": self.source, "unit": self.unit, "freq_hz": list(self.freq_hz),
                "gain": list(self.gain)}


def smooth_log(values, freq_hz, octave_fraction):
    """Running mean of ``values`` (on the uniform grid ``freq_hz``) over ±
    ``octave_fraction``/2 octave around each frequency (at least ± 2 bins)."""
    v = np.asarray(values, dtype=float)
    f = np.asarray(freq_hz, dtype=float)
    df = f[1] - f[0]
    c = np.concatenate([[0.0], np.cumsum(v)])
    half = np.maximum(2, np.round(f * (2.0 ** (octave_fraction / 2) - 1.0) / df)).astype(int)
    lo = np.clip(np.arange(v.size) - half, 0, v.size - 1)
    hi = np.clip(np.arange(v.size) + half, 0, v.size - 1) + 1
    return (c[hi] - c[lo]) / (hi - lo)
