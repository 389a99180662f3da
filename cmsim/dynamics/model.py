"""Equations of motion of a rig at an operating point (paper 001, eq. 1 and Annex A).

The DOFs are ordered as in eq. 1: ``x, y, θ`` of each node (``1b1, 1G1, 1b2, 2b1, 2G1, 2b2``)
then ``θ_2J2``. Rotations are deviations from the nominal rigid rotation Ω·t (shaft 1 at the
imposed speed, shaft 2 at Ω·Z1/Z2, counted positive in its own sense of motion), so the input
coupling becomes a spring to ground and the DTE is ``θ_1G1 − (Z2/Z1)·θ_2G1`` exactly.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, eqs. 1, 5-10 and Annex A.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from cmsim.bearings.forces import ball_offsets
from cmsim.bearings.hertz import bearing_contact_stiffness
from cmsim.bearings.kinematics import cage_ratios
from cmsim.dynamics import _kernels as K
from cmsim.errors import ParameterError
from cmsim.mesh_stiffness._kernels import GEO_SIZE
from cmsim.mesh_stiffness.contact import (contact_geometry, corner_zone_m, potential_slots,
                                          reference_phases, table_range_m)
from cmsim.mesh_stiffness.table import MeshStiffnessTable

__all__ = ["DynamicModel", "SlipModel", "build_model"]


@dataclass(frozen=True)
class SlipModel:
    """Random rolling slip (paper 001 §5, last assumption, and §6.2.1).

    Two independent effects, both Ornstein-Uhlenbeck processes with correlation time
    ``correlation_s``, drawn from the run's seed:

    * the cage speed fluctuates by a fraction ``cage_speed_rms`` of its nominal value, so the
      cage angle wanders like a random walk and the ball-pass lines spread over a band;
    * each ball leads or lags its nominal place in the cage by a small angle of standard
      deviation ``ball_rms_rad`` (cage-pocket play).

    Attributes
    ----------
    cage_speed_rms : float
        Standard deviation of the relative cage-speed fluctuation (0.01 = 1 %).
    ball_rms_rad : float
        Standard deviation of each ball's angular deviation, rad (<= 0.05).
    correlation_s : float
        Correlation time of both processes, s.
    """

    cage_speed_rms: float = 0.0
    ball_rms_rad: float = 0.0
    correlation_s: float = 5e-3

    def __post_init__(self):
        from cmsim.errors import check_range
        check_range("cage_speed_rms", self.cage_speed_rms, 0.0, 0.2)
        check_range("ball_rms_rad", self.ball_rms_rad, 0.0, 0.05, unit="rad")
        check_range("correlation_s", self.correlation_s, 1e-5, 10.0, unit="s")

    @property
    def active(self):
        """True when any slip is requested."""
        return self.cage_speed_rms > 0.0 or self.ball_rms_rad > 0.0


@dataclass(frozen=True)
class DynamicModel:
    """Arrays of eq. 1 for one rig and operating point, ready for the numba kernels.

    Attributes
    ----------
    rig : Rig
    op : OperatingPoint
    mesh_table : MeshStiffnessTable or None
        Pair stiffness table (gear rigs).
    dof_names : tuple of str
        ``x_1b1, y_1b1, theta_1b1, ...``.
    mass : ndarray, shape (n,)
        Diagonal of M (kg or kg·m²).
    stiffness : ndarray, shape (n, n)
        Linear K of the shafts and couplings (N/m, N·m/rad).
    damping : ndarray, shape (n, n)
        Linear C of shafts, couplings and bearings.
    force : ndarray, shape (n,)
        Constant external load (output torque, radial load).
    omega : ndarray, shape (n,)
        Nominal rotation speed of each DOF, rad/s (0 for translations).
    packed : tuple
        Kernel argument tuple ``P`` (see :mod:`cmsim.dynamics._kernels`).
    diag_names : tuple of str
        Names of the output forces the kernel writes (bearing housing forces, pair forces).
    slip : SlipModel
    mesh_model : HybridMeshModel or None
        On-line hybrid contact model (model A), or ``None`` for the table.
    """

    rig: object
    op: object
    mesh_table: MeshStiffnessTable | None
    dof_names: tuple
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    force: np.ndarray
    omega: np.ndarray
    packed: tuple = field(repr=False)
    diag_names: tuple = ()
    slip: SlipModel = SlipModel()
    mesh_model: object = None

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

    @property
    def translational_mask(self):
        """Boolean mask of the x/y DOFs, shape (n,)."""
        return np.array([not d.startswith("theta") for d in self.dof_names])

    def rhs(self, t, y, want_diag=False):
        """Evaluate the kernel right-hand side; returns ``dydt`` (and ``diag``)."""
        dydt = np.empty((1, 2 * self.n_dof))
        diag = np.zeros(len(self.diag_names))
        K.rhs_jit(float(t), np.ascontiguousarray(y, dtype=float), dydt, 0, self.packed, diag,
                  bool(want_diag), K.make_work(self.packed))
        return (dydt[0], diag) if want_diag else dydt[0]

    def static_residual(self, t, q):
        """M·q̈ at rest relative to the nominal rotation (velocities zero), shape (n,)."""
        y = np.concatenate([q, np.zeros(self.n_dof)])
        return self.mass * self.rhs(t, y)[self.n_dof:]

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


def _node_masses(rig):
    masses = []
    for i, shaft in enumerate(rig.shafts):
        if rig.gears is not None:
            gear = rig.gears.driving if i == 0 else rig.gears.driven
            centre = (gear.mass_kg, gear.inertia_kg_m2)
        else:
            centre = (shaft.rotor.mass_kg, shaft.rotor.inertia_kg_m2)
        for mass, inertia in ((shaft.bearing_1.mass_kg, shaft.bearing_1.inertia_kg_m2), centre,
                              (shaft.bearing_2.mass_kg, shaft.bearing_2.inertia_kg_m2)):
            masses += [mass, mass, inertia]
    if rig.gears is not None:
        masses.append(rig.output_inertia_kg_m2)
    return np.array(masses, dtype=float)


def _spring_elements(rig):
    """Two-node spring-dampers of Annex A: list of (dof_a, dof_b or −1, k, c)."""
    elements = []
    for i, shaft in enumerate(rig.shafts):
        b1, c, b2 = 9 * i, 9 * i + 3, 9 * i + 6
        for seg, (na, nb) in enumerate(((b1, c), (c, b2))):
            for d in (0, 1):
                elements.append((na + d, nb + d, shaft.flexural_stiffness_n_per_m[seg],
                                 shaft.flexural_damping_n_s_per_m[seg]))
            elements.append((na + 2, nb + 2, shaft.torsional_stiffness_nm_per_rad[seg],
                             shaft.torsional_damping_nm_s_per_rad[seg]))
        for node, brg in ((b1, shaft.bearing_1), (b2, shaft.bearing_2)):
            for d in (0, 1):
                elements.append((node + d, -1, 0.0, brg.damping_n_s_per_m))
    # imposed input rotation: the coupling is a spring to ground in deviation coordinates
    elements.append((2, -1, rig.input_coupling.stiffness_nm_per_rad,
                     rig.input_coupling.damping_nm_s_per_rad))
    if rig.gears is not None:
        elements.append((9 + 6 + 2, rig.n_dof - 1, rig.output_coupling.stiffness_nm_per_rad,
                         rig.output_coupling.damping_nm_s_per_rad))
    return elements


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


def build_model(rig, op, mesh_table=None, *, slip=None, duration_s=1.0, seed=None,
                cage_phases_rad=None, mesh_model=None):
    """Assemble the :class:`DynamicModel` of ``rig`` at ``op``.

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    mesh_table : MeshStiffnessTable, optional
        Pair stiffness; default: the potential-energy table of the rig's gears, or with
        ``mesh_model`` the hybrid table of one mesh cycle at the operating torque (then used
        only for the mesh damping coefficient and the start guess).
    slip : SlipModel, optional
        Ball-position jitter (default none).
    duration_s : float
        Span over which jitter is generated (only with ``slip``), s.
    seed : int, optional
        Seed of the jitter generator.
    cage_phases_rad : sequence of float, optional
        Initial cage angle θ0 of each bearing (eq. 7), one per bearing in
        ``rig.bearing_names`` order; default all zero.
    mesh_model : HybridMeshModel, optional
        Solve the tooth contact forces on-line from the FE influence coefficients at every
        right-hand-side evaluation (paper 001 §6.1, model A) instead of using the table.

    Returns
    -------
    DynamicModel
    """
    slip = SlipModel() if slip is None else slip
    if mesh_model is not None:
        from cmsim.mesh_stiffness.hybrid import HybridMeshModel
        if not isinstance(mesh_model, HybridMeshModel):
            raise ParameterError(f"mesh_model must be a HybridMeshModel, got "
                                 f"{type(mesh_model).__name__}")
        if rig.gears is None:
            raise ParameterError("mesh_model given for a rig without gears")
        if mesh_model.pair != rig.gears:
            raise ParameterError("mesh_model was built for a different gear pair than the rig's")
    n = rig.n_dof
    mass = _node_masses(rig)
    elements = _spring_elements(rig)
    kmat, cmat = _linear_matrices(elements, n)
    names = _dof_names(rig)
    omega = np.zeros(n)
    ratio = rig.gears.driving.n_teeth / rig.gears.driven.n_teeth if rig.gears else 0.0
    speeds = (op.omega_rad_s, op.omega_rad_s * ratio)
    for i, name in enumerate(names):
        if name.startswith("theta"):
            omega[i] = speeds[0] if name[-3] == "1" else speeds[1]
    force = np.zeros(n)
    if rig.gears is not None:
        force[n - 1] = -op.torque_nm
    if op.radial_load_n > 0:
        force[3] += op.radial_load_n * math.cos(op.radial_load_angle_rad)
        force[4] += op.radial_load_n * math.sin(op.radial_load_angle_rad)

    # ---- bearings
    bearings = rig.bearings
    nb = len(bearings)
    max_balls = max(b.n_balls for b in bearings)
    b_int = np.zeros((nb, K.BI_SIZE), dtype=np.int64)
    b_par = np.zeros((nb, K.BP_SIZE))
    b_cos = np.zeros((nb, max_balls))
    b_sin = np.zeros((nb, max_balls))
    node_of = {name: k for k, name in enumerate(rig.node_names)}
    phases = np.zeros(nb) if cage_phases_rad is None else np.asarray(cage_phases_rad, float)
    if phases.shape != (nb,) or not np.all(np.isfinite(phases)):
        raise ParameterError(f"cage_phases_rad needs {nb} finite values (one per bearing "
                             f"{rig.bearing_names}), got {cage_phases_rad!r}")
    for ib, (bname, brg) in enumerate(zip(rig.bearing_names, bearings)):
        node = node_of[bname]
        k_in, k_out = cage_ratios(brg)
        sense = 1.0 if bname.startswith("1") else -1.0
        rate = (k_in + k_out * brg.outer_ring_speed_ratio) * sense * omega[3 * node + 2]
        # bearings turning alike share the nominal cage cos/sin (not with slip: each cage
        # then wanders on its own)
        group = next(j for j in range(ib + 1)
                     if j == ib or (not slip.active
                                    and b_par[j, K.BP_CAGE] * b_par[j, K.BP_SENSE]
                                    * omega[b_int[j, K.BI_T]] == rate
                                    and b_par[j, K.BP_PHASE] == phases[ib]))
        b_int[ib] = (3 * node, 3 * node + 1, 3 * node + 2, brg.n_balls, group)
        b_par[ib, K.BP_K] = bearing_contact_stiffness(brg)
        b_par[ib, K.BP_P] = brg.load_exponent
        b_par[ib, K.BP_C] = brg.clearance_m
        b_par[ib, K.BP_CAGE] = k_in + k_out * brg.outer_ring_speed_ratio
        b_par[ib, K.BP_SENSE] = sense
        b_par[ib, K.BP_DAMP] = brg.damping_n_s_per_m
        b_par[ib, K.BP_PHASE] = phases[ib]
        co, so = ball_offsets(brg)
        b_cos[ib, :brg.n_balls] = co
        b_sin[ib, :brg.n_balls] = so
    cage_rates = [abs(b_par[ib, K.BP_CAGE] * omega[b_int[ib, K.BI_T]]) for ib in range(nb)]
    jitter, jdt = _jitter(bearings, max_balls, cage_rates, slip, duration_s, seed)

    # ---- mesh
    m_int = np.zeros(K.MI_SIZE, dtype=np.int64)
    m_par = np.zeros(K.MP_SIZE)
    m_par[K.MP_JDT] = jdt
    m_par[K.MP_DIAGB] = 2 * nb
    diag_names = [f"F_{b}_{d}" for b in rig.bearing_names for d in ("x", "y")]
    if rig.gears is not None:
        pair = rig.gears
        if mesh_table is None:
            mesh_table = (default_mesh_table(pair) if mesh_model is None
                          else hybrid_mesh_table(mesh_model, op.torque_nm))
        geo = contact_geometry(pair)
        n_slots = potential_slots(pair)
        psi10, psi20 = reference_phases(pair)
        lo, _ = table_range_m(pair)
        before, after = corner_zone_m(pair)
        mode = K.MODE_TABLE if mesh_model is None else K.MODE_HYBRID
        m_int[:] = (3 * node_of["1G1"], 3 * node_of["2G1"], n_slots, 1, mode)
        mc, lub = rig.mesh_contact, rig.lubricant
        k_mean = mesh_table.mean_mesh_stiffness(pair)
        m_par[K.MP_A0] = pair.working_centre_distance_m
        m_par[K.MP_PSI10] = psi10
        m_par[K.MP_PSI20] = psi20
        m_par[K.MP_PB] = pair.driving.base_pitch_m
        m_par[K.MP_SLO] = lo
        m_par[K.MP_OM1] = speeds[0]
        m_par[K.MP_OM2] = speeds[1]
        m_par[K.MP_MU] = mc.friction_coefficient
        m_par[K.MP_V0] = mc.friction_smoothing_m_s
        m_par[K.MP_CHYST] = 2 * mc.damping_ratio * math.sqrt(k_mean * pair.mesh_stiffness_mass_kg)
        m_par[K.MP_KOSTER] = 12 * math.pi * lub.dynamic_viscosity_pa_s * min(
            pair.driving.face_width_m, pair.driven.face_width_m)
        m_par[K.MP_DTHR] = mc.squeeze_gap_threshold_m
        m_par[K.MP_TAB0] = mesh_table.position_m[0]
        m_par[K.MP_TABD] = mesh_table.spacing_m
        m_par[K.MP_ZBEFORE] = before
        m_par[K.MP_ZAFTER] = after
        tab_k = np.ascontiguousarray(mesh_table.stiffness_n_per_m)
        tab_e = np.ascontiguousarray(mesh_table.separation_m)
        diag_names += [f"Fmesh_{j}" for j in range(n_slots)]
        teeth1 = _pitch_multiples(pair.driving.n_teeth)
        teeth2 = _pitch_multiples(pair.driven.n_teeth)
    else:
        if mesh_table is not None:
            raise ParameterError("mesh_table given for a rig without gears")
        geo = np.zeros(GEO_SIZE)
        teeth1 = teeth2 = np.zeros((1, 2))
        m_par[K.MP_TABD] = 1.0
        tab_k = np.zeros(2)
        tab_e = np.zeros(2)
    # kernel layout: two-node springs first, then ground springs (b = a), count in [0, 2]
    ordered = sorted(elements, key=lambda e: e[1] < 0)
    springs = np.array([(k, c) for _, _, k, c in ordered])
    spring_ends = np.array([(a, a if b < 0 else b, 0) for a, b, _, _ in ordered], dtype=np.int64)
    spring_ends[0, 2] = sum(1 for e in ordered if e[1] < 0)
    if mesh_model is not None:
        hybrid = tuple(np.ascontiguousarray(a, dtype=float) for a in mesh_model.kernel_args())
    else:
        hybrid = K.no_hybrid()
    packed = (1.0 / mass, springs, force, omega, b_int, b_par, b_cos, b_sin, jitter, m_int,
              m_par, geo, tab_k, tab_e, teeth1, teeth2, spring_ends) + hybrid
    return DynamicModel(rig, op, mesh_table, names, mass, kmat, cmat, force, omega, packed,
                        tuple(diag_names), slip, mesh_model)


def _pitch_multiples(n_teeth):
    """cos and sin of k·2π/Z for k = 0..Z−1, shape (Z, 2)."""
    a = 2.0 * math.pi * np.arange(n_teeth) / n_teeth
    return np.ascontiguousarray(np.column_stack([np.cos(a), np.sin(a)]))


def default_mesh_table(pair):
    """Potential-energy table of ``pair`` (cached per gear pair)."""
    return _pe_table_cached(pair)


_PE_CACHE = {}
_HYBRID_CACHE = {}


def hybrid_mesh_table(mesh_model, output_torque_nm):
    """Hybrid table of one mesh cycle at the driving torque that ``output_torque_nm`` needs.

    Memoised per (model, torque): model A uses it for the mesh damping coefficient (from its
    mean stiffness) and the quasi-static start guess.
    """
    pair = mesh_model.pair
    drive = max(output_torque_nm, 1e-3) * pair.driving.n_teeth / pair.driven.n_teeth
    key = (id(mesh_model), drive)
    if key not in _HYBRID_CACHE:
        from cmsim.mesh_stiffness.mesh_cycle import mesh_cycle
        _HYBRID_CACHE[key] = (mesh_model, mesh_cycle(mesh_model, drive, n_steps=24).table)
    return _HYBRID_CACHE[key][1]


def _pe_table_cached(pair):
    if pair not in _PE_CACHE:
        _PE_CACHE[pair] = MeshStiffnessTable.potential_energy(pair)
    return _PE_CACHE[pair]


def _jitter(bearings, max_balls, cage_rates, slip, duration_s, seed):
    """Slip grid (nb, max_balls + 1, n_grid) and its spacing; a dummy (…, 1) grid when off.

    Rows 0..n_balls−1 hold each ball's deviation from its nominal cage pocket; row
    ``max_balls`` holds the cage angle offset (a random walk: the integral of the cage-speed
    fluctuation), rad.
    """
    nb = len(bearings)
    if not slip.active:
        return np.zeros((nb, max_balls + 1, 1)), 1.0
    from cmsim.bearings.kinematics import slip_jitter
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
