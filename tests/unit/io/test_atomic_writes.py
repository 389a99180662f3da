"""Atomic writes: ordinary permissions, and an interrupted write leaves the old file."""

import os
import stat

import numpy as np
import pytest

from cmsim._io import atomic_savez, atomic_write_text


def test_written_file_has_umask_permissions(tmp_path):
    old = os.umask(0o027)
    try:
        path = atomic_write_text(tmp_path / "a.txt", "x")
    finally:
        os.umask(old)
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert path.read_text() == "x"


def test_interrupted_write_keeps_the_previous_file(tmp_path, monkeypatch):
    path = tmp_path / "a.npz"
    atomic_savez(path, x=np.arange(3))

    def boom(fh, **arrays):
        fh.write(b"partial")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez", boom)
    with pytest.raises(KeyboardInterrupt):
        atomic_savez(path, x=np.arange(5))
    monkeypatch.undo()
    with np.load(path) as z:
        assert z["x"].tolist() == [0, 1, 2]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.npz"]
