"""Spur gears and a gear pair: involute geometry, contact ratio, ISO 6336 contact stress.

Values in SI units (m, kg, rad, Pa); the defaults are the paper's gear (Table 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError, check_range
from cmsim.rig.ranges import MAX_INERTIA_KG_M2, MAX_MASS_KG, MAX_TEETH

__all__ = ["SpurGear", "GearPair"]


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
    pressure_angle_rad: float = math.radians(20.0)
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
        check_range("pressure_angle_rad", self.pressure_angle_rad, math.radians(10),
                    math.radians(35),
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
