"""Faults → what the model consumes: :class:`FaultArrays`, a changed rig, slip, modulations.

The contract with the dynamics kernels (:mod:`cmsim.dynamics._bearing_kernels` and
:mod:`cmsim.dynamics._mesh_kernels` read these arrays):
:func:`compile_faults` turns a tuple of faults into one :class:`FaultArrays` (float64 arrays,
all present, neutral when unused); :func:`rig_with_faults` applies the faults that are plain
rig changes (bearing wear); :func:`slip_from_faults` picks the run's rolling slip,
:func:`operating_modulation` the speed and torque factors, :func:`fault_frequencies` the
answer key for a run's meta.

References
----------
.. [1] N. Sawalhi, R. B. Randall, MSSP 22 (2008) 1924-1951 (bearing defects).
.. [2] F. Chaari, T. Fakhfakh, M. Haddar, Eur. J. Mech. A/Solids 28 (2009) 461-468 (crack).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from cmsim.errors import ParameterError
from cmsim.faults.base import Fault, check_bearing, first_clash
from cmsim.faults.bearing import (BallDefect, BearingWear, InnerRaceDefect, OffSizeBall,
                                  OuterRaceDefect, RollingSlip)
from cmsim.faults.crack import crack_stiffness_factor
from cmsim.faults.gear import (BREAKAGE_SEPARATION_M, Eccentricity, ProfileError, ToothBreakage,
                               ToothCrack, ToothSpall, roll_length_m)
from cmsim.faults.operating import (MAX_TOTAL_RELATIVE_AMPLITUDE, SpeedFluctuation,
                                    TorqueRipple)
from cmsim.frequencies import rig_frequencies
from cmsim.mesh_stiffness.contact import table_range_m
from cmsim.mesh_stiffness.geometry import ToothProfile
from cmsim.mesh_stiffness.potential_energy import _path_length

__all__ = ["FaultArrays", "CheckedFaults", "compile_faults", "rig_with_faults",
           "slip_from_faults", "operating_modulation", "fault_frequencies", "check_faults",
           "DEFECT_COLUMNS", "DEFAULT_GRID_POINTS", "TOOTH_TABLE_FAULTS"]

#: Columns of ``FaultArrays.bearing_defects``.
DEFECT_COLUMNS = ("bearing", "kind", "centre_rad", "half_width_rad", "depth_m", "entry_rad",
                  "exit_rad", "ball", "axis_offset", "wander_s", "track_rad")

#: The faults :func:`compile_faults` writes into the per-tooth tables (``tooth_factor*``,
#: ``tooth_sep*``): runs with any of them have the same kernel layout, whichever tooth of
#: which gear they change.
TOOTH_TABLE_FAULTS = (ToothCrack, ToothSpall, ToothBreakage, ProfileError)

#: Grid points of the tooth tables when no mesh table is given (as
#: :meth:`~cmsim.mesh_stiffness.table.MeshStiffnessTable.potential_energy`).
DEFAULT_GRID_POINTS = 257


class FaultArrays(NamedTuple):
    """Everything the kernel needs of the faults (float64 arrays; neutral when unused).

    Attributes
    ----------
    bearing_defects : ndarray, shape (m, 11)
        One row per race/ball defect, columns :data:`DEFECT_COLUMNS` (see
        :mod:`cmsim.faults.bearing`); m = 0 without defects.
    ball_offset_m : ndarray, shape (nb, max_balls)
        Extra overlap of each ball, m (off-size ball: +Δd).
    tooth_factor1, tooth_factor2 : ndarray, shape (Z1, n_s), (Z2, n_s)
        Pair-stiffness factor when tooth k of gear 1 (2) is in contact at s = s0 + i·ds;
        ones when healthy; shape (0, 0) on a rig without gears.
    tooth_sep1, tooth_sep2 : ndarray, shape (Z1, n_s), (Z2, n_s)
        Additional unloaded separation, m; zeros when healthy.
    eccentricity : ndarray, shape (2, 3)
        (amplitude m, phase rad, mass on the offset centre kg) of gear 1 and gear 2.
    tooth_grid_m : ndarray, shape (2,)
        (s0, ds) of the tooth tables' grid, m: the run's mesh table grid when one is given
        (then equal to its ``position_m[0]`` and spacing), else a grid of
        :data:`DEFAULT_GRID_POINTS` over the potential-contact zone; (0, 0) without gears.
    """

    bearing_defects: np.ndarray
    ball_offset_m: np.ndarray
    tooth_factor1: np.ndarray
    tooth_factor2: np.ndarray
    tooth_sep1: np.ndarray
    tooth_sep2: np.ndarray
    eccentricity: np.ndarray
    tooth_grid_m: np.ndarray

    @property
    def has_bearing_defects(self):
        """True when any race/ball defect or off-size ball is present."""
        return self.bearing_defects.shape[0] > 0 or bool(np.any(self.ball_offset_m != 0.0))

    @property
    def has_tooth_faults(self):
        """True when any tooth table differs from healthy."""
        return bool(np.any(self.tooth_factor1 != 1.0) or np.any(self.tooth_factor2 != 1.0)
                    or np.any(self.tooth_sep1 != 0.0) or np.any(self.tooth_sep2 != 0.0))

    @property
    def has_eccentricity(self):
        """True when a gear is eccentric."""
        return bool(np.any(self.eccentricity[:, 0] != 0.0))

    @property
    def active(self):
        """True when the kernel has anything to do."""
        return self.has_bearing_defects or self.has_tooth_faults or self.has_eccentricity


class CheckedFaults(tuple):
    """A tuple of faults :func:`check_faults` validated against one rig (attribute ``rig``).

    The functions of this module validate the faults they are given; handed a
    ``CheckedFaults`` of the same rig (the same object), they trust it instead of validating
    again, so a run validates its faults once however many steps read them.
    """


def check_faults(rig, faults):
    """Validate ``faults`` (a Fault or an iterable of them) against ``rig``.

    Parameters
    ----------
    rig : Rig
        The rig as given (before the faults' own changes, e.g. wear).
    faults : Fault or iterable of Fault
        Catalogue entries; a :class:`CheckedFaults` of this rig is returned as is.

    Returns
    -------
    CheckedFaults
        The faults as a tuple that remembers the rig it was checked on.
    """
    if isinstance(faults, CheckedFaults) and faults.rig is rig:
        return faults
    if isinstance(faults, Fault):
        faults = (faults,)
    faults = tuple(faults or ())
    for i, f in enumerate(faults):
        if not isinstance(f, Fault):
            raise ParameterError(f"faults[{i}] must be a Fault (see cmsim.faults), got "
                                 f"{type(f).__name__}", param="faults")
        f.validate(rig)
    clash = first_clash(faults)
    if clash is not None:
        i, j, why = clash
        raise ParameterError(f"faults[{j}] ({faults[j].label}) {why} faults[{i}] "
                             f"({faults[i].label}); give each fault once", param="faults")
    checked = CheckedFaults(faults)
    checked.rig = rig
    return checked


def _load_zone_angle(rig, bearing_index, op):
    """Centre of the load zone of a bearing, rad (direction of the load on its shaft).

    Bearing rig: the radial load direction (``op.radial_load_angle_rad``, default −π/2, down).
    Gear rig: the mesh force on the shaft's gear along the line of action,
    (cos α_w, −sin α_w) on shaft 1 and the opposite on shaft 2 (the convention of the
    dynamics' ``DynamicModel.loa_direction``).
    """
    if not rig.has_gears:
        return -0.5 * math.pi if op is None else float(op.radial_load_angle_rad)
    alpha = rig.gears.working_pressure_angle_rad
    shaft = 0 if bearing_index < 2 else 1
    return -alpha if shaft == 0 else math.pi - alpha


def _ball_load_n(rig, bearing_index, op):
    """Load of the most loaded ball, N (Stribeck: 5 F_r / Z), at least 10 N.

    F_r: the radial load on a bearing rig, half the mesh force T_out / r_b2 on a gear rig
    (each shaft on two bearings); without ``op`` 100 N per ball.
    """
    if op is None:
        return 100.0
    if rig.has_gears:
        fr = 0.5 * abs(op.torque_nm) / rig.gears.driven.base_radius_m
    else:
        fr = float(op.radial_load_n)
    return max(5.0 * fr / rig.bearings[bearing_index].n_balls, 10.0)


def _grid(rig, mesh_table):
    if not rig.has_gears:
        return np.zeros(0), np.zeros(2)
    if mesh_table is not None:
        s = np.asarray(mesh_table.position_m, dtype=float)
    else:
        lo, hi = table_range_m(rig.gears)
        s = np.linspace(lo, hi, DEFAULT_GRID_POINTS)
    return s, np.array([s[0], s[1] - s[0]])


def _coverage(s, lo, hi):
    """Fraction of each grid cell [s − ds/2, s + ds/2] inside [lo, hi] (smooth band edges)."""
    ds = s[1] - s[0]
    a = np.clip(np.minimum(s + 0.5 * ds, hi) - np.maximum(s - 0.5 * ds, lo), 0.0, None)
    return a / ds


def _line_range(pair, gear_no, lam_lo, lam_hi):
    """Positions on the line of action of the roll-length band [λ_lo, λ_hi] of a tooth, m."""
    if gear_no == 1:
        return lam_lo, lam_hi
    L = _path_length(pair)
    return L - lam_hi, L - lam_lo


def compile_faults(rig, faults, mesh_table=None, *, op=None):
    """Arrays of all ``faults`` on ``rig`` for the kernel (:class:`FaultArrays`).

    Parameters
    ----------
    rig : Rig
        The rig the faults are checked on (:func:`check_faults`); the arrays do not depend
        on the clearances that wear changes.
    faults : iterable of Fault
        Any catalogue entries; those that are not kernel arrays (wear, slip, speed and torque
        modulations) are ignored here (see :func:`rig_with_faults`, :func:`slip_from_faults`,
        :func:`operating_modulation`).
    mesh_table : MeshStiffnessTable or None
        The run's mesh table (gives the grid of the tooth tables); ``None`` on a gearless rig
        or for the on-line (hybrid, model A) mesh: then a grid over the potential-contact zone
        is used and returned in ``tooth_grid_m``.
    op : OperatingPoint, optional
        Gives the radial-load direction (default load zone of outer-race defects on a bearing
        rig); without it the load is taken downwards (−y).

    Returns
    -------
    FaultArrays

    Raises
    ------
    ParameterError
        A fault that does not fit the rig (unknown bearing or gear, a defect larger than
        allowed, a crack deeper than the tooth).
    """
    faults = check_faults(rig, faults)
    nb = len(rig.bearings)
    max_balls = max(b.n_balls for b in rig.bearings)
    rows = []
    ball_offset = np.zeros((nb, max_balls))
    s, grid = _grid(rig, mesh_table)
    if rig.has_gears:
        z1, z2 = rig.gears.driving.n_teeth, rig.gears.driven.n_teeth
        fac = {1: np.ones((z1, s.size)), 2: np.ones((z2, s.size))}
        sep = {1: np.zeros((z1, s.size)), 2: np.zeros((z2, s.size))}
    else:
        fac = {1: np.ones((0, 0)), 2: np.ones((0, 0))}
        sep = {1: np.zeros((0, 0)), 2: np.zeros((0, 0))}
    ecc = np.zeros((2, 3))
    pair = rig.gears

    for f in faults:
        if isinstance(f, (OuterRaceDefect, InnerRaceDefect)):
            ib = check_bearing(rig, f.bearing)
            default = _load_zone_angle(rig, ib, op) if isinstance(f, OuterRaceDefect) else 0.0
            rows.append(f._row(rig, default))          # checked above
        elif isinstance(f, BallDefect):
            rows.append(f._row(rig, _ball_load_n(rig, check_bearing(rig, f.bearing), op)))
        elif isinstance(f, OffSizeBall):
            ball_offset[check_bearing(rig, f.bearing), f.ball] += f.diameter_excess_m
        elif isinstance(f, Eccentricity):
            g = pair.driving if f.gear == 1 else pair.driven
            ecc[f.gear - 1] = (f.amplitude_m, f.phase_rad, f.mass_share * g.mass_kg)
        elif isinstance(f, ToothCrack):
            fac[f.gear][f.tooth] *= crack_stiffness_factor(pair, f.gear, f.depth_m,
                                                           f.angle_rad, s, method=f.method)
        elif isinstance(f, ToothSpall):
            g = pair.driving if f.gear == 1 else pair.driven
            a_lo, a_hi = f.arc_range_m(g)
            lam = [math.sqrt(2.0 * g.base_radius_m * max(a, 0.0)) for a in (a_lo, a_hi)]
            cov = _coverage(s, *_line_range(pair, f.gear, lam[0], lam[1]))
            if f.face_fraction >= 1.0:
                sep[f.gear][f.tooth] += f.depth_m * cov
            else:
                fac[f.gear][f.tooth] *= 1.0 - f.face_fraction * cov
        elif isinstance(f, ToothBreakage):
            g = pair.driving if f.gear == 1 else pair.driven
            lam = roll_length_m(g, g.tip_radius_m - f.lost_height_m)
            big = 10.0 * (s[-1] - s[0]) + 1.0
            cov = _coverage(s, *_line_range(pair, f.gear, lam, big))
            sep[f.gear][f.tooth] += BREAKAGE_SEPARATION_M * cov
        elif isinstance(f, ProfileError):
            g = pair.driving if f.gear == 1 else pair.driven
            e = np.full(s.size, f.wear_depth_m)
            if f.tip_relief_m > 0:
                lam_s = roll_length_m(g, f.relief_start_radius_m(g))
                lam_t = roll_length_m(g, ToothProfile.from_gear(g, n_points=64)
                                      .tip_round_start_radius_m)
                lam = s if f.gear == 1 else _path_length(pair) - s
                e += f.tip_relief_m * np.clip((lam - lam_s) / (lam_t - lam_s), 0.0, 1.0)
            sep[f.gear] += e[None, :]
    defects = np.array(rows, dtype=float).reshape(-1, len(DEFECT_COLUMNS))
    return FaultArrays(bearing_defects=defects, ball_offset_m=ball_offset,
                       tooth_factor1=fac[1], tooth_factor2=fac[2], tooth_sep1=sep[1],
                       tooth_sep2=sep[2], eccentricity=ecc, tooth_grid_m=grid)


def rig_with_faults(rig, faults):
    """``rig`` with the faults that are plain rig changes applied (bearing ``wear``).

    Returns
    -------
    Rig
        A new rig (the same object when no such fault is present).
    """
    faults = check_faults(rig, faults)
    growth = {}
    for f in faults:
        if isinstance(f, BearingWear):
            ib = check_bearing(rig, f.bearing)
            growth[ib] = growth.get(ib, 0.0) + f.clearance_growth_m
    if not growth:
        return rig
    shafts, ib = [], 0
    for sh in rig.shafts:
        new = {}
        for slot, brg in (("bearing_1", sh.bearing_1), ("bearing_2", sh.bearing_2)):
            if ib in growth:
                new[slot] = replace(brg, clearance_m=brg.clearance_m + growth[ib])
            ib += 1
        shafts.append(replace(sh, **new) if new else sh)
    return replace(rig, shafts=tuple(shafts))


def slip_from_faults(faults):
    """The ``rolling_slip`` fault among ``faults`` (the run's slip), or ``None``.

    Returns
    -------
    RollingSlip or None
        ``None`` without a ``rolling_slip`` fault. Two of them are refused.
    """
    slips = [f for f in (faults or ()) if isinstance(f, RollingSlip)]
    if not slips:
        return None
    if len(slips) > 1:
        raise ParameterError("faults may hold at most one rolling_slip", param="rolling_slip")
    return slips[0]


def operating_modulation(faults, op=None, rig=None):
    """Relative speed and torque factors of the ``speed_fluctuation`` / ``torque_ripple`` faults.

    Parameters
    ----------
    faults : iterable of Fault
    op : OperatingPoint, optional
        Needed when a torque ripple is given as an order of a shaft rate.
    rig : Rig, optional
        Gives the output shaft rate (shaft 2) for orders of shaft 2.

    Returns
    -------
    (callable or None, callable or None)
        ``speed_factor(t)`` and ``torque_factor(t)``, vectorised over t (s), each
        1 + Σ ε_k sin(2π f_k t + φ_k) summed over all such faults; ``None`` when absent.
    """
    faults = tuple(faults or ())
    rates = None
    if op is not None:
        rates = {1: float(op.shaft_hz)}
        if rig is not None and rig.has_gears:
            rates[2] = rates[1] / rig.gears.ratio
    speed = [f for f in faults if isinstance(f, SpeedFluctuation)]
    torque = [f for f in faults if isinstance(f, TorqueRipple)]

    def make(items):
        if not items:
            return None
        lines = np.array([ln for f in items for ln in f.lines(rates)], dtype=float)
        total = float(lines[:, 1].sum())
        if total > MAX_TOTAL_RELATIVE_AMPLITUDE:
            raise ParameterError(f"relative_amplitude must sum to at most "
                                 f"{MAX_TOTAL_RELATIVE_AMPLITUDE:g} over all modulation faults, "
                                 f"got {total:g}",
                                 param="relative_amplitude")
        freq, amp, ph = (np.ascontiguousarray(lines[:, k]) for k in range(3))

        def factor(t):
            t = np.asarray(t, dtype=float)
            return 1.0 + np.sum(amp[:, None] * np.sin(2 * math.pi * freq[:, None]
                                                      * t.reshape(1, -1) + ph[:, None]),
                                axis=0).reshape(t.shape)
        factor.lines = lines
        return factor

    return make(speed), make(torque)


def fault_frequencies(rig, op, faults):
    """Answer key of a run: each fault's characteristic frequencies, Hz.

    Bearing defects use the faulty bearing's kinematics (:class:`~cmsim.frequencies.RigFrequencies`
    of the rig with the faults' clearance changes): outer race BPFO, inner race BPFI (and the
    shaft rate of its sidebands), ball 2×BSF (and FTF); gear faults the rate of the faulty
    gear's shaft and the GMF; modulations their lines.

    Returns
    -------
    dict
        ``{label: {"type": name, <key>_hz: value, ...}}`` in fault order (JSON-ready).
    """
    faults = check_faults(rig, faults)
    fr = rig_frequencies(rig_with_faults(rig, faults), op)
    rates = {1: fr.fr1_hz}
    if fr.fr2_hz is not None:
        rates[2] = fr.fr2_hz
    out = {}
    for f in faults:
        d = {"type": f.name}
        if hasattr(f, "bearing"):
            b = fr.bearing(f.bearing)
            d["shaft_hz"] = b.shaft_hz
            d["ftf_hz"] = b.ftf_hz
            if isinstance(f, OuterRaceDefect):
                d["bpfo_hz"] = b.bpfo_hz
            elif isinstance(f, InnerRaceDefect):
                d["bpfi_hz"] = b.bpfi_hz
            elif isinstance(f, BallDefect):
                d["bsf_hz"] = b.bsf_hz
                d["two_bsf_hz"] = 2.0 * b.bsf_hz
            else:
                d["bpf_hz"] = b.bpf_hz
        elif hasattr(f, "gear"):
            d["shaft_hz"] = rates[f.gear]
            d["gmf_hz"] = fr.gmf_hz
        elif isinstance(f, RollingSlip):
            d.update({f"{n}_ftf_hz": fr.bearing(n).ftf_hz for n in fr.bearing_names})
        elif isinstance(f, (SpeedFluctuation, TorqueRipple)):
            d["lines_hz"] = [ln[0] for ln in f.lines({k: v for k, v in rates.items()})]
        key, n = f.label, 2
        while key in out:
            key, n = f"{f.label} #{n}", n + 1
        out[key] = d
    return out
