"""The ``cmsim`` command line, called as ``main([...])``.

Tier (c) behaviour: JSON contracts of the issue (keys and consistency), exit codes and error
messages naming the parameter; ``python -m cmsim`` is the same command.
"""

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import cmsim
from cmsim.cli import main
from cmsim.run import Run


def run_json(capsys, argv):
    status = main(argv + ["--json"])
    out = capsys.readouterr().out
    return status, json.loads(out)


def test_simulate_json_and_npz(capsys, tmp_path):
    out = tmp_path / "run.npz"
    status, res = run_json(capsys, ["simulate", "--speed-rpm", "1000", "--torque-nm", "50",
                                    "--duration-s", "0.1", "--seed", "5", "--out", str(out)])
    assert status == 0
    for key in ("gmf_hz", "bpf_hz", "shaft_hz", "dte_mean_rad", "dte_rms_rad", "sim_s", "wall_s",
                "realtime_factor", "compile_s"):
        assert key in res
    assert res["gmf_hz"] == pytest.approx(466.667, abs=1e-3)
    assert res["realtime_factor"] == pytest.approx(res["sim_s"] / res["wall_s"])
    run = Run.load(out)
    assert run.meta["seed"] == 5
    for name in ("dte", "F_1b1_x", "F_2b2_oloa", "x_1G1", "y_2b1", "theta_2J2", "Fmesh_0"):
        assert name in run.signals
    assert np.mean(run["dte"]) == pytest.approx(res["dte_mean_rad"])


def test_simulate_with_options(capsys, tmp_path):
    rig = tmp_path / "rig.toml"
    from cmsim.rig import Rig
    from dataclasses import replace
    replace(Rig.paper_2016(), name="rig from a file").save(rig)
    runs = {}
    for label, extra in (("options", ["--rig", str(rig), "--friction", "0.03",
                                      "--clearance-m", "-1e-6"]), ("plain", [])):
        out = tmp_path / f"{label}.npz"
        status, res = run_json(capsys, ["simulate", "--speed-rpm", "1500", "--torque-nm", "20",
                                        "--duration-s", "0.05", "--seed", "1", "--out",
                                        str(out)] + extra)
        assert status == 0
        assert res["gmf_hz"] == pytest.approx(28 * 25)
        runs[label] = Run.load(out)
    meta = runs["options"].meta
    assert meta["rig"]["name"] == "rig from a file"
    assert meta["rig"]["mesh_contact"]["friction_coefficient"] == pytest.approx(0.03)
    clearances = {s[b]["clearance_m"] for s in meta["rig"]["shafts"]
                  for b in ("bearing_1", "bearing_2")}
    assert clearances == {-1e-6}
    assert meta["operating_point"]["speed_rpm"] == pytest.approx(1500.0)
    assert meta["operating_point"]["torque_nm"] == pytest.approx(20.0)
    # preload and friction change the physics: a stiffer support, friction across the LOA
    a, b = runs["options"], runs["plain"]
    assert abs(a["dte"].mean() - b["dte"].mean()) > 0.02 * abs(b["dte"].mean())
    diff = a["F_1b1_oloa"] - b["F_1b1_oloa"]           # same seed: the options make it
    assert np.sqrt(np.mean(diff ** 2)) > 0.1 * b["F_1b1_oloa"].std()


def test_modes_json(capsys):
    status, res = run_json(capsys, ["modes", "--torque-nm", "50"])
    assert status == 0
    f = res["frequencies_hz"]
    assert len(f) == len(res["types"]) == 19
    assert f == sorted(f)
    assert f[15] == pytest.approx(14382, rel=0.03)


def test_modes_of_a_bearing_rig_under_its_radial_load(capsys, tmp_path):
    """A rig without gears is loaded by --radial-load-n alone (it was refused for want of
    an option ``modes`` did not have): its modes stiffen with the load (Hertz)."""
    from cmsim.rig.presets import cwru_6205_rig

    cwru_6205_rig().save(tmp_path / "rig.toml")
    freqs = []
    for load in ("500", "5000"):
        status, res = run_json(capsys, ["modes", "--torque-nm", "0", "--radial-load-n", load,
                                        "--rig", str(tmp_path / "rig.toml"), "--positions",
                                        "4"])
        assert status == 0 and res["radial_load_n"] == float(load)
        freqs.append(np.array(res["frequencies_hz"]))
    assert np.all(freqs[1] >= freqs[0] - 1e-9) and np.any(freqs[1] > 1.05 * freqs[0])


@pytest.mark.parametrize("argv, word", [
    (["simulate", "--speed-rpm", "0"], "--speed-rpm"),
    (["simulate", "--speed-rpm", "1000", "--torque-nm", "nan"], "--torque-nm"),
    (["simulate", "--speed-rpm", "1000", "--clearance-m", "0.02"], "--clearance-m"),
    (["simulate", "--speed-rpm", "1000", "--clearance-m", "0.0009"], "--clearance-m"),
    (["simulate", "--speed-rpm", "1000", "--rig", "/nonexistent.toml"], "does not exist"),
    (["modes", "--torque-nm", "-5"], "--torque-nm"),
])
def test_bad_input_exit_code_and_message(capsys, argv, word):
    status = main(argv + ["--json"])
    cap = capsys.readouterr()
    assert status == 2
    assert word in json.loads(cap.out)["error"]
    assert word in cap.err


def test_divergence_exit_code(capsys):
    status = main(["simulate", "--speed-rpm", "100", "--torque-nm", "100", "--fs-hz", "2000", "--substeps", "1",
                   "--warmup-s", "0", "--duration-s", "0.2"])
    assert status == 3
    assert "diverged" in capsys.readouterr().err


def test_text_output(capsys):
    assert main(["modes", "--torque-nm", "10"]) == 0
    assert "natural frequencies" in capsys.readouterr().out


def test_unloaded_default_operating_point_runs(capsys):
    """Issue 10 item 1/10: no torque given is a valid operating point (exit 0)."""
    status, res = run_json(capsys, ["simulate", "--speed-rpm", "1000", "--duration-s", "0.02"])
    assert status == 0 and "warnings" not in res


def test_implausible_torque_warns(capsys):
    """1000 N m on a 6.35 mm face: a warning on stderr and in the JSON object."""
    status, res = run_json(capsys, ["modes", "--torque-nm", "1000"])
    assert status == 0
    assert len(res["warnings"]) == 1 and "MPa" in res["warnings"][0]
    assert main(["modes", "--torque-nm", "1000"]) == 0
    assert "warning: --torque-nm 1000" in capsys.readouterr().err


def test_bearing_rig_sweep_radial_load_and_report(capsys, tmp_path):
    """Issue 10 item 10: a bearing rig sweeps with --radial-load-n and no --torque-nm, and
    report works without dte_um."""
    import cmsim
    from cmsim.rig import Rig
    rig = Rig.rotor_on_bearings(Rig.paper_2016().bearings[0], cmsim.Rotor(3.0, 0.01))
    rig.save(tmp_path / "b.toml")
    out = tmp_path / "sw"
    status, res = run_json(capsys, ["sweep", "--speed-rpm", "1800", "--radial-load-n", "500",
                                    "--rig", str(tmp_path / "b.toml"), "--duration-s", "0.05",
                                    "--out", str(out), "--workers", "1"])
    assert status == 0 and res["records_written"] == 1
    run = Run.load(next((out / "records").glob("*.npz")))
    assert run.meta["operating_point"]["radial_load_n"] == pytest.approx(500.0)
    status, res = run_json(capsys, ["report", str(out)])
    assert status == 0 and "dte_um" not in " ".join(res["figures"])


def test_report_lists_the_grid_points_a_sweep_could_not_run(capsys, tmp_path):
    """Issue 26: 20000 N m diverges (the sweep exits 3); the report of the sweep then lists
    that grid point — in its JSON, on stderr, in the text and in the page's "Runs" — instead
    of reading as a sweep of one run."""
    out = tmp_path / "sw"
    status, _ = run_json(capsys, ["sweep", "--speed-rpm", "1000", "--torque-nm", "10", "20000",
                                  "--duration-s", "0.02", "--warmup-s", "0.01",
                                  "--workers", "1", "--out", str(out)])
    assert status == 3
    status, res = run_json(capsys, ["report", str(out)])
    assert status == 0 and res["n_runs"] == 1 and res["n_failed"] == 1
    (failed,) = res["failed"]
    assert failed["torque_nm"] == 20000.0 and "diverged" in failed["error"]
    assert "20000Nm" in res["warnings"][0] and "1 of 2 grid points failed" in res["warnings"][0]
    page = (out / "report.html").read_text()
    assert "1 of 2 grid points failed" in page and "Failed grid points" in page
    assert main(["report", str(out)]) == 0
    cap = capsys.readouterr()
    assert "1 failed grid points listed (001_n1000rpm_T20000Nm)" in cap.out
    assert "warning: 1 of 2 grid points failed" in cap.err


def test_no_help_text_shows_a_doubled_percent_sign():
    """argparse %-formats help strings but prints a parser's description as written: "5 %%"
    showed in ``cmsim evaluate --help`` (issue 26)."""
    from cmsim.cli import build_parser
    from cmsim.cli.contract import subparsers
    for command, sub in subparsers(build_parser()).items():
        assert "%%" not in sub.format_help(), command


def test_evaluate_text_says_when_a_class_was_never_detected():
    """A fault class none of whose records beat the threshold has no smallest detected
    severity (NaN): the text says so instead of "smallest severity detected nan"."""
    from cmsim.cli.evaluate import text
    res = {"algorithm": "envelope", "dataset": "d", "errors": {}, "unreadable": {},
           "report": None, "metrics": {
        "n_scored": 4, "n_records": 4, "n_failed": 0, "accuracy": 0.5, "chance_accuracy": 0.5,
        "macro_f1": 0.4, "auc": {},
        "detection": {"threshold": 0.3, "classes": {
            "outer_race": {"detection_rate_all": 0.0, "min_detected_severity": float("nan")},
            "ball": {"detection_rate_all": 0.5, "min_detected_severity": 2e-4}}}}}
    out = text(res)
    assert "nan" not in out
    assert "outer_race: detected 0.00 at 5 % false alarms, no record detected" in out
    assert "ball: detected 0.50 at 5 % false alarms, smallest severity detected 0.0002" in out


def test_simulate_announces_the_compile_before_it_compiles(monkeypatch, capsys):
    """On a cold numba cache the notice is on stderr when the kernels start compiling (it
    came from the start callback, after a silent 1-3 min compile)."""
    import cmsim.dynamics.simulation as simulation

    seen = []

    def compile_seconds():
        seen.append(capsys.readouterr().err)
        raise KeyboardInterrupt

    monkeypatch.setattr(simulation, "kernels_cached", lambda: False)
    monkeypatch.setattr(simulation, "_compile_seconds", compile_seconds)
    main(["simulate", "--speed-rpm", "1000", "--duration-s", "0.01"])
    assert seen and "compiling numba kernels" in seen[0]


def test_json_stdout_stays_one_object_while_the_compile_progress_is_on_stderr(monkeypatch,
                                                                              capsys):
    """A cold cache with --json (issue 28): the compile's start, heartbeat and end lines go
    to stderr and stdout holds exactly the run's JSON object; the run compiles once."""
    import cmsim.dynamics.simulation as simulation
    import cmsim.progress as progress

    real = simulation._compile_seconds

    def slow_compile():
        time.sleep(0.35)
        slow_compile.value = real()
        return slow_compile.value

    monkeypatch.setattr(simulation, "kernels_cached", lambda: False)
    monkeypatch.setattr(simulation, "_compile_seconds", slow_compile)
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.1)
    assert main(["simulate", "--speed-rpm", "1000", "--duration-s", "0.01", "--json"]) == 0
    cap = capsys.readouterr()
    res = json.loads(cap.out)                      # one object, nothing around it
    assert isinstance(res, dict) and res["compile_s"] >= 0
    err = cap.err.splitlines()
    assert err[0].startswith("cmsim: compiling numba kernels")
    assert any("still running" in line for line in err)
    assert sum("compiling numba kernels" in line and "done in" in line for line in err) == 1


def test_python_m_cmsim_is_the_command(tmp_path):
    """``python -m cmsim`` runs ``main`` and exits with its status (here the cmsim this test
    imports, whichever checkout that is)."""
    root = str(Path(cmsim.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (root, os.environ.get("PYTHONPATH")) if p)}

    def python_m(*argv):
        return subprocess.run([sys.executable, "-m", "cmsim", *argv], capture_output=True,
                              text=True, env=env, cwd=tmp_path, timeout=120)

    done = python_m("--help")
    assert done.returncode == 0 and done.stdout.startswith("usage: cmsim")
    done = python_m("export", "missing.npz", "--format", "npz", "--out", "x", "--json")
    assert done.returncode == 2
    assert json.loads(done.stdout)["option"] == "RUN|DATASET"


def test_the_console_script_ends_without_teardown_and_loses_nothing(tmp_path):
    """The console script ends the process at once after the command (the interpreter's
    teardown costs a comparison 0.2-0.5 s): the result written to a file through stdout's
    buffer arrives whole, the exit handlers run (a library's, registered before), the status
    is the command's; a thread still running is joined as Python does."""
    root = str(Path(cmsim.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (root, os.environ.get("PYTHONPATH")) if p)}
    script = ("import atexit, sys, threading, time\n"
              "import cmsim.cli.app as app\n"
              "atexit.register(lambda: print('exit handler ran', file=sys.stderr))\n"
              "if sys.argv[1] == 'thread':\n"
              "    threading.Thread(target=lambda: (time.sleep(1.0), print('joined', "
              "file=sys.stderr))).start()\n"
              "sys.argv = ['cmsim'] + sys.argv[2:]\n"
              "app.console()\n")
    argv = ["modes", "--torque-nm", "50", "--json"]
    for mode in ("alone", "thread"):
        out = tmp_path / f"{mode}.json"
        with open(out, "w") as fh:
            done = subprocess.run([sys.executable, "-c", script, mode, *argv], stdout=fh,
                                  stderr=subprocess.PIPE, text=True, env=env, timeout=300)
        assert done.returncode == 0, done.stderr
        assert "exit handler ran" in done.stderr
        assert ("joined" in done.stderr) == (mode == "thread")
        assert json.loads(out.read_text())["frequencies_hz"]    # whole, flushed
    done = subprocess.run([sys.executable, "-c", script, "alone", "modes", "--torque-nm", "-5",
                           "--json"], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 2 and json.loads(done.stdout)["option"] == "--torque-nm"


def test_simulate_warns_when_the_mesh_lies_above_the_nyquist(capsys):
    """Issue 48: at 100000 rpm the paper rig's mesh (46.7 kHz) lies above the default
    75-kHz record's Nyquist frequency; the run is written with a warning naming the option
    to raise (--fs-hz, or --sensor-fs-hz for the sensor record). None at 1000 rpm."""
    argv = ["simulate", "--torque-nm", "50", "--duration-s", "0.02", "--warmup-s", "0.01",
            "--json"]
    assert main(argv + ["--speed-rpm", "100000"]) == 0
    said = json.loads(capsys.readouterr().out)["warnings"]
    assert any("GMF 46667 Hz" in w and "--fs-hz 75000" in w and "raise --fs-hz" in w
               for w in said), said
    assert main(argv + ["--speed-rpm", "30000", "--sensor-fs-hz", "25000"]) == 0
    said = json.loads(capsys.readouterr().out)["warnings"]
    assert any("GMF 14000 Hz" in w and "--sensor-fs-hz 25000" in w for w in said), said
    assert main(argv + ["--speed-rpm", "1000"]) == 0
    assert "warnings" not in json.loads(capsys.readouterr().out)


def test_an_interrupted_dataset_says_what_it_kept(monkeypatch, tmp_path, capsys):
    """Ctrl-C on `dataset` before any record is finished says that nothing was kept (it
    named a folder that did not exist); the words count a folder's finished records from its
    manifest rows."""
    import cmsim.datasets as datasets
    from cmsim.cli.dataset import interrupted_words

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(datasets, "generate_dataset", interrupted)
    spec = Path(__file__).resolve().parents[2] / "datasets" / "ci.toml"
    status = main(["dataset", str(spec), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 130 and "no records were finished yet" in err, err
    assert not (tmp_path / "out").exists()
    assert "no runs were finished" in interrupted_words(tmp_path, "runs")


def test_a_ramp_longer_than_the_record_warns_with_the_speed_it_reaches(capsys):
    """--ramp-s beyond the record: the run is made, and a warning gives the speed the record
    reaches (the profile's own, 1020 rpm of 1000 → 2000 over 5 s at 0.1 s); a ramp that ends
    inside the record warns nothing."""
    status = main(["simulate", "--speed-rpm", "1000", "--duration-s", "0.05", "--ramp-to-rpm",
                   "2000", "--ramp-s", "5", "--json"])
    res = json.loads(capsys.readouterr().out)
    assert status == 0
    assert any("reaches 1020 rpm" in w for w in res["warnings"]), res["warnings"]
    status = main(["simulate", "--speed-rpm", "1000", "--duration-s", "0.05", "--ramp-to-rpm",
                   "2000", "--json"])
    res = json.loads(capsys.readouterr().out)
    assert status == 0 and not any("--ramp-s" in w for w in res.get("warnings", [])), res
