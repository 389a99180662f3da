"""Atomic writes: ordinary permissions, and an interrupted write leaves the old file; a batch
of files is renamed into place only once every one is on the disk."""

import os
import stat

import numpy as np
import pytest

import cmsim._io as io_
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


@pytest.mark.parametrize("fail_at", ["write", "sync"])
def test_an_interrupted_batch_renames_nothing_and_leaves_no_temporary(tmp_path, monkeypatch,
                                                                       fail_at):
    (tmp_path / "r1.npz").write_bytes(b"old")
    synced = []

    def write(i):
        def writer(fh):
            if fail_at == "write" and i == 2:
                raise KeyboardInterrupt
            fh.write(b"new")
        return writer

    def fsync(name):
        if fail_at == "sync" and len(synced) == 2:
            raise OSError("disk full")
        synced.append(name)

    monkeypatch.setattr(io_, "_fsync", fsync)
    with pytest.raises(KeyboardInterrupt if fail_at == "write" else OSError):
        atomic_write_all([(tmp_path / f"r{i}.npz", write(i)) for i in range(4)], threads=1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r1.npz"]
    assert (tmp_path / "r1.npz").read_bytes() == b"old"
