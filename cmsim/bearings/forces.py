"""Ball forces of a radial bearing with clearance or preload (Fukata et al.; paper 001 §5).

References
----------
.. [1] S. Fukata et al., "On the radial vibration of ball bearings (computer simulation)",
   Bulletin of the JSME 28 (239) (1985) 899-904.
.. [2] A. Fernandez-del-Rincon et al., MSSP 2016, eqs. 7-9.
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.bearings._kernels import (ball_forces_jit, ball_tangent_stiffness_jit,
                                     loaded_ball_count_jit)
from cmsim.bearings.hertz import bearing_contact_stiffness
from cmsim.errors import check_range

__all__ = ["ball_offsets", "bearing_force", "bearing_tangent_stiffness", "loaded_balls",
           "bearing_strain_energy"]


def ball_offsets(bearing):
    """(cos, sin) of the nominal ball spacing 2π(i−1)/N_b, each shape ``(n_balls,)``."""
    phi = 2.0 * math.pi * np.arange(bearing.n_balls) / bearing.n_balls
    return np.cos(phi), np.sin(phi)


def _args(bearing, x_m, y_m, cage_angle_rad):
    x = check_range("x_m", x_m, -0.01, 0.01, unit="m")
    y = check_range("y_m", y_m, -0.01, 0.01, unit="m")
    cage = check_range("cage_angle_rad", cage_angle_rad, unit="rad")
    cos_off, sin_off = ball_offsets(bearing)
    return x, y, math.cos(cage), math.sin(cage), cos_off, sin_off


def bearing_force(bearing, x_m, y_m, cage_angle_rad=0.0):
    """Force (Fx, Fy) that the balls put on the housing, N.

    Parameters
    ----------
    bearing : RollingBearing
        Bearing geometry and clearance.
    x_m, y_m : float
        Inner-ring centre offset from the outer-ring centre, m.
    cage_angle_rad : float
        Cage angle θ_cage (ball 1 at θ_cage from +x), rad.

    Returns
    -------
    tuple of float
        (Fx, Fy), N.
    """
    x, y, cc, sc, co, so = _args(bearing, x_m, y_m, cage_angle_rad)
    return ball_forces_jit(x, y, cc, sc, co, so, bearing_contact_stiffness(bearing),
                           bearing.load_exponent, bearing.clearance_m)


def bearing_tangent_stiffness(bearing, x_m, y_m, cage_angle_rad=0.0):
    """Tangent stiffness matrix ∂F/∂(x, y), shape ``(2, 2)``, N/m."""
    x, y, cc, sc, co, so = _args(bearing, x_m, y_m, cage_angle_rad)
    kxx, kxy, kyy = ball_tangent_stiffness_jit(x, y, cc, sc, co, so,
                                               bearing_contact_stiffness(bearing),
                                               bearing.load_exponent, bearing.clearance_m)
    return np.array([[kxx, kxy], [kxy, kyy]])


def loaded_balls(bearing, x_m, y_m, cage_angle_rad=0.0):
    """Number of balls in contact."""
    x, y, cc, sc, co, so = _args(bearing, x_m, y_m, cage_angle_rad)
    return int(loaded_ball_count_jit(x, y, cc, sc, co, so, bearing.clearance_m))


def bearing_strain_energy(bearing, x_m, y_m, cage_angle_rad):
    """Elastic energy stored in the ball contacts, k/(p+1)·Σ H(δ_i) δ_i^(p+1), J.

    Its gradient in (x, y) is the force of :func:`bearing_force`. Arrays broadcast.

    Parameters
    ----------
    bearing : RollingBearing
    x_m, y_m : float or ndarray
        Inner-ring offset, m.
    cage_angle_rad : float or ndarray
        Cage angle, rad.

    Returns
    -------
    float or ndarray
        Energy, J.
    """
    x, y, cage = np.broadcast_arrays(np.asarray(x_m, float), np.asarray(y_m, float),
                                     np.asarray(cage_angle_rad, float))
    theta = cage[..., None] + 2.0 * math.pi * np.arange(bearing.n_balls) / bearing.n_balls
    overlap = x[..., None] * np.cos(theta) + y[..., None] * np.sin(theta) - bearing.clearance_m
    p = bearing.load_exponent
    energy = bearing_contact_stiffness(bearing) / (p + 1.0) * np.sum(
        np.clip(overlap, 0.0, None) ** (p + 1.0), axis=-1)
    return energy if energy.ndim else float(energy)
