"""Local contact deflection of the hybrid method: Hertz line contact, Weber-Banaschek approach.

The hybrid method (paper 001 §3, Vedmar & Andersson [3]) splits the compliance of a tooth
into the finite-element displacement of a point at depth ``h`` below the contact (influence
coefficients, :mod:`cmsim.mesh_stiffness.influence`) and the *local* approach between the
surface point and that depth point, given here in closed form.

For two cylinders in line contact (radii χ1, χ2, face width b, normal force F) the Hertz
half-width is

    a = sqrt(4 F R / (π b E*)),   1/R = 1/χ1 + 1/χ2,   1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2.

Under the elliptic pressure p(x) = p0 sqrt(1 − x²/a²), p0 = 2F/(π a b), the stresses on the
symmetry axis at depth z are (Johnson [2], eq. 4.47, McEwen)

    σ_z = −p0 a / sqrt(a² + z²),   σ_x = −(p0/a) [(a² + 2z²)/sqrt(a² + z²) − 2z],

and in plane strain ε_z = [(1 − ν²) σ_z − ν(1 + ν) σ_x]/E. Integrating −ε_z from the surface to
the depth h gives the approach of the surface point towards the depth-h point of one body

    u = (2F / (π E b)) [(1 − ν²) asinh(h/a) − ν(1 + ν) q],   q = h / (sqrt(a² + h²) + h),

exactly for the half-plane. For h ≫ a, asinh(h/a) → ln(2h/a) and q → 1/2, which is the
Weber-Banaschek formula [1] (as used by Vedmar [3] and in paper 001):

    u = 2F(1 − ν²)/(π E b) · [ln(2h/a) − ν/(2(1 − ν))].

The exact form is kept because it stays positive and monotone for any h/a (it matters only
for the small tip-rounding radii of corner contact). All quantities SI.

References
----------
.. [1] W. Weber, K. Banaschek, "Formänderung und Profilrücknahme bei gerad- und
   schrägverzahnten Rädern", Schriftenreihe Antriebstechnik 11, Vieweg (1953); re-derived in
   J.-F. Hochrein, M. Otto, K. Stahl, "Fast tooth deflection calculation method and its
   validation", Forsch. Ingenieurwes. 86 (2022) 775-790.
.. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press (1985), §4.2
   (two-dimensional Hertz contact, eq. 4.47).
.. [3] L. Vedmar, A. Andersson, "A method to determine dynamic loads on spur gear teeth and
   on bearings", J. Sound Vib. 267 (2003) 1065-1084.
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.errors import check_range

__all__ = ["hertz_half_width", "local_approach", "local_approach_weber_banaschek",
           "contact_modulus"]


def contact_modulus(youngs_1_pa, poisson_1, youngs_2_pa, poisson_2):
    """Plane-strain contact modulus E* = 1/[(1 − ν1²)/E1 + (1 − ν2²)/E2], Pa."""
    return 1.0 / ((1.0 - poisson_1 ** 2) / youngs_1_pa + (1.0 - poisson_2 ** 2) / youngs_2_pa)


def hertz_half_width(force_n, radius_1_m, radius_2_m, face_width_m, contact_modulus_pa):
    """Half-width of the Hertz line contact of two convex cylinders, m.

    Parameters
    ----------
    force_n : float or ndarray
        Normal force F >= 0, N.
    radius_1_m, radius_2_m : float or ndarray
        Radii of curvature χ1, χ2 > 0 (the involute's is its roll length), m.
    face_width_m : float
        b, m.
    contact_modulus_pa : float
        E* (:func:`contact_modulus`), Pa.

    Returns
    -------
    float or ndarray
        a = sqrt(4 F R / (π b E*)), m.

    Examples
    --------
    >>> E = contact_modulus(210e9, 0.3, 210e9, 0.3)
    >>> round(hertz_half_width(1000.0, 0.0152, 0.0152, 6.35e-3, E) * 1e6, 1)
    114.9
    """
    r = np.asarray(radius_1_m, dtype=float) * radius_2_m / (np.asarray(radius_1_m) + radius_2_m)
    a = np.sqrt(4.0 * np.asarray(force_n, dtype=float) * r
                / (math.pi * face_width_m * contact_modulus_pa))
    return float(a) if a.ndim == 0 else a


def local_approach(force_n, half_width_m, depth_m, youngs_modulus_pa, poisson_ratio,
                   face_width_m):
    """Approach of the contact point towards the point at depth h of one body, m.

    Exact plane-strain half-plane result under the Hertz pressure (module docstring).

    Parameters
    ----------
    force_n : float or ndarray
        F >= 0, N.
    half_width_m : float or ndarray
        Hertz half-width a > 0 (:func:`hertz_half_width`), m.
    depth_m : float
        h > 0, m.
    youngs_modulus_pa, poisson_ratio : float
        E, ν of this body.
    face_width_m : float
        b, m.

    Returns
    -------
    float or ndarray
        u, m; 0 where F = 0.
    """
    f = np.asarray(force_n, dtype=float)
    a = np.maximum(np.asarray(half_width_m, dtype=float), 1e-300)
    h, nu = float(depth_m), float(poisson_ratio)
    q = h / (np.sqrt(a * a + h * h) + h)
    g = (1.0 - nu * nu) * np.arcsinh(h / a) - nu * (1.0 + nu) * q
    u = 2.0 * f / (math.pi * youngs_modulus_pa * face_width_m) * g
    return np.where(f > 0.0, u, 0.0) if np.ndim(u) else (float(u) if f > 0 else 0.0)


def local_approach_weber_banaschek(force_n, half_width_m, depth_m, youngs_modulus_pa,
                                   poisson_ratio, face_width_m):
    """The classical Weber-Banaschek form 2F(1 − ν²)/(π E b)[ln(2h/a) − ν/(2(1 − ν))], m.

    The h ≫ a limit of :func:`local_approach` (for comparison and tests).
    """
    check_range("depth_m", depth_m, 0.0, lo_open=True, unit="m")
    nu = float(poisson_ratio)
    f = np.asarray(force_n, dtype=float)
    return (2.0 * f * (1.0 - nu * nu) / (math.pi * youngs_modulus_pa * face_width_m)
            * (np.log(2.0 * depth_m / np.asarray(half_width_m)) - nu / (2.0 * (1.0 - nu))))
