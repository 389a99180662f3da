"""One sweep per directory: an OS-level lock on ``DIR/.sweep.lock``.

The lock is :func:`fcntl.flock` (exclusive, non-blocking) on the open lock file, held for
the whole sweep. The kernel arbitrates simultaneous starts, and releases the lock when its
owner exits in any way (killed, SIGTERM, crash), so there is no stale lock to guess about.
The file also holds the owner's pid, for the error message only.

The file is removed on release while still locked; a process that locked a file which was
removed meanwhile (it opened the path before the removal) sees that the path no longer
names its file and tries again, so two owners can never hold two different files.

A forked process (a worker of the local pool) does not hold the lock: an ``flock`` belongs
to the open file, which a fork shares, so every lock this process holds is closed in the
child right after the fork (without unlocking it, which would release the parent's lock).
A run killed with SIGKILL therefore frees its directory when its own process ends, whatever
its workers are still doing.
"""

from __future__ import annotations

import fcntl
import os
from pathlib import Path

from cmsim.errors import ParameterError

__all__ = ["DirectoryLock", "LOCK_NAME"]

#: Name of the lock file inside a sweep directory.
LOCK_NAME = ".sweep.lock"

#: File descriptors of the locks this process holds.
_HELD = set()


def _forget_held_locks():
    """In a forked child: close the inherited lock files (the parent keeps its locks)."""
    for fd in tuple(_HELD):
        try:
            os.close(fd)
        except OSError:                            # pragma: no cover - already closed
            pass
    _HELD.clear()


os.register_at_fork(after_in_child=_forget_held_locks)


class DirectoryLock:
    """Exclusive lock on a sweep directory, as a context manager.

    Parameters
    ----------
    out_dir : str or path-like
        Sweep directory (must exist).

    Raises
    ------
    ParameterError
        On entry, if another process holds the lock (its pid is named when known).
    """

    def __init__(self, out_dir):
        self.path = Path(out_dir) / LOCK_NAME
        self._fd = None

    def __enter__(self):
        for _ in range(100):
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                pid = _read_pid(fd)
                os.close(fd)
                who = f" (pid {pid})" if pid else ""
                raise ParameterError(f"{self.path.parent} is in use by another sweep{who}; "
                                     f"wait for it to finish") from None
            try:                                   # still the file the path names?
                same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
            except FileNotFoundError:
                same = False
            if not same:                           # removed by its previous owner: retry
                os.close(fd)
                continue
            os.ftruncate(fd, 0)
            os.write(fd, str(os.getpid()).encode())
            self._fd = fd
            _HELD.add(fd)
            return self
        raise ParameterError(f"could not lock {self.path}")   # pragma: no cover

    def __exit__(self, *exc):
        if self._fd is not None:
            self.path.unlink(missing_ok=True)      # while locked: see the module docstring
            _HELD.discard(self._fd)
            fcntl.flock(self._fd, fcntl.LOCK_UN)
            os.close(self._fd)
            self._fd = None
        return False


def _read_pid(fd):
    try:
        text = os.pread(fd, 32, 0).decode().strip()
        return int(text) if text else None
    except (OSError, ValueError):
        return None
