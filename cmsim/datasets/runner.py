"""The one runner of specs (datasets and sweeps alike): :func:`generate_dataset`, resumably.

:func:`generate_dataset` runs the records of a :class:`~cmsim.datasets.spec.DatasetSpec`
that ``DIR`` does not hold yet through the task runner (:func:`cmsim.datasets.pool.run_tasks`:
local processes, or a Dask cluster), each worker writing its record file and its manifest row
(:mod:`cmsim.datasets.records`), and folds the rows into ``DIR/manifest.parquet``
(:mod:`cmsim.datasets.manifest`). One run per directory at a time
(:class:`~cmsim.datasets.lock.DirectoryLock`).

Resuming is the same call: finished records are kept, files half-written by a killed worker
(``.*.tmp``) are removed (also when a run ends: a Dask worker killed mid-write leaves one
while its task is retried elsewhere), a record file without a row is adopted from the row
kept in its meta, anything else is run. A Dask scheduler is connected to before anything is
written, and a directory the call created is removed again if the call fails before any
record is finished: a failed start leaves nothing behind. Ctrl-C or SIGTERM stops the
workers at once and raises :class:`~cmsim.datasets.pool.Interrupted` after the finished
records are recorded. A worker process that dies (killed, out of memory) costs only its
record: Dask retries it, a local pool is started again for the unfinished records. Records
depend only on (spec, base seed, index), so they are bit-identical on any number of workers
and on Dask.

Processes
    On Linux the pool forks after this process has loaded the numba kernels (a 3-sample
    run per fault label of the pending records), so workers start at once and do not
    compile; elsewhere it spawns, and each worker loads the kernels from numba's disk cache.
"""

from __future__ import annotations

import contextlib
import numbers
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cmsim.datasets.lock import DirectoryLock
from cmsim.datasets.manifest import (PARQUET_NAME, RECORDS_DIR, ROWS_DIR, SPEC_NAME, consolidate,
                                     done_indices, open_directory, read_rows)
from cmsim.datasets.pool import check_start_method, check_workers, run_tasks, scheduler_client
from cmsim.datasets.records import default_batch_size, run_records
from cmsim.datasets.spec import DatasetSpec
from cmsim.dynamics.batch import kernel_layout, simulate_batch
from cmsim.dynamics.simulation import integrate_prepared, prepare_run
from cmsim.errors import ParameterError, check_type
from cmsim.faults.compile import TOOTH_TABLE_FAULTS
from cmsim.sensors import housing_acceleration

__all__ = ["generate_dataset", "DatasetSummary"]

_TIMING_KEYS = ("integration", "setup", "sensors", "features", "save")


@dataclass(frozen=True)
class DatasetSummary:
    """What :func:`generate_dataset` did.

    Attributes
    ----------
    dir : str
        The dataset directory.
    records_total : int
        Records in the spec.
    records_written : int
        Records simulated and written by this call.
    records_skipped : int
        Records already done (ok or failed) before this call, adopted ones included.
    records_adopted : int
        Complete record files found without a row (or kept under ``force``), recorded.
    records_failed : int
        Records of this call that failed (recorded with their error).
    workers : int
        Workers used (0 if nothing had to run).
    runner : str
        ``"local"`` or ``"dask"``.
    start_method : str
        Local process start method.
    wall_s : float
        Wall time of the call, s.
    timing_s : dict
        Sums over this call's records, s: ``integration`` (the time loop), ``setup``
        (model, quasi-static start), ``sensors``, ``features`` (manifest features of
        full-run records), ``save``, ``busy`` (their total); ``warmup`` (this process's
        kernel loading before the workers start), ``resume`` (reading the manifest and
        sidecars), ``consolidate``.
    failed : tuple of (str, str)
        ``(record_id, error)`` of this call's failed records (at most 20).
    """

    dir: str
    records_total: int
    records_written: int
    records_skipped: int
    records_adopted: int
    records_failed: int
    workers: int
    runner: str
    start_method: str
    wall_s: float
    timing_s: dict
    failed: tuple = ()

    def to_dict(self):
        """JSON-ready dict (``integration_s`` etc. flattened from ``timing_s``, and
        ``utilisation`` = busy / (wall · workers))."""
        busy = self.timing_s.get("busy", 0.0)
        return {"dir": self.dir, "manifest": str(Path(self.dir) / PARQUET_NAME),
                "records_total": self.records_total, "records_written": self.records_written,
                "records_skipped": self.records_skipped,
                "records_adopted": self.records_adopted, "records_failed": self.records_failed,
                "workers": self.workers, "runner": self.runner,
                "start_method": self.start_method, "wall_s": self.wall_s,
                **{f"{k}_s": v for k, v in self.timing_s.items()},
                "utilisation": busy / (self.wall_s * self.workers) if self.workers else 0.0,
                "failed": [{"record_id": r, "error": e} for r, e in self.failed]}


def _batch_key(plan):
    """What records of one batch share, read from the plan: the kinds of their faults (and
    the bearing a bearing fault sits in; every fault of the per-tooth tables one kind) and
    whether it is a run-up — what sets the kernels' switches and table sizes
    (:func:`cmsim.dynamics.batch.kernel_layout` checks the rest)."""
    kinds = sorted((type(f).__name__, getattr(f, "bearing", None) or "")
                   for f in plan.faults if not isinstance(f, TOOTH_TABLE_FAULTS))
    if any(isinstance(f, TOOTH_TABLE_FAULTS) for f in plan.faults):
        kinds.append(("tooth tables", ""))
    return tuple(kinds), bool(plan.params["runup"])


def _batches(plans, workers, batch_size, batchable):
    """The pending records' plans in batches: records of one :func:`_batch_key` together, in
    index order, at most ``batch_size``, in parts of even size (no more than spreads the
    records over ``workers`` when known), the largest batches first; one by one for
    ``batch_size`` 1 and for a key the batch kernel does not take (``batchable[key]`` False:
    nothing to share, and an interruption then loses no finished run)."""
    size = batch_size
    if workers:
        size = max(1, min(size, -(-len(plans) // int(workers))))
    groups = {}
    for plan in plans:
        groups.setdefault(_batch_key(plan), []).append(plan)
    out = []
    for key, group in groups.items():
        step = size if batchable.get(key, False) else 1
        step = -(-len(group) // -(-len(group) // step))        # even parts
        out += [group[j:j + step] for j in range(0, len(group), step)]
    # the largest first, so the workers, each taking the next when it is free, finish
    # together (in index order, batches of 62 and of 39 records could leave one worker
    # with some 60 records more than the other)
    return sorted(out, key=lambda part: (-len(part), part[0].index))


def _first_runs(spec, plans):
    """``{batch key: RunSetup or None}``: a 3-sample run of the first record of each
    :func:`_batch_key` (None where it cannot be built: the record reports why)."""
    first = {}
    for plan in plans:
        first.setdefault(_batch_key(plan), plan)
    out = {}
    for key, plan in first.items():
        try:
            out[key] = prepare_run(spec.record_rig(plan), spec.record_operating_point(plan),
                                   3.0 / spec.fs_hz, mesh=spec.mesh, fs_hz=spec.fs_hz,
                                   substeps=spec.substeps, seed=0, warmup_s=0.0,
                                   faults=plan.faults, losses=spec.losses)
        except Exception:                  # noqa: BLE001 - the record reports it
            out[key] = None
    return out


def _warm_kernels(spec, setups, batch_size):
    """Compile/load the kernels here before forking workers: the 3-sample runs of
    :func:`_first_runs` as the workers will run them (alone on the single-run kernel for
    ``batch_size`` 1, else in a batch; faulty bearings take their own kernels), and the
    housing path's kernel when the records have accelerometers."""
    if any(c.startswith("accel_") for c in spec.channels or ()):
        try:
            housing_acceleration(np.zeros(8), spec.fs_hz, spec.rig.housing)
        except Exception:                  # noqa: BLE001 - the record reports it
            pass
    setups = [s for s in setups if s is not None]
    if batch_size > 1:
        simulate_batch(setups)
        return
    for setup in setups:
        try:
            integrate_prepared(setup)
        except Exception:                  # noqa: BLE001 - the record reports it
            pass


def generate_dataset(spec, out_dir, *, workers=None, scheduler=None, progress=None,
                     start_method=None, verify=False, force=False, on_record_done=None,
                     batch_size=None):
    """Generate every record of ``spec`` that ``out_dir`` does not hold yet.

    Parameters
    ----------
    spec : DatasetSpec
        The recipe (:meth:`DatasetSpec.load` reads a TOML file; a sweep is
        ``DatasetSpec([Variation(...), ...])``).
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
        Check the SHA-256 of every finished record on resume (reads every file; ``cmsim
        sweep`` always does).
    force : bool
        Replace a dataset of a different spec in ``out_dir`` (keeping the records the new
        spec makes again).
    on_record_done : callable, optional
        ``on_record_done(row)`` after each record (an exception stops the run; the finished
        records are kept).
    batch_size : int, optional
        Most records a worker integrates together in one time loop, fewer when that spreads
        the records over the workers (default
        :func:`~cmsim.datasets.records.default_batch_size`: 64 one-second 25.6-kHz records
        for a spec of 64 records or more, else 1; 1 is each record alone on the single-run
        kernel, the reference). A
        record's arrays are bit for bit the same for every batch size above 1, on any number
        of workers, resumed or not, and within 1e-9 of each signal's range of the single-run
        kernel's.

    Returns
    -------
    DatasetSummary

    Raises
    ------
    ParameterError
        Bad arguments, a directory holding another spec or in use by another run.
    cmsim.datasets.pool.Interrupted
        On Ctrl-C or SIGTERM (finished records are kept; rerun to resume).
    cmsim.errors.WorkersDied
        Worker processes kept dying (a local pool whose worker died is started again for
        the unfinished records, :data:`~cmsim.datasets.pool.POOL_RESTARTS` times; Dask
        retries on its own); finished records are kept.
    """
    check_type("spec", spec, DatasetSpec)
    workers = check_workers(workers)
    if batch_size is not None:
        if isinstance(batch_size, bool) or not isinstance(batch_size, numbers.Integral) \
                or not 1 <= batch_size <= 1024:
            raise ParameterError(f"batch_size must be a whole number in [1, 1024], got "
                                 f"{batch_size!r}", param="batch_size")
        batch_size = int(batch_size)
    method = check_start_method(start_method)
    if progress is None:
        progress = sys.stderr.isatty()
    start = time.perf_counter()
    out = Path(out_dir)
    with scheduler_client(scheduler) as client, _new_directory(out) as created, \
            DirectoryLock(out):
        try:
            return _generate(spec, out, start, workers=workers, client=client,
                             progress=progress, method=method, verify=verify, force=force,
                             on_record_done=on_record_done, batch_size=batch_size)
        except BaseException:
            if created:
                _remove_unfinished(out)
            raise


@contextlib.contextmanager
def _new_directory(out):
    """Create ``out`` (and its parents) while active; yield whether it is new. The
    directories it made are removed again if the run fails and leaves them empty
    (:func:`_remove_unfinished`)."""
    made = [d for d in (out, *out.parents) if not d.exists()]
    out.mkdir(parents=True, exist_ok=True)
    try:
        yield bool(made)
    except BaseException:
        for d in made:                             # innermost first
            try:
                d.rmdir()
            except OSError:                        # not empty: something was finished
                break
        raise


def _remove_unfinished(out):
    """In a directory this run created and that holds no finished record (no manifest, no
    record file), remove what the run wrote: the spec, the empty folders."""
    if (out / PARQUET_NAME).exists() or any((out / RECORDS_DIR).glob("*.npz")) \
            or any((out / ROWS_DIR).glob("*.json")):
        return
    for sub in (RECORDS_DIR, ROWS_DIR):
        shutil.rmtree(out / sub, ignore_errors=True)
    (out / SPEC_NAME).unlink(missing_ok=True)


def _remove_temporary(out):
    """Remove the ``.*.tmp`` files a killed worker left half-written."""
    for sub in (RECORDS_DIR, ROWS_DIR):
        for tmp in (out / sub).glob(".*.tmp"):
            tmp.unlink(missing_ok=True)


def _generate(spec, out, start, *, workers, client, progress, method, verify, force,
              on_record_done, batch_size=None):
    """The body of :func:`generate_dataset`, under the directory lock; ``client`` is the
    Dask client (``None``: local processes)."""
    for sub in (RECORDS_DIR, ROWS_DIR):
        (out / sub).mkdir(exist_ok=True)
    _remove_temporary(out)
    kept = open_directory(spec, out, force)
    # the manifest is read once: for what is done, then to fold this run's rows into
    known = read_rows(out)
    done, adopted = done_indices(spec, out, verify, known)
    adopted += kept
    t_resume = time.perf_counter() - start
    pending = [i for i in range(spec.n_records) if i not in done]
    rows = []

    def record_all(key, batch):
        for row in batch:
            rows.append(row)
            if on_record_done is not None:
                on_record_done(row)

    n_workers, t_warm = 0, 0.0
    try:
        if pending:
            plans = [spec.record(i) for i in pending]      # drawn once, here
            size = default_batch_size(spec) if batch_size is None else batch_size
            first = _first_runs(spec, plans)
            if client is None and method == "fork":
                t_w = time.perf_counter()
                _warm_kernels(spec, first.values(), size)
                t_warm = time.perf_counter() - t_w
            batchable = {k: s is not None and kernel_layout(s) is not None
                         for k, s in first.items()}
            tasks = [(part[0].record_id, (spec, [p.index for p in part], str(out), part, size))
                     for part in _batches(plans, workers if client is None else None, size,
                                          batchable)]
            n_workers = run_tasks(run_records, tasks, record_all, workers=workers,
                                  start_method=method, scheduler=client,
                                  progress=progress, desc=spec.name, unit="rec",
                                  postfix=lambda k, r: f"{r[-1]['record_id']} {r[-1]['status']}",
                                  total=len(pending), units=len)
    finally:
        t_c = time.perf_counter()
        consolidate(out, known)
        _remove_temporary(out)             # a worker killed mid-write (Dask retries it)
        t_consolidate = time.perf_counter() - t_c
    timing = {k: 0.0 for k in (*_TIMING_KEYS, "busy")}
    for r in rows:
        for k in _TIMING_KEYS:
            v = r.get(f"{k}_s")
            timing[k] += float(v) if v is not None and v == v else 0.0
        timing["busy"] += float(r.get("wall_s") or 0.0)
    timing.update(warmup=t_warm, resume=t_resume, consolidate=t_consolidate)
    failed = [r for r in rows if r["status"] == "failed"]
    return DatasetSummary(dir=str(out), records_total=spec.n_records,
                          records_written=sum(r["status"] == "ok" for r in rows),
                          records_skipped=len(done), records_adopted=adopted,
                          records_failed=len(failed), workers=n_workers,
                          runner="dask" if client is not None else "local",
                          start_method=method, wall_s=time.perf_counter() - start,
                          timing_s=timing,
                          failed=tuple((r["record_id"], r["error"]) for r in failed[:20]))
