"""Dataset generator (issue 11): spec checks, records, Parquet manifest, resume, runners, load.

Test tier: behaviour contracts (no physics): every record is drawn from (base seed, index)
alone and is bit-identical on 1 worker, 2 workers and a Dask cluster; an interrupted run
(killed process) loses nothing finished and recomputes nothing; bad specs are refused before
any work, naming the key; the CI-sized standard spec generates. Records are short (0.05-0.2 s).
"""

import copy
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from cmsim.cli import main
from cmsim.datasets import DatasetSpec, generate_dataset, load
from cmsim.datasets.manifest import PARQUET_NAME, RECORDS_DIR, ROWS_DIR, consolidate
from cmsim.errors import ParameterError

ROOT = Path(__file__).resolve().parents[3]
CI_SPEC = ROOT / "datasets" / "ci.toml"

SMALL = {
    "dataset": {"name": "small", "records": 6, "seed": 5},
    "rig": {"builtin": "paper_2016"},
    "operating": {"speed_rpm": {"distribution": "uniform", "min": 950.0, "max": 1050.0},
                  "torque_nm": [20.0, 60.0]},
    "faults": {"healthy_share": 0.3,
               "types": [{"type": "outer_race", "bearing": ["1b1", "2b1"],
                          "size_m": {"min": 0.5e-3, "max": 1.5e-3}, "depth_m": 1e-4}]},
    "nuisances": {"sensor_noise_m_s2": {"min": 0.0, "max": 0.02}, "slip": 0.002},
    "sensor": {"channels": ["accel_1b1_y", "tacho", "dte_um"], "fs_hz": 25600.0,
               "duration_s": 0.05, "warmup_s": 0.02},
}


def _records(out):
    """{record_id: {channel: array}} of a dataset directory."""
    ds = load(out)
    return {r.record_id: {c: np.asarray(r.signals[c]) for c in ds.channels} for r in ds}


def _same(a, b):
    assert sorted(a) == sorted(b)
    for rid in a:
        for c in a[rid]:
            np.testing.assert_array_equal(a[rid][c], b[rid][c], err_msg=f"{rid} {c}")


@pytest.fixture(scope="module")
def ci_dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "ci"
    spec = DatasetSpec.load(CI_SPEC)
    summary = generate_dataset(spec, out, workers=2)
    return out, spec, summary


@pytest.fixture(scope="module")
def small_one_worker(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "small1"
    generate_dataset(DatasetSpec.from_dict(SMALL), out, workers=1)
    return out


# ---------------------------------------------------------------------- the CI spec
def test_ci_spec_generates_a_labelled_dataset(ci_dataset):
    out, spec, s = ci_dataset
    assert (s.records_total, s.records_written, s.records_failed) == (24, 24, 0)
    assert s.wall_s < 120
    ds = load(out)
    m = ds.manifest
    for col in ("record_id", "index", "seed", "status", "error", "path", "wall_s", "rig_name",
                "speed_rpm", "torque_nm", "radial_load_n", "fault_label", "fault_component",
                "fault_severity", "shaft_hz", "gmf_hz", "bpfo_hz_1b1", "bpfi_hz_1b1",
                "bsf_hz_1b1", "ftf_hz_1b1", "sensor_noise_m_s2", "slip", "speed_wobble"):
        assert col in m.columns, col
    assert list(m["index"]) == list(range(24)) and set(m["status"]) == {"ok"}
    assert {"healthy", "outer_race", "inner_race", "tooth_crack"} <= set(m["fault_label"])
    healthy = m["fault_label"] == "healthy"
    assert m.loc[healthy, "fault_severity"].isna().all()
    assert (m.loc[~healthy, "fault_severity"] > 0).all()
    assert m["speed_rpm"].between(900, 1100).all() and m["torque_nm"].between(20, 80).all()
    np.testing.assert_allclose(m["gmf_hz"], 28 * m["speed_rpm"] / 60, rtol=1e-9)
    assert ds.channels == ("accel_1b1_y", "accel_2b1_y", "tacho", "dte_um")
    assert ds.fs_hz == pytest.approx(25_600.0) and len(ds) == 24
    rec = ds.record(3)
    assert rec.labels["fault_label"] == m["fault_label"][3]
    sig = rec.signals["accel_1b1_y"]
    assert sig.dtype == np.float32 and sig.size == m["n_samples"][3]
    assert rec.operating_point.speed_rpm == pytest.approx(m["speed_rpm"][3])
    assert rec.frequencies.gmf_hz == pytest.approx(m["gmf_hz"][3])
    # compact: only the channels, float32 (4 channels x 0.2 s x 25.6 kHz x 4 B ~ 82 kB)
    size = (out / m["path"][3]).stat().st_size
    assert size < 4 * 0.21 * 25_600 * 4 + 40_000          # + the meta (rig, answer key)
    assert not list((out / ROWS_DIR).glob("*.json"))      # consolidated into Parquet
    # each record regenerates on its own from (base seed, index)
    from cmsim.datasets.records import simulate_record
    alone, _ = simulate_record(spec, 5)
    np.testing.assert_array_equal(alone["accel_2b1_y"], ds.record(5).signals["accel_2b1_y"])


def test_to_arrays_keeps_a_record_in_one_group(ci_dataset):
    ds = load(ci_dataset[0])
    X, y, groups = ds.to_arrays(["accel_1b1_y", "tacho"], window=1024, hop=512)
    n = ds.manifest["n_samples"].to_numpy()
    assert X.shape == (int(((n - 1024) // 512 + 1).sum()), 2, 1024) and X.dtype == np.float32
    labels = dict(zip(ds.manifest["record_id"], ds.manifest["fault_label"]))
    assert all(labels[g] == lab for g, lab in zip(groups, y))
    first = ds.record(0).signals["tacho"]
    np.testing.assert_array_equal(X[1, 1], first[512:1536])
    # a subset and a batch generator for datasets bigger than memory
    Xs, ys, gs = ds.to_arrays(["tacho"], window=2048, records=["000002", "000004"])
    assert set(gs) == {"000002", "000004"}
    batches = list(ds.iter_arrays(["tacho"], window=2048, batch_records=5))
    assert len(batches) == 5 and sum(b[0].shape[0] for b in batches) == \
        ds.to_arrays(["tacho"], window=2048)[0].shape[0]
    with pytest.raises(ParameterError, match="channels"):
        ds.to_arrays(["F_1b1_loa"])


# ---------------------------------------------------------------------- runners
def test_same_records_on_one_worker_two_workers_and_dask(small_one_worker, tmp_path):
    one = _records(small_one_worker)
    generate_dataset(DatasetSpec.from_dict(SMALL), tmp_path / "two", workers=2)
    _same(one, _records(tmp_path / "two"))
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        s = generate_dataset(DatasetSpec.from_dict(SMALL), tmp_path / "dask", scheduler=client)
    assert (s.runner, s.records_written, s.workers) == ("dask", 6, 2)
    _same(one, _records(tmp_path / "dask"))
    # resume on Dask recomputes nothing
    with distributed.LocalCluster(n_workers=2, processes=False,
                                  dashboard_address=None) as cluster:
        s = generate_dataset(DatasetSpec.from_dict(SMALL), tmp_path / "dask",
                             scheduler=cluster.scheduler_address)
    assert (s.records_written, s.records_skipped) == (0, 6)


def test_killed_run_resumes_without_recomputing(small_one_worker, tmp_path):
    spec = copy.deepcopy(SMALL)
    spec["dataset"]["records"] = 6
    spec["sensor"]["duration_s"] = 0.3
    spec_file = tmp_path / "spec.toml"
    import tomli_w
    spec_file.write_text(tomli_w.dumps(spec))
    out = tmp_path / "killed"
    proc = subprocess.Popen([sys.executable, "-m", "cmsim.cli", "dataset", str(spec_file),
                             "--out", str(out), "--workers", "1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        end = time.monotonic() + 180
        while time.monotonic() < end and proc.poll() is None:
            if len(list((out / ROWS_DIR).glob("0*.json"))) >= 2:
                break
            time.sleep(0.05)
        assert proc.poll() is None, proc.stderr.read()
        os.killpg(os.getpgid(proc.pid), 0)
        proc.send_signal(signal.SIGKILL)                 # no chance to clean up
        proc.wait(30)
    finally:
        if proc.poll() is None:
            proc.kill()
    # resumed at once: the killed run's workers hold no lock and die with it (no waiting)
    done = sorted(p.stem for p in (out / ROWS_DIR).glob("0*.json"))
    assert 2 <= len(done) < 6
    mtimes = {r: (out / RECORDS_DIR / f"{r}.npz").stat().st_mtime_ns for r in done}
    s = generate_dataset(DatasetSpec.from_dict(spec), out, workers=2)
    assert s.records_skipped >= len(done)
    assert s.records_written + s.records_skipped == 6 and s.records_failed == 0
    assert mtimes == {r: (out / RECORDS_DIR / f"{r}.npz").stat().st_mtime_ns for r in done}
    again = generate_dataset(DatasetSpec.from_dict(spec), tmp_path / "whole", workers=1)
    assert again.records_written == 6
    _same(_records(out), _records(tmp_path / "whole"))


def test_failed_record_is_marked_and_the_rest_go_on(tmp_path, monkeypatch):
    import cmsim.datasets.records as gen
    real = gen.simulate_records

    def flaky(spec, plans, batch_size=None):
        from cmsim.errors import IntegrationDiverged
        return [IntegrationDiverged("integration diverged at t = 0.01 s (test)")
                if plan.index == 2 else res
                for plan, res in zip(plans, real(spec, plans, batch_size))]

    monkeypatch.setattr(gen, "simulate_records", flaky)     # forked workers inherit it
    s = generate_dataset(DatasetSpec.from_dict(SMALL), tmp_path / "f", workers=2,
                         start_method="fork")
    assert (s.records_written, s.records_failed) == (5, 1)
    assert s.failed[0][0] == "000002" and "diverged" in s.failed[0][1]
    ds = load(tmp_path / "f")
    row = ds.manifest.iloc[2]
    assert row["status"] == "failed" and "IntegrationDiverged" in row["error"]
    assert len(ds) == 5 and "000002" not in {r.record_id for r in ds}
    monkeypatch.setattr(gen, "simulate_records", real)
    s = generate_dataset(DatasetSpec.from_dict(SMALL), tmp_path / "f", workers=1)
    assert (s.records_written, s.records_skipped) == (0, 6)     # failed ones are not retried


def test_corrupted_record_is_recomputed_with_verify(small_one_worker, tmp_path):
    import shutil
    out = tmp_path / "c"
    shutil.copytree(small_one_worker, out)
    victim = out / RECORDS_DIR / "000001.npz"
    data = bytearray(victim.read_bytes())
    data[len(data) // 2] ^= 0xFF
    victim.write_bytes(bytes(data))
    assert generate_dataset(DatasetSpec.from_dict(SMALL), out, workers=1).records_written == 0
    s = generate_dataset(DatasetSpec.from_dict(SMALL), out, workers=1, verify=True)
    assert (s.records_written, s.records_skipped) == (1, 5)
    _same(_records(out), _records(small_one_worker))


def test_orphan_record_without_row_is_adopted(small_one_worker, tmp_path):
    """Killed between a record's file and its row: the row kept in the file is used."""
    import pandas as pd
    import shutil
    out = tmp_path / "o"
    shutil.copytree(small_one_worker, out)
    df = pd.read_parquet(out / PARQUET_NAME)
    df[df["index"] != 4].to_parquet(out / PARQUET_NAME, index=False)
    s = generate_dataset(DatasetSpec.from_dict(SMALL), out, workers=1)
    assert (s.records_written, s.records_skipped) == (0, 6)
    assert len(load(out).manifest) == 6


def test_manifest_of_many_records_resumes_fast(tmp_path):
    """A synthetic almost-finished dataset of 20 000 records: resume reads the Parquet
    manifest and stats each file, without reading the records."""
    import pandas as pd
    spec = copy.deepcopy(SMALL)
    spec["dataset"]["records"] = 20_000
    spec = DatasetSpec.from_dict(spec)
    out = tmp_path / "big"
    (out / RECORDS_DIR).mkdir(parents=True)
    (out / ROWS_DIR).mkdir()
    n_done = 19_998
    for i in range(n_done):
        (out / RECORDS_DIR / f"{i:06d}.npz").touch()
    pd.DataFrame({"record_id": [f"{i:06d}" for i in range(n_done)], "index": range(n_done),
                  "status": "ok", "path": [f"records/{i:06d}.npz" for i in range(n_done)],
                  "bytes": 0, "spec_digest": spec.digest, "fault_label": "healthy"}
                 ).to_parquet(out / PARQUET_NAME, index=False)
    from cmsim.datasets.manifest import SPEC_NAME, done_indices, open_directory
    open_directory(spec, out, False)
    t = time.perf_counter()
    done, adopted = done_indices(spec, out, verify=False)
    assert time.perf_counter() - t < 10
    assert len(done) == n_done and adopted == 0
    (out / ROWS_DIR / "019998.json").write_text(json.dumps(
        {"record_id": "019998", "index": 19998, "status": "failed", "error": "x",
         "path": "records/019998.npz", "spec_digest": spec.digest, "fault_label": "healthy"}))
    assert consolidate(out) == n_done + 1
    assert not list((out / ROWS_DIR).glob("*.json")) and (out / SPEC_NAME).is_file()


# ---------------------------------------------------------------------- bad specs
def _bad(path, value):
    spec = copy.deepcopy(SMALL)
    node = spec
    keys = path.split(".")
    for k in keys[:-1]:
        node = node[int(k)] if k.isdigit() else node.setdefault(k, {})
    if value is KeyError:
        del node[keys[-1]]
    else:
        node[int(keys[-1]) if keys[-1].isdigit() else keys[-1]] = value
    return spec


@pytest.mark.parametrize("path, value, key", [
    ("dataset.recrods", 5, "dataset.recrods"),                       # unknown key
    ("sensors", {}, "sensors"),                                      # unknown table
    ("dataset.records", 0, "dataset.records"),                       # zero records
    ("operating.speed_rpm", {"min": 1200.0, "max": 900.0}, "operating.speed_rpm.max"),
    ("operating.speed_rpm", -5.0, "operating.speed_rpm"),
    ("operating.torque_nm", {"distribution": "gamma", "min": 1, "max": 2},
     "operating.torque_nm.distribution"),
    ("operating.friction", 2.0, "operating.friction"),
    ("faults.types.0.type", "cracked_race", "faults.types[0].type"),  # unknown fault
    ("faults.types.0.bearing", ["9b9"], "faults.types[0].bearing[0]"),  # unknown bearing
    ("faults.types.0.size_m", {"min": 0.5e-3, "max": 0.5}, "faults.types[0].size_m"),
    ("faults.types.0.colour", "red", "faults.types[0].colour"),
    ("faults.healthy_share", 1.5, "faults.healthy_share"),
    ("sensor.channels", ["accel_9b9_y"], "sensor.channels[0]"),
    ("sensor.duration_s", 0.0, "sensor.duration_s"),
    ("rig.builtin", "paper_2017", "rig.builtin"),
    ("nuisances.slip", 0.9, "nuisances.slip"),
])
def test_bad_specs_are_refused_naming_the_key(path, value, key):
    with pytest.raises(ParameterError) as info:
        DatasetSpec.from_dict(_bad(path, value))
    assert key in str(info.value)


def test_cli_dataset_bad_spec_does_no_work(tmp_path, capsys):
    import tomli_w
    spec_file = tmp_path / "bad.toml"
    spec_file.write_text(tomli_w.dumps(_bad("dataset.records", 0)))
    out = tmp_path / "never"
    assert main(["dataset", str(spec_file), "--out", str(out), "--json"]) == 2
    res = json.loads(capsys.readouterr().out)
    assert "dataset.records" in res["error"] and res["option"] == "SPEC"
    assert not out.exists()


def test_cli_dataset_json_and_spec_mismatch(small_one_worker, tmp_path, capsys):
    import shutil
    import tomli_w
    out = tmp_path / "cli"
    shutil.copytree(small_one_worker, out)
    spec_file = tmp_path / "s.toml"
    spec_file.write_text(tomli_w.dumps(SMALL))
    assert main(["dataset", str(spec_file), "--out", str(out), "--workers", "1", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    for key in ("records_total", "records_written", "records_skipped", "records_failed",
                "wall_s"):
        assert key in res
    assert (res["records_total"], res["records_skipped"]) == (6, 6)
    spec_file.write_text(tomli_w.dumps(_bad("dataset.seed", 6)))
    assert main(["dataset", str(spec_file), "--out", str(out), "--json"]) == 2
    assert "different spec" in json.loads(capsys.readouterr().out)["error"]


def test_standard_specs_parse():
    for path in sorted((ROOT / "datasets").glob("*.toml")):
        spec = DatasetSpec.load(path)
        assert len(spec) >= 1 and spec.channels


@pytest.mark.parametrize("channels, simulated", [
    (["accel_1b1_y", "accel_2b1_y", "dte_um", "tacho"],
     ["F_1b1_y", "F_2b1_y", "dte_um", "theta_1b1"]),
    (["accel_1b1_x", "accel_1b1_y", "accel_1b2_y"], ["F_1b1_x", "F_1b1_y", "F_1b2_x", "F_1b2_y"]),
])
def test_a_record_simulates_only_what_its_channels_are_made_from(channels, simulated):
    """An accelerometer needs its bearing's force along its direction only (the housing path
    takes the product of the bearings and directions of the record's accelerometers); every
    simulated signal costs the anti-alias filter a column."""
    from cmsim.datasets.records import _simulated_channels

    assert _simulated_channels(channels) == simulated
