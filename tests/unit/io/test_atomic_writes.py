"""Atomic writes: ordinary permissions, and an interrupted write leaves the old file; a batch
of files is renamed into place only once every one is on the disk."""

import os
import stat

import numpy as np
import pytest

from cmsim._io import atomic_savez, atomic_write_all, atomic_write_text, savez_writer


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


def test_a_batch_is_written_in_order_with_ordinary_permissions(tmp_path):
    old = os.umask(0o027)
    try:
        paths = atomic_write_all([(tmp_path / f"r{i}.npz", savez_writer(x=np.arange(i)))
                                  for i in range(5)], threads=3)
    finally:
        os.umask(old)
    assert [p.name for p in paths] == [f"r{i}.npz" for i in range(5)]
    for i, path in enumerate(paths):
        assert stat.S_IMODE(path.stat().st_mode) == 0o640
        with np.load(path) as z:
            assert z["x"].tolist() == list(range(i))
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"r{i}.npz" for i in range(5)]


def test_a_batch_interrupted_while_written_renames_nothing_and_leaves_no_temporary(tmp_path):
    (tmp_path / "r1.npz").write_bytes(b"old")

    def write(i):
        def writer(fh):
            if i == 2:
                raise KeyboardInterrupt
            fh.write(b"new")
        return writer

    with pytest.raises(KeyboardInterrupt):
        atomic_write_all([(tmp_path / f"r{i}.npz", write(i)) for i in range(4)], threads=1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r1.npz"]
    assert (tmp_path / "r1.npz").read_bytes() == b"old"


def test_a_file_that_cannot_be_synced_is_not_renamed_and_the_others_stay_whole(tmp_path,
                                                                               monkeypatch):
    (tmp_path / "r1.npz").write_bytes(b"old")
    calls = []
    real_fsync = os.fsync

    def fsync(fd):
        calls.append(fd)
        if len(calls) == 3:
            raise OSError("disk full")
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    with pytest.raises(OSError, match="disk full"):
        atomic_write_all([(tmp_path / f"r{i}.npz", lambda fh: fh.write(b"new"))
                          for i in range(4)], threads=1)
    monkeypatch.undo()
    names = sorted(p.name for p in tmp_path.iterdir())
    assert len(names) == 3 and not any(n.endswith(".tmp") for n in names), names
    assert all((tmp_path / n).read_bytes() == b"new" for n in names)
