"""Running a spec given as named variations: the spec's mesh reaches simulate, results are
bit-identical on 1 and 2 workers, resume skips, and a file simulated with another mesh model
is never adopted.

Test tier: behaviour contracts (no physics): 4 runs of 0.05 s at 75 kHz per sweep, a few
seconds in all.
"""

import json
import shutil

import numpy as np
import pytest

from cmsim.datasets import (RECORDS_DIR, SPEC_NAME, DatasetSpec, Variation, generate_dataset,
                            read_rows)
from cmsim.run import Run

GRID = [Variation("clearance_m", [15e-6, -1e-6]), Variation("torque_nm", [10.0, 50.0])]
KW = dict(fixed={"speed_rpm": 1000.0}, duration_s=0.05, seed=11)


@pytest.fixture(scope="module")
def one_and_two(tmp_path_factory):
    spec = DatasetSpec(GRID, mesh="potential-energy", **KW)
    root = tmp_path_factory.mktemp("variations")
    s1 = generate_dataset(spec, root / "w1", workers=1)
    s2 = generate_dataset(spec, root / "w2", workers=2)
    return spec, root, s1, s2


def test_same_arrays_on_one_and_two_workers(one_and_two):
    spec, root, s1, s2 = one_and_two
    assert (s1.records_written, s1.workers, s2.records_written, s2.workers) == (4, 1, 4, 2)
    for i in range(len(spec)):
        name = spec.record_id(i)
        a = Run.load(root / "w1" / RECORDS_DIR / f"{name}.npz")
        b = Run.load(root / "w2" / RECORDS_DIR / f"{name}.npz")
        for signal in ("F_1b1_loa", "dte", "x_2b1"):
            np.testing.assert_array_equal(a[signal], b[signal])


def test_runs_carry_their_record(one_and_two):
    spec, root, _, _ = one_and_two
    stored = json.loads((root / "w1" / SPEC_NAME).read_text())["spec"]
    assert [s["name"] for s in stored["settings"]] == ["speed_rpm", "clearance_m", "torque_nm"]
    assert stored["mesh"] == "potential-energy"
    rows = {r["record_id"]: r for r in read_rows(root / "w1").to_dict("records")}
    for i in range(len(spec)):
        plan = spec.record(i)
        run = Run.load(root / "w1" / RECORDS_DIR / f"{plan.record_id}.npz")
        assert run.meta["mesh_table"]["method"] == "potential-energy"   # the spec's mesh
        assert run.rig.bearings[0].clearance_m == pytest.approx(plan.params["clearance_m"],
                                                                rel=1e-12)
        assert run.operating_point.torque_nm == pytest.approx(plan.params["torque_nm"],
                                                              rel=1e-12)
        assert run.meta["record"]["values"] == {"speed_rpm": 1000.0,
                                                "clearance_m": plan.params["clearance_m"],
                                                "torque_nm": plan.params["torque_nm"]}
        row = rows[plan.record_id]
        assert row["seed"] == plan.sim_seed
        assert row["clearance_m"] == plan.params["clearance_m"]


def test_resume_skips_and_another_mesh_is_not_adopted(one_and_two, tmp_path):
    spec, root, _, _ = one_and_two
    assert generate_dataset(spec, root / "w2", workers=2).records_skipped == 4
    out = tmp_path / "copy"
    shutil.copytree(root / "w1", out)
    default_mesh = DatasetSpec(GRID, **KW)
    s = generate_dataset(default_mesh, out, workers=2, force=True)
    assert (s.records_written, s.records_adopted) == (4, 0)   # same records, other mesh
    run = Run.load(out / RECORDS_DIR / f"{spec.record_id(0)}.npz")
    assert run.meta["mesh_table"]["method"] != "potential-energy"
