"""Non-stationary operation: input speed and output torque that follow a profile in time.

A :class:`SpeedProfile` gives the input shaft speed (rpm) and, optionally, the output torque
(N·m) at a few instants, piecewise linear between them (a run-up, a coast-down, a measured
speed trace), and holds the last values after its end. Multiplicative modulations (a speed
wobble, a torque ripple from :mod:`cmsim.faults`) may be laid on top. :func:`kernel_profile`
samples the result on a uniform grid for the kernels: the input shaft angle Θ(t) (the exact
integral of the piecewise-linear speed, plus the modulation integrated numerically), the
speed Ω(t), its rate dΩ/dt and the torque T(t). The nominal rotation of every shaft, cage and
involute then follows Θ(t), and the deviation coordinates carry the inertia load −J·dΩ/dt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cmsim.dynamics._rhs_kernels import PR_ALPHA, PR_OMEGA, PR_SIZE, PR_THETA, PR_TORQUE
from cmsim.errors import ParameterError, check_range

__all__ = ["SpeedProfile", "KernelProfile", "kernel_profile"]


@dataclass(frozen=True)
class SpeedProfile:
    """Input speed (and optionally output torque) against time, piecewise linear.

    Attributes
    ----------
    times_s : tuple of float
        Strictly increasing instants from 0, s.
    speeds_rpm : tuple of float
        Input shaft speed at each instant, rpm (> 0: the model's cage and mesh kinematics
        assume the sense of rotation does not change).
    torques_nm : tuple of float or None
        Output torque at each instant, N·m (>= 0); ``None`` keeps the operating point's.
    """

    times_s: tuple
    speeds_rpm: tuple
    torques_nm: tuple | None = None

    def __post_init__(self):
        t = tuple(float(check_range("times_s", v, 0.0, 1e5, unit="s")) for v in self.times_s)
        w = tuple(float(check_range("speeds_rpm", v, 0.0, 1e5, lo_open=True, unit="rpm"))
                  for v in self.speeds_rpm)
        if len(t) < 1 or len(t) != len(w):
            raise ParameterError("speed profile: times_s and speeds_rpm need the same length "
                                 ">= 1")
        if t[0] != 0.0 or any(b <= a for a, b in zip(t, t[1:])):
            raise ParameterError("speed profile: times_s must start at 0 and increase")
        object.__setattr__(self, "times_s", t)
        object.__setattr__(self, "speeds_rpm", w)
        if self.torques_nm is not None:
            q = tuple(float(check_range("torques_nm", v, 0.0, 1e6, unit="N m"))
                      for v in self.torques_nm)
            if len(q) != len(t):
                raise ParameterError("speed profile: torques_nm needs one value per instant")
            object.__setattr__(self, "torques_nm", q)

    @classmethod
    def ramp(cls, start_rpm, end_rpm, duration_s, *, start_s=0.0):
        """Constant speed ``start_rpm`` until ``start_s``, then linear to ``end_rpm`` over
        ``duration_s`` (a run-up or coast-down)."""
        duration_s = check_range("duration_s", duration_s, 0.0, 1e5, lo_open=True, unit="s")
        start_s = check_range("start_s", start_s, 0.0, 1e5, unit="s")
        if start_s > 0:
            return cls((0.0, start_s, start_s + duration_s), (start_rpm, start_rpm, end_rpm))
        return cls((0.0, duration_s), (start_rpm, end_rpm))

    @property
    def initial_rpm(self):
        """Speed at t = 0, rpm."""
        return self.speeds_rpm[0]

    def speed_rpm_at(self, t_s):
        """Speed at ``t_s`` (array), rpm."""
        return np.interp(t_s, self.times_s, self.speeds_rpm)

    def angle_rad_at(self, t_s):
        """Exact input shaft angle ∫Ω dt from 0 to ``t_s`` (array), rad."""
        t_s = np.asarray(t_s, dtype=float)
        tk = np.array(self.times_s)
        wk = np.array(self.speeds_rpm) * (2.0 * math.pi / 60.0)
        # angle at the knots, then the trapezoid of the partial segment
        knots = np.concatenate([[0.0], np.cumsum(0.5 * (wk[1:] + wk[:-1]) * np.diff(tk))])
        i = np.clip(np.searchsorted(tk, t_s, side="right") - 1, 0, tk.size - 1)
        w_t = np.interp(t_s, tk, wk)
        return knots[i] + 0.5 * (wk[i] + w_t) * (t_s - tk[i])

    def to_dict(self):
        """JSON-ready values."""
        return {"times_s": list(self.times_s), "speeds_rpm": list(self.speeds_rpm),
                "torques_nm": None if self.torques_nm is None else list(self.torques_nm)}


class KernelProfile(NamedTuple):
    """Profile table for the kernels (:data:`cmsim.dynamics._rhs_kernels.PR_SIZE` columns)."""

    t0_s: float
    dt_s: float
    table: np.ndarray


def kernel_profile(profile, torque_nm, end_s, dt_s, *, speed_factor=None, torque_factor=None):
    """Sample a profile (and modulations) on a uniform grid for the kernels.

    Parameters
    ----------
    profile : SpeedProfile or None
        Input speed (and torque) against time; ``None`` = the constant ``speed`` of the
        modulated operating point (then ``speed_factor`` or ``torque_factor`` is required).
    torque_nm : float
        Output torque when the profile gives none, N·m.
    end_s : float
        Last instant the run reaches, s.
    dt_s : float
        Grid spacing, s (the integration step or a small multiple of it).
    speed_factor, torque_factor : callable, optional
        Relative modulations ``f(t) -> array`` multiplying the speed and the torque.

    Returns
    -------
    KernelProfile
    """
    n = int(math.ceil(end_s / dt_s)) + 3
    t = np.arange(n) * dt_s
    if profile is None:
        raise ParameterError("kernel_profile needs a SpeedProfile")
    omega = profile.speed_rpm_at(t) * (2.0 * math.pi / 60.0)
    theta = profile.angle_rad_at(t)
    alpha = np.gradient(omega, dt_s)
    if speed_factor is not None:
        fac = np.asarray(speed_factor(t), dtype=float)
        if fac.shape != t.shape or not np.all(np.isfinite(fac)) or np.any(fac <= 0):
            raise ParameterError("speed modulation must stay positive and finite")
        omega = omega * fac
        # cumulative trapezoid of the modulated speed: second-order accurate on the grid
        theta = np.concatenate([[0.0], np.cumsum(0.5 * (omega[1:] + omega[:-1]) * dt_s)])
        alpha = np.gradient(omega, dt_s)
    if profile.torques_nm is not None:
        torque = np.interp(t, profile.times_s, profile.torques_nm)
    else:
        torque = np.full(n, float(torque_nm))
    if torque_factor is not None:
        torque = torque * np.asarray(torque_factor(t), dtype=float)
    table = np.empty((n, PR_SIZE))
    table[:, PR_THETA] = theta
    table[:, PR_OMEGA] = omega
    table[:, PR_ALPHA] = alpha
    table[:, PR_TORQUE] = torque
    return KernelProfile(0.0, float(dt_s), np.ascontiguousarray(table))
