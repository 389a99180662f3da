"""A local pool whose workers die is started again exactly POOL_RESTARTS times.

Test tier: behaviour (no physics). The class of a planted bug: the restart count one short
(or one long). A task that kills its own worker process on its first n attempts (as the OOM
killer would) finishes when n <= POOL_RESTARTS — the pool started n + 1 times — and stops
the run with :class:`~cmsim.errors.WorkersDied` when n = POOL_RESTARTS + 1, after exactly
POOL_RESTARTS + 1 pools. Counted, not read from the message (which prints the constant).
"""

import os
from pathlib import Path

import pytest

import cmsim.datasets.pool as pool
from cmsim.errors import WorkersDied


def dies_first(counter, n):
    """Kill this worker process on the first ``n`` calls (counted in the file ``counter``),
    then return the number of the call."""
    path = Path(counter)
    calls = int(path.read_text()) + 1 if path.exists() else 1
    path.write_text(str(calls))
    if calls <= n:
        os._exit(1)
    return calls


def _run(tmp_path, n, monkeypatch):
    started = []
    real = pool.process_pool

    def counting(*args, **kwargs):
        started.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(pool, "process_pool", counting)
    got = {}
    try:
        pool.run_tasks(dies_first, [("t", (str(tmp_path / "calls"), n))],
                       lambda key, res: got.update({key: res}), workers=1,
                       start_method="fork")
    finally:
        monkeypatch.undo()
    return got, len(started)


@pytest.mark.parametrize("n", [1, pool.POOL_RESTARTS])
def test_deaths_up_to_the_restart_count_are_survived(tmp_path, monkeypatch, n):
    got, pools = _run(tmp_path, n, monkeypatch)
    assert got == {"t": n + 1} and pools == n + 1


def test_one_death_more_stops_the_run_after_every_restart(tmp_path, monkeypatch):
    n = pool.POOL_RESTARTS + 1
    with pytest.raises(WorkersDied):
        _run(tmp_path, n, monkeypatch)
    assert int((tmp_path / "calls").read_text()) == n
