"""Which tooth-contact model a run uses: the paper's model B by default.

:func:`resolve_mesh` turns the ``mesh`` argument of :func:`cmsim.dynamics.simulate` and
:func:`cmsim.dynamics.modal.modal_analysis`, and the ``--mesh`` / ``--mesh-table`` options of
the ``cmsim`` command, into the pair the model is built with
(:func:`cmsim.dynamics.model.build_model`): the pair stiffness table the dynamics uses and,
for the on-line contact (model A), the hybrid contact model:

``None`` or ``"hybrid-tables"`` (default)
    Paper 001 §6.1 model B: the rig's hybrid FE + Weber–Banaschek tables
    (:func:`~cmsim.dynamics.torque_tables.torque_tables`) on the torque grid
    :data:`TORQUE_GRID_NM`, linear in torque at the run's torque
    (:meth:`~cmsim.mesh_stiffness.table_set.MeshTableSet.at`). Below the grid's first torque
    (5 N·m) the 5 N·m table is used (no extrapolation, also at 0 N·m); above its last (200 N·m)
    a table is built at the run's torque on demand and cached.
``"potential-energy"``
    The load-independent table of paper 004 (mean mesh stiffness 1.305e8 N/m on the paper's
    rig at every torque).
``"hybrid"``
    Model A: contact forces solved on-line from the FE influence coefficients; the returned
    table (one quasi-static mesh cycle at the run's torque) sets the mesh damping and the
    quasi-static start.
a :class:`~cmsim.mesh_stiffness.table.MeshStiffnessTable`
    Used as is (e.g. model C: a table at another torque).
a :class:`~cmsim.mesh_stiffness.table_set.MeshTableSet`
    The table at the run's torque.
a :class:`~cmsim.mesh_stiffness.hybrid.HybridMeshModel`
    Model A with this model.

Where the tables come from. The paper's rig (:meth:`cmsim.rig.Rig.paper_2016`) ships them as
package data (:data:`PAPER_TABLES_FILE`, rebuilt by ``python -m cmsim.dynamics.tooth_contact``),
so a fresh install runs without an FE build. The file stores the hash of the rig parameters
the tables depend on (:func:`tables_key`: gears, shafts with their bearings, couplings); a rig
whose set is shipped or cached (:func:`hybrid_table_set` builds and caches a whole set, e.g.
for ``cmsim mesh-table``) reads the table at the run's torque from it; any other rig — a
user's rig, or the paper's rig with another clearance — builds the one table its torque needs
(FE influence tables about 8 s once per gear design, then about 0.1-0.5 s per torque) and
caches it on disk in :func:`cmsim.mesh_stiffness.cache.cache_dir` (atomic writes), with a
progress bar on stderr; below 5 N·m the 5 N·m table is used.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016 (paper 001), §6.1 (models A, B, C).
"""

from __future__ import annotations

import functools
import sys
import threading
import warnings
from dataclasses import replace
from importlib import resources
from pathlib import Path

import numpy as np

from cmsim.dynamics import torque_tables as table_builder
from cmsim.errors import ModelWarning, ParameterError, check_range
from cmsim.mesh_stiffness import cache
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.mesh_stiffness.mesh_cycle import hybrid_mesh_table
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.mesh_stiffness.table_set import MeshTableSet
from cmsim.rig import Rig
from cmsim.rig.codec import to_plain

__all__ = ["resolve_mesh", "hybrid_table_set", "tables_key", "default_mesh_table",
           "build_paper_tables", "MESH_CHOICES", "TORQUE_GRID_NM", "PAPER_TABLES_FILE"]

#: Names accepted for ``mesh`` (the first is the default).
MESH_CHOICES = ("hybrid-tables", "potential-energy", "hybrid")

#: Output torques of the default table sets, N·m. Linear interpolation between neighbours is
#: within 0.25 % of a directly computed table's mean mesh stiffness on the paper's rig.
TORQUE_GRID_NM = (5.0, 7.5, 10.0, 12.5, 15.0, 20.0, 25.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0,
                  90.0, 100.0, 120.0, 140.0, 160.0, 180.0, 200.0)

#: Settings of :func:`~cmsim.dynamics.torque_tables.torque_tables` for the default sets.
BUILD_SETTINGS = {"method": "hybrid", "speed_rpm": 1000.0, "n_orbit": 24, "n_steps": 120,
                  "n_points": 257, "centres": "centroid"}

#: Bump when the tables' contents change for the same inputs (invalidates cached sets).
TABLES_VERSION = 1

#: Bump when the potential-energy table's contents change for the same gear pair.
PE_TABLE_VERSION = 1

#: Package data file with the paper rig's set (relative to the ``cmsim`` package).
PAPER_TABLES_FILE = "data/paper_2016_hybrid_tables.npz"

_SETS = {}
_ABOVE = {}
_PE_CACHE = {}
_PE_LOCK = threading.Lock()


@functools.lru_cache(maxsize=64)
def tables_key(rig):
    """Hash of every rig parameter the hybrid tables depend on (32 hex characters).

    Gears (every field of both gears, centre distance), shafts with their bearings, the
    couplings, the torque grid, the build settings and :data:`TABLES_VERSION`. The mesh
    friction is left out: it moves the orbit centroids so little that the tables change by
    at most 0.05 % of their peak (f = 0 vs 0.05 on the paper's rig at 10 and 100 N·m), while
    the bearing clearance moves them by up to 9-23 % of the peak near the ends of the loaded
    contact (5-30 µm vs 15 µm; the mean by 0.1-0.2 %) and stays in.

    Memoised per rig (a frozen value: an equal rig has the same key, any changed field makes
    another entry), as every record of a dataset asks for it.
    """
    d = rig.to_dict()
    inputs = {"gears": d.get("gears"), "shafts": d.get("shafts"),
              "input_coupling": d.get("input_coupling"),
              "output_coupling": d.get("output_coupling"),
              "grid_nm": list(TORQUE_GRID_NM), "settings": BUILD_SETTINGS,
              "version": TABLES_VERSION}
    return cache.cache_key("hybrid-tables", inputs)


def default_mesh_table(pair):
    """Potential-energy table of ``pair`` (paper 004), memoised per gear pair and cached on
    disk: its corner zones take 0.4 s to find, which every process simulating a machine's
    twin (:func:`cmsim.machine.twin_mesh`) paid, a comparison's refining run included. The
    warnings of its build (a formula used beyond its fit) are stored with it and said again
    once a process, as when it was built."""
    with _PE_LOCK:      # a healthy and a changed run may ask at once (two threads)
        return _potential_energy_table(pair)


def _potential_energy_table(pair):
    if pair not in _PE_CACHE:
        key = cache.cache_key("potential-energy", {"pair": to_plain(pair),
                                                   "version": PE_TABLE_VERSION})
        path = cache.cache_path("potential-energy", key)
        table = _load_table(path)
        if table is None:
            with warnings.catch_warnings(record=True) as said:
                warnings.simplefilter("always")
                table = MeshStiffnessTable.potential_energy(pair)
            kept = [w for w in said if w.category in (ModelWarning, UserWarning)]
            for w in said:
                if w not in kept:       # not the table's own: said now, not stored
                    warnings.warn(w.message, w.category, stacklevel=2)
            table = replace(table, meta={**table.meta, "warnings": [
                [w.category.__name__, str(w.message)] for w in kept]})
            table.save(path)
        for category, message in table.meta.get("warnings", ()):
            warnings.warn(message, ModelWarning if category == "ModelWarning" else UserWarning,
                          stacklevel=2)
        _PE_CACHE[pair] = table
    return _PE_CACHE[pair]


def _load_table(path):
    """The table cached at ``path``, or None (absent or unreadable: built again)."""
    if not path.is_file():
        return None
    try:
        return MeshStiffnessTable.load(path)
    except (OSError, ValueError, KeyError):
        return None


def _bar_progress(progress, n, what):
    """``(callback, close)``: the caller's callback, nothing (False) or a tqdm bar (None)."""
    if progress is False:
        return None, lambda: None
    if callable(progress):
        return progress, lambda: None
    from tqdm import tqdm
    bar = tqdm(total=n, desc=what, unit="torque", file=sys.stderr, leave=False)

    def step(i, total, row):
        bar.set_postfix_str(f"{row['torque_nm']:g} N m")
        bar.update(1)
    return step, bar.close


def _shipped_set(key):
    """The packaged set if its stored parameter hash is ``key``, else ``None``."""
    path = resources.files("cmsim").joinpath(PAPER_TABLES_FILE)
    if not path.is_file():
        return None
    with resources.as_file(path) as p:
        tables = MeshTableSet.load(p)
    return tables if tables.meta.get("parameter_key") == key else None


def _build_set(rig, key, progress):
    step, close = _bar_progress(progress, len(TORQUE_GRID_NM),
                                f"cmsim: mesh tables for {rig.name}")
    try:
        built = table_builder.torque_tables(
            rig, TORQUE_GRID_NM, mesh_model=HybridMeshModel.from_pair(rig.gears),
            progress=step, **{k: v for k, v in BUILD_SETTINGS.items() if k != "method"})
    finally:
        close()
    meta = dict(built.meta, parameter_key=key, torque_grid_nm=list(TORQUE_GRID_NM),
                below_grid="the first table (5 N m) is used below the grid",
                above_grid="a table at the run's torque is built on demand")
    return MeshTableSet(built.tables, built.summary, meta)


def hybrid_table_set(rig, *, progress=None):
    """The rig's hybrid table set on :data:`TORQUE_GRID_NM` (shipped, cached or built).

    Parameters
    ----------
    rig : Rig
        A rig with gears.
    progress : None, False or callable
        ``None``: a tqdm bar on stderr while building; ``False``: silent; a callable is called
        as ``progress(i, n, summary_i)`` after each torque.

    Returns
    -------
    MeshTableSet
    """
    if rig.gears is None:
        raise ParameterError("hybrid tables need a rig with gears")
    tables = _known_set(rig)
    if tables is None:
        key = tables_key(rig)
        tables = _build_set(rig, key, progress)
        tables.save(cache.cache_path("hybrid-tables", key))
        _SETS[key] = tables
    return tables


def _known_set(rig):
    """The rig's table set if it is shipped or already cached (memory or disk), else None."""
    key = tables_key(rig)
    if key in _SETS:
        return _SETS[key]
    tables = _shipped_set(key)
    if tables is None:
        path = cache.cache_path("hybrid-tables", key)
        if path.is_file():
            try:
                tables = MeshTableSet.load(path)
            except (OSError, ValueError, KeyError):
                tables = None
        if tables is not None and tables.meta.get("parameter_key") != key:
            tables = None
    if tables is not None:
        _SETS[key] = tables
    return tables


def _table_at(rig, torque_nm, progress):
    """Hybrid table at one torque, built once and cached on disk."""
    key = cache.cache_key("hybrid-table", {"set": tables_key(rig), "torque_nm": torque_nm})
    if key in _ABOVE:
        return _ABOVE[key]
    path = cache.cache_path("hybrid-table", key)
    table = _load_table(path)
    if table is None:
        step, close = _bar_progress(progress, 1, f"cmsim: mesh table at {torque_nm:g} N m")
        try:
            table = table_builder.torque_tables(
                rig, [torque_nm], mesh_model=HybridMeshModel.from_pair(rig.gears),
                progress=step,
                **{k: v for k, v in BUILD_SETTINGS.items() if k != "method"}).tables[0]
        finally:
            close()
        table.save(path)
    _ABOVE[key] = table
    return table


def resolve_mesh(rig, mesh, torque_nm, *, progress=None):
    """Pair stiffness table and on-line contact model for ``mesh`` at ``torque_nm``.

    Parameters
    ----------
    rig : Rig
    mesh : None, str, MeshStiffnessTable, MeshTableSet or HybridMeshModel
        See the module docstring; strings from :data:`MESH_CHOICES`.
    torque_nm : float
        Output torque of the run, N·m (>= 0).
    progress : None, False or callable
        Progress of a table build (see :func:`hybrid_table_set`).

    Returns
    -------
    (MeshStiffnessTable or None, HybridMeshModel or None)
        ``(None, None)`` for a rig without gears.

    Raises
    ------
    ParameterError
        For an unknown ``mesh``, or a mesh object for a rig without gears or for another
        gear pair.
    """
    torque = check_range("torque_nm", torque_nm, 0.0, 1e6, unit="N m")
    if isinstance(mesh, str) and mesh not in MESH_CHOICES:
        raise ParameterError(f"mesh must be None, one of {MESH_CHOICES}, a MeshStiffnessTable, "
                             f"a MeshTableSet or a HybridMeshModel, got {mesh!r}")
    if rig.gears is None:
        if mesh is None or mesh in ("hybrid-tables", "potential-energy"):
            return None, None
        raise ParameterError(f"mesh = {mesh!r} given for a rig without gears (allowed: None)")
    pair = rig.gears
    if mesh is None or mesh == "hybrid-tables":
        tables = _known_set(rig)
        if tables is not None and torque <= tables.torques_nm[-1] * (1 + 1e-12):
            return tables.at(torque), None
        # a rig without a built set (e.g. one record of a dataset that varies the clearance)
        # builds the one table its torque needs, not the whole grid
        return _table_at(rig, max(torque, TORQUE_GRID_NM[0]), progress), None
    if mesh == "potential-energy":
        return default_mesh_table(pair), None
    if isinstance(mesh, MeshStiffnessTable):
        return mesh, None
    if isinstance(mesh, MeshTableSet):
        return mesh.at(torque), None
    if mesh == "hybrid":
        mesh = HybridMeshModel.from_pair(pair)
    if isinstance(mesh, HybridMeshModel):
        mesh.check_pair(pair)
        return hybrid_mesh_table(mesh, torque), mesh
    raise ParameterError(f"mesh must be None, one of {MESH_CHOICES}, a MeshStiffnessTable, a "
                         f"MeshTableSet or a HybridMeshModel, got {type(mesh).__name__}")


def build_paper_tables(path=None, *, progress=None):
    """Build the paper rig's set and write it (default: the package data file).

    Parameters
    ----------
    path : str or pathlib.Path, optional
        Output ``.npz`` file (default :data:`PAPER_TABLES_FILE` in the package).
    progress : None, False or callable
        Progress of the build (see :func:`hybrid_table_set`).

    Returns
    -------
    pathlib.Path
    """
    rig = Rig.paper_2016()
    target = Path(path) if path is not None else Path(__file__).resolve().parents[1] / \
        PAPER_TABLES_FILE
    tables = _build_set(rig, tables_key(rig), progress)
    tables.save(target)
    return target


if __name__ == "__main__":          # python -m cmsim.dynamics.tooth_contact [OUT.npz]
    out = build_paper_tables(sys.argv[1] if len(sys.argv) > 1 else None)
    k = [row["mean_stiffness_n_per_m"] for row in MeshTableSet.load(out).summary]
    print(f"wrote {out}: {len(k)} torques, mean mesh stiffness "
          f"{np.min(k):.4g}..{np.max(k):.4g} N/m")
