"""Hertzian contact stiffness of a ball between two raceways (paper 001, Annex B).

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, Annex B, eqs. B.1-B.7 and Table 7.
.. [2] T. Harris, M. Kotzalas, *Rolling Bearing Analysis*, Wiley 2001 (δ* table, steel).
.. [3] B. Hamrock, B. Jacobson, S. Schmid, *Fundamentals of Fluid Film Lubrication*, 1994.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError

__all__ = ["DELTA_STAR_TABLE", "RacewayContact", "raceway_contact", "contact_stiffness",
           "ball_stiffness", "bearing_contact_stiffness", "bearing_raceway_contacts",
           "contact_semi_axes_m",
           "STEEL_REDUCED_MODULUS_PA"]

#: E' = 2 / ((1 − ν1²)/E1 + (1 − ν2²)/E2) of steel on steel (E = 208 GPa, ν = 0.3), Pa.
STEEL_REDUCED_MODULUS_PA = 208e9 / (1.0 - 0.3 ** 2)

#: Table 7 of paper 001 (from Harris): curvature difference F(ρ) → dimensionless δ*.
DELTA_STAR_TABLE = np.array([
    (0.0, 1.0), (0.1075, 0.9974), (0.3204, 0.9761), (0.4795, 0.9429), (0.5916, 0.9077),
    (0.6716, 0.8733), (0.7332, 0.8394), (0.7948, 0.7961), (0.83495, 0.7602),
    (0.87366, 0.7169), (0.90999, 0.6636), (0.936738, 0.6112), (0.95738, 0.5551),
    (0.97290, 0.4960), (0.983797, 0.4352), (0.990902, 0.3745), (0.995112, 0.3176),
    (0.997300, 0.2705), (0.9981847, 0.2427), (0.9989156, 0.2106), (0.9994785, 0.17167),
    (0.9998527, 0.11995), (1.0, 0.0),
])

#: eq. B.6 constant, N/mm^1.5 with Σρ in 1/mm (steel on steel).
_KC_CONSTANT = 2.15e5
#: N/mm^p → N/m^p for p = 1.5.
_MM_TO_M_15 = 1000.0 ** 1.5


@dataclass(frozen=True)
class RacewayContact:
    """Curvature sum and difference of one ball-raceway contact.

    Attributes
    ----------
    curvature_sum_per_m : float
        Σρ of eq. B.3, 1/m.
    curvature_difference : float
        F(ρ) of eq. B.4, dimensionless in [0, 1).
    delta_star : float
        δ* interpolated linearly in Table 7.
    stiffness_n_per_m15 : float
        k_C of eq. B.6 converted to N/m^1.5.
    """

    curvature_sum_per_m: float
    curvature_difference: float
    delta_star: float
    stiffness_n_per_m15: float


def raceway_contact(ball_diameter_m, raceway_radius_m, groove_radius_m, *, inner):
    """Curvatures and Hertz stiffness of a ball on the inner or outer raceway.

    Parameters
    ----------
    ball_diameter_m : float
        Ball diameter d, m.
    raceway_radius_m : float
        Raceway radius R_i or R_o (half the raceway diameter), m.
    groove_radius_m : float
        Groove curvature radius r_i or r_o, m.
    inner : bool
        True for the inner raceway (convex, eq. B.1), False for the outer (concave, B.2).

    Returns
    -------
    RacewayContact
    """
    ra = 0.5 * ball_diameter_m
    rb1 = raceway_radius_m if inner else -raceway_radius_m
    rb2 = -groove_radius_m
    s = 2.0 / ra + 1.0 / rb1 + 1.0 / rb2
    f = ((1.0 / ra - 1.0 / ra) + (1.0 / rb1 - 1.0 / rb2)) / s
    delta_star = float(np.interp(f, DELTA_STAR_TABLE[:, 0], DELTA_STAR_TABLE[:, 1]))
    return RacewayContact(s, f, delta_star, contact_stiffness(s, delta_star))


def contact_stiffness(curvature_sum_per_m, delta_star):
    """Eq. B.6: k_C = 2.15e5 δ*^(-3/2) (Σρ)^(-1/2) N/mm^1.5, returned in N/m^1.5.

    Parameters
    ----------
    curvature_sum_per_m : float
        Σρ, 1/m.
    delta_star : float
        Dimensionless deflection δ* (Table 7).

    Returns
    -------
    float
        Contact stiffness, N/m^1.5.
    """
    sum_per_mm = curvature_sum_per_m * 1e-3
    return _KC_CONSTANT * delta_star ** -1.5 * sum_per_mm ** -0.5 * _MM_TO_M_15


def ball_stiffness(k_inner, k_outer, exponent=1.5):
    """Eq. B.7: series combination k = k_i k_o / (k_i^(1/p) + k_o^(1/p))^p.

    Parameters
    ----------
    k_inner, k_outer : float
        Contact stiffnesses with the inner and outer raceway, N/m^p.
    exponent : float
        Load-deflection exponent p.

    Returns
    -------
    float
        Ball stiffness k_RE, N/m^p.

    Examples
    --------
    Two equal springs in series with p = 1 halve the stiffness:

    >>> ball_stiffness(2.0, 2.0, exponent=1.0)
    1.0
    """
    p = float(exponent)
    return k_inner * k_outer / (k_inner ** (1.0 / p) + k_outer ** (1.0 / p)) ** p


def bearing_raceway_contacts(bearing):
    """(inner, outer) :class:`RacewayContact` of a bearing's balls.

    Parameters
    ----------
    bearing : cmsim.rig.Bearing
    """
    d = bearing.ball_diameter_m
    return (raceway_contact(d, 0.5 * bearing.inner_raceway_diameter_m,
                            bearing.inner_groove_radius_m, inner=True),
            raceway_contact(d, 0.5 * bearing.outer_raceway_diameter_m,
                            bearing.outer_groove_radius_m, inner=False))


def bearing_contact_stiffness(bearing):
    """k_RE of a :class:`~cmsim.rig.RollingBearing` from Annex B, N/m^p.

    Uses ``bearing.stiffness_n_per_m_p`` when it is set. Raceway radii are half the raceway
    diameters (papers/NOTES.md). Eq. B.6 is for steel balls on steel rings.

    Examples
    --------
    >>> from cmsim.rig import Rig
    >>> round(bearing_contact_stiffness(Rig.paper_2016().bearings[0]) / 1e10, 2)
    1.18
    """
    if bearing.stiffness_n_per_m_p is not None:
        return float(bearing.stiffness_n_per_m_p)
    if abs(bearing.load_exponent - 1.5) > 1e-12:
        raise ParameterError("Annex B gives ball (point-contact, p = 1.5) stiffness only; "
                             f"load_exponent = {bearing.load_exponent:g} needs "
                             "stiffness_n_per_m_p to be given")
    ci, co = bearing_raceway_contacts(bearing)
    return ball_stiffness(ci.stiffness_n_per_m15, co.stiffness_n_per_m15, bearing.load_exponent)


def contact_semi_axes_m(contact, ball_load_n, *, reduced_modulus_pa=STEEL_REDUCED_MODULUS_PA):
    """Semi-axes of the Hertz contact ellipse of a ball on a raceway, m.

    Hamrock & Brewe's closed form (ref. [3], ch. 3: ellipticity k = α^(2/π), elliptic
    integral E = 1 + (π/2 − 1)/α with α = R_y/R_x): D_y = 2 (6 k² E w R/(π E'))^(1/3),
    D_x = 2 (6 E w R/(π k E'))^(1/3). The effective radii along (R_x) and across (R_y) the
    rolling direction come from the contact's curvature sum and difference (eq. B.3-B.4):
    1/R_x, 1/R_y = Σρ (1 ± F(ρ))/2, and 1/R = Σρ.

    Parameters
    ----------
    contact : RacewayContact
        The ball-raceway contact (:func:`raceway_contact`).
    ball_load_n : float
        Normal load of the ball on the raceway, N (>= 0).
    reduced_modulus_pa : float
        E' of the two bodies, Pa.

    Returns
    -------
    (float, float)
        Semi-axis along the rolling direction and across it (along the bearing axis for a
        radial ball bearing: the wider one), m.

    Examples
    --------
    A 6205 ball on its outer raceway at 200 N: a band about 1.5 mm wide across the track.

    >>> ax, ay = contact_semi_axes_m(
    ...     raceway_contact(7.94e-3, 23.49e-3, 4.13e-3, inner=False), 200.0)
    >>> round(ay * 1e3, 2), round(ax * 1e3, 3)
    (0.73, 0.104)
    """
    total, diff = contact.curvature_sum_per_m, contact.curvature_difference
    rx, ry = 2.0 / (total * (1.0 + diff)), 2.0 / (total * (1.0 - diff))
    r = 1.0 / total
    alpha = ry / rx
    k = alpha ** (2.0 / np.pi)
    e = 1.0 + (0.5 * np.pi - 1.0) / alpha
    w = max(float(ball_load_n), 0.0)
    dy = 2.0 * (6.0 * k * k * e * w * r / (np.pi * reduced_modulus_pa)) ** (1.0 / 3.0)
    dx = 2.0 * (6.0 * e * w * r / (np.pi * k * reduced_modulus_pa)) ** (1.0 / 3.0)
    return 0.5 * float(dx), 0.5 * float(dy)
