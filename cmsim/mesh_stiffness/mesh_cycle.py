"""Quasi-static loaded mesh analysis with the hybrid contact model, and hybrid stiffness tables.

For a driving torque T on gear 1, gear-centre offsets and a driving-gear angle θ1, the
driven gear's angle θ2 is found such that the contact forces of the hybrid model
(:class:`~cmsim.mesh_stiffness.hybrid.HybridMeshModel`, paper 001 eq. 2) balance the torque,

    Σ_i F_i · [(p_i − C1) × n_i] = T,

with p_i, n_i the contact point and normal of pair i and C1 the centre of gear 1. The
interferences come from the exact rigid-body geometry of
:mod:`cmsim.mesh_stiffness._kernels` (involute contact and rounded-tip corner contact outside
the involute path). The loaded transmission error is reported along the line of action,
LTE = r_b1 θ1 − r_b2 θ2 (m; positive: gear 2 lags), and each loaded pair's stiffness is the
secant k_i = F_i / δ_i, which is what the dynamics needs to reproduce the forces through
F = k (δ − e) (models B and C of paper 001 §6.1).

:func:`mesh_cycle` sweeps one mesh cycle and builds a
:class:`~cmsim.mesh_stiffness.table.MeshStiffnessTable` (``method="hybrid"``) on a uniform
grid of positions s over the potential-contact zone
(:func:`~cmsim.mesh_stiffness.contact.table_range_m`). Where a pair carries no load at this
torque (early approach and late recess corners), the table holds the stiffness of the nearest
loaded position (constant extrapolation), the same convention as the potential-energy table;
the dynamics then only uses it if the dynamic interference becomes positive there. The
abscissa is the pair's position s (``position_m``), also for corner contacts, whose secant
stiffness is about half the involute one; the dynamics reads the table at s too (not at the
contact's s_eq, which for a corner contact lies inside the involute path).

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016 (paper 001), §3 and §6.1, Fig. 4.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from cmsim.errors import ParameterError, check_range, check_type
from cmsim.mesh_stiffness._hybrid_kernels import hybrid_forces_jit
from cmsim.mesh_stiffness.contact import pair_contacts, potential_slots, table_range_m
from cmsim.mesh_stiffness.hybrid import HybridMeshModel, work_size
from cmsim.mesh_stiffness.table import MeshStiffnessTable

__all__ = ["QuasiStaticMesh", "MeshCycle", "quasi_static_mesh", "mesh_cycle",
           "hybrid_mesh_table", "slot_contacts", "MAX_CENTRE_OFFSET_M"]

#: A pair counts as loaded above this fraction of the total normal force.
LOADED_FRACTION = 1e-9

_HYBRID_TABLES = {}


def slot_contacts(pair, theta1_rad, theta2_rad, centre1_m=(0.0, 0.0), centre2_m=(0.0, 0.0),
                  n_slots=None, slot_start_m=None):
    """Rigid contact geometry of the potential pairs, with the curvature radii.

    :func:`cmsim.mesh_stiffness.contact.pair_contacts`, whose output includes the radii of
    curvature χ1, χ2 and the instantaneous line-of-action length that the hybrid solve needs.

    Parameters
    ----------
    pair : GearPair
    theta1_rad, theta2_rad : float
        Rotations of gear 1 (counter-clockwise) and gear 2 (clockwise) from the reference
        position, rad.
    centre1_m, centre2_m : tuple of float
        Gear-centre offsets from nominal, m.
    n_slots : int, optional
        Default :func:`~cmsim.mesh_stiffness.contact.potential_slots`.
    slot_start_m : float, optional
        Default: start of :func:`~cmsim.mesh_stiffness.contact.table_range_m`.

    Returns
    -------
    dict
        ``position_m``, ``delta_m``, ``s_eq_m``, ``chi1_m``, ``chi2_m`` (n_slots,),
        ``normal``, ``point_m`` (n_slots, 2), ``length_m`` (float, T1T2).
    """
    return pair_contacts(pair, theta1_rad, theta2_rad, centre1_m, centre2_m, n_slots,
                         slot_start_m)


@dataclass(frozen=True)
class QuasiStaticMesh:
    """Loaded equilibrium of the pair at one driving-gear angle.

    Attributes
    ----------
    torque_nm : float
        Driving torque on gear 1, N·m.
    theta1_rad, theta2_rad : float
        Gear angles (gear 2 in its own, clockwise, sense), rad.
    lte_m : float
        Loaded transmission error r_b1 θ1 − r_b2 θ2 along the line of action, m.
    position_m, delta_m, force_n, arm_m : ndarray, shape (n_slots,)
        Per potential pair: position s on the line of action, rigid interference (m),
        normal force (N) and its moment arm about gear 1's centre (m).
    roll1_m, roll2_m : ndarray, shape (n_slots,)
        Roll lengths of the contact points on both gears (table abscissae), m.
    stiffness_n_per_m : ndarray, shape (n_slots,)
        Secant stiffness F/δ of the loaded pairs, N/m (NaN where unloaded).
    loaded : ndarray of bool, shape (n_slots,)
    """

    torque_nm: float
    theta1_rad: float
    theta2_rad: float
    lte_m: float
    position_m: np.ndarray = field(repr=False)
    delta_m: np.ndarray = field(repr=False)
    force_n: np.ndarray = field(repr=False)
    arm_m: np.ndarray = field(repr=False)
    roll1_m: np.ndarray = field(repr=False)
    roll2_m: np.ndarray = field(repr=False)
    stiffness_n_per_m: np.ndarray = field(repr=False)
    loaded: np.ndarray = field(repr=False)

    @property
    def n_loaded(self):
        """Number of loaded pairs."""
        return int(np.count_nonzero(self.loaded))

    @property
    def mesh_stiffness_n_per_m(self):
        """Sum of the loaded pairs' stiffnesses, N/m."""
        return float(np.sum(self.stiffness_n_per_m[self.loaded]))


class _Evaluator:
    """Forces at (θ1, θ2) for fixed torque, offsets and model (internal)."""

    def __init__(self, model, centre1_m, centre2_m):
        self.model = model
        self.pair = model.pair
        self.c1, self.c2 = centre1_m, centre2_m
        self.args = model.kernel_args()
        self.n = potential_slots(self.pair)
        self.work = np.empty(work_size(self.n))

    def __call__(self, theta1, theta2):
        c = slot_contacts(self.pair, theta1, theta2, self.c1, self.c2, n_slots=self.n)
        rho1 = c["s_eq_m"]
        rho2 = c["length_m"] - rho1
        force = np.empty(self.n)
        it = hybrid_forces_jit(np.ascontiguousarray(c["delta_m"]), rho1, rho2,
                               np.maximum(c["chi1_m"], 1e-9), np.maximum(c["chi2_m"], 1e-9),
                               *self.args, np.zeros(self.n), self.work, force)
        if it < 0:
            raise RuntimeError("hybrid contact solve did not converge")
        cx, cy = c["centre1_m"]
        arm = ((c["point_m"][:, 0] - cx) * c["normal"][:, 1]
               - (c["point_m"][:, 1] - cy) * c["normal"][:, 0])
        return c, rho1, rho2, force, arm


#: Largest offset of a gear centre from its nominal position the contact geometry takes, m.
MAX_CENTRE_OFFSET_M = 1e-3


def _check_offset(name, value):
    v = np.asarray(value, dtype=float).reshape(-1)
    if v.size != 2 or not np.all(np.isfinite(v)) or np.max(np.abs(v)) > MAX_CENTRE_OFFSET_M:
        raise ParameterError(f"{name} must be two finite offsets within "
                             f"±{MAX_CENTRE_OFFSET_M * 1e3:g} mm, got {value!r}", param=name)
    return (float(v[0]), float(v[1]))


def quasi_static_mesh(model, torque_nm, theta1_rad=0.0, centre1_m=(0.0, 0.0),
                      centre2_m=(0.0, 0.0), _evaluator=None):
    """Loaded equilibrium of the gear pair at one driving-gear angle.

    Parameters
    ----------
    model : HybridMeshModel
    torque_nm : float
        Driving torque on gear 1, N·m (> 0).
    theta1_rad : float
        Driving-gear angle from the reference position (pair 0 at the pitch point), rad.
    centre1_m, centre2_m : tuple of float
        Offsets (x, y) of the gear centres from nominal, m (y: along the line of centres
        from gear 1 to gear 2; moving gear 2 by +y separates the gears).

    Returns
    -------
    QuasiStaticMesh
    """
    check_type("model", model, HybridMeshModel)
    torque = check_range("torque_nm", torque_nm, 0.0, 1e6, lo_open=True, unit="N m")
    theta1 = check_range("theta1_rad", theta1_rad, -1e3, 1e3, unit="rad")
    c1, c2 = _check_offset("centre1_m", centre1_m), _check_offset("centre2_m", centre2_m)
    ev = _evaluator if _evaluator is not None else _Evaluator(model, c1, c2)
    pair = model.pair
    rb1, rb2 = pair.driving.base_radius_m, pair.driven.base_radius_m

    def moment(theta2):
        _, _, _, force, arm = ev(theta1, theta2)
        return float(np.sum(force * arm)) - torque

    # bracket: no contact at hi (gear 2 ahead), enough overlap at lo
    theta2_kin = theta1 * pair.driving.n_teeth / pair.driven.n_teeth
    slack = 2.0 * (abs(c1[0]) + abs(c1[1]) + abs(c2[0]) + abs(c2[1])) + 1e-6
    hi = theta2_kin + slack / rb2
    for _ in range(60):
        if moment(hi) <= 0.0:
            break
        hi += 10.0 * slack / rb2
    guess = torque / (rb1 * 5e7)
    lo = hi - (slack + guess) / rb2
    for _ in range(60):
        if moment(lo) >= 0.0:
            break
        lo -= 2.0 * (hi - lo)
    else:
        raise RuntimeError(f"no equilibrium found for torque_nm = {torque:g}")
    theta2 = brentq(moment, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
    c, rho1, rho2, force, arm = ev(theta1, theta2)
    total = float(np.sum(force))
    loaded = force > LOADED_FRACTION * total
    k = np.full(force.shape, np.nan)
    k[loaded] = force[loaded] / c["delta_m"][loaded]
    return QuasiStaticMesh(torque_nm=torque, theta1_rad=theta1, theta2_rad=float(theta2),
                           lte_m=rb1 * theta1 - rb2 * float(theta2),
                           position_m=c["position_m"], delta_m=c["delta_m"], force_n=force,
                           arm_m=arm, roll1_m=rho1, roll2_m=rho2, stiffness_n_per_m=k,
                           loaded=loaded)


@dataclass(frozen=True)
class MeshCycle:
    """Quasi-static sweep of one mesh cycle.

    Attributes
    ----------
    torque_nm : float
    states : tuple of QuasiStaticMesh
        One per driving-gear angle (uniform over one angular pitch).
    table : MeshStiffnessTable
        Per-pair stiffness vs position (``method="hybrid"``).
    seconds : float
        Wall time of the sweep, s.
    """

    torque_nm: float
    states: tuple = field(repr=False)
    table: MeshStiffnessTable = field(repr=False)
    seconds: float

    @property
    def theta1_rad(self):
        """Driving-gear angles, rad, shape (n_steps,)."""
        return np.array([s.theta1_rad for s in self.states])

    @property
    def lte_m(self):
        """Loaded transmission error, m, shape (n_steps,)."""
        return np.array([s.lte_m for s in self.states])

    @property
    def n_loaded(self):
        """Loaded pairs at each angle, shape (n_steps,)."""
        return np.array([s.n_loaded for s in self.states])

    @property
    def loaded_contact_ratio(self):
        """Mean number of loaded pairs over the cycle (1 + fraction of double contact)."""
        return float(np.mean(self.n_loaded))

    @property
    def mesh_stiffness_n_per_m(self):
        """Sum of the loaded pairs' secant stiffnesses at each angle, N/m, shape (n_steps,)."""
        return np.array([s.mesh_stiffness_n_per_m for s in self.states])

    @property
    def mean_mesh_stiffness_n_per_m(self):
        """Mean of :attr:`mesh_stiffness_n_per_m`, N/m."""
        return float(np.mean(self.mesh_stiffness_n_per_m))


def mesh_cycle(model, torque_nm, centre1_m=(0.0, 0.0), centre2_m=(0.0, 0.0), n_steps=120,
               n_points=257):
    """Sweep one mesh cycle and build the hybrid per-pair stiffness table.

    Parameters
    ----------
    model : HybridMeshModel
    torque_nm : float
        Driving torque on gear 1, N·m.
    centre1_m, centre2_m : tuple of float
        Gear-centre offsets, m (e.g. the centroids of the bearing orbits, paper §6.1).
    n_steps : int
        Driving-gear angles over one angular pitch 2π/Z1 (>= 8).
    n_points : int
        Points of the table's uniform position grid over the potential-contact zone (>= 2).

    Returns
    -------
    MeshCycle
    """
    if isinstance(n_steps, bool) or not isinstance(n_steps, (int, np.integer)) or n_steps < 8:
        raise ParameterError(f"n_steps must be an integer >= 8, got {n_steps!r}")
    if isinstance(n_points, bool) or not isinstance(n_points, (int, np.integer)) \
            or n_points < 2:
        raise ParameterError(f"n_points must be an integer >= 2, got {n_points!r}")
    check_type("model", model, HybridMeshModel)
    t0 = time.perf_counter()
    c1, c2 = _check_offset("centre1_m", centre1_m), _check_offset("centre2_m", centre2_m)
    pair = model.pair
    ev = _Evaluator(model, c1, c2)
    step = 2.0 * math.pi / pair.driving.n_teeth / n_steps
    states = tuple(quasi_static_mesh(model, torque_nm, k * step, c1, c2, _evaluator=ev)
                   for k in range(n_steps))
    pos = np.concatenate([s.position_m[s.loaded] for s in states])
    stiff = np.concatenate([s.stiffness_n_per_m[s.loaded] for s in states])
    order = np.argsort(pos)
    lo, hi = table_range_m(pair)
    grid = np.linspace(lo, hi, n_points)
    k_grid = np.interp(grid, pos[order], stiff[order])
    cyc_n = np.array([s.n_loaded for s in states])
    meta = {"source": "hybrid FE influence coefficients + Weber-Banaschek (paper 001 eq. 2)",
            "centre1_m": list(c1), "centre2_m": list(c2), "n_steps": int(n_steps),
            "loaded_contact_ratio": float(np.mean(cyc_n)),
            "loaded_range_m": [float(pos.min()), float(pos.max())],
            "influence_key_driving": model.driving.meta.get("key"),
            "influence_key_driven": model.driven.meta.get("key"),
            "depth_m": float(model.params[8]),
            "unloaded_positions": "stiffness of the nearest loaded position"}
    table = MeshStiffnessTable(grid, k_grid, np.zeros(n_points), pair.driving.base_radius_m,
                               "hybrid", torque_nm=float(torque_nm), meta=meta)
    return MeshCycle(torque_nm=float(torque_nm), states=states, table=table,
                     seconds=time.perf_counter() - t0)


def hybrid_mesh_table(model, output_torque_nm):
    """Hybrid table of one mesh cycle at the driving torque that ``output_torque_nm`` needs.

    The on-line contact (paper 001 model A) uses it for the mesh damping coefficient (from
    its mean stiffness) and the quasi-static start guess. Memoised per (model, torque).

    Parameters
    ----------
    model : HybridMeshModel
        Influence tables of the gear pair.
    output_torque_nm : float
        Output torque, N·m (below 1e-3 N·m the table at 1e-3 N·m).

    Returns
    -------
    MeshStiffnessTable
        :func:`mesh_cycle` table with 24 steps at the driving torque T_out·Z1/Z2.
    """
    pair = model.pair
    drive = max(output_torque_nm, 1e-3) * pair.driving.n_teeth / pair.driven.n_teeth
    key = (id(model), drive)
    if key not in _HYBRID_TABLES:
        # the model is kept with its table, so its id is not reused while the entry lives
        _HYBRID_TABLES[key] = (model, mesh_cycle(model, drive, n_steps=24).table)
    return _HYBRID_TABLES[key][1]
