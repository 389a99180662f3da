"""Elastohydrodynamic film thickness: ball-race (point) and tooth (line) contacts.

Point contact, Hamrock & Dowson (1977), with U = η0·u/(E'·R_x), G = α·E',
W = w/(E'·R_x²) and the ellipticity k = 1.0339·(R_y/R_x)^0.636:

    H_c   = h_c/R_x   = 2.69 · U^0.67 · G^0.53 · W^−0.067 · (1 − 0.61·e^(−0.73k))
    H_min = h_min/R_x = 3.63 · U^0.68 · G^0.49 · W^−0.073 · (1 − e^(−0.68k))

Line contact (tooth pairs), W' = w'/(E'·R) with w' the load per unit face width:
central film of Dowson & Toyoda H_c = 3.06·U^0.69·G^0.56·W'^−0.10 and minimum film of
Dowson & Higginson H_min = 2.65·U^0.70·G^0.54·W'^−0.13.

u is the entrainment (mean rolling) velocity (u1 + u2)/2 of the two surfaces relative to the
contact, E' = 2/((1 − ν1²)/E1 + (1 − ν2²)/E2).

References
----------
.. [1] B.J. Hamrock, D. Dowson, Isothermal elastohydrodynamic lubrication of point contacts,
       Part III, J. Lubr. Technol. 99 (1977) 264-276.
.. [2] D. Dowson, G.R. Higginson, Elastohydrodynamic Lubrication, Pergamon 1977.
.. [3] G.W. Stachowiak, A.W. Batchelor, Engineering Tribology, ch. 7 (worked problems).
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.errors import ParameterError, check_range
from cmsim.mesh_stiffness.contact import active_path_m

__all__ = ["reduced_modulus_pa", "film_thickness_point", "film_thickness_line",
           "pair_load_share", "mesh_film_along_path", "ball_race_curvatures", "bearing_films"]


def reduced_modulus_pa(e1_pa, nu1, e2_pa=None, nu2=None):
    """E' = 2/((1 − ν1²)/E1 + (1 − ν2²)/E2), Pa (body 2 defaults to body 1).

    Parameters
    ----------
    e1_pa, e2_pa : float
        Young's moduli, Pa.
    nu1, nu2 : float
        Poisson ratios.

    Examples
    --------
    >>> round(reduced_modulus_pa(210e9, 0.3) / 1e9, 2)
    230.77
    """
    e2_pa = e1_pa if e2_pa is None else e2_pa
    nu2 = nu1 if nu2 is None else nu2
    for name, v in (("e1_pa", e1_pa), ("e2_pa", e2_pa)):
        check_range(name, v, 0.0, 1e13, lo_open=True, unit="Pa")
    for name, v in (("nu1", nu1), ("nu2", nu2)):
        check_range(name, v, -1.0, 0.5, lo_open=True)
    return 2.0 / ((1 - nu1 ** 2) / e1_pa + (1 - nu2 ** 2) / e2_pa)


def _positive(name, value):
    a = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ParameterError(f"{name} must be finite and >= 0, got {value!r}")
    return a


def film_thickness_point(load_n, entrainment_m_s, rx_m, ry_m, viscosity_pa_s,
                         pressure_viscosity_pa_inv, reduced_modulus_pa):
    """Central and minimum film of an elliptical contact (Hamrock–Dowson), m.

    Parameters
    ----------
    load_n : float or ndarray
        Contact load w, N (> 0).
    entrainment_m_s : float or ndarray
        Entrainment velocity u = (u1 + u2)/2, m/s (>= 0; 0 gives no film).
    rx_m, ry_m : float
        Effective radii along and across the rolling direction, m.
    viscosity_pa_s : float
        Dynamic viscosity at ambient pressure η0, Pa·s.
    pressure_viscosity_pa_inv : float
        Barus coefficient α, 1/Pa.
    reduced_modulus_pa : float
        E', Pa (:func:`reduced_modulus_pa`).

    Returns
    -------
    (h_c, h_min) : ndarray
        Central and minimum film thickness, m.
    """
    w = _positive("load_n", load_n)
    u = _positive("entrainment_m_s", entrainment_m_s)
    check_range("rx_m", rx_m, 0.0, 10.0, lo_open=True, unit="m")
    check_range("ry_m", ry_m, 0.0, 1e3, lo_open=True, unit="m")
    e = reduced_modulus_pa
    k = 1.0339 * (ry_m / rx_m) ** 0.636
    uu = viscosity_pa_s * u / (e * rx_m)
    g = pressure_viscosity_pa_inv * e
    ww = np.maximum(w, 1e-12) / (e * rx_m ** 2)
    hc = 2.69 * uu ** 0.67 * g ** 0.53 * ww ** -0.067 * (1 - 0.61 * math.exp(-0.73 * k))
    hm = 3.63 * uu ** 0.68 * g ** 0.49 * ww ** -0.073 * (1 - math.exp(-0.68 * k))
    return hc * rx_m, hm * rx_m


def film_thickness_line(load_per_width_n_m, entrainment_m_s, radius_m, viscosity_pa_s,
                        pressure_viscosity_pa_inv, reduced_modulus_pa):
    """Central (Dowson–Toyoda) and minimum (Dowson–Higginson) film of a line contact, m.

    Parameters
    ----------
    load_per_width_n_m : float or ndarray
        Load per unit face width w', N/m.
    entrainment_m_s : float or ndarray
        Entrainment velocity, m/s.
    radius_m : float or ndarray
        Equivalent radius R = ρ1ρ2/(ρ1 + ρ2), m (> 0).
    viscosity_pa_s, pressure_viscosity_pa_inv, reduced_modulus_pa : float
        As :func:`film_thickness_point`.

    Returns
    -------
    (h_c, h_min) : ndarray, m
    """
    w = _positive("load_per_width_n_m", load_per_width_n_m)
    u = _positive("entrainment_m_s", entrainment_m_s)
    r = _positive("radius_m", radius_m)
    e = reduced_modulus_pa
    r = np.maximum(r, 1e-9)
    uu = viscosity_pa_s * u / (e * r)
    g = pressure_viscosity_pa_inv * e
    ww = np.maximum(w, 1e-6) / (e * r)
    hc = 3.06 * uu ** 0.69 * g ** 0.56 * ww ** -0.10
    hm = 2.65 * uu ** 0.70 * g ** 0.54 * ww ** -0.13
    return hc * r, hm * r


def pair_load_share(pair, mesh_table, positions_m):
    """Quasi-static share of the mesh load carried by the pair at ``positions_m``.

    Pairs one base pitch apart deflect alike, so a pair carries k(s)/Σ_m k(s + m·p_b) of the
    load (k from ``mesh_table``, or 1 on the loaded range for ``None``), shape like
    ``positions_m``.
    """
    s = np.asarray(positions_m, dtype=float)
    pb = pair.driving.base_pitch_m
    if mesh_table is None:
        lo, hi = active_path_m(pair)

        def k_of(x):
            return ((x >= lo) & (x <= hi)).astype(float)
    else:
        lo, hi = mesh_table.contact_range_m(pair)

        def k_of(x):
            return np.where((x >= lo) & (x <= hi), mesh_table.stiffness_at(x), 0.0)
    own = k_of(s)
    total = np.zeros_like(s)
    for m in range(-3, 4):
        total += k_of(s + m * pb)
    return np.where(total > 0, own / np.where(total > 0, total, 1.0), 0.0)


def mesh_film_along_path(rig, op, positions_m, mesh_table=None, *, viscosity_pa_s=None):
    """Kinematics, load and EHL film of the tooth contact at positions s on the line of action.

    Parameters
    ----------
    rig : Rig
        A gear rig; its lubricant gives η0 (unless ``viscosity_pa_s``) and α.
    op : OperatingPoint
    positions_m : ndarray
        Positions s from T1, m.
    mesh_table : MeshStiffnessTable, optional
        Load sharing between pairs (:func:`pair_load_share`).
    viscosity_pa_s : float, optional
        Override of the oil viscosity, Pa·s.

    Returns
    -------
    dict of ndarray
        ``rho1_m``, ``rho2_m`` (radii of curvature), ``radius_m`` (equivalent),
        ``entrainment_m_s``, ``sliding_m_s`` (ω1ρ1 − ω2ρ2, signed), ``load_n`` (pair load),
        ``load_per_width_n_m``, ``half_width_m`` (Hertz b), ``mean_pressure_pa``,
        ``h_c_m``, ``h_min_m``.
    """
    pair = rig.gears
    if pair is None:
        raise ParameterError("mesh_film_along_path needs a rig with gears")
    s = np.asarray(positions_m, dtype=float)
    length = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)
    rho1 = np.clip(s, 1e-4, None)
    rho2 = np.clip(length - s, 1e-4, None)
    radius = rho1 * rho2 / (rho1 + rho2)
    w1 = op.omega_rad_s
    w2 = w1 * pair.driving.n_teeth / pair.driven.n_teeth
    u_e = 0.5 * (w1 * rho1 + w2 * rho2)
    v_s = w1 * rho1 - w2 * rho2
    total = op.torque_nm / pair.driven.base_radius_m
    load = total * pair_load_share(pair, mesh_table, s)
    width = min(pair.driving.face_width_m, pair.driven.face_width_m)
    e = reduced_modulus_pa(pair.driving.youngs_modulus_pa, pair.driving.poisson_ratio,
                           pair.driven.youngs_modulus_pa, pair.driven.poisson_ratio)
    wprime = load / width
    half = np.sqrt(8.0 * wprime * radius / (math.pi * e))
    p_mean = np.where(half > 0, wprime / np.where(half > 0, 2 * half, 1.0), 0.0)
    lub = rig.lubricant
    eta = lub.dynamic_viscosity_pa_s if viscosity_pa_s is None else viscosity_pa_s
    hc, hm = film_thickness_line(wprime, u_e, radius, eta, lub.pressure_viscosity_pa_inv, e)
    return {"rho1_m": rho1, "rho2_m": rho2, "radius_m": radius, "entrainment_m_s": u_e,
            "sliding_m_s": v_s, "load_n": load, "load_per_width_n_m": wprime,
            "half_width_m": half, "mean_pressure_pa": p_mean, "h_c_m": hc, "h_min_m": hm}


def ball_race_curvatures(bearing):
    """((R_x, R_y) inner, (R_x, R_y) outer) effective radii of the ball-race contacts, m.

    Parameters
    ----------
    bearing : RollingBearing
    """
    d = bearing.ball_diameter_m * math.cos(bearing.effective_contact_angle_rad)
    dm = bearing.pitch_diameter_m
    db = bearing.ball_diameter_m
    ri, ro = bearing.inner_groove_radius_m, bearing.outer_groove_radius_m
    rx_i = 0.5 * db * (dm - d) / dm
    rx_o = 0.5 * db * (dm + d) / dm
    ry_i = ri * db / (2 * ri - db)
    ry_o = ro * db / (2 * ro - db)
    return (rx_i, ry_i), (rx_o, ry_o)


def bearing_films(bearing, kinematics, ball_load_n, lubricant, reduced_modulus):
    """Central and minimum films (m) of the inner and outer contacts of the loaded ball.

    Parameters
    ----------
    bearing : RollingBearing
    kinematics : RingKinematics
        From :func:`cmsim.losses.bearing_friction.ring_kinematics` (both rings may turn).
    ball_load_n : float
        Load of the ball, N (Stribeck: Q_max ≈ 5·F_r/Z).
    lubricant : Lubricant
    reduced_modulus : float
        E', Pa.

    Returns
    -------
    dict
        ``inner`` and ``outer``: (h_c, h_min), m.
    """
    (rxi, ryi), (rxo, ryo) = ball_race_curvatures(bearing)
    args = (lubricant.dynamic_viscosity_pa_s, lubricant.pressure_viscosity_pa_inv,
            reduced_modulus)
    hi = film_thickness_point(ball_load_n, kinematics.inner_entrainment_m_s, rxi, ryi, *args)
    ho = film_thickness_point(ball_load_n, kinematics.outer_entrainment_m_s, rxo, ryo, *args)
    return {"inner": tuple(float(x) for x in hi), "outer": tuple(float(x) for x in ho)}
