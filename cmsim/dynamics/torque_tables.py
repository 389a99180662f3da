"""Mesh stiffness tables for a grid of torques (paper 001 §6.1, models B and C).

The hybrid contact model makes the pair stiffness depend on the load (Hertzian local
deflection, load sharing, actual contact ratio) and on where the gear centres sit. Paper 001
builds its tables in three steps, which :func:`torque_tables` follows for each torque:

1. a quasi-static analysis of the whole rig, with the on-line hybrid contact (model A), at
   instants spread over one bearing cycle (one ball pass): the orbits of the gear centres;
2. the centroids of those orbits;
3. a quasi-static sweep of one mesh cycle with the gear centres fixed at the centroids
   (:func:`~cmsim.mesh_stiffness.mesh_cycle.mesh_cycle`), giving the secant stiffness of
   each pair vs its position on the line of action.

The result is a :class:`~cmsim.mesh_stiffness.table_set.MeshTableSet` (the data container
lives in :mod:`cmsim.mesh_stiffness`; this builder sits in :mod:`cmsim.dynamics` because
step 1 needs the whole rig's model). Each table's meta records the loaded mean mesh
stiffness and the loaded contact range of its mesh cycle.

Step 1 is a few quasi-static solves: a table costs about 0.1 s per torque once the FE
influence tables of the gears exist (built once per gear design, about 8 s, then cached).

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016 (paper 001), §6.1, Figs. 3-4.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from cmsim.bearings.kinematics import ball_pass_cycles_per_rev
from cmsim.dynamics.model import build_model
from cmsim.dynamics.quasistatic import quasi_static_orbit, quasi_static_state
from cmsim.errors import IntegrationDiverged, ParameterError, check_choice, check_range
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.mesh_stiffness.mesh_cycle import MAX_CENTRE_OFFSET_M, hybrid_mesh_table, mesh_cycle
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.mesh_stiffness.table_set import MeshTableSet
from cmsim.rig import OperatingPoint

__all__ = ["torque_tables", "TABLE_METHODS"]

#: Methods :func:`torque_tables` can use.
TABLE_METHODS = ("hybrid", "potential-energy")


def _check_centres_carry(torque_nm, centre1_m, centre2_m):
    """Refuse a torque that pushes a gear centre beyond :data:`MAX_CENTRE_OFFSET_M` (the
    contact geometry's limit), naming the torque (``torques_nm``), not the centres."""
    offset = float(np.max(np.abs(np.concatenate([centre1_m, centre2_m]))))
    if offset > MAX_CENTRE_OFFSET_M:
        most = torque_nm * MAX_CENTRE_OFFSET_M / offset        # the offsets grow with load
        raise ParameterError(
            f"torques_nm = {torque_nm:g} N m moves the gear centres {offset * 1e3:.3g} mm off "
            f"their nominal positions, and the tooth contact holds within "
            f"±{MAX_CENTRE_OFFSET_M * 1e3:g} mm: on this rig's shafts and bearings the torque "
            f"must be <= about {most:.3g} N m", param="torques_nm",
            allowed=f"<= about {most:.3g} N m")


def torque_tables(rig, torques_nm, method="hybrid", *, mesh_model=None, speed_rpm=1000.0,
                  n_orbit=24, n_steps=120, n_points=257, centres="centroid", progress=None):
    """Pair stiffness tables of ``rig`` for each output torque in ``torques_nm``.

    Parameters
    ----------
    rig : Rig
        A rig with gears.
    torques_nm : sequence of float
        Output torques, N·m (> 0, distinct).
    method : {'hybrid', 'potential-energy'}
        ``hybrid``: the three steps of the module docstring. ``potential-energy``: the
        load-independent table of paper 004 repeated for each torque (for comparison).
    mesh_model : HybridMeshModel, optional
        Influence tables of the rig's gears (default: from the cache, built once).
    speed_rpm : float
        Input speed of the quasi-static orbits (sets only the nominal sliding speeds).
    n_orbit : int
        Instants over the bearing cycle (>= 4).
    n_steps : int
        Driving-gear angles over one mesh cycle (>= 8).
    n_points : int
        Points of the table's position grid (>= 2).
    centres : {'centroid', 'nominal'}
        Gear centres of the mesh-cycle sweep: centroids of the quasi-static orbits (paper) or
        the nominal positions (skips step 1).
    progress : callable, optional
        Called as ``progress(i, n, summary_i)`` after each torque.

    Returns
    -------
    MeshTableSet
    """
    if rig.gears is None:
        raise ParameterError("torque_tables needs a rig with gears")
    check_choice("method", method, TABLE_METHODS)
    if centres not in ("centroid", "nominal"):
        raise ParameterError(f"centres must be 'centroid' or 'nominal', got {centres!r}")
    torques = sorted(check_range("torques_nm", q, 0.0, 1e6, lo_open=True, unit="N m")
                     for q in np.atleast_1d(np.asarray(torques_nm, dtype=float)))
    if not torques or len(set(torques)) != len(torques):
        raise ParameterError(f"torques_nm must be distinct positive values, got {torques_nm!r}")
    for name, value, least in (("n_orbit", n_orbit, 4), ("n_steps", n_steps, 8),
                               ("n_points", n_points, 2)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
            raise ParameterError(f"{name} must be an integer >= {least}, got {value!r}")
    pair = rig.gears
    tables, summary = [], []
    if method == "potential-energy":
        base = MeshStiffnessTable.potential_energy(pair)
        _, k_mesh, count = base.mesh_stiffness(pair)
        for q in torques:
            tables.append(replace(base, torque_nm=q))
            summary.append({"torque_nm": q, "mean_stiffness_n_per_m": float(np.mean(k_mesh)),
                            "peak_to_peak_stiffness_n_per_m": float(np.ptp(k_mesh)),
                            "loaded_contact_ratio": float(np.mean(count))})
            if progress is not None:
                progress(len(tables), len(torques), summary[-1])
        return MeshTableSet(tuple(tables), tuple(summary),
                            {"method": method, "rig": rig.name, "load_independent": True})

    if mesh_model is None:
        mesh_model = HybridMeshModel.from_pair(pair)
    ratio = pair.driving.n_teeth / pair.driven.n_teeth
    for q in torques:
        start = time.perf_counter()
        c1 = c2 = (0.0, 0.0)
        spread = None
        placed = centres
        if centres == "centroid":
            try:
                c1, c2, spread = _orbit_centroids(rig, q, speed_rpm, mesh_model, n_orbit)
            except IntegrationDiverged:
                # no quasi-static orbit (light load on a preloaded or loose rig): the centres
                # then sit within a bearing clearance of nominal, which moves the pair
                # stiffness by far less than the torque does
                placed = "nominal (orbit not found)"
        _check_centres_carry(q, c1, c2)
        cycle = mesh_cycle(mesh_model, q * ratio, c1, c2, n_steps=n_steps, n_points=n_points)
        k_mesh = cycle.mesh_stiffness_n_per_m
        meta = dict(cycle.table.meta, mean_mesh_stiffness_n_per_m=float(np.mean(k_mesh)))
        tables.append(replace(cycle.table, torque_nm=q, meta=meta))  # by output torque
        summary.append({
            "torque_nm": q, "driving_torque_nm": q * ratio,
            "mean_stiffness_n_per_m": float(np.mean(k_mesh)),
            "peak_to_peak_stiffness_n_per_m": float(np.ptp(k_mesh)),
            "loaded_contact_ratio": cycle.loaded_contact_ratio,
            "mean_lte_um": float(np.mean(cycle.lte_m) * 1e6),
            "peak_to_peak_lte_um": float(np.ptp(cycle.lte_m) * 1e6),
            "centre1_um": [1e6 * c1[0], 1e6 * c1[1]], "centre2_um": [1e6 * c2[0], 1e6 * c2[1]],
            "orbit_radius_um": spread, "centres": placed,
            "seconds": time.perf_counter() - start})
        if progress is not None:
            progress(len(tables), len(torques), summary[-1])
    meta = {"method": method, "rig": rig.name, "speed_rpm": float(speed_rpm),
            "centres": centres, "n_orbit": int(n_orbit), "n_steps": int(n_steps),
            "influence_key_driving": mesh_model.driving.meta.get("key"),
            "influence_key_driven": mesh_model.driven.meta.get("key")}
    return MeshTableSet(tuple(tables), tuple(summary), meta)


def _orbit_centroids(rig, torque_nm, speed_rpm, mesh_model, n_orbit):
    """Centroids of the gear-centre orbits over one bearing cycle (quasi-static, model A).

    Returns ``(centre1, centre2, radius_um)``: offsets from nominal (m) in the mesh frame
    and the largest distance of an orbit point from its centroid, µm.
    """
    op = OperatingPoint(speed_rpm, torque_nm)
    model = build_model(rig, op, (hybrid_mesh_table(mesh_model, torque_nm), mesh_model))
    bpf = op.omega_rad_s * ball_pass_cycles_per_rev(rig.bearings[0]) / (2.0 * math.pi)
    # instants over one ball pass; the mesh phase then sweeps several mesh cycles
    times = np.arange(n_orbit) / (n_orbit * bpf)
    try:
        orbit = quasi_static_orbit(model, times)
    except IntegrationDiverged:
        orbit = _guided_orbit(rig, op, model, times)
    out, radius = [], 0.0
    for node in ("1G1", "2G1"):
        ix = model.index(f"x_{node}")
        pts = orbit[:, ix:ix + 2]
        c = pts.mean(axis=0)
        radius = max(radius, float(np.max(np.hypot(*(pts - c).T))) * 1e6)
        out.append((float(c[0]), float(c[1])))
    return out[0], out[1], radius



def _guided_orbit(rig, op, model, times):
    """Quasi-static orbit of the on-line hybrid ``model``, each instant started from the table model.

    The non-smooth on-line contact can stall from the linear start guess at light loads
    (below about 10 N·m on the paper's rig, where the bearings barely close their clearance)
    or at an instant where a pair enters contact; the same rig with the model's own hybrid
    table at this torque is a smooth problem whose equilibrium is a close start. An
    equilibrium within a relative force residual of 1e-3 is accepted here (it places the
    centroid to far below a micrometre), and an instant that still fails is left out of the
    centroid; at least half of them must succeed.
    """
    guide = build_model(rig, op, (model.mesh_table, None))
    orbit = []
    g = None
    for t in times:
        try:
            g = quasi_static_state(guide, t, q_guess=g, tol=1e-6)
            orbit.append(quasi_static_state(model, t, q_guess=g, tol=1e-6))
        except IntegrationDiverged:
            continue
    if 2 * len(orbit) < len(times):
        raise IntegrationDiverged(f"quasi-static orbit of the on-line hybrid model failed at "
                                  f"{len(times) - len(orbit)} of {len(times)} instants "
                                  f"(torque_nm = {op.torque_nm:g})")
    return np.array(orbit)
