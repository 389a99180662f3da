"""The TOML form of a dataset spec: its tables, read into :class:`DatasetSpec` keywords.

A spec file (``datasets/*.toml`` holds the standard ones) has these tables; every key is
checked, and a bad spec is refused before any work with a message naming the key
(``operating.speed_rpm.max``)::

    [dataset]      name, records (number of records; a grid's default: its points × repeats),
                   seed (base seed), seed_policy = "per_run" | "shared", repeats (grid)
    [rig]          builtin = "paper_2016" | "cwru_6205" | "mfpt_nice", or file = "rig.toml"
                   (relative to the spec file)
    [operating]    sampling = "random" | "grid"; speed_rpm, torque_nm, friction, clearance_m,
                   radial_load_n, or any other setting a variation may name
                   (:mod:`cmsim.datasets.variation`: ``radial_load_angle_rad``, a quoted
                   dotted rig field such as ``"lubricant.dynamic_viscosity_pa_s"``);
                   runup_share (share of run-up records), runup_to_rpm (end speed of a
                   run-up over the recorded duration)
    [faults]       healthy_share; [[faults.types]] with type (catalogue name), the
                   component (bearing = [...] or gear = [...], one drawn per record), weight,
                   and any field of the fault as a value (its main size is the severity)
    [nuisances]    sensor_noise_m_s2, speed_wobble (relative amplitude of a speed
                   fluctuation), speed_wobble_hz (default: the input shaft rate), slip
                   (relative cage-speed fluctuation, a rolling_slip), housing_mode_hz and
                   housing_damping (drawn once per mode of ``rig.housing``: the transfer
                   path's resonances and damping ratios; absent = the rig's)
    [sensor]       channels (accel_<bearing>_<x|y>, tacho, F_<bearing>_<x|y|loa|oloa>, dte,
                   dte_um, Fmesh_total; or "all": the simulated run in full, as a sweep
                   keeps it), fs_hz (output rate; the integration step is chosen from the
                   model's highest mode and fastest excitation, and the output is anti-alias
                   decimated), duration_s,
                   warmup_s (simulated and dropped); the defaults are cmsim.rig.SAMPLING's
                   (75 kHz, 1 s, 0.05 s), as for simulate and sweep
    [simulation]   mesh (tooth contact model name), substeps (integration steps per sample;
                   default automatic), losses (true: every loss source in every run)
    [machine]      file = "MACHINE.toml" (``cmsim calibrate --out``; relative to the spec
                   file): the records are made on the machine's rig at its sample rate, and
                   its channel (e.g. ``DE``; the default channels are it and ``tacho``) is the
                   model force through the machine's calibrated path plus its background,
                   at the machine's speed and load where ``[operating]`` leaves them out
                   (:func:`machine_operating`); leave ``[rig]`` out

Values are :class:`~cmsim.datasets.distribution.Distribution` s: a number (constant), a list
(grid values; drawn uniformly under random sampling) or a distribution table.
"""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

from cmsim.datasets.distribution import Distribution, spec_error
from cmsim.datasets.plan import NUISANCES, FaultChoice
from cmsim.datasets.variation import OPERATING_POINT_FIELDS, RIG_TRANSFORMS, setting_kind
from cmsim.errors import ParameterError
from cmsim.machine import Machine
from cmsim.rig import PRESETS, RANGES, SAMPLING, Rig

__all__ = ["read_toml", "toml_keywords", "load_rig", "load_machine", "check_channels", "setting_range",
           "OPERATING_DEFAULTS", "machine_operating", "through_machine", "MACHINE_OWNS"]


def machine_operating(machine):
    """The operating settings a machine brings, as calibrated (its speed, its load: a
    bearing rig's radial load, a gear rig's torque): what its records default to."""
    out = {"speed_rpm": machine.op.speed_rpm, "radial_load_n": machine.op.radial_load_n}
    if machine.rig.gears is not None:
        out["torque_nm"] = machine.op.torque_nm
    return out


#: Operating settings a TOML spec always has (with these values when it leaves them out),
#: and the order in which a record draws the named operating settings.
OPERATING_DEFAULTS = {"speed_rpm": 1000.0, "torque_nm": 0.0, "friction": None,
                      "clearance_m": None, "radial_load_n": 0.0}

_TABLES = {"dataset": {"name", "records", "seed", "seed_policy", "repeats"},
           "rig": {"builtin", "file"},
           "operating": {"sampling", "runup_share", "runup_to_rpm"},
           "faults": {"healthy_share", "types"}, "nuisances": set(NUISANCES),
           "sensor": {"channels", "fs_hz", "duration_s", "warmup_s"},
           "simulation": {"mesh", "substeps", "losses"}, "machine": {"file"}}

#: DatasetSpec keyword -> its TOML key (errors of the constructor are renamed to these).
_TOML_KEYS = {"name": "dataset.name", "records": "dataset.records", "seed": "dataset.seed",
              "seed_policy": "dataset.seed_policy", "repeats": "dataset.repeats",
              "sampling": "operating.sampling", "runup_share": "operating.runup_share",
              "runup_to_rpm": "operating.runup_to_rpm",
              "healthy_share": "faults.healthy_share", "fault_types": "faults.types",
              "channels": "sensor.channels", "fs_hz": "sensor.fs_hz",
              "duration_s": "sensor.duration_s", "warmup_s": "sensor.warmup_s",
              "mesh": "simulation.mesh", "substeps": "simulation.substeps",
              "losses": "simulation.losses"}


def setting_range(name):
    """The :data:`cmsim.rig.RANGES` entry of a setting, or None (a dotted rig field is
    checked by its component).

    Parameters
    ----------
    name : str
        Setting name.
    """
    if name in OPERATING_POINT_FIELDS or name in RIG_TRANSFORMS:
        return RANGES.get(name)
    return None


def read_toml(path):
    """The parsed TOML of a spec file (errors say what is wrong with the file).

    Parameters
    ----------
    path : str or Path
        The spec file.

    Returns
    -------
    dict
    """
    try:
        return tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"not valid TOML ({exc})") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(f"not a text file ({exc})") from None


def toml_key(param, settings=()):
    """The TOML key of a :class:`DatasetSpec` keyword or setting named in an error.

    Parameters
    ----------
    param : str
        The error's parameter (``"records"``, ``"channels[0]"``, ``"torque_nm"``).
    settings : iterable of str
        The spec's setting names (under ``[operating]``).
    """
    head, sep, rest = param.partition("[")
    if head in _TOML_KEYS:
        return _TOML_KEYS[head] + sep + rest
    if head in NUISANCES:
        return f"nuisances.{param}"
    if head in settings:
        return f"operating.{param}"
    return param


def toml_keywords(data, base_dir=None):
    """:class:`~cmsim.datasets.spec.DatasetSpec` keywords of a parsed TOML spec.

    Parameters
    ----------
    data : dict
        The parsed spec.
    base_dir : str or Path, optional
        Folder a rig ``file`` is relative to.

    Returns
    -------
    dict
        Keywords for ``DatasetSpec(**kw)`` (the settings under ``variations``).
    """
    if not isinstance(data, dict):
        raise ParameterError(f"a dataset spec must be a table, got {type(data).__name__}")
    if "format_version" in data:            # a rig's or a machine's file, never a spec's
        raise spec_error("format_version", "a key of a rig or machine file, not of a dataset "
                                           "spec (a spec names its rig in [rig] file = ..., its "
                                           "machine in [machine] file = ...)")
    for key in data:
        if key not in _TABLES:
            what = f"unknown {'table' if isinstance(data[key], dict) else 'key'}"
            raise spec_error(key, f"{what}; allowed tables: {sorted(_TABLES)}")
        if not isinstance(data[key], dict):
            raise spec_error(key, "must be a table")
        for sub in data[key]:
            if sub not in _TABLES[key] and key != "operating":
                raise spec_error(f"{key}.{sub}", f"unknown key; allowed: {sorted(_TABLES[key])}")
    ds = data.get("dataset", {})
    machine = load_machine(data["machine"], base_dir) if "machine" in data else None
    if machine is not None and "rig" in data:
        raise spec_error("rig", "a [machine] brings its rig; leave [rig] out")
    rig, source = ((machine.rig, f"machine:{machine.name}") if machine is not None
                   else load_rig(data.get("rig", {}), base_dir))
    op = data.get("operating", {})
    sampling = op.get("sampling", "random")
    # a machine's records default to its own speed and load (DatasetSpec fixes them)
    brought = machine_operating(machine) if machine is not None else {}
    named = [n for n in OPERATING_DEFAULTS if n in op or (OPERATING_DEFAULTS[n] is not None
                                                          and n not in brought)]
    others = [n for n in op if n not in OPERATING_DEFAULTS and n not in _TABLES["operating"]]
    settings = []
    for name in named + others:
        key = f"operating.{name}"
        try:
            setting_kind(name, rig)
        except ParameterError as exc:
            raise spec_error(key, str(exc)) from None
        if name == "torque_nm" and name in op and rig.gears is None:
            raise spec_error(key, "needs a rig with gears (a bearing rig is loaded by "
                                  "radial_load_n)")
        dist = Distribution.parse(key, op.get(name, OPERATING_DEFAULTS.get(name)),
                                  setting_range(name))
        if sampling == "grid" and dist.kind not in ("constant", "choice"):
            raise spec_error(key, "grid sampling takes a number or a list")
        settings.append((name, dist))
    runup = op.get("runup_to_rpm")
    fl = data.get("faults", {})
    types = fl.get("types", [])
    if not isinstance(types, list):
        raise spec_error("faults.types", "must be a list of tables ([[faults.types]])")
    nz = data.get("nuisances", {})
    sensor = data.get("sensor", {})
    channels = sensor.get("channels")
    if machine is not None:
        _check_through_machine(machine, channels, nz)
    sim = data.get("simulation", {})
    return dict(
        variations=settings, sampling=sampling, name=ds.get("name", "dataset"),
        records=ds.get("records"), seed=ds.get("seed", SAMPLING.seed),
        seed_policy=ds.get("seed_policy", "per_run"), repeats=ds.get("repeats", 1),
        rig=rig, rig_source=source, runup_share=op.get("runup_share", 0.0),
        runup_to_rpm=None if runup is None else Distribution.parse(
            "operating.runup_to_rpm", runup, RANGES["speed_rpm"]),
        fault_types=tuple(FaultChoice.parse(f"faults.types[{i}]", t, rig)
                          for i, t in enumerate(types)),
        healthy_share=fl.get("healthy_share"),
        nuisances={n: Distribution.parse(f"nuisances.{n}", nz[n], NUISANCES[n])
                   for n in NUISANCES if n in nz},
        channels=(None if channels == "all" else channels if channels is not None else
                  [f"accel_{rig.bearing_names[0]}_y" if machine is None else machine.channel,
                   "tacho"]),
        fs_hz=sensor.get("fs_hz", SAMPLING.fs_hz if machine is None else machine.fs_hz),
        machine=machine,
        duration_s=sensor.get("duration_s", SAMPLING.duration_s),
        warmup_s=sensor.get("warmup_s", SAMPLING.warmup_s), mesh=sim.get("mesh"),
        substeps=sim.get("substeps"), losses=sim.get("losses"))


#: Nuisances a machine's own path and background replace: a spec through a machine that
#: draws them would draw a housing and a sensor noise its records never go through.
MACHINE_OWNS = ("housing_mode_hz", "housing_damping", "sensor_noise_m_s2")


def through_machine(data, machine_file):
    """A spec's TOML table made through a machine: ``[rig]`` replaced by ``[machine] file =
    machine_file``, the nuisances the machine owns (:data:`MACHINE_OWNS`) and the sensor's
    channels left out (the machine brings its path, background and channel).

    Parameters
    ----------
    data : dict
        A spec's table (:func:`read_toml`); not changed.
    machine_file : str or Path
        A machine file (``cmsim calibrate --out``).

    Returns
    -------
    dict
    """
    out = copy.deepcopy(data)
    out.pop("rig", None)
    out["machine"] = {"file": str(machine_file)}
    for n in MACHINE_OWNS:
        out.get("nuisances", {}).pop(n, None)
    out.get("sensor", {}).pop("channels", None)
    return out


def _check_through_machine(machine, channels, nuisances):
    """Through a machine, a record's channel is the machine's and the path and background
    are its own: a spec that names another accelerometer, or draws a housing or a sensor
    noise, is refused naming the key (a stock spec with a ``[machine]`` added kept
    ``accel_1b1_y`` and its housing nuisances, and evaluate then refused its records)."""
    for i, c in enumerate(channels or ()):
        if isinstance(c, str) and c.startswith("accel_"):
            raise spec_error(f"sensor.channels[{i}]",
                             f"{c!r} is the model's housing accelerometer; through a [machine] "
                             f"the record's channel is the machine's ({machine.channel!r}), "
                             "its path and background the machine's own")
    for n in MACHINE_OWNS:
        if n in nuisances:
            raise spec_error(f"nuisances.{n}",
                             "through a [machine] the transfer path and the background are "
                             "the machine's own (calibrated on its baseline); leave it out")


def _spec_file(key, name, base_dir):
    """The file a spec key names (relative to the spec's folder), which must exist."""
    path = Path(name)
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    if not path.is_file():
        raise spec_error(key, f"{path} does not exist")
    return path


def load_machine(table, base_dir):
    """The calibrated machine of a ``[machine]`` table (``{"file": path}``).

    Parameters
    ----------
    table : dict
        ``{"file": "MACHINE.toml"}``.
    base_dir : str or Path or None
        Folder a relative ``file`` is in.
    """
    if "file" not in table:
        raise spec_error("machine.file", "is required (a machine file of cmsim calibrate)")
    path = _spec_file("machine.file", table["file"], base_dir)
    try:
        return Machine.load(path)
    except ParameterError as exc:
        raise spec_error("machine.file", f"{path}: {exc}") from None


def load_rig(table, base_dir):
    """The rig of a ``[rig]`` table and where it came from (``"builtin:<name>"`` or the file).

    Parameters
    ----------
    table : dict
        ``{"builtin": name}`` or ``{"file": path}`` (default: the paper's rig).
    base_dir : str or Path or None
        Folder a relative ``file`` is in.
    """
    if "builtin" in table and "file" in table:
        raise spec_error("rig.file", "give builtin or file, not both")
    if "file" in table:
        path = _spec_file("rig.file", table["file"], base_dir)
        try:
            return Rig.load(path), str(table["file"])
        except ParameterError as exc:
            raise spec_error("rig.file", f"{path}: {exc}") from None
    name = table.get("builtin", "paper_2016")
    if name not in PRESETS:
        raise spec_error("rig.builtin", f"must be one of {sorted(PRESETS)}, got {name!r}")
    return PRESETS[name](), f"builtin:{name}"


def check_channels(raw, rig, machine=None):
    """``raw`` as a tuple of channel names this rig can give (None: the run in full).

    Parameters
    ----------
    raw : sequence of str or None
        Channel names.
    rig : cmsim.rig.Rig
        The spec's rig.
    machine : cmsim.machine.Machine, optional
        A calibrated machine, whose channel is one more.
    """
    if raw is None:
        return None
    bearings = list(rig.bearing_names)
    allowed = {"tacho"} | {f"accel_{b}_{a}" for b in bearings for a in "xy"} | {
        f"F_{b}_{a}" for b in bearings for a in ("x", "y", "loa", "oloa")}
    if rig.gears is not None:
        allowed |= {"dte", "dte_um", "Fmesh_total"}
    if machine is not None:
        allowed.add(machine.channel)
    if isinstance(raw, (str, bytes)) or not hasattr(raw, "__iter__") or not list(raw):
        raise ParameterError('channels must be a non-empty list of signal names (or "all")',
                             param="channels")
    raw = list(raw)
    for i, c in enumerate(raw):
        if c not in allowed:
            raise ParameterError(f"channels[{i}]: unknown channel {c!r} on this rig; "
                                 f"allowed: {sorted(allowed)}", param=f"channels[{i}]")
    if len(set(raw)) != len(raw):
        raise ParameterError("channels names a channel twice", param="channels")
    return tuple(raw)
