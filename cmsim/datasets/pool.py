"""The one task runner of sweeps and datasets: local processes or a Dask cluster.

:func:`run_tasks` calls a top-level function on each task's arguments in worker processes
(:class:`concurrent.futures.ProcessPoolExecutor`) or on a ``dask.distributed`` cluster, and
hands every result to ``on_result`` in the calling process as soon as it arrives.

Interruptions
    Ctrl-C (SIGINT) and SIGTERM stop the run promptly: the workers are terminated at once
    (the calling process is the only one that reacts to the signal; workers ignore SIGINT),
    the results that arrived before are already recorded, and :class:`Interrupted` (a
    :class:`KeyboardInterrupt`) is raised so that the caller's ``with`` blocks (the directory
    lock) unwind. Files are written atomically by the task functions, so a terminated
    worker leaves at most a ``.*.tmp`` file, which the next run removes.

Processes
    On Linux the pool forks (``start_method="fork"``) after the caller has loaded the numba
    kernels, so workers start at once and do not compile; elsewhere it spawns. A worker
    exits on its own when its parent disappears (a killed run leaves no orphans), keeps
    the memory its tasks free for the next one (:func:`keep_freed_memory`), and its garbage
    collector leaves the objects it was forked with alone (:func:`_frozen_for_fork`).
"""

from __future__ import annotations

import contextlib
import ctypes
import gc
import multiprocessing
import numbers
import operator
import os
import signal
import socket
import sys
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from cmsim.errors import ParameterError, WorkersDied
from cmsim.rig.ranges import RANGES

__all__ = ["run_tasks", "process_pool", "Interrupted", "POOL_RESTARTS", "START_METHODS",
           "default_start_method", "check_workers", "check_start_method", "scheduler_client",
           "keep_freed_memory"]

#: Process start methods accepted by :func:`run_tasks`.
START_METHODS = ("fork", "spawn", "forkserver")


class Interrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C (SIGINT) or SIGTERM; ``signal_name`` says which."""

    def __init__(self, signal_name="SIGINT"):
        super().__init__(signal_name)
        self.signal_name = signal_name


def default_start_method():
    """"fork" on Linux, else "spawn"."""
    return "fork" if sys.platform.startswith("linux") else "spawn"


def check_workers(workers):
    """``workers`` (default ``os.cpu_count()``) checked against ``RANGES["workers"]``."""
    workers = (os.cpu_count() or 1) if workers is None else workers
    if not isinstance(workers, numbers.Integral) and hasattr(workers, "__index__"):
        workers = operator.index(workers)
    return RANGES["workers"].check("workers", workers)


def check_start_method(start_method):
    """``start_method`` (default :func:`default_start_method`) checked against the platform."""
    method = default_start_method() if start_method is None else start_method
    available = [m for m in START_METHODS if m in multiprocessing.get_all_start_methods()]
    if method not in available:
        raise ParameterError(f"start_method must be one of {available}, got {start_method!r}",
                             param="start_method")
    return method


#: prctl option: signal to send this process when its parent dies (linux/prctl.h).
_PR_SET_PDEATHSIG = 1

#: mallopt parameters (glibc malloc.h) and the values a worker sets: blocks up to 32 MiB (the
#: largest threshold every glibc accepts) come from the heap, and up to 1 GiB of free heap is
#: kept instead of being handed back to the kernel.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_MMAP_THRESHOLD_BYTES = 32 << 20
_TRIM_THRESHOLD_BYTES = 1 << 30


def keep_freed_memory():
    """Make this process's ``malloc`` keep the memory it frees for the next allocations
    (glibc ``mallopt``); False where there is no glibc.

    A task of a worker (a dataset record) allocates and frees tens of megabytes of arrays.
    glibc hands blocks of that size back to the kernel when they are freed, so the next task
    takes them again page by page: about 4000 page faults, 8-10 ms of kernel time per
    one-second record, 6 % of its CPU. Kept, the pages are reused; the process's resident
    memory stays at the peak of its largest task. Worker processes only: a user's own process
    keeps glibc's defaults.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):              # pragma: no cover - not glibc
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    return bool(mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD_BYTES)) \
        and bool(mallopt(_M_TRIM_THRESHOLD, _TRIM_THRESHOLD_BYTES))


def _watch_parent(parent_pid, period_s=0.5):
    """Exit this worker as soon as its parent is gone (killed run: no orphans left)."""
    while True:
        time.sleep(period_s)
        if os.getppid() != parent_pid:
            os._exit(1)


def _die_with_parent():
    """Ask the kernel to kill this process when its parent dies (Linux ``PR_SET_PDEATHSIG``);
    False where that is not available."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):              # pragma: no cover - no prctl
        return False


def _worker_init(parent_pid, initializer=None, initargs=()):
    """Pool initializer: only the parent reacts to Ctrl-C/SIGTERM; the worker dies with the
    parent (SIGKILL from the kernel on Linux, else a thread that watches it) and keeps the
    memory its tasks free (:func:`keep_freed_memory`); then ``initializer(*initargs)``."""
    keep_freed_memory()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if _die_with_parent():
        if os.getppid() != parent_pid:             # the parent died before the request
            os._exit(1)
    else:
        threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True,
                         name="cmsim-parent-watch").start()
    if initializer is not None:
        initializer(*initargs)


def process_pool(workers, start_method=None, initializer=None, initargs=()):
    """A local :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` processes set
    up as a run's workers (they ignore Ctrl-C, die with this process, keep the memory their
    tasks free), each then calling ``initializer(*initargs)``.

    With ``start_method="fork"`` (Linux's default) the initializer's arguments reach the
    workers without being pickled: a worker starts from a copy of this process's objects,
    caches included.
    """
    ctx = multiprocessing.get_context(check_start_method(start_method))
    return ProcessPoolExecutor(max_workers=check_workers(workers), mp_context=ctx,
                               initializer=_worker_init,
                               initargs=(os.getpid(), initializer, initargs))


class _SignalHandlers:
    """While active (main thread only), SIGTERM and SIGINT go to :attr:`handler`; the
    previous handlers come back on exit."""

    handler = signal.SIG_DFL

    def __enter__(self):
        self._old = {}
        if threading.current_thread() is not threading.main_thread():
            return self
        for sig in (signal.SIGTERM, signal.SIGINT):
            try:
                self._old[sig] = signal.signal(sig, self.handler)
            except (ValueError, OSError):      # pragma: no cover - not settable here
                pass
        return self

    def __exit__(self, *exc):
        for sig, old in self._old.items():
            signal.signal(sig, old)
        return False


class _SignalsRaise(_SignalHandlers):
    """While active (main thread only), SIGTERM and SIGINT raise :class:`Interrupted`."""

    @staticmethod
    def handler(signum, frame):
        raise Interrupted(signal.Signals(signum).name)


def run_tasks(fn, tasks, on_result, *, workers, start_method=None, scheduler=None,
              progress=False, desc="run", unit="run", postfix=None, total=None, units=None):
    """Call ``fn(*args)`` for every ``(key, args)`` of ``tasks``; results to ``on_result``.

    Parameters
    ----------
    fn : callable
        A module-level (picklable) function; it must not raise for an expected failure
        (return a result that says so instead).
    tasks : sequence of (key, tuple)
        Task keys (for ``on_result``) and the arguments of ``fn``.
    on_result : callable
        ``on_result(key, result)``, called in this process as each task finishes; an
        exception raised there stops the run (the workers are terminated) and propagates.
    workers : int
        Worker processes (local pool; at most the number of tasks).
    start_method : {"fork", "spawn", "forkserver"}, optional
        Start method of the local pool.
    scheduler : str or distributed.Client, optional
        A ``dask.distributed`` scheduler address (``"tcp://host:8786"``) or client: run the
        tasks on that cluster instead of a local pool (``workers`` is then ignored). The
        task functions write to the file system, so the cluster's workers must see the
        output directory at the same path.
    progress : bool
        tqdm progress bar on stderr.
    desc, unit : str
        Progress bar label and unit.
    postfix : callable, optional
        ``postfix(key, result)`` → text shown beside the bar.
    total : int, optional
        The bar's length in ``unit`` (default: one per task).
    units : callable, optional
        ``units(result)`` → how many ``unit`` a task's result advances the bar (default 1:
        a task that makes a batch of records advances it by its records).

    Returns
    -------
    int
        Workers used (local processes, or the cluster's workers).

    Raises
    ------
    Interrupted
        On Ctrl-C or SIGTERM (the results received before are recorded).
    """
    tasks = list(tasks)
    if not tasks:
        return 0
    from tqdm import tqdm

    bar = None
    with _SignalsRaise():
        try:
            bar = tqdm(total=len(tasks) if total is None else total, disable=not progress,
                       file=sys.stderr, unit=unit, desc=desc, dynamic_ncols=True, delay=0.0)

            def done(key, res):
                on_result(key, res)
                bar.update(1 if units is None else units(res))
                if postfix is not None:
                    bar.set_postfix_str(str(postfix(key, res)), refresh=False)

            if scheduler is not None:
                return _run_dask(fn, tasks, done, scheduler)
            return _run_local(fn, tasks, done, min(int(workers), len(tasks)),
                              check_start_method(start_method))
        finally:
            if bar is not None:
                bar.close()


#: Times a local pool whose worker process died (killed, out of memory) is started again
#: for the tasks it had not finished before the run stops.
POOL_RESTARTS = 3


def _run_local(fn, tasks, done, n_workers, method):
    """Run the tasks on a local pool; a pool broken by a worker that died is started again
    (at most :data:`POOL_RESTARTS` times) for the tasks not finished."""
    pending = list(tasks)
    for _ in range(POOL_RESTARTS + 1):
        pending = _run_pool(fn, pending, done, n_workers, method)
        if not pending:
            return n_workers
    raise WorkersDied(f"worker processes died {POOL_RESTARTS + 1} times (killed, or out of "
                      f"memory?) with {len(pending)} tasks left; what finished is kept")


def _run_pool(fn, tasks, done, n_workers, method):
    """One pool over ``tasks``; returns the tasks not finished if a worker died, else []."""
    pool = process_pool(n_workers, method)
    futures, delivered = {}, set()
    try:
        with _frozen_for_fork(method):
            for key, args in tasks:
                futures[pool.submit(fn, *args)] = (key, args)
        remaining = set(futures)
        while remaining:
            finished, remaining = wait(remaining, return_when=FIRST_COMPLETED)
            for fut in finished:
                if isinstance(fut.exception(), BrokenProcessPool):
                    continue                   # a worker died: handed over below
                delivered.add(fut)
                done(futures[fut][0], fut.result())
    except BaseException:
        # stop now: terminate the busy workers, then record what had already finished
        _terminate(pool)
        with _SignalsIgnored():
            _deliver_finished(futures, delivered, done)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
    return [futures[f] for f in futures if f not in delivered]


@contextlib.contextmanager
def _frozen_for_fork(method):
    """While the pool forks its workers (at its first task), every object of this process
    is moved out of the garbage collector's reach (:func:`gc.freeze`), then handed back.

    A forked worker starts with a copy of this process's objects (numba, numpy, scipy and
    the caches: about 190 000 of them). Left tracked, each of the worker's full collections
    walks them all, and writing their collector headers copies their pages: about 2 % of a
    dataset record's CPU and 15 % of a worker's page faults (``cmsim dataset``, 400 gear
    records). Frozen, the worker collects only what it made; this process collects them
    all again afterwards (in its oldest generation). A process that froze objects itself
    is left as it is (its workers inherit that freeze).
    """
    if method != "fork" or gc.get_freeze_count() > 0:
        yield
        return
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def _deliver_finished(futures, delivered, done):
    """Hand over the results that finished but were not delivered yet (best effort)."""
    for fut, (key, _) in futures.items():
        if fut not in delivered and fut.done() and not fut.cancelled() \
                and fut.exception() is None:
            try:
                done(key, fut.result())
            except Exception:                  # pragma: no cover - best effort
                pass


class _SignalsIgnored(_SignalHandlers):
    """While active (main thread only), a second Ctrl-C/SIGTERM does not cut the clean-up."""

    handler = signal.SIG_IGN


def _terminate(pool):
    """Cancel queued tasks and terminate the pool's worker processes at once."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        try:
            p.terminate()
        except (OSError, AttributeError):          # pragma: no cover - already gone
            pass
    for p in procs:
        p.join(timeout=5)


def _distributed():
    """The ``distributed`` package, or an error saying how to install it."""
    try:
        import distributed
    except ImportError:                            # pragma: no cover - optional extra
        raise ParameterError("scheduler needs dask.distributed: pip install 'cmsim[dask]'",
                             param="scheduler") from None
    return distributed


def _probe_tcp(address, timeout_s):
    """Refuse at once a ``tcp://host:port`` where nothing listens (the client would retry
    until its timeout); other addresses are left to the client."""
    from distributed.comm import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address)
        if scheme != "tcp":
            return
        host, port = parse_host_port(location)
    except (ValueError, TypeError):
        raise ParameterError(f"scheduler must be an address like tcp://host:8786, got "
                             f"{address!r}", param="scheduler") from None
    try:
        socket.create_connection((host, port), timeout=timeout_s).close()
    except OSError as exc:
        raise ParameterError(f"scheduler {address!r}: cannot connect, nothing answers there "
                             f"({type(exc).__name__}: {exc}); start the Dask cluster "
                             f"first, or give the address it prints", param="scheduler") from None


def check_scheduler(address, timeout_s=5.0):
    """Refuse, before anything is computed, a scheduler address that is malformed or where
    nothing listens (:class:`ParameterError` naming ``scheduler``)."""
    _distributed()
    _probe_tcp(address, timeout_s)


@contextlib.contextmanager
def scheduler_client(scheduler, timeout_s=30):
    """The ``distributed.Client`` of ``scheduler`` while active: ``None`` for ``None``, the
    client itself, or a client connected to the address (closed on exit).

    Connecting first lets a caller refuse an unreachable cluster before it creates anything.

    Parameters
    ----------
    scheduler : str or distributed.Client or None
        ``"tcp://host:8786"``, a client, or ``None`` (local processes).
    timeout_s : float
        How long to try to connect, s.
    """
    if scheduler is None:
        yield None
        return
    Client = _distributed().Client
    if isinstance(scheduler, Client):
        yield scheduler
        return
    if not isinstance(scheduler, str):
        raise ParameterError(f"scheduler must be an address (tcp://host:8786) or a "
                             f"distributed.Client, got {type(scheduler).__name__}",
                             param="scheduler")
    _probe_tcp(scheduler, min(timeout_s, 5.0))
    try:
        client = Client(scheduler, timeout=timeout_s)
    except (OSError, TimeoutError, ValueError) as exc:
        raise ParameterError(f"scheduler {scheduler!r}: cannot connect ({exc})",
                             param="scheduler") from None
    try:
        yield client
    finally:
        client.close()


def _run_dask(fn, tasks, done, scheduler):
    with scheduler_client(scheduler) as client:
        return _run_on_client(fn, tasks, done, client)


def _run_on_client(fn, tasks, done, client):
    """Run the tasks on a Dask client; a task whose workers kept dying (Dask's
    ``KilledWorker``) does not stop the others, and :class:`WorkersDied` names it at the end."""
    from distributed import KilledWorker, as_completed

    futures, lost = {}, []
    try:
        for key, args in tasks:
            futures[client.submit(fn, *args, pure=False, key=f"cmsim-{key}-{os.getpid()}-"
                                  f"{time.monotonic_ns()}")] = key
        n_workers = max(len(client.scheduler_info().get("workers", {})), 1)
        for fut in as_completed(list(futures)):
            if isinstance(fut.exception(), KilledWorker):
                lost.append(futures[fut])
            else:
                done(futures[fut], fut.result())
            fut.release()
        if lost:
            raise WorkersDied(f"Dask workers kept dying (killed, or out of memory?) on "
                              f"{len(lost)} tasks ({', '.join(lost[:5])}); what finished "
                              f"is kept")
        return n_workers
    except BaseException:
        client.cancel(list(futures))
        raise
