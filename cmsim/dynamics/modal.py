"""Linearised modal analysis about the quasi-static state (paper 001 Tables 5/6, ref. [34]).

Each bearing is linearised at its quasi-static displacement and its tangent stiffness is
averaged over one ball-pass (bearing) cycle; the mesh enters as k̄·g·gᵀ with k̄ the mean mesh
stiffness over a mesh cycle and g = ∂δ/∂q the line-of-action coupling vector. Friction and the
centre-distance dependence of the mesh geometry are left out of the linear model (as in the
paper's linearised model). See papers/NOTES.md for the mixed-mode orientation issue.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, Tables 5-6.
.. [2] A. Fernandez-del-Rincon et al., "Load effects on the dynamics of spur gear
   transmissions", ASME IDETC 2010, 369-378.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from cmsim.bearings._kernels import ball_tangent_stiffness_jit
from cmsim.bearings.kinematics import ball_pass_cycles_per_rev
from cmsim.dynamics._bearing_kernels import BI_X, BP_C, BP_CAGE, BP_K, BP_P, BP_PHASE, BP_SENSE
from cmsim.dynamics.model import build_model
from cmsim.dynamics.quasistatic import quasi_static_orbit
from cmsim.dynamics.tooth_contact import resolve_mesh
from cmsim.errors import ParameterError

__all__ = ["ModalResult", "modal_analysis", "check_loaded", "MODE_TYPES"]

#: Mode types of the paper: rotational, translational, mixed.
MODE_TYPES = ("R", "T", "R-T")

#: Kinetic-energy share of the rotational DOFs above which a mode is "R" (and below
#: 1 − this, "T").
PURE_MODE_SHARE = 0.9


@dataclass(frozen=True)
class ModalResult:
    """Natural frequencies and mode shapes of the linearised model.

    Attributes
    ----------
    frequencies_hz : ndarray, shape (n,)
        Natural frequencies, ascending, Hz.
    shapes : ndarray, shape (n, n)
        Mass-normalised mode shapes, one per column.
    types : tuple of str
        ``"R"``, ``"T"`` or ``"R-T"`` per mode (see :data:`PURE_MODE_SHARE`).
    details : tuple of str
        ``"R"``, ``"Tn"`` (translation mostly along the line of action), ``"Tt"`` (mostly
        normal to it) or ``"R-T"``.
    rotational_share : ndarray, shape (n,)
        Kinetic-energy share of the rotational DOFs per mode.
    dof_names : tuple of str
    mean_mesh_stiffness_n_per_m : float
        k̄ used for the mesh (0 without gears).
    bearing_stiffness_n_per_m : ndarray, shape (n_bearings, 2, 2)
        Cycle-averaged tangent stiffness of each bearing, N/m.
    """

    frequencies_hz: np.ndarray
    shapes: np.ndarray
    types: tuple
    details: tuple
    rotational_share: np.ndarray
    dof_names: tuple
    mean_mesh_stiffness_n_per_m: float
    bearing_stiffness_n_per_m: np.ndarray

    def to_records(self):
        """One dict per mode (``mode``, ``frequency_hz``, ``type``, ``detail``)."""
        return [{"mode": i + 1, "frequency_hz": float(f), "type": t, "detail": d}
                for i, (f, t, d) in enumerate(zip(self.frequencies_hz, self.types, self.details))]


def _bearing_cycle_times(model, n_positions):
    """Instants spanning one ball-pass period of the first bearing, s."""
    brg = model.rig.bearings[0]
    cycles_per_rev = ball_pass_cycles_per_rev(brg)
    period = 2.0 * math.pi / (model.op.omega_rad_s * cycles_per_rev)
    return period * np.arange(n_positions) / n_positions


def _averaged_bearing_stiffness(model, states, times):
    """Tangent stiffness of each bearing averaged over the given states, (nb, 2, 2)."""
    P = model.kernel_params
    b_int, b_par, b_cos, b_sin = P.b_int, P.b_par, P.b_cos, P.b_sin
    nb = b_int.shape[0]
    out = np.zeros((nb, 2, 2))
    for q, t in zip(states, times):
        for ib in range(nb):
            ix, iy, it, n_balls = (int(v) for v in b_int[ib, :4])
            rate = b_par[ib, BP_CAGE] * b_par[ib, BP_SENSE]
            cage = rate * (model.omega[it] * t + q[it]) + b_par[ib, BP_PHASE]
            kxx, kxy, kyy = ball_tangent_stiffness_jit(
                q[ix], q[iy], math.cos(cage), math.sin(cage), b_cos[ib, :n_balls],
                b_sin[ib, :n_balls], b_par[ib, BP_K], b_par[ib, BP_P], b_par[ib, BP_C])
            out[ib] += np.array([[kxx, kxy], [kxy, kyy]])
    return out / len(states)


def _linearised_stiffness(model, k_brg, k_mesh, linear_stiffness=None):
    """Symmetric K of the linearised model: the linear part (``model.stiffness`` unless
    ``linear_stiffness`` is given), each bearing's tangent stiffness ``k_brg`` (nb, 2, 2) on its
    x, y DOFs and the mesh stiffness ``k_mesh`` (N/m) along the mesh Jacobian (a rig without
    gears has no mesh term)."""
    kmat = (model.stiffness if linear_stiffness is None else linear_stiffness).copy()
    for ib in range(k_brg.shape[0]):
        ix = int(model.kernel_params.b_int[ib, BI_X])
        kmat[ix:ix + 2, ix:ix + 2] += k_brg[ib]
    if model.rig.gears is not None:
        g = model.mesh_jacobian()
        kmat += k_mesh * np.outer(g, g)
    return 0.5 * (kmat + kmat.T)


def highest_frequency_hz(model, q, t=0.0, linear_stiffness=None):
    """Highest natural frequency of ``model`` linearised at state ``q`` (time ``t``), Hz.

    Bearings enter with their tangent stiffness at ``q`` and the mesh with the peak of its
    total stiffness over a mesh cycle (double contact), so the figure bounds the stiffest
    mode the integrator meets; it sets the automatic integration step of
    :func:`cmsim.dynamics.simulate`. One 19×19 eigenvalue problem: cheap.
    ``linear_stiffness`` replaces the linear springs' K (the part an exponential scheme
    leaves to the explicit stages).
    """
    k_brg = _averaged_bearing_stiffness(model, [np.asarray(q, float)], [t])
    gears = model.rig.gears
    k_peak = 0.0 if gears is None else float(np.max(model.mesh_table.mesh_stiffness(gears)[1]))
    eig = scipy.linalg.eigvalsh(_linearised_stiffness(model, k_brg, k_peak, linear_stiffness),
                                np.diag(model.mass))
    return float(math.sqrt(max(eig[-1], 0.0)) / (2.0 * math.pi))


def check_loaded(rig, op):
    """Refuse an unloaded operating point: it has no unique static state to linearise about
    (the gears turn freely within the backlash, bearings with clearance carry nothing).

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint

    Raises
    ------
    ParameterError
        No torque on a geared rig, or no radial load on a rig without gears.
    """
    why = ("an unloaded rig has no unique static state to linearise about (the gears turn "
           "freely within the backlash and the bearings carry nothing); a run (simulate) "
           "starts there from the nominal geometry")
    if rig.gears is not None and op.torque_nm <= 0.0 and op.radial_load_n <= 0.0:
        raise ParameterError(f"torque_nm must be > 0 N m for a modal analysis, got "
                             f"{op.torque_nm:g}: {why}", param="torque_nm", allowed="> 0 N m")
    if rig.gears is None and op.radial_load_n <= 0.0:
        raise ParameterError(f"radial_load_n must be > 0 N for a modal analysis of a rig "
                             f"without gears, got {op.radial_load_n:g}: {why}",
                             param="radial_load_n", allowed="> 0 N")


def modal_analysis(rig, op, mesh=None, *, n_positions=24):
    """Natural frequencies and mode types of ``rig`` at ``op``.

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
        Speed (sets the bearing-cycle instants) and torque (sets the linearisation point).
    mesh : None, str, MeshStiffnessTable, MeshTableSet or HybridMeshModel
        Tooth contact model, as in :func:`cmsim.dynamics.simulate` (default: the rig's
        hybrid tables at the torque); the mesh enters as its mean stiffness k̄ at the torque.
    n_positions : int
        Quasi-static solutions per bearing cycle used for the average (>= 4).

    Returns
    -------
    ModalResult

    Raises
    ------
    ParameterError
        An unloaded operating point (no torque on a gear rig, no radial load on a rig
        without gears): there is no unique static state to linearise about. Light loads
        are reached by continuation from a firmly loaded state.
    """
    if not isinstance(n_positions, (int, np.integer)) or n_positions < 4:
        raise ParameterError(f"n_positions must be an integer >= 4, got {n_positions!r}")
    check_loaded(rig, op)
    model = build_model(rig, op, resolve_mesh(rig, mesh, op.torque_nm))
    times = _bearing_cycle_times(model, n_positions)
    states = quasi_static_orbit(model, times, light_load=True)
    k_brg = _averaged_bearing_stiffness(model, states, times)
    k_mean = 0.0 if rig.gears is None else model.mesh_table.mean_mesh_stiffness(rig.gears)
    eigvals, shapes = scipy.linalg.eigh(_linearised_stiffness(model, k_brg, k_mean),
                                        np.diag(model.mass))
    freqs = np.sqrt(np.clip(eigvals, 0.0, None)) / (2.0 * math.pi)
    types, details, shares = _classify(model, shapes)
    return ModalResult(freqs, shapes, tuple(types), tuple(details), np.array(shares),
                       model.dof_names, k_mean, k_brg)


def _classify(model, shapes):
    rot = np.array([d.startswith("theta") for d in model.dof_names])
    energy = model.mass[:, None] * shapes ** 2
    total = energy.sum(axis=0)
    share_rot = energy[rot].sum(axis=0) / total
    # translational energy along / normal to each shaft's line of action
    loa, oloa = np.zeros(shapes.shape[1]), np.zeros(shapes.shape[1])
    for name in model.rig.node_names:
        e = model.loa_direction(0 if name.startswith("1") else 1)
        ix = model.index(f"x_{name}")
        m = model.mass[ix]
        along = e[0] * shapes[ix] + e[1] * shapes[ix + 1]
        normal = -e[1] * shapes[ix] + e[0] * shapes[ix + 1]
        loa += m * along ** 2
        oloa += m * normal ** 2
    types, details = [], []
    for j in range(shapes.shape[1]):
        if share_rot[j] >= PURE_MODE_SHARE:
            types.append("R")
            details.append("R")
        elif share_rot[j] <= 1.0 - PURE_MODE_SHARE:
            types.append("T")
            details.append("Tn" if loa[j] >= oloa[j] else "Tt")
        else:
            types.append("R-T")
            details.append("R-T")
    return types, details, share_rot
