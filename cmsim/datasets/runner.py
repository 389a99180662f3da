"""Run a sweep on local processes, resumably: :func:`run_sweep`.

:func:`run_sweep` expands a :class:`~cmsim.datasets.spec.SweepSpec` into its cases,
simulates the missing ones in parallel (:class:`concurrent.futures.ProcessPoolExecutor`) and
writes

* ``DIR/runs/<name>.npz`` — each run, atomically, by the worker the moment it finishes;
* ``DIR/manifest.json`` — :mod:`cmsim.datasets.manifest`, rewritten atomically after every
  finished run.

Resuming is the same call: a run whose file exists and matches its manifest entry (size and
SHA-256 checksum) is skipped; a file that does not is recomputed;
a file that is complete but missing from the manifest (the process was killed between the
worker's write and the manifest update) is checked against its case (seed, operating point,
rig, sampling, mesh) and adopted. So an interrupted sweep (Ctrl-C, killed process, a raising
callback) loses nothing that finished. A manifest written for another spec is an error unless
``force=True``. Two sweeps never share a directory (:class:`~cmsim.datasets.lock.DirectoryLock`).

Processes
    On Linux the pool forks (``start_method="fork"``) after the parent has loaded the numba
    kernels, so workers start at once and do not compile; elsewhere it spawns, and each
    worker loads the kernels from numba's disk cache once (its compile time is counted with
    its first run). Each run depends only on its case (rig, operating point, seed), so the
    arrays are bit-identical on any number of workers.
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from cmsim.datasets.lock import DirectoryLock
from cmsim.datasets.pool import START_METHODS, check_start_method, check_workers, run_tasks
from cmsim.datasets.manifest import (MANIFEST_NAME, RUNS_DIR, case_entry, file_matches,
                                     file_sha256, manifest_features, new_manifest, normalised,
                                     read_manifest, run_file, spec_difference,
                                     write_manifest)
from cmsim.datasets.spec import SweepSpec, mesh_key
from cmsim.dynamics.simulate import _compile_seconds, simulate
from cmsim.errors import IntegrationDiverged, ParameterError
from cmsim.run import Run

__all__ = ["run_sweep", "SweepSummary", "START_METHODS"]

#: Keys of the wall-time split of a run (``timing_s``), summed in :class:`SweepSummary`.
_TIMING_KEYS = ("integration", "compile", "setup", "spectra", "save")


@dataclass(frozen=True)
class SweepSummary:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    dir : str
        Sweep directory.
    n_runs : int
        Cases in the spec.
    completed : int
        Runs simulated by this call.
    skipped : int
        Runs already on disk (including ``adopted``).
    adopted : int
        Complete run files found without a manifest entry, verified and recorded.
    failed : tuple of str
        Names of runs whose integration diverged (recorded in the manifest).
    workers : int
        Worker processes used (0 if nothing had to run).
    start_method : str
        Process start method.
    wall_s : float
        Wall time of the call, s.
    timing_s : dict of str to float
        Sums over the runs of this call, s: ``integration`` (``run.meta["wall_s"]``),
        ``compile`` (kernel loading, per process), ``setup`` (model, quasi-static start,
        signals), ``spectra`` (manifest features), ``save``, ``busy`` (their total),
        ``startup`` (the parent's warm-up run); ``utilisation`` = busy / (wall·workers).
    """

    dir: str
    n_runs: int
    completed: int
    skipped: int
    adopted: int
    failed: tuple
    workers: int
    start_method: str
    wall_s: float
    timing_s: dict

    def to_dict(self):
        """JSON-ready dict (``integration_s`` etc. flattened from ``timing_s``)."""
        out = {"dir": self.dir, "manifest": str(Path(self.dir) / MANIFEST_NAME),
               "n_runs": self.n_runs, "completed": self.completed, "skipped": self.skipped,
               "adopted": self.adopted, "failed": list(self.failed), "workers": self.workers,
               "start_method": self.start_method, "wall_s": self.wall_s}
        for k, v in self.timing_s.items():
            out[k if k == "utilisation" else f"{k}_s"] = v
        return out


# ---------------------------------------------------------------------- worker
_PROCESS_RUNS = {"n": 0, "warm": False}


def _simulate_case(spec, case, duration_s=None, **kw):
    return simulate(spec.case_rig(case), spec.case_operating_point(case),
                    spec.duration_s if duration_s is None else duration_s, mesh=spec.mesh,
                    fs_hz=spec.fs_hz, faults=spec.faults, losses=spec.losses, **kw)


def _run_case(spec, case, path):
    """Simulate one case, save it atomically, return a small JSON-ready record."""
    start = time.perf_counter()
    first = _PROCESS_RUNS["n"] == 0 and not _PROCESS_RUNS["warm"]
    _PROCESS_RUNS["n"] += 1
    try:
        run = _simulate_case(spec, case, substeps=spec.substeps, seed=case.seed,
                             warmup_s=spec.warmup_s)
    except IntegrationDiverged as exc:
        return {"name": case.name, "status": "failed", "error": str(exc), "pid": os.getpid(),
                "timing_s": {"total": time.perf_counter() - start}}
    sim_end = time.perf_counter()
    run = run.with_meta(sweep_case={**case.to_dict(), "base_seed": spec.seed,
                                    "seed_policy": spec.seed_policy,
                                    "mesh": mesh_key(spec.mesh)})
    meta = run.meta
    features = manifest_features(run)
    spectra_end = time.perf_counter()
    run.save(path)
    checksum = file_sha256(path)
    end = time.perf_counter()
    compile_s = float(meta["compile_s"]) if first else 0.0
    integration = float(meta["wall_s"])
    return {"name": case.name, "status": "done", "pid": os.getpid(),
            "bytes": Path(path).stat().st_size, "sha256": checksum, "features": features,
            "timing_s": {"integration": integration, "compile": compile_s,
                         "setup": max(sim_end - start - integration - compile_s, 0.0),
                         "spectra": spectra_end - sim_end, "save": end - spectra_end,
                         "total": end - start}}


def _warm_kernels(spec):
    """Load/compile the kernels in this process, before forking workers (which inherit
    them). Returns ``{"compile": s, "startup": s}``: kernel compile/load time, and the rest
    (a 3-sample run with the spec's mesh model)."""
    start = time.perf_counter()
    try:                     # also builds a model, so every kernel in the path is loaded
        _simulate_case(spec, spec.cases()[0], 3.0 / spec.fs_hz, seed=0, warmup_s=0.0)
    except IntegrationDiverged:                    # the worker will report it per run
        pass
    _PROCESS_RUNS["warm"] = True
    compile_s = float(_compile_seconds())
    return {"compile": compile_s, "startup": time.perf_counter() - start - compile_s}


def _try_adopt(case, path):
    """:func:`_adopt`, or None if the file cannot be read in full (recompute it)."""
    try:
        return _adopt(case, path)
    except Exception:                      # noqa: BLE001 - corrupt archive of any kind
        return None


def _adopt(case, path):
    """Record of a complete run file found without a manifest entry."""
    start = time.perf_counter()
    run = Run.load(path)
    features = manifest_features(run)
    return {"name": case.name, "status": "done", "adopted": True,
            "bytes": path.stat().st_size, "sha256": file_sha256(path), "features": features,
            "timing_s": {"integration": float(run.meta.get("wall_s", 0.0)), "compile": 0.0,
                         "setup": 0.0, "spectra": time.perf_counter() - start, "save": 0.0,
                         "total": time.perf_counter() - start}}


# ---------------------------------------------------------------------- runner
def run_sweep(spec, out_dir, *, workers=None, force=False, progress=None, start_method=None,
              on_run_done=None):
    """Simulate every case of ``spec`` that is not yet in ``out_dir``; resume-safe.

    Parameters
    ----------
    spec : SweepSpec
        What to run.
    out_dir : str or path-like
        Sweep directory (created); holds ``manifest.json`` and ``runs/``.
    workers : int, optional
        Worker processes (1-256); default ``os.cpu_count()``, never more than the runs left.
    force : bool
        Replace a manifest written for a different spec (run files that still match their
        case are kept; the others are recomputed).
    progress : bool, optional
        tqdm progress bar on stderr; default: only if stderr is a terminal.
    start_method : {"fork", "spawn", "forkserver"}, optional
        Process start method; default "fork" on Linux, else "spawn".
    on_run_done : callable, optional
        ``on_run_done(name, entry)`` after each finished run is recorded in the manifest
        (an exception raised there stops the sweep, keeping what is recorded).

    Returns
    -------
    SweepSummary

    Raises
    ------
    ParameterError
        Spec mismatch with an existing manifest (without ``force``), bad ``workers``, a
        directory in use by another sweep.
    IntegrationDiverged
        After the sweep, if some runs diverged (they are recorded as failed; the others
        are saved); its ``summary`` attribute is the :class:`SweepSummary`.
    cmsim.datasets.pool.Interrupted
        On Ctrl-C or SIGTERM: the workers are stopped at once, every run that finished is
        in the manifest, the lock is released; the same call resumes.
    """
    if not isinstance(spec, SweepSpec):
        raise ParameterError(f"spec must be a SweepSpec, got {type(spec).__name__}")
    workers = check_workers(workers)
    method = check_start_method(start_method)
    if progress is None:
        progress = sys.stderr.isatty()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / RUNS_DIR).mkdir(exist_ok=True)
    start = time.perf_counter()
    with DirectoryLock(out):
        for tmp in (out / RUNS_DIR).glob(".*.tmp"):     # left by a killed worker
            tmp.unlink(missing_ok=True)
        manifest = _open_manifest(spec, out, force)
        cases = spec.cases()
        pending, skipped, adopted = _resume(spec, out, manifest, cases)
        write_manifest(out, manifest)
        results, n_workers, warm_s = _execute(spec, out, manifest, pending, workers, method,
                                              progress, on_run_done)
    wall = time.perf_counter() - start
    summary = _summary(out, cases, results, skipped, adopted, n_workers, method, wall, warm_s)
    if summary.failed:
        errors = "; ".join(f"{r['name']}: {r['error']}" for r in results
                           if r["status"] == "failed")
        exc = IntegrationDiverged(f"{len(summary.failed)} of {len(cases)} runs diverged "
                                  f"({errors}); the other runs are saved in "
                                  f"{out / MANIFEST_NAME}")
        exc.summary = summary
        raise exc
    return summary


def _open_manifest(spec, out, force):
    """The directory's manifest for ``spec``, or a new one (a foreign spec needs ``force``)."""
    spec_dict = normalised(spec.to_dict())
    manifest = read_manifest(out)
    if manifest is not None and manifest.get("spec") != spec_dict:
        diff = spec_difference(manifest.get("spec", {}), spec)
        if not force:
            raise ParameterError(
                f"{out / MANIFEST_NAME} was written for a different sweep spec (differs in "
                f"{diff}); use another directory, or force=True (--force) to replace it")
        manifest = None
    return new_manifest(spec) if manifest is None else manifest


def _resume(spec, out, manifest, cases):
    """Split ``cases`` into pending ones and runs already done (recorded or adopted)."""
    runs = manifest["runs"]
    for stale in set(runs) - {c.name for c in cases}:
        del runs[stale]
    pending, skipped, adopted = [], 0, 0
    for case in cases:
        path = run_file(out, case)
        entry = runs.get(case.name)
        if entry is not None and file_matches(spec, case, path, entry):
            skipped += 1
        elif entry is None and file_matches(spec, case, path) \
                and (res := _try_adopt(case, path)) is not None:   # saved, never recorded
            runs[case.name] = case_entry(spec, case, res)
            skipped += 1
            adopted += 1
        else:
            runs.pop(case.name, None)
            pending.append(case)
    return pending, skipped, adopted


def _summary(out, cases, results, skipped, adopted, n_workers, method, wall, warm_s):
    timing = {k: 0.0 for k in (*_TIMING_KEYS, "busy")}
    timing["compile"] = warm_s.get("compile", 0.0)
    timing["startup"] = warm_s.get("startup", 0.0)
    for res in results:
        t = res.get("timing_s", {})
        for k in _TIMING_KEYS:
            timing[k] += float(t.get(k, 0.0))
        timing["busy"] += float(t.get("total", 0.0))
    timing["utilisation"] = timing["busy"] / (wall * n_workers) if n_workers else 0.0
    return SweepSummary(dir=str(out), n_runs=len(cases),
                        completed=sum(r["status"] == "done" for r in results),
                        skipped=skipped, adopted=adopted,
                        failed=tuple(r["name"] for r in results if r["status"] == "failed"),
                        workers=n_workers, start_method=method, wall_s=wall, timing_s=timing)


def _execute(spec, out, manifest, pending, workers, method, progress, on_run_done):
    """Run ``pending`` cases on worker processes, recording each result as it arrives."""
    if not pending:
        return [], 0, {}
    warm_s = _warm_kernels(spec) if method == "fork" else {}
    by_name = {c.name: c for c in pending}
    results = []

    def record(name, res):
        case = by_name[name]
        manifest["runs"][case.name] = entry = case_entry(spec, case, res)
        write_manifest(out, manifest)
        results.append(res)
        if on_run_done is not None:
            on_run_done(name, entry)

    n_workers = run_tasks(_run_case, [(c.name, (spec, c, run_file(out, c))) for c in pending],
                          record, workers=workers, start_method=method, progress=progress,
                          desc="sweep", unit="run", postfix=lambda name, res: name)
    return results, n_workers, warm_s
