"""The recipe of a sweep: a base rig, named variations, sampling, mesh model and seeds.

:class:`SweepSpec` holds a list of :class:`~cmsim.datasets.variation.Variation` s; its
:meth:`~SweepSpec.cases` are their Cartesian product (the first variation slowest), each
grid point repeated ``repeats`` times with its own seed. Adding an axis is adding a
variation — a rig field, an operating-point field or a named rig transformation — not
writing a loop::

    spec = SweepSpec([Variation("speed_rpm", [1000, 1500]),
                      Variation("torque_nm", [10, 50, 100]),
                      Variation("clearance_m", [15e-6, -1e-6]),
                      Variation("lubricant.dynamic_viscosity_pa_s", [0.004, 0.04])],
                     fixed={"radial_load_n": 0.0}, duration_s=0.5, seed=3)
    len(spec.cases())                                     # 2 * 3 * 2 * 2 = 24

The older keywords ``speeds_rpm``, ``torques_nm``, ``frictions``, ``clearances_m`` (and
``radial_load_n``) are shorthands for the variations ``speed_rpm``, ``torque_nm``,
``friction``, ``clearance_m`` (in that order, before ``variations``) and for
``fixed={"radial_load_n": ...}``; a spec of that shape also serialises in that older form,
so manifests written before variations existed still resume.

Seeds
    ``seed_policy="per_run"`` (default): case ``i`` gets
    ``SeedSequence(seed, spawn_key=(i,))`` → a 31-bit integer, so cases are independent and
    each is reproducible from (base seed, index); ``"shared"``: every case uses ``seed``
    (same cage phases at every torque, for like-for-like comparisons).
"""

from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import dataclass, fields, is_dataclass

import numpy as np

from cmsim.datasets.variation import (OPERATING_POINT_FIELDS, Variation, _check_value,
                                      apply_rig_setting, setting_kind, value_token)
from cmsim.dynamics.tooth_contact import MESH_CHOICES
from cmsim.errors import ParameterError, check_range
from cmsim.faults import check_faults, fault_from_dict
from cmsim.losses import LossSettings
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.mesh_stiffness.table_set import MeshTableSet
from cmsim.rig import OperatingPoint, Rig

__all__ = ["SweepSpec", "SweepCase", "SEED_POLICIES", "mesh_key"]

#: Seed policies of :class:`SweepSpec`.
SEED_POLICIES = ("per_run", "shared")

#: Keys of the older serialised form (speed × torque × friction × clearance grids).
_LEGACY_KEYS = ("speeds_rpm", "torques_nm", "frictions", "clearances_m", "duration_s",
                "fs_hz", "warmup_s", "substeps", "radial_load_n", "seed", "seed_policy", "rig")
_LEGACY_AXES = (("speeds_rpm", "speed_rpm"), ("torques_nm", "torque_nm"),
                ("frictions", "friction"), ("clearances_m", "clearance_m"))
_KEYS = ("variations", "fixed", "repeats", "duration_s", "fs_hz", "warmup_s", "substeps",
         "mesh", "seed", "seed_policy", "rig", "faults", "losses")


@dataclass(frozen=True)
class SweepCase:
    """One case of a sweep: a point of the variations' grid and its seed.

    Attributes
    ----------
    index : int
        Position in :meth:`SweepSpec.cases` (first variation slowest, repeats fastest).
    name : str
        File stem of the run: the index and one token per varied setting, e.g.
        ``"003_n1000rpm_T40Nm_c15um"`` (``_r<k>`` for repeat k when ``repeats > 1``).
    values : tuple of (str, value)
        The varied settings of this case, in variation order (``None``: base value).
    seed : int
        Seed of this run.
    repeat : int
        Repeat number at this grid point (0 .. repeats-1).
    """

    index: int
    name: str
    values: tuple
    seed: int
    repeat: int = 0

    @property
    def params(self):
        """The varied settings as a dict ``{name: value}``."""
        return dict(self.values)

    @property
    def id(self):
        """Stable 12-hex-digit id from the case's values and repeat alone (not its index)."""
        text = json.dumps([list(self.values), self.repeat], sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:12]

    def to_dict(self):
        """JSON-ready dict (stored in each run's ``meta["sweep_case"]``)."""
        return {"index": self.index, "name": self.name, "id": self.id, "seed": self.seed,
                "repeat": self.repeat, "values": self.params}


def mesh_key(mesh):
    """JSON-ready description of a ``mesh`` argument (a name, or the type and a content hash
    of a table, table set or hybrid model), so two specs with different tables differ."""
    if mesh is None or isinstance(mesh, str):
        return mesh
    digest = hashlib.sha256()

    def feed(obj):
        if isinstance(obj, np.ndarray):
            digest.update(str(obj.dtype).encode() + str(obj.shape).encode())
            digest.update(np.ascontiguousarray(obj).tobytes())
        elif is_dataclass(obj):
            for f in fields(obj):
                if f.name not in ("meta", "summary"):
                    feed(getattr(obj, f.name))
        elif isinstance(obj, (tuple, list)):
            for x in obj:
                feed(x)
        elif not isinstance(obj, dict):
            digest.update(repr(obj).encode())

    feed(mesh)
    return {"type": type(mesh).__name__, "sha256": digest.hexdigest()[:16]}


def _check_mesh(mesh):
    if mesh is None or mesh == MESH_CHOICES[0]:
        return None
    if isinstance(mesh, str):
        if mesh not in MESH_CHOICES:
            raise ParameterError(f"mesh must be one of {list(MESH_CHOICES)}, a mesh table, a "
                                 f"table set or a hybrid model, got {mesh!r}")
        return mesh
    if not isinstance(mesh, (MeshStiffnessTable, MeshTableSet, HybridMeshModel)):
        raise ParameterError(f"mesh must be one of {list(MESH_CHOICES)}, a MeshStiffnessTable, "
                             f"a MeshTableSet or a HybridMeshModel, got {type(mesh).__name__}")
    return mesh


def _legacy_variations(speeds_rpm, torques_nm, frictions, clearances_m):
    """Variations of the shorthand keywords, checked under their own names."""
    out = []
    for (key, name), values in zip(_LEGACY_AXES, (speeds_rpm, torques_nm, frictions,
                                                  clearances_m)):
        if values is None:
            continue
        if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
            values = (values,)
        values = tuple(values)
        if not values:
            raise ParameterError(f"{key} must hold at least one value")
        checked = []
        for i, v in enumerate(values):
            if v is not None or name not in ("friction", "clearance_m"):
                v = check_range(f"{key}[{i}]", v)
            checked.append(v)
            if v is None:
                continue
            if name == "speed_rpm":
                check_range(f"{key}[{i}]", v, 0.0, 1e5, lo_open=True, unit="rpm")
            elif name == "friction":
                check_range(f"{key}[{i}]", v, 0.0, 1.0)
        values = tuple(checked)
        if len(set(values)) != len(values):
            raise ParameterError(f"{key} must not repeat a value, got {list(values)}")
        if values != (None,):
            out.append(Variation(name, values))
    return out


@dataclass(frozen=True, init=False)
class SweepSpec:
    """Recipe of a sweep (SI units): base rig, variations, sampling, mesh model and seeds.

    Parameters
    ----------
    variations : sequence of Variation, (name, values) pairs, or a dict {name: values}
        The axes of the grid, first slowest (:mod:`cmsim.datasets.variation` lists the
        settings a variation may name).
    fixed : dict, optional
        Settings applied to every case, same names as variations, one value each (e.g.
        ``{"speed_rpm": 1000.0, "radial_load_n": 500.0}``); not part of case names.
        ``speed_rpm`` must be varied or fixed.
    repeats : int
        Runs per grid point, each with its own seed (1-10000).
    duration_s : float
        Recorded duration of every run, s (0 < d <= 600).
    rig : Rig, optional
        Base rig (default the paper's, Tables 1-3).
    fs_hz : float
        Output sample rate, Hz.
    warmup_s : float
        Simulated time discarded before recording, s.
    substeps : int
        Integration steps per sample.
    mesh : None, str, MeshStiffnessTable, MeshTableSet or HybridMeshModel
        Tooth contact model passed to :func:`cmsim.dynamics.simulate` (``None`` or
        ``"hybrid-tables"``: the rig's hybrid tables at each case's torque).
    seed : int
        Base seed (>= 0).
    seed_policy : {"per_run", "shared"}
        How case seeds follow from ``seed`` (module docstring).
    speeds_rpm, torques_nm, frictions, clearances_m : sequence of float, optional
        Shorthands for the variations ``speed_rpm``, ``torque_nm``, ``friction``,
        ``clearance_m`` (``(None,)`` for the last two = the rig's own), placed first.
    radial_load_n : float, optional
        Shorthand for ``fixed={"radial_load_n": ...}`` (N).
    faults : sequence of Fault, optional
        Faults of the catalogue (:mod:`cmsim.faults`) built into every case's model (a
        cracked gear at every torque, say); checked against every case's rig.
    losses : LossSettings or True, optional
        Every loss source in every run (``simulate(losses=...)``): the runs' meta carry the
        breakdown by source and the power balance (``cmsim report`` draws them).

    Every case's rig and operating point are built (and so checked) on construction.
    """

    variations: tuple
    fixed: tuple
    repeats: int
    duration_s: float
    rig: Rig
    fs_hz: float
    warmup_s: float
    substeps: int
    mesh: object
    seed: int
    seed_policy: str
    faults: tuple
    losses: LossSettings | None

    def __init__(self, variations=(), *, fixed=None, repeats=1, duration_s=1.0, rig=None,
                 fs_hz=75_000.0, warmup_s=0.05, substeps=1, mesh=None, seed=0,
                 seed_policy="per_run", speeds_rpm=None, torques_nm=None, frictions=None,
                 clearances_m=None, radial_load_n=None, faults=(), losses=None):
        set_ = object.__setattr__
        rig = Rig.paper_2016() if rig is None else rig
        if not isinstance(rig, Rig):
            raise ParameterError(f"rig must be a cmsim.rig.Rig, got {type(rig).__name__}")
        set_(self, "rig", rig)
        if isinstance(variations, dict):
            variations = list(variations.items())
        if isinstance(variations, (str, bytes)) or not hasattr(variations, "__iter__"):
            raise ParameterError(f"variations must be a list of Variation, got {variations!r}")
        varied = _legacy_variations(speeds_rpm, torques_nm, frictions, clearances_m)
        varied += [Variation.coerce(v) for v in variations]
        names = [v.name for v in varied]
        for v in varied:
            setting_kind(v.name, rig)
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ParameterError(f"variations name {dup} more than once")
        set_(self, "variations", tuple(varied))
        fixed = dict(fixed or {})
        if radial_load_n is not None:
            if "radial_load_n" in fixed:
                raise ParameterError("radial_load_n is given twice (keyword and fixed)")
            value = check_range("radial_load_n", radial_load_n, unit="N")
            if value != 0.0:
                fixed["radial_load_n"] = value
        for name, value in fixed.items():
            setting_kind(name, rig)
            if name in names:
                raise ParameterError(f"{name} is both varied and fixed")
            fixed[name] = _check_value(f"fixed[{name!r}]", name, value)
        set_(self, "fixed", tuple(sorted(fixed.items())))
        if "speed_rpm" not in names and "speed_rpm" not in fixed:
            raise ParameterError("speed_rpm must be varied (speeds_rpm=[...] or "
                                 "Variation('speed_rpm', [...])) or fixed "
                                 "(fixed={'speed_rpm': ...})")
        set_(self, "duration_s", check_range("duration_s", duration_s, 0.0, 600.0,
                                             lo_open=True, unit="s"))
        set_(self, "fs_hz", check_range("fs_hz", fs_hz, 1e3, 1e7, unit="Hz"))
        set_(self, "warmup_s", check_range("warmup_s", warmup_s, 0.0, 60.0, unit="s"))
        for name, v, lo, hi in (("repeats", repeats, 1, 10_000), ("substeps", substeps, 1, 1000),
                                ("seed", seed, 0, 2 ** 63 - 1)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi:
                raise ParameterError(f"{name} must be an integer in [{lo}, {hi}], got {v!r}")
            set_(self, name, int(v))
        if seed_policy not in SEED_POLICIES:
            raise ParameterError(f"seed_policy must be one of {SEED_POLICIES}, "
                                 f"got {seed_policy!r}")
        set_(self, "seed_policy", seed_policy)
        set_(self, "mesh", _check_mesh(mesh))
        set_(self, "faults", check_faults(rig, faults))
        if losses is True:
            losses = LossSettings()
        elif isinstance(losses, dict):
            losses = LossSettings(**losses)
        if losses is not None and losses is not False and not isinstance(losses, LossSettings):
            raise ParameterError(f"losses must be a LossSettings, True or None, got {losses!r}",
                                 param="losses")
        set_(self, "losses", losses or None)
        for case in self.cases():          # every case must be a valid rig / op
            try:
                check_faults(self.case_rig(case), self.faults)
                self.case_operating_point(case)
            except ParameterError as exc:
                raise ParameterError(f"case {case.name}: {exc}") from None

    def __eq__(self, other):
        if not isinstance(other, SweepSpec):
            return NotImplemented
        return self.to_dict() == other.to_dict()

    def __hash__(self):
        return hash(json.dumps(self.to_dict(), sort_keys=True))

    # ------------------------------------------------------------------ grid
    def run_seed(self, index):
        """Seed of case ``index`` (module docstring), a 31-bit integer."""
        if self.seed_policy == "shared":
            return self.seed
        state = np.random.SeedSequence(self.seed, spawn_key=(int(index),)).generate_state(1)
        return int(state[0] >> 1)

    def __len__(self):
        n = self.repeats
        for v in self.variations:
            n *= len(v.values)
        return n

    def cases(self):
        """Every case: the product of the variations (first slowest), then the repeats."""
        names = [v.name for v in self.variations]
        grid = itertools.product(*(v.values for v in self.variations), range(self.repeats))
        out = []
        for index, point in enumerate(grid):
            *values, repeat = point
            tokens = [value_token(n, x) for n, x in zip(names, values)]
            if self.repeats > 1:
                tokens.append(f"r{repeat}")
            name = "_".join([f"{index:03d}"] + [t for t in tokens if t])
            out.append(SweepCase(index, name, tuple(zip(names, values)),
                                 self.run_seed(index), repeat))
        return out

    def _settings(self, case):
        """Fixed settings, then the case's values (None = base), in that order."""
        return [*self.fixed, *((n, v) for n, v in case.values if v is not None)]

    def case_rig(self, case):
        """The rig of one case: the base rig with the fixed and the case's rig settings."""
        rig = self.rig
        for name, value in self._settings(case):
            if name not in OPERATING_POINT_FIELDS:
                rig = apply_rig_setting(rig, name, value)
        return rig

    def case_operating_point(self, case):
        """The :class:`~cmsim.rig.OperatingPoint` of one case."""
        kw = {n: v for n, v in self._settings(case) if n in OPERATING_POINT_FIELDS}
        return OperatingPoint(**kw)

    # ------------------------------------------------------------------ (de)serialisation
    def _legacy_form(self):
        """True if the spec is a speed × torque (× friction × clearance) grid."""
        names = [v.name for v in self.variations]
        order = [name for _, name in _LEGACY_AXES]
        legacy_names = ([*order[:2], *rest] for rest in
                        ([], ["friction"], ["clearance_m"], ["friction", "clearance_m"]))
        return (names in legacy_names
                and {n for n, _ in self.fixed} <= {"radial_load_n"} and self.mesh is None
                and self.repeats == 1 and not self.faults and self.losses is None)

    def to_dict(self, older_form=True):
        """JSON-ready dict (the rig as :meth:`Rig.to_dict`); with ``older_form``, a speed ×
        torque (× friction × clearance) grid keeps the older keys ``speeds_rpm``,
        ``torques_nm``, ... (so its manifests read as before)."""
        common = {"duration_s": self.duration_s, "fs_hz": self.fs_hz,
                  "warmup_s": self.warmup_s, "substeps": self.substeps}
        tail = {"seed": self.seed, "seed_policy": self.seed_policy, "rig": self.rig.to_dict()}
        if older_form and self._legacy_form():
            axes = {v.name: list(v.values) for v in self.variations}
            return {**{key: axes.get(name, [None]) for key, name in _LEGACY_AXES}, **common,
                    "radial_load_n": dict(self.fixed).get("radial_load_n", 0.0), **tail}
        out = {"variations": [v.to_dict() for v in self.variations],
               "fixed": dict(self.fixed), "repeats": self.repeats, **common,
               "mesh": mesh_key(self.mesh), **tail}
        if self.faults:
            out["faults"] = [f.to_dict() for f in self.faults]
        if self.losses is not None:
            out["losses"] = {k: getattr(self.losses, k)
                             for k in self.losses.__dataclass_fields__}
        return out

    @classmethod
    def from_dict(cls, data):
        """Spec from :meth:`to_dict` output (either form); unknown keys raise
        :class:`ParameterError` naming them."""
        data = dict(data)
        allowed = _KEYS if "variations" in data else _LEGACY_KEYS
        unknown = set(data) - set(allowed)
        if unknown:
            raise ParameterError(f"unknown sweep spec keys {sorted(unknown)}; allowed: "
                                 f"{sorted(allowed)}")
        if "rig" in data:
            data["rig"] = Rig.from_dict(data["rig"])
        if isinstance(data.get("mesh"), dict):
            raise ParameterError(f"the spec's mesh is a {data['mesh'].get('type')} object; "
                                 f"pass the object itself as mesh=")
        variations = data.pop("variations", ())
        data["faults"] = tuple(fault_from_dict(f) for f in data.get("faults", ()))
        return cls(variations, **data)

