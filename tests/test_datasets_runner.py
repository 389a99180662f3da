"""Running a sweep given as named variations: the spec's mesh reaches simulate, results are
bit-identical on 1 and 2 workers, resume skips, and a file simulated with another mesh model
is never adopted.

Test tier: behaviour contracts (no physics): 4 runs of 0.05 s at 75 kHz per sweep, a few
seconds in all.
"""

import shutil

import numpy as np
import pytest

from cmsim.datasets import RUNS_DIR, SweepSpec, Variation, read_manifest, run_sweep
from cmsim.run import Run

GRID = [Variation("clearance_m", [15e-6, -1e-6]), Variation("torque_nm", [10.0, 50.0])]
KW = dict(fixed={"speed_rpm": 1000.0}, duration_s=0.05, seed=11)


@pytest.fixture(scope="module")
def one_and_two(tmp_path_factory):
    spec = SweepSpec(GRID, mesh="potential-energy", **KW)
    root = tmp_path_factory.mktemp("variations")
    s1 = run_sweep(spec, root / "w1", workers=1)
    s2 = run_sweep(spec, root / "w2", workers=2)
    return spec, root, s1, s2


def test_same_arrays_on_one_and_two_workers(one_and_two):
    spec, root, s1, s2 = one_and_two
    assert (s1.completed, s1.workers, s2.completed, s2.workers) == (4, 1, 4, 2)
    for case in spec.cases():
        a = Run.load(root / "w1" / RUNS_DIR / f"{case.name}.npz")
        b = Run.load(root / "w2" / RUNS_DIR / f"{case.name}.npz")
        for name in ("F_1b1_loa", "dte", "x_2b1"):
            np.testing.assert_array_equal(a[name], b[name])


def test_runs_carry_their_case(one_and_two):
    spec, root, _, _ = one_and_two
    man = read_manifest(root / "w1")
    assert man["spec"]["variations"][0]["name"] == "clearance_m"
    assert man["spec"]["mesh"] == "potential-energy"
    for case in spec.cases():
        run = Run.load(root / "w1" / RUNS_DIR / f"{case.name}.npz")
        assert run.meta["mesh_table"]["method"] == "potential-energy"   # the spec's mesh
        assert run.rig.bearings[0].clearance_m == pytest.approx(case.params["clearance_m"],
                                                                rel=1e-12)
        assert run.operating_point.torque_nm == pytest.approx(case.params["torque_nm"],
                                                              rel=1e-12)
        assert run.meta["sweep_case"]["id"] == case.id
        entry = man["runs"][case.name]
        assert entry["values"] == case.params and entry["seed"] == case.seed
        assert entry["clearance_m"] == case.params["clearance_m"]


def test_resume_skips_and_another_mesh_is_not_adopted(one_and_two, tmp_path):
    spec, root, _, _ = one_and_two
    assert run_sweep(spec, root / "w2", workers=2).skipped == 4
    out = tmp_path / "copy"
    shutil.copytree(root / "w1", out)
    default_mesh = SweepSpec(GRID, **KW)
    s = run_sweep(default_mesh, out, workers=2, force=True)
    assert (s.completed, s.adopted) == (4, 0)         # same cases, other mesh: recomputed
    run = Run.load(out / RUNS_DIR / f"{spec.cases()[0].name}.npz")
    assert run.meta["mesh_table"]["method"] != "potential-energy"
