"""Generate a dataset from a :class:`~cmsim.datasets.dataset_spec.DatasetSpec`, resumably.

:func:`generate_dataset` runs the records that are missing from ``DIR`` through the same task
runner as sweeps (:func:`cmsim.datasets.pool.run_tasks`: local processes, or a Dask
cluster) and writes

* ``DIR/records/<id>.npz`` — one record: the spec's channels only, float32, at the sensor
  rate, and ``meta`` (JSON: the manifest row, rig, operating point, faults, their
  characteristic frequencies); written atomically by the worker;
* ``DIR/rows/<id>.json`` — the record's manifest row (a sidecar), written by the worker
  right after its record (also for a failed record, with its error);
* ``DIR/manifest.parquet`` — every row, one per record: the sidecars are consolidated into
  it (and then removed) at the end of a run and when one resumes, never after every
  record, so a 100 000-record dataset never rewrites a large file per record;
* ``DIR/dataset.json`` — the resolved spec and its digest.

Resuming is the same call: a record whose row says ``ok`` and whose file has the recorded
size, or whose row says ``failed``, is done; a record file without a row (killed between the
two writes) is adopted from the row kept in its own meta; anything else is run. ``verify``
also checks every file's SHA-256 (slower: it reads every file). Records depend only on (spec,
base seed, index), so they are bit-identical on any number of workers and on Dask.
"""

from __future__ import annotations

import io
import json
import math
import os
import sys
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cmsim._io import atomic_savez, atomic_write_bytes, atomic_write_text
from cmsim.dynamics import simulate
from cmsim.dynamics.profiles import SpeedProfile
from cmsim.faults import fault_frequencies
from cmsim.sensors import add_sensors
from cmsim.datasets.dataset_spec import DatasetSpec
from cmsim.datasets.lock import DirectoryLock
from cmsim.datasets.manifest import file_sha256
from cmsim.datasets.pool import check_start_method, check_workers, run_tasks
from cmsim.errors import ParameterError
from cmsim.frequencies import rig_frequencies

__all__ = ["generate_dataset", "DatasetSummary", "PARQUET_NAME", "RECORDS_DIR", "ROWS_DIR",
           "SPEC_NAME", "consolidate", "read_rows", "simulate_record"]

PARQUET_NAME = "manifest.parquet"
RECORDS_DIR = "records"
ROWS_DIR = "rows"
SPEC_NAME = "dataset.json"
_FORMAT = "cmsim-dataset"


@dataclass(frozen=True)
class DatasetSummary:
    """What :func:`generate_dataset` did.

    Attributes
    ----------
    dir : str
    records_total : int
        Records in the spec.
    records_written : int
        Records simulated and written by this call.
    records_skipped : int
        Records already done (ok or failed) before this call.
    records_failed : int
        Records of this call that failed (recorded with their error).
    workers : int
        Workers used (0 if nothing had to run).
    runner : str
        ``"local"`` or ``"dask"``.
    wall_s : float
        Wall time of the call, s.
    timing_s : dict
        Sums over this call's records, s: ``integration`` (the time loop), ``setup``
        (model, quasi-static start), ``sensors``, ``save``, ``busy`` (their total);
        ``resume`` (reading the manifest and sidecars), ``consolidate``.
    failed : tuple of (str, str)
        ``(record_id, error)`` of this call's failed records (at most 20).
    """

    dir: str
    records_total: int
    records_written: int
    records_skipped: int
    records_failed: int
    workers: int
    runner: str
    wall_s: float
    timing_s: dict
    failed: tuple = ()

    def to_dict(self):
        """JSON-ready dict."""
        return {"dir": self.dir, "manifest": str(Path(self.dir) / PARQUET_NAME),
                "records_total": self.records_total, "records_written": self.records_written,
                "records_skipped": self.records_skipped, "records_failed": self.records_failed,
                "workers": self.workers, "runner": self.runner, "wall_s": self.wall_s,
                **{f"{k}_s": v for k, v in self.timing_s.items()},
                "failed": [{"record_id": r, "error": e} for r, e in self.failed]}


# ---------------------------------------------------------------------- one record
def _frequency_columns(rig, op):
    fr = rig_frequencies(rig, op)
    out = {"shaft_hz": fr.fr1_hz, "gmf_hz": math.nan if fr.gmf_hz is None else fr.gmf_hz}
    for name in fr.bearing_names:
        b = fr.bearing(name)
        for key in ("bpfo", "bpfi", "bsf", "ftf"):
            out[f"{key}_hz_{name}"] = float(getattr(b, f"{key}_hz"))
    return out


def base_row(spec, rec):
    """The manifest row of a record before it is simulated (parameters and answer key)."""
    f = rec.fault
    row = {"record_id": rec.record_id, "index": rec.index, "seed": rec.sim_seed,
           "status": "pending", "error": None,
           "path": f"{RECORDS_DIR}/{rec.record_id}.npz", "wall_s": math.nan,
           "rig_name": spec.rig.name, "spec_digest": spec.digest,
           **{k: (float(v) if not isinstance(v, bool) else v) for k, v in rec.params.items()},
           "fault_label": rec.fault_label, "fault_component": rec.fault_component,
           "fault_severity": rec.fault_severity}
    row.setdefault("torque_nm", 0.0)
    row.setdefault("radial_load_n", 0.0)
    if f is not None:
        for k, v in f.to_dict().items():
            if k not in ("type", "bearing", "gear") and isinstance(v, (int, float)) \
                    and not isinstance(v, bool):
                row[f"fault_{k}"] = float(v)
    row.update(_frequency_columns(spec.record_rig(rec), spec.record_operating_point(rec)))
    return row


def _simulated_channels(channels):
    """The simulated signals a record's channels are made from: an accelerometer needs both
    force components of its bearing, the tacho the input shaft's rotation."""
    out = set()
    for c in channels:
        if c.startswith("accel_"):
            b = c.split("_")[1]
            out |= {f"F_{b}_x", f"F_{b}_y"}
        elif c == "tacho":
            out.add("theta_1b1")
        else:
            out.add(c)
    return sorted(out)


def simulate_record(spec, index):
    """Simulate record ``index`` of ``spec``: ``(signals, meta)`` with float32 signals of the
    spec's channels at the sensor rate, and the meta stored with it. Raises what
    :func:`cmsim.dynamics.simulate` raises (e.g. :class:`IntegrationDiverged`)."""
    rec = spec.record(index)
    rig = spec.record_rig(rec)
    op = spec.record_operating_point(rec)
    faults = ([rec.fault] if rec.fault is not None else []) + rec.nuisance_faults()
    profile = None
    if rec.params["runup"]:
        profile = SpeedProfile.ramp(op.speed_rpm, rec.params["end_speed_rpm"], spec.duration_s,
                                    start_s=spec.warmup_s)
    sensed = [c for c in spec.channels if c.startswith("accel_") or c == "tacho"]
    t0 = time.perf_counter()
    run = simulate(rig, op, spec.duration_s, mesh=spec.mesh, fs_hz=spec.fs_hz,
                   substeps=spec.substeps, seed=rec.sim_seed, warmup_s=spec.warmup_s,
                   faults=faults, profile=profile, record=_simulated_channels(spec.channels))
    t1 = time.perf_counter()
    if sensed:
        accel = [c.split("_") for c in sensed if c.startswith("accel_")]
        bearings = sorted({a[1] for a in accel}) or None
        directions = sorted({a[2] for a in accel}) or ("x", "y")
        run = add_sensors(run, path=rig.housing, noise_rms=rec.params["sensor_noise_m_s2"],
                          seed=rec.sim_seed, bearings=bearings, directions=directions)
    t2 = time.perf_counter()
    signals = {c: np.asarray(run[c], dtype=np.float32) for c in spec.channels}
    key = fault_frequencies(rig, op, [rec.fault]) if rec.fault is not None else {}
    meta = {"format": _FORMAT, "fs_hz": run.fs_hz, "t0_s": float(run.t[0]),
            "n_samples": int(run.t.size), "rig": rig.to_dict(),
            "operating_point": run.meta["operating_point"],
            "profile": None if profile is None else {"times_s": list(profile.times_s),
                                                     "speeds_rpm": list(profile.speeds_rpm)},
            "faults": [f.to_dict() for f in faults],
            "labels": {"fault_label": rec.fault_label, "fault_component": rec.fault_component,
                       "fault_severity": rec.fault_severity,
                       "faults": [rec.fault.to_dict()] if rec.fault is not None else [],
                       "fault_frequencies": key},
            "substeps": run.meta.get("substeps"), "sim_wall_s": float(run.meta["wall_s"]),
            "timing_s": {"integration": float(run.meta["wall_s"]),
                         "setup": t1 - t0 - float(run.meta["wall_s"]), "sensors": t2 - t1}}
    return signals, meta


def _run_record(spec, index, out_dir):
    """Worker task: simulate, write the record then its sidecar row; return the row."""
    start = time.perf_counter()
    out = Path(out_dir)
    rec = spec.record(index)
    row = base_row(spec, rec)
    path = out / row["path"]
    try:
        signals, meta = simulate_record(spec, index)
    except Exception as exc:               # noqa: BLE001 - a failed record, the rest go on
        row.update(status="failed", error=" ".join(f"{type(exc).__name__}: {exc}".split()),
                   wall_s=time.perf_counter() - start)
        if os.environ.get("CMSIM_DEBUG"):
            traceback.print_exc()
        _write_row(out, row)
        return row
    t_save = time.perf_counter()
    row.update(status="ok", n_samples=meta["n_samples"], fs_hz=meta["fs_hz"],
               integration_s=meta["timing_s"]["integration"],
               setup_s=meta["timing_s"]["setup"], sensors_s=meta["timing_s"]["sensors"])
    meta["row"] = row
    atomic_savez(path, meta=json.dumps(meta, default=_json_default), **signals)
    row["bytes"] = path.stat().st_size
    row["sha256"] = file_sha256(path)
    row["save_s"] = time.perf_counter() - t_save
    row["wall_s"] = time.perf_counter() - start
    _write_row(out, row)
    return row


def _json_default(obj):
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def _write_row(out, row):
    atomic_write_text(out / ROWS_DIR / f"{row['record_id']}.json",
                      json.dumps(row, default=_json_default, allow_nan=True))


# ---------------------------------------------------------------------- manifest
def read_rows(out_dir):
    """Every manifest row of ``out_dir`` as a DataFrame (Parquet plus unconsolidated
    sidecars; the latest row of a record wins), sorted by index; None if there is none."""
    import pandas as pd

    out = Path(out_dir)
    frames = []
    if (out / PARQUET_NAME).is_file():
        frames.append(pd.read_parquet(out / PARQUET_NAME))
    side = _read_sidecars(out)
    if side:
        frames.append(pd.DataFrame.from_records(side))
    if not frames:
        return None
    df = pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0]
    df = df.drop_duplicates("index", keep="last").sort_values("index", kind="stable")
    return df.reset_index(drop=True)


def _read_sidecars(out):
    rows = []
    folder = out / ROWS_DIR
    if not folder.is_dir():
        return rows
    for entry in os.scandir(folder):
        if entry.name.endswith(".json") and not entry.name.startswith("."):
            try:
                with open(entry.path, encoding="utf-8") as fh:
                    rows.append(json.load(fh))
            except (OSError, ValueError):   # half-written by a killed worker: rerun it
                continue
    return rows


def consolidate(out_dir):
    """Fold the sidecar rows into ``manifest.parquet`` (atomic), then remove them.

    Parameters
    ----------
    out_dir : str or Path
        The dataset folder.

    Returns
    -------
    int
        The number of rows in the manifest.
    """
    out = Path(out_dir)
    names = [e.name for e in os.scandir(out / ROWS_DIR)] if (out / ROWS_DIR).is_dir() else []
    names = [n for n in names if n.endswith(".json") and not n.startswith(".")]
    if not names and (out / PARQUET_NAME).is_file():
        import pyarrow.parquet as pq
        return pq.ParquetFile(out / PARQUET_NAME).metadata.num_rows
    df = read_rows(out)
    if df is None:
        return 0
    for col in df.columns:                 # mixed None/str columns stay strings
        if df[col].dtype == object and col not in ("runup",):
            df[col] = df[col].astype("string")
    buf = io.BytesIO()
    df.to_parquet(buf, engine="pyarrow", index=False)
    atomic_write_bytes(out / PARQUET_NAME, buf.getvalue())
    for n in names:
        (out / ROWS_DIR / n).unlink(missing_ok=True)
    return len(df)


# ---------------------------------------------------------------------- runner
def _open(spec, out, force):
    """Check (or write) ``dataset.json``: one spec per directory."""
    path = out / SPEC_NAME
    mine = {"format": _FORMAT, "version": 1, "digest": spec.digest,
            "spec": json.loads(json.dumps(spec.to_dict(), default=str))}
    if path.is_file():
        try:
            old = json.loads(path.read_text(encoding="utf-8"))
        except ValueError:
            old = {}
        if old.get("digest") != spec.digest:
            a, b = old.get("spec", {}), mine["spec"]
            diff = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k)) or ["format"]
            if not force:
                raise ParameterError(f"{out} holds a dataset of a different spec (differs in "
                                     f"{', '.join(diff)}); use another directory, or --force "
                                     f"to replace it", param="out")
            for sub in (RECORDS_DIR, ROWS_DIR):
                for p in (out / sub).glob("*"):
                    p.unlink()
            (out / PARQUET_NAME).unlink(missing_ok=True)
    atomic_write_text(path, json.dumps(mine, indent=1) + "\n")


def _done_indices(spec, out, verify):
    """Indices already done (ok with their file intact, or failed); adopts orphan files."""
    df = read_rows(out)
    done = set()
    if df is not None:
        df = df[df["spec_digest"] == spec.digest] if "spec_digest" in df else df.iloc[:0]
        status = df["status"].to_numpy()
        idx = df["index"].to_numpy()
        paths = df["path"].to_numpy()
        sizes = df["bytes"].to_numpy() if "bytes" in df else np.full(len(df), np.nan)
        sums = df["sha256"].to_numpy() if "sha256" in df else [None] * len(df)
        for i, st, p, size, digest in zip(idx, status, paths, sizes, sums):
            if int(i) >= spec.n_records:
                continue
            if st == "failed":
                done.add(int(i))
            elif st == "ok":
                try:
                    ok = os.stat(out / p).st_size == size
                except OSError:
                    ok = False
                if ok and verify:
                    ok = file_sha256(out / p) == digest
                if ok:
                    done.add(int(i))
    adopted = 0
    for entry in os.scandir(out / RECORDS_DIR):
        name = entry.name
        if not name.endswith(".npz") or name.startswith(".") or not name[:-4].isdigit():
            continue
        index = int(name[:-4])
        if index in done or index >= spec.n_records:
            continue
        row = _row_in_file(Path(entry.path), spec)
        if row is not None:
            _write_row(out, row)
            done.add(index)
            adopted += 1
    return done, adopted


def _row_in_file(path, spec):
    """The row kept in a complete record file of ``spec``, or None."""
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            row = meta["row"]
            if row.get("spec_digest") != spec.digest:
                return None
            for c in spec.channels:        # every array readable (CRC checked)
                z[c]
    except Exception:                      # noqa: BLE001 - unreadable: rerun it
        return None
    row["bytes"] = path.stat().st_size
    row["sha256"] = file_sha256(path)
    return row


def _warm_kernels(spec, pending):
    """Compile/load the kernels here before forking workers: a 3-sample run of the first
    pending record of each fault label (faulty bearings take their own kernels)."""
    seen = set()
    for i in pending[:200]:
        rec = spec.record(i)
        if rec.fault_label in seen:
            continue
        seen.add(rec.fault_label)
        try:
            simulate(spec.record_rig(rec), spec.record_operating_point(rec), 3.0 / spec.fs_hz,
                     mesh=spec.mesh, fs_hz=spec.fs_hz, substeps=spec.substeps, seed=0,
                     warmup_s=0.0, faults=[rec.fault] if rec.fault is not None else ())
        except Exception:                  # noqa: BLE001 - the record reports it
            pass


def generate_dataset(spec, out_dir, *, workers=None, scheduler=None, progress=None,
                     start_method=None, verify=False, force=False, on_record_done=None):
    """Generate every record of ``spec`` that ``out_dir`` does not hold yet.

    Parameters
    ----------
    spec : DatasetSpec
        The recipe (:meth:`DatasetSpec.load` reads a TOML file).
    out_dir : str or path-like
        Dataset directory (created).
    workers : int, optional
        Local worker processes (1-256; default ``os.cpu_count()``).
    scheduler : str or distributed.Client, optional
        Run on a ``dask.distributed`` cluster (its workers must see ``out_dir``).
    progress : bool, optional
        tqdm bar on stderr; default: only if stderr is a terminal.
    start_method : {"fork", "spawn", "forkserver"}, optional
        Local process start method.
    verify : bool
        Check the SHA-256 of every finished record on resume (reads every file).
    force : bool
        Replace a dataset of a different spec in ``out_dir``.
    on_record_done : callable, optional
        ``on_record_done(row)`` after each record (an exception stops the run; the finished
        records are kept).

    Returns
    -------
    DatasetSummary

    Raises
    ------
    ParameterError
        Bad arguments, a directory holding another spec or in use by another run.
    cmsim.datasets.pool.Interrupted
        On Ctrl-C or SIGTERM (finished records are kept; rerun to resume).
    """
    if not isinstance(spec, DatasetSpec):
        raise ParameterError(f"spec must be a DatasetSpec, got {type(spec).__name__}",
                             param="spec")
    workers = check_workers(workers)
    method = check_start_method(start_method)
    if progress is None:
        progress = sys.stderr.isatty()
    start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with DirectoryLock(out):
        (out / RECORDS_DIR).mkdir(exist_ok=True)
        (out / ROWS_DIR).mkdir(exist_ok=True)
        for sub in (RECORDS_DIR, ROWS_DIR):
            for tmp in (out / sub).glob(".*.tmp"):     # left by a killed worker
                tmp.unlink(missing_ok=True)
        _open(spec, out, force)
        done, _ = _done_indices(spec, out, verify)
        t_resume = time.perf_counter() - start
        pending = [i for i in range(spec.n_records) if i not in done]
        rows = []

        def record(key, row):
            rows.append(row)
            if on_record_done is not None:
                on_record_done(row)

        n_workers = 0
        try:
            if pending:
                if scheduler is None and method == "fork":
                    _warm_kernels(spec, pending)
                tasks = [(f"{i:06d}", (spec, i, str(out))) for i in pending]
                n_workers = run_tasks(_run_record, tasks, record, workers=workers,
                                      start_method=method, scheduler=scheduler,
                                      progress=progress, desc=f"dataset {spec.name}",
                                      unit="rec", postfix=lambda k, r: r["status"])
        finally:
            t_c = time.perf_counter()
            consolidate(out)
            t_consolidate = time.perf_counter() - t_c
    timing = {"integration": 0.0, "setup": 0.0, "sensors": 0.0, "save": 0.0, "busy": 0.0}
    for r in rows:
        for k in ("integration", "setup", "sensors", "save"):
            v = r.get(f"{k}_s")
            timing[k] += float(v) if v is not None and v == v else 0.0
        timing["busy"] += float(r.get("wall_s") or 0.0)
    timing.update(resume=t_resume, consolidate=t_consolidate)
    failed = [r for r in rows if r["status"] == "failed"]
    return DatasetSummary(dir=str(out), records_total=spec.n_records,
                          records_written=sum(r["status"] == "ok" for r in rows),
                          records_skipped=len(done), records_failed=len(failed),
                          workers=n_workers, runner="dask" if scheduler is not None else "local",
                          wall_s=time.perf_counter() - start, timing_s=timing,
                          failed=tuple((r["record_id"], r["error"]) for r in failed[:20]))
