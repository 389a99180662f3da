"""Parameters of a transmission: gears, bearings, shafts, lubricant, operating point.

Every class is a frozen dataclass in SI units (m, kg, N, s, rad, Pa·s); field names carry the
unit. Build variants with :func:`dataclasses.replace` or the ``with_*`` helpers, never by
mutation. :meth:`Rig.paper_2016` holds Tables 1-3 of Fernandez-del-Rincon et al. (2016).

Two topologies are supported:

* a gear rig: two shafts (``1`` driving, ``2`` driven), each ``b1 - G1 - b2`` on two ball
  bearings, one spur-gear pair, an imposed input speed through a torsional coupling on
  ``1b1`` and a load torque on an output inertia ``2J2`` coupled to ``2b2`` (19 DOF);
* a bearing rig: one shaft ``b1 - D1 - b2`` carrying a rotor disk, driven at constant speed,
  with a static radial load on the disk (9 DOF) — e.g. the CWRU and MFPT test rigs.

References
----------
.. [1] A. Fernandez-del-Rincon et al., "Enhanced model of gear transmission dynamics for
   condition monitoring applications: effects of torque, friction and bearing clearance",
   MSSP 85 (2017) 445-467 (preprint 2016), Tables 1-3.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import tomli_w

from cmsim._io import atomic_write_text
from cmsim.errors import ParameterError, check_range

__all__ = [
    "SpurGear", "GearPair", "RollingBearing", "Rotor", "ShaftLine", "Coupling",
    "Lubricant", "MeshContact", "OperatingPoint", "HousingPath", "Rig", "RIG_FORMAT_VERSION",
]

RIG_FORMAT_VERSION = 1

_DEG = math.pi / 180.0

# Plausibility bounds: far beyond any gearbox or bearing test rig (the paper's rig: 28 teeth,
# 6.24e8 N/m shafts, 4e5 N m/rad couplings, k_RE ~ 1e10 N/m^1.5, 0.8 kg gears), so a value
# outside them is a typing or unit error; the integrator would need an absurdly small step.
MAX_TEETH = 1000
MAX_MASS_KG = 1.0e5
MAX_INERTIA_KG_M2 = 1.0e4
MAX_DAMPING_N_S_PER_M = 1.0e8
MAX_CONTACT_STIFFNESS = 1.0e14
MAX_TRANSLATIONAL_STIFFNESS = 1.0e12
MAX_TORSIONAL_STIFFNESS = 1.0e10
MAX_TORSIONAL_DAMPING = 1.0e6
_SHAFT_MAX = {"flexural_stiffness_n_per_m": MAX_TRANSLATIONAL_STIFFNESS,
              "flexural_damping_n_s_per_m": MAX_DAMPING_N_S_PER_M,
              "torsional_stiffness_nm_per_rad": MAX_TORSIONAL_STIFFNESS,
              "torsional_damping_nm_s_per_rad": MAX_TORSIONAL_DAMPING}


def _involute(alpha):
    return math.tan(alpha) - alpha


def _inverse_involute(value):
    """Angle whose involute function equals ``value`` (Newton, converges in <10 steps)."""
    a = (3.0 * value) ** (1.0 / 3.0) if value > 0 else 0.0
    for _ in range(50):
        f = math.tan(a) - a - value
        a_new = a - f / (math.tan(a) ** 2)
        if abs(a_new - a) < 1e-15:
            break
        a = a_new
    return a


@dataclass(frozen=True)
class SpurGear:
    """A spur gear cut by a rack with rounded tips.

    Attributes
    ----------
    n_teeth : int
        Number of teeth, >= 6.
    module_m : float
        Module, m.
    face_width_m : float
        Face width, m.
    pressure_angle_rad : float
        Standard (rack) pressure angle, rad.
    profile_shift : float
        Profile shift coefficient x (rack offset x·m away from the gear centre).
    rack_addendum_coef : float
        Cutter (rack) addendum in modules; it forms the gear dedendum (Table 1: 1.25).
    rack_dedendum_coef : float
        Cutter (rack) dedendum in modules; it forms the gear addendum (Table 1: 1.0).
    rack_tip_radius_coef : float
        Cutter tip rounding radius in modules, forms the trochoidal root fillet (0.25).
    tip_radius_coef : float
        Gear tip rounding radius in modules (0.05).
    bore_radius_m : float
        Radius of the shaft bore (the gear body's inner boundary), m.
    mass_kg : float
        Lumped mass of the gear, kg.
    inertia_kg_m2 : float
        Polar moment of inertia of the gear, kg·m².
    youngs_modulus_pa : float
        Young's modulus, Pa.
    poisson_ratio : float
        Poisson's ratio.
    """

    n_teeth: int
    module_m: float
    face_width_m: float
    pressure_angle_rad: float = 20.0 * _DEG
    profile_shift: float = 0.0
    rack_addendum_coef: float = 1.25
    rack_dedendum_coef: float = 1.0
    rack_tip_radius_coef: float = 0.25
    tip_radius_coef: float = 0.05
    bore_radius_m: float = 0.02
    mass_kg: float = 0.79999
    inertia_kg_m2: float = 4.0408e-4
    youngs_modulus_pa: float = 210e9
    poisson_ratio: float = 0.3

    def __post_init__(self):
        if (not isinstance(self.n_teeth, (int, np.integer)) or isinstance(self.n_teeth, bool)
                or not 6 <= self.n_teeth <= MAX_TEETH):
            raise ParameterError(f"n_teeth must be an integer in [6, {MAX_TEETH}], got "
                                 f"{self.n_teeth!r}", allowed=f"an integer in [6, {MAX_TEETH}]")
        check_range("module_m", self.module_m, 0.0, 0.1, lo_open=True, unit="m")
        check_range("face_width_m", self.face_width_m, 0.0, 2.0, lo_open=True, unit="m")
        check_range("pressure_angle_rad", self.pressure_angle_rad, 10 * _DEG, 35 * _DEG,
                    unit="rad")
        check_range("profile_shift", self.profile_shift, -1.0, 1.5)
        check_range("rack_addendum_coef", self.rack_addendum_coef, 0.5, 2.0)
        check_range("rack_dedendum_coef", self.rack_dedendum_coef, 0.5, 2.0)
        check_range("rack_tip_radius_coef", self.rack_tip_radius_coef, 0.0, 0.5)
        check_range("tip_radius_coef", self.tip_radius_coef, 0.0, 0.3)
        check_range("mass_kg", self.mass_kg, 0.0, MAX_MASS_KG, lo_open=True, unit="kg")
        check_range("inertia_kg_m2", self.inertia_kg_m2, 0.0, MAX_INERTIA_KG_M2, lo_open=True,
                    unit="kg m^2")
        check_range("youngs_modulus_pa", self.youngs_modulus_pa, 1e9, 1e13, unit="Pa")
        check_range("poisson_ratio", self.poisson_ratio, 0.0, 0.5, hi_open=True)
        check_range("bore_radius_m", self.bore_radius_m, 0.0, self.root_radius_m, lo_open=True,
                    hi_open=True, unit="m (below the root circle)")
        if self.tip_radius_m <= self.base_radius_m:
            raise ParameterError(
                f"tip radius {self.tip_radius_m:g} m must exceed the base radius "
                f"{self.base_radius_m:g} m (check rack_dedendum_coef and profile_shift)")

    @property
    def pitch_radius_m(self):
        """Reference pitch radius m·Z/2, m."""
        return 0.5 * self.module_m * self.n_teeth

    @property
    def base_radius_m(self):
        """Base circle radius, m."""
        return self.pitch_radius_m * math.cos(self.pressure_angle_rad)

    @property
    def tip_radius_m(self):
        """Tip (addendum) circle radius, m."""
        return self.pitch_radius_m + self.module_m * (self.rack_dedendum_coef + self.profile_shift)

    @property
    def root_radius_m(self):
        """Root (dedendum) circle radius, m."""
        return self.pitch_radius_m - self.module_m * (self.rack_addendum_coef - self.profile_shift)

    @property
    def tip_rounding_m(self):
        """Gear tip rounding radius, m."""
        return self.tip_radius_coef * self.module_m

    @property
    def base_pitch_m(self):
        """Base pitch π·m·cos α, m."""
        return math.pi * self.module_m * math.cos(self.pressure_angle_rad)

    @property
    def tooth_angle_rad(self):
        """Angular pitch 2π/Z, rad."""
        return 2.0 * math.pi / self.n_teeth

    @property
    def base_half_thickness_angle_rad(self):
        """Half the angular tooth thickness at the base circle, rad.

        ψ_b = π/(2Z) + 2·x·tan α / Z + inv α.
        """
        a = self.pressure_angle_rad
        return (math.pi / (2 * self.n_teeth) + 2 * self.profile_shift * math.tan(a) / self.n_teeth
                + _involute(a))


@dataclass(frozen=True)
class GearPair:
    """A driving (pinion, shaft 1) and a driven (wheel, shaft 2) spur gear in mesh.

    Attributes
    ----------
    driving : SpurGear
        Gear on shaft 1 (input side).
    driven : SpurGear
        Gear on shaft 2 (output side).
    centre_distance_m : float or None
        Operating centre distance, m; ``None`` uses the zero-backlash working centre distance
        implied by the profile shifts.
    """

    driving: SpurGear
    driven: SpurGear
    centre_distance_m: float | None = None

    def __post_init__(self):
        if abs(self.driving.module_m - self.driven.module_m) > 1e-12 * self.driving.module_m:
            raise ParameterError("driving and driven gears must have the same module_m")
        if abs(self.driving.pressure_angle_rad - self.driven.pressure_angle_rad) > 1e-12:
            raise ParameterError("driving and driven gears must have the same pressure_angle_rad")
        a = self.working_centre_distance_m
        lo = self.driving.base_radius_m + self.driven.base_radius_m
        if self.centre_distance_m is not None:
            check_range("centre_distance_m", self.centre_distance_m, lo,
                        self.driving.tip_radius_m + self.driven.tip_radius_m,
                        lo_open=True, hi_open=True, unit="m")
        if self.contact_ratio < 1.0:
            raise ParameterError(
                f"contact ratio {self.contact_ratio:.3f} < 1 at centre distance {a:g} m: "
                "the gears cannot transmit motion continuously")

    @property
    def ratio(self):
        """Speed ratio Z2/Z1 (input speed / output speed)."""
        return self.driven.n_teeth / self.driving.n_teeth

    @property
    def standard_centre_distance_m(self):
        """Reference centre distance m(Z1+Z2)/2, m."""
        return self.driving.pitch_radius_m + self.driven.pitch_radius_m

    @property
    def working_centre_distance_m(self):
        """Operating centre distance, m."""
        if self.centre_distance_m is not None:
            return float(self.centre_distance_m)
        g1, g2 = self.driving, self.driven
        a = g1.pressure_angle_rad
        inv_w = _involute(a) + 2 * math.tan(a) * (g1.profile_shift + g2.profile_shift) / (
            g1.n_teeth + g2.n_teeth)
        alpha_w = _inverse_involute(inv_w)
        return self.standard_centre_distance_m * math.cos(a) / math.cos(alpha_w)

    @property
    def working_pressure_angle_rad(self):
        """Operating pressure angle acos((rb1 + rb2)/a), rad."""
        return math.acos((self.driving.base_radius_m + self.driven.base_radius_m)
                         / self.working_centre_distance_m)

    @property
    def contact_ratio(self):
        """Transverse contact ratio for sharp tips at the working centre distance."""
        g1, g2 = self.driving, self.driven
        a = self.working_centre_distance_m
        path = (math.sqrt(g1.tip_radius_m ** 2 - g1.base_radius_m ** 2)
                + math.sqrt(g2.tip_radius_m ** 2 - g2.base_radius_m ** 2)
                - a * math.sin(self.working_pressure_angle_rad))
        return path / g1.base_pitch_m

    def nominal_contact_stress_pa(self, torque_nm):
        """Nominal contact stress at the pitch point for an output torque, Pa (ISO 6336-2).

        σ_H0 = Z_H·Z_E·sqrt(F_t/(d_1·b)·(u + 1)/u), F_t = torque_nm / r_2 (the driven gear's
        reference radius), d_1 the driving gear's reference diameter, b the narrower face,
        u = Z2/Z1, Z_H = sqrt(2/(cos α_w·sin α_w)) (spur gears),
        Z_E = sqrt(1/(π((1 − ν1²)/E1 + (1 − ν2²)/E2))).

        Parameters
        ----------
        torque_nm : float
            Torque on the driven gear, N·m.
        """
        g1, g2 = self.driving, self.driven
        ft = float(torque_nm) / g2.pitch_radius_m
        b = min(g1.face_width_m, g2.face_width_m)
        u = self.ratio
        aw = self.working_pressure_angle_rad
        z_h = math.sqrt(2.0 / (math.cos(aw) * math.sin(aw)))
        z_e = math.sqrt(1.0 / (math.pi * ((1 - g1.poisson_ratio ** 2) / g1.youngs_modulus_pa
                                          + (1 - g2.poisson_ratio ** 2) / g2.youngs_modulus_pa)))
        return z_h * z_e * math.sqrt(max(ft, 0.0) / (2 * g1.pitch_radius_m * b) * (u + 1) / u)

    @property
    def mesh_stiffness_mass_kg(self):
        """Equivalent mass along the line of action J1·J2/(J1·rb2² + J2·rb1²), kg."""
        j1, j2 = self.driving.inertia_kg_m2, self.driven.inertia_kg_m2
        r1, r2 = self.driving.base_radius_m, self.driven.base_radius_m
        return j1 * j2 / (j1 * r2 ** 2 + j2 * r1 ** 2)


@dataclass(frozen=True)
class RollingBearing:
    """A radial ball (or roller) bearing, inner ring on the shaft, outer ring in the housing.

    Attributes
    ----------
    n_balls : int
        Number of rolling elements, >= 3.
    ball_diameter_m : float
        Rolling element diameter d, m.
    inner_raceway_diameter_m : float
        Inner raceway (groove bottom) diameter, m.
    outer_raceway_diameter_m : float
        Outer raceway (groove bottom) diameter, m.
    inner_groove_radius_m : float
        Inner groove curvature radius r_i, m (> d/2).
    outer_groove_radius_m : float
        Outer groove curvature radius r_o, m (> d/2).
    clearance_m : float
        Radial clearance c of Fukata's overlap δ = x cos θ + y sin θ − c, m; negative = preload.
    contact_angle_rad : float or None
        Contact angle α used in the cage kinematics, rad; ``None`` = the operating contact
        angle :attr:`effective_contact_angle_rad` (from the clearance; 0 under preload).
    mass_kg : float
        Lumped mass at the bearing centre (inner ring + shaft share), kg.
    inertia_kg_m2 : float
        Polar inertia lumped at the bearing node, kg·m².
    damping_n_s_per_m : float
        Viscous damping to ground, N·s/m.
    load_exponent : float
        Hertz exponent p (1.5 balls, 1.1 rollers).
    outer_ring_speed_ratio : float
        Outer ring speed over shaft speed, signed (0 = fixed outer ring; +: same sense;
        −: counter-rotating, paper 002 Table 1).
    stiffness_n_per_m_p : float or None
        Contact stiffness k_RE in N/m^p; ``None`` computes it from Annex B.
    """

    n_balls: int
    ball_diameter_m: float
    inner_raceway_diameter_m: float
    outer_raceway_diameter_m: float
    inner_groove_radius_m: float
    outer_groove_radius_m: float
    clearance_m: float = 0.0
    contact_angle_rad: float | None = None
    mass_kg: float = 0.49
    inertia_kg_m2: float = 9.9e-5
    damping_n_s_per_m: float = 334.27
    load_exponent: float = 1.5
    outer_ring_speed_ratio: float = 0.0
    stiffness_n_per_m_p: float | None = None

    def __post_init__(self):
        if not isinstance(self.n_balls, (int, np.integer)) or isinstance(self.n_balls, bool) \
                or self.n_balls < 3:
            raise ParameterError(f"n_balls must be an integer >= 3, got {self.n_balls!r}")
        d = check_range("ball_diameter_m", self.ball_diameter_m, 0.0, 0.5, lo_open=True, unit="m")
        di = check_range("inner_raceway_diameter_m", self.inner_raceway_diameter_m, 0.0,
                         lo_open=True, unit="m")
        check_range("outer_raceway_diameter_m", self.outer_raceway_diameter_m, di + 1.5 * d,
                    di + 2.5 * d, unit="m (inner raceway diameter + about two ball diameters)")
        check_range("inner_groove_radius_m", self.inner_groove_radius_m, 0.5 * d, 2.0 * d,
                    lo_open=True, unit="m (> d/2)")
        check_range("outer_groove_radius_m", self.outer_groove_radius_m, 0.5 * d, 2.0 * d,
                    lo_open=True, unit="m (> d/2)")
        check_range("clearance_m", self.clearance_m, -0.05 * d, 0.05 * d,
                    unit="m (|c| below 5 % of the ball diameter)")
        if self.contact_angle_rad is not None:
            check_range("contact_angle_rad", self.contact_angle_rad, 0.0, 45 * _DEG, unit="rad")
        check_range("mass_kg", self.mass_kg, 0.0, MAX_MASS_KG, lo_open=True, unit="kg")
        check_range("inertia_kg_m2", self.inertia_kg_m2, 0.0, MAX_INERTIA_KG_M2, lo_open=True,
                    unit="kg m^2")
        check_range("damping_n_s_per_m", self.damping_n_s_per_m, 0.0, MAX_DAMPING_N_S_PER_M,
                    unit="N s/m")
        check_range("load_exponent", self.load_exponent, 1.0, 2.0)
        check_range("outer_ring_speed_ratio", self.outer_ring_speed_ratio, -10.0, 10.0)
        if self.stiffness_n_per_m_p is not None:
            check_range("stiffness_n_per_m_p", self.stiffness_n_per_m_p, 0.0,
                        MAX_CONTACT_STIFFNESS, lo_open=True, unit="N/m^p")

    @classmethod
    def from_pitch(cls, n_balls, ball_diameter_m, pitch_diameter_m, *, groove_conformity=0.52,
                   **kwargs):
        """Bearing from catalogue data (balls, ball and pitch diameters).

        Raceway diameters are D ∓ d and groove radii ``groove_conformity``·d (0.52 is typical
        of deep-groove ball bearings); other fields go through ``kwargs``.
        """
        d, dm = float(ball_diameter_m), float(pitch_diameter_m)
        return cls(n_balls=int(n_balls), ball_diameter_m=d, inner_raceway_diameter_m=dm - d,
                   outer_raceway_diameter_m=dm + d, inner_groove_radius_m=groove_conformity * d,
                   outer_groove_radius_m=groove_conformity * d, **kwargs)

    @property
    def pitch_diameter_m(self):
        """Pitch diameter D = mean of the raceway diameters, m."""
        return 0.5 * (self.inner_raceway_diameter_m + self.outer_raceway_diameter_m)

    @property
    def diametral_clearance_m(self):
        """Geometric diametral clearance P_d = d_o − d_i − 2d, m."""
        return self.outer_raceway_diameter_m - self.inner_raceway_diameter_m - 2 * self.ball_diameter_m

    @property
    def free_contact_angle_rad(self):
        """Free contact angle acos(1 − P_d/(2A)), A = r_i + r_o − d; 0 if P_d <= 0."""
        a = self.inner_groove_radius_m + self.outer_groove_radius_m - self.ball_diameter_m
        pd = self.diametral_clearance_m
        if pd <= 0 or a <= 0:
            return 0.0
        return math.acos(max(-1.0, 1.0 - pd / (2 * a)))

    @property
    def operating_contact_angle_rad(self):
        """Contact angle of the mounted bearing, acos(1 − P/(2A)), rad.

        P = min(c, P_d) is the play the balls take up by an axial shift of the rings: the
        operating clearance c (``clearance_m``, which paper 001 uses as the diametral
        clearance, see papers/NOTES.md), at most the unmounted diametral clearance P_d of
        the raceways (mounting only reduces it). For the paper's bearing c = P_d = 0.015 mm:
        the free angle, 9.94°, and 3.6342 ball passes per revolution. Under preload
        (c <= 0) no play is left: the balls sit at the groove bottoms, α = 0, and the ball
        pass follows (3.6207 for the paper's bearing). Catalogue bearings built from the
        pitch diameter have P_d = 0 and so α = 0, the angle of the published defect
        frequencies.
        """
        a = self.inner_groove_radius_m + self.outer_groove_radius_m - self.ball_diameter_m
        play = min(self.clearance_m, self.diametral_clearance_m)
        if play <= 0 or a <= 0:
            return 0.0
        return math.acos(max(-1.0, 1.0 - play / (2 * a)))

    @property
    def effective_contact_angle_rad(self):
        """Contact angle used by the kinematics: ``contact_angle_rad`` if given, else
        :attr:`operating_contact_angle_rad`, rad."""
        if self.contact_angle_rad is not None:
            return self.contact_angle_rad
        return self.operating_contact_angle_rad


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


@dataclass(frozen=True)
class Lubricant:
    """Lubricant between the teeth.

    Attributes
    ----------
    dynamic_viscosity_pa_s : float
        Dynamic viscosity η, Pa·s (Koster squeeze-film damping, paper eq. 5).
    pressure_viscosity_pa_inv : float
        Barus pressure-viscosity coefficient α, 1/Pa (EHL film thickness, :mod:`cmsim.losses`;
        mineral oils 1-3e-8).
    density_kg_m3 : float
        Oil density, kg/m³ (paper 000 Table 5: 970 for its ISO 46).
    surface_roughness_m : float
        Composite RMS roughness σ = sqrt(σ1² + σ2²) of the tooth and race surfaces, m (film
        ratio λ = h/σ of the mixed-lubrication friction).
    """

    dynamic_viscosity_pa_s: float = 0.004
    pressure_viscosity_pa_inv: float = 2.0e-8
    density_kg_m3: float = 870.0
    surface_roughness_m: float = 0.4e-6

    def __post_init__(self):
        check_range("dynamic_viscosity_pa_s", self.dynamic_viscosity_pa_s, 0.0, 10.0, unit="Pa s")
        check_range("pressure_viscosity_pa_inv", self.pressure_viscosity_pa_inv, 0.0, 1e-7,
                    unit="1/Pa")
        check_range("density_kg_m3", self.density_kg_m3, 100.0, 3000.0, unit="kg/m^3")
        check_range("surface_roughness_m", self.surface_roughness_m, 0.0, 50e-6, lo_open=True,
                    unit="m")


@dataclass(frozen=True)
class MeshContact:
    """Dissipative terms of the tooth contact (paper §4).

    The paper does not print ξ, v0 or δ_threshold; the defaults are our choices.

    Attributes
    ----------
    friction_coefficient : float
        Coulomb coefficient f (paper: 0, 0.03, 0.05).
    friction_smoothing_m_s : float
        v0 of the smoothed sign v/sqrt(v² + v0²), m/s. 0.05 m/s spreads the flip at the pitch
        point over about 4 steps at 75 kHz and 1000 rpm.
    damping_ratio : float
        ξ of the hysteretic damping 2ξ·sqrt(K̄·M_eq) in contact.
    squeeze_gap_threshold_m : float
        δ_threshold that bounds the Koster squeeze-film coefficient out of contact, m.
    """

    friction_coefficient: float = 0.0
    friction_smoothing_m_s: float = 0.05
    damping_ratio: float = 0.05
    squeeze_gap_threshold_m: float = 1.0e-6

    def __post_init__(self):
        check_range("friction_coefficient", self.friction_coefficient, 0.0, 0.3)
        check_range("friction_smoothing_m_s", self.friction_smoothing_m_s, 0.0, 10.0,
                    lo_open=True, unit="m/s")
        check_range("damping_ratio", self.damping_ratio, 0.0, 1.0)
        check_range("squeeze_gap_threshold_m", self.squeeze_gap_threshold_m, 0.0, 1e-3,
                    lo_open=True, unit="m")


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
        check_range("speed_rpm", self.speed_rpm, 0.0, 1.0e5, lo_open=True, unit="rpm")
        check_range("torque_nm", self.torque_nm, 0.0, 1.0e6, unit="N m")
        check_range("radial_load_n", self.radial_load_n, 0.0, 1.0e7, unit="N")
        check_range("radial_load_angle_rad", self.radial_load_angle_rad, -2 * math.pi,
                    2 * math.pi, unit="rad")

    @property
    def omega_rad_s(self):
        """Input shaft speed, rad/s."""
        return self.speed_rpm * math.pi / 30.0

    @property
    def shaft_hz(self):
        """Input shaft rotation frequency, Hz."""
        return self.speed_rpm / 60.0


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


@dataclass(frozen=True)
class Rig:
    """A complete transmission (gear rig) or bearing test rig.

    Attributes
    ----------
    name : str
        Free-text name.
    shafts : tuple of ShaftLine
        Shaft 1 (driving), and shaft 2 (driven) when there are gears.
    gears : GearPair or None
        The spur-gear pair; ``None`` for a bearing rig with one shaft.
    input_coupling : Coupling
        Coupling between the imposed input rotation and node 1b1.
    output_coupling : Coupling or None
        Coupling between node 2b2 and the output inertia 2J2 (gear rigs).
    output_inertia_kg_m2 : float or None
        Output inertia J_2J2 carrying the load torque (gear rigs), kg·m².
    lubricant : Lubricant
        Oil between the teeth.
    mesh_contact : MeshContact
        Friction and damping of the tooth contact.
    housing : HousingPath
        Transfer path from bearing forces to housing accelerations (the sensor model of
        :mod:`cmsim.sensors`); a rig file without it gets the documented defaults.
    """

    name: str
    shafts: tuple[ShaftLine, ...]
    gears: GearPair | None = None
    input_coupling: Coupling = field(default_factory=Coupling)
    output_coupling: Coupling | None = None
    output_inertia_kg_m2: float | None = None
    lubricant: Lubricant = field(default_factory=Lubricant)
    mesh_contact: MeshContact = field(default_factory=MeshContact)
    housing: HousingPath = field(default_factory=HousingPath)

    def __post_init__(self):
        object.__setattr__(self, "shafts", tuple(self.shafts))
        if self.gears is not None:
            if len(self.shafts) != 2:
                raise ParameterError("a gear rig needs exactly 2 shafts (driving, driven)")
            if self.output_coupling is None or self.output_inertia_kg_m2 is None:
                raise ParameterError("a gear rig needs output_coupling and output_inertia_kg_m2")
            check_range("output_inertia_kg_m2", self.output_inertia_kg_m2, 0.0,
                        MAX_INERTIA_KG_M2, lo_open=True, unit="kg m^2")
            for i, s in enumerate(self.shafts):
                if s.rotor is not None:
                    raise ParameterError(f"shaft {i + 1} of a gear rig carries the gear; "
                                         "rotor must be None")
        else:
            if len(self.shafts) != 1:
                raise ParameterError("a rig without gears has exactly 1 shaft")
            if self.shafts[0].rotor is None:
                raise ParameterError("a rig without gears needs shafts[0].rotor (the disk)")

    # ------------------------------------------------------------------ topology
    @property
    def has_gears(self):
        """True for a gear rig."""
        return self.gears is not None

    @property
    def node_names(self):
        """Names of the 3-DOF nodes in DOF order, e.g. ``('1b1', '1G1', '1b2', ...)``."""
        names = []
        for i, _ in enumerate(self.shafts, start=1):
            centre = "G1" if self.has_gears else "D1"
            names += [f"{i}b1", f"{i}{centre}", f"{i}b2"]
        return tuple(names)

    @property
    def bearing_names(self):
        """Names of the bearing nodes, e.g. ``('1b1', '1b2', '2b1', '2b2')``."""
        return tuple(n for n in self.node_names if "b" in n)

    @property
    def bearings(self):
        """Bearings in the order of :attr:`bearing_names`."""
        return tuple(b for s in self.shafts for b in s.bearings)

    @property
    def dof_masses(self):
        """Diagonal of the mass matrix in DOF order (x, y, θ of each node, then θ_2J2):
        kg for translations, kg·m² for rotations, shape (n_dof,)."""
        masses = []
        for i, shaft in enumerate(self.shafts):
            if self.gears is not None:
                gear = self.gears.driving if i == 0 else self.gears.driven
                centre = (gear.mass_kg, gear.inertia_kg_m2)
            else:
                centre = (shaft.rotor.mass_kg, shaft.rotor.inertia_kg_m2)
            for mass, inertia in ((shaft.bearing_1.mass_kg, shaft.bearing_1.inertia_kg_m2),
                                  centre,
                                  (shaft.bearing_2.mass_kg, shaft.bearing_2.inertia_kg_m2)):
                masses += [mass, mass, inertia]
        if self.gears is not None:
            masses.append(self.output_inertia_kg_m2)
        return np.array(masses, dtype=float)

    def spring_elements(self, bearing_dampers=True):
        """Linear spring-dampers of Annex A in DOF indices: list of (a, b, k, c), b = −1 for
        a spring to ground (k in N/m or N·m/rad, c in N·s/m or N·m·s/rad).

        Shaft segments (x, y, θ between bearing and centre nodes), the bearings' dampers to
        the housing (``bearing_dampers``; their forces are part of the recorded housing
        forces), the input coupling (a spring to ground in deviation coordinates: the input
        rotation is imposed) and, on a gear rig, the output coupling to θ_2J2.
        """
        elements = []
        for i, shaft in enumerate(self.shafts):
            b1, c, b2 = 9 * i, 9 * i + 3, 9 * i + 6
            for seg, (na, nb) in enumerate(((b1, c), (c, b2))):
                for d in (0, 1):
                    elements.append((na + d, nb + d, shaft.flexural_stiffness_n_per_m[seg],
                                     shaft.flexural_damping_n_s_per_m[seg]))
                elements.append((na + 2, nb + 2, shaft.torsional_stiffness_nm_per_rad[seg],
                                 shaft.torsional_damping_nm_s_per_rad[seg]))
            if bearing_dampers:
                for node, brg in ((b1, shaft.bearing_1), (b2, shaft.bearing_2)):
                    for d in (0, 1):
                        elements.append((node + d, -1, 0.0, brg.damping_n_s_per_m))
        elements.append((2, -1, self.input_coupling.stiffness_nm_per_rad,
                         self.input_coupling.damping_nm_s_per_rad))
        if self.gears is not None:
            elements.append((9 + 6 + 2, self.n_dof - 1,
                             self.output_coupling.stiffness_nm_per_rad,
                             self.output_coupling.damping_nm_s_per_rad))
        return elements

    @property
    def n_dof(self):
        """Number of degrees of freedom (19 for the paper rig, 9 for a bearing rig)."""
        return 3 * len(self.node_names) + (1 if self.has_gears else 0)

    # ------------------------------------------------------------------ variants
    def with_clearance(self, clearance_m):
        """Same rig with every bearing's radial clearance set to ``clearance_m`` (m)."""
        shafts = tuple(replace(s, bearing_1=replace(s.bearing_1, clearance_m=clearance_m),
                               bearing_2=replace(s.bearing_2, clearance_m=clearance_m))
                       for s in self.shafts)
        return replace(self, shafts=shafts)

    def with_friction(self, friction_coefficient):
        """Same rig with mesh friction coefficient ``friction_coefficient``."""
        return replace(self, mesh_contact=replace(self.mesh_contact,
                                                  friction_coefficient=friction_coefficient))

    # ------------------------------------------------------------------ presets
    @classmethod
    def paper_2016(cls):
        """The rig of Fernandez-del-Rincon et al. (2016), Tables 1-3.

        Bearing 209 with raceway *diameters* 52.291/77.706 mm, c = 0.015 mm (see
        papers/NOTES.md), free contact angle ≈ 9.9° from the groove geometry; J_1b1 = J_2b2 =
        9.9e-5 kg·m² as printed (9.8e-5 would match modes 16-19 to 0.02 %).
        """
        gear = SpurGear(n_teeth=28, module_m=3.175e-3, face_width_m=6.35e-3,
                        pressure_angle_rad=20 * _DEG, rack_addendum_coef=1.25,
                        rack_dedendum_coef=1.0, rack_tip_radius_coef=0.25, tip_radius_coef=0.05,
                        bore_radius_m=0.020, mass_kg=0.79999, inertia_kg_m2=4.0408e-4,
                        youngs_modulus_pa=210e9, poisson_ratio=0.3)

        def brg(mass, inertia):
            return RollingBearing(n_balls=9, ball_diameter_m=12.7e-3,
                                  inner_raceway_diameter_m=52.291e-3,
                                  outer_raceway_diameter_m=77.706e-3,
                                  inner_groove_radius_m=6.6e-3, outer_groove_radius_m=6.6e-3,
                                  clearance_m=0.015e-3, mass_kg=mass, inertia_kg_m2=inertia,
                                  damping_n_s_per_m=334.27)

        heavy, light = brg(0.4901, 9.9e-5), brg(0.245, 4.9e-5)
        shaft_kw = dict(flexural_stiffness_n_per_m=(6.24e8, 6.24e8),
                        flexural_damping_n_s_per_m=(31.6, 31.6),
                        torsional_stiffness_nm_per_rad=(4.0e5, 4.0e5),
                        torsional_damping_nm_s_per_rad=(0.0, 0.0))
        return cls(
            name="Fernandez-del-Rincon et al. 2016 (Tables 1-3)",
            shafts=(ShaftLine(bearing_1=heavy, bearing_2=light, **shaft_kw),
                    ShaftLine(bearing_1=light, bearing_2=heavy, **shaft_kw)),
            gears=GearPair(driving=gear, driven=gear),
            input_coupling=Coupling(4.0e5, 3.5761),
            output_coupling=Coupling(4.0e5, 3.5761),
            output_inertia_kg_m2=3.56e-4,
            lubricant=Lubricant(0.004),
            mesh_contact=MeshContact(),
        )

    @classmethod
    def rotor_on_bearings(cls, bearing, rotor, *, name="rotor on two ball bearings",
                          bearing_2=None, shaft_stiffness_n_per_m=(2.0e8, 2.0e8),
                          shaft_damping_n_s_per_m=(30.0, 30.0),
                          torsional_stiffness_nm_per_rad=(1.0e5, 1.0e5),
                          input_coupling=None):
        """A bearing test rig: one shaft ``1b1 - 1D1 - 1b2`` carrying a rotor, no gears.

        Driven at constant speed through ``input_coupling``; load it with
        :attr:`OperatingPoint.radial_load_n`. ``bearing_2`` defaults to ``bearing``.
        """
        shaft = ShaftLine(bearing_1=bearing, bearing_2=bearing if bearing_2 is None else bearing_2,
                          flexural_stiffness_n_per_m=shaft_stiffness_n_per_m,
                          flexural_damping_n_s_per_m=shaft_damping_n_s_per_m,
                          torsional_stiffness_nm_per_rad=torsional_stiffness_nm_per_rad,
                          torsional_damping_nm_s_per_rad=(0.0, 0.0), rotor=rotor)
        return cls(name=name, shafts=(shaft,),
                   input_coupling=Coupling() if input_coupling is None else input_coupling)

    # ------------------------------------------------------------------ TOML
    def to_dict(self):
        """Plain nested dict (SI values) with a format version."""
        d = _to_plain(self)
        d["format_version"] = RIG_FORMAT_VERSION
        return d

    @classmethod
    def from_dict(cls, data):
        """Rig from :meth:`to_dict` output; unknown keys raise :class:`ParameterError`.

        Keys ending in ``_deg`` or ``_mm`` are converted explicitly to the ``_rad`` / ``_m``
        fields of the same stem.
        """
        data = dict(data)
        data.pop("faults", None)     # a [[faults]] list: read by cmsim.faults.load_faults
        version = data.pop("format_version", RIG_FORMAT_VERSION)
        if version != RIG_FORMAT_VERSION:
            raise ParameterError(f"rig format_version {version} is not supported "
                                 f"(this cmsim reads version {RIG_FORMAT_VERSION})")
        return _from_plain(cls, data, "rig")

    def save(self, path, faults=()):
        """Write the rig as TOML (atomically), with an optional ``[[faults]]`` list.

        ``faults`` are :mod:`cmsim.faults` values (anything with ``to_dict()``); read them
        back with :func:`cmsim.faults.load_faults` (:meth:`load` ignores the list).
        """
        data = _drop_none(self.to_dict())
        if faults:
            data["faults"] = [_drop_none(f.to_dict()) for f in faults]
        text = ("# cmsim rig description — auto-generated, SI units (m, kg, N, s, rad).\n"
                "# Keys ending in _deg or _mm are accepted on reading and converted.\n"
                + tomli_w.dumps(data))
        atomic_write_text(Path(path), text)

    @classmethod
    def load(cls, path):
        """Read a rig written by :meth:`save` (or by hand in the same layout)."""
        path = Path(path)

        def refuse(detail):
            err = ParameterError(f"rig file {path}: {detail}", param="rig")
            err.detail = detail
            return err

        try:
            with path.open("rb") as fh:
                data = tomllib.load(fh)
        except FileNotFoundError:
            raise refuse("does not exist") from None
        except IsADirectoryError:
            raise refuse("is a directory, not a TOML file") from None
        except OSError as exc:
            raise refuse(f"cannot be read ({exc.strerror or exc})") from None
        except UnicodeDecodeError:
            raise refuse("is not a text (TOML) file") from None
        except tomllib.TOMLDecodeError as exc:
            raise refuse(f"is not valid TOML: {exc}") from None
        try:
            return cls.from_dict(data)
        except ParameterError as exc:
            raise refuse(str(exc)) from None


# ---------------------------------------------------------------------- (de)serialisation
_UNIT_ALIASES = {"_deg": ("_rad", _DEG), "_mm": ("_m", 1e-3)}


def _to_plain(obj):
    if dataclasses.is_dataclass(obj):
        return {f.name: _to_plain(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, tuple):
        return [_to_plain(x) for x in obj]
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        return float(obj)
    return obj


def _drop_none(d):
    if isinstance(d, dict):
        return {k: _drop_none(v) for k, v in d.items() if v is not None}
    if isinstance(d, list):
        return [_drop_none(x) for x in d]
    return d


_NESTED = {
    ("Rig", "shafts"): "ShaftLine", ("Rig", "gears"): "GearPair",
    ("Rig", "input_coupling"): "Coupling", ("Rig", "output_coupling"): "Coupling",
    ("Rig", "lubricant"): "Lubricant", ("Rig", "mesh_contact"): "MeshContact",
    ("GearPair", "driving"): "SpurGear", ("GearPair", "driven"): "SpurGear",
    ("ShaftLine", "bearing_1"): "RollingBearing", ("ShaftLine", "bearing_2"): "RollingBearing",
    ("ShaftLine", "rotor"): "Rotor", ("Rig", "housing"): "HousingPath",
}


def _key(where, name):
    """``rig.shafts[0].bearing_1`` + ``n_balls`` → ``shafts[0].bearing_1.n_balls``."""
    path = f"{where}.{name}"
    return path[len("rig."):] if path.startswith("rig.") else path


def _check_numbers(cls, target, value, where, key):
    """Refuse booleans, strings and nested lists where a field holds numbers."""
    ftype = {f.name: str(f.type) for f in dataclasses.fields(cls)}[target]
    if not ("float" in ftype or "int" in ftype):
        return
    items = value if isinstance(value, list) else [value]
    for x in items:
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            what = "numbers" if isinstance(value, list) else "a number"
            raise ParameterError(f"{_key(where, key)} must be {what}, got {value!r}",
                                 param=_key(where, key), allowed=what)


def _from_plain(cls, data, where):
    if not isinstance(data, dict):
        raise ParameterError(f"{where} must be a table, got {type(data).__name__}")
    names = {f.name for f in dataclasses.fields(cls)}
    kwargs = {}
    given = {}
    for key, value in data.items():
        target = key
        for alias, (si, factor) in _UNIT_ALIASES.items():
            if key.endswith(alias) and key[: -len(alias)] + si in names:
                target = key[: -len(alias)] + si
                _check_numbers(cls, target, value, where, key)
                value = _scale(value, factor)
        if target not in names:
            raise ParameterError(f"unknown key {where}.{key}; allowed: {sorted(names)}")
        if target in given:
            raise ParameterError(f"{_key(where, given[target])} and {_key(where, key)} are both "
                                 f"given (the same setting in two units); keep one",
                                 param=_key(where, key))
        given[target] = key
        if value is not None and (cls.__name__, target) not in _NESTED:
            _check_numbers(cls, target, value, where, key)
        sub = _NESTED.get((cls.__name__, target))
        if sub is not None and value is not None:
            sub_cls = globals()[sub]
            if isinstance(value, list):
                value = tuple(_from_plain(sub_cls, v, f"{where}.{target}[{i}]")
                              for i, v in enumerate(value))
            else:
                value = _from_plain(sub_cls, value, f"{where}.{target}")
        elif isinstance(value, list):
            value = tuple(value)
        kwargs[target] = value
    missing = [f.name for f in dataclasses.fields(cls)
               if f.name not in kwargs and f.default is dataclasses.MISSING
               and f.default_factory is dataclasses.MISSING]
    if missing:
        raise ParameterError(f"missing key {_key(where, missing[0])!r}"
                             + (f" (and {', '.join(missing[1:])})" if missing[1:] else ""),
                             param=_key(where, missing[0]))
    try:
        return cls(**kwargs)
    except ParameterError as exc:
        if getattr(exc, "located", False):
            raise
        # name the component: "shafts[0].bearing_1.n_balls must be ...", not "n_balls ..."
        msg, param = str(exc), exc.param
        if param and msg.startswith(param) and where != "rig":
            param = _key(where, param)
            msg = param + msg[len(exc.param):]
        elif where != "rig":
            msg = f"{where[len('rig.'):] if where.startswith('rig.') else where}: {msg}"
        err = ParameterError(msg, param=param, allowed=exc.allowed)
        err.located = True
        raise err from None
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{where}: {exc}") from None


def _scale(value, factor):
    if isinstance(value, list):
        return [v * factor for v in value]
    return value * factor
