"""Every loss source of a rig at one operating point, and the loads that put them in a run.

Load-independent: windage and meshing (pumping) of each gear (paper 000 eq. 25-28), the
oil jet (eq. 30) and the bearings' viscous torque (Palmgren). Load-dependent: the bearings'
load torque (Harris–Palmgren) and the tooth friction (paper 004 eq. 21, P = μ·F·|v_s|,
averaged over one base pitch with the quasi-static load sharing and the mixed-lubrication μ).

:meth:`LossBreakdown.loads` gives the resisting torques by DOF name for
``cmsim.dynamics.simulate(loads=...)``; the tooth friction enters a run through
``friction_table`` (:func:`cmsim.losses.mixed_friction.friction_table_for`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from cmsim.errors import ParameterError, check_range, check_type
from cmsim.rig import OperatingPoint
from cmsim.losses.bearing_friction import bearing_friction_torque, ring_kinematics
from cmsim.losses.gear_losses import (air_density_kg_m3, meshing_torque_nm, oil_jet_torque_nm,
                                      windage_torque_nm)
from cmsim.losses.ehl import mesh_film_along_path
from cmsim.losses.mixed_friction import (BOUNDARY_FRICTION, friction_table_for,
                                         mesh_friction_along_path)

__all__ = ["LossSettings", "LossBreakdown", "RunLosses", "operating_losses", "run_losses",
           "loss_sweep", "rig_with_film_gap", "LOAD_INDEPENDENT", "LOAD_DEPENDENT"]

#: Sources that do not depend on the transmitted torque.
LOAD_INDEPENDENT = ("windage", "meshing", "oil_jet", "bearing_viscous")
#: Sources that grow with the torque.
LOAD_DEPENDENT = ("bearing_load", "tooth_friction")


@dataclass(frozen=True)
class LossSettings:
    """Environment and model constants of the loss sources.

    Attributes
    ----------
    air_pressure_pa : float
        Pressure around the gears, Pa (paper 000 Table 4: ~101 kPa; its chamber can go 60 kPa
        below ambient).
    air_temperature_c : float
        Air temperature, °C.
    oil_jet_kg_s : float
        Oil mass flow of the radial jet per gear, kg/s (0: no jet).
    bearing_f0 : float
        Palmgren lubrication factor of the viscous torque.
    boundary_friction : float
        μ_b of the asperity contacts.
    roughness_m : float or None
        Composite roughness (default: the rig lubricant's).
    """

    air_pressure_pa: float = 101325.0
    air_temperature_c: float = 20.0
    oil_jet_kg_s: float = 0.0
    bearing_f0: float = 2.0
    boundary_friction: float = BOUNDARY_FRICTION
    roughness_m: float | None = None

    def __post_init__(self):
        check_range("air_pressure_pa", self.air_pressure_pa, 0.0, 1e7, lo_open=True, unit="Pa")
        check_range("air_temperature_c", self.air_temperature_c, -100.0, 500.0, unit="degC")
        check_range("oil_jet_kg_s", self.oil_jet_kg_s, 0.0, 100.0, unit="kg/s")
        check_range("bearing_f0", self.bearing_f0, 0.0, 20.0)
        check_range("boundary_friction", self.boundary_friction, 0.0, 1.0)
        if self.roughness_m is not None:
            check_range("roughness_m", self.roughness_m, 0.0, 50e-6, lo_open=True, unit="m")


@dataclass(frozen=True)
class LossBreakdown:
    """Loss sources at one operating point.

    Attributes
    ----------
    speed_rpm, torque_nm : float
        Input speed and output torque.
    output_power_w : float
        T·ω of the output, W.
    power_w : dict
        Loss power by source (``windage``, ``meshing``, ``oil_jet``, ``bearing_viscous``,
        ``bearing_load``, ``tooth_friction``), W.
    torques_nm : dict
        Resisting torque by DOF name (``theta_1G1``, ``theta_2b1``, ...), N·m (>= 0).
    mean_friction : float
        Load-weighted mean tooth friction coefficient.
    min_film_ratio : float
        Smallest λ = h_min/σ on the loaded path.
    """

    speed_rpm: float
    torque_nm: float
    output_power_w: float
    power_w: dict
    torques_nm: dict = field(default_factory=dict)
    mean_friction: float = 0.0
    min_film_ratio: float = math.inf

    @property
    def total_loss_w(self):
        """Sum of every source, W."""
        return float(sum(self.power_w.values()))

    @property
    def input_power_w(self):
        """Output + losses, W."""
        return self.output_power_w + self.total_loss_w

    @property
    def efficiency(self):
        """Output / input (1 when nothing is transmitted nor lost)."""
        p_in = self.input_power_w
        return self.output_power_w / p_in if p_in > 0 else 1.0

    @property
    def load_independent_w(self):
        """Windage + meshing + oil jet + bearing viscous, W."""
        return float(sum(self.power_w.get(k, 0.0) for k in LOAD_INDEPENDENT))

    @property
    def load_dependent_w(self):
        """Bearing load term + tooth friction, W."""
        return float(sum(self.power_w.get(k, 0.0) for k in LOAD_DEPENDENT))

    def loads(self):
        """Resisting torques as ``simulate(loads=...)`` wants them (negative, N·m)."""
        return {name: -value for name, value in self.torques_nm.items() if value > 0}

    def to_dict(self):
        """Plain dict (JSON)."""
        return {"speed_rpm": self.speed_rpm, "torque_nm": self.torque_nm,
                "output_power_w": self.output_power_w, "input_power_w": self.input_power_w,
                "power_w": dict(self.power_w), "total_loss_w": self.total_loss_w,
                "load_independent_w": self.load_independent_w,
                "load_dependent_w": self.load_dependent_w, "efficiency": self.efficiency,
                "torques_nm": dict(self.torques_nm), "mean_friction": self.mean_friction,
                "min_film_ratio": self.min_film_ratio}


def _static_bearing_loads(rig, op):
    """Radial load of each bearing, N: the mesh force shared by the shaft's two bearings (or
    the radial load of a rotor rig)."""
    if rig.gears is not None:
        force = op.torque_nm / rig.gears.driven.base_radius_m
    else:
        force = op.radial_load_n
    return {name: 0.5 * force for name in rig.bearing_names}


def operating_losses(rig, op, settings=None, mesh_table=None):
    """Every loss source of ``rig`` at ``op`` (module docstring).

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    settings : LossSettings, optional
    mesh_table : MeshStiffnessTable, optional
        Load sharing of the tooth pairs (default: equal sharing on the involute path).

    Returns
    -------
    LossBreakdown

    Examples
    --------
    >>> from cmsim.rig import Rig, OperatingPoint
    >>> b = operating_losses(Rig.paper_2016(), OperatingPoint(1000.0, 50.0))
    >>> bool(0.95 < b.efficiency < 1.0)
    True
    """
    settings = LossSettings() if settings is None else settings
    rho_air = air_density_kg_m3(settings.air_pressure_pa, settings.air_temperature_c)
    n1 = op.speed_rpm
    torques = {}
    power = dict.fromkeys(LOAD_INDEPENDENT + LOAD_DEPENDENT, 0.0)
    mean_mu, min_lam = 0.0, math.inf
    lub = rig.lubricant
    nu_cst = lub.dynamic_viscosity_pa_s / lub.density_kg_m3 * 1e6
    if rig.gears is not None:
        pair = rig.gears
        n2 = n1 * pair.driving.n_teeth / pair.driven.n_teeth
        output = op.torque_nm * n2 * math.pi / 30.0
        for dof, gear, n in (("theta_1G1", pair.driving, n1), ("theta_2G1", pair.driven, n2)):
            w = float(windage_torque_nm(n, gear.pitch_radius_m, rho_air))
            m = float(meshing_torque_nm(n, gear.pitch_radius_m, rho_air))
            j = float(oil_jet_torque_nm(n, gear.pitch_radius_m, settings.oil_jet_kg_s))
            torques[dof] = w + m + j
            omega = n * math.pi / 30.0
            power["windage"] += w * omega
            power["meshing"] += m * omega
            power["oil_jet"] += j * omega
        if op.torque_nm > 0:
            pb = pair.driving.base_pitch_m
            lo = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad) / 2
            s = lo + np.linspace(-2 * pb, 2 * pb, 801)
            path = mesh_friction_along_path(rig, op, s, mesh_table,
                                            roughness_m=settings.roughness_m,
                                            boundary_friction=settings.boundary_friction)
            f = path["load_n"]
            # four base pitches: each pair position counted once per pitch (mean over a cycle)
            p_f = path["friction"] * f * np.abs(path["sliding_m_s"])
            power["tooth_friction"] = float(np.trapezoid(p_f, s) / pb)
            loaded = f > 0
            if np.any(loaded):
                mean_mu = float(np.sum(path["friction"][loaded] * f[loaded]) / np.sum(f[loaded]))
                min_lam = float(np.min(path["lambda"][loaded]))
    else:
        n2 = n1
        output = 0.0
    loads = _static_bearing_loads(rig, op)
    for name, brg in zip(rig.bearing_names, rig.bearings):
        n = n1 if name.startswith("1") else n2
        kin = ring_kinematics(brg, n)
        fr = bearing_friction_torque(brg, loads[name], kin.relative_rpm, nu_cst,
                                     f0=settings.bearing_f0)
        torques[f"theta_{name}"] = fr.torque_nm
        omega = kin.relative_rpm * math.pi / 30.0
        power["bearing_viscous"] += fr.viscous_torque_nm * omega
        power["bearing_load"] += fr.load_torque_nm * omega
    return LossBreakdown(n1, op.torque_nm, output, power, torques, mean_mu, min_lam)


@dataclass(frozen=True)
class RunLosses:
    """What a run with every loss on is given, and the breakdown it was made from.

    Attributes
    ----------
    breakdown : LossBreakdown
        Every source at the operating point (quasi-static).
    loads : dict
        Resisting torques by DOF name (``simulate(loads=...)``), N·m, negative.
    friction_table : ndarray or None
        Mixed-lubrication friction coefficient on the mesh table's grid
        (``simulate(friction_table=...)``); ``None`` on a rig without gears.
    settings : LossSettings
    """

    breakdown: LossBreakdown
    loads: dict
    friction_table: np.ndarray | None
    settings: LossSettings

    def to_dict(self):
        """Plain dict (run meta): the settings and the quasi-static breakdown."""
        return {"settings": {k: getattr(self.settings, k)
                             for k in self.settings.__dataclass_fields__},
                "quasi_static": self.breakdown.to_dict()}


def run_losses(rig, op, mesh_table=None, settings=None):
    """Every loss source of ``rig`` at ``op`` as the inputs of a run (:class:`RunLosses`).

    The windage, pumping, oil-jet and bearing torques become resisting torques on the gear
    and bearing rotations, and the tooth friction follows the film: the mixed-lubrication
    coefficient along the path of contact (the rig lubricant's viscosity, the settings' or
    the lubricant's roughness) replaces the rig's constant.

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    mesh_table : MeshStiffnessTable, optional
        The run's table (its grid and load sharing); needed on a gear rig.
    settings : LossSettings, optional

    Returns
    -------
    RunLosses
    """
    settings = LossSettings() if settings is None else settings
    check_type("losses", settings, LossSettings)
    if rig.gears is not None and mesh_table is None:
        raise ParameterError("run_losses needs the run's mesh_table on a gear rig",
                             param="mesh_table")
    breakdown = operating_losses(rig, op, settings, mesh_table)
    mu = None
    if rig.gears is not None:
        roughness = (rig.lubricant.surface_roughness_m if settings.roughness_m is None
                     else settings.roughness_m)
        mu = friction_table_for(rig, op, mesh_table, roughness,
                                rig.lubricant.dynamic_viscosity_pa_s,
                                boundary_friction=settings.boundary_friction)
    return RunLosses(breakdown, breakdown.loads(), mu, settings)


def loss_sweep(rig, speeds_rpm, torque_nm, settings=None):
    """:class:`LossBreakdown` at each speed (same torque): the data of paper 000 Figs. 53-57.

    Parameters
    ----------
    rig : Rig
    speeds_rpm : sequence of float
        Input speeds, rpm.
    torque_nm : float
        Output torque, N·m.
    settings : LossSettings, optional
    """
    return [operating_losses(rig, OperatingPoint(float(n), torque_nm), settings)
            for n in speeds_rpm]


def rig_with_film_gap(rig, op):
    """Same rig with the Koster squeeze gap threshold set to the central film on the pitch
    point at ``op`` (the gap below which oil can no longer be squeezed out)."""
    if rig.gears is None:
        raise ParameterError("rig_with_film_gap needs a rig with gears")
    pair = rig.gears
    length = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)
    pitch = pair.driving.base_radius_m * math.tan(pair.working_pressure_angle_rad)
    h = float(mesh_film_along_path(rig, op, np.array([min(pitch, length)]))["h_c_m"][0])
    h = min(max(h, 1e-9), 1e-3)
    return replace(rig, mesh_contact=replace(rig.mesh_contact, squeeze_gap_threshold_m=h))
