"""Gear faults: eccentricity, a root crack, a spall, a broken tip, profile errors of all teeth.

Each tooth fault acts on the per-tooth tables of :class:`~cmsim.faults.compile.FaultArrays`
on the grid of the run's mesh table (positions s on the line of action from T1, see
:mod:`cmsim.mesh_stiffness.table`): a stiffness factor (crack; a spall over part of the face
width) or an additional unloaded separation (spall, broken tip, wear, tip relief), used when
that tooth is in contact. A point at radius r on a tooth of gear 1 meets the line of action at
s = sqrt(r² − r_b1²); on gear 2 at s = L − sqrt(r² − r_b2²), L = T1T2 (the conventions of
:mod:`cmsim.mesh_stiffness.contact`). Lengths "along the profile" are involute arc lengths,
λ²/(2 r_b) from the base circle for the roll length λ.

Teeth are numbered 0 .. Z − 1 in the order the dynamics' mesh kernel tracks them (tooth 0 is
the one in contact at the pitch point at t = 0).

References
----------
.. [1] F. Chaari, W. Baccar, M. S. Abbes, M. Haddar, "Effect of spalling or tooth breakage on
   gearmesh stiffness and dynamic response of a one-stage spur gear transmission",
   Eur. J. Mech. A/Solids 27 (2008) 691-705.
.. [2] F. Chaari, T. Fakhfakh, M. Haddar, "Analytical modelling of spur gear tooth crack and
   influence on gearmesh stiffness", Eur. J. Mech. A/Solids 28 (2009) 461-468.
.. [3] P. Velex, M. Maatar, "A mathematical model for analyzing the influence of shape
   deviations and mounting errors on gear dynamic behaviour", J. Sound Vib. 191 (1996)
   629-660 (eccentricity, profile errors as separations along the line of action).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cmsim.errors import ParameterError, check_range
from cmsim.faults.base import Fault, check_angle, check_gear, check_int, mm, register
from cmsim.faults.crack import max_crack_depth_m
from cmsim.mesh_stiffness.geometry import ToothProfile

__all__ = ["Eccentricity", "ToothCrack", "ToothSpall", "ToothBreakage", "ProfileError",
           "BREAKAGE_SEPARATION_M", "roll_length_m", "involute_arc_m"]

#: Separation standing for "no material here" (a broken tip): far beyond any elastic mesh
#: approach and beyond the 200 µm corner-contact limit of the tables, m.
BREAKAGE_SEPARATION_M = 1.0e-3


def roll_length_m(gear, radius_m):
    """Roll length sqrt(r² − r_b²) of the involute point at radius r (0 below the base), m."""
    return math.sqrt(max(radius_m ** 2 - gear.base_radius_m ** 2, 0.0))


def involute_arc_m(gear, radius_m):
    """Involute arc length from the base circle to radius r, λ²/(2 r_b), m."""
    return roll_length_m(gear, radius_m) ** 2 / (2.0 * gear.base_radius_m)


def _check_gear_field(gear):
    if isinstance(gear, bool) or gear not in (1, 2):
        raise ParameterError(f"gear must be 1 (driving) or 2 (driven), got {gear!r}",
                             param="gear", allowed="1 or 2")


@dataclass(frozen=True)
class _ToothFault(Fault):
    """A fault on one tooth of one gear."""

    def _check_tooth(self, rig):
        g = check_gear(rig, self.gear)
        check_int("tooth", self.tooth, 0, g.n_teeth - 1)
        return g


@register
@dataclass(frozen=True)
class Eccentricity(Fault):
    """Run-out of a gear: its geometric centre turns with it at ``amplitude_m`` from the axis.

    The contact geometry follows the offset centre (a transmission error of e along the line
    of action once per revolution, [3]); the gear's body turns about the shaft with its mass
    centre on the offset centre, so the shaft carries the rotating force m·e·Ω² of that mass
    (``mass_share`` of the gear's mass: 1 for a gear bored off-centre or mounted on an
    eccentric bush, whose whole body runs out with its toothing; 0 for a toothing cut
    eccentric on a balanced body). At 0.1 mm on a 0.8-kg gear at 1500 rpm that is 2 N, the
    residual unbalance of a 3-kg rotor of balance grade G 6.3 (ISO 21940-11): the 1× line
    of the shaft rises by several dB, which the mesh's own change (under 2 dB on its
    sidebands) does not make.

    Attributes
    ----------
    gear : int
        1 (driving) or 2 (driven).
    amplitude_m : float
        Eccentricity e, m (> 0, at most a quarter of the module).
    phase_rad : float
        Angle of the offset at zero gear rotation, rad.
    mass_share : float
        Share of the gear's mass whose centre is the offset centre, 0..1.
    """

    name = "eccentricity"

    gear: int
    amplitude_m: float
    phase_rad: float = 0.0
    mass_share: float = 1.0

    def __post_init__(self):
        _check_gear_field(self.gear)
        check_range("amplitude_m", self.amplitude_m, 0.0, 1e-3, lo_open=True, unit="m")
        check_angle("phase_rad", self.phase_rad)
        check_range("mass_share", self.mass_share, 0.0, 1.0)

    @property
    def label(self):
        return f"eccentricity@G{self.gear} e={1e6 * self.amplitude_m:.3g}um"

    @property
    def site(self):
        return f"eccentricity of gear {self.gear}"

    def validate(self, rig):
        g = check_gear(rig, self.gear)
        check_range("amplitude_m", self.amplitude_m, 0.0, 0.25 * g.module_m, lo_open=True,
                    unit="m (a quarter of the module)")
        return self


@register
@dataclass(frozen=True)
class ToothCrack(_ToothFault):
    """Root crack of one tooth (potential-energy cracked section, :mod:`cmsim.faults.crack`).

    Attributes
    ----------
    gear : int
        1 or 2.
    depth_m : float
        Crack depth q along the crack, m (> 0; its tip at most on the tooth centreline).
    angle_rad : float
        Crack angle ν to the tooth centreline, rad, in (0, π/2] (default 45°, as in [2]).
    tooth : int
        Cracked tooth, 0 .. Z − 1.
    method : {"pe", "fe"}
        Stiffness of the cracked pair: the potential-energy cracked section (fast) or the
        plane-strain FE model with the crack cut into the mesh (about 30 s per crack, then
        cached; :func:`cmsim.faults.crack.crack_stiffness_factor`).
    """

    name = "tooth_crack"

    gear: int
    depth_m: float
    angle_rad: float = math.pi / 4
    tooth: int = 0
    method: str = "pe"

    def __post_init__(self):
        _check_gear_field(self.gear)
        check_range("depth_m", self.depth_m, 0.0, 0.05, lo_open=True, unit="m")
        check_range("angle_rad", self.angle_rad, 0.0, 0.5 * math.pi, lo_open=True, unit="rad")
        check_int("tooth", self.tooth, 0)
        if self.method not in ("pe", "fe"):
            raise ParameterError(f"method must be 'pe' or 'fe', got {self.method!r}",
                                 param="method")

    @property
    def label(self):
        return (f"tooth_crack@G{self.gear}#{self.tooth} depth={mm(self.depth_m)} "
                f"angle={math.degrees(self.angle_rad):.3g}deg")

    @property
    def site(self):
        return f"tooth_crack on tooth {self.tooth} of gear {self.gear}"

    def validate(self, rig):
        g = self._check_tooth(rig)
        qmax = max_crack_depth_m(g, self.angle_rad)
        check_range("depth_m", self.depth_m, 0.0, qmax, lo_open=True,
                    unit=f"m (crack tip at most on the tooth centreline at this angle)")
        return self


@register
@dataclass(frozen=True)
class ToothSpall(_ToothFault):
    """A spall (pit) on the loaded flank of one tooth.

    Over the spalled band the flank is ``depth_m`` lower: across the whole face width
    (``face_fraction = 1``) the pair separates there (an added separation); over part of it
    the remaining width carries the load, so the pair stiffness scales by
    1 − ``face_fraction`` (Chaari et al. 2008 [1]) and no separation is added.

    Attributes
    ----------
    gear : int
        1 or 2.
    width_m : float
        Extent of the spall along the profile (involute arc length), m (> 0).
    depth_m : float
        Spall depth, m (> 0, at most half the module).
    radius_m : float or None
        Radius of the spall centre on the tooth, m; ``None`` = the pitch radius.
    face_fraction : float
        Fraction of the face width spalled, in (0, 1].
    tooth : int
        Spalled tooth, 0 .. Z − 1.
    """

    name = "tooth_spall"

    gear: int
    width_m: float
    depth_m: float
    radius_m: float | None = None
    face_fraction: float = 1.0
    tooth: int = 0

    def __post_init__(self):
        _check_gear_field(self.gear)
        check_range("width_m", self.width_m, 0.0, 0.05, lo_open=True, unit="m")
        check_range("depth_m", self.depth_m, 0.0, 0.01, lo_open=True, unit="m")
        if self.radius_m is not None:
            check_range("radius_m", self.radius_m, 0.0, 10.0, lo_open=True, unit="m")
        check_range("face_fraction", self.face_fraction, 0.0, 1.0, lo_open=True)
        check_int("tooth", self.tooth, 0)

    @property
    def label(self):
        return (f"tooth_spall@G{self.gear}#{self.tooth} width={mm(self.width_m)} "
                f"depth={mm(self.depth_m)}")

    def arc_range_m(self, g):
        """(σ_lo, σ_hi): the spalled band as involute arc lengths from the base circle, m."""
        r = g.pitch_radius_m if self.radius_m is None else self.radius_m
        sc = involute_arc_m(g, r)
        return sc - 0.5 * self.width_m, sc + 0.5 * self.width_m

    def validate(self, rig):
        g = self._check_tooth(rig)
        prof = ToothProfile.from_gear(g, n_points=64)
        lo_r, hi_r = prof.form_radius_m, prof.tip_round_start_radius_m
        if self.radius_m is not None:
            check_range("radius_m", self.radius_m, lo_r, hi_r,
                        unit=f"m (on the involute flank of gear {self.gear})")
        flank = involute_arc_m(g, hi_r) - involute_arc_m(g, lo_r)
        check_range("width_m", self.width_m, 0.0, flank, lo_open=True,
                    unit=f"m (the involute flank of gear {self.gear} is {flank * 1e3:.4g} mm)")
        check_range("depth_m", self.depth_m, 0.0, 0.5 * g.module_m, lo_open=True,
                    unit="m (half the module)")
        return self


@register
@dataclass(frozen=True)
class ToothBreakage(_ToothFault):
    """A broken tooth tip: no contact above the radius r_a − ``lost_height_m``.

    Attributes
    ----------
    gear : int
        1 or 2.
    lost_height_m : float
        Height lost at the tip, m (> 0, at most the whole tooth height r_a − r_f: a missing
        tooth).
    tooth : int
        Broken tooth, 0 .. Z − 1.
    """

    name = "tooth_breakage"

    gear: int
    lost_height_m: float
    tooth: int = 0

    def __post_init__(self):
        _check_gear_field(self.gear)
        check_range("lost_height_m", self.lost_height_m, 0.0, 0.2, lo_open=True, unit="m")
        check_int("tooth", self.tooth, 0)

    @property
    def label(self):
        return f"tooth_breakage@G{self.gear}#{self.tooth} lost={mm(self.lost_height_m)}"

    @property
    def site(self):
        return f"tooth_breakage on tooth {self.tooth} of gear {self.gear}"

    def validate(self, rig):
        g = self._check_tooth(rig)
        h = g.tip_radius_m - g.root_radius_m
        check_range("lost_height_m", self.lost_height_m, 0.0, h, lo_open=True,
                    unit=f"m (the tooth height of gear {self.gear})")
        return self


@register
@dataclass(frozen=True)
class ProfileError(Fault):
    """Profile deviation of all teeth of a gear: uniform wear and/or linear tip relief.

    The separation added at roll length λ on every tooth is
    ``wear_depth_m`` + ``tip_relief_m``·max(0, (λ − λ_s)/(λ_t − λ_s)), λ_s the roll length at
    ``tip_relief_start_radius_m`` and λ_t at the start of the tip rounding.

    Attributes
    ----------
    gear : int
        1 or 2.
    wear_depth_m : float
        Uniform material loss over the flank, m (>= 0).
    tip_relief_m : float
        Tip relief amplitude C_a at the end of the involute, m (>= 0).
    tip_relief_start_radius_m : float or None
        Radius where the relief starts, m; ``None`` = r_a − 0.4·module (a short relief).
    """

    name = "profile_error"

    gear: int
    wear_depth_m: float = 0.0
    tip_relief_m: float = 0.0
    tip_relief_start_radius_m: float | None = None

    def __post_init__(self):
        _check_gear_field(self.gear)
        check_range("wear_depth_m", self.wear_depth_m, 0.0, 1e-3, unit="m")
        check_range("tip_relief_m", self.tip_relief_m, 0.0, 1e-3, unit="m")
        if self.wear_depth_m <= 0.0 and self.tip_relief_m <= 0.0:
            raise ParameterError("wear_depth_m or tip_relief_m must be > 0 (a profile error "
                                 "with neither is no fault)", param="wear_depth_m",
                                 allowed="> 0 m")
        if self.tip_relief_start_radius_m is not None:
            check_range("tip_relief_start_radius_m", self.tip_relief_start_radius_m, 0.0,
                        10.0, lo_open=True, unit="m")

    @property
    def label(self):
        parts = [f"profile_error@G{self.gear}"]
        if self.wear_depth_m > 0:
            parts.append(f"wear={1e6 * self.wear_depth_m:.3g}um")
        if self.tip_relief_m > 0:
            parts.append(f"tip_relief={1e6 * self.tip_relief_m:.3g}um")
        return " ".join(parts)

    @property
    def site(self):
        return f"profile_error of gear {self.gear} (it covers every tooth: give one)"

    def relief_start_radius_m(self, g):
        """Radius where the tip relief starts, m."""
        if self.tip_relief_start_radius_m is not None:
            return self.tip_relief_start_radius_m
        return g.tip_radius_m - 0.4 * g.module_m

    def validate(self, rig):
        g = check_gear(rig, self.gear)
        prof = ToothProfile.from_gear(g, n_points=64)
        if self.tip_relief_m > 0:
            check_range("tip_relief_start_radius_m", self.relief_start_radius_m(g),
                        max(g.base_radius_m, prof.form_radius_m),
                        prof.tip_round_start_radius_m, hi_open=True,
                        unit=f"m (on the involute flank of gear {self.gear})")
        return self
