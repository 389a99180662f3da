"""Quasi-static equilibrium (paper 001 eq. 1 with velocity and acceleration terms dropped).

Solved relative to the nominal rigid rotation at a given instant, so the cage and mesh
positions follow from the time; friction acts with the nominal sliding velocities. Used as the
initial state of the dynamics, for the bearing-cycle orbits of paper Fig. 3 and as the
linearisation point of the modal analysis.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.optimize import root

from cmsim.bearings.hertz import bearing_contact_stiffness
from cmsim.errors import IntegrationDiverged

__all__ = ["quasi_static_state", "quasi_static_orbit", "continued_state", "initial_state"]

#: Relative loads of the continuation that reaches a light load from a firmly loaded state.
CONTINUATION_FACTORS = (64.0, 16.0, 4.0, 2.0, 1.0)


def _scales(model, load_factor=1.0):
    """Scales of the unknowns and residuals, and the reference load f_ref (N), of ``model``
    with its loads multiplied by ``load_factor`` (:func:`_with_load_scaled`)."""
    rig, op = model.rig, model.op
    torque_nm, radial_load_n = op.torque_nm * load_factor, op.radial_load_n * load_factor
    if rig.gears is not None:
        rb = rig.gears.driving.base_radius_m
        f_ref = max(torque_nm / rb, radial_load_n, 1.0)
        length = rb
    else:
        f_ref = max(radial_load_n, 1.0)
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
        ix = int(model.kernel_params.b_int[ib, 0])
        kmat[ix, ix] += k_lin
        kmat[ix + 1, ix + 1] += k_lin
        offsets[ix:ix + 2] = max(brg.clearance_m, 0.0)
    rhs = model.force.copy()
    if model.rig.gears is not None:
        g = model.mesh_jacobian()
        k_mesh = model.mesh_table.mean_mesh_stiffness(model.rig.gears)
        kmat += k_mesh * np.outer(g, g)
        # the mesh force is k̄·(g·q − e) with e the smallest unloaded separation (backlash)
        gap = max(0.0, float(np.min(model.mesh_table.separation_m)))
        rhs += k_mesh * gap * g
    q = np.linalg.solve(kmat, rhs)
    # push each bearing across its clearance in the direction it moves
    for ib in range(nb):
        ix = int(model.kernel_params.b_int[ib, 0])
        r = math.hypot(q[ix], q[ix + 1])
        if r > 0:
            q[ix:ix + 2] += offsets[ix:ix + 2] * q[ix:ix + 2] / r
    return q


def quasi_static_state(model, t=0.0, q_guess=None, tol=1e-9, *, load_factor=1.0):
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
    load_factor : float
        The factor by which ``model``'s loads were multiplied (:func:`_with_load_scaled`):
        sets the reference load; the operating point keeps the user's values.

    Raises
    ------
    IntegrationDiverged
        If no equilibrium is found (e.g. a rig that cannot carry the load).
    """
    q_scale, f_scale, f_ref = _scales(model, load_factor)
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
        loads = (["torque_nm"] if model.rig.gears is not None else []) + (
            ["radial_load_n"] if model.rig.gears is None or model.op.radial_load_n > 0 else [])
        raise IntegrationDiverged(
            f"no quasi-static equilibrium at t = {t:g} s (max relative residual {best[1]:.2e}); "
            f"check {', '.join(loads)} and clearance_m")
    return best[0] * q_scale


def quasi_static_orbit(model, times_s, *, light_load=False):
    """Quasi-static states at several instants (continuation), shape (len(times_s), n).

    With ``light_load`` an instant whose equilibrium the direct solve misses is followed
    down from a firmly loaded state (:func:`continued_state`), as the start of a run is.
    """
    out = np.empty((len(times_s), model.n_dof))
    q = None
    for i, t in enumerate(times_s):
        try:
            q = quasi_static_state(model, t, q_guess=q)
        except IntegrationDiverged:
            if not light_load:
                raise
            q = continued_state(model, t, q_guess=q)
        out[i] = q
    return out


def continued_state(model, t=0.0, q_guess=None):
    """Equilibrium at a light load, followed down from :data:`CONTINUATION_FACTORS` times it.

    At light loads the Hertzian contacts barely close (their stiffness vanishes at first
    touch, so Newton's method may stall); each step is accepted within a force residual of
    1e-5 of the reference load.

    Parameters
    ----------
    model : DynamicModel
    t : float
        Instant (sets the cage and mesh positions), s.
    q_guess : ndarray, optional
        Starting point of the first (most loaded) step.

    Returns
    -------
    ndarray, shape (n,)
        DOF deviations in equilibrium at the model's load.

    Raises
    ------
    IntegrationDiverged
        If a step finds no equilibrium.
    """
    q = q_guess
    for factor in CONTINUATION_FACTORS:
        q = quasi_static_state(_with_load_scaled(model, factor), t, q_guess=q, tol=1e-5,
                               load_factor=factor)
    return q


def _with_load_scaled(model, factor):
    """The same model with its external loads multiplied by ``factor`` (a step of the
    continuation: its operating point stays the user's, which may already be at the top of
    its range; :func:`quasi_static_state` takes the factor as ``load_factor``)."""
    force = model.force * factor
    return replace(model, force=force, kernel_params=model.kernel_params._replace(fext=force))


def initial_state(model, t=0.0):
    """Start of a dynamic run: ``(q, method)`` with ``method`` saying how ``q`` was found.

    * ``"nominal geometry"`` — the rig carries no load (no torque, no radial load): the
      nominal geometry is an equilibrium (every contact just touching or open), and the
      unloaded gears have no unique one (gear 2 may turn freely within the backlash), so the
      dynamics starts there and the contact model handles separation;
    * ``"quasi-static"`` — :func:`quasi_static_state` from the linear guess;
    * ``"continuation"`` — at light loads the Hertzian contacts barely close (their
      stiffness vanishes at first touch, so Newton's method may stall): the equilibrium is
      followed down from :data:`CONTINUATION_FACTORS` times the load, each step accepted
      within a force residual of 1 % of the reference load (the warm-up of a dynamic run
      absorbs far larger start errors);
    * ``"nominal geometry (no equilibrium found)"`` — the last resort; the warm-up then
      carries the start transient.
    """
    op = model.op
    if op.torque_nm == 0.0 and op.radial_load_n == 0.0:
        return np.zeros(model.n_dof), "nominal geometry"
    try:
        return quasi_static_state(model, t), "quasi-static"
    except IntegrationDiverged:
        pass
    try:
        return continued_state(model, t), "continuation"
    except IntegrationDiverged:
        return np.zeros(model.n_dof), "nominal geometry (no equilibrium found)"
