"""Per-pair mesh stiffness tables: the interface between stiffness methods and the dynamics.

A :class:`MeshStiffnessTable` gives, for one tooth pair, the contact stiffness k (N/m) and the
unloaded profile separation e (m; profile modifications and deviations, 0 for perfect
involutes) as functions of where that pair is in its engagement, so the dynamics computes the
normal force as ``F = k(s)·max(δ − e(s), 0)`` with δ the rigid-body interference.

The abscissa is the position ``s`` of the pair on the line of action, measured from the tangent
point T1 on the driving gear's base circle; equivalently the driving-gear angle
``s / r_b1`` turned since the pair's contact passed T1 (:attr:`driving_angle_rad`).

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016, §6.1 (tables per torque, models B and C).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from cmsim._io import atomic_savez
from cmsim.errors import ParameterError, check_choice
from cmsim.mesh_stiffness.contact import active_path_m, table_range_m
from cmsim.mesh_stiffness.potential_energy import pair_stiffness_potential_energy

__all__ = ["MeshStiffnessTable", "MESH_METHODS"]

#: Methods that can fill a table.
MESH_METHODS = ("potential-energy", "hybrid", "constant")


@dataclass(frozen=True)
class MeshStiffnessTable:
    """Single-pair mesh stiffness vs position along the line of action.

    Attributes
    ----------
    position_m : ndarray, shape (n,)
        Uniform grid of positions s from T1, m.
    stiffness_n_per_m : ndarray, shape (n,)
        Pair stiffness k(s), N/m (values outside the grid are held constant).
    separation_m : ndarray, shape (n,)
        Unloaded profile separation e(s), m.
    base_radius_m : float
        Base radius of the driving gear (converts positions to driving-gear angles), m.
    method : str
        One of :data:`MESH_METHODS`.
    torque_nm : float or None
        Torque at which the table was computed (``None``: load-independent method).
    meta : dict
        Free-form provenance (geometry hash, rig name, ...).
    """

    position_m: np.ndarray
    stiffness_n_per_m: np.ndarray
    separation_m: np.ndarray
    base_radius_m: float
    method: str
    torque_nm: float | None = None
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        s = np.ascontiguousarray(self.position_m, dtype=float)
        k = np.ascontiguousarray(self.stiffness_n_per_m, dtype=float)
        e = np.ascontiguousarray(self.separation_m, dtype=float)
        if s.ndim != 1 or s.size < 2 or k.shape != s.shape or e.shape != s.shape:
            raise ParameterError("position_m, stiffness_n_per_m and separation_m must be 1-D "
                                 "arrays of the same length >= 2")
        ds = np.diff(s)
        if not np.all(ds > 0) or np.ptp(ds) > 1e-9 * abs(ds[0]) + 1e-15:
            raise ParameterError("position_m must be a uniform increasing grid")
        if not (np.all(np.isfinite(k)) and np.all(k >= 0)):
            raise ParameterError("stiffness_n_per_m must be finite and >= 0")
        if not np.all(np.isfinite(e)):
            raise ParameterError("separation_m must be finite")
        check_choice("method", self.method, MESH_METHODS)
        for name, arr in (("position_m", s), ("stiffness_n_per_m", k), ("separation_m", e)):
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    # ------------------------------------------------------------------ views
    @property
    def driving_angle_rad(self):
        """Driving-gear angle since the pair's contact passed T1, rad (shape (n,))."""
        return self.position_m / self.base_radius_m

    @property
    def spacing_m(self):
        """Grid spacing, m."""
        return float(self.position_m[1] - self.position_m[0])

    def stiffness_at(self, position_m):
        """k(s) by linear interpolation, held constant outside the grid, N/m."""
        return np.interp(position_m, self.position_m, self.stiffness_n_per_m)

    def separation_at(self, position_m):
        """e(s) by linear interpolation, held constant outside the grid, m."""
        return np.interp(position_m, self.position_m, self.separation_m)

    def contact_range_m(self, pair):
        """Positions on the line of action where a pair of this table carries load, m.

        The loaded range of the quasi-static mesh cycle that built the table
        (``meta["loaded_range_m"]``: hybrid tables, which extend beyond the nominal involute
        path as the teeth deflect under load), else the nominal involute path
        [s_start, s_end] (:func:`cmsim.mesh_stiffness.contact.active_path_m`).

        Returns
        -------
        (float, float)
        """
        loaded = self.meta.get("loaded_range_m")
        if loaded is not None:
            return float(loaded[0]), float(loaded[1])
        s0, s1 = active_path_m(pair)
        return float(s0), float(s1)

    def mesh_stiffness(self, pair, n_points=400):
        """Total mesh stiffness over one mesh cycle.

        Sums k over the pairs whose position lies in :meth:`contact_range_m` (for hybrid
        tables the range loaded at the table's torque, so the mean equals the loaded mesh
        stiffness of the mesh cycle that built the table; for load-independent tables the
        nominal involute path).

        Returns
        -------
        position_m : ndarray, shape (n_points,)
            Position of the leading pair over one base pitch, m.
        stiffness_n_per_m : ndarray, shape (n_points,)
            Sum of the pair stiffnesses in contact, N/m.
        pairs_in_contact : ndarray of int, shape (n_points,)
            (Read-only arrays, computed once per table, pair and ``n_points``: a table is a
            value, and a run asks for its mesh stiffness four times.)
        """
        memo = self.__dict__.setdefault("_mesh_stiffness", {})
        key = (pair, int(n_points))
        if key not in memo:
            memo[key] = tuple(_read_only(a) for a in self._mesh_cycle(pair, n_points))
        return memo[key]

    def _mesh_cycle(self, pair, n_points):
        """The sums of :meth:`mesh_stiffness`."""
        s0, s1 = self.contact_range_m(pair)
        pb = pair.driving.base_pitch_m
        s = s0 + pb * np.arange(n_points) / n_points
        total = np.zeros(n_points)
        count = np.zeros(n_points, dtype=int)
        # a pair touches where its unloaded separation is the smallest along the path (a
        # uniform offset, e.g. backlash, moves every pair alike and separates none of them)
        inside = (self.position_m >= s0) & (self.position_m <= s1)
        touch = max(0.0, float(np.min(self.separation_m[inside]))) if inside.any() else 0.0
        for j in range(int(math.ceil((s1 - s0) / pb)) + 1):
            sj = s + j * pb
            on = (sj >= s0) & (sj <= s1) & (self.separation_at(sj) <= touch)
            total += np.where(on, self.stiffness_at(sj), 0.0)
            count += on
        return s, total, count

    def mean_mesh_stiffness(self, pair):
        """Mean of the total mesh stiffness over a mesh cycle, N/m."""
        return float(np.mean(self.mesh_stiffness(pair)[1]))

    # ------------------------------------------------------------------ constructors
    @classmethod
    def constant(cls, pair, stiffness_n_per_m, n_points=64):
        """Load-independent table with the same stiffness everywhere (closed-form tests)."""
        lo, hi = table_range_m(pair)
        s = np.linspace(lo, hi, n_points)
        return cls(s, np.full(n_points, float(stiffness_n_per_m)), np.zeros(n_points),
                   pair.driving.base_radius_m, "constant")

    @classmethod
    def potential_energy(cls, pair, n_points=257):
        """Table from the potential-energy method of paper 004 (eqs. 5-13).

        The stiffness over the involute path is extended as a constant (its end values)
        into the tip-rounding (corner contact) zones on both sides.
        """
        lo, hi = table_range_m(pair)
        s = np.linspace(lo, hi, n_points)
        s0, s1 = active_path_m(pair)
        k = pair_stiffness_potential_energy(pair, np.clip(s, s0, s1))
        return cls(s, k, np.zeros(n_points), pair.driving.base_radius_m, "potential-energy",
                   meta={"source": "paper 004 eqs. 5-13 (Yang-Lin + Sainsot + Hertz)"})

    # ------------------------------------------------------------------ I/O
    def save(self, path):
        """Write the table as ``.npz`` (atomically)."""
        atomic_savez(path, position_m=self.position_m, stiffness_n_per_m=self.stiffness_n_per_m,
                     separation_m=self.separation_m,
                     meta=json.dumps({"base_radius_m": self.base_radius_m, "method": self.method,
                                      "torque_nm": self.torque_nm, "meta": self.meta}))

    @classmethod
    def load(cls, path):
        """Read a table written by :meth:`save`."""
        with np.load(path) as z:
            info = json.loads(str(z["meta"]))
            return cls(z["position_m"], z["stiffness_n_per_m"], z["separation_m"],
                       info["base_radius_m"], info["method"], info["torque_nm"], info["meta"])


def _read_only(a):
    a.setflags(write=False)
    return a
