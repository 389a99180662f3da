"""``cmsim import`` over a folder that is not all clean (issue 48).

Tier: behaviour. One file that cannot be read no longer stops the folder: it is left out and
named, the others are documented. A ``metadata.json`` cmsim wrote holds copies of what the
files stated; a file re-recorded at another rate is documented at its new rate with
``--force``, not refused against import's own earlier output.
"""

import json

import numpy as np
from scipy.io import savemat

from cmsim.cli import main


def _mat(path, fs_hz, n=12000, seed=0):
    x = np.random.default_rng(seed).standard_normal((n, 1))
    savemat(path, {"X097_DE_time": x, "fs": float(fs_hz)})


def test_a_damaged_file_is_left_out_and_named(tmp_path, capsys):
    """Two good .mat files and a truncated one: exit 0, the two documented, the third named
    in a warning and in the JSON's ``unreadable`` with why."""
    for i in range(2):
        _mat(tmp_path / f"r{i}.mat", 12000.0, seed=i)
    (tmp_path / "bad.mat").write_bytes((tmp_path / "r0.mat").read_bytes()[:300])
    assert main(["import", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [r["file"] for r in out["recordings"]] == ["r0.mat", "r1.mat"]
    assert list(out["unreadable"]) == ["bad.mat"] and "bad.mat" in out["unreadable"]["bad.mat"]
    assert any(w.startswith("left out bad.mat") for w in out["warnings"]), out["warnings"]
    meta = json.loads((tmp_path / "metadata.json").read_text())
    assert [r["file"] for r in meta["recordings"]] == ["r0.mat", "r1.mat"]


def test_a_folder_of_nothing_readable_is_refused_naming_the_first(tmp_path, capsys):
    """With no readable file left there is nothing to document: exit 2, one line."""
    (tmp_path / "bad.mat").write_bytes(b"MATLAB 5.0 MAT-file" + b"\0" * 50)
    assert main(["import", str(tmp_path), "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert "no recording could be read" in err and "bad.mat" in err, err


def test_import_does_not_refuse_a_rate_against_its_own_output(tmp_path, capsys):
    """A .mat file re-recorded at 48 kHz in a folder import documented at 12 kHz: import
    --force documents 48 kHz (the earlier metadata.json is import's copy of the file, not a
    statement to agree with); a hand-written metadata.json that disagrees still refuses the
    file, naming both values."""
    _mat(tmp_path / "r.mat", 12000.0)
    assert main(["import", str(tmp_path)]) == 0
    capsys.readouterr()
    _mat(tmp_path / "r.mat", 48000.0)
    assert main(["import", str(tmp_path), "--force", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["recordings"][0]["fs_hz"] == 48000.0 and not out["unreadable"]
    meta = json.loads((tmp_path / "metadata.json").read_text())
    meta["source"] = "written by hand"
    meta["recordings"][0]["fs_hz"] = 12000.0
    (tmp_path / "metadata.json").write_text(json.dumps(meta))
    assert main(["import", str(tmp_path), "--force", "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert "48000 Hz" in err and '"fs_hz" says 12000 Hz' in err, err
