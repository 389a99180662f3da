"""Records integrated in batches (issue 49): a record's arrays do not depend on its batch,
its worker or a resume; a batch of one is the single-run kernel, the reference.

Test tier: behaviour contracts (no physics): 8 records of 0.03 s of a gear spec with faults,
slip and a speed wobble, generated with batch sizes 1, 3 and 4 on 1 and 2 workers and
resumed; a record that diverges in a batch fails alone; the runner's batches (the tooth
faults' records together, the largest first) from 60 plans, with no integration.
"""

import numpy as np
import pytest

from cmsim.datasets import DatasetSpec, generate_dataset, load
from cmsim.datasets.records import (BATCH_FROM_RECORDS, BATCH_MIN, BATCH_SAMPLES,
                                    BATCH_SAMPLES_FULL, BATCH_SIZE,
                                    default_batch_size, simulate_record, simulate_records)
from cmsim.errors import ParameterError

#: Batched runs: the module waits for the session's one compile of the batch integrator
#: (tests/conftest.py).
pytestmark = pytest.mark.batch_kernels

SPEC = {
    "dataset": {"name": "batches", "records": 8, "seed": 3},
    "rig": {"builtin": "paper_2016"},
    "operating": {"speed_rpm": {"distribution": "uniform", "min": 800.0, "max": 1200.0},
                  "torque_nm": {"distribution": "uniform", "min": 20.0, "max": 90.0}},
    "faults": {"healthy_share": 0.3,
               "types": [{"type": "tooth_crack", "gear": [1, 2],
                          "depth_m": {"min": 0.5e-3, "max": 2.0e-3}}]},
    "nuisances": {"slip": {"min": 0.0, "max": 0.01},
                  "speed_wobble": {"min": 0.0, "max": 0.003}},
    "sensor": {"channels": ["accel_1b1_y", "dte_um", "tacho"], "fs_hz": 25600.0,
               "duration_s": 0.03, "warmup_s": 0.01},
}


def _arrays(out):
    ds = load(out)
    return {r.record_id: {c: np.asarray(r.signals[c]) for c in ds.channels} for r in ds}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    root = tmp_path_factory.mktemp("batches")
    spec = DatasetSpec.from_dict(SPEC)
    out = {}
    for name, kw in {"b3w1": dict(batch_size=3, workers=1), "b4w2": dict(batch_size=4, workers=2),
                     "b1w2": dict(batch_size=1, workers=2)}.items():
        s = generate_dataset(spec, root / name, **kw)
        assert (s.records_written, s.records_failed) == (8, 0)
        out[name] = _arrays(root / name)
    return spec, root, out


def test_a_record_is_the_same_in_any_batch_and_on_any_worker(made):
    _, _, out = made
    a, b = out["b3w1"], out["b4w2"]
    assert sorted(a) == sorted(b)
    for rid in a:
        for c in a[rid]:
            np.testing.assert_array_equal(a[rid][c], b[rid][c], err_msg=f"{rid} {c}")


def test_batches_agree_with_the_single_run_kernel(made):
    spec, _, out = made
    assert default_batch_size(spec) == 1                 # 8 records: the reference path
    one, batched = out["b1w2"], out["b4w2"]
    for rid in one:
        for c in one[rid]:
            ref = one[rid][c].astype(float)
            # float32 channels: one unit in the last place of the signal's range at most
            tol = max(np.ptp(ref), np.max(np.abs(ref))) * 2.0 ** -22
            assert np.max(np.abs(batched[rid][c] - ref)) <= tol, (rid, c)
    alone, _ = simulate_record(spec, 5)                  # the spec's default: alone
    np.testing.assert_array_equal(alone["dte_um"], one["000005"]["dte_um"])


def test_a_resume_in_other_batches_gives_the_same_records(made, tmp_path):
    import shutil

    spec, root, out = made
    shutil.copytree(root / "b3w1", tmp_path / "r")
    for rid in ("000001", "000002", "000006"):
        (tmp_path / "r" / "records" / f"{rid}.npz").unlink()
    s = generate_dataset(spec, tmp_path / "r", workers=2, batch_size=2)
    assert (s.records_written, s.records_skipped) == (3, 5)
    again = _arrays(tmp_path / "r")
    for rid in out["b3w1"]:
        for c in again[rid]:
            np.testing.assert_array_equal(again[rid][c], out["b3w1"][rid][c])


@pytest.mark.parametrize("bad", [0, -2, 1.5, True, "8"])
def test_a_bad_batch_size_is_refused(bad, tmp_path):
    with pytest.raises(ParameterError, match="batch_size"):
        generate_dataset(DatasetSpec.from_dict(SPEC), tmp_path / "x", batch_size=bad)
    assert not (tmp_path / "x").exists()


def test_a_large_spec_batches_by_default_and_its_records_keep_their_bits():
    """From BATCH_FROM_RECORDS records on, a spec's records take the batch kernel by
    default, decided by the spec alone: a record made alone (simulate_record, a batch of
    one) is the record made among others, bit for bit."""
    raw = {**SPEC, "dataset": {**SPEC["dataset"], "records": BATCH_FROM_RECORDS}}
    spec = DatasetSpec.from_dict(raw)
    assert default_batch_size(spec) == BATCH_SIZE > 1
    hybrid = DatasetSpec.from_dict({**raw, "simulation": {"mesh": "hybrid"}})
    assert default_batch_size(hybrid) == 1               # the on-line solve: run by run
    fs = SPEC["sensor"]["fs_hz"]
    for duration, size in ((BATCH_SAMPLES / fs / 20, 20), (BATCH_SAMPLES / fs / 10, 1)):
        longer = DatasetSpec.from_dict({**raw, "sensor": {**SPEC["sensor"],
                                                          "duration_s": duration}})
        assert default_batch_size(longer) == (size if size >= BATCH_MIN else 1)
    # records that keep their whole run (channels = "all") hold every state: half the
    # samples
    whole = {**SPEC["sensor"], "channels": "all"}
    assert BATCH_SAMPLES_FULL == BATCH_SAMPLES // 2
    for duration, size in ((BATCH_SAMPLES / fs / 20, 1), (BATCH_SAMPLES / fs / 40, 20)):
        full = DatasetSpec.from_dict({**raw, "sensor": {**whole, "duration_s": duration}})
        assert default_batch_size(full) == size           # 10 records would not pay: 1
    plans = [spec.record(i) for i in range(5)]
    together = simulate_records(spec, plans)             # the default: one batch of 5
    for i in (0, 3):
        alone, _ = simulate_record(spec, i)
        for c in alone:
            np.testing.assert_array_equal(alone[c], together[i][0][c], err_msg=f"{i} {c}")
    reference = simulate_records(spec, plans[3:4], batch_size=1)[0][0]
    for c in reference:
        ref = reference[c].astype(float)
        tol = max(np.ptp(ref), np.max(np.abs(ref))) * 2.0 ** -22
        assert np.max(np.abs(together[3][0][c] - ref)) <= tol, c


def test_tooth_table_faults_share_a_batch_and_the_largest_batches_go_first():
    """A crack, a spall and a breakage write the same per-tooth tables: their records share
    a batch key (and the kernel layout the key stands for), a healthy or an eccentric record
    does not; the runner hands the batches out largest first."""
    from cmsim.datasets.records import _prepared
    from cmsim.datasets.runner import _batch_key, _batches
    from cmsim.dynamics.batch import kernel_layout
    from cmsim.faults import Eccentricity
    from cmsim.faults.compile import TOOTH_TABLE_FAULTS

    spec = DatasetSpec.from_dict({**SPEC, "dataset": {"name": "kinds", "records": 60, "seed": 5},
                                  "faults": {"healthy_share": 0.2, "types": [
                                      {"type": "tooth_crack", "gear": [1, 2],
                                       "depth_m": {"min": 0.5e-3, "max": 2.0e-3}},
                                      {"type": "tooth_spall", "gear": [1, 2],
                                       "width_m": {"min": 0.5e-3, "max": 2.0e-3},
                                       "depth_m": 20.0e-6},
                                      {"type": "tooth_breakage", "gear": [1, 2],
                                       "lost_height_m": {"min": 0.5e-3, "max": 2.0e-3}},
                                      {"type": "eccentricity", "gear": [1, 2],
                                       "amplitude_m": {"min": 5.0e-6, "max": 50.0e-6}}]}})
    plans = [spec.record(i) for i in range(spec.n_records)]

    def first(kind):
        return next(p for p in plans if any(type(f).__name__ == kind for f in p.faults))

    tooth = [first(k) for k in ("ToothCrack", "ToothSpall", "ToothBreakage")]
    healthy = next(p for p in plans
                   if not any(isinstance(f, TOOTH_TABLE_FAULTS + (Eccentricity,))
                              for f in p.faults))
    keys = {_batch_key(p) for p in tooth}
    assert len(keys) == 1
    assert _batch_key(healthy) not in keys and _batch_key(first("Eccentricity")) not in keys
    layouts = {kernel_layout(_prepared(spec, p)[0]) for p in tooth}
    assert len(layouts) == 1 and None not in layouts

    batches = _batches(plans, 2, 16, {_batch_key(p): True for p in plans})
    sizes = [len(b) for b in batches]
    assert sizes == sorted(sizes, reverse=True) and sizes[0] > sizes[-1]
    assert sorted(p.index for b in batches for p in b) == list(range(spec.n_records))
    for b in batches:
        assert len({_batch_key(p) for p in b}) == 1
        assert [p.index for p in b] == sorted(p.index for p in b)
