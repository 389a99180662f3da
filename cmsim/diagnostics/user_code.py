"""Run a user's code (a diagnostic algorithm) isolated from cmsim's own output and exit.

A user's function may print, write to file descriptor 1, raise, or call ``sys.exit``; none
of it may change what cmsim reports:

* its output goes to stderr (:func:`output_to_stderr`: ``sys.stdout`` and file descriptor 1
  both), so stdout keeps cmsim's result only (one JSON object with ``--json``);
* whatever it raises, :class:`SystemExit` included, is returned as a :class:`UserError`
  with the traceback of the user's frames (:func:`call_user`): that record fails, the
  evaluation goes on;
* :class:`KeyboardInterrupt` is not caught: Ctrl-C stops the evaluation;
* with :func:`isolated_steps`, each step runs in a forked child process, so a function that
  ends the process itself (``os._exit``, a signal, a crash in compiled code), which no
  ``except`` can catch, fails the step it ended and not the evaluation: a new child goes on
  from the next step (what ``cmsim evaluate`` does; where the platform cannot fork, the
  steps run in this process).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
import time
import traceback
from dataclasses import dataclass

__all__ = ["UserError", "call_user", "output_to_stderr", "isolated_steps"]

#: Longest error message kept (the traceback is kept whole).
MAX_MESSAGE_CHARS = 500


@dataclass(frozen=True)
class UserError:
    """What a user's function raised.

    Attributes
    ----------
    message : str
        One line, ``"ExceptionType: message"`` (``"SystemExit: the function called
        sys.exit(1)"``).
    traceback : str
        The formatted traceback, from the user's function down (cmsim's frames left out).
    """

    message: str
    traceback: str

    @classmethod
    def from_exception(cls, exc, skip_frames=0):
        """The error of ``exc``, leaving out the first ``skip_frames`` frames (the caller's).

        Parameters
        ----------
        exc : BaseException
            The exception caught.
        skip_frames : int
            Outer frames of its traceback to leave out.
        """
        tb = exc.__traceback__
        for _ in range(skip_frames):
            if tb is not None and tb.tb_next is not None:
                tb = tb.tb_next
        if isinstance(exc, SystemExit):
            text = f"the function called sys.exit({exc.code!r})"
        else:
            text = " ".join(str(exc).split())
        message = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
        lines = traceback.format_exception(type(exc), exc, tb)
        return cls(message[:MAX_MESSAGE_CHARS], "".join(lines))


@contextlib.contextmanager
def output_to_stderr():
    """While active, what is written to stdout (``print`` and file descriptor 1) goes to
    stderr."""
    with contextlib.suppress(ValueError, OSError):
        sys.stdout.flush()
    saved = None
    try:
        saved = os.dup(1)
        os.dup2(2, 1)
    except OSError:                        # no descriptor 1 or 2: Python level only
        saved = None
    try:
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        with contextlib.suppress(ValueError, OSError):
            sys.stderr.flush()
        if saved is not None:
            os.dup2(saved, 1)
            os.close(saved)


def call_user(func, *args):
    """``func(*args)`` with its output sent to stderr and whatever it raises caught.

    Parameters
    ----------
    func : callable
        The user's function.
    *args
        Its arguments.

    Returns
    -------
    result : object
        What ``func`` returned (``None`` if it raised).
    error : UserError or None
        What it raised (:class:`SystemExit` included; never :class:`KeyboardInterrupt`).
    """
    with output_to_stderr():
        try:
            return func(*args), None
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - the user's code
            return None, UserError.from_exception(exc, skip_frames=1)


def isolated_steps(n, step, ended):
    """``step(j, about)`` for ``j`` in ``0 .. n-1``, in order, in a forked child process the
    user's code may end without ending this one.

    ``step`` calls ``about(info)`` just before it runs the user's code on step ``j``; where
    the child then ends (``os._exit``, killed by a signal), step ``j`` yields ``ended(info,
    why, wall_s)`` — ``why`` says how it ended, ``wall_s`` how long after ``about`` — and a
    new child goes on from step ``j + 1``. An exception ``step`` raises (cmsim's own, not the
    user's: :func:`call_user` keeps those) is raised here. Where the platform cannot fork,
    the steps run in this process.

    Parameters
    ----------
    n : int
        Number of steps.
    step : callable
        ``step(j, about) -> value`` (picklable).
    ended : callable
        ``ended(info, why, wall_s) -> value`` for a step whose child ended.

    Yields
    ------
    object
        Each step's value, in order.
    """
    try:
        ctx = multiprocessing.get_context("fork")
    except ValueError:                     # no fork on this platform
        for j in range(n):
            yield step(j, lambda info: None)
        return
    j = 0
    while j < n:
        recv, send = ctx.Pipe(duplex=False)
        child = ctx.Process(target=_serve, args=(step, j, n, send), daemon=True)
        child.start()
        send.close()
        about = None
        try:
            while j < n:
                try:
                    kind, value = recv.recv()
                except EOFError:           # the child ended before it finished step j
                    break
                if kind == "about":
                    about = (value, time.perf_counter())
                elif kind == "raised":
                    raise value
                else:
                    j, about = j + 1, None
                    yield value
        finally:
            recv.close()
            if child.is_alive() and j < n:   # interrupted, or cmsim raised: stop it
                child.terminate()
            child.join()
        if j < n:
            if about is None:
                raise RuntimeError(f"the process evaluating step {j} ended ({_how(child)}) "
                                   f"before it ran the user's code")
            yield ended(about[0], _how(child), time.perf_counter() - about[1])
            j += 1


def _serve(step, start, n, send):
    """The child of :func:`isolated_steps`: steps ``start .. n-1``, each announced and
    reported through ``send``."""
    try:
        for j in range(start, n):
            value = step(j, lambda info: send.send(("about", info)))
            send.send(("done", value))
    except KeyboardInterrupt:              # Ctrl-C reaches the parent too: it stops
        pass
    except BaseException as exc:  # noqa: BLE001 - cmsim's own error: the parent raises it
        try:
            send.send(("raised", exc))
        except Exception:  # noqa: BLE001 - an exception that does not pickle
            send.send(("raised", RuntimeError(f"{type(exc).__name__}: {exc}")))
    finally:
        send.close()


def _how(child):
    """How a child process ended, in words."""
    code = child.exitcode
    if code is not None and code < 0:
        with contextlib.suppress(ValueError):
            return f"killed by {signal.Signals(-code).name}"
        return f"killed by signal {-code}"
    return f"exit status {code}"
