"""The one table of allowed ranges: every layer and the command line read it.

A value that a user gives in several places — an operating point, a sweep variation, a
dataset spec, a command-line option — is checked against the same :class:`Range` of
:data:`RANGES`, so what one front end allows the others allow too, with the same message
(``torque_nm must be a number in [0, 1e+06] N m, got -1``). Ranges that depend on other
values (a bearing's clearance against its ball diameter, a gear's bore against its root
circle) are checked by the component itself on top of these.

The bounds are plausibility bounds, far beyond any gearbox or bearing test rig (the paper's
rig: 28 teeth, 6.24e8 N/m shafts, 4e5 N·m/rad couplings, k_RE ~ 1e10 N/m^1.5, 0.8 kg
gears): a value outside them is a typing or unit error, or would need an absurdly small
integration step.

Examples
--------
>>> RANGES["torque_nm"].check("torque_nm", 10)
10.0
>>> RANGES["friction"].allowed
'a number in [0, 0.3]'
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

from cmsim.errors import ParameterError, check_range, format_range, format_value, within

__all__ = ["Range", "RANGES", "MAX_TEETH", "MAX_MASS_KG", "MAX_INERTIA_KG_M2",
           "MAX_DAMPING_N_S_PER_M", "MAX_CONTACT_STIFFNESS", "MAX_TRANSLATIONAL_STIFFNESS",
           "MAX_TORSIONAL_STIFFNESS", "MAX_TORSIONAL_DAMPING"]

#: Most teeth of a gear.
MAX_TEETH = 1000
#: Largest lumped mass, kg.
MAX_MASS_KG = 1.0e5
#: Largest polar inertia, kg·m².
MAX_INERTIA_KG_M2 = 1.0e4
#: Largest translational damping, N·s/m.
MAX_DAMPING_N_S_PER_M = 1.0e8
#: Largest ball contact stiffness k_RE, N/m^p.
MAX_CONTACT_STIFFNESS = 1.0e14
#: Largest translational (shaft bending) stiffness, N/m.
MAX_TRANSLATIONAL_STIFFNESS = 1.0e12
#: Largest torsional stiffness, N·m/rad.
MAX_TORSIONAL_STIFFNESS = 1.0e10
#: Largest torsional damping, N·m·s/rad.
MAX_TORSIONAL_DAMPING = 1.0e6


@dataclass(frozen=True)
class Range:
    """An allowed interval of one parameter.

    Attributes
    ----------
    lo, hi : float
        Bounds (infinite: unbounded on that side; infinity itself is always refused).
    lo_open, hi_open : bool
        Whether the bound itself is excluded.
    unit : str
        Unit shown in messages (``"N m"``).
    integer : bool
        Whether the value must be a whole number.
    """

    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False
    unit: str = ""
    integer: bool = False

    @property
    def allowed(self):
        """The range as a user reads it: ``"a number in [0, 0.3]"``."""
        return format_range(self.lo, self.hi, lo_open=self.lo_open, hi_open=self.hi_open,
                            unit=self.unit, integer=self.integer)

    def contains(self, value):
        """True when ``value`` is a finite number within the range (integral if required)."""
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            return False
        v = float(value)
        if self.integer and math.isfinite(v) and v != int(v):
            return False
        return within(v, self.lo, self.hi, lo_open=self.lo_open, hi_open=self.hi_open)

    def check(self, name, value):
        """``value`` as a float (an int for an integer range), or a
        :class:`~cmsim.errors.ParameterError` naming ``name`` and the range.

        Parameters
        ----------
        name : str
            The parameter's name as the caller knows it (recorded as the error's ``param``).
        value : object
            The value to check.
        """
        if self.integer:
            if isinstance(value, bool) or not isinstance(value, numbers.Integral) \
                    or not self.contains(value):
                raise ParameterError(f"{name} must be {self.allowed}, got "
                                     f"{format_value(value)}", param=name,
                                     allowed=self.allowed)
            return int(value)
        return check_range(name, value, self.lo, self.hi, lo_open=self.lo_open,
                           hi_open=self.hi_open, unit=self.unit)


#: Name → range of every value a user sets in more than one place (operating point, rig
#: settings a sweep or dataset varies, sampling, slip, sensor noise). The names are the ones
#: users type (``friction`` is :attr:`MeshContact.friction_coefficient
#: <cmsim.rig.MeshContact.friction_coefficient>`).
RANGES = {
    # operating point (OperatingPoint)
    "speed_rpm": Range(0.0, 1.0e5, lo_open=True, unit="rpm"),
    "torque_nm": Range(0.0, 1.0e6, unit="N m"),
    "radial_load_n": Range(0.0, 1.0e7, unit="N"),
    "radial_load_angle_rad": Range(-2 * math.pi, 2 * math.pi, unit="rad"),
    # rig settings a run, a sweep or a dataset varies
    "friction": Range(0.0, 0.3),
    "clearance_m": Range(-1.0e-3, 1.0e-3, unit="m"),
    # sampling of a run
    "duration_s": Range(0.0, 600.0, lo_open=True, unit="s"),
    "fs_hz": Range(1.0e3, 1.0e7, unit="Hz"),
    "warmup_s": Range(0.0, 60.0, unit="s"),
    "substeps": Range(1, 1000, integer=True),
    "seed": Range(0, 2 ** 32 - 1, integer=True),
    # random rolling slip
    "cage_slip": Range(0.0, 0.2),
    "ball_jitter_rad": Range(0.0, 0.05, unit="rad"),
    "slip_correlation_s": Range(1.0e-5, 10.0, unit="s"),
    # housing sensors
    "sensor_noise_m_s2": Range(0.0, 1.0e6, unit="m/s^2"),
    # what a measured recording's metadata.json states (cmsim.measured.schema); its sample
    # rate may be below a simulation's (a slow machine logged at a few hundred Hz)
    "record_fs_hz": Range(0.0, 1.0e7, lo_open=True, unit="Hz"),
    "shaft_speed_hz": Range(0.0, 1.0e5 / 60.0, lo_open=True, unit="Hz"),
    "motor_load_hp": Range(0.0, 1.0e5, unit="hp"),
    "radial_load_lbs": Range(0.0, 2.2e6, unit="lbf"),
    "load_percent": Range(0.0, 200.0, unit="%"),
    "n_samples": Range(1, 1.0e12, integer=True),
    # physical units per stored sample value of a recording (a WAV in counts or volts)
    "calibration": Range(0.0, 1.0e12, lo_open=True),
    # processes of a job (a sweep, a dataset, a comparison's runs)
    "workers": Range(1, 256, integer=True),
}
