"""A machine's background: what its sensor records that the model's forces do not make.

Two parts, both measured on a healthy baseline (:mod:`cmsim.machine.calibration`):

* a **coloured noise** of one-sided power spectral density ``psd`` (sensor unit²/Hz) on a
  frequency grid: the broadband part of the baseline the model's healthy force leaves
  unexplained (flow, other machinery, the sensor's own floor). It is synthesised as Gaussian
  noise shaped in the frequency domain (the variance of a record is ∫ psd df);
* **deterministic lines** the model does not make, each a sinusoid at its own amplitude and
  a random phase per record: shaft orders of the input or output shaft (unbalance,
  misalignment, run-out, the motor), which follow the speed of the record, and lines at a
  fixed frequency (the mains and its harmonics, other machines).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError

__all__ = ["Background", "BackgroundLine", "LINE_REFERENCES", "sum_of_cosines"]

#: What a line's frequency follows: the input shaft's order, the output shaft's, or nothing.
LINE_REFERENCES = ("input", "output", "fixed")


@dataclass(frozen=True)
class BackgroundLine:
    """One deterministic line of the background.

    Attributes
    ----------
    reference : str
        ``"input"`` or ``"output"`` (``value`` is an order of that shaft's rate) or
        ``"fixed"`` (``value`` is a frequency, Hz).
    value : float
        Order or frequency, Hz.
    amplitude : float
        Amplitude of the sinusoid, sensor unit.
    """

    reference: str
    value: float
    amplitude: float

    def __post_init__(self):
        if self.reference not in LINE_REFERENCES:
            raise ParameterError(f"line reference must be one of {LINE_REFERENCES}, got "
                                 f"{self.reference!r}", param="reference")
        if not (math.isfinite(self.value) and self.value > 0):
            raise ParameterError(f"line value must be > 0, got {self.value!r}", param="value")
        if not (math.isfinite(self.amplitude) and self.amplitude >= 0):
            raise ParameterError(f"line amplitude must be >= 0, got {self.amplitude!r}",
                                 param="amplitude")

    def frequency_hz(self, shaft_hz):
        """The line's frequency, Hz, for the input/output shaft rates ``shaft_hz`` (a pair)."""
        if self.reference == "fixed":
            return self.value
        return self.value * shaft_hz[0 if self.reference == "input" else 1]


@dataclass(frozen=True)
class Background:
    """The background of a machine's sensor.

    Attributes
    ----------
    freq_hz : tuple of float
        Frequency grid of ``psd``, Hz, increasing from 0.
    psd : tuple of float
        One-sided power spectral density of the coloured noise, sensor unit²/Hz (>= 0).
    lines : tuple of BackgroundLine
        Deterministic lines.
    """

    freq_hz: tuple
    psd: tuple
    lines: tuple = ()

    def __post_init__(self):
        f = np.asarray(self.freq_hz, dtype=float)
        p = np.asarray(self.psd, dtype=float)
        if f.ndim != 1 or f.size < 2 or f.shape != p.shape or not np.all(np.diff(f) > 0):
            raise ParameterError("a background needs an increasing freq_hz and a psd of the "
                                 "same length", param="background")
        if not (np.all(np.isfinite(p)) and np.all(p >= 0)):
            raise ParameterError("background psd must be finite and >= 0", param="background")
        object.__setattr__(self, "freq_hz", tuple(float(x) for x in f))
        object.__setattr__(self, "psd", tuple(float(x) for x in p))
        object.__setattr__(self, "lines", tuple(self.lines))

    def noise_rms(self, fs_hz):
        """RMS of the coloured noise up to the Nyquist frequency of ``fs_hz``: √∫ psd df."""
        f = np.asarray(self.freq_hz)
        keep = f <= 0.5 * fs_hz
        f, p = f[keep], np.asarray(self.psd)[keep]
        return float(np.sqrt(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(f))))

    def noise(self, n, fs_hz, rng, gain=1.0):
        """``n`` samples of the coloured noise at ``fs_hz`` (``gain`` scales its RMS).

        Parameters
        ----------
        n : int
            Samples.
        fs_hz : float
            Sample rate, Hz.
        rng : numpy.random.Generator
            Source of the noise.
        gain : float
            Factor on the amplitude.

        Returns
        -------
        numpy.ndarray, shape (n,)
        """
        spec = np.fft.rfft(rng.standard_normal(n))
        f = np.fft.rfftfreq(n, 1.0 / fs_hz)
        psd = np.interp(f, self.freq_hz, self.psd, right=0.0)
        # white unit-variance noise has a one-sided density 2/fs: rescale to psd
        return gain * np.fft.irfft(spec * np.sqrt(psd * fs_hz / 2.0), n)

    def deterministic(self, n, fs_hz, shaft_hz, rng, gain=1.0):
        """``n`` samples at ``fs_hz`` (from t = 0) of the lines at shaft rates ``shaft_hz`` =
        (input, output) Hz, each with a phase drawn from ``rng`` in the lines' order;
        ``gain`` scales them.

        Parameters
        ----------
        n, fs_hz, shaft_hz
            As :meth:`synthesize`.
        rng : numpy.random.Generator
            Source of the phases, one per line.
        gain : float
            Factor on the amplitudes.

        Returns
        -------
        numpy.ndarray, shape (n,)
        """
        if not self.lines:
            return np.zeros(n)
        freq = np.array([line.frequency_hz(shaft_hz) for line in self.lines])
        amp = gain * np.array([line.amplitude for line in self.lines])
        phase = rng.uniform(0.0, 2.0 * math.pi, len(self.lines))
        return sum_of_cosines(freq, amp, phase, n, fs_hz)

    def synthesize(self, n, fs_hz, shaft_hz, rng, noise_gain=1.0, line_gain=1.0,
                   line_rng=None):
        """``n`` samples of the whole background (noise plus lines).

        Parameters
        ----------
        n : int
            Samples.
        fs_hz : float
            Sample rate, Hz.
        shaft_hz : tuple of float
            (input, output) shaft rates, Hz (the output's may equal the input's).
        rng : numpy.random.Generator
            Source of the noise and of the line phases.
        noise_gain, line_gain : float
            Factors on the noise and on the lines.
        line_rng : numpy.random.Generator, optional
            Source of the line phases apart from the noise's (default ``rng``, after it).

        Returns
        -------
        numpy.ndarray, shape (n,)
        """
        return (self.noise(n, fs_hz, rng, noise_gain)
                + self.deterministic(n, fs_hz, shaft_hz, rng if line_rng is None else line_rng,
                                     line_gain))

    def to_dict(self):
        """Plain dict for the machine file."""
        return {"freq_hz": list(self.freq_hz), "psd": list(self.psd),
                "lines": [{"reference": ln.reference, "value": ln.value,
                           "amplitude": ln.amplitude} for ln in self.lines]}


def sum_of_cosines(freq_hz, amplitude, phase_rad, n, fs_hz):
    """Σ_l a_l·cos(2π·f_l·k/fs + φ_l) at the samples k = 0 … n − 1.

    The instants are split as k = i·B + j (B ≈ √n): e^{iω k} = e^{iω i B}·e^{iω j}, so the sum
    over the lines is one complex matrix product of an (n/B × L) and an (L × B) table instead
    of L·n cosines (89 lines of a 12 000-sample record: 0.5 ms instead of 11). Each factor is
    an exponential of its own argument, so the phase is as exact as the direct cosine's
    (its argument reaches 2π·f·T, rounded alike).

    Parameters
    ----------
    freq_hz, amplitude, phase_rad : array_like, shape (L,)
        The lines.
    n : int
        Samples.
    fs_hz : float
        Sample rate, Hz.

    Returns
    -------
    numpy.ndarray, shape (n,)

    Examples
    --------
    >>> x = sum_of_cosines([50.0], [2.0], [0.0], 4, 200.0)
    >>> [float(round(v, 12)) + 0.0 for v in x]
    [2.0, 0.0, -2.0, 0.0]
    """
    w = 2.0 * math.pi * np.asarray(freq_hz, dtype=float) / fs_hz
    c = np.asarray(amplitude, dtype=float) * np.exp(1j * np.asarray(phase_rad, dtype=float))
    b = max(1, math.isqrt(max(int(n), 1)))
    rows = -(-int(n) // b)
    outer = c[None, :] * np.exp(1j * np.outer(np.arange(rows) * float(b), w))
    inner = np.exp(1j * np.outer(w, np.arange(b, dtype=float)))
    return (outer @ inner).real.reshape(-1)[:n]
