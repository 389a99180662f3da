"""One record of a spec: simulate it, write its file, make its manifest row.

A record's file ``DIR/records/<record_id>.npz`` holds its signals and ``meta`` (JSON: the
manifest row, rig, operating point, faults, the answer key, timing):

* a spec with ``channels`` keeps those channels only, float32 at the sensor rate
  (accelerometers and tacho through the rig's housing path, with the drawn sensor noise;
  a calibrated machine's channel through its path, plus its background: :mod:`cmsim.machine`);
* a spec without (a sweep) keeps the simulated run in full — ``t``, every signal at full
  precision and the run's own meta — so the file is a :class:`~cmsim.run.Run`
  (:meth:`Run.load <cmsim.run.Run.load>` reads it; ``cmsim report`` draws it), and its
  manifest row also carries the features of :data:`FEATURE_SIGNALS`.

:func:`run_records` is the task a worker runs: it simulates a batch of records in one time
loop (:func:`simulate_records`; a record's arrays do not depend on its batch), writes each
record file atomically, then its row as a sidecar (``DIR/rows/<record_id>.json``), also for a
failed record (with its error); the runner folds the sidecars into the Parquet manifest
(:mod:`cmsim.datasets.manifest`).
"""

from __future__ import annotations

import json
import math
import os
import time
import traceback
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_all, savez_writer
from cmsim.datasets.manifest import RECORDS_DIR, file_sha256, json_default, write_row
from cmsim.datasets.spec import mesh_key
from cmsim.dynamics.batch import simulate_batch
from cmsim.dynamics.simulation import integrate_prepared, prepare_run
from cmsim.dynamics.profiles import SpeedProfile
from cmsim.faults import fault_frequencies
from cmsim.features import N_GMF_HARMONICS, run_features
from cmsim.frequencies import rig_frequencies
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.run import Run
from cmsim.sensors import add_sensors

__all__ = ["simulate_record", "simulate_records", "run_record", "run_records",
           "BATCH_SIZE", "BATCH_SAMPLES", "BATCH_SAMPLES_FULL", "BATCH_MIN", "BATCH_FROM_RECORDS",
           "default_batch_size", "base_row",
           "manifest_features", "FEATURE_SIGNALS",
           "FORMAT"]

#: Signals of a full-run record whose features go into its manifest row (those it has).
FEATURE_SIGNALS = ("F_1b1_loa", "F_1b1_oloa", "dte_um")

#: ``meta["format"]`` of a record file.
FORMAT = "cmsim-dataset"


def _frequency_columns(rig, op):
    fr = rig_frequencies(rig, op)
    out = {"shaft_hz": fr.fr1_hz, "gmf_hz": math.nan if fr.gmf_hz is None else fr.gmf_hz}
    for name in fr.bearing_names:
        b = fr.bearing(name)
        for key in ("bpfo", "bpfi", "bsf", "ftf"):
            out[f"{key}_hz_{name}"] = float(getattr(b, f"{key}_hz"))
    return out


def _column(v):
    """A manifest cell: bools and None stay, numbers become floats."""
    return v if v is None or isinstance(v, (bool, np.bool_)) else float(v)


def base_row(spec, plan):
    """The manifest row of a record before it is simulated (parameters and answer key).

    Parameters
    ----------
    spec : DatasetSpec
        The spec.
    plan : RecordPlan
        One of its records (:meth:`DatasetSpec.record`).

    Returns
    -------
    dict
    """
    f = plan.fault
    row = {"record_id": plan.record_id, "index": plan.index, "seed": plan.sim_seed,
           "status": "pending", "error": None,
           "path": f"{RECORDS_DIR}/{plan.record_id}.npz", "wall_s": math.nan,
           "rig_name": spec.rig.name, "spec_digest": spec.digest, "repeat": plan.repeat,
           **{k: _column(v) for k, v in plan.params.items()},
           "fault_label": plan.fault_label, "fault_component": plan.fault_component,
           "fault_severity": plan.fault_severity}
    row.setdefault("torque_nm", 0.0)
    row.setdefault("radial_load_n", 0.0)
    if f is not None:
        for k, v in f.to_dict().items():
            if k not in ("type", "bearing", "gear") and isinstance(v, (int, float)) \
                    and not isinstance(v, bool):
                row[f"fault_{k}"] = float(v)
    row.update(_frequency_columns(spec.record_rig(plan), spec.record_operating_point(plan)))
    return row


def _accelerometers(channels):
    """``(bearings, directions)`` of a record's accelerometer channels, sorted: the housing
    path feels the forces of every bearing along every direction of the two lists."""
    accel = [c.split("_") for c in channels if c.startswith("accel_")]
    return sorted({a[1] for a in accel}), sorted({a[2] for a in accel})


def _simulated_channels(channels, machine=None):
    """The simulated signals a record's channels are made from: the accelerometers need the
    forces of their bearings along their directions (:func:`_accelerometers`), the tacho the
    input shaft's rotation, a machine's channel the force of its model signal's bearing."""
    bearings, directions = _accelerometers(channels)
    out = {f"F_{b}_{d}" for b in bearings for d in directions}
    for c in channels:
        if machine is not None and c == machine.channel:
            out |= set(machine.force_signals)
        elif c.startswith("accel_"):
            continue
        elif c == "tacho":
            out.add("theta_1b1")
        else:
            out.add(c)
    return sorted(out)


def _prepared(spec, plan):
    """``(setup, rig, op, profile)`` of a record: its run checked and built up to the time
    loop (:func:`cmsim.dynamics.simulation.prepare_run`)."""
    rig = spec.record_rig(plan)
    op = spec.record_operating_point(plan)
    profile = None
    if plan.params["runup"]:
        profile = SpeedProfile.ramp(op.speed_rpm, plan.params["end_speed_rpm"],
                                    spec.duration_s, start_s=spec.warmup_s)
    channels = spec.channels
    setup = prepare_run(rig, op, spec.duration_s, mesh=spec.mesh, fs_hz=spec.fs_hz,
                        substeps=spec.substeps, seed=plan.sim_seed, warmup_s=spec.warmup_s,
                        faults=plan.faults, profile=profile, losses=spec.losses,
                        record=None if channels is None else _simulated_channels(channels,
                                                                                 spec.machine))
    return setup, rig, op, profile


def _record_arrays(spec, plan, rig, op, profile, run, setup_s, reference=None):
    """``(arrays, meta)`` of a record from its simulated ``run``: the sensors, the answer key,
    the meta (module docstring); ``reference`` is the healthy run its change through the
    machine is read against (:func:`_machine_references`)."""
    channels = spec.channels
    sensed = [c for c in channels or () if c.startswith("accel_") or c == "tacho"]
    t1 = time.perf_counter()
    if _through_machine(spec):
        run = spec.machine.sensor_channel(run, plan.sim_seed, healthy=reference)
    if sensed:
        bearings, directions = _accelerometers(sensed)
        run = add_sensors(run, path=rig.housing, noise_rms=plan.params["sensor_noise_m_s2"],
                          seed=plan.sim_seed, bearings=bearings or None,
                          directions=directions or ("x", "y"))
    t2 = time.perf_counter()
    key = fault_frequencies(rig, op, [plan.fault]) if plan.fault is not None else {}
    integration = float(run.meta["wall_s"])
    record = {"format": FORMAT,
              "labels": {"fault_label": plan.fault_label, "fault_component": plan.fault_component,
                         "fault_severity": plan.fault_severity,
                         "faults": [plan.fault.to_dict()] if plan.fault is not None else [],
                         "fault_frequencies": key},
              "record": {"index": plan.index, "record_id": plan.record_id, "seed": plan.sim_seed,
                         "base_seed": spec.seed, "seed_policy": spec.seed_policy,
                         "repeat": plan.repeat, "mesh": mesh_key(spec.mesh),
                         "values": {n: plan.params[n] for n, _ in spec.settings}},
              "timing_s": {"integration": integration, "setup": setup_s, "sensors": t2 - t1}}
    if channels is None:
        return {"t": run.t, "source": np.asarray(run.source), **run.signals}, \
            {**run.meta, **record}
    meta = {"fs_hz": run.fs_hz, "t0_s": float(run.t[0]), "n_samples": int(run.t.size),
            "rig": run.meta["rig"], "operating_point": run.meta["operating_point"],
            "profile": None if profile is None else {"times_s": list(profile.times_s),
                                                     "speeds_rpm": list(profile.speeds_rpm)},
            "faults": [f.to_dict() for f in plan.faults], "substeps": run.meta.get("substeps"),
            "scheme": run.meta.get("scheme"), "sim_wall_s": integration, **record}
    return {c: np.asarray(run[c], dtype=np.float32) for c in channels}, meta


def _through_machine(spec):
    """Whether the spec's records are read through its machine (its channel recorded)."""
    return spec.machine is not None and (spec.channels is None
                                         or spec.machine.channel in spec.channels)


def _reference_setup(spec, rig, op, plan, profile):
    """The healthy run a record's change through a machine is read against
    (:meth:`cmsim.machine.Machine.sensor_channel`), prepared: the same model run — seed,
    duration, warm-up, tooth contact — on the machine's rig at its operating point without
    the record's faults; None when the record is that run (no fault, the machine's rig and
    operating point, no run-up), or the machine has no baseline to lay a change on (a
    version-1 machine file)."""
    machine = spec.machine
    if not machine.needs_reference(op, plan.faults, profile, rig):
        return None
    return prepare_run(machine.rig, machine.op, spec.duration_s, mesh=spec.mesh,
                       fs_hz=spec.fs_hz, substeps=spec.substeps, seed=plan.sim_seed,
                       warmup_s=spec.warmup_s, losses=spec.losses,
                       record=None if spec.channels is None else list(machine.force_signals))


def _machine_references(spec, todo, batch_size):
    """Per record of ``todo`` (``(i, plan, rig, op, profile, setup_s)``), its healthy
    reference run (:func:`_reference_setup`; None where it needs none), or the exception
    that stopped it: each alone on the single-run kernel for ``batch_size`` 1, else those of
    a batch together (a reference's bits, as a record's, do not depend on its companions)."""
    if not _through_machine(spec):
        return [None] * len(todo)
    out, setups, where = [None] * len(todo), [], []
    for k, (_, plan, rig, op, profile, _) in enumerate(todo):
        try:
            setup = _reference_setup(spec, rig, op, plan, profile)
        except Exception as exc:           # noqa: BLE001 - a failed record, the rest go on
            out[k] = exc
            continue
        if setup is not None:
            setups.append(setup)
            where.append(k)
    runs = (simulate_batch(setups, batch_size) if batch_size > 1
            else [_alone(s) for s in setups])
    for k, run in zip(where, runs):
        out[k] = run
    return out


#: Most records a dataset integrates together by default (:func:`default_batch_size`): B runs
#: in one time loop, the record the inner array axis (:mod:`cmsim.dynamics.batch`). Measured
#: on the 2-core build machine (docs/benchmarks.md): a record of the paper rig costs, in CPU,
#: 0.77 of its cost alone in a batch of 32 and 0.69-0.74 in one of 64 (8: 1.14-1.19); a batch
#: itself costs about 6.7 µs a step whatever its size, so 400 gear records in batches of at
#: most 128 (of 124, 123, 78 and 75 records) took 0.98 of the CPU of batches of at most 64
#: (of 61-62 and 37-39; in-process, 281 records: 0.98 as well).
BATCH_SIZE = 128
#: Samples (duration × sample rate) a default batch holds at most where each record keeps
#: only the columns its channels read: a batch's arrays grow with it (64 one-second records
#: at 25.6 kHz of the paper rig peaked at 0.53 GiB in one process, 0.30 before the batch; the
#: 400-record gear spec's largest process at 0.64 GiB in batches of 124), so 128 such
#: records, and fewer of longer or faster ones, keep a worker under 1 GiB.
BATCH_SAMPLES = 128 * 25_600
#: The same where each record keeps its whole run (a spec without channels: every state and
#: force, 64 one-second records peaked at 0.87 GiB).
BATCH_SAMPLES_FULL = 64 * 25_600
#: Smallest batch that pays (a batch of 16 costs 0.87-0.88 of its records alone, one of 8
#: more than alone): a spec whose records would batch fewer keeps each record alone.
BATCH_MIN = 16
#: Fewest records a spec has for them to be batched by default (fewer make batches too
#: small to pay once spread over the workers and fault types).
BATCH_FROM_RECORDS = 64


def default_batch_size(spec):
    """Records of ``spec`` integrated together when no batch size is given: up to
    :data:`BATCH_SIZE`, as many as :data:`BATCH_SAMPLES` allows (:data:`BATCH_SAMPLES_FULL`
    for records that keep their whole run), for a spec of at least
    :data:`BATCH_FROM_RECORDS` records whose tooth contact is not the on-line hybrid solve
    (the batch kernel runs that record by record); 1 (each record alone on the single-run
    kernel) otherwise, and where fewer than :data:`BATCH_MIN` would fit.

    Decided from the spec alone — not from how many records are pending or on which worker —
    so a record's arrays are the same bits in a fresh run, a resume or
    :func:`simulate_record`: every batch size above 1 gives the same bits (a batch of one
    included), and 1 agrees with them within 1e-9 of each signal's range.

    Parameters
    ----------
    spec : DatasetSpec
        The spec.

    Returns
    -------
    int
    """
    hybrid = spec.mesh == "hybrid" or isinstance(spec.mesh, HybridMeshModel)
    if spec.n_records < BATCH_FROM_RECORDS or hybrid:
        return 1
    samples = BATCH_SAMPLES if spec.channels is not None else BATCH_SAMPLES_FULL
    size = min(BATCH_SIZE, int(samples // (spec.duration_s * spec.fs_hz)))
    return size if size >= BATCH_MIN else 1


def simulate_records(spec, plans, batch_size=None):
    """Simulate records of ``spec`` together; per record, in order, ``(arrays, meta)``
    (:func:`simulate_record`) or the exception it raised.

    With ``batch_size`` 1 each record runs alone on the single-run kernel
    (:func:`cmsim.dynamics.simulation.integrate_prepared`, the reference); otherwise those of
    one kernel layout share one time loop (:func:`cmsim.dynamics.batch.simulate_batch`), and
    so do the healthy reference runs of a spec read through a machine. A record's arrays do
    not depend on the records it is simulated with: bit for bit the same in any batch (of any
    size above 1), and within 1e-9 of each signal's range of the single-run kernel's.

    Parameters
    ----------
    spec : DatasetSpec
        The spec.
    plans : sequence of RecordPlan
        Its records (:meth:`DatasetSpec.record`).
    batch_size : int, optional
        1: each record alone; larger: together (default :func:`default_batch_size`).

    Returns
    -------
    list of tuple or Exception
    """
    batch_size = default_batch_size(spec) if batch_size is None else batch_size
    out = [None] * len(plans)
    setups, todo = [], []
    for i, plan in enumerate(plans):
        t0 = time.perf_counter()
        try:
            setup, rig, op, profile = _prepared(spec, plan)
        except Exception as exc:           # noqa: BLE001 - a failed record, the rest go on
            out[i] = exc
            continue
        setups.append(setup)
        todo.append((i, plan, rig, op, profile, time.perf_counter() - t0))
    t0 = time.perf_counter()
    runs = (simulate_batch(setups, batch_size) if batch_size > 1
            else [_alone(s) for s in setups])
    references = _machine_references(spec, todo, batch_size)
    # what the batch spent besides integrating its records (filters, signals, the healthy
    # references of a machine spec), shared out
    around = (time.perf_counter() - t0
              - sum(r.meta["wall_s"] for r in runs if not isinstance(r, Exception)))
    around /= max(len(setups), 1)
    for (i, plan, rig, op, profile, setup_s), run, ref in zip(todo, runs, references):
        if isinstance(run, Exception) or isinstance(ref, Exception):
            out[i] = run if isinstance(run, Exception) else ref
            continue
        try:
            out[i] = _record_arrays(spec, plan, rig, op, profile, run, setup_s + around, ref)
        except Exception as exc:           # noqa: BLE001 - a failed record, the rest go on
            out[i] = exc
    return out


def _alone(setup):
    """A record's run on the single-run kernel, or the exception it raised."""
    try:
        return integrate_prepared(setup)
    except Exception as exc:               # noqa: BLE001 - a failed record, the rest go on
        return exc


def simulate_record(spec, index, plan=None):
    """Simulate record ``index`` of ``spec``: ``(arrays, meta)``, what its file holds (module
    docstring), bit for bit as a dataset run makes it by default
    (:func:`simulate_records` with :func:`default_batch_size`). Raises what
    :func:`cmsim.dynamics.simulate` raises (e.g. :class:`~cmsim.errors.IntegrationDiverged`).

    Parameters
    ----------
    spec : DatasetSpec
        The spec.
    index : int
        Record number.
    plan : RecordPlan, optional
        The record's plan, when the caller has drawn it (:meth:`DatasetSpec.record`).

    Returns
    -------
    arrays : dict of str to ndarray
        The channels (float32), or ``t``, ``source`` and every signal of the full run.
    meta : dict
        JSON-ready meta of the record.
    """
    result = simulate_records(spec, [spec.record(index) if plan is None else plan])[0]
    if isinstance(result, Exception):
        raise result
    return result


def manifest_features(run, signals=FEATURE_SIGNALS, n_harmonics=N_GMF_HARMONICS, top_n=5):
    """Features of a full run as flat manifest columns ``<signal>.<feature>``.

    Parameters
    ----------
    run : cmsim.run.Run
        Simulated run.
    signals : sequence of str
        Signals to summarise (those absent from the run are left out).
    n_harmonics : int
        GMF harmonics measured (default :data:`cmsim.features.N_GMF_HARMONICS`).
    top_n : int
        Largest labelled peaks kept per signal.

    Returns
    -------
    dict
        Per signal, the columns of :meth:`cmsim.features.FeatureRow.to_dict` (``gmf1_amp``
        ..., ``rms``, ``peak1_hz`` ...) and ``dominant_gmf_harmonic`` (NaN without gears),
        each named ``"<signal>.<column>"``.
    """
    out = {}
    for name in signals:
        if name not in run.signals:
            continue
        row = run_features(run, name, n_gmf_harmonics=n_harmonics, top_n=top_n)
        dominant = row.dominant_gmf_harmonic
        out[f"{name}.dominant_gmf_harmonic"] = math.nan if dominant is None else float(dominant)
        out.update({f"{name}.{k}": v for k, v in row.to_dict().items()})
    return out


def run_records(spec, indices, out_dir, plans=None, batch_size=None):
    """Worker task: simulate records ``indices`` of ``spec`` together
    (:func:`simulate_records`), write each one's file then its sidecar row; return the rows
    in order (status ``"ok"``, or ``"failed"`` with the error: a failed record does not stop
    the others).

    The files are written one after another and forced to the disk together
    (:func:`cmsim._io.atomic_write_all`), each before its row is written
    (:func:`cmsim.datasets.manifest.write_row`): the file system commits them at once instead
    of once per record, and no thread contends for the worker's core while they are encoded.
    A failed record's row is written first; a record whose file is in place but whose row
    was not written (an interruption) is adopted from its file on a resume.

    Parameters
    ----------
    spec : DatasetSpec
        The spec.
    indices : sequence of int
        Record numbers.
    out_dir : str or Path
        The dataset directory.
    plans : sequence of RecordPlan, optional
        The records' plans, when the caller has drawn them (:meth:`DatasetSpec.record`).
    batch_size : int, optional
        As :func:`simulate_records`.

    Returns
    -------
    list of dict
    """
    start = time.perf_counter()
    out = Path(out_dir)
    plans = [spec.record(i) for i in indices] if plans is None else list(plans)
    rows = []
    for plan in plans:
        row = base_row(spec, plan)
        row["record_key"] = spec.record_key(plan)
        row["pid"] = os.getpid()
        rows.append(row)
    results = simulate_records(spec, plans, batch_size)
    spent = (time.perf_counter() - start) / max(len(plans), 1)
    for row, result in zip(rows, results):
        if isinstance(result, Exception):     # its row first: it waits on no file
            row.update(status="failed", error=" ".join(f"{type(result).__name__}: {result}"
                                                       .split()), wall_s=spent)
            if os.environ.get("CMSIM_DEBUG"):
                traceback.print_exception(result)
            write_row(out, row)
    files = [(out / row["path"], _record_file(spec, row, result))
             for row, result in zip(rows, results) if not isinstance(result, Exception)]
    t_save = time.perf_counter()
    atomic_write_all(files)
    written = (time.perf_counter() - t_save) / max(len(files), 1)
    for row, result in zip(rows, results):
        if isinstance(result, Exception):
            continue
        t_row = time.perf_counter()
        path = out / row["path"]
        row["bytes"] = path.stat().st_size
        row["sha256"] = file_sha256(path)
        row["save_s"] = written + time.perf_counter() - t_row
        row["wall_s"] = spent + row["features_s"] + row["save_s"]
        write_row(out, row)
    return rows


def _record_file(spec, row, result):
    """Fill ``row`` with a simulated record's status, sizes, timings and manifest features;
    return the writer of its file (meta with the row, then the arrays)."""
    arrays, meta = result
    t_features = time.perf_counter()
    if spec.channels is None:
        signals = {k: v for k, v in arrays.items() if k not in ("t", "source")}
        row.update(manifest_features(Run(arrays["t"], signals, meta)))
    timing = meta["timing_s"]
    row.update(status="ok", n_samples=int(next(iter(arrays.values())).size
                                          if spec.channels else arrays["t"].size),
               fs_hz=meta["fs_hz"], integration_s=timing["integration"],
               setup_s=timing["setup"], sensors_s=timing["sensors"],
               features_s=time.perf_counter() - t_features)
    meta["row"] = row
    return savez_writer(meta=json.dumps(meta, default=json_default), **arrays)


def run_record(spec, index, out_dir):
    """Worker task of one record: :func:`run_records` of ``[index]``; returns its row.

    Parameters
    ----------
    spec : DatasetSpec
        The spec the record belongs to.
    index : int
        Its number in the spec.
    out_dir : str or Path
        The dataset directory it is written to.

    Returns
    -------
    dict
    """
    return run_records(spec, [index], out_dir)[0]
