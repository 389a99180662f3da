"""The one recipe of many runs, :class:`DatasetSpec`: a sweep is a grid spec without drawn faults.

A spec names *settings* (:mod:`cmsim.datasets.variation`: operating-point fields, named rig
transformations, dotted rig fields), each a :class:`~cmsim.datasets.distribution.Distribution`,
and samples them one of two ways:

``sampling="grid"``
    the records are the Cartesian product of the settings' values (the first setting
    slowest), each point repeated ``repeats`` times; record ``i`` is grid point
    ``(i // repeats) mod n_points``, so a ``records`` beyond the grid cycles through it again.
    A sweep is such a spec (``DatasetSpec([Variation("torque_nm", [10, 100])],
    fixed={"speed_rpm": 1000})``, or ``cmsim sweep``), keeping every signal of its runs.
``sampling="random"``
    each record draws every setting from its distribution.

On top of the settings a record draws a run-up, a labelled fault from the spec's fault types
(or none: healthy), and nuisances (sensor noise, speed wobble, slip, housing modes); the
spec's ``faults`` are built into every record. :meth:`DatasetSpec.record` returns what is
drawn as a :class:`~cmsim.datasets.plan.RecordPlan`. The TOML form
(:mod:`~cmsim.datasets.spec_toml`, ``datasets/*.toml``) reads into the same class::

    spec = DatasetSpec.load("datasets/ci.toml")              # a labelled dataset
    sweep = DatasetSpec([Variation("speed_rpm", [1000, 1500]),
                         Variation("torque_nm", [10, 50, 100])], duration_s=0.5, seed=3)
    len(sweep)                                              # 2 * 3 = 6

Seeds (one rule)
    Record ``i`` draws everything it varies from ``np.random.SeedSequence([seed, i])``
    alone, in a fixed order (the settings in spec order, the run-up, the fault, the
    nuisances), and its simulation seed is the generator's last draw, an integer in
    [0, 2**31 - 1); so any record regenerates on its own (:meth:`DatasetSpec.record`) and
    does not depend on how many workers made it. ``seed_policy="shared"`` gives every record
    the base seed itself as its simulation seed (the same cage phases at every torque, for
    like-for-like comparisons).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
from dataclasses import dataclass, fields, is_dataclass
from pathlib import Path

import numpy as np

from cmsim.datasets.distribution import Distribution
from cmsim.datasets.plan import NUISANCES, PER_MODE, FaultChoice, RecordPlan, nuisance_faults
from cmsim.datasets.spec_toml import (check_channels, machine_operating, read_toml,
                                      setting_range, toml_key, toml_keywords)
from cmsim.datasets.variation import (OPERATING_POINT_FIELDS, Variation, _check_value,
                                      apply_rig_setting, setting_kind, value_token)
from cmsim.dynamics.step import fastest_excitation, integration_substeps
from cmsim.dynamics.tooth_contact import MESH_CHOICES
from cmsim.errors import ParameterError, check_choice, check_range
from cmsim.faults import FAULT_TYPES, check_faults
from cmsim.losses import LossSettings
from cmsim.machine import Machine, twin_mesh
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.mesh_stiffness.table_set import MeshTableSet
from cmsim.rig import RANGES, SAMPLING, OperatingPoint, Rig

__all__ = ["DatasetSpec", "SAMPLINGS", "SEED_POLICIES", "mesh_key"]

#: Sampling modes of :class:`DatasetSpec`.
SAMPLINGS = ("grid", "random")

#: Seed policies of :class:`DatasetSpec` (module docstring).
SEED_POLICIES = ("per_run", "shared")

#: Records a spec draws on construction to check them (every point of a grid is checked).
_CHECKED_RECORDS = 8


def mesh_key(mesh):
    """JSON-ready description of a ``mesh`` argument (a name, or the type and a content hash
    of a table, table set or hybrid model), so two specs with different tables differ.

    Parameters
    ----------
    mesh : None, str, MeshStiffnessTable, MeshTableSet or HybridMeshModel
        The spec's tooth contact model.
    """
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


@dataclass(frozen=True, init=False)
class DatasetSpec:
    """A recipe of many runs (module docstring); :meth:`load` reads the TOML form.

    Parameters
    ----------
    variations : sequence of Variation, (name, values) pairs, (name, Distribution) pairs, or a
        dict {name: values}
        The settings records vary, in order (the first is the slowest grid axis).
    fixed : dict, optional
        Settings every record shares, one value each (``{"speed_rpm": 1000.0}``); not part
        of record ids. ``speed_rpm`` must be varied or fixed.
    sampling : {"grid", "random"}
        Lay the settings on a grid, or draw them per record.
    records : int, optional
        Number of records (default: a grid's points × ``repeats``; required for random).
    repeats : int
        Records per grid point, each with its own seed (1-10000).
    name : str
        Name of the spec (``dataset.json``, progress bars).
    seed : int
        Base seed (:data:`cmsim.rig.RANGES` ``seed``).
    seed_policy : {"per_run", "shared"}
        How record seeds follow from ``seed`` (module docstring).
    rig : Rig, optional
        Base rig (default the paper's, Tables 1-3).
    rig_source : str, optional
        Where the rig came from (``"builtin:<name>"``, a file), for the record.
    runup_share : float
        Share of run-up records (0-1).
    runup_to_rpm : Distribution, optional
        End speed of a run-up over the recorded duration, rpm.
    fault_types : sequence of FaultChoice
        Fault types a record draws one of (labelled), with their weights.
    healthy_share : float, optional
        Share of records drawn healthy (default 1 without fault types, else 0).
    faults : sequence of Fault
        Faults of the catalogue built into every record's model (a cracked gear at every
        torque, say); checked against every grid point's rig.
    nuisances : dict, optional
        ``{name: Distribution or value}`` of :data:`cmsim.datasets.plan.NUISANCES`.
    channels : sequence of str, optional
        Signals a record keeps, float32 at the sensor rate (``accel_<bearing>_<x|y>`` and
        ``tacho`` through the rig's housing path); None (default): the simulated run in
        full, every signal at full precision, as ``cmsim report`` draws it.
    fs_hz, duration_s, warmup_s : float
        Output rate (Hz), recorded and dropped durations (s).
    substeps : int, optional
        Integration steps per sample (default: automatic, with anti-alias decimation, as
        :func:`cmsim.dynamics.simulate`).
    mesh : None, str, MeshStiffnessTable, MeshTableSet or HybridMeshModel
        Tooth contact model passed to :func:`cmsim.dynamics.simulate`.
    losses : LossSettings or True, optional
        Every loss source in every run (their breakdown and power balance in the meta).
    machine : cmsim.machine.Machine, optional
        A calibrated machine (:func:`cmsim.machine.calibrate`): the records are made on its
        rig at its sample rate, and the channel named as the machine's is the model force
        through its calibrated path plus its background; its speed and load (as calibrated)
        are fixed where the settings leave them out.
    """

    name: str
    n_records: int
    seed: int
    seed_policy: str
    sampling: str
    repeats: int
    rig: Rig
    rig_source: str
    settings: tuple
    runup_share: float
    runup_to_rpm: object
    healthy_share: float
    fault_types: tuple
    faults: tuple
    nuisances: tuple
    channels: object
    fs_hz: float
    duration_s: float
    warmup_s: float
    substeps: object
    mesh: object
    losses: object
    machine: object

    def __init__(self, variations=(), *, fixed=None, sampling="grid", records=None, repeats=1,
                 name="sweep", seed=SAMPLING.seed, seed_policy="per_run", rig=None, rig_source=None,
                 runup_share=0.0, runup_to_rpm=None, fault_types=(), healthy_share=None,
                 faults=(), nuisances=None, channels=None, fs_hz=SAMPLING.fs_hz,
                 duration_s=SAMPLING.duration_s, warmup_s=SAMPLING.warmup_s,
                 substeps=SAMPLING.substeps, mesh=None, losses=None, machine=None):
        set_ = object.__setattr__
        if machine is not None:
            if not isinstance(machine, Machine):
                raise ParameterError(f"machine must be a cmsim.machine.Machine, got "
                                     f"{type(machine).__name__}", param="machine")
            if rig is not None and rig != machine.rig:
                raise ParameterError("a machine brings its rig: leave rig out",
                                     param="machine")
            rig = machine.rig
            if mesh is None:             # its twin's tooth contact, as calibrated
                mesh = twin_mesh(rig)
            if abs(float(fs_hz) / machine.fs_hz - 1.0) > 1e-9:
                raise ParameterError(f"fs_hz must be the machine's sample rate "
                                     f"({machine.fs_hz:g} Hz), got {fs_hz!r}", param="fs_hz")
        set_(self, "machine", machine)
        rig = Rig.paper_2016() if rig is None else rig
        if not isinstance(rig, Rig):
            raise ParameterError(f"rig must be a cmsim.rig.Rig, got {type(rig).__name__}")
        set_(self, "rig", rig)
        set_(self, "rig_source", rig_source or f"rig:{rig.name}")
        set_(self, "name", str(name))
        if sampling not in SAMPLINGS:
            raise ParameterError(f"sampling must be 'random' or 'grid', got {sampling!r}",
                                 param="sampling")
        set_(self, "sampling", sampling)
        set_(self, "settings", _settings(variations, fixed, rig, sampling, None if machine is None
                                         else machine_operating(machine)))
        set_(self, "seed", RANGES["seed"].check("seed", seed))
        check_choice("seed_policy", seed_policy, SEED_POLICIES)
        set_(self, "seed_policy", seed_policy)
        set_(self, "repeats", _integer("repeats", repeats, 1, 10_000))
        n_default = self.n_points * self.repeats if sampling == "grid" else None
        if records is None and n_default is None:
            raise ParameterError("records is required with random sampling", param="records")
        set_(self, "n_records", _integer("records", n_default if records is None else records,
                                         1, 10_000_000))
        set_(self, "runup_share", _share("runup_share", runup_share))
        if self.runup_share > 0 and runup_to_rpm is None:
            raise ParameterError("runup_to_rpm is required when runup_share > 0",
                                 param="runup_to_rpm")
        if runup_to_rpm is not None and not isinstance(runup_to_rpm, Distribution):
            runup_to_rpm = Distribution.parse("runup_to_rpm", runup_to_rpm, RANGES["speed_rpm"])
        set_(self, "runup_to_rpm", runup_to_rpm)
        if not all(isinstance(c, FaultChoice) for c in fault_types):
            raise ParameterError("fault_types must be FaultChoice entries", param="fault_types")
        set_(self, "fault_types", tuple(fault_types))
        set_(self, "healthy_share", _share("healthy_share", (0.0 if fault_types else 1.0)
                                           if healthy_share is None else healthy_share))
        if self.healthy_share < 1 and not self.fault_types:
            raise ParameterError("fault_types is empty but healthy_share < 1",
                                 param="fault_types")
        set_(self, "faults", check_faults(rig, faults))
        nuisances = dict(nuisances or {})
        for n in nuisances:
            if n not in NUISANCES:
                raise ParameterError(f"unknown nuisance {n!r}; allowed: {list(NUISANCES)}",
                                     param="nuisances")
        set_(self, "nuisances", tuple(
            (n, v if isinstance(v, Distribution) else Distribution.parse(n, v, NUISANCES[n]))
            for n, v in ((n, nuisances[n]) for n in NUISANCES if n in nuisances)))
        set_(self, "channels", check_channels(channels, rig, machine))
        set_(self, "fs_hz", RANGES["fs_hz"].check("fs_hz", fs_hz))
        set_(self, "duration_s", RANGES["duration_s"].check("duration_s", duration_s))
        set_(self, "warmup_s", RANGES["warmup_s"].check("warmup_s", warmup_s))
        set_(self, "substeps", None if substeps is None else
             RANGES["substeps"].check("substeps", substeps))
        set_(self, "mesh", _check_mesh(mesh))
        set_(self, "losses", _check_losses(losses))
        self._check_records()

    @classmethod
    def load(cls, path):
        """Read a TOML spec (:mod:`~cmsim.datasets.spec_toml`); a rig ``file`` is relative
        to the spec's folder.

        Parameters
        ----------
        path : str or Path
            The spec file.

        Returns
        -------
        DatasetSpec
        """
        return cls.from_dict(read_toml(path), base_dir=Path(path).parent)

    @classmethod
    def from_dict(cls, data, *, base_dir=None):
        """Spec from a parsed TOML dict (checked in full; errors name the TOML key).

        Parameters
        ----------
        data : dict
            The parsed spec.
        base_dir : str or Path, optional
            Folder a rig ``file`` is relative to.

        Returns
        -------
        DatasetSpec
        """
        kw = toml_keywords(data, base_dir)
        try:
            return cls(**kw)
        except ParameterError as exc:            # name the TOML key, not the keyword
            param = getattr(exc, "param", None)
            key = toml_key(param, [n for n, _ in kw["variations"]]) if param else param
            if key == param:
                raise
            text = str(exc)
            text = text[len(param):].lstrip(": ") if text.startswith(param) else text
            raise ParameterError(f"{key}: {text}", param=key) from None

    # ------------------------------------------------------------------ records
    def __len__(self):
        return self.n_records

    @property
    def n_points(self):
        """Points of the settings' grid (the product of their numbers of values)."""
        return math.prod(len(d.values) for _, d in self.settings) \
            if self.sampling == "grid" else 0

    def _grid_point(self, index):
        values, k = [], (index // self.repeats) % self.n_points
        for _, dist in reversed(self.settings):
            k, j = divmod(k, len(dist.values))
            values.append(dist.values[j])
        return tuple(reversed(values))

    def record(self, index):
        """Draw record ``index`` from ``SeedSequence([seed, index])`` alone (module docstring).

        Parameters
        ----------
        index : int
            Record number, 0 .. ``len(spec) - 1``.

        Returns
        -------
        RecordPlan

        Raises
        ------
        ParameterError
            An index out of range, or a drawn fault that does not fit the rig.
        """
        index = int(index)
        if not 0 <= index < self.n_records:
            raise ParameterError(f"record index must be in [0, {self.n_records - 1}], "
                                 f"got {index}", param="index")
        rng = np.random.default_rng(np.random.SeedSequence([self.seed, index]))
        names = [n for n, _ in self.settings]
        if self.sampling == "grid":
            params = dict(zip(names, self._grid_point(index)))
        else:
            params = {name: dist.draw(rng) for name, dist in self.settings}
        runup = bool(rng.random() < self.runup_share)
        end = self.runup_to_rpm.draw(rng) if self.runup_to_rpm is not None else math.nan
        params["runup"] = runup
        params["end_speed_rpm"] = float(end) if runup else float(params["speed_rpm"])
        drawn = self._draw_fault(rng, index) if rng.random() >= self.healthy_share else None
        nuis = dict(self.nuisances)
        for name in NUISANCES:
            dist = nuis.get(name)
            if name in PER_MODE:
                if dist is not None:
                    for k in range(self.rig.housing.n_modes):
                        params[f"{name}_{k + 1}"] = float(dist.draw(rng))
                continue
            params[name] = float(dist.draw(rng)) if dist is not None else (
                math.nan if name == "speed_wobble_hz" else 0.0)
        if math.isnan(params["speed_wobble_hz"]):
            params["speed_wobble_hz"] = params["speed_rpm"] / 60.0
        sim_seed = int(rng.integers(0, 2 ** 31 - 1))
        if self.seed_policy == "shared":
            sim_seed = self.seed
        repeat = index % self.repeats if self.sampling == "grid" else 0
        faults = (*self.faults, *([drawn] if drawn is not None else []),
                  *nuisance_faults(params))
        labelled = drawn if drawn is not None else (self.faults[0] if self.faults else None)
        plan = RecordPlan(index, self.record_id(index), sim_seed, params, labelled, faults,
                          repeat)
        if drawn is not None:
            try:
                check_faults(self.record_rig(plan), [drawn])
            except ParameterError as exc:
                raise ParameterError(f"faults.types ({drawn.name}) record {index}: {exc}",
                                     param="faults.types") from None
        return plan

    def _draw_fault(self, rng, index):
        weights = np.array([c.weight for c in self.fault_types])
        choice = self.fault_types[int(rng.choice(len(self.fault_types),
                                                 p=weights / weights.sum()))]
        kw = {}
        if choice.component_key:
            kw[choice.component_key] = choice.components[
                int(rng.integers(len(choice.components)))]
        for name, dist in choice.fields:
            kw[name] = dist.draw(rng)
        try:
            return FAULT_TYPES[choice.type](**kw)
        except (ParameterError, TypeError) as exc:
            raise ParameterError(f"faults.types ({choice.type}) record {index}: {exc}",
                                 param="faults.types") from None

    def record_id(self, index):
        """The id of record ``index`` (file stem, manifest key), without drawing it:
        ``"000042"`` under random sampling, else the index and the record's grid values,
        ``"003_n1000rpm_T40Nm"`` (``_r<k>`` for repeat k when the grid points repeat).

        Parameters
        ----------
        index : int
            Record number.
        """
        if self.sampling == "random":
            return f"{index:06d}"
        point = self._grid_point(index)
        tokens = [value_token(n, v) for (n, d), v in zip(self.settings, point)
                  if d.is_grid_axis]
        if self.repeats > 1:
            tokens.append(f"r{index % self.repeats}")
        return "_".join([f"{index:03d}"] + [t for t in tokens if t])

    def record_rig(self, plan):
        """The rig of a record: the base rig with its rig settings and drawn housing modes.

        Parameters
        ----------
        plan : RecordPlan
            A record of this spec (:meth:`record`).
        """
        rig = self.rig
        for name, _ in self.settings:
            if name not in OPERATING_POINT_FIELDS:
                rig = apply_rig_setting(rig, name, plan.params[name])
        housing = {}
        for name, field_name in PER_MODE.items():
            if f"{name}_1" in plan.params:
                housing[field_name] = tuple(plan.params[f"{name}_{k + 1}"]
                                            for k in range(rig.housing.n_modes))
        if housing:
            rig = dataclasses.replace(rig, housing=dataclasses.replace(rig.housing, **housing))
        return rig

    def record_operating_point(self, plan):
        """The :class:`~cmsim.rig.OperatingPoint` of a record (the start speed of a run-up).

        Parameters
        ----------
        plan : RecordPlan
            A record of this spec (:meth:`record`).
        """
        kw = {n: plan.params[n] for n, _ in self.settings
              if n in OPERATING_POINT_FIELDS and plan.params[n] is not None}
        if self.rig.gears is None:
            kw.pop("torque_nm", None)
        return OperatingPoint(**kw)

    def _check_records(self):
        """Every grid point (or the first records drawn) builds a valid rig, operating point
        and model faults, and its fastest excitation is resolved by the spec's sampling
        (:func:`cmsim.dynamics.step.integration_substeps`: the step a run takes)."""
        if self.sampling == "grid":
            indices = range(0, min(self.n_records, self.n_points * self.repeats),
                            self.repeats)
        else:
            indices = range(min(self.n_records, _CHECKED_RECORDS))
        for i in indices:
            plan = self.record(i)
            try:
                rig = self.record_rig(plan)
                check_faults(rig, self.faults)
                op = self.record_operating_point(plan)
                ratio = plan.params["end_speed_rpm"] / op.speed_rpm
                integration_substeps(self.fs_hz, fastest_excitation(rig, op, ratio),
                                     substeps=self.substeps)
            except ParameterError as exc:
                raise ParameterError(f"record {plan.record_id}: {exc}",
                                     param=getattr(exc, "param", None)) from None

    # ------------------------------------------------------------------ identity
    def to_dict(self):
        """JSON-ready dict of the resolved spec (the rig in full)."""
        out = {"name": self.name, "records": self.n_records, "seed": self.seed,
                "seed_policy": self.seed_policy, "sampling": self.sampling,
                "repeats": self.repeats, "rig": self.rig.to_dict(),
                "rig_source": self.rig_source,
                "settings": [{"name": n, **d.to_dict()} for n, d in self.settings],
                "runup_share": self.runup_share,
                "runup_to_rpm": None if self.runup_to_rpm is None else self.runup_to_rpm.to_dict(),
                "healthy_share": self.healthy_share,
                "fault_types": [c.to_dict() for c in self.fault_types],
                "faults": [f.to_dict() for f in self.faults],
                "nuisances": {n: d.to_dict() for n, d in self.nuisances},
                "channels": None if self.channels is None else list(self.channels),
                "fs_hz": self.fs_hz, "duration_s": self.duration_s, "warmup_s": self.warmup_s,
                "substeps": self.substeps, "mesh": mesh_key(self.mesh),
                "losses": None if self.losses is None else dataclasses.asdict(self.losses)}
        if self.machine is not None:            # (absent otherwise: digests stay as they were)
            out["machine"] = self.machine.to_dict()
        return out

    @functools.cached_property
    def _identity(self):
        """``(digest, fields every record key shares, each already in its JSON text)`` from
        one :meth:`to_dict`, computed once (a spec is a frozen value) and carried with the
        spec to the workers: a machine's fields (its path, background, baseline samples) took
        6 ms to encode per record."""
        spec = self.to_dict()
        return _hash(spec), {k: _encode(spec[k]) for k in ("channels", "fs_hz", "duration_s",
                                                           "warmup_s", "substeps", "mesh",
                                                           "losses", "machine") if k in spec}

    @property
    def digest(self):
        """16-hex-digit hash of :meth:`to_dict` (stored with every record)."""
        return self._identity[0]

    def record_key(self, plan):
        """16-hex-digit hash of everything that makes a record's file: its plan, rig,
        operating point, faults, sampling, channels, mesh and losses (not its place in the
        spec), so a record of another spec with the same key is the same file.

        Parameters
        ----------
        plan : RecordPlan
            A record of this spec (:meth:`record`).
        """
        own = {"id": plan.record_id, "seed": plan.sim_seed, "params": plan.params,
               "rig": self.record_rig(plan).to_dict(),
               "op": dataclasses.asdict(self.record_operating_point(plan)),
               "faults": [f.to_dict() for f in plan.faults]}
        return _hash_encoded({**{k: _encode(v) for k, v in own.items()}, **self._identity[1]})

    def __eq__(self, other):
        if not isinstance(other, DatasetSpec):
            return NotImplemented
        return self.to_dict() == other.to_dict()

    def __hash__(self):
        return hash(self.digest)


def _hash(obj):
    return _digest(_encode(obj))


def _encode(obj):
    return json.dumps(obj, sort_keys=True, default=str)


def _hash_encoded(fields):
    """:func:`_hash` of a dict whose values are given in their JSON text: the same text, so
    the same digest (``json.dumps`` with sorted keys writes a dict's values as it would
    alone, between ``{"key": `` and ``, ``)."""
    return _digest("{" + ", ".join(f"{json.dumps(k)}: {fields[k]}" for k in sorted(fields))
                   + "}")


def _digest(text):
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _integer(name, v, lo, hi):
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi:
        raise ParameterError(f"{name} must be an integer in [{lo}, {hi}], got {v!r}",
                             param=name)
    return int(v)


def _share(name, v):
    return check_range(name, v, 0.0, 1.0)


def _settings(variations, fixed, rig, sampling, defaults=None):
    """``fixed`` then ``variations`` as ``(name, Distribution)`` pairs, checked; a name of
    ``defaults`` that neither names is fixed at its default."""
    if isinstance(variations, dict):
        variations = list(variations.items())
    if isinstance(variations, (str, bytes)) or not hasattr(variations, "__iter__"):
        raise ParameterError(f"variations must be a list of Variation, got {variations!r}",
                             param="variations")
    varied = []
    for item in variations:
        if isinstance(item, (tuple, list)) and len(item) == 2 \
                and isinstance(item[1], Distribution):
            varied.append(tuple(item))
        else:
            v = Variation.coerce(item)
            varied.append((v.name, Distribution("choice", values=v.values)))
    names = [n for n, _ in varied]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ParameterError(f"variations name {dup} more than once", param="variations")
    fixed = dict(fixed or {})
    for name, value in (defaults or {}).items():
        if name not in names and name not in fixed:
            fixed[name] = value
    out = []
    for name, value in fixed.items():
        if name in names:
            raise ParameterError(f"{name} is both varied and fixed", param=name)
        setting_kind(name, rig)
        out.append((name, Distribution("constant",
                                       values=(_check_value(f"fixed[{name!r}]", name, value),))))
    for name, dist in varied:
        setting_kind(name, rig)
        bounds = setting_range(name)
        if bounds is not None and dist.kind not in ("choice", "constant"):
            for v in dist.extremes:     # listed values: checked by Variation or per record
                bounds.check(name, v)
        if sampling == "grid" and dist.kind not in ("constant", "choice"):
            raise ParameterError(f"{name}: grid sampling takes a number or a list", param=name)
        if sampling == "grid" and dist.kind == "choice":
            Variation(name, dist.values)   # a grid axis: the sweep's check (no repeats)
        out.append((name, dist))
    if "speed_rpm" not in {n for n, _ in out}:
        raise ParameterError("speed_rpm must be varied (Variation('speed_rpm', [...])) or "
                             "fixed (fixed={'speed_rpm': ...})", param="speed_rpm")
    return tuple(out)


def _check_mesh(mesh):
    if mesh is None or mesh == MESH_CHOICES[0]:
        return None
    if isinstance(mesh, str):
        if mesh not in MESH_CHOICES:
            raise ParameterError(f"mesh must be one of {list(MESH_CHOICES)}, a mesh table, a "
                                 f"table set or a hybrid model, got {mesh!r}", param="mesh")
        return mesh
    if not isinstance(mesh, (MeshStiffnessTable, MeshTableSet, HybridMeshModel)):
        raise ParameterError(f"mesh must be one of {list(MESH_CHOICES)}, a MeshStiffnessTable, "
                             f"a MeshTableSet or a HybridMeshModel, got {type(mesh).__name__}",
                             param="mesh")
    return mesh


def _check_losses(losses):
    if losses is True:
        return LossSettings()
    if isinstance(losses, dict):
        return LossSettings(**losses)
    if losses is not None and losses is not False and not isinstance(losses, LossSettings):
        raise ParameterError(f"losses must be a LossSettings, True or None, got {losses!r}",
                             param="losses")
    return losses or None
