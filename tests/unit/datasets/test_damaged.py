"""Datasets damaged on disk, and runs that fail before they start (issue 26).

Test tier: behaviour contracts (no physics). A corrupt manifest is an error naming the file
and the fix, and the fix works; a record file missing or cut short is an error naming it;
windows longer than the records are refused (not an empty X); a run that cannot start (no
scheduler listening) leaves nothing; a file half-written by a killed worker does not outlive
the run. Records are 0.02 s long.
"""

import shutil
import time

import pandas as pd
import pytest

from cmsim.datasets import DatasetSpec, generate_dataset, load
from cmsim.datasets.manifest import PARQUET_NAME, RECORDS_DIR, ROWS_DIR
from cmsim.errors import ParameterError

SPEC = {
    "dataset": {"name": "damaged", "records": 3, "seed": 2},
    "rig": {"builtin": "paper_2016"},
    "sensor": {"channels": ["accel_1b1_y"], "fs_hz": 25600.0, "duration_s": 0.02,
               "warmup_s": 0.01},
}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    out = tmp_path_factory.mktemp("damaged") / "ds"
    generate_dataset(DatasetSpec.from_dict(SPEC), out, workers=1, progress=False)
    return out


@pytest.fixture
def copy(made, tmp_path):
    out = tmp_path / "ds"
    shutil.copytree(made, out)
    return out


def test_window_longer_than_the_records_is_refused(made):
    ds = load(made)
    n = int(ds.manifest["n_samples"].min())
    assert ds.to_arrays(window=n)[0].shape == (len(ds), 1, n)
    with pytest.raises(ParameterError, match=rf"window must be at most the record length, "
                                             rf"{n} samples .*got {n + 1}") as err:
        ds.to_arrays(window=n + 1)
    assert err.value.param == "window"
    with pytest.raises(ParameterError, match="window"):
        next(ds.iter_arrays(window=n + 1))


@pytest.mark.parametrize("damage", ["truncated", "deleted"])
def test_a_damaged_record_file_is_named(copy, damage):
    victim = copy / RECORDS_DIR / "000001.npz"
    if damage == "truncated":
        victim.write_bytes(victim.read_bytes()[:500])
    else:
        victim.unlink()
    ds = load(copy)
    with pytest.raises(ParameterError, match=r"record file .*000001\.npz is "
                                             r"(missing|unreadable \(BadZipFile).*--verify"):
        ds.to_arrays(window=64)
    s = generate_dataset(DatasetSpec.from_dict(SPEC), copy, workers=1, progress=False,
                         verify=True)                    # the fix the message gives
    assert (s.records_written, s.records_skipped) == (1, 2)
    assert load(copy).to_arrays(window=64)[0].shape[0] > 0


@pytest.mark.parametrize("damage", ["cut", "foreign"])
def test_a_corrupt_manifest_is_named_with_its_fix(copy, damage):
    manifest = copy / PARQUET_NAME
    if damage == "cut":
        manifest.write_bytes(manifest.read_bytes()[:200])
    else:
        pd.DataFrame({"x": [1.0]}).to_parquet(manifest)
    spec = DatasetSpec.from_dict(SPEC)
    for attempt in (lambda: load(copy),
                    lambda: generate_dataset(spec, copy, workers=1, progress=False)):
        with pytest.raises(ParameterError, match=r"manifest\.parquet is (corrupt|not a cmsim "
                                                 r"manifest).*remove it") as err:
            attempt()
        assert err.value.param == "out"
    manifest.unlink()                                    # the fix the message gives
    s = generate_dataset(spec, copy, workers=1, progress=False)
    assert (s.records_written, s.records_adopted) == (0, 3)
    assert len(load(copy)) == 3


def test_no_scheduler_listening_leaves_nothing(tmp_path):
    out = tmp_path / "new" / "ds"
    t = time.monotonic()
    with pytest.raises(ParameterError, match="scheduler 'tcp://127.0.0.1:1': cannot connect"):
        generate_dataset(DatasetSpec.from_dict(SPEC), out, scheduler="tcp://127.0.0.1:1",
                         progress=False)
    assert time.monotonic() - t < 10                     # refused at once, not after 30 s
    assert list(tmp_path.iterdir()) == []


def test_a_run_failing_before_any_record_removes_the_directory_it_made(tmp_path, monkeypatch):
    import cmsim.datasets.runner as runner

    def broken(*args, **kwargs):
        raise RuntimeError("the pool could not start")

    monkeypatch.setattr(runner, "run_tasks", broken)
    spec = DatasetSpec.from_dict(SPEC)
    with pytest.raises(RuntimeError):
        generate_dataset(spec, tmp_path / "a" / "b", workers=1, progress=False)
    assert list(tmp_path.iterdir()) == []
    mine = tmp_path / "mine"                             # a directory it did not make stays
    mine.mkdir()
    (mine / "notes.txt").write_text("x")
    with pytest.raises(RuntimeError):
        generate_dataset(spec, mine, workers=1, progress=False)
    assert (mine / "notes.txt").is_file()


def test_a_file_half_written_by_a_killed_worker_does_not_outlive_the_run(tmp_path):
    out = tmp_path / "ds"

    def worker_killed_mid_write(row):                    # what a killed Dask worker leaves
        (out / RECORDS_DIR / f".{row['record_id']}.npz.abc.tmp").write_bytes(b"half")

    generate_dataset(DatasetSpec.from_dict(SPEC), out, workers=1, progress=False,
                     on_record_done=worker_killed_mid_write)
    assert not list(out.rglob("*.tmp"))
    assert sorted(p.name for p in (out / RECORDS_DIR).iterdir()) == \
        ["000000.npz", "000001.npz", "000002.npz"]
    assert not list((out / ROWS_DIR).iterdir())
