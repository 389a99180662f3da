"""Cage and ball-pass kinematics with inner and outer ring rotation (paper 001 eq. 6-7).

θ_cage = θ_in·(1 − γ)/2 + θ_out·(1 + γ)/2 with γ = (d/D)·cos α; with both rings turning,
same-sense and counter rotation follow from the signs (paper 002, Table 1:
n_c = n_i K1 ± n_o K2).

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, eqs. 6-7.
.. [2] Paper 002 (inter-shaft bearing with both rings rotating), Table 1.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import lfilter

from cmsim.frequencies import cage_speed_ratios

__all__ = ["cage_ratios", "cage_angle", "ball_angles", "ball_pass_cycles_per_rev",
           "slip_jitter"]


def cage_ratios(bearing):
    """(K_in, K_out) with θ_cage = K_in·θ_in + K_out·θ_out
    (:func:`cmsim.frequencies.cage_speed_ratios`, the one cage formula).

    Examples
    --------
    >>> from cmsim.rig import Rig
    >>> k_in, k_out = cage_ratios(Rig.paper_2016().bearings[0])
    >>> round(k_in + k_out, 12)
    1.0
    """
    return cage_speed_ratios(bearing.ball_diameter_m, bearing.pitch_diameter_m,
                             bearing.effective_contact_angle_rad)


def cage_angle(bearing, theta_inner_rad, theta_outer_rad=0.0):
    """Cage angle from the ring angles, eq. 6, rad (arrays broadcast)."""
    k_in, k_out = cage_ratios(bearing)
    return k_in * np.asarray(theta_inner_rad) + k_out * np.asarray(theta_outer_rad)


def ball_angles(bearing, theta_inner_rad, theta_outer_rad=0.0, offset_rad=0.0):
    """Angular positions of all balls, eq. 7 generalised: shape ``(..., n_balls)``, rad."""
    c = cage_angle(bearing, theta_inner_rad, theta_outer_rad)
    spacing = 2.0 * math.pi * np.arange(bearing.n_balls) / bearing.n_balls
    return np.asarray(c)[..., None] + spacing + offset_rad


def ball_pass_cycles_per_rev(bearing):
    """Ball passes over a fixed load direction per inner-ring revolution.

    N_b·|K_in + K_out·ρ| with ρ = ``outer_ring_speed_ratio``. The paper's rig gives 3.6339
    with the bearing's free contact angle (9.94°); the paper prints 3.6342 (α ≈ 10.0°).

    Examples
    --------
    >>> from cmsim.rig import Rig
    >>> round(ball_pass_cycles_per_rev(Rig.paper_2016().bearings[0]), 4)
    3.6339
    """
    k_in, k_out = cage_ratios(bearing)
    return bearing.n_balls * abs(k_in + k_out * bearing.outer_ring_speed_ratio)


def slip_jitter(n_balls, n_samples, dt_s, rms_rad, correlation_s, rng):
    """Random ball-angle deviations imitating rolling slip, shape ``(n_balls, n_samples)``, rad.

    Each ball gets an independent Ornstein-Uhlenbeck process (exact discretisation) with
    standard deviation ``rms_rad`` and correlation time ``correlation_s``, started from its
    stationary distribution so the record has no transient. The random generator stays here,
    outside the numba kernels.

    Parameters
    ----------
    n_balls, n_samples : int
        Output shape.
    dt_s : float
        Sample spacing, s.
    rms_rad : float
        Standard deviation of each ball's angular deviation, rad.
    correlation_s : float
        Correlation time, s.
    rng : numpy.random.Generator
        Source of randomness (seeded by the caller).
    """
    out = np.empty((n_balls, n_samples))
    if rms_rad == 0.0:
        out[:] = 0.0
        return out
    a = math.exp(-dt_s / correlation_s)
    b = rms_rad * math.sqrt(1.0 - a * a)
    noise = rng.standard_normal((n_balls, n_samples))
    drive = b * noise
    drive[:, 0] = rms_rad * noise[:, 0]
    # out[i] = a·out[i−1] + b·noise[i], the recursion run by lfilter (same arithmetic)
    out[:] = lfilter([1.0], [1.0, -a], drive, axis=1)
    return out
