"""Quasi-static equilibrium (paper 001 eq. 1 with velocity and acceleration terms dropped).

Solved relative to the nominal rigid rotation at a given instant, so the cage and mesh
positions follow from the time; friction acts with the nominal sliding velocities. Used as the
initial state of the dynamics, for the bearing-cycle orbits of paper Fig. 3 and as the
linearisation point of the modal analysis.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import root

from cmsim.bearings.hertz import bearing_contact_stiffness
from cmsim.errors import IntegrationDiverged

__all__ = ["quasi_static_state", "quasi_static_orbit"]


def _scales(model):
    rig, op = model.rig, model.op
    if rig.gears is not None:
        rb = rig.gears.driving.base_radius_m
        f_ref = max(op.torque_nm / rb, op.radial_load_n, 1.0)
        length = rb
    else:
        f_ref = max(op.radial_load_n, 1.0)
        length = 0.05
    rot = np.array([d.startswith("theta") for d in model.dof_names])
    q_scale = np.where(rot, 1e-4, 1e-5)
    f_scale = np.where(rot, f_ref * length, f_ref)
    return q_scale, f_scale, f_ref


def _linear_guess(model, f_ref):
    """Static solution of a linearised model: bearings as springs, mesh as k̄·g·gᵀ."""
    kmat = model.stiffness.copy()
    offsets = np.zeros(model.n_dof)
    nb = len(model.rig.bearings)
    for ib, brg in enumerate(model.rig.bearings):
        load = max(f_ref / 2.0, 10.0)
        k_re = bearing_contact_stiffness(brg)
        deflection = (load / k_re) ** (1.0 / brg.load_exponent)
        k_lin = 1.5 * load / deflection
        ix = int(model.packed.b_int[ib, 0])
        kmat[ix, ix] += k_lin
        kmat[ix + 1, ix + 1] += k_lin
        offsets[ix:ix + 2] = max(brg.clearance_m, 0.0)
    if model.rig.gears is not None:
        g = model.mesh_jacobian()
        kmat += model.mesh_table.mean_mesh_stiffness(model.rig.gears) * np.outer(g, g)
    q = np.linalg.solve(kmat, model.force)
    # push each bearing across its clearance in the direction it moves
    for ib in range(nb):
        ix = int(model.packed.b_int[ib, 0])
        r = math.hypot(q[ix], q[ix + 1])
        if r > 0:
            q[ix:ix + 2] += offsets[ix:ix + 2] * q[ix:ix + 2] / r
    return q


def quasi_static_state(model, t=0.0, q_guess=None, tol=1e-9):
    """DOF deviations ``q`` (shape (n,)) in static equilibrium at time ``t``.

    Parameters
    ----------
    model : DynamicModel
    t : float
        Instant (sets the cage and mesh positions), s.
    q_guess : ndarray, optional
        Starting point (e.g. the solution at a neighbouring instant).
    tol : float
        Required max |residual| relative to the reference load.

    Raises
    ------
    IntegrationDiverged
        If no equilibrium is found (e.g. a rig that cannot carry the load).
    """
    q_scale, f_scale, f_ref = _scales(model)
    x0 = (_linear_guess(model, f_ref) if q_guess is None else np.asarray(q_guess)) / q_scale

    def fun(x):
        return model.static_residual(t, x * q_scale) / f_scale

    best = None
    for method in ("hybr", "lm"):
        sol = root(fun, x0, method=method, tol=1e-12)
        err = float(np.max(np.abs(fun(sol.x))))
        if best is None or err < best[1]:
            best = (sol.x, err)
        if err < tol:
            break
        x0 = sol.x
    if best[1] > 1e3 * tol:
        raise IntegrationDiverged(
            f"no quasi-static equilibrium at t = {t:g} s (max relative residual {best[1]:.2e}); "
            "check torque_nm, radial_load_n and clearance_m")
    return best[0] * q_scale


def quasi_static_orbit(model, times_s):
    """Quasi-static states at several instants (continuation), shape (len(times_s), n)."""
    out = np.empty((len(times_s), model.n_dof))
    q = None
    for i, t in enumerate(times_s):
        q = quasi_static_state(model, t, q_guess=q)
        out[i] = q
    return out
