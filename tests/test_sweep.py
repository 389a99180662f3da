"""Sweeps: spec, seeds, parallel runner, manifest, resume after interruption, CLI.

Test tier: behaviour contracts (no physics): every finished run is on disk and in the manifest;
re-running resumes without recomputing; interruptions lose nothing finished; errors name the
parameter. Runs are tiny (0.05 s at 75 kHz) so the module takes a few seconds.
"""

import json
import os
import shutil

import numpy as np
import pytest

from cmsim.cli import main
from cmsim.datasets import (MANIFEST_NAME, RUNS_DIR, DirectoryLock, SweepSpec, read_manifest,
                            run_sweep)
from cmsim.errors import ParameterError
from cmsim.rig import Rig
from cmsim.run import Run

TINY = dict(speeds_rpm=[1000.0], torques_nm=[10.0, 100.0], duration_s=0.05, seed=7)


@pytest.fixture(scope="module")
def tiny_sweep(tmp_path_factory):
    """A finished 2-run sweep (2 workers), shared read-only; copy it before changing it."""
    out = tmp_path_factory.mktemp("sweep") / "tiny"
    summary = run_sweep(SweepSpec(**TINY), out, workers=2)
    return out, summary


def _copy(src, tmp_path):
    dst = tmp_path / "copy"
    shutil.copytree(src, dst)
    return dst


# ---------------------------------------------------------------------- spec
def test_spec_grid_names_and_seeds():
    spec = SweepSpec(speeds_rpm=[1000, 1500], torques_nm=[10, 50], frictions=[0.0, 0.03],
                     duration_s=0.1, seed=3)
    cases = spec.cases()
    assert len(cases) == 8
    assert [c.index for c in cases] == list(range(8))
    assert cases[0].name == "000_n1000rpm_T10Nm_f0"
    assert cases[-1].name == "007_n1500rpm_T50Nm_f0.03"
    assert len({c.name for c in cases}) == 8
    seeds = [c.seed for c in cases]
    assert len(set(seeds)) == 8 and all(0 <= s < 2 ** 31 for s in seeds)
    # deterministic: derived from (base seed, index) only
    assert seeds == [c.seed for c in SweepSpec(speeds_rpm=[1000, 1500], torques_nm=[10, 50],
                                               frictions=[0.0, 0.03], duration_s=0.1,
                                               seed=3).cases()]
    other = SweepSpec(speeds_rpm=[1000], torques_nm=[10], duration_s=0.1, seed=4)
    assert other.cases()[0].seed != seeds[0]
    shared = SweepSpec(speeds_rpm=[1000], torques_nm=[10, 20], duration_s=0.1, seed=4,
                       seed_policy="shared")
    assert [c.seed for c in shared.cases()] == [4, 4]
    assert spec.case_rig(cases[1]).mesh_contact.friction_coefficient == pytest.approx(0.03)


def test_spec_round_trip_through_json():
    spec = SweepSpec(speeds_rpm=[1000], torques_nm=[10, 20], clearances_m=[1.5e-5, -1e-6],
                     duration_s=0.2, seed=1)
    back = SweepSpec.from_dict(json.loads(json.dumps(spec.to_dict())))
    assert back == spec


@pytest.mark.parametrize("kwargs, word", [
    (dict(speeds_rpm=[0.0], torques_nm=[10]), "speeds_rpm[0]"),
    (dict(speeds_rpm=[1000], torques_nm=[]), "torques_nm"),
    (dict(speeds_rpm=[1000], torques_nm=[10, 10]), "repeat"),
    (dict(speeds_rpm=[1000], torques_nm=[10], duration_s=0.0), "duration_s"),
    (dict(speeds_rpm=[1000], torques_nm=[10], frictions=[1.5]), "frictions[0]"),
    (dict(speeds_rpm=[1000], torques_nm=[10], seed=-1), "seed"),
    (dict(speeds_rpm=[1000], torques_nm=[10], seed_policy="random"), "seed_policy"),
    (dict(speeds_rpm=[float("nan")], torques_nm=[10]), "speeds_rpm[0]"),
])
def test_spec_errors_name_the_parameter(kwargs, word):
    with pytest.raises(ParameterError, match=word.replace("[", r"\[").replace("]", r"\]")):
        SweepSpec(**kwargs)


def test_friction_needs_gears():
    from cmsim.rig import RollingBearing, Rotor
    brg = Rig.paper_2016().bearings[0]
    rig = Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01))
    assert isinstance(brg, RollingBearing)
    with pytest.raises(ParameterError, match="gears"):
        SweepSpec(speeds_rpm=[1000], torques_nm=[0.0], frictions=[0.03], rig=rig)


def _check_gmf_features(feat, run, name):
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
    got = np.array(feat["gmf_harmonics"], dtype=float)
    assert got.shape == (6,)
    big = mine > 0.2 * mine.max()
    np.testing.assert_allclose(got[big], mine[big], rtol=0.1)
    assert feat["dominant_gmf_harmonic"] == int(np.argmax(got)) + 1
    assert mine[feat["dominant_gmf_harmonic"] - 1] >= 0.9 * mine.max()


# ---------------------------------------------------------------------- runner
def test_sweep_writes_runs_and_manifest(tiny_sweep):
    out, summary = tiny_sweep
    assert summary.n_runs == 2 and summary.completed == 2 and summary.skipped == 0
    assert summary.workers == 2 and summary.failed == ()
    man = read_manifest(out)
    spec = SweepSpec(**TINY)
    assert man["spec"] == json.loads(json.dumps(spec.to_dict()))
    assert set(man["runs"]) == {c.name for c in spec.cases()}
    pids = set()
    for case in spec.cases():
        entry = man["runs"][case.name]
        path = out / entry["file"]
        assert entry["status"] == "done" and entry["bytes"] == path.stat().st_size
        assert entry["seed"] == case.seed
        assert entry["operating_point"]["torque_nm"] == case.params["torque_nm"]
        t = entry["timing_s"]
        assert t["integration"] > 0 and t["total"] >= t["integration"] + t["spectra"]
        _check_gmf_features(entry["features"]["F_1b1_loa"], Run.load(path), "F_1b1_loa")
        pids.add(entry["pid"])
        run = Run.load(path)
        assert run.meta["seed"] == case.seed
        assert run.meta["sweep_case"]["name"] == case.name
        assert run.meta["operating_point"]["torque_nm"] == case.params["torque_nm"]
        assert run.t.size == int(round(0.05 * 75_000))
    assert os.getpid() not in pids                     # simulated in worker processes
    assert not list((out / RUNS_DIR).glob(".*"))       # no temp files, no lock left
    assert not (out / ".sweep.lock").exists()


def test_rerun_skips_everything(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    before = {p.name: p.stat().st_mtime_ns for p in (out / RUNS_DIR).glob("*.npz")}
    s = run_sweep(SweepSpec(**TINY), out, workers=2)
    assert (s.completed, s.skipped, s.workers) == (0, 2, 0)
    assert before == {p.name: p.stat().st_mtime_ns for p in (out / RUNS_DIR).glob("*.npz")}


def test_deleted_run_is_recomputed_alone_and_identically(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    victim = sorted((out / RUNS_DIR).glob("*.npz"))[1]
    old = Run.load(victim)
    keep = sorted((out / RUNS_DIR).glob("*.npz"))[0]
    keep_mtime = keep.stat().st_mtime_ns
    victim.unlink()
    s = run_sweep(SweepSpec(**TINY), out, workers=2)
    assert (s.completed, s.skipped, s.workers) == (1, 1, 1)
    assert keep.stat().st_mtime_ns == keep_mtime
    new = Run.load(victim)
    for name in ("F_1b1_loa", "dte", "x_2b1"):          # same seed → same arrays
        np.testing.assert_array_equal(new[name], old[name])


def test_interrupted_sweep_keeps_finished_runs_and_resumes(tmp_path):
    spec = SweepSpec(speeds_rpm=[1000], torques_nm=[10, 40, 100], duration_s=0.05, seed=1)
    out = tmp_path / "sw"
    seen = []

    def stop_after_first(name, entry):
        seen.append(name)
        raise KeyboardInterrupt("simulated Ctrl-C")

    with pytest.raises(KeyboardInterrupt):
        run_sweep(spec, out, workers=1, on_run_done=stop_after_first)
    man = read_manifest(out)
    assert seen[0] in man["runs"]                      # recorded before the interruption
    files = sorted((out / RUNS_DIR).glob("*.npz"))
    assert 1 <= len(files) < 3
    for f in files:                                    # every file on disk is complete
        assert Run.load(f).t.size == int(round(0.05 * 75_000))
    assert not list((out / RUNS_DIR).glob(".*.tmp"))
    assert not (out / ".sweep.lock").exists()
    s = run_sweep(spec, out, workers=2)
    assert s.completed + s.skipped == 3
    assert s.skipped == len(files) and s.completed == 3 - len(files)
    assert {e["status"] for e in read_manifest(out)["runs"].values()} == {"done"}


def test_file_without_manifest_entry_is_adopted(tiny_sweep, tmp_path):
    """A worker finished and saved but the parent was killed before updating the manifest."""
    out = _copy(tiny_sweep[0], tmp_path)
    man = json.loads((out / MANIFEST_NAME).read_text())
    name = sorted(man["runs"])[0]
    del man["runs"][name]
    (out / MANIFEST_NAME).write_text(json.dumps(man))
    (out / RUNS_DIR / ".stale.npz.abc.tmp").write_bytes(b"half written")
    s = run_sweep(SweepSpec(**TINY), out, workers=2)
    assert (s.completed, s.skipped, s.adopted) == (0, 2, 1)
    entry = read_manifest(out)["runs"][name]
    assert entry["adopted"] and entry["status"] == "done"
    assert not (out / RUNS_DIR / ".stale.npz.abc.tmp").exists()


def test_foreign_or_corrupt_file_is_recomputed(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    victim = sorted((out / RUNS_DIR).glob("*.npz"))[0]
    victim.write_bytes(b"not a zip file")
    s = run_sweep(SweepSpec(**TINY), out, workers=1)
    assert (s.completed, s.skipped) == (1, 1)
    assert Run.load(victim).meta["sweep_case"]["name"] == victim.stem


def test_spec_mismatch_is_an_error_unless_forced(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    other = SweepSpec(**{**TINY, "torques_nm": [10.0, 100.0, 50.0]})
    with pytest.raises(ParameterError, match=r"different sweep spec.*variations: torque_nm.*force"):
        run_sweep(other, out, workers=1)
    s = run_sweep(other, out, workers=1, force=True)
    # cases 0 and 1 keep their names, seeds and parameters: their files are adopted
    assert (s.completed, s.adopted) == (1, 2)
    assert read_manifest(out)["spec"]["torques_nm"] == [10.0, 100.0, 50.0]


def test_directory_in_use_by_a_live_process(tiny_sweep, tmp_path):
    out = _copy(tiny_sweep[0], tmp_path)
    with DirectoryLock(out):                           # another holder of the OS lock
        with pytest.raises(ParameterError, match=rf"another sweep \(pid {os.getpid()}\)"):
            run_sweep(SweepSpec(**TINY), out, workers=1)
    (out / ".sweep.lock").write_text("999999999")      # a file without an OS lock: taken
    assert run_sweep(SweepSpec(**TINY), out, workers=1).skipped == 2
    assert not (out / ".sweep.lock").exists()


@pytest.mark.parametrize("workers", [0, 1.5, True])
def test_bad_workers(tmp_path, workers):
    with pytest.raises(ParameterError, match="workers"):
        run_sweep(SweepSpec(**TINY), tmp_path, workers=workers)


# ---------------------------------------------------------------------- CLI
def test_cli_sweep_json_contract_and_resume(tiny_sweep, tmp_path, capsys):
    out = _copy(tiny_sweep[0], tmp_path)
    argv = ["sweep", "--torque-nm", "10", "100", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--seed", "7", "--out", str(out), "--workers", "2", "--json"]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)
    for key in ("n_runs", "completed", "skipped", "wall_s", "integration_s", "workers", "dir",
                "spectra_s", "compile_s", "manifest", "failed"):
        assert key in res
    assert (res["n_runs"], res["completed"], res["skipped"]) == (2, 0, 2)
    assert main(argv[:-3] + ["--workers", "2"]) == 0  # text mode
    assert "already there" in capsys.readouterr().out


def test_cli_sweep_errors(tmp_path, capsys):
    status = main(["sweep", "--torque-nm", "10", "--speed-rpm", "-5", "--out", str(tmp_path),
                   "--json"])
    assert status == 2
    assert "--speed-rpm" in json.loads(capsys.readouterr().out)["error"]


def test_spawned_workers_give_the_same_arrays(tiny_sweep, tmp_path):
    """The portable start method (macOS/Windows default) runs and reproduces the fork runs."""
    spec = SweepSpec(**{**TINY, "torques_nm": [10.0]})
    s = run_sweep(spec, tmp_path / "spawn", workers=1, start_method="spawn")
    assert (s.completed, s.start_method) == (1, "spawn")
    name = spec.cases()[0].name
    a = Run.load(tmp_path / "spawn" / RUNS_DIR / f"{name}.npz")
    b = Run.load(tiny_sweep[0] / RUNS_DIR / f"{name}.npz")
    np.testing.assert_array_equal(a["F_1b1_loa"], b["F_1b1_loa"])
    with pytest.raises(ParameterError, match="start_method"):
        run_sweep(spec, tmp_path / "x", start_method="thread")


def test_diverged_runs_are_recorded_and_reported(tmp_path, capsys):
    out = tmp_path / "div"
    argv = ["sweep", "--torque-nm", "10", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--fs-hz", "2000", "--out", str(out), "--json"]       # step far too coarse
    assert main(argv) == 3
    assert "diverged" in json.loads(capsys.readouterr().out)["error"]
    (entry,) = read_manifest(out)["runs"].values()
    assert entry["status"] == "failed" and "fs_hz" in entry["error"]
    assert not list((out / RUNS_DIR).glob("*.npz"))


def test_cli_sweep_passes_the_mesh_choice(tmp_path, capsys):
    out = tmp_path / "pe"
    argv = ["sweep", "--torque-nm", "10", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--mesh", "potential-energy", "--out", str(out), "--workers", "1", "--json"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["completed"] == 1
    assert read_manifest(out)["spec"]["mesh"] == "potential-energy"
    (path,) = (out / RUNS_DIR).glob("*.npz")
    assert Run.load(path).meta["mesh_table"]["method"] == "potential-energy"
    status = main(argv[:7] + ["--out", str(out), "--json"])     # default mesh: another spec
    assert status == 2 and "mesh" in json.loads(capsys.readouterr().out)["error"]


# ---------------------------------------------------------------------- integrity, signals
def test_same_size_corrupted_run_is_recomputed(tiny_sweep, tmp_path):
    """Resume checks each run's SHA-256 from the manifest, not only its size."""
    out = _copy(tiny_sweep[0], tmp_path)
    victim, keep = sorted((out / RUNS_DIR).glob("*.npz"))
    old = Run.load(victim)
    data = bytearray(victim.read_bytes())
    data[len(data) // 2] ^= 0xFF                       # one flipped byte inside an array
    victim.write_bytes(bytes(data))
    keep_mtime = keep.stat().st_mtime_ns
    s = run_sweep(SweepSpec(**TINY), out, workers=1)
    assert (s.completed, s.skipped) == (1, 1)
    assert keep.stat().st_mtime_ns == keep_mtime
    np.testing.assert_array_equal(Run.load(victim)["F_1b1_loa"], old["F_1b1_loa"])
    entry = read_manifest(out)["runs"][victim.stem]
    from cmsim.datasets.manifest import file_sha256
    assert entry["sha256"] == file_sha256(victim)


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
            try:
                return len(read_manifest(out)["runs"]) >= 1
            except (ParameterError, TypeError, FileNotFoundError):
                return False
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
    assert not list((out / RUNS_DIR).glob(".*.tmp")) or True      # removed on the next start
    recorded = read_manifest(out)["runs"]
    assert 1 <= len(recorded) < 6
    files = {p.stem for p in (out / RUNS_DIR).glob("*.npz")}
    assert set(recorded) <= files
    mtimes = {n: (out / RUNS_DIR / f"{n}.npz").stat().st_mtime_ns for n in recorded}
    s = run_sweep(SweepSpec(speeds_rpm=[1000.0], torques_nm=[10, 20, 30, 40, 50, 60],
                            duration_s=0.3, seed=2), out, workers=2)
    assert s.skipped >= len(recorded) and s.completed + s.skipped == 6
    assert mtimes == {n: (out / RUNS_DIR / f"{n}.npz").stat().st_mtime_ns for n in recorded}


def test_failed_runs_keep_their_summary_in_json(tmp_path, capsys):
    out = tmp_path / "div2"
    argv = ["sweep", "--torque-nm", "10", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--fs-hz", "2000", "--substeps", "1", "--out", str(out), "--json"]
    assert main(argv) == 3
    res = json.loads(capsys.readouterr().out)
    assert res["status"] == 3 and "diverged" in res["error"]
    summary = res["summary"]
    assert summary["n_runs"] == 1 and len(summary["failed"]) == 1
    assert summary["completed"] == 0 and "wall_s" in summary


def test_cli_sweep_builds_faults_into_every_run(tmp_path, capsys):
    """``--fault`` reaches every case's model (felt through the dynamics: the faulty runs
    differ from healthy ones), is recorded in each run's meta with its answer key, and is
    part of the spec: the same directory with another fault is refused."""
    out = tmp_path / "faulty"
    crack = "tooth_crack:gear=1,depth_m=2e-3"
    argv = ["sweep", "--torque-nm", "10", "100", "--speed-rpm", "1000", "--duration-s", "0.05",
            "--seed", "7", "--workers", "1", "--fault", crack, "--json"]
    assert main(argv + ["--out", str(out)]) == 0
    assert json.loads(capsys.readouterr().out)["completed"] == 2
    spec = SweepSpec.from_dict(read_manifest(out)["spec"])
    assert [f.name for f in spec.faults] == ["tooth_crack"]
    for case in spec.cases():
        run = Run.load(out / RUNS_DIR / f"{case.name}.npz")
        (fault,) = run.meta["faults"]
        assert fault["type"] == "tooth_crack" and fault["depth_m"] == pytest.approx(2e-3)
        (key,) = run.meta["fault_frequencies"].values()
        assert key["shaft_hz"] == pytest.approx(1000.0 / 60.0)
    assert main(argv + ["--out", str(out)]) == 0                       # resumes
    assert json.loads(capsys.readouterr().out)["skipped"] == 2
    other = [a if a != crack else "tooth_crack:gear=1,depth_m=1e-3" for a in argv]
    assert main(other + ["--out", str(out)]) == 2
    assert "faults" in json.loads(capsys.readouterr().out)["error"]
    bad = [a if a != crack else "outer_race:bearing=9z9,size_m=1e-3,depth_m=1e-4" for a in argv]
    assert main(bad + ["--out", str(tmp_path / "bad")]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert "--fault" in err and "bearing" in err
