"""Data out of cmsim: a run or a dataset as signal files (:func:`export`), and a dataset in the
schema of the ``bearing-datasets`` index (:func:`to_bearing_datasets`).

Signal files (``cmsim export``)
-------------------------------
:func:`export` writes a saved run or a generated dataset into a new folder, in one of
:data:`SIGNAL_FORMATS`: the run, or each record of a dataset, as one file
``<name>.<format>`` holding its channels, with the sample rate and each channel's unit where
the format has a place for them. Each is written by
:func:`cmsim.measured.readers.write_signals`, the writer beside the reader of its format (that
module's docstring gives each layout), so an exported file reads back through
:func:`cmsim.measured.readers.read_file` with the same samples, rate and units; a ``wav``
holds float32 at full scale, its calibration factor, channels and units in cmsim's
``LIST``/``INFO`` comment. Float32 samples (a dataset's records) stay float32 in ``npz``,
``mat`` and ``tdms``. Each export also writes

* ``metadata.json`` — the measured-record schema of ``../shared/datasets/README.md``,
  written and checked by :func:`cmsim.measured.importing.write_folder_metadata` (the writer of
  ``cmsim import``): the sample rate, each channel's unit (``sensors``), the rig's
  ``geometry`` (:func:`cmsim.measured.schema.rig_geometry`: bearings and gears, so the files
  read back in ``cmsim spectrum`` and ``compare`` with no ``--rig``), one ``recordings[]``
  entry per file with its operating point and the answer key (``condition`` ``healthy`` or
  ``faulty``, ``fault`` the fault type, ``fault_component``, ``fault_severity`` the main size
  in SI; a run of ``cmsim simulate`` takes it from its faults, a dataset record from its
  labels);
* for a dataset, ``labels.csv`` — one row per record: ``record_id``, ``file``, ``label``,
  ``fault_component``, ``severity``, operating point, ``fs_hz``, ``n_samples``, ``group``,
  ``split`` (:func:`cmsim.datasets.windows.split_of`).

A dataset exported as ``parquet`` is the windowed layout instead
(:mod:`cmsim.datasets.windows`, ``windows.parquet``) and nothing else: every window carries
its record's labels (label, severity, operating point, group, split), so the folder loads as
one table (``pandas.read_parquet(out)``, ``pyarrow.dataset.dataset(out)``, HuggingFace
``load_dataset("parquet", data_dir=out)``); a single run has no windowed layout and is
refused as ``parquet``. The
default channels are those a real machine could measure (:func:`cmsim.run.is_measurable`).
The folder is assembled beside ``out`` and renamed into place when complete: an interrupted
export leaves no ``out``; an existing ``out`` is replaced only with ``force``, and never when
it is, holds or lies in the source.

Bearing-datasets schema
-----------------------
One Parquet row per signal, so cmsim data mix with public bearing datasets.

Columns (one row per record and vibration channel):

* ``dataset``, ``signal_id`` (``<dataset>/<record_id>/<channel>``), ``record_id``,
  ``channel``, ``unit`` (the channel's unit in ASCII: ``m/s^2`` for an acceleration, ``V``
  for the tacho), ``signal`` (list of float32), ``n_samples``, ``fs``
  (Hz), ``duration_s``;
* ``speed_rpm``, ``load`` (radial load on the bearing, N; the torque for a gear rig),
  ``load_unit``;
* ``fault_type`` (``"healthy"``, ``"localized"`` for race/ball defects, else the cmsim fault
  name), ``fault_location`` (``"none"``, ``"inner_race"``, ``"outer_race"``, ``"ball"``,
  ``"gear"``, ``"bearing"``), ``fault_size_mm`` (the fault's main size, mm; NaN when
  healthy), ``fault_severity_level`` (0 healthy, 1-3 the tertile of the size among the
  records of the same fault label);
* ``bpfo``, ``bpfi``, ``bsf``, ``ftf``: the bearing's defect frequencies in shaft orders
  (BSF = ball spin, one race), of the faulty bearing or the first one;
* ``bearing_id`` (virtual: ``cmsim:<rig>:<bearing>:<record_id>``), ``fault_origin``
  (``"simulated"``), ``rig``.
"""

from __future__ import annotations

import io
import json
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_bytes, atomic_write_text, finite, staging_dir
from cmsim.datasets.load import Dataset, load
from cmsim.datasets.plan import fault_answer_key
from cmsim.datasets.windows import check_fractions, split_of
from cmsim.errors import ParameterError, check_choice
from cmsim.faults import fault_from_dict
from cmsim.measured.importing import write_folder_metadata
from cmsim.measured.readers import WRITERS, write_signals
from cmsim.measured.schema import rig_geometry
from cmsim.rig import Rig
from cmsim.run import Run, is_measurable, signal_info

__all__ = ["export", "FORMATS", "SIGNAL_FORMATS", "to_bearing_datasets",
           "bearing_datasets_frame"]

#: Signal-file formats (the file suffix is ``.<format>``): every format of
#: :data:`cmsim.measured.readers.WRITERS` (``.unv`` is ``.uff`` under another name); each
#: reads back through :func:`cmsim.measured.readers.read_file`.
SIGNAL_FORMATS = tuple(s.lstrip(".") for s in WRITERS if s != ".unv")

#: Formats of :func:`export`: the signal formats, and ``parquet`` (a dataset's windows).
FORMATS = SIGNAL_FORMATS + ("parquet",)

_LOCAL = {"inner_race", "outer_race", "ball"}
_GEAR = {"tooth_crack", "tooth_spall", "tooth_breakage", "eccentricity", "profile_error"}


def _location(label):
    if label == "healthy":
        return "none"
    if label in _LOCAL:
        return label
    if label in _GEAR:
        return "gear"
    return "bearing" if label in ("wear", "off_size_ball") else label


def bearing_datasets_frame(dataset, channels=None):
    """The rows of :func:`to_bearing_datasets` as a DataFrame.

    Parameters
    ----------
    dataset : cmsim.datasets.Dataset or str or Path
    channels : sequence of str, optional
        Default: every ``accel_*`` channel.

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    ds = load(dataset) if isinstance(dataset, (str, Path)) else dataset
    chans = list(channels) if channels else [c for c in ds.channels if c.startswith("accel_")]
    if not chans:
        raise ParameterError("channels: the dataset has no accel_* channel", param="channels")
    for c in chans:
        if c not in ds.channels:
            raise ParameterError(f"channels: {c!r} is not in {list(ds.channels)}",
                                 param="channels")
    units = {c: ds.unit(c).replace("²", "^2").replace("µ", "u") for c in chans}
    man = ds.manifest[ds.manifest["status"] == "ok"].copy()
    level = np.zeros(len(man), int)
    for lab, idx in man.groupby("fault_label").groups.items():
        if lab == "healthy":
            continue
        sev = man.loc[idx, "fault_severity"].to_numpy(float)
        edges = np.nanquantile(sev, [1 / 3, 2 / 3]) if np.isfinite(sev).any() else [0, 0]
        pos = [man.index.get_loc(i) for i in idx]
        level[pos] = 1 + np.searchsorted(edges, sev, side="right")
    rows = []
    name = str((getattr(ds, "spec", None) or {}).get("name") or "cmsim")
    for k, (_, row) in enumerate(man.iterrows()):
        rec = ds.record(row["record_id"])
        comp = row.get("fault_component") or ""
        bf = rec.frequencies.bearing(comp if comp in rec.frequencies.bearings else None)
        fr = bf.shaft_hz
        label = row["fault_label"]
        gear = rec.rig.gears is not None
        sig = rec.signals
        for ch in chans:
            x = np.asarray(sig[ch], np.float32)
            rows.append({
                "dataset": name, "signal_id": f"{name}/{row['record_id']}/{ch}",
                "record_id": row["record_id"], "channel": ch, "unit": units[ch],
                "signal": x, "n_samples": int(x.size), "fs": float(rec.fs_hz),
                "duration_s": x.size / float(rec.fs_hz),
                "speed_rpm": float(row["speed_rpm"]),
                "load": float(row["torque_nm"] if gear else row["radial_load_n"]),
                "load_unit": "N m" if gear else "N",
                "fault_type": "healthy" if label == "healthy" else (
                    "localized" if label in _LOCAL else label),
                "fault_location": _location(label),
                "fault_size_mm": 1e3 * float(row["fault_severity"])
                if label in _LOCAL else math.nan,
                "fault_severity_level": int(level[k]),
                "bpfo": bf.bpfo_hz / fr, "bpfi": bf.bpfi_hz / fr, "bsf": bf.bsf_hz / fr,
                "ftf": bf.ftf_hz / fr,
                "bearing_id": f"cmsim:{rec.rig.name}:{comp or 'none'}:{row['record_id']}",
                "fault_origin": "simulated", "rig": rec.rig.name})
    return pd.DataFrame(rows)


def to_bearing_datasets(dataset, out, channels=None):
    """Write ``out`` (Parquet, atomically): one row per signal (module docstring).

    Parameters
    ----------
    dataset : cmsim.datasets.Dataset or str or Path
    out : str or Path
        The ``.parquet`` file to write.
    channels : sequence of str, optional

    Returns
    -------
    pathlib.Path
    """
    df = bearing_datasets_frame(dataset, channels)
    buf = io.BytesIO()
    df.to_parquet(buf, index=False)
    out = Path(out)
    atomic_write_bytes(out, buf.getvalue())
    return out


# ---------------------------------------------------------------------- signal files
def _write_signals(path, signals, rate_hz, units):
    """Write channels to one signal file (its format chosen by the suffix of ``path``, one of
    :data:`SIGNAL_FORMATS`), atomically, by :func:`cmsim.measured.readers.write_signals`: the
    writer beside each reader.

    Parameters
    ----------
    path : str or path-like
        The file, ``.<format>``.
    signals : dict of str to ndarray
        Channel name → samples, shape (n,) each (float32 samples stay float32 where the
        format stores the type: npz, mat, tdms).
    rate_hz : float
        Sample rate, Hz.
    units : dict of str to str
        Channel name → unit of its samples.

    Returns
    -------
    pathlib.Path
    """
    path = Path(path)
    check_choice("format", path.suffix.lower().lstrip("."), SIGNAL_FORMATS)
    return write_signals(path, signals, rate_hz, units)


def _source(source):
    """``("run", Run)`` or ``("dataset", Dataset)`` of a path (or either object)."""
    if isinstance(source, (Run, Dataset)):
        return ("run" if isinstance(source, Run) else "dataset"), source
    p = Path(source)
    if p.is_dir() and (p / "dataset.json").is_file():
        return "dataset", load(p)
    if p.is_file() and p.suffix.lower() == ".npz":
        try:
            return "run", Run.load(p)
        except Exception:  # noqa: BLE001 - any failure: not a run
            why = "is a .npz file but not a cmsim run"
    else:
        why = ("does not exist" if not p.exists() else "is a directory without dataset.json"
               if p.is_dir() else "is not a .npz file")
    raise ParameterError(f"source {p}: {why}; expected a run file (.npz of cmsim simulate "
                         f"--out) or a dataset directory (cmsim dataset --out)",
                         param="source", allowed="a run .npz or a dataset directory")


def _check_out(out, source, force):
    """``out`` is a new folder (or ``force`` and a folder) that neither is, holds nor lies in
    the source: replacing it must never remove what is being exported."""
    if out.exists() and not force:
        raise ParameterError(f"out {out}: exists; give force=True to replace it (or a new "
                             f"folder)", param="out", allowed="a new folder")
    if out.exists() and not out.is_dir():
        raise ParameterError(f"out {out}: is a file (expected a folder)", param="out",
                             allowed="a folder")
    if isinstance(source, (Run, Dataset)):
        source = getattr(source, "directory", None)
    if source is None:
        return
    src, dst = Path(source).resolve(), out.resolve()
    if dst == src or src in dst.parents or dst in src.parents:
        raise ParameterError(f"out {out}: is, holds or lies in the source {source}; export "
                             f"to a folder outside it", param="out",
                             allowed="a folder outside the source")


def _channels(available, channels):
    """The channels to export: those asked (each checked), else the measurable ones."""
    available = list(available)
    if channels:
        for c in channels:
            if c not in available:
                raise ParameterError(f"channels: {c!r} is not a channel of the source; "
                                     f"available: {available}", param="channels")
        return list(channels)
    chosen = [c for c in available if is_measurable(c)]
    if not chosen:
        raise ParameterError(f"channels: the source has no channel a real machine could "
                             f"measure (accelerations, tacho: cmsim simulate --sensors adds "
                             f"them); name the simulated ones to export; available: "
                             f"{available}", param="channels")
    return chosen


def _sensors(channels, units):
    out = {}
    for c in channels:
        try:
            info = signal_info(c)
            near = info.component if info.component[:1].isdigit() else "unknown"
            out[c] = {"near": near, "direction": info.direction or "unknown", "unit": units[c]}
        except ParameterError:
            out[c] = {"near": "unknown", "direction": "unknown", "unit": units[c]}
    return out


def _answer_key(label, component, severity):
    """The answer-key fields of a ``recordings[]`` entry, in the schema
    :func:`cmsim.measured.schema.label_of` reads: ``condition`` (``healthy`` or ``faulty``),
    ``fault`` (the fault type), ``fault_component`` (bearing or ``G<k>``), ``fault_severity``
    (the fault's main size, SI)."""
    healthy = label in (None, "healthy")
    return {"condition": "healthy" if healthy else "faulty",
            "fault": None if healthy else label, "fault_component": component or None,
            "fault_severity": None if healthy else severity}


def _run_answer_key(run):
    """The answer key of a run: a dataset record's labels, else the run's first fault
    (``meta["faults"]``; none: healthy), every fault's label in ``faults``."""
    labels = run.meta.get("labels")
    if labels:
        return _answer_key(labels.get("fault_label"), labels.get("fault_component"),
                           labels.get("fault_severity"))
    faults = run.meta.get("faults") or []
    if not faults:
        return _answer_key("healthy", "", None)
    first = fault_from_dict({k: v for k, v in faults[0].items() if k != "label"})
    return {**_answer_key(*fault_answer_key(first)),
            "faults": [f.get("label") or f.get("type") for f in faults]}


def _run_entry(file, run, channels):
    op = run.meta.get("operating_point") or {}
    return {"file": file, "n_samples": int(run.t.size), "fs_hz": run.fs_hz,
            "shaft_speed_rpm": op.get("speed_rpm"), "torque_nm": op.get("torque_nm"),
            "radial_load_n": op.get("radial_load_n"), "channels": list(channels),
            **_run_answer_key(run)}


def _write_metadata(stage, meta):
    """``metadata.json`` of the export, written (and checked) by the measured writer."""
    write_folder_metadata(stage / "metadata.json", finite(meta))


def export(source, out, fmt, channels=None, *, force=False, window=None, hop=None,
           group_by="record_id", seed=0, fractions=(0.8, 0.1, 0.1), name=None):
    """Write a run or a dataset into the new folder ``out`` (module docstring).

    Parameters
    ----------
    source : str or path-like or cmsim.run.Run or cmsim.datasets.Dataset
        A saved run (``.npz``) or a dataset directory.
    out : str or path-like
        The folder to make (it must not exist unless ``force``).
    fmt : str
        One of :data:`FORMATS`.
    channels : sequence of str, optional
        Channels to write (default: the measurable ones, :func:`cmsim.run.is_measurable`).
    force : bool
        Replace an existing ``out``.
    window, hop : int, optional
        Windows of the Parquet layout of a dataset (default window 2048, hop = window);
        only for ``fmt="parquet"`` and a dataset.
    group_by, seed, fractions
        Group and split keys of ``labels.csv`` and of the windows
        (:func:`cmsim.datasets.windows.to_parquet`).
    name : str, optional
        File name stem of a run (default: the run file's stem, or ``run``).

    Returns
    -------
    dict
        ``kind`` (``run`` or ``dataset``), ``format``, ``out``, ``files`` (written signal
        files), ``records``, ``channels``, ``units``, ``fs_hz``; for windows, ``windows``
        (:func:`~cmsim.datasets.windows.to_parquet`'s summary).
    """
    check_choice("format", fmt, FORMATS)
    out = Path(out)
    kind, src = _source(source)
    _check_out(out, source, force)
    if kind == "run" and fmt == "parquet":
        raise ParameterError(f"format parquet is the windowed layout of a dataset "
                             f"(windows.parquet); export a run as one of "
                             f"{', '.join(f for f in FORMATS if f != 'parquet')}",
                             param="format", allowed="a signal format for a run")
    windowed = kind == "dataset" and fmt == "parquet"
    for key, value in (("window", window), ("hop", hop)):
        if value is not None and not windowed:
            raise ParameterError(f"{key}: windows are cut only for the parquet format of a "
                                 f"dataset", param=key)
    if kind == "run" and group_by != "record_id":
        raise ParameterError("group_by: groups split the records of a dataset; a run has "
                             "none", param="group_by")
    check_fractions(fractions)
    out.parent.mkdir(parents=True, exist_ok=True)
    stage = staging_dir(out, ".export")
    try:
        if kind == "run":
            res = _export_run(src, stage, fmt, channels,
                              name or (Path(source).stem if not isinstance(source, Run)
                                       else "run"))
        else:
            res = _export_dataset(src, stage, fmt, channels, windowed, window, hop, group_by,
                                  seed, fractions, out.name)
        _replace_dir(stage, out)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    return {"kind": kind, "format": fmt, "out": str(out), **res}


def _replace_dir(stage, out):
    """Rename the finished ``stage`` to ``out``; an old ``out`` is moved away first and
    removed after."""
    old = None
    if out.exists():
        old = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".old", dir=out.parent))
        os.replace(out, old / "dir")
    os.replace(stage, out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _export_run(run, stage, fmt, channels, stem):
    chans = _channels(run.names, channels)
    units = {c: _run_unit(run, c) for c in chans}
    file = f"{stem}.{fmt}"
    _write_signals(stage / file, {c: run.signals[c] for c in chans}, run.fs_hz, units)
    rig = run.meta.get("rig")
    meta = {"dataset": stem, "source": "cmsim export", "fs_hz": run.fs_hz,
            "channels": {c: f"cmsim {run.source} signal {c}" for c in chans},
            "sensors": _sensors(chans, units),
            "geometry": rig_geometry(Rig.from_dict(rig)) if rig else None,
            "recordings": [_run_entry(file, run, chans)]}
    _write_metadata(stage, meta)
    return {"files": 1, "records": 1, "channels": chans, "units": units, "fs_hz": run.fs_hz}


def _run_unit(run, name):
    try:
        return signal_info(name).unit
    except ParameterError:
        machine = run.meta.get("machine") or {}
        return str(machine.get("unit") or "") if machine.get("channel") == name else ""


def _export_dataset(ds, stage, fmt, channels, windowed, window, hop, group_by, seed,
                    fractions, out_name):
    chans = ds.select_channels(channels or None)
    units = {c: ds.unit(c) for c in chans}
    if group_by not in ds.manifest.columns:
        raise ParameterError(f"group_by must be a manifest column {list(ds.manifest.columns)}, "
                             f"got {group_by!r}", param="group_by")
    res = {"channels": chans, "units": units, "fs_hz": ds.fs_hz, "records": len(ds)}
    if windowed:           # the windows carry every record's labels: Parquet alone, so
        res["windows"] = ds.to_parquet(   # the folder loads as a folder (pandas, pyarrow, HF)
            stage / "windows.parquet", window=2048 if window is None else window, hop=hop,
            channels=chans, group_by=group_by, seed=seed, fractions=fractions)
        res["windows"]["path"] = str(stage.parent / out_name / "windows.parquet")
        res["files"] = 1
        return res
    rows, entries, geometries = [], [], {}
    for rec in ds:
        r = rec.row
        file = f"{rec.record_id}.{fmt}"
        _write_signals(stage / file, {c: rec.signals[c] for c in chans}, rec.fs_hz, units)
        group = str(r[group_by])
        n = int(r["n_samples"]) if r.get("n_samples") is not None else None
        rows.append({"record_id": rec.record_id, "file": file, "label": r.get("fault_label"),
                     "fault_component": r.get("fault_component"),
                     "severity": r.get("fault_severity"), "speed_rpm": r.get("speed_rpm"),
                     "torque_nm": r.get("torque_nm"), "radial_load_n": r.get("radial_load_n"),
                     "fs_hz": rec.fs_hz, "n_samples": n, "group": group,
                     "split": split_of(group, seed, fractions)})
        entries.append({"file": file, "n_samples": n, "fs_hz": rec.fs_hz,
                        "shaft_speed_rpm": r.get("speed_rpm"), "torque_nm": r.get("torque_nm"),
                        "radial_load_n": r.get("radial_load_n"), "channels": chans,
                        **_answer_key(r.get("fault_label"), r.get("fault_component"),
                                      r.get("fault_severity"))})
        geometries.setdefault(json.dumps(rig_geometry(rec.rig), sort_keys=True), rec.record_id)
    import pandas as pd
    atomic_write_text(stage / "labels.csv", pd.DataFrame(
        rows, columns=["record_id", "file", "label", "fault_component", "severity",
                       "speed_rpm", "torque_nm", "radial_load_n", "fs_hz", "n_samples",
                       "group", "split"]).to_csv(index=False))
    name = str(ds.spec.get("name") or ds.directory.name)
    meta = {"dataset": name, "source": f"cmsim export of dataset {name}", "fs_hz": ds.fs_hz,
            "channels": {c: f"cmsim simulated {c}" for c in chans},
            "sensors": _sensors(chans, units),
            "geometry": json.loads(next(iter(geometries))) if geometries else None,
            "recordings": entries}
    if len(geometries) > 1:
        meta["geometry_note"] = (f"the records' rigs differ ({len(geometries)} bearing or gear "
                                 f"geometries): this is record "
                                 f"{next(iter(geometries.values()))}'s")
    _write_metadata(stage, meta)
    res["files"] = len(entries)
    return res
