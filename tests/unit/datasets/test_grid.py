"""Grid-sampled datasets: record i is the i-th point of the product grid, each point once.

Test tier: behaviour contract (no physics). The axes have different lengths (2, 3, 2), so a
grid walked in another order, an axis dropped, or a setting not applied to the record's rig
or operating point gives another sequence than :func:`itertools.product`; the generated
dataset is checked in its manifest *and* in what each record file says it simulated.
"""

import itertools

import pytest

from cmsim.datasets import DatasetSpec, Variation, generate_dataset, load

AXES = {"speed_rpm": [900.0, 1100.0], "torque_nm": [10.0, 30.0, 50.0],
        "friction": [0.0, 0.05]}
POINTS = list(itertools.product(*AXES.values()))          # first axis slowest


def _spec(**kw):
    return DatasetSpec([Variation(name, values) for name, values in AXES.items()],
                       channels=["dte_um"], duration_s=0.02, warmup_s=0.01, seed=11, **kw)


@pytest.mark.parametrize("repeats", [1, 3])
def test_record_i_holds_the_ith_point_of_the_product(repeats):
    spec = _spec(repeats=repeats)
    assert len(spec) == len(POINTS) * repeats
    seen = []
    for i in range(len(spec)):
        plan = spec.record(i)
        point = tuple(plan.params[name] for name in AXES)
        assert point == POINTS[i // repeats], i
        assert plan.repeat == i % repeats
        seen.append((point, plan.repeat))
    assert sorted(seen) == sorted(itertools.product(POINTS, range(repeats)))    # each once
    assert len({spec.record(i).sim_seed for i in range(len(spec))}) == len(spec)


@pytest.fixture(scope="module")
def grid_dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("grid") / "ds"
    summary = generate_dataset(_spec(), out, workers=1)
    assert summary.records_failed == 0, summary.failed
    return load(out)


def test_generated_grid_records_hold_their_points_once(grid_dataset):
    """Manifest row i and record file i hold grid point i: the operating point the run
    simulated and the friction of the rig it ran on, not only the values written in the row."""
    m = grid_dataset.manifest.sort_values("index").reset_index(drop=True)
    assert list(m["index"]) == list(range(len(POINTS)))
    assert (m["status"] == "ok").all()
    rows = [tuple(float(m.loc[i, name]) for name in AXES) for i in range(len(m))]
    assert rows == POINTS
    assert m["record_id"].is_unique
    simulated = []
    for i in range(len(POINTS)):
        rec = grid_dataset.record(m.loc[i, "record_id"])
        op = rec.meta["operating_point"]
        simulated.append((op["speed_rpm"], op["torque_nm"],
                          rec.rig.mesh_contact.friction_coefficient))
    for got, want in zip(simulated, POINTS):
        assert got == pytest.approx(want, rel=1e-12, abs=1e-15)
    assert len(set(simulated)) == len(POINTS)
