"""Rigid-body contact geometry of a spur-gear pair with rounded tips (Python side).

Builds the geometry vector used by :func:`cmsim.mesh_stiffness._kernels.pair_contact_jit`
and gives the involute path and the potential-contact zone on the line of action.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.mesh_stiffness._kernels import GEO_SIZE, mesh_frame_jit, pair_contact_jit

__all__ = ["TipRounding", "tip_rounding", "contact_geometry", "active_path_m", "table_range_m",
           "corner_zone_m", "potential_slots", "pair_contacts", "CORNER_GAP_LIMIT_M"]

#: Rigid gap beyond which a tip corner is too far from its mating flank to touch or squeeze oil:
#: 200 µm, ten times the largest elastic mesh approach of the rigs we model.
CORNER_GAP_LIMIT_M = 200e-6


@dataclass(frozen=True)
class TipRounding:
    """Tip-rounding circle of a drive flank, in polar coordinates about the gear centre.

    Attributes
    ----------
    centre_radius_m : float
        Radius of the rounding centre, r_a − ρ, m.
    centre_offset_rad : float
        Polar angle of the centre minus the involute origin angle ψ, rad.
    radius_m : float
        Rounding radius ρ, m.
    start_roll_m : float
        Roll length sqrt(r² − r_b²) where the rounding meets the involute, m.
    """

    centre_radius_m: float
    centre_offset_rad: float
    radius_m: float
    start_roll_m: float


def tip_rounding(gear):
    """Closed-form tip rounding of ``gear`` (tangent to the involute and the tip circle).

    With λ_Q = sqrt((r_a − ρ)² − r_b²): offset = −(λ_Q + ρ)/r_b + atan(λ_Q/r_b), and the
    rounding starts at roll length λ_Q + ρ. With ρ = 0 the "centre" is the sharp tip corner.
    """
    rb, ra, rho = gear.base_radius_m, gear.tip_radius_m, gear.tip_rounding_m
    rq = ra - rho
    lam = math.sqrt(max(rq * rq - rb * rb, 0.0))
    return TipRounding(rq, -(lam + rho) / rb + math.atan2(lam, rb), rho, lam + rho)


def contact_geometry(pair):
    """Geometry vector ``geo`` of the pair, shape (14,), see the kernel module docstring."""
    t1, t2 = tip_rounding(pair.driving), tip_rounding(pair.driven)
    geo = np.array([pair.driving.base_radius_m, pair.driven.base_radius_m,
                    t1.start_roll_m, t2.start_roll_m,
                    t1.centre_radius_m, t1.centre_offset_rad, t1.radius_m,
                    t2.centre_radius_m, t2.centre_offset_rad, t2.radius_m,
                    math.cos(t1.centre_offset_rad), math.sin(t1.centre_offset_rad),
                    math.cos(t2.centre_offset_rad), math.sin(t2.centre_offset_rad)])
    assert geo.size == GEO_SIZE
    return geo


def _length_m(pair):
    return pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)


def active_path_m(pair):
    """(s_start, s_end): involute-involute contact on the line of action at nominal centres, m.

    Bounded by the tip-rounding starts of the driven gear (start) and the driving gear (end).

    Examples
    --------
    >>> from cmsim.rig import Rig
    >>> pair = Rig.paper_2016().gears
    >>> s0, s1 = active_path_m(pair)
    >>> round((s1 - s0) / pair.driving.base_pitch_m, 2)
    1.6
    """
    return (_length_m(pair) - tip_rounding(pair.driven).start_roll_m,
            tip_rounding(pair.driving).start_roll_m)


def corner_zone_m(pair, gap_limit_m=CORNER_GAP_LIMIT_M):
    """(before, after): how far outside the involute path a rounded tip can still touch, m.

    Found at nominal geometry as the distance along the line of action at which the rigid
    corner gap reaches ``gap_limit_m`` (cached per pair).
    """
    return _corner_zone_cached(pair, float(gap_limit_m))


_ZONE_CACHE = {}


def _corner_zone_cached(pair, gap_limit_m):
    key = (pair, gap_limit_m)
    if key not in _ZONE_CACHE:
        s0, s1 = active_path_m(pair)
        pb = pair.driving.base_pitch_m
        steps = np.linspace(0.0, pb, 801)[1:]
        out = []
        for side, edge in ((-1.0, s0), (1.0, s1)):
            gaps = np.array([-_rigid_overlap_at(pair, edge + side * d) for d in steps])
            beyond = np.nonzero(gaps >= gap_limit_m)[0]
            out.append(float(steps[beyond[0]]) if beyond.size else pb)
        _ZONE_CACHE[key] = tuple(out)
    return _ZONE_CACHE[key]


def _rigid_overlap_at(pair, s):
    """Overlap of the pair whose gear-1 flank sits at ``s`` at nominal geometry, m."""
    rb1 = pair.driving.base_radius_m
    alpha = pair.working_pressure_angle_rad
    theta = (s - rb1 * math.tan(alpha)) / rb1
    c = pair_contacts(pair, theta, theta * pair.driving.n_teeth / pair.driven.n_teeth,
                      n_slots=1, slot_start_m=s - 0.5 * pair.driving.base_pitch_m)
    return float(c["delta_m"][0])


def table_range_m(pair):
    """(s_lo, s_hi): the potential-contact zone, the involute path widened by
    :func:`corner_zone_m` on each side, m."""
    s0, s1 = active_path_m(pair)
    before, after = corner_zone_m(pair)
    return s0 - before, s1 + after


def potential_slots(pair):
    """Number of tooth pairs evaluated at every instant (covers the potential-contact zone)."""
    lo, hi = table_range_m(pair)
    return int(math.ceil((hi - lo) / pair.driving.base_pitch_m))


def reference_phases(pair):
    """(ψ1₀, ψ2₀): involute origin angles of tooth 0 of both gears at t = 0 and rest.

    Chosen so that pair 0 touches at the pitch point with zero interference.
    """
    alpha = pair.working_pressure_angle_rad
    phi_t1 = 0.5 * math.pi - alpha
    return phi_t1 + math.tan(alpha), phi_t1 + math.pi + math.tan(alpha)


def pair_contacts(pair, theta1_rad, theta2_rad, centre1_m=(0.0, 0.0), centre2_m=(0.0, 0.0),
                  n_slots=None, slot_start_m=None):
    """Interference of the potential pairs for given gear angles and centre offsets.

    A Python wrapper of the dynamics kernel for tables, tests and plots.

    Parameters
    ----------
    pair : GearPair
    theta1_rad : float
        Rotation of gear 1 (counter-clockwise) from the reference position, rad.
    theta2_rad : float
        Rotation of gear 2 in its own sense (clockwise) from the reference position, rad.
    centre1_m, centre2_m : tuple of float
        Offsets of the gear centres from nominal, m.
    n_slots : int, optional
        Pairs to evaluate (default :func:`potential_slots`).
    slot_start_m : float, optional
        Start of the first slot on the line of action (default: start of
        :func:`table_range_m`).

    Returns
    -------
    dict of ndarray, shape (n_slots,)
        ``position_m`` (s of each pair), ``delta_m`` (overlap), ``normal`` (n_slots, 2),
        ``point_m`` (n_slots, 2), ``s_eq_m``, ``chi1_m``, ``chi2_m`` (radii of curvature of
        the two surfaces at the contact), ``tooth`` (gear-1 tooth number of the pair,
        counting back from tooth 0); and ``length_m`` (T1T2, float) and ``centre1_m``
        (absolute centre of gear 1).
    """
    geo = contact_geometry(pair)
    rb1, rb2 = geo[0], geo[1]
    pb = pair.driving.base_pitch_m
    psi10, psi20 = reference_phases(pair)
    a0 = pair.working_centre_distance_m
    c1x, c1y = float(centre1_m[0]), float(centre1_m[1])
    c2x, c2y = float(centre2_m[0]), a0 + float(centre2_m[1])
    phi_t1, length, cos_t1, sin_t1 = mesh_frame_jit(c1x, c1y, c2x, c2y, rb1, rb2)
    psi1 = theta1_rad + psi10
    psi2 = psi20 - theta2_rad
    delta_inv = rb1 * (psi1 - phi_t1) + rb2 * (psi2 - phi_t1 - math.pi) - length
    s_ref = rb1 * (psi1 - phi_t1)
    lo = table_range_m(pair)[0] if slot_start_m is None else float(slot_start_m)
    n_slots = potential_slots(pair) if n_slots is None else int(n_slots)
    m0 = math.floor((s_ref - lo) / pb)
    out = {k: np.empty(n_slots) for k in ("position_m", "delta_m", "s_eq_m", "chi1_m",
                                          "chi2_m")}
    out["normal"] = np.empty((n_slots, 2))
    out["point_m"] = np.empty((n_slots, 2))
    out["tooth"] = np.empty(n_slots, dtype=int)
    for j in range(n_slots):
        n = m0 - j
        s = s_ref - n * pb
        p1, p2 = psi1 - n * pb / rb1, psi2 + n * pb / rb2
        res = pair_contact_jit(s, delta_inv, math.cos(p1), math.sin(p1), math.cos(p2),
                               math.sin(p2), c1x, c1y, c2x, c2y, cos_t1, sin_t1, length, geo)
        out["position_m"][j] = s
        out["delta_m"][j] = res[0]
        out["normal"][j] = res[1:3]
        out["point_m"][j] = res[3:5]
        out["s_eq_m"][j] = res[5]
        out["chi1_m"][j] = res[6]
        out["chi2_m"][j] = res[7]
        out["tooth"][j] = n
    out["length_m"] = length
    out["centre1_m"] = (c1x, c1y)
    return out
