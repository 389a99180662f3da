"""The recipe of a labelled dataset: :class:`DatasetSpec`, read from TOML, and its records.

A dataset spec (``datasets/*.toml`` holds the standard ones) has these tables; every key is
checked, and a bad spec is refused before any work with a message naming the key
(``operating.speed_rpm.max``)::

    [dataset]      name, records (number of records), seed (base seed)
    [rig]          builtin = "paper_2016" | "cwru_6205" | "mfpt_nice", or file = "rig.toml" (relative to
                   the spec file)
    [operating]    sampling = "random" | "grid"; speed_rpm, torque_nm, friction, clearance_m,
                   radial_load_n (values, see below); runup_share (share of run-up records),
                   runup_to_rpm (end speed of a run-up over the recorded duration)
    [faults]       healthy_share; [[faults.types]] with type (catalogue name), the
                   component (bearing = [...] or gear = [...], one drawn per record), weight,
                   and any field of the fault as a value (its main size is the severity)
    [nuisances]    sensor_noise_m_s2, speed_wobble (relative amplitude of a speed
                   fluctuation), speed_wobble_hz (default: the input shaft rate), slip
                   (relative cage-speed fluctuation, a rolling_slip), housing_mode_hz and
                   housing_damping (drawn once per mode of ``rig.housing``: the transfer
                   path's resonances and damping ratios; absent = the rig's)
    [sensor]       channels (accel_<bearing>_<x|y>, tacho, F_<bearing>_<x|y|loa|oloa}, dte,
                   dte_um, Fmesh_total), fs_hz (output rate; the integration step is chosen
                   from the model's highest mode and the output is anti-alias decimated),
                   duration_s, warmup_s (simulated and dropped)
    [simulation]   mesh (tooth contact model name), substeps (integration steps per sample)

A value is a number (constant), a list (grid values; under random sampling one is drawn
uniformly) or a table ``{distribution = "uniform" | "loguniform" | "normal" | "choice",
min, max, mean, std, values}`` (a normal draw is clipped to ``[min, max]``).

Seeds
    Record ``i`` draws everything it varies from ``np.random.SeedSequence([seed, i])`` alone,
    in a fixed order, so any record can be regenerated on its own (:meth:`DatasetSpec.record`)
    and the records do not depend on how many workers made them.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cmsim.datasets.variation import RIG_TRANSFORMS
from cmsim.dynamics.tooth_contact import MESH_CHOICES
from cmsim.errors import ParameterError
from cmsim.faults import FAULT_TYPES, RollingSlip, SpeedFluctuation, check_faults
from cmsim.rig import OperatingPoint, RollingBearing, Rig, Rotor

__all__ = ["DatasetSpec", "DatasetRecord", "Distribution", "BUILTIN_RIGS", "SEVERITY_FIELDS",
           "cwru_6205_rig", "mfpt_nice_rig"]

#: Main size of each fault type: the record's ``fault_severity`` (SI).
SEVERITY_FIELDS = {"outer_race": "size_m", "inner_race": "size_m", "ball": "size_m",
                   "wear": "clearance_growth_m", "off_size_ball": "diameter_excess_m",
                   "tooth_crack": "depth_m", "tooth_spall": "width_m",
                   "tooth_breakage": "lost_height_m", "eccentricity": "amplitude_m",
                   "profile_error": "wear_depth_m", "speed_fluctuation": "relative_amplitude",
                   "torque_ripple": "relative_amplitude", "rolling_slip": "cage_speed_rms"}

#: Operating-point settings a spec may vary, with their physical bounds (lo, hi, unit).
_OPERATING = {"speed_rpm": (0.0, 1e5, "rpm"), "torque_nm": (0.0, 1e6, "N m"),
              "friction": (0.0, 0.3, ""), "clearance_m": (-1e-3, 1e-3, "m"),
              "radial_load_n": (0.0, 1e7, "N")}
_NUISANCES = {"sensor_noise_m_s2": (0.0, 1e6, "m/s^2"), "speed_wobble": (0.0, 0.1, ""),
              "speed_wobble_hz": (0.0, 1e4, "Hz"), "slip": (0.0, 0.2, ""),
              "housing_mode_hz": (1.0, 1e6, "Hz"), "housing_damping": (1e-4, 0.5, "")}
#: Nuisances drawn once per housing mode (columns ``<name>_1`` .. ``<name>_n``), and only
#: when the spec gives them: domain randomisation of the transfer path.
_PER_MODE = {"housing_mode_hz": "natural_frequencies_hz", "housing_damping": "damping_ratios"}
_TABLES = {"dataset": {"name", "records", "seed"}, "rig": {"builtin", "file"},
           "operating": {"sampling", "runup_share", "runup_to_rpm", *_OPERATING},
           "faults": {"healthy_share", "types"}, "nuisances": set(_NUISANCES),
           "sensor": {"channels", "fs_hz", "duration_s", "warmup_s"},
           "simulation": {"mesh", "substeps"}}
_DIST_KEYS = {"distribution", "min", "max", "mean", "std", "values"}
DISTRIBUTIONS = ("constant", "uniform", "loguniform", "normal", "choice")


def cwru_6205_rig():
    """A rotor on two SKF 6205 ball bearings (CWRU drive-end geometry: 9 balls,
    d = 7.94 mm, pitch D = 39.04 mm), loaded radially through ``radial_load_n``."""
    brg = RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3)
    return Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01),
                                 name="cwru_6205")


def mfpt_nice_rig():
    """A rotor on two MFPT test bearings (NICE, 8 rollers, d = 5.969 mm (0.235 in), pitch
    D = 31.623 mm (1.245 in), 0 deg), loaded radially through ``radial_load_n``."""
    brg = RollingBearing.from_pitch(8, 5.969e-3, 31.623e-3)
    return Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01),
                                 name="mfpt_nice")


#: Built-in rigs by name.
BUILTIN_RIGS = {"paper_2016": Rig.paper_2016, "cwru_6205": cwru_6205_rig,
                "mfpt_nice": mfpt_nice_rig}


def _err(key, msg):
    return ParameterError(f"{key}: {msg}", param=key)


def _number(key, v):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise _err(key, f"must be a finite number, got {v!r}")
    return float(v)


@dataclass(frozen=True)
class Distribution:
    """One spec value: a constant, a choice among values, or a bounded distribution.

    Attributes
    ----------
    kind : str
        One of :data:`DISTRIBUTIONS`.
    lo, hi : float
        Bounds (uniform, loguniform, the clip of normal); NaN if unused.
    mean, std : float
        Of a normal draw; NaN if unused.
    values : tuple
        The constant (one value) or the choices.
    """

    kind: str
    lo: float = math.nan
    hi: float = math.nan
    mean: float = math.nan
    std: float = math.nan
    values: tuple = ()

    @classmethod
    def parse(cls, key, raw, bounds=None, numeric=True):
        """Parse a spec value at ``key``, checked against ``bounds = (lo, hi, unit)``.

        Parameters
        ----------
        key : str
            Dotted spec key (named in errors).
        raw : object
            A fixed value, a list of choices, or a table with ``min``/``max`` (and a
            distribution).
        bounds : tuple, optional
            ``(lo, hi, unit)`` every value must lie in.
        numeric : bool
            Whether the values are numbers (else labels, left unchecked).

        Returns
        -------
        Distribution
        """
        def check(k, v):
            if not numeric:
                return v
            v = _number(k, v)
            if bounds is not None and not bounds[0] <= v <= bounds[1]:
                raise _err(k, f"must be in [{bounds[0]:g}, {bounds[1]:g}] {bounds[2]}"
                              f"".rstrip() + f", got {v:g}")
            return v

        if isinstance(raw, dict):
            unknown = set(raw) - _DIST_KEYS
            if unknown:
                raise _err(f"{key}.{sorted(unknown)[0]}", f"unknown key; allowed: "
                                                          f"{sorted(_DIST_KEYS)}")
            kind = raw.get("distribution", "choice" if "values" in raw else "uniform")
            if kind not in DISTRIBUTIONS:
                raise _err(f"{key}.distribution", f"must be one of {list(DISTRIBUTIONS)}, "
                                                  f"got {kind!r}")
            if kind in ("choice", "constant"):
                vals = raw.get("values")
                if not isinstance(vals, list) or not vals:
                    raise _err(f"{key}.values", "must be a non-empty list")
                return cls(kind, values=tuple(check(f"{key}.values[{i}]", v)
                                              for i, v in enumerate(vals)))
            for need in ("min", "max") if kind != "normal" else ("mean", "std"):
                if need not in raw:
                    raise _err(f"{key}.{need}", f"is required for a {kind} distribution")
            lo = check(f"{key}.min", raw["min"]) if "min" in raw else (
                bounds[0] if bounds else -math.inf)
            hi = check(f"{key}.max", raw["max"]) if "max" in raw else (
                bounds[1] if bounds else math.inf)
            if not lo <= hi:
                raise _err(f"{key}.max", f"must be >= min ({lo:g}), got {hi:g}")
            if kind == "loguniform" and lo <= 0:
                raise _err(f"{key}.min", f"must be > 0 for a loguniform distribution, "
                                         f"got {lo:g}")
            if kind == "normal":
                mean = check(f"{key}.mean", raw["mean"])
                std = _number(f"{key}.std", raw["std"])
                if std < 0:
                    raise _err(f"{key}.std", f"must be >= 0, got {std:g}")
                if not lo <= mean <= hi:
                    raise _err(f"{key}.mean", f"must be in [min, max] = [{lo:g}, {hi:g}]")
                return cls(kind, lo, hi, mean, std)
            return cls(kind, lo, hi)
        if isinstance(raw, list):
            if not raw:
                raise _err(key, "must not be an empty list")
            return cls("choice", values=tuple(check(f"{key}[{i}]", v) for i, v in enumerate(raw)))
        return cls("constant", values=(check(key, raw),))

    @property
    def extremes(self):
        """The smallest and largest values it can give."""
        if self.kind in ("choice", "constant"):
            if isinstance(self.values[0], str):
                return self.values
            return (min(self.values), max(self.values))
        return (self.lo, self.hi)

    def draw(self, rng):
        """One value from ``rng`` (a constant draws nothing)."""
        if self.kind == "constant":
            return self.values[0]
        if self.kind == "choice":
            return self.values[int(rng.integers(len(self.values)))]
        if self.kind == "uniform":
            return float(rng.uniform(self.lo, self.hi))
        if self.kind == "loguniform":
            return float(math.exp(rng.uniform(math.log(self.lo), math.log(self.hi))))
        return float(np.clip(rng.normal(self.mean, self.std), self.lo, self.hi))

    def to_dict(self):
        """JSON-ready form."""
        return {k: v for k, v in dataclasses.asdict(self).items()
                if not (isinstance(v, float) and math.isnan(v))}


@dataclass(frozen=True)
class FaultChoice:
    """One entry of ``[[faults.types]]``: a fault type, its components, fields, weight."""

    type: str
    component_key: str          # "bearing", "gear" or ""
    components: tuple
    fields: tuple               # ((name, Distribution), ...)
    weight: float

    def to_dict(self):
        """JSON-ready form."""
        return {"type": self.type, "component_key": self.component_key,
                "components": list(self.components), "weight": self.weight,
                "fields": {k: d.to_dict() for k, d in self.fields}}


@dataclass(frozen=True)
class DatasetRecord:
    """Everything drawn for one record (its parameters and answer key).

    Attributes
    ----------
    index : int
        Record number (0 ..).
    record_id : str
        ``"000042"``: file stem and manifest key.
    sim_seed : int
        Seed of the simulation (cage phases, slip) and of the sensor noise.
    params : dict
        Drawn parameters, one flat column each (``speed_rpm``, ``torque_nm``, ``friction``,
        ``clearance_m``, ``radial_load_n``, ``runup``, ``end_speed_rpm``,
        ``sensor_noise_m_s2``, ``speed_wobble``, ``speed_wobble_hz``, ``slip``).
    fault : Fault or None
        The labelled fault (None: healthy).
    """

    index: int
    record_id: str
    sim_seed: int
    params: dict
    fault: object

    @property
    def fault_label(self):
        """``"healthy"`` or the fault type."""
        return "healthy" if self.fault is None else self.fault.name

    @property
    def fault_component(self):
        """Bearing name, ``"G<k>"`` for a gear, or ``""``."""
        f = self.fault
        if f is None:
            return ""
        if hasattr(f, "bearing"):
            return str(f.bearing)
        if hasattr(f, "gear"):
            return f"G{f.gear}"
        return ""

    @property
    def fault_severity(self):
        """The fault's main size (SI, :data:`SEVERITY_FIELDS`), NaN when healthy."""
        if self.fault is None:
            return math.nan
        return float(getattr(self.fault, SEVERITY_FIELDS.get(self.fault.name, ""), math.nan))

    def nuisance_faults(self):
        """Speed wobble and rolling slip as catalogue faults (not labels)."""
        out = []
        if self.params["speed_wobble"] > 0:
            out.append(SpeedFluctuation(relative_amplitude=self.params["speed_wobble"],
                                        frequency_hz=self.params["speed_wobble_hz"]))
        if self.params["slip"] > 0:
            out.append(RollingSlip(cage_speed_rms=self.params["slip"]))
        return out


@dataclass(frozen=True, init=False)
class DatasetSpec:
    """A dataset recipe (module docstring); build with :meth:`load` or :meth:`from_dict`.

    Attributes
    ----------
    name : str
    n_records : int
    seed : int
        Base seed.
    rig : Rig
    rig_source : str
        ``"builtin:<name>"`` or the rig file's path as given.
    sampling : str
        ``"random"`` or ``"grid"``.
    operating : tuple of (str, Distribution)
    runup_share : float
    runup_to_rpm : Distribution or None
    healthy_share : float
    faults : tuple of FaultChoice
    nuisances : tuple of (str, Distribution)
    channels : tuple of str
    fs_hz, duration_s, warmup_s : float
        Sensor rate (Hz), recorded and dropped durations (s).
    mesh : str or None
    substeps : int or None
    """

    name: str
    n_records: int
    seed: int
    rig: Rig
    rig_source: str
    sampling: str
    operating: tuple
    runup_share: float
    runup_to_rpm: object
    healthy_share: float
    faults: tuple
    nuisances: tuple
    channels: tuple
    fs_hz: float
    duration_s: float
    warmup_s: float
    mesh: object
    substeps: object

    def __init__(self, data, *, base_dir=None):
        raise TypeError("use DatasetSpec.from_dict(data) or DatasetSpec.load(path)")

    # ------------------------------------------------------------------ building
    @classmethod
    def load(cls, path):
        """Read a TOML spec; a rig ``file`` is relative to the spec's folder.

        Parameters
        ----------
        path : str or Path
            The spec file.

        Returns
        -------
        DatasetSpec
        """
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except tomllib.TOMLDecodeError as exc:
            raise ParameterError(f"not valid TOML ({exc})") from None
        except UnicodeDecodeError as exc:
            raise ParameterError(f"not a text file ({exc})") from None
        return cls.from_dict(data, base_dir=path.parent)

    @classmethod
    def from_dict(cls, data, *, base_dir=None):
        """Spec from a parsed TOML dict (checked in full, and its first records drawn).

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
        if not isinstance(data, dict):
            raise ParameterError(f"a dataset spec must be a table, got {type(data).__name__}")
        for key in data:
            if key not in _TABLES:
                raise _err(key, f"unknown table; allowed: {sorted(_TABLES)}")
            if not isinstance(data[key], dict):
                raise _err(key, "must be a table")
            for sub in data[key]:
                if sub not in _TABLES[key]:
                    raise _err(f"{key}.{sub}", f"unknown key; allowed: {sorted(_TABLES[key])}")
        self = object.__new__(cls)
        set_ = object.__setattr__
        ds = data.get("dataset", {})
        set_(self, "name", str(ds.get("name", "dataset")))
        set_(self, "seed", _int("dataset.seed", ds.get("seed", 0), 0, 2 ** 63 - 1))
        rig, source = _rig(data.get("rig", {}), base_dir)
        set_(self, "rig", rig)
        set_(self, "rig_source", source)
        op = data.get("operating", {})
        sampling = op.get("sampling", "random")
        if sampling not in ("random", "grid"):
            raise _err("operating.sampling", f"must be 'random' or 'grid', got {sampling!r}")
        set_(self, "sampling", sampling)
        defaults = {"speed_rpm": 1000.0, "torque_nm": 0.0, "radial_load_n": 0.0}
        operating = []
        for name, bounds in _OPERATING.items():
            if name not in op and name not in defaults:
                continue
            if name in ("friction",) and name in op and rig.gears is None:
                raise _err(f"operating.{name}", "needs a rig with gears")
            if name == "torque_nm" and name in op and rig.gears is None:
                raise _err("operating.torque_nm", "needs a rig with gears (a bearing rig is "
                                                  "loaded by radial_load_n)")
            dist = Distribution.parse(f"operating.{name}", op.get(name, defaults.get(name)),
                                      bounds)
            if name == "speed_rpm" and dist.extremes[0] <= 0:
                raise _err("operating.speed_rpm", "must be > 0 rpm")
            if sampling == "grid" and dist.kind not in ("constant", "choice"):
                raise _err(f"operating.{name}", "grid sampling takes a number or a list")
            operating.append((name, dist))
        set_(self, "operating", tuple(operating))
        set_(self, "runup_share", _share("operating.runup_share", op.get("runup_share", 0.0)))
        runup = op.get("runup_to_rpm")
        if self.runup_share > 0 and runup is None:
            raise _err("operating.runup_to_rpm", "is required when runup_share > 0")
        set_(self, "runup_to_rpm", None if runup is None else Distribution.parse(
            "operating.runup_to_rpm", runup, (1e-3, 1e5, "rpm")))
        n_grid = math.prod(len(d.values) for _, d in operating) if sampling == "grid" else None
        records = ds.get("records", n_grid)
        if records is None:
            raise _err("dataset.records", "is required with random sampling")
        set_(self, "n_records", _int("dataset.records", records, 1, 10_000_000))
        fl = data.get("faults", {})
        set_(self, "healthy_share", _share("faults.healthy_share",
                                           fl.get("healthy_share", 1.0 if not fl.get("types")
                                                  else 0.0)))
        types = fl.get("types", [])
        if not isinstance(types, list):
            raise _err("faults.types", "must be a list of tables ([[faults.types]])")
        set_(self, "faults", tuple(_fault_choice(f"faults.types[{i}]", t, rig)
                                   for i, t in enumerate(types)))
        if self.healthy_share < 1 and not self.faults:
            raise _err("faults.types", "is empty but healthy_share < 1")
        nz = data.get("nuisances", {})
        set_(self, "nuisances", tuple((n, Distribution.parse(f"nuisances.{n}", nz[n], b))
                                      for n, b in _NUISANCES.items() if n in nz))
        sensor = data.get("sensor", {})
        set_(self, "fs_hz", _float("sensor.fs_hz", sensor.get("fs_hz", 25_600.0), 1e3, 1e6))
        set_(self, "duration_s", _float("sensor.duration_s", sensor.get("duration_s", 1.0),
                                        1e-3, 600.0))
        set_(self, "warmup_s", _float("sensor.warmup_s", sensor.get("warmup_s", 0.05), 0.0,
                                      60.0))
        set_(self, "channels", _channels(sensor.get("channels"), rig))
        sim = data.get("simulation", {})
        mesh = sim.get("mesh")
        if mesh is not None and mesh not in MESH_CHOICES:
            raise _err("simulation.mesh", f"must be one of {list(MESH_CHOICES)}, got {mesh!r}")
        set_(self, "mesh", mesh)
        sub = sim.get("substeps")
        set_(self, "substeps", None if sub is None else _int("simulation.substeps", sub, 1, 1000))
        for i in range(min(self.n_records, 8)):        # the first records build and check
            self.record(i)
        return self

    # ------------------------------------------------------------------ records
    def __len__(self):
        return self.n_records

    def record(self, index):
        """Draw record ``index`` from ``SeedSequence([seed, index])`` alone.

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
        params = {}
        if self.sampling == "grid":
            grid = list(itertools.product(*(d.values for _, d in self.operating)))
            params.update(zip((n for n, _ in self.operating), grid[index % len(grid)]))
        else:
            for name, dist in self.operating:
                params[name] = dist.draw(rng)
        runup = bool(rng.random() < self.runup_share)
        end = self.runup_to_rpm.draw(rng) if self.runup_to_rpm is not None else math.nan
        params["runup"] = runup
        params["end_speed_rpm"] = float(end) if runup else float(params["speed_rpm"])
        fault = None
        if rng.random() >= self.healthy_share:
            weights = np.array([c.weight for c in self.faults])
            choice = self.faults[int(rng.choice(len(self.faults), p=weights / weights.sum()))]
            kw = {}
            if choice.component_key:
                comp = choice.components[int(rng.integers(len(choice.components)))]
                kw[choice.component_key] = comp
            for name, dist in choice.fields:
                kw[name] = dist.draw(rng)
            try:
                fault = FAULT_TYPES[choice.type](**kw)
            except (ParameterError, TypeError) as exc:
                raise ParameterError(f"faults.types ({choice.type}) record {index}: {exc}",
                                     param="faults.types") from None
        nuis = {n: d for n, d in self.nuisances}
        for name in _NUISANCES:
            dist = nuis.get(name)
            if name in _PER_MODE:
                if dist is not None:
                    for k in range(self.rig.housing.n_modes):
                        params[f"{name}_{k + 1}"] = float(dist.draw(rng))
                continue
            params[name] = float(dist.draw(rng)) if dist is not None else (
                math.nan if name == "speed_wobble_hz" else 0.0)
        if math.isnan(params["speed_wobble_hz"]):
            params["speed_wobble_hz"] = params["speed_rpm"] / 60.0
        sim_seed = int(rng.integers(0, 2 ** 31 - 1))
        rec = DatasetRecord(index, f"{index:06d}", sim_seed, params, fault)
        if fault is not None:
            try:
                check_faults(self.record_rig(rec), [fault])
            except ParameterError as exc:
                raise ParameterError(f"faults.types ({fault.name}) record {index}: {exc}",
                                     param="faults.types") from None
        return rec

    def record_rig(self, rec):
        """The rig of a record: the base rig with its drawn friction, clearance and housing
        modes.

        Parameters
        ----------
        rec : DatasetRecord
            A record of this spec (:meth:`record`).
        """
        rig = self.rig
        for name in ("clearance_m", "friction"):
            if name in rec.params:
                rig = RIG_TRANSFORMS[name].apply(rig, rec.params[name])
        housing = {}
        for name, field_name in _PER_MODE.items():
            if f"{name}_1" in rec.params:
                housing[field_name] = tuple(rec.params[f"{name}_{k + 1}"]
                                            for k in range(rig.housing.n_modes))
        if housing:
            rig = dataclasses.replace(rig, housing=dataclasses.replace(rig.housing, **housing))
        return rig

    def record_operating_point(self, rec):
        """The :class:`~cmsim.rig.OperatingPoint` of a record (start speed for run-ups).

        Parameters
        ----------
        rec : DatasetRecord
            A record of this spec (:meth:`record`).
        """
        p = rec.params
        return OperatingPoint(speed_rpm=p["speed_rpm"],
                              torque_nm=p.get("torque_nm", 0.0) if self.rig.gears else 0.0,
                              radial_load_n=p.get("radial_load_n", 0.0))

    # ------------------------------------------------------------------ identity
    def to_dict(self):
        """JSON-ready dict of the resolved spec (the rig in full)."""
        return {"name": self.name, "records": self.n_records, "seed": self.seed,
                "rig": self.rig.to_dict(), "rig_source": self.rig_source,
                "sampling": self.sampling,
                "operating": {n: d.to_dict() for n, d in self.operating},
                "runup_share": self.runup_share,
                "runup_to_rpm": None if self.runup_to_rpm is None else self.runup_to_rpm.to_dict(),
                "healthy_share": self.healthy_share,
                "faults": [c.to_dict() for c in self.faults],
                "nuisances": {n: d.to_dict() for n, d in self.nuisances},
                "channels": list(self.channels), "fs_hz": self.fs_hz,
                "duration_s": self.duration_s, "warmup_s": self.warmup_s, "mesh": self.mesh,
                "substeps": self.substeps}

    @property
    def digest(self):
        """16-hex-digit hash of :meth:`to_dict` (stored with every record)."""
        text = json.dumps(self.to_dict(), sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def _int(key, v, lo, hi):
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise _err(key, f"must be an integer in [{lo}, {hi}], got {v!r}")
    return int(v)


def _float(key, v, lo, hi):
    v = _number(key, v)
    if not lo <= v <= hi:
        raise _err(key, f"must be in [{lo:g}, {hi:g}], got {v:g}")
    return v


def _share(key, v):
    return _float(key, v, 0.0, 1.0)


def _rig(table, base_dir):
    if "builtin" in table and "file" in table:
        raise _err("rig.file", "give builtin or file, not both")
    if "file" in table:
        path = Path(table["file"])
        if not path.is_absolute() and base_dir is not None:
            path = Path(base_dir) / path
        if not path.is_file():
            raise _err("rig.file", f"{path} does not exist")
        try:
            return Rig.load(path), str(table["file"])
        except ParameterError as exc:
            raise _err("rig.file", f"{path}: {exc}") from None
    name = table.get("builtin", "paper_2016")
    if name not in BUILTIN_RIGS:
        raise _err("rig.builtin", f"must be one of {sorted(BUILTIN_RIGS)}, got {name!r}")
    return BUILTIN_RIGS[name](), f"builtin:{name}"


def _fault_choice(key, table, rig):
    if not isinstance(table, dict):
        raise _err(key, "must be a table")
    kind = table.get("type")
    if kind not in FAULT_TYPES:
        raise _err(f"{key}.type", f"must be one of {sorted(FAULT_TYPES)}, got {kind!r}")
    cls = FAULT_TYPES[kind]
    names = {f.name for f in dataclasses.fields(cls)}
    comp_key = "bearing" if "bearing" in names else "gear" if "gear" in names else ""
    components = ()
    if comp_key:
        raw = table.get(comp_key)
        if raw is None:
            raw = list(rig.bearing_names) if comp_key == "bearing" else [1]
        raw = raw if isinstance(raw, list) else [raw]
        if not raw:
            raise _err(f"{key}.{comp_key}", "must not be empty")
        for i, c in enumerate(raw):
            if comp_key == "bearing" and c not in rig.bearing_names:
                raise _err(f"{key}.bearing[{i}]", f"unknown bearing {c!r}; this rig has "
                                                  f"{list(rig.bearing_names)}")
            if comp_key == "gear" and (rig.gears is None or c not in (1, 2)):
                raise _err(f"{key}.gear[{i}]", "must be 1 or 2 on a rig with gears"
                                               if rig.gears is not None else
                                               "this rig has no gears")
        components = tuple(raw)
    weight = _number(f"{key}.weight", table.get("weight", 1.0))
    if weight <= 0:
        raise _err(f"{key}.weight", f"must be > 0, got {weight:g}")
    fields = []
    for name, raw in table.items():
        if name in ("type", "weight", comp_key):
            continue
        if name not in names:
            raise _err(f"{key}.{name}", f"unknown field of {kind}; allowed: "
                                        f"{sorted(names - {comp_key})}")
        fields.append((name, Distribution.parse(f"{key}.{name}", raw)))
    severity = SEVERITY_FIELDS.get(kind)
    if severity in names and severity not in dict(fields):
        raise _err(f"{key}.{severity}", f"the severity of {kind} is required (a value or a "
                                        f"range)")
    choice = FaultChoice(kind, comp_key, components, tuple(fields), weight)
    # both ends of every range must make a valid fault on this rig
    for pick in (0, -1):
        kw = {n: d.extremes[pick] for n, d in fields}
        if comp_key:
            kw[comp_key] = components[0]
        try:
            check_faults(rig, [cls(**kw)])
        except ParameterError as exc:
            raise _err(f"{key}.{getattr(exc, 'param', None) or severity}",
                       f"{exc} (at the {'lower' if pick == 0 else 'upper'} end of the "
                       f"range)") from None
        except TypeError as exc:
            raise _err(key, str(exc)) from None
    return choice


def _channels(raw, rig):
    bearings = list(rig.bearing_names)
    allowed = {"tacho"} | {f"accel_{b}_{a}" for b in bearings for a in "xy"} | {
        f"F_{b}_{a}" for b in bearings for a in ("x", "y", "loa", "oloa")}
    if rig.gears is not None:
        allowed |= {"dte", "dte_um", "Fmesh_total"}
    if raw is None:
        raw = [f"accel_{bearings[0]}_y", "tacho"]
    if not isinstance(raw, list) or not raw:
        raise _err("sensor.channels", "must be a non-empty list of signal names")
    for i, c in enumerate(raw):
        if c not in allowed:
            raise _err(f"sensor.channels[{i}]", f"unknown channel {c!r} on this rig; allowed: "
                                                f"{sorted(allowed)}")
    if len(set(raw)) != len(raw):
        raise _err("sensor.channels", "names a channel twice")
    return tuple(raw)
