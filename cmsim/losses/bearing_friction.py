"""Rolling-bearing friction torque (Harris–Palmgren) and ring/cage/ball kinematics.

Paper 000 (§3.2, refs [26-27]) computes the bearing loss torque as the Palmgren load term
plus the viscous (fluid-dynamic) term:

    M_l = f1 · P1 · d_m,            f1 = z · (F_s/C_0)^y                 (load, N·mm)
    M_v = 1e-7 · f0 · (ν·n)^(2/3) · d_m³      if ν·n >= 2000           (viscous, N·mm)
        = 160e-7 · f0 · d_m³                   otherwise

with d_m the pitch diameter in mm, ν the kinematic viscosity in mm²/s (cSt), n the speed of
the rotating ring relative to the other in rpm (both rings may turn), P1 the friction load
(max(0.9·F_a·cot α − 0.1·F_r, F_r) for radial ball bearings), F_s ≈ F_r the static
equivalent load, C_0 = f_s·i·Z·D_w²·cos α the ISO 76 static load rating (f_s ~ 12.3 N/mm² for
deep-groove bearings, as the CLI's plausibility check), z = 0.0005 and y = 0.55 for
deep-groove ball bearings (Harris & Kotzalas; range 0.0004-0.0006), and f0 = 2 for an oil
bath/jet (1 oil mist, 4 vertical shaft).

Kinematics with both rings rotating (paper 002 Table 1, K1 = (1 − γ)/2, K2 = (1 + γ)/2,
γ = D_w·cos α / d_m): cage n_c = n_i·K1 + n_o·K2 (same sense; counter rotation: n_o < 0),
ball spin about its own axis n_b = −(n_i − n_o)·(d_m/D_w)·2·K1·K2, and the entrainment
(mean rolling) velocity of the ball-inner race contact ū = (d_m − D_w)/2 · |ω_i − ω_c|
(eq. 11, written for any ring speeds); outer contact ū = (d_m + D_w)/2 · |ω_o − ω_c|.

References
----------
.. [1] T.A. Harris, M.N. Kotzalas, Essential Concepts of Bearing Technology, CRC 2006
       (ref. [26] of paper 000), friction torque of ball bearings.
.. [2] A. Palmgren, Ball and Roller Bearing Engineering, 1959 (ref. [27]).
.. [3] Paper 002, Table 1 and eq. 1-11.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cmsim.errors import check_range
from cmsim.frequencies import cage_speed_ratios

__all__ = ["BearingFriction", "RingKinematics", "ring_kinematics", "bearing_friction_torque"]


@dataclass(frozen=True)
class RingKinematics:
    """Speeds of one ball bearing with both rings rotating (paper 002 Table 1).

    Attributes
    ----------
    cage_rpm : float
        Cage speed n_c, rpm (signed, the inner ring's sense positive).
    ball_spin_rpm : float
        Ball rotation about its own axis n_b, rpm (signed).
    inner_entrainment_m_s, outer_entrainment_m_s : float
        Mean rolling velocity of the ball-inner and ball-outer race contacts, m/s.
    relative_rpm : float
        |n_i − n_o|, the speed that drives the viscous loss, rpm.
    """

    cage_rpm: float
    ball_spin_rpm: float
    inner_entrainment_m_s: float
    outer_entrainment_m_s: float
    relative_rpm: float


def ring_kinematics(bearing, inner_rpm, outer_rpm=None):
    """Cage, ball and contact speeds of ``bearing`` (paper 002 Table 1, eq. 11).

    Parameters
    ----------
    bearing : RollingBearing
    inner_rpm : float
        Inner-ring speed, rpm (signed).
    outer_rpm : float, optional
        Outer-ring speed, rpm, signed: same sense > 0, counter rotation < 0 (default
        ``bearing.outer_ring_speed_ratio · inner_rpm``).

    Examples
    --------
    >>> from cmsim.rig import RollingBearing
    >>> nu210 = RollingBearing.from_pitch(16, 13e-3, 70e-3)     # paper 002 Table 2 geometry
    >>> k = ring_kinematics(nu210, 12000.0, -10000.0)           # counter rotation, Table 3
    >>> round(k.cage_rpm, 1)
    -1042.9
    """
    if outer_rpm is None:
        outer_rpm = bearing.outer_ring_speed_ratio * inner_rpm
    check_range("inner_rpm", inner_rpm, -1e6, 1e6, unit="rpm")
    check_range("outer_rpm", outer_rpm, -1e6, 1e6, unit="rpm")
    d, dm = bearing.ball_diameter_m, bearing.pitch_diameter_m
    alpha = bearing.effective_contact_angle_rad
    k1, k2 = cage_speed_ratios(d, dm, alpha)
    cage = inner_rpm * k1 + outer_rpm * k2
    spin = -(inner_rpm - outer_rpm) * dm / (d * math.cos(alpha) if alpha else d) * 2 * k1 * k2
    to_rad = math.pi / 30.0
    dc = d * math.cos(alpha)
    u_in = 0.5 * (dm - dc) * abs(inner_rpm - cage) * to_rad
    u_out = 0.5 * (dm + dc) * abs(outer_rpm - cage) * to_rad
    return RingKinematics(cage, spin, u_in, u_out, abs(inner_rpm - outer_rpm))


@dataclass(frozen=True)
class BearingFriction:
    """Friction torque of one bearing.

    Attributes
    ----------
    load_torque_nm : float
        Palmgren load term M_l, N·m.
    viscous_torque_nm : float
        Palmgren viscous term M_v, N·m.
    """

    load_torque_nm: float
    viscous_torque_nm: float

    @property
    def torque_nm(self):
        """M_l + M_v, N·m."""
        return self.load_torque_nm + self.viscous_torque_nm


def bearing_friction_torque(bearing, radial_load_n, relative_rpm, kinematic_viscosity_mm2_s,
                            *, axial_load_n=0.0, f0=2.0, z=0.0005, y=0.55):
    """Harris–Palmgren friction torque of a ball bearing (module docstring).

    Parameters
    ----------
    bearing : RollingBearing
    radial_load_n : float
        Radial load F_r, N (>= 0).
    relative_rpm : float
        Speed of one ring relative to the other, rpm (>= 0).
    kinematic_viscosity_mm2_s : float
        Oil kinematic viscosity ν, mm²/s (cSt) = η/ρ·1e6.
    axial_load_n : float
        Axial load F_a, N.
    f0 : float
        Lubrication factor of the viscous term (2: oil bath or jet).
    z, y : float
        Load-term constants of f1 = z·(F_s/C_0)^y (deep-groove ball bearing).

    Returns
    -------
    BearingFriction

    Examples
    --------
    >>> from cmsim.rig import Rig
    >>> b = Rig.paper_2016().bearings[0]
    >>> f = bearing_friction_torque(b, 250.0, 1000.0, 4.6)
    >>> round(f.viscous_torque_nm * 1e3, 2), round(f.load_torque_nm * 1e3, 3)
    (15.19, 0.783)
    """
    check_range("radial_load_n", radial_load_n, 0.0, 1e8, unit="N")
    check_range("axial_load_n", axial_load_n, 0.0, 1e8, unit="N")
    check_range("relative_rpm", relative_rpm, 0.0, 1e6, unit="rpm")
    check_range("kinematic_viscosity_mm2_s", kinematic_viscosity_mm2_s, 0.0, 1e5, unit="mm^2/s")
    check_range("f0", f0, 0.0, 20.0)
    dm_mm = bearing.pitch_diameter_m * 1e3
    alpha = bearing.effective_contact_angle_rad
    fr, fa = radial_load_n, axial_load_n
    p1 = max(0.9 * fa / math.tan(alpha) - 0.1 * fr if alpha > 1e-6 else fr, fr)
    fs = max(fr, 0.6 * fr + 0.5 * fa)
    c0 = bearing.static_load_rating_n
    f1 = z * (fs / c0) ** y if fs > 0 else 0.0
    m_load = f1 * p1 * dm_mm
    nun = kinematic_viscosity_mm2_s * relative_rpm
    if relative_rpm == 0.0:
        m_visc = 0.0
    elif nun >= 2000.0:
        m_visc = 1e-7 * f0 * nun ** (2.0 / 3.0) * dm_mm ** 3
    else:
        m_visc = 160e-7 * f0 * dm_mm ** 3
    return BearingFriction(m_load * 1e-3, m_visc * 1e-3)
