"""Power balance of a simulated run: input = output + losses by source + d(stored energy)/dt.

Everything is read from the :class:`~cmsim.run.Run` (DOF signals, bearing housing forces,
per-pair mesh normal forces ``Fmesh_j``) and the rig in its meta; velocities are central
differences of the recorded positions. Averaged over the record of duration W:

* input: the motor turns at Ω1 and drives ``theta_1b1`` through the input coupling, torque
  T_c = −k_c·q − c_c·q̇ (q: twist from the imposed rotation), P_in = ⟨T_c⟩·Ω1;
* output: the load torque T on ``theta_2J2``, P_out = T·Δθ_2J2/W;
* extra resisting torques (windage, pumping, bearing friction: the ``loads`` given to
  ``simulate``): Σ |L_i|·Δθ_i/W;
* tooth friction: Σ_j μ(s_j)·F_j·v_s²/sqrt(v_s² + v0²) (paper 004 eq. 21 with the kernel's
  smoothed sign), s_j and v_s from the gear rotations and centre velocities;
* mesh normal force: Σ_j F_j·(approach velocity) (hysteretic and squeeze damping, plus the
  work of the position-dependent stiffness), minus the change of ½·F²/k stored in the teeth;
* bearings: Σ F_housing·v (Hertz contacts with their moving balls and the bearing dampers);
* linear springs and dampers of Annex A (shafts, couplings): Σ c·Δv², and the change of
  ½·k·Δq²;
* kinetic energy: ½·Σ m·(Ω + v)² at the ends.

The residual P_in − P_out − Σ sources − ΔE/W measures how well the run conserves energy
(integration error, central differences, the Hertz energy of the balls which is not
counted). The nominal geometry of the line of action is used for s and v_s (centre
displacements of µm change them by < 1e-5 relative).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError
from cmsim.mesh_stiffness.contact import reference_phases, table_range_m

__all__ = ["PowerBalance", "power_balance"]


@dataclass(frozen=True)
class PowerBalance:
    """Mean powers of a run, W.

    Attributes
    ----------
    input_w, output_w : float
        Motor power into the input coupling and power into the load torque.
    losses_w : dict
        Dissipated power by source: ``loads`` (extra resisting torques, by DOF in
        ``loads_by_dof_w``), ``tooth_friction``, ``mesh_damping``, ``bearings``,
        ``linear_damping``.
    stored_rate_w : float
        Change of stored energy (kinetic, springs, teeth) over the window / its duration.
    loads_by_dof_w : dict
    duration_s : float
    """

    input_w: float
    output_w: float
    losses_w: dict
    stored_rate_w: float
    loads_by_dof_w: dict
    duration_s: float

    @property
    def total_loss_w(self):
        """Σ losses, W."""
        return float(sum(self.losses_w.values()))

    @property
    def residual_w(self):
        """P_in − P_out − Σ losses − dE/dt, W."""
        return self.input_w - self.output_w - self.total_loss_w - self.stored_rate_w

    @property
    def closure(self):
        """|residual| / P_in."""
        return abs(self.residual_w) / abs(self.input_w) if self.input_w else math.inf

    @property
    def closure_of_losses(self):
        """|residual| / (P_in − P_out): the error on the losses themselves."""
        gap = self.input_w - self.output_w
        return abs(self.residual_w) / abs(gap) if gap else math.inf

    @property
    def efficiency(self):
        """P_out / P_in."""
        return self.output_w / self.input_w if self.input_w else math.nan

    def to_dict(self):
        """Plain dict (JSON, run meta)."""
        return {"input_w": float(self.input_w), "output_w": float(self.output_w),
                "losses_w": {k: float(x) for k, x in self.losses_w.items()},
                "stored_rate_w": float(self.stored_rate_w),
                "residual_w": float(self.residual_w), "closure": float(self.closure),
                "closure_of_losses": float(self.closure_of_losses),
                "efficiency": float(self.efficiency),
                "loads_by_dof_w": {k: float(x) for k, x in self.loads_by_dof_w.items()},
                "duration_s": float(self.duration_s)}


def _mean(x, t):
    return float(np.trapezoid(x, t) / (t[-1] - t[0]))


def power_balance(run, loads=None, friction_table=None, mesh_table=None):
    """Power balance of ``run`` (module docstring).

    Parameters
    ----------
    run : Run
        A simulated run at constant speed (no speed profile), with its rig in the meta.
    loads : dict, optional
        The ``loads`` given to ``simulate`` (DOF name → generalised force, negative for a
        resisting torque).
    friction_table : ndarray, optional
        The ``friction_table`` given to ``simulate`` (on ``mesh_table``'s grid).
    mesh_table : MeshStiffnessTable, optional
        The run's table (needed with ``friction_table``; its k(s) gives the teeth's stored
        energy).

    Returns
    -------
    PowerBalance
    """
    rig, op = run.rig, run.operating_point
    if rig is None or op is None or "dof_names" not in run.meta:
        raise ParameterError("power_balance needs a simulated run (rig, operating point and "
                             "dof_names in its meta)")
    if run.meta.get("speed_profile"):
        raise ParameterError("power_balance needs a run at constant speed (no speed profile)")
    if friction_table is not None and mesh_table is None:
        raise ParameterError("power_balance: friction_table needs its mesh_table")
    names = list(run.meta["dof_names"])
    n = len(names)
    t = np.asarray(run.t, dtype=float)
    if t.size < 3:
        raise ParameterError("power_balance needs at least 3 samples")
    dt = float(t[1] - t[0])
    duration = float(t[-1] - t[0])
    omega1 = op.omega_rad_s
    ratio = rig.gears.driving.n_teeth / rig.gears.driven.n_teeth if rig.gears else 1.0
    nominal = np.array([(omega1 if nm[-3] == "1" else omega1 * ratio)
                        if nm.startswith("theta") else 0.0 for nm in names])
    q = np.empty((n, t.size))
    for i, nm in enumerate(names):
        q[i] = np.asarray(run[nm], dtype=float) - nominal[i] * t
    v = np.gradient(q, dt, axis=1)
    mass = rig.dof_masses
    # input, output
    kc, cc = rig.input_coupling.stiffness_nm_per_rad, rig.input_coupling.damping_nm_s_per_rad
    p_in = _mean((-kc * q[2] - cc * v[2]) * omega1, t)
    p_out = 0.0
    if rig.gears is not None:
        p_out = op.torque_nm * (nominal[-1] + (q[-1, -1] - q[-1, 0]) / duration)
    losses = {"loads": 0.0, "tooth_friction": 0.0, "mesh_damping": 0.0, "bearings": 0.0,
              "linear_damping": 0.0}
    by_dof = {}
    for nm, value in (loads or {}).items():
        i = names.index(nm)
        by_dof[nm] = -value * (nominal[i] + (q[i, -1] - q[i, 0]) / duration)
        losses["loads"] += by_dof[nm]
    stored = 0.0
    # bearings: housing force (Hertz + damper) times the node velocity
    for b in rig.bearing_names:
        ix = names.index(f"x_{b}")
        losses["bearings"] += _mean(run[f"F_{b}_x"] * v[ix] + run[f"F_{b}_y"] * v[ix + 1], t)
    # linear elements
    for a, b, k, c in rig.spring_elements(bearing_dampers=False):
        dq = q[a] - (q[b] if b >= 0 else 0.0)
        dv = v[a] - (v[b] if b >= 0 else 0.0)
        losses["linear_damping"] += c * _mean(dv * dv, t)
        stored += 0.5 * k * (dq[-1] ** 2 - dq[0] ** 2)
    speed = nominal[:, None] + v
    stored += 0.5 * float(np.sum(mass * (speed[:, -1] ** 2 - speed[:, 0] ** 2)))
    if rig.gears is not None:
        fr, mesh_stored = _mesh_powers(rig, op, run, names, q, v, nominal, t, friction_table,
                                       mesh_table)
        losses["tooth_friction"] = fr[0]
        losses["mesh_damping"] = fr[1]
        stored += mesh_stored
    return PowerBalance(float(p_in), float(p_out), {k: float(x) for k, x in losses.items()},
                        float(stored / duration), {k: float(x) for k, x in by_dof.items()},
                        duration)


def _mesh_powers(rig, op, run, names, q, v, nominal, t, friction_table, mesh_table):
    pair = rig.gears
    rb1, rb2 = pair.driving.base_radius_m, pair.driven.base_radius_m
    pb = pair.driving.base_pitch_m
    alpha = pair.working_pressure_angle_rad
    a0 = pair.working_centre_distance_m
    length = a0 * math.sin(alpha)
    phi_t = 0.5 * math.pi - alpha
    psi10, _ = reference_phases(pair)
    slo = table_range_m(pair)[0]
    i1, i2 = names.index("x_1G1"), names.index("x_2G1")
    th1 = q[i1 + 2] + nominal[i1 + 2] * t
    w1 = nominal[i1 + 2] + v[i1 + 2]
    w2 = -(nominal[i2 + 2] + v[i2 + 2])
    t1 = np.array([rb1 * math.cos(phi_t), rb1 * math.sin(phi_t)])
    t2 = np.array([0.0, a0]) - np.array([rb2 * math.cos(phi_t), rb2 * math.sin(phi_t)])
    e = (t2 - t1) / length
    tang = np.array([e[1], -e[0]])
    s_ref = rb1 * (th1 + psi10 - phi_t)
    m0 = np.floor((s_ref - slo) / pb)
    slots = sorted(int(k.split("_")[1]) for k in run.names if k.startswith("Fmesh_")
                   and k != "Fmesh_total")
    mu0 = rig.mesh_contact.friction_coefficient
    v0 = rig.mesh_contact.friction_smoothing_m_s
    p_fric = np.zeros_like(t)
    p_norm = np.zeros_like(t)
    stored_ends = [0.0, 0.0]
    for j in slots:
        fn = np.asarray(run[f"Fmesh_{j}"], dtype=float)
        s = s_ref - (m0 - j) * pb
        px = t1[0] + s * e[0]
        py = t1[1] + s * e[1]
        dvx = (v[i1] - w1 * py) - (v[i2] - w2 * (py - a0))
        dvy = (v[i1 + 1] + w1 * px) - (v[i2 + 1] + w2 * px)
        approach = dvx * e[0] + dvy * e[1]
        slide = dvx * tang[0] + dvy * tang[1]
        if friction_table is not None:
            mu = np.interp(s, mesh_table.position_m, np.asarray(friction_table, dtype=float))
        else:
            mu = mu0
        p_fric += mu * fn * slide * slide / np.sqrt(slide * slide + v0 * v0)
        p_norm += fn * approach
        if mesh_table is not None:
            for end, idx in ((0, 0), (1, -1)):
                k = float(mesh_table.stiffness_at(s[idx]))
                if k > 0 and fn[idx] > 0:
                    stored_ends[end] += 0.5 * fn[idx] ** 2 / k
    mesh_stored = stored_ends[1] - stored_ends[0]
    duration = t[-1] - t[0]
    return (_mean(p_fric, t), _mean(p_norm, t) - mesh_stored / duration), mesh_stored
