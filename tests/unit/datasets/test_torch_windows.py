"""The PyTorch dataset over a generated dataset (issue 28) yields the windows of to_arrays.

Test tier: behaviour contract (no physics, trains nothing). Every test but the one of the
missing extra needs torch (CI installs it: .ci/run): a test that skipped where torch was
absent let a planted swap of window and hop through (issue 48). The dataset has 3 records
of 0.02 s.
"""

import numpy as np
import pytest

from cmsim.datasets import DatasetSpec, generate_dataset, load
from cmsim.datasets.torch_windows import WindowDataset
from cmsim.errors import ParameterError

SPEC = {
    "dataset": {"name": "torch", "records": 3, "seed": 4},
    "rig": {"builtin": "paper_2016"},
    "faults": {"healthy_share": 0.5,
               "types": [{"type": "inner_race", "bearing": ["1b1"],
                          "size_m": {"min": 0.5e-3, "max": 1.5e-3}, "depth_m": 1e-4}]},
    "sensor": {"channels": ["accel_1b1_y", "dte_um", "tacho"], "fs_hz": 25600.0,
               "duration_s": 0.02, "warmup_s": 0.01},
}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    out = tmp_path_factory.mktemp("torch") / "ds"
    generate_dataset(DatasetSpec.from_dict(SPEC), out, workers=1, progress=False)
    return out


@pytest.mark.parametrize("kwargs", [{}, {"channels": ["dte_um", "tacho"]}],
                         ids=["measurable", "named"])
def test_dataloader_yields_the_windows_of_to_arrays(made, kwargs):
    torch = pytest.importorskip("torch")
    from torch.utils.data import DataLoader

    ds = load(made)
    X, y, groups = ds.to_arrays(window=128, hop=96, **kwargs)
    wins = WindowDataset(ds, window=128, hop=96, **kwargs)
    assert len(wins) == len(X)
    xs, ys, gs = [], [], []
    for x, label, group in DataLoader(wins, batch_size=5, shuffle=False):
        assert x.dtype == torch.float32 and x.shape[1:] == X.shape[1:]
        xs.append(x.numpy())
        ys += [wins.classes[i] for i in label.tolist()]
        gs += list(group)
    np.testing.assert_array_equal(np.concatenate(xs), X)
    assert ys == list(y) and gs == list(groups)
    if not kwargs:
        assert wins.channels == ["accel_1b1_y", "tacho"]          # no DTE by default


def test_shuffled_items_are_the_same_windows(made):
    pytest.importorskip("torch")
    ds = load(made)
    X, _, _ = ds.to_arrays(window=256)
    wins = WindowDataset(ds, window=256, cache_records=1)
    for i in (5, 0, len(wins) - 1, 3):
        np.testing.assert_array_equal(wins[i][0].numpy(), X[i])
    with pytest.raises(IndexError):
        wins[len(wins)]


def test_label_indices_do_not_depend_on_the_chosen_records(made):
    """A train and a test loader over parts of one dataset number the labels alike: classes
    come from the whole dataset (or are given)."""
    pytest.importorskip("torch")
    ds = load(made)
    labels = dict(zip(ds.manifest["record_id"], ds.manifest["fault_label"]))
    assert len(set(labels.values())) == 2
    every = sorted(set(labels.values()))
    for rid in labels:
        wins = WindowDataset(ds, window=256, records=[rid])
        assert wins.classes == every
        assert wins.classes[wins._label[int(wins.index[0, 0])]] == labels[rid]
    given = WindowDataset(ds, window=256, classes=every[::-1] + ["ball"])
    assert given.classes == every[::-1] + ["ball"]
    with pytest.raises(ParameterError, match="classes") as err:
        WindowDataset(ds, window=256, classes=["ball"])
    assert err.value.param == "classes"


def test_window_and_hop_are_not_swapped(made):
    """Windows of 128 samples every 32 (hop a quarter of the window): item k starts 32·k
    samples into its record and is 128 long, as to_arrays cuts it (the class of a planted
    bug: window and hop swapped)."""
    pytest.importorskip("torch")
    ds = load(made)
    X, _, _ = ds.to_arrays(["accel_1b1_y"], window=128, hop=32)
    wins = WindowDataset(ds, ["accel_1b1_y"], window=128, hop=32)
    assert (wins.window, wins.hop) == (128, 32) and len(wins) == len(X)
    first = ds.record(0).signals["accel_1b1_y"]
    for k in (0, 1, 3):
        np.testing.assert_array_equal(wins[k][0].numpy()[0], first[32 * k:32 * k + 128])
    np.testing.assert_array_equal(wins.index[:4, 1], [0, 32, 64, 96])


def test_without_torch_the_constructor_names_the_extra(made, monkeypatch):
    """Without torch, making the dataset fails at once, naming the extra (it failed at the
    first item with a bare ModuleNotFoundError)."""
    import sys

    monkeypatch.setitem(sys.modules, "torch", None)          # import torch -> ImportError
    with pytest.raises(ModuleNotFoundError, match=r"pip install cmsim\[torch\]"):
        WindowDataset(load(made), window=128)
