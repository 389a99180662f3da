"""Run a user's code (a diagnostic algorithm) isolated from cmsim's own output and exit.

A user's function may print, write to file descriptor 1, raise, or call ``sys.exit``; none
of it may change what cmsim reports:

* its output goes to stderr (:func:`output_to_stderr`: ``sys.stdout`` and file descriptor 1
  both), so stdout keeps cmsim's result only (one JSON object with ``--json``);
* whatever it raises, :class:`SystemExit` included, is returned as a :class:`UserError`
  with the traceback of the user's frames (:func:`call_user`): that record fails, the
  evaluation goes on;
* :class:`KeyboardInterrupt` is not caught: Ctrl-C stops the evaluation.
"""

from __future__ import annotations

import contextlib
import os
import sys
import traceback
from dataclasses import dataclass

__all__ = ["UserError", "call_user", "output_to_stderr"]

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
