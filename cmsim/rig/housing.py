"""The housing transfer path from a bearing force to the acceleration at that bearing."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError, check_range
from cmsim.rig.ranges import MAX_MASS_KG

__all__ = ["HousingPath"]


@dataclass(frozen=True)
class HousingPath:
    """Transfer path from a bearing force to the housing acceleration at that bearing.

    A sum of damped housing modes (accelerance, a force in N gives an acceleration in m/s²)::

        H(s) = Σ_k s² / (m_k (s² + 2 ζ_k ω_k s + ω_k²)),   ω_k = 2π f_k

    Each mode is the accelerance of a mass m_k on a spring: ω²/k_k below its resonance (a
    stiff housing barely moves at the shaft rate), 1/(2 ζ_k m_k) at resonance, the mass line
    1/m_k above. The path is the same for every bearing and for the x and y directions
    (``accel_<bearing>_x`` from ``F_<bearing>_x``); :func:`cmsim.sensors.housing_acceleration`
    applies it.

    The defaults are generic, not fitted to any record: three modes at 2.5, 4.0 and 5.5 kHz
    (the 2-6 kHz band where the housings and end shields of small motors and gearboxes, and
    stud-mounted accelerometers on them, ring under bearing impacts — the band where envelope
    analysis of such machines usually finds the fault, Randall & Antoni 2011), ζ = 0.03 (the
    2-5 % of bolted steel structures) and modal masses of 2 kg (the order of a small motor's
    end shield or a gearbox wall): a peak accelerance of 8.3 (m/s²)/N per mode. All three
    lie below the 6 kHz Nyquist frequency of a 12 kHz acquisition.

    Attributes
    ----------
    natural_frequencies_hz : tuple of float
        Mode frequencies f_k, Hz, each in (0, 1 MHz).
    damping_ratios : tuple of float
        Modal damping ratios ζ_k, each in (0, 0.5]; one per mode.
    modal_masses_kg : tuple of float
        Modal masses m_k, kg (> 0); the accelerance at resonance is 1/(2 ζ_k m_k).

    References
    ----------
    .. [1] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial",
       MSSP 25 (2011) 485-520.
    .. [2] P. D. McFadden, J. D. Smith, "Model for the vibration produced by a single point
       defect in a rolling element bearing", J. Sound Vib. 96 (1984) 69-82.
    """

    natural_frequencies_hz: tuple[float, ...] = (2500.0, 4000.0, 5500.0)
    damping_ratios: tuple[float, ...] = (0.03, 0.03, 0.03)
    modal_masses_kg: tuple[float, ...] = (2.0, 2.0, 2.0)

    def __post_init__(self):
        for name in ("natural_frequencies_hz", "damping_ratios", "modal_masses_kg"):
            value = getattr(self, name)
            if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
                raise ParameterError(f"{name} must be a list of numbers, got {value!r}",
                                     param=name, allowed="a list of numbers")
            object.__setattr__(self, name, tuple(value))
        n = len(self.natural_frequencies_hz)
        if not 1 <= n <= 20:
            raise ParameterError(f"natural_frequencies_hz must list 1 to 20 modes, got {n}",
                                 param="natural_frequencies_hz", allowed="1 to 20 modes")
        for name in ("damping_ratios", "modal_masses_kg"):
            if len(getattr(self, name)) != n:
                raise ParameterError(f"{name} must have one value per mode ({n}), got "
                                     f"{len(getattr(self, name))}", param=name,
                                     allowed=f"{n} values")
        checked = (
            ("natural_frequencies_hz", dict(lo=0.0, hi=1.0e6, hi_open=True, unit="Hz")),
            ("damping_ratios", dict(lo=0.0, hi=0.5)),
            ("modal_masses_kg", dict(lo=0.0, hi=MAX_MASS_KG, unit="kg")))
        for name, bounds in checked:
            object.__setattr__(self, name, tuple(
                check_range(f"{name}[{k}]", v, lo_open=True, **bounds)
                for k, v in enumerate(getattr(self, name))))

    @property
    def n_modes(self):
        """Number of housing modes."""
        return len(self.natural_frequencies_hz)

    def accelerance(self, freq_hz):
        """Closed-form accelerance H(j·2πf), (m/s²)/N, complex, same shape as ``freq_hz``."""
        s = 2j * math.pi * np.asarray(freq_hz, dtype=float)
        out = np.zeros(s.shape, dtype=complex)
        for f, z, m in zip(self.natural_frequencies_hz, self.damping_ratios,
                           self.modal_masses_kg):
            w = 2.0 * math.pi * f
            out += s ** 2 / (m * (s ** 2 + 2.0 * z * w * s + w ** 2))
        return out
