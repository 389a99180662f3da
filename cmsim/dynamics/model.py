"""Equations of motion of a rig at an operating point (paper 001, eq. 1 and Annex A).

The model is built in three parts by lifetime, so that a dataset or a calibration that runs
one rig many times rebuilds only what changes:

* :class:`~cmsim.dynamics.rig_model.RigModel` — per rig: masses, shaft and coupling
  springs, bearing and tooth geometry (:func:`~cmsim.dynamics.rig_model.rig_model`,
  memoised per rig);
* :class:`DynamicModel` — per operating point: speeds, loads, the mesh stiffness at the
  torque (:func:`build_model`);
* per run: cage phases, slip and a ball defect's spin-axis walk, by
  :meth:`DynamicModel.for_run` (cheap).

The DOFs are ordered as in eq. 1: ``x, y, θ`` of each node (``1b1, 1G1, 1b2, 2b1, 2G1, 2b2``)
then ``θ_2J2``. Rotations are deviations from the nominal rigid rotation Ω·t (shaft 1 at the
imposed speed, shaft 2 at Ω·Z1/Z2, counted positive in its own sense of motion), so the input
coupling becomes a spring to ground and the DTE is ``θ_1G1 − (Z2/Z1)·θ_2G1`` exactly.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, eqs. 1, 5-10 and Annex A.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

import numpy as np

from cmsim.bearings.kinematics import slip_jitter
from cmsim.dynamics._bearing_kernels import (BI_DEF0, BI_FAULTY, BI_NDEF, BI_T, BP_CAGE, BP_PHASE,
                                             DEF_BALL, DF_AXIS, DF_BRG, DF_HALF, DF_KIND, DF_SIZE,
                                             DF_TRACK, DF_WANDER)
from cmsim.dynamics._mesh_kernels import (MI_BALL_SLIP, MI_CTAB, MI_ECC, MI_FAULTY_BALLS,
                                          MI_MUTAB, MI_PROFILE, MI_SIZE, MI_TDOF, MI_TEETH, MODE_HYBRID, MODE_TABLE,
                                          MP_A0, MP_BETA, MP_COST0, MP_DIAGB, MP_DTHR, MP_JDT,
                                          MP_KOSTER, MP_MU, MP_OM1, MP_OM2, MP_OMREF, MP_PB,
                                          MP_PDT, MP_PHIT0, MP_PSI10, MP_PSI20, MP_PT0, MP_SINT0,
                                          MP_SIZE, MP_SLO, MP_TAB0, MP_TABD, MP_TDT, MP_V0,
                                          MP_ZAFTER, MP_ZBEFORE, no_hybrid)
from cmsim.dynamics._rhs_kernels import (KernelParams, make_work, no_faults, no_profile, rhs_jit,
                                         static_residual_jit)
from cmsim.dynamics.rig_model import RigModel, rig_model
from cmsim.errors import ParameterError, check_range
from cmsim.faults import check_faults, compile_faults, rig_with_faults
from cmsim.faults.bearing import NO_SLIP, track_share, wandering_offset
from cmsim.mesh_stiffness._kernels import GEO_SIZE
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.mesh_stiffness.table import MeshStiffnessTable

__all__ = ["DynamicModel", "build_model", "teeth_with_own_tables"]


@dataclass(frozen=True)
class DynamicModel:
    """Arrays of eq. 1 for one rig, operating point and run, ready for the numba kernels.

    Attributes
    ----------
    rig_model : RigModel
        The per-rig part.
    op : OperatingPoint
    mesh_table : MeshStiffnessTable or None
        Pair stiffness table (gear rigs; with the on-line model it sets only the mean
        stiffness for the damping and the start guess).
    force : ndarray, shape (n,)
        Constant external load (output torque, radial load).
    omega : ndarray, shape (n,)
        Nominal rotation speed of each DOF, rad/s (0 for translations).
    kernel_params : KernelParams
        Named kernel arrays ``P`` (:class:`cmsim.dynamics._rhs_kernels.KernelParams`).
    output_force_names : tuple of str
        Names of the forces the kernel writes at each output instant, in its order:
        ``F_<bearing>_x``, ``F_<bearing>_y`` (housing forces), then ``Fmesh_<slot>``.
    slip : RollingSlip
        The run's rolling slip (:data:`cmsim.faults.NO_SLIP` without).
    mesh_model : HybridMeshModel or None
        On-line hybrid contact model (model A), or ``None`` for the table.
    cage_phases_rad : ndarray, shape (n_bearings,)
        Initial cage angle of each bearing, rad.
    faults : tuple of Fault
        The faults built into the model.
    """

    rig_model: RigModel
    op: object
    mesh_table: MeshStiffnessTable | None
    force: np.ndarray
    omega: np.ndarray
    kernel_params: KernelParams = field(repr=False)
    output_force_names: tuple = ()
    slip: object = NO_SLIP
    mesh_model: object = None
    cage_phases_rad: np.ndarray = field(default=None, repr=False)
    faults: tuple = ()

    def __post_init__(self):
        # one array-flag signature for the kernels, whatever built the model (numba
        # recompiles the integrator for each mix of read-only and writeable arrays)
        object.__setattr__(self, "kernel_params", self.kernel_params.frozen())

    @property
    def rig(self):
        """The rig."""
        return self.rig_model.rig

    @property
    def dof_names(self):
        """``x_1b1, y_1b1, theta_1b1, ...``."""
        return self.rig_model.dof_names

    @property
    def mass(self):
        """Diagonal of M, shape (n,)."""
        return self.rig_model.mass

    @property
    def stiffness(self):
        """Linear K, shape (n, n)."""
        return self.rig_model.stiffness

    @property
    def damping(self):
        """Linear C, shape (n, n)."""
        return self.rig_model.damping

    @property
    def n_dof(self):
        """Number of DOFs."""
        return self.mass.size

    def index(self, name):
        """Position of DOF ``name`` (e.g. ``"theta_1G1"``)."""
        return self.rig_model.index(name)

    @property
    def translational_mask(self):
        """Boolean mask of the x/y DOFs, shape (n,)."""
        return np.array([not d.startswith("theta") for d in self.dof_names])

    def for_run(self, *, cage_phases_rad=None, slip=None, duration_s=1.0, seed=None):
        """The same model with another run's cage phases, slip and spin-axis walk (nothing else
        rebuilt).

        Parameters
        ----------
        cage_phases_rad : sequence of float, optional
            Initial cage angle θ0 of each bearing (eq. 7), one per bearing in
            ``rig.bearing_names`` order; default all zero.
        slip : RollingSlip, optional
            Random rolling slip (:class:`cmsim.faults.RollingSlip`; default none).
        duration_s : float
            Span over which the slip and a wandering spin axis are generated, s.
        seed : int, optional
            Seed of the slip and spin-axis generators.
        """
        rig = self.rig
        nb = len(rig.bearings)
        slip = NO_SLIP if slip is None else slip
        phases = np.zeros(nb) if cage_phases_rad is None else np.asarray(cage_phases_rad, float)
        if phases.shape != (nb,) or not np.all(np.isfinite(phases)):
            raise ParameterError(f"cage_phases_rad needs {nb} finite values (one per bearing "
                                 f"{rig.bearing_names}), got {cage_phases_rad!r}")
        b_par = self.rig_model.bearing_params.copy()
        b_par[:, BP_PHASE] = phases
        shaft_dof = self.rig_model.bearing_index[:, BI_T]
        cage_rates = [abs(b_par[ib, BP_CAGE] * self.omega[shaft_dof[ib]]) for ib in range(nb)]
        jitter, jdt = _jitter(rig.bearings, self.rig_model.ball_cos.shape[1], cage_rates, slip,
                              duration_s, seed)
        track, tdt = _track(self.kernel_params.b_def, duration_s, seed)
        m_par = self.kernel_params.m_par.copy()
        m_par[MP_JDT] = jdt
        m_par[MP_TDT] = tdt
        m_int = self.kernel_params.m_int.copy()
        # a slip of the cages alone leaves the ball rows zero: the kernel then skips them
        m_int[MI_BALL_SLIP] = int(bool(np.any(jitter[:, :-1] != 0.0)))
        kernel_params = self.kernel_params._replace(b_par=b_par, jitter=jitter, m_par=m_par,
                                                    m_int=m_int, track=track)
        return replace(self, kernel_params=kernel_params, slip=slip, cage_phases_rad=phases)

    def rhs(self, t, y, want_diag=False):
        """Evaluate the kernel right-hand side; returns ``dydt`` (and ``diag``)."""
        dydt = np.empty((1, 2 * self.n_dof))
        diag = np.zeros(len(self.output_force_names))
        rhs_jit(float(t), np.ascontiguousarray(y, dtype=float), dydt, 0, self.kernel_params, diag,
                bool(want_diag), make_work(self.kernel_params))
        return (dydt[0], diag) if want_diag else dydt[0]

    def static_residual(self, t, q):
        """M·q̈ at rest relative to the nominal rotation (velocities zero), shape (n,): the
        kernel's right-hand side as :meth:`rhs` evaluates it, with fresh scratch each call,
        in one numba call on buffers the model keeps (a quasi-static start takes some 65)."""
        out = np.empty(self.n_dof)
        static_residual_jit(float(t), np.ascontiguousarray(q, dtype=float), self.mass,
                            self.kernel_params, *self._static_buffers, out)
        return out

    @functools.cached_property
    def _static_buffers(self):
        """Scratch, its fresh copy, state, slope and force buffers of :meth:`static_residual`
        (one model's solve at a time: not shared between threads)."""
        P, n = self.kernel_params, self.n_dof
        return (make_work(P), make_work(P), np.empty(2 * n), np.empty((1, 2 * n)),
                np.zeros(len(self.output_force_names)))

    def loa_direction(self, shaft_index):
        """Unit vector (x, y) of the line of action for shaft ``shaft_index`` (0 or 1).

        It is the direction of the nominal mesh force on that shaft's gear (so the mean
        bearing force on the housing along it is positive); for a rig without gears, the
        direction of the radial load.
        """
        if self.rig.gears is None:
            a = self.op.radial_load_angle_rad
            return np.array([math.cos(a), math.sin(a)])
        alpha = self.rig.gears.working_pressure_angle_rad
        e = np.array([math.cos(alpha), -math.sin(alpha)])
        return e if shaft_index == 0 else -e

    def mesh_jacobian(self):
        """∂δ/∂q of the involute interference at nominal geometry, shape (n,).

        δ ≈ r_b1·θ_1G1 − r_b2·θ_2G1 + n·(c_1G1 − c_2G1) with n the direction of the force of
        gear 1 on gear 2; zeros for a rig without gears.
        """
        g = np.zeros(self.n_dof)
        if self.rig.gears is None:
            return g
        n_dir = -self.loa_direction(0)
        i1, i2 = self.index("x_1G1"), self.index("x_2G1")
        g[i1:i1 + 2] = n_dir
        g[i2:i2 + 2] = -n_dir
        g[i1 + 2] = self.rig.gears.driving.base_radius_m
        g[i2 + 2] = -self.rig.gears.driven.base_radius_m
        return g


def build_model(rig, op, mesh=(None, None), *, slip=None, duration_s=1.0, seed=None,
                cage_phases_rad=None, faults=(), profile=None, loads=None, friction_table=None,
                damping_table=None):
    """Assemble the :class:`DynamicModel` of ``rig`` at ``op``.

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    mesh : tuple of (MeshStiffnessTable or None, HybridMeshModel or None)
        The tooth contact, already resolved at ``op.torque_nm`` for the rig with its faults'
        changes (:func:`cmsim.dynamics.tooth_contact.resolve_mesh`, which turns the user's
        ``mesh`` choice into this pair): the pair stiffness table and, for the on-line
        contact solve (paper 001 §6.1, model A), the hybrid model. ``(None, None)`` (the
        default) for a rig without gears.
    slip, duration_s, seed, cage_phases_rad
        Per-run values, as in :meth:`DynamicModel.for_run`.
    faults : sequence of Fault
        Catalogue entries (:mod:`cmsim.faults`) felt through the model: race and ball
        defects, off-size balls, per-tooth stiffness factors and separations, eccentric gears
        (compiled against the run's mesh table by :func:`cmsim.faults.compile_faults`);
        clearance growth (wear) changes the rig first. Slip and speed or torque modulations
        are per-run inputs of :func:`cmsim.dynamics.simulate`.
    profile : KernelProfile, optional
        Input speed and output torque against time (:mod:`cmsim.dynamics.profiles`);
        ``op`` then gives the reference (initial) speed.
    loads : dict, optional
        Extra constant generalised forces by DOF name, N or N·m (e.g. resisting torques of
        windage, oil pumping or bearing friction on ``theta_1G1``; a resisting torque is
        negative in the DOF's own sense of motion).
    friction_table : ndarray, shape (m,), optional
        Mesh friction coefficient against the pair's position on the run's mesh table grid
        (a mixed-lubrication model at the operating point), in place of the rig's constant.
    damping_table : ndarray, shape (m,), optional
        Viscous damping of a loaded pair against its position on the same grid, N·s/m (e.g.
        :func:`cmsim.losses.contact_mixed.mesh_mixed_stiffness_damping`), in place of the
        stiffness-proportional β·k.

    Returns
    -------
    DynamicModel

    Notes
    -----
    Mesh damping is stiffness-proportional per pair: a loaded pair of stiffness k_j (the
    table's, or the secant F/δ of the on-line solve) gets β·k_j with
    β = 2ξ√(M_eq/k̄), so the mesh has 2ξ√(k̄·M_eq) on average (k̄: mean mesh stiffness at the
    torque) and does not double in double contact.
    """
    faults = check_faults(rig, faults)
    given, rig = rig, rig_with_faults(rig, faults)
    rm = rig_model(rig)
    n = rm.n_dof
    mesh_table, mesh_model = _checked_mesh(rig, mesh)
    fault_arrays = compile_faults(given, faults, mesh_table, op=op) if faults else None
    omega = np.zeros(n)
    ratio = rig.gears.driving.n_teeth / rig.gears.driven.n_teeth if rig.gears else 0.0
    speeds = (op.omega_rad_s, op.omega_rad_s * ratio)
    for i, name in enumerate(rm.dof_names):
        if name.startswith("theta"):
            omega[i] = speeds[0] if name[-3] == "1" else speeds[1]
    force = np.zeros(n)
    if rig.gears is not None:
        force[n - 1] = -op.torque_nm
    if op.radial_load_n > 0:
        force[3] += op.radial_load_n * math.cos(op.radial_load_angle_rad)
        force[4] += op.radial_load_n * math.sin(op.radial_load_angle_rad)
    for name, value in (loads or {}).items():
        force[rm.index(name)] += check_range(f"loads[{name!r}]", value, unit="N or N m")

    nb = len(rig.bearings)
    m_int = np.zeros(MI_SIZE, dtype=np.int64)
    m_int[MI_TDOF] = -1
    m_par = np.zeros(MP_SIZE)
    m_par[MP_JDT] = 1.0
    m_par[MP_DIAGB] = 2 * nb
    output_force_names = [f"F_{b}_{d}" for b in rig.bearing_names for d in ("x", "y")]
    if rig.gears is not None:
        pair, geom = rig.gears, rm.mesh
        mode = MODE_TABLE if mesh_model is None else MODE_HYBRID
        m_int[:MI_TEETH] = (geom["g1"], geom["g2"], geom["n_slots"], 1, mode)
        mc = rig.mesh_contact
        k_mean = mesh_table.mean_mesh_stiffness(pair)
        m_par[MP_A0] = pair.working_centre_distance_m
        m_par[MP_PSI10] = geom["psi10"]
        m_par[MP_PSI20] = geom["psi20"]
        m_par[MP_PB] = pair.driving.base_pitch_m
        m_par[MP_SLO] = geom["slo"]
        m_par[MP_OM1] = speeds[0]
        m_par[MP_OM2] = speeds[1]
        m_par[MP_MU] = mc.friction_coefficient
        m_par[MP_V0] = mc.friction_smoothing_m_s
        m_par[MP_BETA] = 2 * mc.damping_ratio * math.sqrt(pair.mesh_stiffness_mass_kg / k_mean)
        m_par[MP_KOSTER] = geom["koster"]
        m_par[MP_DTHR] = mc.squeeze_gap_threshold_m
        m_par[MP_TAB0] = mesh_table.position_m[0]
        m_par[MP_TABD] = mesh_table.spacing_m
        m_par[MP_ZBEFORE] = geom["before"]
        m_par[MP_ZAFTER] = geom["after"]
        m_par[MP_PHIT0] = geom["phi_t0"]
        m_par[MP_COST0] = math.cos(geom["phi_t0"])
        m_par[MP_SINT0] = math.sin(geom["phi_t0"])
        tab_k = np.ascontiguousarray(mesh_table.stiffness_n_per_m)
        tab_e = np.ascontiguousarray(mesh_table.separation_m)
        output_force_names += [f"Fmesh_{j}" for j in range(geom["n_slots"])]
        geo, teeth1, teeth2 = geom["geo"], geom["teeth1"], geom["teeth2"]
    else:
        geo = np.zeros(GEO_SIZE)
        teeth1 = teeth2 = np.zeros((1, 2))
        m_par[MP_TABD] = 1.0
        tab_k = np.zeros(2)
        tab_e = np.zeros(2)
    if mesh_model is not None:
        hybrid = tuple(np.ascontiguousarray(a, dtype=float) for a in mesh_model.kernel_args())
    else:
        hybrid = no_hybrid()
    b_int, fields = _fault_fields(rm, m_int, fault_arrays,
                                  (m_par[MP_TAB0], m_par[MP_TABD]))
    prof = no_profile()
    if profile is not None:
        m_int[MI_PROFILE] = 1
        m_int[MI_TDOF] = n - 1 if rig.gears is not None else -1
        m_par[MP_PT0] = profile.t0_s
        m_par[MP_PDT] = profile.dt_s
        m_par[MP_OMREF] = op.omega_rad_s
        prof = np.ascontiguousarray(profile.table, dtype=float)
    mu_tab = np.zeros(1)
    if friction_table is not None:
        mu_tab = np.ascontiguousarray(friction_table, dtype=float)
        if rig.gears is None or mu_tab.shape != (len(tab_k),) or not np.all(np.isfinite(mu_tab)) \
                or np.any(mu_tab < 0) or np.any(mu_tab > 1):
            raise ParameterError(f"friction_table needs {len(tab_k)} values in [0, 1] (one "
                                 f"per point of the mesh table grid)")
        m_int[MI_MUTAB] = 1
    c_tab = np.zeros(1)
    if damping_table is not None:
        c_tab = np.ascontiguousarray(damping_table, dtype=float)
        if rig.gears is None or c_tab.shape != (len(tab_k),) or not np.all(np.isfinite(c_tab)) \
                or np.any(c_tab < 0):
            raise ParameterError(f"damping_table needs {len(tab_k)} finite values >= 0 N s/m "
                                 f"(one per point of the mesh table grid)")
        m_int[MI_CTAB] = 1
    kernel_params = KernelParams(
        1.0 / rm.mass, rm.springs, force, omega, b_int, rm.bearing_params, rm.ball_cos,
        rm.ball_sin, np.zeros((nb, rm.ball_cos.shape[1] + 1, 1)), m_int, m_par, geo, tab_k,
        tab_e, teeth1, teeth2, rm.spring_ends, *hybrid, fields[0], rm.ball_angles_rad,
        *fields[1:], prof, mu_tab, c_tab, np.ones((fields[0].shape[0], 1)))
    model = DynamicModel(rm, op, mesh_table, force, omega, kernel_params, tuple(output_force_names),
                         NO_SLIP, mesh_model, np.zeros(nb), faults)
    return model.for_run(cage_phases_rad=cage_phases_rad, slip=slip, duration_s=duration_s,
                         seed=seed)


def _checked_mesh(rig, mesh):
    """``(table, on-line model)`` of a resolved ``mesh`` (:func:`build_model`), checked
    against ``rig``."""
    if not (isinstance(mesh, tuple) and len(mesh) == 2):
        raise ParameterError(f"mesh must be the (table, on-line model) pair that "
                             f"cmsim.dynamics.tooth_contact.resolve_mesh returns, got "
                             f"{type(mesh).__name__}", param="mesh")
    table, online = mesh
    if rig.gears is None:
        if table is not None or online is not None:
            raise ParameterError("mesh given for a rig without gears (allowed: (None, None))",
                                 param="mesh")
        return None, None
    if not isinstance(table, MeshStiffnessTable):
        raise ParameterError(f"mesh: a rig with gears needs a MeshStiffnessTable first (from "
                             f"resolve_mesh), got {type(table).__name__}", param="mesh")
    if online is not None:
        if not isinstance(online, HybridMeshModel):
            raise ParameterError(f"mesh: the on-line model must be a HybridMeshModel or None, "
                                 f"got {type(online).__name__}", param="mesh")
        online.check_pair(rig.gears)
    return table, online


def teeth_with_own_tables(tk, te):
    """Which teeth have per-tooth tables of their own: a stiffness factor other than 1 or a
    separation other than 0 anywhere along the path (the last axis); the others are
    nominal, and their look-up returns 1 and 0 to the bit.

    Parameters
    ----------
    tk, te : numpy.ndarray, shape (..., Z, m)
        Per-tooth stiffness factors and separations (one run's, or several stacked).

    Returns
    -------
    numpy.ndarray of bool, shape (..., Z)
    """
    return np.any(tk != 1.0, axis=-1) | np.any(te != 0.0, axis=-1)


def _fault_fields(rm, m_int, fa, m_par_grid=(0.0, 1.0)):
    """``(b_int, (b_def, b_off, tk1, tk2, te1, te2, ecc))`` for the kernel from FaultArrays."""
    nb, max_balls = rm.ball_cos.shape
    if fa is None or not fa.active:
        return rm.bearing_index, no_faults(nb, max_balls)
    b_def = np.ascontiguousarray(fa.bearing_defects, dtype=float).reshape(-1, DF_SIZE)
    b_off = np.ascontiguousarray(fa.ball_offset_m, dtype=float)
    if b_off.shape != (nb, max_balls):
        raise ParameterError(f"ball_offset_m must have shape {(nb, max_balls)}, "
                             f"got {b_off.shape}")
    order = np.argsort(b_def[:, DF_BRG], kind="stable")
    b_def = np.ascontiguousarray(b_def[order])
    b_int = rm.bearing_index.copy()
    for ib in range(nb):
        rows = np.flatnonzero(b_def[:, DF_BRG] == ib)
        b_int[ib, BI_DEF0] = rows[0] if rows.size else 0
        b_int[ib, BI_NDEF] = rows.size
        # 2: an off-size ball, every ball ball by ball; 1: defects only, healthy law plus
        # the change of the balls in a defect (the kernels' faulty_bearing_forces_jit)
        b_int[ib, BI_FAULTY] = 2 if np.any(b_off[ib] != 0.0) else int(rows.size > 0)
    if np.any(b_off != 0.0):
        m_int[MI_FAULTY_BALLS] = 1
    rig = rm.rig
    tk1, tk2, te1, te2 = (np.ascontiguousarray(a, dtype=float) for a in
                          (fa.tooth_factor1, fa.tooth_factor2, fa.tooth_sep1, fa.tooth_sep2))
    teeth = rig.gears is not None and (np.any(teeth_with_own_tables(tk1, te1))
                                       or np.any(teeth_with_own_tables(tk2, te2)))
    if teeth:
        s0, ds = (float(v) for v in fa.tooth_grid_m)
        if abs(s0 - m_par_grid[0]) > 1e-12 or abs(ds - m_par_grid[1]) > 1e-12 * abs(ds):
            raise ParameterError("per-tooth tables must be on the run's mesh table grid")
        z1, z2 = rig.gears.driving.n_teeth, rig.gears.driven.n_teeth
        if tk1.shape[0] != z1 or te1.shape[0] != z1 or tk2.shape[0] != z2 \
                or te2.shape[0] != z2:
            raise ParameterError(f"per-tooth tables need {z1} rows for gear 1 and {z2} for "
                                 f"gear 2")
        m_int[MI_TEETH] = 1
    else:
        tk1 = tk2 = np.ones((1, 1))
        te1 = te2 = np.zeros((1, 1))
    ecc_in = np.asarray(fa.eccentricity, dtype=float).reshape(2, 3)
    ecc = np.zeros((2, 4))
    if rig.gears is not None and np.any(ecc_in[:, 0] != 0.0):
        m_int[MI_ECC] = 1
        # the kernel turns the offset with the gear's involute origin ψ = θ + ψ0
        refs = (rm.mesh["psi10"], rm.mesh["psi20"])
        for gear in range(2):
            ecc[gear] = (ecc_in[gear, 0], math.cos(ecc_in[gear, 1] - refs[gear]),
                         math.sin(ecc_in[gear, 1] - refs[gear]), ecc_in[gear, 2])
    return b_int, (b_def, b_off, tk1, tk2, te1, te2, ecc)


def _track(b_def, duration_s, seed):
    """Share of each defect row the races meet, on a time grid, and its spacing.

    Race defects: 1. Ball defects: the part of the pit inside the rolling track
    (:func:`cmsim.faults.bearing.track_share`) at its offset, constant for a fixed spin axis,
    else along a random walk of the axis (:func:`cmsim.faults.bearing.wandering_offset`,
    grid spacing a twentieth of the shortest correlation time, its own random stream of
    ``seed``). Returns ((m, n_grid), dt); n_grid = 1 when nothing varies.
    """
    m = b_def.shape[0]
    ball = b_def[:, DF_KIND] == DEF_BALL
    wander = ball & (b_def[:, DF_WANDER] > 0.0)
    if not np.any(wander):
        out = np.ones((m, 1))
        for r in np.flatnonzero(ball):
            out[r] = track_share(b_def[r, DF_AXIS], b_def[r, DF_TRACK], b_def[r, DF_HALF])
        return out, 1.0
    dt = float(np.min(b_def[wander, DF_WANDER])) / 20.0
    n_grid = int(math.ceil(duration_s / dt)) + 2
    rng = np.random.default_rng(None if seed is None else [int(seed), _TRACK_STREAM])
    out = np.ones((m, n_grid))
    for r in np.flatnonzero(ball):
        z = b_def[r, DF_AXIS]
        if wander[r]:
            z = wandering_offset(z, b_def[r, DF_WANDER], n_grid, dt, rng)
        out[r] = track_share(z, b_def[r, DF_TRACK], b_def[r, DF_HALF])
    return out, dt


#: Second word of the spin-axis random stream's seed (apart from the slip's stream).
_TRACK_STREAM = 0x5B1


def _jitter(bearings, max_balls, cage_rates, slip, duration_s, seed):
    """Slip grid (nb, max_balls + 1, n_grid) and its spacing; a dummy (…, 1) grid when off.

    Rows 0..n_balls−1 hold each ball's deviation from its nominal cage pocket; row
    ``max_balls`` holds the cage angle offset (a random walk: the integral of the cage-speed
    fluctuation), rad.
    """
    nb = len(bearings)
    if not slip.active:
        return np.zeros((nb, max_balls + 1, 1)), 1.0
    rng = np.random.default_rng(seed)
    dt = slip.correlation_s / 10.0
    n_grid = int(math.ceil(duration_s / dt)) + 2
    out = np.zeros((nb, max_balls + 1, n_grid))
    for ib, brg in enumerate(bearings):
        out[ib, :brg.n_balls] = slip_jitter(brg.n_balls, n_grid, dt, slip.ball_rms_rad,
                                            slip.correlation_s, rng)
        speed = slip_jitter(1, n_grid, dt, slip.cage_speed_rms, slip.correlation_s, rng)[0]
        out[ib, max_balls] = np.concatenate([[0.0], np.cumsum(speed[:-1])]) * cage_rates[ib] * dt
    return out, dt
