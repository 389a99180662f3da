"""The steady operating point: input speed, output torque, radial load."""

from __future__ import annotations

import math
from dataclasses import dataclass

from cmsim.rig.ranges import RANGES

__all__ = ["OperatingPoint"]


@dataclass(frozen=True)
class OperatingPoint:
    """Steady operating condition.

    Attributes
    ----------
    speed_rpm : float
        Imposed speed of the input shaft, rpm (> 0).
    torque_nm : float
        Load torque on the output inertia, N·m (>= 0; ignored without gears).
    radial_load_n : float
        Static radial force on the centre node of shaft 1 (rotor rigs), N (>= 0).
    radial_load_angle_rad : float
        Direction of that force in the x-y frame, rad (−π/2 = −y, "down").
    """

    speed_rpm: float
    torque_nm: float = 0.0
    radial_load_n: float = 0.0
    radial_load_angle_rad: float = -math.pi / 2

    def __post_init__(self):
        for name in ("speed_rpm", "torque_nm", "radial_load_n", "radial_load_angle_rad"):
            RANGES[name].check(name, getattr(self, name))

    @property
    def omega_rad_s(self):
        """Input shaft speed, rad/s."""
        return self.speed_rpm * math.pi / 30.0

    @property
    def shaft_hz(self):
        """Input shaft rotation frequency, Hz."""
        return self.speed_rpm / 60.0
