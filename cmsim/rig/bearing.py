"""A radial ball (or roller) bearing: raceway geometry, clearance, contact angle.

Values in SI units (m, kg, rad); Annex B of paper 001 turns them into the contact stiffness
(:mod:`cmsim.bearings.hertz`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError, check_range
from cmsim.rig.ranges import (MAX_CONTACT_STIFFNESS, MAX_DAMPING_N_S_PER_M, MAX_INERTIA_KG_M2,
                              MAX_MASS_KG)

__all__ = ["RollingBearing", "STATIC_LOAD_FACTOR_N_PER_M2"]

#: ISO 76 static load rating factor f0 of deep-groove ball bearings, N/m² (12.3 N/mm²).
STATIC_LOAD_FACTOR_N_PER_M2 = 12.3e6


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
            check_range("contact_angle_rad", self.contact_angle_rad, 0.0, math.radians(45),
                        unit="rad")
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
        of deep-groove ball bearings).

        Parameters
        ----------
        n_balls : int
            Number of rolling elements.
        ball_diameter_m : float
            Ball diameter d, m.
        pitch_diameter_m : float
            Pitch diameter D, m.
        groove_conformity : float
            Groove radius over ball diameter.
        **kwargs
            Other fields of :class:`RollingBearing` (clearance, masses, ...).
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
    def static_load_rating_n(self):
        """Basic static radial load rating C0 = f0·Z·d²·cos α of a single-row ball bearing,
        N (ISO 76; f0 ≈ 12.3 N/mm² for deep-groove ball bearings, α the effective contact
        angle)."""
        return (STATIC_LOAD_FACTOR_N_PER_M2 * self.n_balls * self.ball_diameter_m ** 2
                * math.cos(self.effective_contact_angle_rad))

    @property
    def effective_contact_angle_rad(self):
        """Contact angle used by the kinematics: ``contact_angle_rad`` if given, else
        :attr:`operating_contact_angle_rad`, rad."""
        if self.contact_angle_rad is not None:
            return self.contact_angle_rad
        return self.operating_contact_angle_rad
