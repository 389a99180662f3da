"""The parts of eq. 1 that depend on the rig alone (paper 001, eq. 1 and Annex A).

:func:`rig_model` turns a rig into a :class:`RigModel` — masses, the linear springs and
dampers of the shafts, couplings and bearings, the bearings' geometry and Hertz constants and
the gears' tooth geometry, in the layout of the kernels — once per rig (memoised: rigs are
frozen values). :func:`cmsim.dynamics.model.build_model` adds the operating point and the run.

The DOFs are ordered as in eq. 1: ``x, y, θ`` of each node (``1b1, 1G1, 1b2, 2b1, 2G1, 2b2``)
then ``θ_2J2``.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, eqs. 1, 5-10 and Annex A.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from cmsim.bearings.forces import ball_offsets
from cmsim.bearings.hertz import bearing_contact_stiffness
from cmsim.bearings.kinematics import cage_ratios
from cmsim.dynamics._bearing_kernels import (BI_DEF0, BI_SIZE, BP_C, BP_CAGE, BP_DAMP, BP_K, BP_P,
                                             BP_SENSE, BP_SIZE, BP_SPIN)
from cmsim.mesh_stiffness.contact import (contact_geometry, corner_zone_m, potential_slots,
                                          reference_phases, table_range_m)

__all__ = ["RigModel", "rig_model"]


@dataclass(frozen=True)
class RigModel:
    """The parts of eq. 1 that depend on the rig alone (built once per rig).

    Attributes
    ----------
    rig : Rig
    dof_names : tuple of str
        ``x_1b1, y_1b1, theta_1b1, ...``.
    mass : ndarray, shape (n,)
        Diagonal of M (kg or kg·m²).
    stiffness, damping : ndarray, shape (n, n)
        Linear K and C of the shafts, couplings and bearing dampers.
    springs : ndarray, shape (e, 2)
        Spring-damper (k, c) of each element in kernel order.
    spring_ends : ndarray of int64, shape (e, 3)
        DOF indices of each element (:func:`cmsim.dynamics._rhs_kernels.linear_accel_jit`).
    bearing_index : ndarray of int64, shape (nb, BI_SIZE)
        Per bearing: its node's DOF indices and its number of balls (columns ``BI_*`` of
        :mod:`cmsim.dynamics._bearing_kernels`; the defect columns are filled per model).
    bearing_params : ndarray, shape (nb, BP_SIZE)
        Per bearing: Hertz constant, exponent, clearance, cage rate, sense, damping, spin
        ratio (columns ``BP_*``); the cage phase column is set per run.
    ball_cos, ball_sin : ndarray, shape (nb, max_balls)
        cos and sin of each ball's nominal angle in its cage.
    ball_angles_rad : ndarray, shape (nb, max_balls)
        Each ball's nominal angle in its cage, rad.
    mesh : dict
        Tooth geometry of the kernels (``geo``, ``teeth1``, ``teeth2``, slots, phases, zone
        limits); empty without gears.
    """

    rig: object
    dof_names: tuple
    mass: np.ndarray = field(repr=False)
    stiffness: np.ndarray = field(repr=False)
    damping: np.ndarray = field(repr=False)
    springs: np.ndarray = field(repr=False)
    spring_ends: np.ndarray = field(repr=False)
    bearing_index: np.ndarray = field(repr=False)
    bearing_params: np.ndarray = field(repr=False)
    ball_cos: np.ndarray = field(repr=False)
    ball_sin: np.ndarray = field(repr=False)
    ball_angles_rad: np.ndarray = field(repr=False, default=None)
    mesh: dict = field(repr=False, default_factory=dict)

    @property
    def n_dof(self):
        """Number of DOFs."""
        return self.mass.size

    def index(self, name):
        """Position of DOF ``name`` (e.g. ``"theta_1G1"``)."""
        try:
            return self.dof_names.index(name)
        except ValueError:
            raise KeyError(f"no DOF {name!r}; DOFs are {self.dof_names}") from None


@lru_cache(maxsize=16)
def rig_model(rig):
    """The :class:`RigModel` of ``rig`` (memoised: rigs are frozen values)."""
    n = rig.n_dof
    mass = rig.dof_masses
    elements = rig.spring_elements()
    kmat, cmat = _linear_matrices(elements, n)
    names = _dof_names(rig)
    # kernel layout: two-node springs first, then ground springs (b = a), count in [0, 2]
    ordered = sorted(elements, key=lambda e: e[1] < 0)
    springs = np.array([(k, c) for _, _, k, c in ordered])
    spring_ends = np.array([(a, a if b < 0 else b, 0) for a, b, _, _ in ordered], dtype=np.int64)
    spring_ends[0, 2] = sum(1 for e in ordered if e[1] < 0)
    bearings = rig.bearings
    nb = len(bearings)
    max_balls = max(b.n_balls for b in bearings)
    b_int = np.zeros((nb, BI_SIZE), dtype=np.int64)
    b_par = np.zeros((nb, BP_SIZE))
    b_cos = np.zeros((nb, max_balls))
    b_sin = np.zeros((nb, max_balls))
    b_ang = np.zeros((nb, max_balls))
    node_of = {name: k for k, name in enumerate(rig.node_names)}
    for ib, (bname, brg) in enumerate(zip(rig.bearing_names, bearings)):
        node = node_of[bname]
        k_in, k_out = cage_ratios(brg)
        b_int[ib, :BI_DEF0] = (3 * node, 3 * node + 1, 3 * node + 2, brg.n_balls)
        b_par[ib, BP_K] = bearing_contact_stiffness(brg)
        b_par[ib, BP_P] = brg.load_exponent
        b_par[ib, BP_C] = brg.clearance_m
        b_par[ib, BP_CAGE] = k_in + k_out * brg.outer_ring_speed_ratio
        b_par[ib, BP_SENSE] = 1.0 if bname.startswith("1") else -1.0
        b_par[ib, BP_DAMP] = brg.damping_n_s_per_m
        b_par[ib, BP_SPIN] = (brg.pitch_diameter_m - brg.ball_diameter_m
                              * math.cos(brg.effective_contact_angle_rad)) / brg.ball_diameter_m
        co, so = ball_offsets(brg)
        b_cos[ib, :brg.n_balls] = co
        b_sin[ib, :brg.n_balls] = so
        b_ang[ib, :brg.n_balls] = np.arctan2(so, co)
    mesh = {}
    if rig.gears is not None:
        pair = rig.gears
        lo, _ = table_range_m(pair)
        before, after = corner_zone_m(pair)
        psi10, psi20 = reference_phases(pair)
        alpha = pair.working_pressure_angle_rad
        lub = rig.lubricant
        mesh = {"geo": contact_geometry(pair), "n_slots": potential_slots(pair),
                "psi10": psi10, "psi20": psi20, "slo": lo, "before": before, "after": after,
                "teeth1": _pitch_multiples(pair.driving.n_teeth),
                "teeth2": _pitch_multiples(pair.driven.n_teeth),
                "g1": 3 * node_of["1G1"], "g2": 3 * node_of["2G1"],
                # nominal line of action: tangent point T1 at polar angle π/2 − α_w
                "phi_t0": 0.5 * math.pi - alpha,
                "koster": 12 * math.pi * lub.dynamic_viscosity_pa_s * min(
                    pair.driving.face_width_m, pair.driven.face_width_m)}
    for arr in (mass, kmat, cmat, springs, spring_ends, b_int, b_par, b_cos, b_sin, b_ang):
        arr.setflags(write=False)
    return RigModel(rig, names, mass, kmat, cmat, springs, spring_ends, b_int, b_par, b_cos,
                    b_sin, b_ang, mesh)


def _linear_matrices(elements, n):
    """Assemble K and C (n, n) from spring elements."""
    kmat = np.zeros((n, n))
    cmat = np.zeros((n, n))
    for a, b, k, c in elements:
        for mat, value in ((kmat, k), (cmat, c)):
            mat[a, a] += value
            if b >= 0:
                mat[b, b] += value
                mat[a, b] -= value
                mat[b, a] -= value
    return kmat, cmat


def _dof_names(rig):
    names = [f"{d}_{node}" for node in rig.node_names for d in ("x", "y", "theta")]
    if rig.gears is not None:
        names.append("theta_2J2")
    return tuple(names)


def _pitch_multiples(n_teeth):
    """cos and sin of k·2π/Z for k = 0..Z−1, shape (Z, 2)."""
    a = 2.0 * math.pi * np.arange(n_teeth) / n_teeth
    return np.ascontiguousarray(np.column_stack([np.cos(a), np.sin(a)]))
