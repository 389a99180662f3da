"""Every option of ``cmsim simulate``, ``cmsim sweep`` and ``cmsim mesh-table`` reaches the run.

Tier: behaviour contracts (table-driven). An option that is parsed but not passed on is
silently ignored: the run is made with the default and nothing says so. Each row below
changes one option from a baseline command and names where the saved run's ``meta`` must
show it; options that change the physics are also checked on the signals (the baseline and
the changed run share their seed, so any difference comes from the option).
"""

import dataclasses
import json

import numpy as np
import pytest

from cmsim.cli import main
from cmsim.datasets import RECORDS_DIR
from cmsim.mesh_stiffness.table_set import MeshTableSet
from cmsim.rig import Rig
from cmsim.run import Run

BASE = ["simulate", "--speed-rpm", "1000", "--torque-nm", "20", "--duration-s", "0.02",
        "--warmup-s", "0.01", "--mesh", "potential-energy", "--seed", "1"]


def _bearings(meta):
    return [s[k] for s in meta["rig"]["shafts"] for k in ("bearing_1", "bearing_2")]


def _simulate(tmp_path, capsys, extra, name):
    out = tmp_path / f"{name}.npz"
    argv = list(BASE)
    for i in range(0, len(extra), 2):           # a repeated option replaces the baseline's
        if extra[i] in argv:
            argv[argv.index(extra[i]) + 1] = extra[i + 1]
        else:
            argv += extra[i:i + 2]
    status = main(argv + ["--out", str(out), "--json"])
    res = json.loads(capsys.readouterr().out)
    assert status == 0, res
    return Run.load(out)


@pytest.fixture(scope="module")
def base_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "base.npz"
    assert main(BASE + ["--out", str(out), "--json"]) == 0
    return Run.load(out)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("inputs")
    dataclasses.replace(Rig.paper_2016(), name="my rig").save(d / "rig.toml")
    assert main(["mesh-table", "--method", "potential-energy", "--torque-nm", "10", "50",
                 "--steps", "24", "--out", str(d / "tables.npz"), "--json"]) == 0
    return d


def _differs(a, b, name, rel=1e-3):
    return np.abs(np.mean(a[name]) - np.mean(b[name])) > rel * np.abs(np.mean(b[name]))


# (option, value, check of the run's meta, check of the physics against the baseline or None)
SIMULATE_OPTIONS = [
    ("--speed-rpm", "1500", lambda m: m["operating_point"]["speed_rpm"] == 1500.0,
     lambda r, b: np.polyfit(r.t, r["theta_1G1"], 1)[0] > 1.4 * np.polyfit(b.t, b["theta_1G1"],
                                                                            1)[0]),
    ("--torque-nm", "35", lambda m: m["operating_point"]["torque_nm"] == 35.0,
     lambda r, b: r["Fmesh_total"].mean() > 1.5 * b["Fmesh_total"].mean()),
    ("--radial-load-n", "300", lambda m: m["operating_point"]["radial_load_n"] == 300.0,
     lambda r, b: _differs(r, b, "F_1b1_x")),
    ("--duration-s", "0.03", lambda m: abs(m["duration_s"] - 0.03) < 1e-12,
     lambda r, b: r.t.size == int(round(1.5 * b.t.size))),
    ("--fs-hz", "50000", lambda m: m["fs_hz"] == 50_000.0,
     lambda r, b: abs(r.fs_hz - 50_000.0) < 1e-6),
    ("--substeps", "3", lambda m: m["substeps"] == 3 and m["anti_alias"] is not None, None),
    ("--warmup-s", "0.02", lambda m: abs(m["warmup_s"] - 0.02) < 1e-12,
     lambda r, b: abs(r.t[0] - 0.02) < 1e-12),
    ("--mesh", "hybrid-tables", lambda m: m["mesh_table"]["method"] == "hybrid",
     lambda r, b: _differs(r, b, "dte")),
    ("--cage-slip", "0.02", lambda m: m["slip"]["cage_speed_rms"] == 0.02,
     lambda r, b: not np.allclose(r["F_1b1_x"], b["F_1b1_x"], rtol=1e-6)),
    ("--ball-jitter-rad", "0.01", lambda m: m["slip"]["ball_rms_rad"] == 0.01,
     lambda r, b: not np.allclose(r["F_1b1_x"], b["F_1b1_x"], rtol=1e-6)),
    ("--slip-correlation-s", "0.002", lambda m: m["slip"]["correlation_s"] == 0.002, None),
    ("--seed", "9", lambda m: m["seed"] == 9,
     lambda r, b: not np.allclose(r["F_1b1_x"], b["F_1b1_x"], rtol=1e-6)),
    ("--clearance-m", "-1e-6", lambda m: all(b["clearance_m"] == -1e-6 for b in _bearings(m)),
     lambda r, b: _differs(r, b, "dte")),
    ("--friction", "0.08",
     lambda m: m["rig"]["mesh_contact"]["friction_coefficient"] == 0.08,
     lambda r, b: _differs(r, b, "F_1b1_oloa", rel=0.01)),
]


@pytest.mark.parametrize("option, value, meta_ok, physics_ok", SIMULATE_OPTIONS,
                         ids=[row[0] for row in SIMULATE_OPTIONS])
def test_simulate_option_reaches_the_run(tmp_path, capsys, base_run, option, value, meta_ok,
                                         physics_ok):
    assert not meta_ok(base_run.meta), "the baseline must not already satisfy the check"
    run = _simulate(tmp_path, capsys, [option, value], option.strip("-"))
    assert meta_ok(run.meta)
    if physics_ok is not None:
        assert physics_ok(run, base_run)


def test_slip_correlation_changes_a_slipping_run(tmp_path, capsys):
    a = _simulate(tmp_path, capsys, ["--cage-slip", "0.02"], "slip_a")
    b = _simulate(tmp_path, capsys, ["--cage-slip", "0.02", "--slip-correlation-s", "0.002"],
                  "slip_b")
    assert b.meta["slip"]["correlation_s"] == 0.002
    assert not np.allclose(a["F_1b1_x"], b["F_1b1_x"], rtol=1e-6)


def test_rig_file_reaches_the_run(tmp_path, capsys, files):
    run = _simulate(tmp_path, capsys, ["--rig", str(files / "rig.toml")], "rig")
    assert run.meta["rig"]["name"] == "my rig"


@pytest.mark.parametrize("extra, torque", [([], 20.0), (["--table-torque-nm", "50"], 50.0)])
def test_mesh_table_file_reaches_the_run(tmp_path, capsys, files, extra, torque):
    argv = ["--mesh", "hybrid-tables", "--mesh-table", str(files / "tables.npz")] + extra
    run = _simulate(tmp_path, capsys, argv, "table")
    assert run.meta["mesh_table"]["method"] == "potential-energy"
    assert run.meta["mesh_table"]["torque_nm"] == pytest.approx(torque)


def test_mesh_table_options_reach_the_tables(files):
    tables = MeshTableSet.load(files / "tables.npz")
    assert tables.meta["method"] == "potential-energy"
    assert [t.torque_nm for t in tables.tables] == [10.0, 50.0]


def test_sweep_options_reach_the_runs(tmp_path, capsys):
    out = tmp_path / "sw"
    argv = ["sweep", "--torque-nm", "15", "--speed-rpm", "1200", "--duration-s", "0.02",
            "--warmup-s", "0.015", "--fs-hz", "50000", "--substeps", "2", "--friction", "0.07",
            "--clearance-m", "-2e-6", "--seed", "11", "--seed-policy", "shared",
            "--mesh", "potential-energy", "--workers", "1", "--out", str(out), "--json"]
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["records_written"] == 1
    (path,) = (out / RECORDS_DIR).glob("*.npz")
    m = Run.load(path).meta
    assert m["operating_point"]["torque_nm"] == 15.0
    assert m["operating_point"]["speed_rpm"] == 1200.0
    assert abs(m["duration_s"] - 0.02) < 1e-12
    assert abs(m["warmup_s"] - 0.015) < 1e-12
    assert m["fs_hz"] == 50_000.0 and m["substeps"] == 2
    assert m["rig"]["mesh_contact"]["friction_coefficient"] == 0.07
    assert all(b["clearance_m"] == -2e-6 for b in _bearings(m))
    assert m["seed"] == 11                              # shared policy: the base seed itself
    assert m["record"]["base_seed"] == 11 and m["record"]["seed_policy"] == "shared"
    assert m["mesh_table"]["method"] == "potential-energy"
