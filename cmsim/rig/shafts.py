"""Shafts and couplings: a shaft line of two bearing nodes and a centre node, the rotor disk
of a bearing rig, and the torsional couplings at the ends.
"""

from __future__ import annotations

from dataclasses import dataclass

from cmsim.errors import ParameterError, check_range
from cmsim.rig.bearing import RollingBearing
from cmsim.rig.ranges import (MAX_DAMPING_N_S_PER_M, MAX_INERTIA_KG_M2, MAX_MASS_KG,
                              MAX_TORSIONAL_DAMPING, MAX_TORSIONAL_STIFFNESS,
                              MAX_TRANSLATIONAL_STIFFNESS)

__all__ = ["Rotor", "ShaftLine", "Coupling"]

_SHAFT_MAX = {"flexural_stiffness_n_per_m": MAX_TRANSLATIONAL_STIFFNESS,
              "flexural_damping_n_s_per_m": MAX_DAMPING_N_S_PER_M,
              "torsional_stiffness_nm_per_rad": MAX_TORSIONAL_STIFFNESS,
              "torsional_damping_nm_s_per_rad": MAX_TORSIONAL_DAMPING}


@dataclass(frozen=True)
class Rotor:
    """A rigid disk lumped at the centre node of a shaft without gears.

    Attributes
    ----------
    mass_kg : float
        Mass, kg.
    inertia_kg_m2 : float
        Polar moment of inertia, kg·m².
    """

    mass_kg: float
    inertia_kg_m2: float

    def __post_init__(self):
        check_range("mass_kg", self.mass_kg, 0.0, MAX_MASS_KG, lo_open=True, unit="kg")
        check_range("inertia_kg_m2", self.inertia_kg_m2, 0.0, MAX_INERTIA_KG_M2, lo_open=True,
                    unit="kg m^2")


@dataclass(frozen=True)
class ShaftLine:
    """One shaft: node ``b1`` (bearing 1) — centre node (gear or rotor) — node ``b2``.

    Attributes
    ----------
    bearing_1, bearing_2 : RollingBearing
        Bearings at nodes b1 and b2.
    flexural_stiffness_n_per_m : tuple of float
        Translational stiffness of the segments b1-centre and centre-b2, N/m.
    flexural_damping_n_s_per_m : tuple of float
        Translational damping of the two segments, N·s/m.
    torsional_stiffness_nm_per_rad : tuple of float
        Torsional stiffness of the two segments, N·m/rad.
    torsional_damping_nm_s_per_rad : tuple of float
        Torsional damping of the two segments, N·m·s/rad.
    rotor : Rotor or None
        Disk at the centre node when the shaft carries no gear.
    """

    bearing_1: RollingBearing
    bearing_2: RollingBearing
    flexural_stiffness_n_per_m: tuple[float, float] = (6.24e8, 6.24e8)
    flexural_damping_n_s_per_m: tuple[float, float] = (31.6, 31.6)
    torsional_stiffness_nm_per_rad: tuple[float, float] = (4.0e5, 4.0e5)
    torsional_damping_nm_s_per_rad: tuple[float, float] = (0.0, 0.0)
    rotor: Rotor | None = None

    def __post_init__(self):
        for name in ("flexural_stiffness_n_per_m", "flexural_damping_n_s_per_m",
                     "torsional_stiffness_nm_per_rad", "torsional_damping_nm_s_per_rad"):
            raw = getattr(self, name)
            try:
                if isinstance(raw, (str, bytes)) or any(isinstance(x, bool) for x in raw):
                    raise TypeError
                v = tuple(float(x) for x in raw)
            except (TypeError, ValueError):
                raise ParameterError(f"{name} needs two numbers (segment b1-centre, "
                                     f"centre-b2), got {raw!r}", param=name) from None
            if len(v) != 2:
                raise ParameterError(f"{name} needs two values (segment b1-centre, centre-b2), "
                                     f"got {len(v)}", param=name)
            lo_open = "stiffness" in name
            hi = _SHAFT_MAX[name]
            for x in v:
                check_range(name, x, 0.0, hi, lo_open=lo_open)
            object.__setattr__(self, name, v)

    @property
    def bearings(self):
        """(bearing_1, bearing_2)."""
        return (self.bearing_1, self.bearing_2)


@dataclass(frozen=True)
class Coupling:
    """A torsional coupling (spring + viscous damper).

    Attributes
    ----------
    stiffness_nm_per_rad : float
        Torsional stiffness, N·m/rad.
    damping_nm_s_per_rad : float
        Torsional damping, N·m·s/rad.
    """

    stiffness_nm_per_rad: float = 4.0e5
    damping_nm_s_per_rad: float = 3.5761

    def __post_init__(self):
        check_range("stiffness_nm_per_rad", self.stiffness_nm_per_rad, 0.0,
                    MAX_TORSIONAL_STIFFNESS, lo_open=True, unit="N m/rad")
        check_range("damping_nm_s_per_rad", self.damping_nm_s_per_rad, 0.0,
                    MAX_TORSIONAL_DAMPING, unit="N m s/rad")
