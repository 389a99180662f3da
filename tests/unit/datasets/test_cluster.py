"""A dataset on a real Dask cluster: a scheduler and two worker *processes* on localhost;
and the local pool with one of its worker processes killed.

Test tier: behaviour contract (issue 26, "A real cluster"). The other Dask test runs its
workers as threads of the test process; here they are separate processes (each its own
interpreter, numba kernels loaded from the disk cache), as users run them. The records must
be bit-identical to the local runner's, and killing one worker process mid-run (SIGKILL, once
the first record has landed) must lose nothing: Dask retries its task on a worker the nanny
restarts, and the dataset completes with every record present once, every checksum verified
and nothing half-written. The cluster test takes 40-100 s on the two shared cores (marked
slow). The local pool must survive the same (a worker killed by the out-of-memory killer):
it is started again for the unfinished records, a few times, then the run stops with
:class:`~cmsim.errors.WorkersDied` keeping what finished.
"""

import hashlib
import multiprocessing
import os
import signal

import numpy as np
import pytest

from cmsim.datasets import DatasetSpec, generate_dataset, load
from cmsim.datasets.manifest import PARQUET_NAME, RECORDS_DIR, ROWS_DIR, file_sha256
from cmsim.errors import WorkersDied

distributed = pytest.importorskip("distributed")

#: Records long enough (about 0.5 s of work each) for a worker to be busy when one lands.
SPEC = {
    "dataset": {"name": "cluster", "records": 8, "seed": 11},
    "rig": {"builtin": "paper_2016"},
    "operating": {"speed_rpm": {"distribution": "uniform", "min": 950.0, "max": 1050.0},
                  "torque_nm": [20.0, 60.0]},
    "faults": {"healthy_share": 0.5,
               "types": [{"type": "outer_race", "bearing": ["1b1", "2b1"],
                          "size_m": {"min": 0.5e-3, "max": 1.5e-3}, "depth_m": 1e-4}]},
    "nuisances": {"sensor_noise_m_s2": {"min": 0.0, "max": 0.02}},
    "sensor": {"channels": ["accel_1b1_y", "tacho"], "fs_hz": 25600.0, "duration_s": 1.0,
               "warmup_s": 0.02},
}


def _array_sums(out):
    """{record_id: {channel: SHA-256 of the array's bytes}} of a dataset directory."""
    ds = load(out)
    return {r.record_id: {c: hashlib.sha256(np.ascontiguousarray(r.signals[c]).tobytes())
                          .hexdigest() for c in ds.channels} for r in ds}


def _check_complete(out, spec):
    """Every record present once, ok, its file's size and SHA-256 those of its row, no
    temporary or sidecar file left."""
    ds = load(out)
    m = ds.manifest
    assert sorted(m["index"]) == list(range(spec.n_records))
    assert m["record_id"].is_unique and set(m["status"]) == {"ok"}
    files = sorted(p.name for p in (out / RECORDS_DIR).iterdir())
    assert files == sorted(f"{rid}.npz" for rid in m["record_id"])      # no .tmp either
    assert not list((out / ROWS_DIR).iterdir())
    for path, size, digest in zip(m["path"], m["bytes"], m["sha256"]):
        assert (out / path).stat().st_size == size
        assert file_sha256(out / path) == digest
    assert (out / PARQUET_NAME).is_file()


@pytest.mark.slow
def test_process_cluster_matches_local_and_survives_a_killed_worker(tmp_path):
    spec = DatasetSpec.from_dict(SPEC)
    generate_dataset(spec, tmp_path / "local", workers=2, progress=False)
    killed = []
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None, host="127.0.0.1") as cluster, \
            distributed.Client(cluster) as client:
        pids = client.run(os.getpid)                       # {worker address: pid}

        def kill_a_busy_worker(row):
            if killed:
                return
            busy = [w for w, keys in client.processing().items() if keys and w in pids]
            assert busy, "no worker busy when the first record landed"
            os.kill(pids[busy[0]], signal.SIGKILL)
            killed.append(busy[0])

        s = generate_dataset(spec, tmp_path / "dask", scheduler=client, progress=False,
                             on_record_done=kill_a_busy_worker)
        assert killed, "no worker was killed"
        assert (s.runner, s.records_written, s.records_failed) == ("dask", 8, 0)
        assert set(client.run(os.getpid).values()) != set(pids.values())   # restarted
    _check_complete(tmp_path / "dask", spec)
    assert _array_sums(tmp_path / "dask") == _array_sums(tmp_path / "local")
    # cmsim's own check of every checksum: resuming with verify recomputes nothing
    again = generate_dataset(spec, tmp_path / "dask", workers=1, verify=True, progress=False)
    assert (again.records_written, again.records_skipped) == (0, 8)


def _kill_a_local_worker(times):
    """``on_record_done`` that SIGKILLs one live worker process of the local pool on each
    of the first ``times`` records that land."""
    killed = []

    def kill(row):
        if len(killed) < times:
            workers = [p.pid for p in multiprocessing.active_children() if p.pid != row["pid"]]
            for victim in workers + [row["pid"]]:
                try:
                    os.kill(victim, signal.SIGKILL)
                except ProcessLookupError:     # gone since it was listed (killed before)
                    continue
                killed.append(victim)
                return

    return kill, killed


def test_local_pool_survives_a_killed_worker(tmp_path):
    spec = DatasetSpec.from_dict({**SPEC, "sensor": {**SPEC["sensor"], "duration_s": 0.2}})
    kill, killed = _kill_a_local_worker(1)
    s = generate_dataset(spec, tmp_path / "killed", workers=2, start_method="fork",
                         progress=False, on_record_done=kill)
    assert len(killed) == 1 and (s.records_written, s.records_failed) == (8, 0)
    _check_complete(tmp_path / "killed", spec)
    generate_dataset(spec, tmp_path / "whole", workers=2, progress=False)
    assert _array_sums(tmp_path / "killed") == _array_sums(tmp_path / "whole")


def test_local_workers_that_keep_dying_stop_the_run_keeping_what_finished(tmp_path,
                                                                          monkeypatch):
    import cmsim.datasets.pool as pool

    monkeypatch.setattr(pool, "POOL_RESTARTS", 1)
    spec = DatasetSpec.from_dict({**SPEC, "sensor": {**SPEC["sensor"], "duration_s": 0.2}})
    kill, killed = _kill_a_local_worker(8)
    with pytest.raises(WorkersDied, match="died 2 times"):
        generate_dataset(spec, tmp_path / "d", workers=2, start_method="fork",
                         progress=False, on_record_done=kill)
    m = load(tmp_path / "d").manifest
    assert 1 <= len(m) < 8 and set(m["status"]) == {"ok"}
    assert not list((tmp_path / "d").rglob("*.tmp"))
