"""Progress lines on stderr for the long silent waits (issue 28).

A few steps run for tens of seconds to minutes without anything to show: the first numba
compile of the integration kernels (1-3 min on 2 cores, once per install), and the FE build
of a gear body (meshing, assembling and factorising, solving for the influence coefficients;
≈ 10-50 s per gear design or crack, once: the result is cached). Each such step runs inside
:func:`stage`, which writes

* one line when the step starts (``cmsim: <what>...``),
* a heartbeat line while it runs (``cmsim: <what>: still running, 40 s``): every
  :data:`TTY_INTERVAL_S` on a terminal, every :data:`LOG_INTERVAL_S` otherwise, so a CI log
  gets a handful of lines rather than a flood,
* one line when it ends (``cmsim: <what>: done in 48.7 s``).

Only ever on stderr: a command's ``--json`` stdout stays one JSON object. Set
``CMSIM_PROGRESS=0`` to silence the lines.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time

__all__ = ["stage", "progress_enabled", "TTY_INTERVAL_S", "LOG_INTERVAL_S"]

#: Seconds between heartbeat lines when stderr is a terminal.
TTY_INTERVAL_S = 10.0
#: Seconds between heartbeat lines when stderr is a file or a pipe (a CI log).
LOG_INTERVAL_S = 60.0


def progress_enabled():
    """False when the environment variable ``CMSIM_PROGRESS`` is ``0``, ``off``, ``no`` or
    ``false``; True otherwise (the default)."""
    return os.environ.get("CMSIM_PROGRESS", "1").strip().lower() not in {"0", "off", "no",
                                                                         "false"}


def _write(stream, text):
    try:
        print(text, file=stream, flush=True)
    except (OSError, ValueError):          # a closed or broken stderr must not stop the work
        pass


@contextlib.contextmanager
def stage(what, interval_s=None):
    """Announce a long step on stderr: a start line, heartbeat lines, an end line.

    Parameters
    ----------
    what : str
        What the step does, as the user should read it ("compiling numba kernels").
    interval_s : float, optional
        Seconds between heartbeat lines (default :data:`TTY_INTERVAL_S` when stderr is a
        terminal, else :data:`LOG_INTERVAL_S`).

    Yields
    ------
    None

    Examples
    --------
    >>> import io, contextlib
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err), stage("counting"):
    ...     pass
    >>> err.getvalue().splitlines()[0]
    'cmsim: counting...'
    """
    if not progress_enabled():
        yield
        return
    stream = sys.stderr
    if interval_s is None:
        try:
            tty = stream.isatty()
        except (AttributeError, ValueError):
            tty = False
        interval_s = TTY_INTERVAL_S if tty else LOG_INTERVAL_S
    start = time.perf_counter()
    stop = threading.Event()

    def heartbeat():
        while not stop.wait(interval_s):
            _write(stream, f"cmsim: {what}: still running, {time.perf_counter() - start:.0f} s")

    _write(stream, f"cmsim: {what}...")
    beat = threading.Thread(target=heartbeat, name="cmsim-progress", daemon=True)
    beat.start()
    ended = "stopped after"
    try:
        yield
        ended = "done in"
    finally:
        stop.set()
        beat.join()
        _write(stream, f"cmsim: {what}: {ended} {time.perf_counter() - start:.1f} s")
