"""``cmsim export`` (issue 28), called as ``main([...])``.

Tier (c) behaviour: the JSON object and the files of a dataset exported as windows and as
WAV, a simulated run exported with a simulated-only channel named, a repeated export refused
without --force (its bad-input rows are in ``test_contract.py``), the --format choices the
library's formats. Records are 0.02 s.
"""

import json

import numpy as np
import pandas as pd
import pytest

from cmsim.cli import main
from cmsim.datasets import DatasetSpec, generate_dataset, load
from cmsim.measured.readers import read_signals
from cmsim.run import Run

SPEC = {
    "dataset": {"name": "cli", "records": 3, "seed": 6},
    "rig": {"builtin": "paper_2016"},
    "sensor": {"channels": ["accel_1b1_y", "dte_um"], "fs_hz": 25600.0, "duration_s": 0.02,
               "warmup_s": 0.01},
}


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    out = tmp_path_factory.mktemp("cli_export") / "ds"
    generate_dataset(DatasetSpec.from_dict(SPEC), out, workers=1, progress=False)
    return out


def run_json(capsys, argv):
    status = main(argv + ["--json"])
    out = capsys.readouterr().out
    return status, json.loads(out)


def test_dataset_as_windows(made, tmp_path, capsys):
    out = tmp_path / "w"
    status, res = run_json(capsys, ["export", str(made), "--format", "parquet", "--out",
                                    str(out), "--window", "256", "--hop", "128",
                                    "--split-seed", "3", "--fractions", "0.6", "0.2", "0.2"])
    assert status == 0, res
    X, y, _ = load(made).to_arrays(window=256, hop=128)
    df = pd.read_parquet(out / "windows.parquet")
    assert res["windows"]["rows"] == len(df) == len(X) and list(df["label"]) == list(y)
    assert res["channels"] == ["accel_1b1_y"] and "dte_um" not in df.columns
    assert res["windows"]["seed"] == 3 and res["windows"]["fractions"] == [0.6, 0.2, 0.2]
    status = main(["export", str(made), "--format", "parquet", "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2 and "--out" in err and "--force" in err
    assert main(["export", str(made), "--format", "wav", "--out", str(out), "--force"]) == 0
    assert "dataset exported as wav" in capsys.readouterr().out
    assert sorted(p.suffix for p in out.iterdir()) == [".csv", ".json"] + [".wav"] * 3


def test_run_with_a_simulated_channel_named(made, tmp_path, capsys):
    src = made / "records" / "000001.npz"
    status, res = run_json(capsys, ["export", str(src), "--format", "csv", "--out",
                                    str(tmp_path / "r"), "--channels", "dte_um"])
    assert status == 0 and res["kind"] == "run" and res["units"] == {"dte_um": "µm"}
    signals, _ = read_signals(tmp_path / "r" / "000001.csv")
    np.testing.assert_array_equal(signals["dte_um"].astype(np.float32), Run.load(src)["dte_um"])


def test_format_choices_are_the_formats_of_export():
    """The parser writes the formats out (building it imports no library module): they must
    be the library's."""
    from cmsim.cli import export as cli_export
    from cmsim.datasets.export import FORMATS

    assert cli_export.FORMATS == FORMATS
