"""Pair stiffness tables at several torques on one position grid (paper 001 §6.1).

A :class:`MeshTableSet` holds one :class:`~cmsim.mesh_stiffness.table.MeshStiffnessTable` per
torque on a common position grid, with the per-torque summary (mean and peak-to-peak mesh
stiffness, loaded contact ratio, centroids), and gives the table at any torque in its range
by linear interpolation in torque (:meth:`MeshTableSet.at`). The builder of hybrid sets,
which needs the whole rig's quasi-static orbits, is
:func:`cmsim.dynamics.torque_tables.torque_tables`.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016 (paper 001), §6.1, Figs. 3-4.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace

import numpy as np

from cmsim._io import atomic_savez
from cmsim.errors import ParameterError, check_range
from cmsim.mesh_stiffness.table import MeshStiffnessTable

__all__ = ["MeshTableSet"]

#: Table meta entries interpolated linearly in torque by :meth:`MeshTableSet.at`.
_INTERPOLATED_META = ("loaded_range_m", "mean_mesh_stiffness_n_per_m", "loaded_contact_ratio")


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
        Provenance (method, rig name, settings, parameter hash).
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
        (the stiffness is not extrapolated). The loaded contact range and the loaded mean
        mesh stiffness recorded in the tables' meta are interpolated the same way.

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
        i = int(np.searchsorted(torques, q, side="right")) - 1
        a, b = self.tables[i], self.tables[i + 1]
        if q == torques[i]:
            return a
        w = (q - torques[i]) / (torques[i + 1] - torques[i])
        meta = {"interpolated_between_nm": [float(torques[i]), float(torques[i + 1])]}
        for key in _INTERPOLATED_META:
            if key in a.meta and key in b.meta:
                va, vb = np.asarray(a.meta[key], float), np.asarray(b.meta[key], float)
                meta[key] = ((1 - w) * va + w * vb).tolist()
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
