"""Operating-condition faults: a fluctuating input speed and a rippling load torque.

Both are relative modulations, vectorised over time, handed to the dynamics as callables by
:func:`~cmsim.faults.compile.operating_modulation`:

    speed(t) = speed_rpm · (1 + Σ_k ε_k sin(2π f_k t + φ_k))
    torque(t) = torque_nm · (1 + Σ_k ε_k sin(2π f_k t + φ_k))

A single line is given by ``relative_amplitude``, ``frequency_hz`` (or, for the torque,
``order`` of a shaft rate) and ``phase_rad``; a spectrum by ``spectrum``, rows of
(frequency Hz, relative amplitude, phase rad). Motor torque ripple, coupling misalignment and
a cyclic load show up this way (Feng & Zuo [1]); the sum of relative amplitudes is kept below
0.5 so the speed never reverses.

References
----------
.. [1] Z. Feng, M. J. Zuo, "Vibration signal models for fault diagnosis of planetary
   gearboxes", J. Sound Vib. 331 (2012) 4919-4939 (amplitude and frequency modulation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError, check_range
from cmsim.faults.base import Fault, check_angle, register

__all__ = ["SpeedFluctuation", "TorqueRipple", "MAX_TOTAL_RELATIVE_AMPLITUDE"]

#: Largest Σ ε_k: the modulated speed or torque stays above half its mean.
MAX_TOTAL_RELATIVE_AMPLITUDE = 0.5


def _check_frequency(name, value):
    """A line's frequency, Hz, in (0, 100 kHz]."""
    return check_range(name, value, 0.0, 1e5, lo_open=True, unit="Hz")


def _check_spectrum(spectrum):
    rows = []
    for i, row in enumerate(spectrum):
        if len(row) != 3:
            raise ParameterError(f"spectrum[{i}] must be (frequency_hz, relative_amplitude, "
                                 f"phase_rad), got {row!r}", param="spectrum")
        f = _check_frequency(f"spectrum[{i}] frequency_hz", row[0])
        a = check_range(f"spectrum[{i}] relative_amplitude", row[1], 0.0,
                        MAX_TOTAL_RELATIVE_AMPLITUDE)
        p = check_angle(f"spectrum[{i}] phase_rad", row[2])
        rows.append((f, a, p))
    return tuple(rows)


@dataclass(frozen=True)
class _Modulation(Fault):
    """Common checks and evaluation of a relative sinusoidal modulation.

    Subclasses hold ``relative_amplitude``, ``phase_rad`` and ``spectrum`` and say how their
    single line's frequency is given (:meth:`_check_line`) and what else they check
    (:meth:`_check_fields`).
    """

    def __post_init__(self):
        check_range("relative_amplitude", self.relative_amplitude, 0.0,
                    MAX_TOTAL_RELATIVE_AMPLITUDE)
        check_angle("phase_rad", self.phase_rad)
        object.__setattr__(self, "spectrum", _check_spectrum(self.spectrum))
        self._check_fields()
        if self.relative_amplitude > 0:
            self._check_line()
        elif not self.spectrum:
            raise ParameterError("relative_amplitude must be > 0 (or give a spectrum)",
                                 param="relative_amplitude", allowed="in (0, 0.5]")
        total = sum([self.relative_amplitude] + [a for _, a, _ in self.spectrum])
        if total > MAX_TOTAL_RELATIVE_AMPLITUDE:
            raise ParameterError(
                f"relative_amplitude must sum to at most {MAX_TOTAL_RELATIVE_AMPLITUDE:g} "
                f"over all lines, got {total:g}", param="relative_amplitude",
                allowed=f"a total in [0, {MAX_TOTAL_RELATIVE_AMPLITUDE:g}]")

    def _check_fields(self):
        """Checks of the subclass's own fields (none by default)."""

    def _check_line(self):
        """Check how the single line's frequency is given (``relative_amplitude > 0``)."""
        raise NotImplementedError

    def factor(self, t, shaft_hz=None):
        """1 + Σ ε_k sin(2π f_k t + φ_k) at times ``t`` (s), same shape as ``t``."""
        t = np.asarray(t, dtype=float)
        out = np.ones_like(t)
        for f, a, p in self.lines(shaft_hz):
            out += a * np.sin(2 * math.pi * f * t + p)
        return out


@register
@dataclass(frozen=True)
class SpeedFluctuation(_Modulation):
    """Sinusoidal wobble (or a given spectrum) of the imposed input speed.

    Attributes
    ----------
    relative_amplitude : float
        ε of the single line (0.01 = ±1 % of the speed), in [0, 0.5].
    frequency_hz : float or None
        Frequency of the single line, Hz (> 0); required unless ``spectrum`` is given.
    phase_rad : float
        Phase of the single line, rad.
    spectrum : tuple of (float, float, float)
        Further lines (frequency Hz, relative amplitude, phase rad).
    """

    name = "speed_fluctuation"

    relative_amplitude: float = 0.0
    frequency_hz: float | None = None
    phase_rad: float = 0.0
    spectrum: tuple = ()

    def _check_line(self):
        if self.frequency_hz is None:
            raise ParameterError("frequency_hz must be given with relative_amplitude "
                                 "(a number > 0 Hz)", param="frequency_hz", allowed="> 0 Hz")
        _check_frequency("frequency_hz", self.frequency_hz)

    def lines(self, shaft_hz=None):
        """All lines as (frequency Hz, relative amplitude, phase rad)."""
        own = ((float(self.frequency_hz), self.relative_amplitude, self.phase_rad),) \
            if self.relative_amplitude > 0 else ()
        return own + self.spectrum

    @property
    def label(self):
        return "speed_fluctuation " + " ".join(f"{100 * a:.3g}%@{f:.4g}Hz"
                                               for f, a, _ in self.lines())


@register
@dataclass(frozen=True)
class TorqueRipple(_Modulation):
    """Ripple of the load torque at a frequency, an order of a shaft rate, or a spectrum.

    Attributes
    ----------
    relative_amplitude : float
        ε of the single line, in [0, 0.5].
    frequency_hz : float or None
        Frequency of the single line, Hz; or give ``order``.
    order : float or None
        The single line at ``order`` × the rate of shaft ``shaft`` (needs the operating point).
    shaft : int
        1 (input) or 2 (output) for ``order``.
    phase_rad : float
        Phase of the single line, rad.
    spectrum : tuple of (float, float, float)
        Further lines (frequency Hz, relative amplitude, phase rad).
    """

    name = "torque_ripple"

    relative_amplitude: float = 0.0
    frequency_hz: float | None = None
    order: float | None = None
    shaft: int = 1
    phase_rad: float = 0.0
    spectrum: tuple = ()

    def _check_fields(self):
        if self.shaft not in (1, 2) or isinstance(self.shaft, bool):
            raise ParameterError(f"shaft must be 1 or 2, got {self.shaft!r}", param="shaft",
                                 allowed="1 or 2")

    def _check_line(self):
        if (self.frequency_hz is None) == (self.order is None):
            raise ParameterError("give exactly one of frequency_hz and order with "
                                 "relative_amplitude", param="frequency_hz",
                                 allowed="frequency_hz > 0 Hz or order > 0")
        if self.frequency_hz is not None:
            _check_frequency("frequency_hz", self.frequency_hz)
        else:
            check_range("order", self.order, 0.0, 1e3, lo_open=True)

    def lines(self, shaft_hz=None):
        """All lines as (frequency Hz, relative amplitude, phase rad).

        Parameters
        ----------
        shaft_hz : dict or None
            ``{1: fr1_hz, 2: fr2_hz}``; required when the ripple is given as an order.
        """
        own = ()
        if self.relative_amplitude > 0:
            if self.order is not None:
                if not shaft_hz or self.shaft not in shaft_hz:
                    raise ParameterError("torque_ripple given as an order needs the "
                                         "operating point (op=...) to find the shaft rate",
                                         param="order")
                f = self.order * shaft_hz[self.shaft]
            else:
                f = float(self.frequency_hz)
            own = ((f, self.relative_amplitude, self.phase_rad),)
        return own + self.spectrum

    @property
    def label(self):
        if self.relative_amplitude > 0 and self.order is not None:
            head = f"{100 * self.relative_amplitude:.3g}%@{self.order:g}x{self.shaft}"
        elif self.relative_amplitude > 0:
            head = f"{100 * self.relative_amplitude:.3g}%@{self.frequency_hz:.4g}Hz"
        else:
            head = ""
        rest = " ".join(f"{100 * a:.3g}%@{f:.4g}Hz" for f, a, _ in self.spectrum)
        return " ".join(x for x in ("torque_ripple", head, rest) if x)
