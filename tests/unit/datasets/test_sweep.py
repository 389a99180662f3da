"""Sweeps: spec, seeds, parallel runner, manifest, resume after interruption, CLI.

Test tier: behaviour contracts (no physics): every finished run is on disk and in the manifest;
re-running resumes without recomputing; interruptions lose nothing finished; errors name the
parameter. Runs are tiny (0.05 s at 75 kHz) so the module takes a few seconds.

A sweep is a grid :class:`~cmsim.datasets.DatasetSpec` whose records keep the full runs; it
runs on the one runner, :func:`~cmsim.datasets.generate_dataset`, with ``verify=True`` (a
resumed sweep checks every run's SHA-256, as ``cmsim sweep`` does).
"""

import json
import os
import shutil

import numpy as np
import pytest

from cmsim.cli import main
from cmsim.datasets import (PARQUET_NAME, RECORDS_DIR, SPEC_NAME, DatasetSpec, DirectoryLock,
                            Variation, generate_dataset, read_rows)
from cmsim.errors import ParameterError
from cmsim.rig import Rig
from cmsim.run import Run


def tiny(torques=(10.0, 100.0), **kw):
    """The 2-run sweep of this module (1000 rpm, 0.05 s, seed 7)."""
    kw = {"duration_s": 0.05, "seed": 7, **kw}
    return DatasetSpec([Variation("speed_rpm", [1000.0]), Variation("torque_nm", list(torques))],
                       **kw)


def run_sweep(spec, out, **kw):
    """The runner as a sweep uses it: SHA-256 of every finished run checked on resume."""
    return generate_dataset(spec, out, verify=True, **kw)


def rows_of(out):
    """{record_id: row} of a sweep directory."""
    return {r["record_id"]: r for r in read_rows(out).to_dict("records")}


@pytest.fixture(scope="module")
def tiny_sweep(tmp_path_factory):
    """A finished 2-run sweep (2 workers), shared read-only; copy it before changing it."""
    out = tmp_path_factory.mktemp("sweep") / "tiny"
    summary = run_sweep(tiny(), out, workers=2)
    return out, summary


def _copy(src, tmp_path):
    dst = tmp_path / "copy"
    shutil.copytree(src, dst)
    return dst


# ---------------------------------------------------------------------- spec
def _grid(speeds, torques, frictions=None, **kw):
    axes = [Variation("speed_rpm", speeds), Variation("torque_nm", torques)]
    if frictions is not None:
        axes.append(Variation("friction", frictions))
    return DatasetSpec(axes, **kw)


def test_spec_grid_names_and_seeds():
    spec = _grid([1000, 1500], [10, 50], [0.0, 0.03], duration_s=0.1, seed=3)
    plans = [spec.record(i) for i in range(len(spec))]
    assert len(plans) == 8
    assert [p.index for p in plans] == list(range(8))
    assert plans[0].record_id == "000_n1000rpm_T10Nm_f0"
    assert plans[-1].record_id == "007_n1500rpm_T50Nm_f0.03"
    assert len({p.record_id for p in plans}) == 8
    seeds = [p.sim_seed for p in plans]
    assert len(set(seeds)) == 8 and all(0 <= s < 2 ** 31 for s in seeds)
    # deterministic: from SeedSequence([base seed, index]) alone
    again = _grid([1000, 1500], [10, 50], [0.0, 0.03], duration_s=0.1, seed=3)
    assert seeds == [again.record(i).sim_seed for i in range(8)]
    rng = np.random.default_rng(np.random.SeedSequence([3, 5]))
    rng.random(), rng.random()                           # run-up and fault draws
    assert seeds[5] == int(rng.integers(0, 2 ** 31 - 1))
    other = _grid([1000], [10], duration_s=0.1, seed=4)
    assert other.record(0).sim_seed != seeds[0]
    shared = _grid([1000], [10, 20], duration_s=0.1, seed=4, seed_policy="shared")
    assert [shared.record(i).sim_seed for i in range(2)] == [4, 4]
    assert spec.record_rig(plans[1]).mesh_contact.friction_coefficient == pytest.approx(0.03)


def test_spec_identity_is_its_resolved_form():
    """The stored form (``dataset.json``) is JSON, equal specs share a digest, another value
    changes it. (It replaces the older round trip through the JSON manifest: the input forms
    are the keywords and the TOML tables.)"""
    def make(c):
        return DatasetSpec([("speed_rpm", [1000]), ("torque_nm", [10, 20]),
                            ("clearance_m", c)], duration_s=0.2, seed=1)
    spec = make([1.5e-5, -1e-6])
    data = json.loads(json.dumps(spec.to_dict()))
    assert [s["name"] for s in data["settings"]] == ["speed_rpm", "torque_nm", "clearance_m"]
    assert make([1.5e-5, -1e-6]) == spec and make([1.5e-5, -1e-6]).digest == spec.digest
    assert make([1.5e-5, -2e-6]).digest != spec.digest


@pytest.mark.parametrize("kwargs, word", [
    (dict(speeds=[0.0], torques=[10]), "speed_rpm"),
    (dict(speeds=[1000], torques=[]), "at least one"),
    (dict(speeds=[1000], torques=[10, 10]), "repeat"),
    (dict(speeds=[1000], torques=[10], duration_s=0.0), "duration_s"),
    (dict(speeds=[1000], torques=[10], frictions=[1.5]), "friction[0]"),
    (dict(speeds=[1000], torques=[10], seed=-1), "seed"),
    (dict(speeds=[1000], torques=[10], seed_policy="random"), "seed_policy"),
    (dict(speeds=[float("nan")], torques=[10]), "speed_rpm[0]"),
])
def test_spec_errors_name_the_parameter(kwargs, word):
    with pytest.raises(ParameterError, match=word.replace("[", r"\[").replace("]", r"\]")):
        _grid(**kwargs)


def test_friction_needs_gears():
    from cmsim.rig import RollingBearing, Rotor
    brg = Rig.paper_2016().bearings[0]
    rig = Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01))
    assert isinstance(brg, RollingBearing)
    with pytest.raises(ParameterError, match="gears"):
        _grid([1000], [0.0], [0.03], rig=rig)


def _check_gmf_features(row, run, name):
    """The manifest's GMF harmonics are those of the saved signal (flat-top window, read
    independently here), and the dominant one is their largest."""
    import scipy.signal
    x = run[name] - run[name].mean()
    w = scipy.signal.windows.flattop(x.size, sym=False)
    amp = 2 * np.abs(np.fft.rfft(x * w)) / w.sum()
    freq = np.fft.rfftfreq(x.size, 1 / run.fs_hz)
    gmf = 28 * run.meta["operating_point"]["speed_rpm"] / 60
    df = freq[1]
    mine = np.array([amp[np.abs(freq - k * gmf) <= 1.5 * df].max() for k in range(1, 7)])
    got = np.array([row[f"{name}.gmf{k}_amp"] for k in range(1, 7)], dtype=float)
    big = mine > 0.2 * mine.max()
    np.testing.assert_allclose(got[big], mine[big], rtol=0.1)
    dominant = row[f"{name}.dominant_gmf_harmonic"]
    assert dominant == int(np.argmax(got)) + 1
    assert mine[int(dominant) - 1] >= 0.9 * mine.max()


# ---------------------------------------------------------------------- runner
def test_sweep_writes_runs_and_manifest(tiny_sweep):
    out, summary = tiny_sweep
    assert (summary.records_total, summary.records_written, summary.records_skipped) == (2, 2, 0)
    assert summary.workers == 2 and summary.failed == ()
    spec = tiny()
    stored = json.loads((out / SPEC_NAME).read_text())
    assert stored["digest"] == spec.digest
    assert stored["spec"] == json.loads(json.dumps(spec.to_dict(), default=str))
    rows = rows_of(out)
    plans = [spec.record(i) for i in range(len(spec))]
    assert set(rows) == {p.record_id for p in plans}
    assert (out / PARQUET_NAME).is_file() and not list((out / "rows").glob("*.json"))
    pids = set()
    for plan in plans:
        row = rows[plan.record_id]
        path = out / row["path"]
        assert row["status"] == "ok" and row["bytes"] == path.stat().st_size
        assert row["seed"] == plan.sim_seed
        assert row["torque_nm"] == plan.params["torque_nm"]
        assert row["integration_s"] > 0
        assert row["wall_s"] >= row["integration_s"] + row["features_s"]
        run = Run.load(path)                           # a sweep's record is a whole run
        _check_gmf_features(row, run, "F_1b1_loa")
        pids.add(row["pid"])
        assert run.meta["seed"] == plan.sim_seed
        assert run.meta["record"]["record_id"] == plan.record_id
        assert run.meta["operating_point"]["torque_nm"] == plan.params["torque_nm"]
        assert run.t.size == int(round(0.05 * 75_000))
        assert {"dte_um", "F_1b1_loa", "x_1b1", "y_2b1", "theta_1G1"} <= set(run.signals)
    assert os.getpid() not in pids                     # simulated in worker processes
    assert not list((out / RECORDS_DIR).glob(".*"))    # no temp files, no lock left
    assert not (out / ".sweep.lock").exists()


def test_rerun_skips_everything(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    before = {p.name: p.stat().st_mtime_ns for p in (out / RECORDS_DIR).glob("*.npz")}
    s = run_sweep(tiny(), out, workers=2)
    assert (s.records_written, s.records_skipped, s.workers) == (0, 2, 0)
    assert before == {p.name: p.stat().st_mtime_ns for p in (out / RECORDS_DIR).glob("*.npz")}


def test_deleted_run_is_recomputed_alone_and_identically(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    victim = sorted((out / RECORDS_DIR).glob("*.npz"))[1]
    old = Run.load(victim)
    keep = sorted((out / RECORDS_DIR).glob("*.npz"))[0]
    keep_mtime = keep.stat().st_mtime_ns
    victim.unlink()
    s = run_sweep(tiny(), out, workers=2)
    assert (s.records_written, s.records_skipped, s.workers) == (1, 1, 1)
    assert keep.stat().st_mtime_ns == keep_mtime
    new = Run.load(victim)
    for name in ("F_1b1_loa", "dte", "x_2b1"):          # same seed → same arrays
        np.testing.assert_array_equal(new[name], old[name])


def test_interrupted_sweep_keeps_finished_runs_and_resumes(tmp_path):
    spec = tiny([10, 40, 100], seed=1)
    out = tmp_path / "sw"
    seen = []

    def stop_after_first(row):
        seen.append(row["record_id"])
        raise KeyboardInterrupt("simulated Ctrl-C")

    with pytest.raises(KeyboardInterrupt):
        run_sweep(spec, out, workers=1, on_record_done=stop_after_first)
    assert seen[0] in rows_of(out)                     # recorded before the interruption
    files = sorted((out / RECORDS_DIR).glob("*.npz"))
    assert 1 <= len(files) < 3
    for f in files:                                    # every file on disk is complete
        assert Run.load(f).t.size == int(round(0.05 * 75_000))
    assert not list((out / RECORDS_DIR).glob(".*.tmp"))
    assert not (out / ".sweep.lock").exists()
    s = run_sweep(spec, out, workers=2)
    assert s.records_written + s.records_skipped == 3
    assert s.records_skipped == len(files) and s.records_written == 3 - len(files)
    assert {r["status"] for r in rows_of(out).values()} == {"ok"}


def test_file_without_manifest_entry_is_adopted(tiny_sweep, tmp_path):
    """A worker finished and saved but the parent was killed before recording its row."""
    import pandas as pd
    out = _copy(tiny_sweep[0], tmp_path)
    df = pd.read_parquet(out / PARQUET_NAME)
    name = df["record_id"][0]
    df[df["index"] != 0].to_parquet(out / PARQUET_NAME, index=False)
    (out / RECORDS_DIR / ".stale.npz.abc.tmp").write_bytes(b"half written")
    s = run_sweep(tiny(), out, workers=2)
    assert (s.records_written, s.records_skipped, s.records_adopted) == (0, 2, 1)
    row = rows_of(out)[name]
    assert row["adopted"] and row["status"] == "ok"
    assert not (out / RECORDS_DIR / ".stale.npz.abc.tmp").exists()


def test_foreign_or_corrupt_file_is_recomputed(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    victim = sorted((out / RECORDS_DIR).glob("*.npz"))[0]
    victim.write_bytes(b"not a zip file")
    s = run_sweep(tiny(), out, workers=1)
    assert (s.records_written, s.records_skipped) == (1, 1)
    assert Run.load(victim).meta["record"]["record_id"] == victim.stem


def test_spec_mismatch_is_an_error_unless_forced(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    other = tiny([10.0, 100.0, 50.0])
    with pytest.raises(ParameterError, match=r"different spec.*settings: torque_nm.*force"):
        run_sweep(other, out, workers=1)
    s = run_sweep(other, out, workers=1, force=True)
    # records 0 and 1 keep their ids, seeds and parameters: their files are kept
    assert (s.records_written, s.records_adopted) == (1, 2)
    stored = json.loads((out / SPEC_NAME).read_text())["spec"]
    assert stored["settings"][1]["values"] == [10.0, 100.0, 50.0]


def test_directory_in_use_by_a_live_process(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    with DirectoryLock(out):                           # another holder of the OS lock
        with pytest.raises(ParameterError, match=rf"another sweep \(pid {os.getpid()}\)"):
            run_sweep(tiny(), out, workers=1)
    (out / ".sweep.lock").write_text("999999999")      # a file without an OS lock: taken
    assert run_sweep(tiny(), out, workers=1).records_skipped == 2
    assert not (out / ".sweep.lock").exists()


@pytest.mark.parametrize("workers", [0, 1.5, True])
def test_bad_workers(tmp_path, workers):
    with pytest.raises(ParameterError, match="workers"):
        run_sweep(tiny(), tmp_path, workers=workers)


# ---------------------------------------------------------------------- CLI
def test_cli_sweep_json_contract_and_resume(tiny_sweep, tmp_path, capsys):
    out = _copy(tiny_sweep[0], tmp_path)
    argv = ["sweep", "--torque-nm", "10", "100", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--seed", "7", "--out", str(out), "--workers", "2", "--json"]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    for key in ("records_total", "records_written", "records_skipped", "wall_s",
                "integration_s", "workers", "dir", "features_s", "warmup_s", "manifest",
                "failed"):
        assert key in res
    assert (res["records_total"], res["records_written"], res["records_skipped"]) == (2, 0, 2)
    assert main(argv[:-3] + ["--workers", "2"]) == 0  # text mode
    assert "already there" in capsys.readouterr().out


def test_cli_sweep_errors(tmp_path, capsys):
    status = main(["sweep", "--torque-nm", "10", "--speed-rpm", "-5", "--out", str(tmp_path),
                   "--json"])
    assert status == 2
    assert "--speed-rpm" in json.loads(capsys.readouterr().out)["error"]


def test_spawned_workers_give_the_same_arrays(tiny_sweep, tmp_path):
    """The portable start method (macOS/Windows default) runs and reproduces the fork runs."""
    spec = tiny([10.0])
    s = run_sweep(spec, tmp_path / "spawn", workers=1, start_method="spawn")
    assert (s.records_written, s.start_method) == (1, "spawn")
    name = spec.record_id(0)
    a = Run.load(tmp_path / "spawn" / RECORDS_DIR / f"{name}.npz")
    b = Run.load(tiny_sweep[0] / RECORDS_DIR / f"{name}.npz")
    np.testing.assert_array_equal(a["F_1b1_loa"], b["F_1b1_loa"])
    with pytest.raises(ParameterError, match="start_method"):
        run_sweep(spec, tmp_path / "x", start_method="thread")


def test_diverged_runs_are_recorded_and_reported(tmp_path, capsys):
    """One integration step per sample at 2 kHz (asked for: by default the step follows the
    model, see the next test; at 100 rpm, where it still resolves the mesh) diverges: the
    run is recorded as failed, exit status 3."""
    out = tmp_path / "div"
    argv = ["sweep", "--torque-nm", "10", "--speed-rpm", "100", "--duration-s", "0.05",
            "--fs-hz", "2000", "--substeps", "1", "--out", str(out), "--json"]
    assert main(argv) == 3
    assert "diverged" in json.loads(capsys.readouterr().out)["error"]
    (row,) = rows_of(out).values()
    assert row["status"] == "failed" and "fs_hz" in row["error"]
    assert not list((out / RECORDS_DIR).glob("*.npz"))


def test_low_rate_sweep_is_anti_aliased_like_simulate(tmp_path, capsys):
    """Without --substeps a sweep at 2 kHz takes the step simulate takes (automatic, from the
    model's highest mode) and decimates through the same anti-alias filter."""
    out = tmp_path / "low"
    argv = ["sweep", "--torque-nm", "10", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--fs-hz", "2000", "--out", str(out), "--workers", "1", "--json"]
    assert main(argv) == 0
    capsys.readouterr()
    (path,) = (out / RECORDS_DIR).glob("*.npz")
    swept = Run.load(path).meta
    assert main(["simulate", "--speed-rpm", "1000", "--torque-nm", "10", "--duration-s", "0.05",
                 "--fs-hz", "2000", "--out", str(tmp_path / "one.npz"), "--json"]) == 0
    simulated = Run.load(tmp_path / "one.npz").meta
    assert swept["substeps"] == simulated["substeps"] > 1
    assert swept["anti_alias"] == simulated["anti_alias"] is not None


def test_cli_sweep_passes_the_mesh_choice(tmp_path, capsys):
    out = tmp_path / "pe"
    argv = ["sweep", "--torque-nm", "10", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--mesh", "potential-energy", "--out", str(out), "--workers", "1", "--json"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["records_written"] == 1
    assert json.loads((out / SPEC_NAME).read_text())["spec"]["mesh"] == "potential-energy"
    (path,) = (out / RECORDS_DIR).glob("*.npz")
    assert Run.load(path).meta["mesh_table"]["method"] == "potential-energy"
    status = main(argv[:7] + ["--out", str(out), "--json"])     # default mesh: another spec
    assert status == 2 and "mesh" in json.loads(capsys.readouterr().out)["error"]


# ---------------------------------------------------------------------- integrity, signals
def test_same_size_corrupted_run_is_recomputed(tiny_sweep, tmp_path):
    """Resume checks each run's SHA-256 from the manifest, not only its size."""
    out = _copy(tiny_sweep[0], tmp_path)
    victim, keep = sorted((out / RECORDS_DIR).glob("*.npz"))
    old = Run.load(victim)
    data = bytearray(victim.read_bytes())
    data[len(data) // 2] ^= 0xFF                       # one flipped byte inside an array
    victim.write_bytes(bytes(data))
    keep_mtime = keep.stat().st_mtime_ns
    s = run_sweep(tiny(), out, workers=1)
    assert (s.records_written, s.records_skipped) == (1, 1)
    assert keep.stat().st_mtime_ns == keep_mtime
    np.testing.assert_array_equal(Run.load(victim)["F_1b1_loa"], old["F_1b1_loa"])
    from cmsim.datasets.manifest import file_sha256
    assert rows_of(out)[victim.stem]["sha256"] == file_sha256(victim)


def _wait_for(predicate, timeout_s):
    import time
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGINT"])
def test_signal_stops_the_sweep_promptly_and_rerun_completes(tmp_path, signame):
    """A sweep sent SIGTERM/SIGINT mid-run stops within seconds, records the finished runs,
    says how to resume, releases the lock; re-running computes only the missing runs."""
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "sig"
    argv = [sys.executable, "-m", "cmsim.cli", "sweep", "--torque-nm", "10", "20", "30", "40",
            "50", "60", "--speed-rpm", "1000", "--duration-s", "0.3", "--seed", "2",
            "--out", str(out), "--workers", "1"]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "MPLBACKEND": "Agg"})
    try:
        def some_done():
            return len(list((out / "rows").glob("0*.json"))) >= 1
        assert _wait_for(some_done, 120), proc.stderr.read() if proc.poll() is not None else ""
        sent = time.monotonic()
        proc.send_signal(getattr(signal, signame))
        _, err = proc.communicate(timeout=30)
        stop_s = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "re-run the same command to resume" in err and "Traceback" not in err
    assert stop_s < 10
    assert not (out / ".sweep.lock").exists()
    recorded = rows_of(out)
    assert 1 <= len(recorded) < 6
    files = {p.stem for p in (out / RECORDS_DIR).glob("*.npz")}
    assert set(recorded) <= files
    mtimes = {n: (out / RECORDS_DIR / f"{n}.npz").stat().st_mtime_ns for n in recorded}
    s = run_sweep(tiny([10, 20, 30, 40, 50, 60], duration_s=0.3, seed=2), out, workers=2)
    assert s.records_skipped >= len(recorded) and s.records_written + s.records_skipped == 6
    assert mtimes == {n: (out / RECORDS_DIR / f"{n}.npz").stat().st_mtime_ns for n in recorded}


def test_failed_runs_keep_their_summary_in_json(tmp_path, capsys):
    out = tmp_path / "div2"
    argv = ["sweep", "--torque-nm", "10", "--speed-rpm", "100", "--duration-s", "0.05",
            "--fs-hz", "2000", "--substeps", "1", "--out", str(out), "--json"]
    assert main(argv) == 3
    res = json.loads(capsys.readouterr().out)
    assert res["status"] == 3 and "diverged" in res["error"]
    summary = res["summary"]
    assert summary["records_total"] == 1 and len(summary["failed"]) == 1
    assert summary["records_written"] == 0 and "wall_s" in summary


def test_cli_sweep_builds_faults_into_every_run(tmp_path, capsys):
    """``--fault`` reaches every run's model (felt through the dynamics: the faulty runs
    differ from healthy ones), is recorded in each run's meta with its answer key and as the
    records' label, and is part of the spec: the same directory with another fault is
    refused."""
    out = tmp_path / "faulty"
    crack = "tooth_crack:gear=1,depth_m=2e-3"
    argv = ["sweep", "--torque-nm", "10", "100", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--seed", "7", "--workers", "1", "--fault", crack, "--json"]
    assert main(argv + ["--out", str(out)]) == 0
    assert json.loads(capsys.readouterr().out)["records_written"] == 2
    stored = json.loads((out / SPEC_NAME).read_text())["spec"]
    assert [f["type"] for f in stored["faults"]] == ["tooth_crack"]
    rows = rows_of(out)
    assert len(rows) == 2
    for row in rows.values():
        assert row["fault_label"] == "tooth_crack" and row["fault_component"] == "G1"
        run = Run.load(out / row["path"])
        (fault,) = run.meta["faults"]
        assert fault["type"] == "tooth_crack" and fault["depth_m"] == pytest.approx(2e-3)
        (key,) = run.meta["fault_frequencies"].values()
        assert key["shaft_hz"] == pytest.approx(1000.0 / 60.0)
    assert main(argv + ["--out", str(out)]) == 0                       # resumes
    assert json.loads(capsys.readouterr().out)["records_skipped"] == 2
    other = [a if a != crack else "tooth_crack:gear=1,depth_m=1e-3" for a in argv]
    assert main(other + ["--out", str(out)]) == 2
    assert "faults" in json.loads(capsys.readouterr().out)["error"]
    bad = [a if a != crack else "outer_race:bearing=9z9,size_m=1e-3,depth_m=1e-4" for a in argv]
    assert main(bad + ["--out", str(tmp_path / "bad")]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert "--fault" in err and "bearing" in err
