"""Atomic file writes: write to a temporary file beside the target, then rename.

The file gets the permissions an ordinary ``open(path, "w")`` would give (0o666 less the
umask), not the owner-only mode of the temporary file; a folder assembled beside its target
(:func:`staging_dir`) those of ``mkdir`` (0o777 less the umask), not ``mkdtemp``'s 0o700.
"""

from __future__ import annotations

import math
import os
import tempfile
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

__all__ = ["atomic_write", "atomic_write_all", "atomic_write_text", "atomic_write_bytes",
           "atomic_savez", "savez_writer",
           "staging_dir", "READ_ERRORS", "finite"]

#: What reading a file a user brings can raise when the file is missing, truncated, of the
#: wrong kind or holds the wrong keys (an ``.npz`` cut short raises ``BadZipFile`` or
#: ``EOFError``; a missing array ``KeyError``). Readers turn these into one line naming the
#: file; anything else is a bug of cmsim.
READ_ERRORS = (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile)


def _staged(path, write):
    """``write(fh)`` into a new temporary file beside ``path`` with ``path``'s permissions;
    return its descriptor, still open (the data handed to the system), and its name, for
    :func:`_settle` (removed again if ``write`` raises)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb", closefd=False) as fh:
            write(fh)
            fh.flush()
            os.fchmod(fd, 0o666 & ~_umask())
    except BaseException:
        os.close(fd)
        _unlink(tmp)
        raise
    return fd, tmp


def _settle(fd, tmp, path, sync=True):
    """Force a staged temporary to the disk through its own descriptor (``sync``), close it
    and rename it to ``path``; return ``path``."""
    try:
        if sync:
            os.fsync(fd)
    finally:
        os.close(fd)
    os.replace(tmp, path)
    return path


def _unlink(tmp):
    try:
        os.unlink(tmp)
    except OSError:                   # gone already (renamed), or held open elsewhere
        pass


def _atomic(path, write, sync=True):
    path = Path(path)
    fd, tmp = _staged(path, write)
    try:
        _settle(fd, tmp, path, sync)
    except BaseException:
        _unlink(tmp)
        raise
    return path


def atomic_write_all(jobs, threads=16, chunk=64):
    """Write each ``(path, write)`` of ``jobs`` as :func:`atomic_write` does, in batches of
    ``chunk``: the files of a batch are written to their temporaries in turn, then forced to
    the disk side by side (``threads`` wait on it together, so the file system commits them
    at once instead of once per file, and writing them costs no thread switches), each
    renamed into place once it is there. Interrupted, it leaves no temporary behind; the
    files renamed stay, each whole.

    Parameters
    ----------
    jobs : iterable of (str or Path, callable)
        Each file's path and its writer ``write(fh)`` (``fh`` a binary file object).
    threads : int
        Most files forced to the disk at once.
    chunk : int
        Most files open at once.

    Returns
    -------
    list of pathlib.Path
        The paths, in order.
    """
    jobs, done = list(jobs), []
    for lo in range(0, len(jobs), chunk):
        staged, settling = [], False
        try:
            for path, write in jobs[lo:lo + chunk]:
                path = Path(path)
                staged.append((*_staged(path, write), path))
            settling = True                         # each _settle closes its descriptor
            if len(staged) == 1:
                done.append(_settle(*staged[0]))
            else:
                with ThreadPoolExecutor(max_workers=min(len(staged), threads)) as pool:
                    done += pool.map(lambda s: _settle(*s), staged)
        except BaseException:
            for fd, tmp, _ in staged:
                if not settling:
                    os.close(fd)
                _unlink(tmp)
            raise
    return done


def _umask():
    """The process umask (read by setting and restoring it)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def staging_dir(target, suffix):
    """A new hidden folder beside ``target`` (``.<name>.XXXX<suffix>``) to assemble it in
    and rename into place, with the permissions ``mkdir`` would give ``target``.

    Parameters
    ----------
    target : pathlib.Path
        The folder it will become.
    suffix : str
        End of its name (``.export``).

    Returns
    -------
    pathlib.Path
    """
    stage = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=suffix, dir=target.parent))
    os.chmod(stage, 0o777 & ~_umask())
    return stage


def atomic_write(path, write):
    """``write(fh)`` into a temporary file beside ``path`` (``fh`` a binary file object),
    renamed to ``path`` only when ``write`` returns: a writer streaming many parts (Parquet
    row groups) leaves nothing behind when interrupted; return the path."""
    return _atomic(path, write)


def atomic_write_bytes(path, data, sync=True):
    """Write ``data`` (bytes) to ``path`` atomically; return the path. With ``sync=False``
    the data is not forced to the disk before the rename: a crash of the machine (not of the
    process) may then leave the file empty, for files another one can stand in for."""
    return _atomic(path, lambda fh: fh.write(data), sync)


def atomic_write_text(path, text, sync=True):
    """Write ``text`` (UTF-8) to ``path`` atomically; return the path (``sync``: as
    :func:`atomic_write_bytes`)."""
    return atomic_write_bytes(path, text.encode("utf-8"), sync)


def savez_writer(compressed=False, **arrays):
    """A writer ``write(fh)`` of ``np.savez`` (``np.savez_compressed``) of ``arrays``, for
    :func:`atomic_write` and :func:`atomic_write_all`.

    Parameters
    ----------
    compressed : bool
        Deflate the arrays.
    **arrays : array_like
        The arrays, by name.
    """
    saver = np.savez_compressed if compressed else np.savez
    return lambda fh: saver(fh, **arrays)


def atomic_savez(path, compressed=False, **arrays):
    """``np.savez`` to ``path`` atomically (no ``.npz`` suffix is appended)."""
    return _atomic(path, savez_writer(compressed, **arrays))


def finite(value):
    """``value`` ready for JSON, at every depth: non-finite floats as ``None`` (JSON has no
    NaN), numpy scalars as Python numbers.

    Parameters
    ----------
    value : object
        A number, or dicts, lists and tuples of them (tuples become lists).

    Examples
    --------
    >>> finite({"a": float("nan"), "b": [np.float32(1.5), np.int64(2)]})
    {'a': None, 'b': [1.5, 2]}
    """
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value
