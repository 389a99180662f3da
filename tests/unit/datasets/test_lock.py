"""The sweep directory lock (issue 10 item 3): an OS-level lock that simultaneous starts share.

Test tier: behaviour contract (no physics). Fifty processes released together (the issue's 50 simultaneous
starts) keep trying to
take :class:`cmsim.datasets.DirectoryLock` for a while; a shared counter, incremented under the
lock, must never read more than one holder. The lock file is removed on release while locked,
so the test also covers a process that opened the old file just before its removal.
"""

import multiprocessing
import os
import time

import pytest

from cmsim.datasets import LOCK_NAME, DirectoryLock
from cmsim.errors import ParameterError


def _contend(out_dir, go, holders, most, taken, refused, duration_s):
    go.wait()
    end = time.monotonic() + duration_s
    while time.monotonic() < end:
        try:
            with DirectoryLock(out_dir):
                with holders.get_lock():
                    holders.value += 1
                    most.value = max(most.value, holders.value)
                time.sleep(0.002)
                with holders.get_lock():
                    holders.value -= 1
                with taken.get_lock():
                    taken.value += 1
        except ParameterError:
            with refused.get_lock():
                refused.value += 1


def test_fifty_processes_started_together_never_both_hold_the_lock(tmp_path):
    ctx = multiprocessing.get_context("fork")
    go = ctx.Event()
    holders, most, taken, refused = (ctx.Value("i", 0) for _ in range(4))
    procs = [ctx.Process(target=_contend,
                         args=(tmp_path, go, holders, most, taken, refused, 0.5))
             for _ in range(50)]
    for p in procs:
        p.start()
    go.set()
    for p in procs:
        p.join(30)
    assert all(p.exitcode == 0 for p in procs)
    assert most.value == 1                     # never two holders at once
    assert taken.value >= 20 and refused.value >= 50   # real contention, both outcomes seen
    assert not (tmp_path / LOCK_NAME).exists()


def test_lock_is_released_when_its_holder_dies(tmp_path):
    """No stale lock: a killed owner's lock goes with its process."""
    ctx = multiprocessing.get_context("fork")
    ready = ctx.Event()

    def hold():
        lock = DirectoryLock(tmp_path).__enter__()
        assert lock is not None
        ready.set()
        time.sleep(60)

    p = ctx.Process(target=hold)
    p.start()
    assert ready.wait(10)
    with pytest.raises(ParameterError, match=f"in use by another sweep \\(pid {p.pid}\\)"):
        DirectoryLock(tmp_path).__enter__()
    p.kill()
    p.join(10)
    assert (tmp_path / LOCK_NAME).exists()     # the file stays, but holds no lock
    with DirectoryLock(tmp_path):
        assert (tmp_path / LOCK_NAME).read_text() == str(os.getpid())
    assert not (tmp_path / LOCK_NAME).exists()
