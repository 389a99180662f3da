"""Mesh stiffness tables for a grid of torques (paper 001 §6.1, models B and C).

The hybrid contact model makes the pair stiffness depend on the load (Hertzian local
deflection, load sharing, actual contact ratio) and on where the gear centres sit. Paper 001
builds its tables in three steps, which :func:`torque_tables` follows for each torque:

1. a quasi-static analysis of the whole rig, with the on-line hybrid contact (model A), at
   instants spread over one bearing cycle (one ball pass): the orbits of the gear centres;
2. the centroids of those orbits;
3. a quasi-static sweep of one mesh cycle with the gear centres fixed at the centroids
   (:func:`~cmsim.mesh_stiffness.quasi_static.mesh_cycle`), giving the secant stiffness of
   each pair vs its position on the line of action.

A :class:`MeshTableSet` holds one :class:`~cmsim.mesh_stiffness.table.MeshStiffnessTable` per
torque on a common position grid, with the per-torque summary (mean and peak-to-peak mesh
stiffness, loaded contact ratio, centroids), and gives the table at any torque in its range
by linear interpolation in torque (:meth:`MeshTableSet.at`).

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016 (paper 001), §6.1, Figs. 3-4.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field, replace

import numpy as np

from cmsim._io import atomic_savez
from cmsim.errors import ParameterError, check_range
from cmsim.mesh_stiffness.table import MeshStiffnessTable

__all__ = ["MeshTableSet", "torque_tables", "TABLE_METHODS"]

#: Methods :func:`torque_tables` can use.
TABLE_METHODS = ("hybrid", "potential-energy")


@dataclass(frozen=True)
class MeshTableSet:
    """Pair stiffness tables at several torques, on one position grid.

    Attributes
    ----------
    tables : tuple of MeshStiffnessTable
        One per torque, in increasing torque (``table.torque_nm`` set, output torque in N·m).
    summary : tuple of dict
        Per torque: ``torque_nm``, ``mean_stiffness_n_per_m``,
        ``peak_to_peak_stiffness_n_per_m``, ``loaded_contact_ratio`` and method-specific
        entries (centroids, loaded transmission error, seconds).
    meta : dict
        Provenance (method, rig name, settings).
    """

    tables: tuple
    summary: tuple = ()
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        tables = tuple(self.tables)
        if not tables or not all(isinstance(t, MeshStiffnessTable) for t in tables):
            raise ParameterError("tables must be a non-empty sequence of MeshStiffnessTable")
        torques = [t.torque_nm for t in tables]
        if any(q is None for q in torques):
            raise ParameterError("every table of a MeshTableSet needs its torque_nm")
        if any(b <= a for a, b in zip(torques, torques[1:])):
            raise ParameterError(f"table torques must be strictly increasing, got {torques}")
        grid = tables[0].position_m
        for t in tables[1:]:
            if t.position_m.shape != grid.shape or not np.allclose(t.position_m, grid,
                                                                  rtol=0, atol=1e-12):
                raise ParameterError("all tables of a MeshTableSet must share one position grid")
        object.__setattr__(self, "tables", tables)
        object.__setattr__(self, "summary", tuple(self.summary))

    @property
    def torques_nm(self):
        """Torques of the tables, N·m, shape (m,)."""
        return np.array([t.torque_nm for t in self.tables])

    @property
    def method(self):
        """Method that filled the tables."""
        return self.tables[0].method

    def at(self, torque_nm):
        """Table at ``torque_nm``, linear in torque between the two neighbouring tables.

        Exact at a table torque; outside the range of the set the nearest table is returned
        (the stiffness is not extrapolated).

        Returns
        -------
        MeshStiffnessTable
        """
        q = check_range("torque_nm", torque_nm, 0.0, 1e6, unit="N m")
        torques = self.torques_nm
        if q <= torques[0] or len(self.tables) == 1:
            return self.tables[0]
        if q >= torques[-1]:
            return self.tables[-1]
        i = int(np.searchsorted(torques, q)) - 1
        a, b = self.tables[i], self.tables[i + 1]
        if q == torques[i]:
            return a
        w = (q - torques[i]) / (torques[i + 1] - torques[i])
        meta = {"interpolated_between_nm": [float(torques[i]), float(torques[i + 1])]}
        return MeshStiffnessTable(a.position_m,
                                  (1 - w) * a.stiffness_n_per_m + w * b.stiffness_n_per_m,
                                  (1 - w) * a.separation_m + w * b.separation_m,
                                  a.base_radius_m, a.method, torque_nm=q, meta=meta)

    # ------------------------------------------------------------------ I/O
    def save(self, path):
        """Write the set as one ``.npz`` (atomically)."""
        atomic_savez(path, torques_nm=self.torques_nm, position_m=self.tables[0].position_m,
                     stiffness_n_per_m=np.array([t.stiffness_n_per_m for t in self.tables]),
                     separation_m=np.array([t.separation_m for t in self.tables]),
                     meta=json.dumps({"kind": "mesh-table-set", "method": self.method,
                                      "base_radius_m": self.tables[0].base_radius_m,
                                      "table_meta": [t.meta for t in self.tables],
                                      "summary": list(self.summary), "meta": self.meta}))

    @classmethod
    def load(cls, path):
        """Read a set written by :meth:`save`, or a single table file as a set of one.

        A single table without a torque (a load-independent method) is given torque 0.
        """
        with np.load(path) as z:
            info = json.loads(str(z["meta"]))
            if info.get("kind") != "mesh-table-set":
                t = MeshStiffnessTable.load(path)
                return cls((replace(t, torque_nm=t.torque_nm or 0.0),),
                           meta={"source_file": str(path)})
            tables = tuple(MeshStiffnessTable(z["position_m"], k, e, info["base_radius_m"],
                                              info["method"], float(q), m)
                           for q, k, e, m in zip(z["torques_nm"], z["stiffness_n_per_m"],
                                                 z["separation_m"], info["table_meta"]))
        return cls(tables, tuple(info["summary"]), info["meta"])


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
    from cmsim.mesh_stiffness.quasi_static import mesh_cycle

    if rig.gears is None:
        raise ParameterError("torque_tables needs a rig with gears")
    if method not in TABLE_METHODS:
        raise ParameterError(f"method must be one of {TABLE_METHODS}, got {method!r}")
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
        from cmsim.dynamics.model import default_mesh_table
        base = default_mesh_table(pair)
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
        from cmsim.mesh_stiffness.hybrid import HybridMeshModel
        mesh_model = HybridMeshModel.from_pair(pair)
    ratio = pair.driving.n_teeth / pair.driven.n_teeth
    for q in torques:
        start = time.perf_counter()
        c1 = c2 = (0.0, 0.0)
        spread = None
        if centres == "centroid":
            c1, c2, spread = _orbit_centroids(rig, q, speed_rpm, mesh_model, n_orbit)
        cycle = mesh_cycle(mesh_model, q * ratio, c1, c2, n_steps=n_steps, n_points=n_points)
        k_mesh = cycle.mesh_stiffness_n_per_m
        tables.append(replace(cycle.table, torque_nm=q))     # labelled by output torque
        summary.append({
            "torque_nm": q, "driving_torque_nm": q * ratio,
            "mean_stiffness_n_per_m": float(np.mean(k_mesh)),
            "peak_to_peak_stiffness_n_per_m": float(np.ptp(k_mesh)),
            "loaded_contact_ratio": cycle.loaded_contact_ratio,
            "mean_lte_um": float(np.mean(cycle.lte_m) * 1e6),
            "peak_to_peak_lte_um": float(np.ptp(cycle.lte_m) * 1e6),
            "centre1_um": [1e6 * c1[0], 1e6 * c1[1]], "centre2_um": [1e6 * c2[0], 1e6 * c2[1]],
            "orbit_radius_um": spread, "seconds": time.perf_counter() - start})
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
    from cmsim.dynamics.model import build_model
    from cmsim.dynamics.quasistatic import quasi_static_orbit
    from cmsim.rig import OperatingPoint
    from cmsim.spectra.frequencies import rig_frequencies

    op = OperatingPoint(speed_rpm, torque_nm)
    model = build_model(rig, op, mesh_model=mesh_model)
    bpf = rig_frequencies(rig, op)[rig.bearing_names[0]]["bpf_hz"]
    # instants over one ball pass; the mesh phase then sweeps several mesh cycles
    times = np.arange(n_orbit) / (n_orbit * bpf)
    orbit = quasi_static_orbit(model, times)
    out, radius = [], 0.0
    for node in ("1G1", "2G1"):
        ix = model.index(f"x_{node}")
        pts = orbit[:, ix:ix + 2]
        c = pts.mean(axis=0)
        radius = max(radius, float(np.max(np.hypot(*(pts - c).T))) * 1e6)
        out.append((float(c[0]), float(c[1])))
    return out[0], out[1], radius

