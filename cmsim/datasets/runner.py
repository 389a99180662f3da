"""Sweeps: a grid of operating points → many runs on local processes → a manifest.

A :class:`SweepSpec` is the whole recipe (rig, speeds × torques × optional friction and
clearance lists, duration, sample rate, seed policy). :func:`run_sweep` expands it into
:class:`SweepCase` s, simulates the missing ones in parallel
(:class:`concurrent.futures.ProcessPoolExecutor`) and writes

* ``DIR/runs/<name>.npz`` — each run, atomically, by the worker the moment it finishes;
* ``DIR/manifest.json`` — spec, and per run: file, operating point, seed, wall-time split
  and a few spectral features; rewritten atomically after every finished run.

Resuming is the same call: a run whose file exists and matches its manifest entry is skipped;
a file that is complete but missing from the manifest (the process was killed between the
worker's write and the manifest update) is checked against its case (seed, operating point,
rig, sampling) and adopted. So an interrupted sweep (Ctrl-C, killed process, a raising
callback) loses nothing that finished. A manifest written for another spec is an error unless
``force=True``.

Seeds
    ``seed_policy="per_run"`` (default): run ``i`` gets
    ``SeedSequence(seed, spawn_key=(i,))`` → a 31-bit integer, so runs are independent and
    each is reproducible from (base seed, index); ``"shared"``: every run uses ``seed`` (same
    cage phases at every torque, for like-for-like comparisons). The seed of each run is in
    the manifest and in the run's own meta.

Processes
    On Linux the pool forks (``start_method="fork"``) after the parent has loaded the numba
    kernels, so workers start at once and do not compile; elsewhere it spawns, and each
    worker loads the kernels from numba's disk cache once (its compile time is counted with
    its first run). Two sweeps must not share a directory: ``DIR/.sweep.lock`` holds the
    owner's pid.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import sys
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_text
from cmsim.dynamics.simulate import _compile_seconds, simulate
from cmsim.errors import IntegrationDiverged, ParameterError, check_range
from cmsim.features import N_GMF_HARMONICS
from cmsim.features import run_features as signal_features
from cmsim.rig import OperatingPoint, Rig
from cmsim.run import Run

__all__ = ["SweepSpec", "SweepCase", "SweepSummary", "run_sweep", "read_manifest",
           "run_features", "SEED_POLICIES", "START_METHODS", "MANIFEST_NAME", "RUNS_DIR",
           "FEATURE_SIGNALS"]

#: Seed policies of :class:`SweepSpec`.
SEED_POLICIES = ("per_run", "shared")

#: Process start methods accepted by :func:`run_sweep`.
START_METHODS = ("fork", "spawn", "forkserver")

#: File name of the manifest inside a sweep directory.
MANIFEST_NAME = "manifest.json"

#: Sub-directory of the run files.
RUNS_DIR = "runs"

#: Signals whose spectral features are stored in the manifest (those present in a run).
FEATURE_SIGNALS = ("F_1b1_loa", "F_1b1_oloa", "dte_um")

_MANIFEST_FORMAT = "cmsim-sweep-manifest"
_MANIFEST_VERSION = 1
_LOCK_NAME = ".sweep.lock"


def _floats(name, values, allow_none=False):
    if values is None or isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        values = (values,)
    out = []
    for i, v in enumerate(values):
        if v is None and allow_none:
            out.append(None)
        else:
            out.append(check_range(f"{name}[{i}]", v))
    if not out:
        raise ParameterError(f"{name} must hold at least one value")
    if len(set(out)) != len(out):
        raise ParameterError(f"{name} must not repeat a value, got {out}")
    return tuple(out)


@dataclass(frozen=True)
class SweepCase:
    """One grid point of a sweep.

    Attributes
    ----------
    index : int
        Position in the grid (speed slowest, clearance fastest).
    name : str
        File stem of the run, e.g. ``"003_n1000rpm_T40Nm"``.
    speed_rpm : float
        Input shaft speed, rpm.
    torque_nm : float
        Output torque, N·m.
    friction : float or None
        Mesh friction coefficient (None: the rig's own).
    clearance_m : float or None
        Radial clearance of every bearing, m (None: the rig's own; negative = preload).
    seed : int
        Seed of this run.
    """

    index: int
    name: str
    speed_rpm: float
    torque_nm: float
    friction: float | None
    clearance_m: float | None
    seed: int

    def to_dict(self):
        """Plain dict of the fields."""
        return {"index": self.index, "name": self.name, "speed_rpm": self.speed_rpm,
                "torque_nm": self.torque_nm, "friction": self.friction,
                "clearance_m": self.clearance_m, "seed": self.seed}


@dataclass(frozen=True)
class SweepSpec:
    """Recipe of a sweep: rig, grid of operating points, sampling and seeds (SI units).

    Attributes
    ----------
    speeds_rpm : tuple of float
        Input shaft speeds, rpm (> 0, no repeats).
    torques_nm : tuple of float
        Output torques, N·m (no repeats).
    duration_s : float
        Recorded duration of every run, s (0 < d <= 600).
    frictions : tuple of float or None
        Mesh friction coefficients in [0, 1]; ``(None,)`` keeps the rig's.
    clearances_m : tuple of float or None
        Bearing radial clearances, m (negative = preload); ``(None,)`` keeps the rig's.
    rig : Rig
        Base rig (default the paper's, Tables 1-3).
    fs_hz : float
        Output sample rate, Hz.
    warmup_s : float
        Simulated time discarded before recording, s.
    substeps : int
        Integration steps per sample.
    radial_load_n : float
        Static radial load on shaft 1's centre node, N (bearing rigs).
    seed : int
        Base seed (>= 0).
    seed_policy : {"per_run", "shared"}
        How run seeds follow from ``seed`` (module docstring).
    """

    speeds_rpm: tuple
    torques_nm: tuple
    duration_s: float = 1.0
    frictions: tuple = (None,)
    clearances_m: tuple = (None,)
    rig: Rig = field(default_factory=Rig.paper_2016)
    fs_hz: float = 75_000.0
    warmup_s: float = 0.05
    substeps: int = 1
    radial_load_n: float = 0.0
    seed: int = 0
    seed_policy: str = "per_run"

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "speeds_rpm", _floats("speeds_rpm", self.speeds_rpm))
        set_(self, "torques_nm", _floats("torques_nm", self.torques_nm))
        set_(self, "frictions", _floats("frictions", self.frictions, allow_none=True))
        set_(self, "clearances_m", _floats("clearances_m", self.clearances_m, allow_none=True))
        for i, v in enumerate(self.speeds_rpm):
            check_range(f"speeds_rpm[{i}]", v, 0.0, 1e5, lo_open=True, unit="rpm")
        for i, v in enumerate(self.frictions):
            if v is not None:
                check_range(f"frictions[{i}]", v, 0.0, 1.0)
        if not isinstance(self.rig, Rig):
            raise ParameterError(f"rig must be a cmsim.rig.Rig, got {type(self.rig).__name__}")
        if not self.rig.has_gears and any(f is not None for f in self.frictions):
            raise ParameterError("frictions need a rig with gears (this rig has none)")
        set_(self, "duration_s", check_range("duration_s", self.duration_s, 0.0, 600.0,
                                             lo_open=True, unit="s"))
        set_(self, "fs_hz", check_range("fs_hz", self.fs_hz, 1e3, 1e7, unit="Hz"))
        set_(self, "warmup_s", check_range("warmup_s", self.warmup_s, 0.0, 60.0, unit="s"))
        set_(self, "radial_load_n", check_range("radial_load_n", self.radial_load_n, unit="N"))
        for name, lo, hi in (("substeps", 1, 1000), ("seed", 0, 2 ** 63 - 1)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi:
                raise ParameterError(f"{name} must be an integer in [{lo}, {hi}], got {v!r}")
            set_(self, name, int(v))
        if self.seed_policy not in SEED_POLICIES:
            raise ParameterError(f"seed_policy must be one of {SEED_POLICIES}, "
                                 f"got {self.seed_policy!r}")
        for case in self.cases():          # every grid point must be a valid rig / op
            self.case_rig(case)
            self.case_operating_point(case)

    # ------------------------------------------------------------------ grid
    def run_seed(self, index):
        """Seed of run ``index`` (see the module docstring), a 31-bit integer."""
        if self.seed_policy == "shared":
            return self.seed
        state = np.random.SeedSequence(self.seed, spawn_key=(int(index),)).generate_state(1)
        return int(state[0] >> 1)

    def cases(self):
        """All grid points, speed slowest and clearance fastest, as :class:`SweepCase` s."""
        out = []
        for n in self.speeds_rpm:
            for t in self.torques_nm:
                for f in self.frictions:
                    for c in self.clearances_m:
                        i = len(out)
                        name = f"{i:03d}_n{n:g}rpm_T{t:g}Nm"
                        if f is not None:
                            name += f"_f{f:g}"
                        if c is not None:
                            name += f"_c{c * 1e6:g}um"
                        out.append(SweepCase(i, name, n, t, f, c, self.run_seed(i)))
        return out

    def case_rig(self, case):
        """The rig of one case (base rig with the case's friction and clearance)."""
        rig = self.rig
        if case.clearance_m is not None:
            rig = rig.with_clearance(case.clearance_m)
        if case.friction is not None:
            rig = rig.with_friction(case.friction)
        return rig

    def case_operating_point(self, case):
        """The :class:`~cmsim.rig.OperatingPoint` of one case."""
        return OperatingPoint(speed_rpm=case.speed_rpm, torque_nm=case.torque_nm,
                              radial_load_n=self.radial_load_n)

    # ------------------------------------------------------------------ (de)serialisation
    def to_dict(self):
        """JSON-ready dict (the rig as :meth:`Rig.to_dict`)."""
        return {"speeds_rpm": list(self.speeds_rpm), "torques_nm": list(self.torques_nm),
                "frictions": list(self.frictions), "clearances_m": list(self.clearances_m),
                "duration_s": self.duration_s, "fs_hz": self.fs_hz, "warmup_s": self.warmup_s,
                "substeps": self.substeps, "radial_load_n": self.radial_load_n,
                "seed": self.seed, "seed_policy": self.seed_policy, "rig": self.rig.to_dict()}

    @classmethod
    def from_dict(cls, data):
        """Spec from :meth:`to_dict` output; unknown keys raise :class:`ParameterError`."""
        data = dict(data)
        names = {f for f in cls.__dataclass_fields__}
        unknown = set(data) - names
        if unknown:
            raise ParameterError(f"unknown sweep spec keys {sorted(unknown)}; allowed: "
                                 f"{sorted(names)}")
        if "rig" in data:
            data["rig"] = Rig.from_dict(data["rig"])
        return cls(**data)


@dataclass(frozen=True)
class SweepSummary:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    dir : str
        Sweep directory.
    n_runs : int
        Grid points in the spec.
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
        signals), ``spectra`` (manifest features), ``save``, ``busy`` (their total);
        ``utilisation`` = busy / (wall·workers).
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


# ---------------------------------------------------------------------- features
def run_features(run, signals=FEATURE_SIGNALS, n_harmonics=N_GMF_HARMONICS, top_n=5):
    """Features of a run for the manifest (:mod:`cmsim.features`), per signal.

    Parameters
    ----------
    run : cmsim.run.Run
        Simulated run.
    signals : sequence of str
        Signals to summarise (those absent from the run are left out).
    n_harmonics : int
        GMF harmonics measured (default 6, :data:`cmsim.features.N_GMF_HARMONICS`).
    top_n : int
        Largest labelled peaks kept per signal.

    Returns
    -------
    dict
        Per signal, :meth:`cmsim.features.FeatureRow.to_summary`: ``dominant_gmf_harmonic``
        (int or None for bearing rigs), ``gmf_harmonics`` (amplitudes of 1..n_harmonics ×
        GMF, signal unit), ``top_peaks`` (list of {frequency_hz, amplitude, label,
        db_re_carrier}) and ``features`` (the flat feature columns, NaN as None).
    """
    return {name: signal_features(run, name, n_gmf_harmonics=n_harmonics,
                                  top_n=top_n).to_summary()
            for name in signals if name in run.signals}


# ---------------------------------------------------------------------- worker
_PROCESS_RUNS = {"n": 0, "warm": False}


def _run_case(spec, case, path):
    """Simulate one case, save it atomically, return a small JSON-ready record."""
    start = time.perf_counter()
    first = _PROCESS_RUNS["n"] == 0 and not _PROCESS_RUNS["warm"]
    _PROCESS_RUNS["n"] += 1
    rig, op = spec.case_rig(case), spec.case_operating_point(case)
    try:
        run = simulate(rig, op, spec.duration_s, fs_hz=spec.fs_hz, substeps=spec.substeps,
                       seed=case.seed, warmup_s=spec.warmup_s)
    except IntegrationDiverged as exc:
        return {"name": case.name, "status": "failed", "error": str(exc), "pid": os.getpid(),
                "timing_s": {"total": time.perf_counter() - start}}
    sim_end = time.perf_counter()
    run = run.with_meta(sweep_case={**case.to_dict(), "base_seed": spec.seed,
                                    "seed_policy": spec.seed_policy})
    meta = run.meta
    features = run_features(run)
    spectra_end = time.perf_counter()
    run.save(path)
    end = time.perf_counter()
    compile_s = float(meta["compile_s"]) if first else 0.0
    integration = float(meta["wall_s"])
    return {"name": case.name, "status": "done", "pid": os.getpid(),
            "bytes": Path(path).stat().st_size, "features": features,
            "timing_s": {"integration": integration, "compile": compile_s,
                         "setup": max(sim_end - start - integration - compile_s, 0.0),
                         "spectra": spectra_end - sim_end, "save": end - spectra_end,
                         "total": end - start}}


def _watch_parent(parent_pid, period_s=0.5):
    """Exit this worker as soon as its parent is gone (killed sweep: no orphans left)."""
    while True:
        time.sleep(period_s)
        if os.getppid() != parent_pid:
            os._exit(1)


def _worker_init(parent_pid):
    """Pool initializer: watch the parent from a daemon thread."""
    threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True,
                     name="cmsim-parent-watch").start()


def _warm_kernels(spec):
    """Load/compile the kernels in this process, before forking workers (which inherit
    them). Returns ``{"compile": s, "startup": s}``: kernel compile/load time, and the rest
    (a 3-sample run)."""
    start = time.perf_counter()
    case = spec.cases()[0]
    try:                     # also builds a model, so every kernel in the path is loaded
        simulate(spec.case_rig(case), spec.case_operating_point(case), 3.0 / spec.fs_hz,
                 fs_hz=spec.fs_hz, seed=0, warmup_s=0.0)
    except IntegrationDiverged:                    # the worker will report it per run
        pass
    _PROCESS_RUNS["warm"] = True
    compile_s = float(_compile_seconds())
    return {"compile": compile_s, "startup": time.perf_counter() - start - compile_s}


# ---------------------------------------------------------------------- manifest
def _normalised(obj):
    return json.loads(json.dumps(obj))


def read_manifest(out_dir):
    """The manifest of a sweep directory as a dict, or None if there is none.

    Raises :class:`ParameterError` if the file exists but is not a cmsim sweep manifest.
    """
    path = Path(out_dir) / MANIFEST_NAME
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except json.JSONDecodeError as exc:
        raise ParameterError(f"{path} is not valid JSON: {exc}") from None
    if not isinstance(data, dict) or data.get("format") != _MANIFEST_FORMAT:
        raise ParameterError(f"{path} is not a cmsim sweep manifest")
    if data.get("version") != _MANIFEST_VERSION:
        raise ParameterError(f"{path} has manifest version {data.get('version')!r}; this "
                             f"cmsim reads version {_MANIFEST_VERSION}")
    return data


def _write_manifest(out_dir, manifest):
    manifest["updated"] = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    atomic_write_text(Path(out_dir) / MANIFEST_NAME, json.dumps(manifest, indent=1) + "\n")


def _spec_difference(old, new):
    keys = sorted(set(old) | set(new))
    return [k for k in keys if old.get(k) != new.get(k)]


def _case_entry(spec, case, result):
    op = spec.case_operating_point(case)
    return {"index": case.index, "file": f"{RUNS_DIR}/{case.name}.npz",
            "status": result["status"],
            "operating_point": {"speed_rpm": op.speed_rpm, "torque_nm": op.torque_nm,
                                "radial_load_n": op.radial_load_n},
            "friction": case.friction, "clearance_m": case.clearance_m, "seed": case.seed,
            **{k: result[k] for k in ("bytes", "error", "features", "timing_s", "pid",
                                      "adopted") if k in result},
            "finished": time.strftime("%Y-%m-%dT%H:%M:%S%z")}


def _file_matches(spec, case, path, entry=None):
    """True if ``path`` is a complete run of ``case`` (and matches ``entry`` if given)."""
    if not path.is_file():
        return False
    if entry is not None:
        if entry.get("status") != "done" or entry.get("bytes") != path.stat().st_size:
            return False
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
    except Exception:                      # unreadable or foreign file: recompute it
        return False
    op = meta.get("operating_point", {})
    sc = meta.get("sweep_case", {})
    rig_dict = _normalised(spec.case_rig(case).to_dict())
    return (sc.get("name") == case.name and meta.get("seed") == case.seed
            and op.get("speed_rpm") == case.speed_rpm and op.get("torque_nm") == case.torque_nm
            and op.get("radial_load_n") == spec.radial_load_n
            and meta.get("fs_hz") == spec.fs_hz and meta.get("warmup_s") == spec.warmup_s
            and meta.get("substeps") == spec.substeps
            and abs(meta.get("duration_s", -1.0) - spec.duration_s) <= 0.5 / spec.fs_hz
            and _normalised(meta.get("rig")) == rig_dict)


def _adopt(spec, case, path):
    start = time.perf_counter()
    run = Run.load(path)
    features = run_features(run)
    return {"name": case.name, "status": "done", "adopted": True,
            "bytes": path.stat().st_size, "features": features,
            "timing_s": {"integration": float(run.meta.get("wall_s", 0.0)), "compile": 0.0,
                         "setup": 0.0, "spectra": time.perf_counter() - start, "save": 0.0,
                         "total": time.perf_counter() - start}}


class _DirectoryLock:
    """``DIR/.sweep.lock`` holding the owner's pid; a stale lock (dead pid) is taken over."""

    def __init__(self, out_dir):
        self.path = Path(out_dir) / _LOCK_NAME

    def __enter__(self):
        for _ in range(2):
            try:
                fd = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            except FileExistsError:
                try:
                    pid = int(self.path.read_text().strip() or "0")
                except (OSError, ValueError):
                    pid = 0
                if pid and pid != os.getpid() and _pid_alive(pid):
                    raise ParameterError(f"{self.path.parent} is in use by another sweep "
                                         f"(pid {pid}); wait for it or remove {self.path}")
                self.path.unlink(missing_ok=True)
                continue
            with os.fdopen(fd, "w") as fh:
                fh.write(str(os.getpid()))
            return self
        raise ParameterError(f"could not lock {self.path}")

    def __exit__(self, *exc):
        self.path.unlink(missing_ok=True)
        return False


def _pid_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _default_start_method():
    return "fork" if sys.platform.startswith("linux") else "spawn"


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
        are saved).
    """
    if not isinstance(spec, SweepSpec):
        raise ParameterError(f"spec must be a SweepSpec, got {type(spec).__name__}")
    n_cpu = os.cpu_count() or 1
    workers = n_cpu if workers is None else workers
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) \
            or not 1 <= workers <= 256:
        raise ParameterError(f"workers must be an integer in [1, 256], got {workers!r}")
    method = _default_start_method() if start_method is None else start_method
    available = [m for m in START_METHODS if m in multiprocessing.get_all_start_methods()]
    if method not in available:
        raise ParameterError(f"start_method must be one of {available}, got {start_method!r}")
    if progress is None:
        progress = sys.stderr.isatty()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / RUNS_DIR).mkdir(exist_ok=True)
    start = time.perf_counter()
    with _DirectoryLock(out):
        for tmp in (out / RUNS_DIR).glob(".*.tmp"):     # left by a killed worker
            tmp.unlink(missing_ok=True)
        spec_dict = _normalised(spec.to_dict())
        manifest = read_manifest(out)
        if manifest is not None and manifest.get("spec") != spec_dict:
            diff = _spec_difference(manifest.get("spec", {}), spec_dict)
            if not force:
                raise ParameterError(
                    f"{out / MANIFEST_NAME} was written for a different sweep spec "
                    f"(differs in {diff}); use another directory, or force=True (--force) to "
                    f"replace it")
            manifest = None
        if manifest is None:
            manifest = {"format": _MANIFEST_FORMAT, "version": _MANIFEST_VERSION,
                        "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "spec": spec_dict,
                        "runs": {}}
        cases = spec.cases()
        runs = manifest["runs"]
        names = {c.name for c in cases}
        for stale in set(runs) - names:
            del runs[stale]
        pending, skipped, adopted = [], 0, 0
        for case in cases:
            path = out / RUNS_DIR / f"{case.name}.npz"
            entry = runs.get(case.name)
            if entry is not None and _file_matches(spec, case, path, entry):
                skipped += 1
            elif _file_matches(spec, case, path):
                runs[case.name] = _case_entry(spec, case, _adopt(spec, case, path))
                skipped += 1
                adopted += 1
            else:
                runs.pop(case.name, None)
                pending.append(case)
        _write_manifest(out, manifest)
        results, n_workers, warm_s = _execute(spec, out, manifest, pending, workers, method,
                                              progress, on_run_done)
    timing = {k: 0.0 for k in ("integration", "compile", "setup", "spectra", "save", "busy")}
    timing["compile"] = warm_s.get("compile", 0.0)
    timing["startup"] = warm_s.get("startup", 0.0)
    for res in results:
        t = res.get("timing_s", {})
        for k in ("integration", "compile", "setup", "spectra", "save"):
            timing[k] += float(t.get(k, 0.0))
        timing["busy"] += float(t.get("total", 0.0))
    wall = time.perf_counter() - start
    timing["utilisation"] = timing["busy"] / (wall * n_workers) if n_workers else 0.0
    failed = tuple(r["name"] for r in results if r["status"] == "failed")
    summary = SweepSummary(dir=str(out), n_runs=len(cases),
                           completed=sum(r["status"] == "done" for r in results),
                           skipped=skipped, adopted=adopted, failed=failed, workers=n_workers,
                           start_method=method, wall_s=wall, timing_s=timing)
    if failed:
        errors = "; ".join(f"{r['name']}: {r['error']}" for r in results
                           if r["status"] == "failed")
        raise IntegrationDiverged(f"{len(failed)} of {len(cases)} runs diverged ({errors}); "
                                  f"the other runs are saved in {out / MANIFEST_NAME}")
    return summary


def _execute(spec, out, manifest, pending, workers, method, progress, on_run_done):
    """Run ``pending`` cases in a process pool, recording each result as it arrives."""
    if not pending:
        return [], 0, {}
    from tqdm import tqdm

    n_workers = min(int(workers), len(pending))
    warm_s = _warm_kernels(spec) if method == "fork" else {}
    by_name = {c.name: c for c in pending}
    results = []

    def record(res):
        case = by_name[res["name"]]
        manifest["runs"][case.name] = entry = _case_entry(spec, case, res)
        _write_manifest(out, manifest)
        results.append(res)
        return entry

    ctx = multiprocessing.get_context(method)
    pool = ProcessPoolExecutor(max_workers=n_workers, mp_context=ctx,
                               initializer=_worker_init, initargs=(os.getpid(),))
    futures = {}
    bar = None
    try:
        for case in pending:
            fut = pool.submit(_run_case, spec, case, out / RUNS_DIR / f"{case.name}.npz")
            futures[fut] = case.name
        # the bar (and its monitor thread) only after the workers are forked
        bar = tqdm(total=len(pending), disable=not progress, file=sys.stderr, unit="run",
                   desc="sweep", dynamic_ncols=True)
        remaining = set(futures)
        while remaining:
            done, remaining = wait(remaining, return_when=FIRST_COMPLETED)
            for fut in done:
                res = fut.result()
                entry = record(res)
                bar.update(1)
                bar.set_postfix_str(res["name"], refresh=False)
                if on_run_done is not None:
                    on_run_done(res["name"], entry)
    except BaseException:
        # keep whatever finished meanwhile; do not wait for the cancelled rest
        pool.shutdown(wait=False, cancel_futures=True)
        for fut, name in futures.items():
            if fut.done() and not fut.cancelled() and fut.exception() is None \
                    and name not in manifest["runs"]:
                try:
                    record(fut.result())
                except BaseException:      # pragma: no cover - best effort while unwinding
                    pass
        raise
    finally:
        if bar is not None:
            bar.close()
        pool.shutdown(wait=True, cancel_futures=True)
    return results, n_workers, warm_s
