"""``main(argv)``: parse, run one command, print its result (text or one JSON object).

Exit status: 0 success, 1 internal error (please report) or worker processes that kept
dying, 2 bad input, 3 diverged integration, 130 interrupted, 141 stdout closed early (``cmsim
... | head``: the reader left before the result was written; quietly, no traceback, and the
status a Unix filter killed by SIGPIPE gives, so ``set -o pipefail`` treats cmsim as it
treats ``grep`` or ``cat``: the output did not all arrive). With ``--json`` stdout holds
exactly one JSON object, also on errors: ``{"error": message, "status": code, "option":
"--top" or null}``; warnings go to stderr (and, with ``--json``, to the object's
``warnings`` list).
"""

from __future__ import annotations

import argparse
import atexit
import json
import os
import re
import sys
import threading
import warnings

import numpy as np

from cmsim.cli import (calibrate, compare, dataset, evaluate, export, import_, losses,
                       mesh_table, modes, report, simulate, spectrum, sweep)
from cmsim.cli.contract import (CLIError, Parser, check_paths, finite, option_named_in,
                                options_of, subparsers, user_message)
from cmsim.errors import (IntegrationDiverged, ModelWarning, ParameterError, RecordWarning,
                          WorkersDied)

__all__ = ["main", "console", "build_parser", "COMMANDS"]

#: The command modules, in ``cmsim --help`` order; each has ``register(sub)``, which gives
#: its parser the defaults ``func=run`` (``run(args) -> dict``) and ``text`` (``text(dict)
#: -> str``).
COMMANDS = (simulate, modes, mesh_table, spectrum, sweep, dataset, export, report, evaluate,
            compare, calibrate, import_, losses)


def build_parser():
    """The argparse parser of ``cmsim``: one subparser per command, each with ``--json``."""
    from cmsim import __version__

    parser = Parser(prog="cmsim",
                    description="Vibration of a spur-gear transmission on ball bearings "
                                "(19-DOF model of Fernandez-del-Rincon et al. 2016).")
    parser.add_argument("--version", action="version", version=f"cmsim {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.register(sub)
    for p in subparsers(parser).values():
        p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    return parser


_NEGATIVE_EXPONENT_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)e[-+]?\d+$", re.IGNORECASE)


def _plain_negative_numbers(argv):
    """``-1e-6`` → ``-0.000001``: argparse takes a negative number in exponent notation for an
    option, but a plain decimal for a value, also in lists (``--clearance-m 0 -1e-6``)."""
    return [np.format_float_positional(float(a), trim="-")
            if _NEGATIVE_EXPONENT_NUMBER.match(a) else a for a in argv]


def _notice_compile(args, integrates=True):
    """Once per process, before the first heavy step of a command, on a cold numba cache:
    compile the integration kernels now with progress lines on stderr (``integrates``: the
    command simulates; also with ``--json``, whose stdout keeps its one JSON object), or
    say in one stderr line that the command's own, smaller kernels compile (not with
    ``--json``: a script reads that command's stderr as its warnings)."""
    from cmsim.dynamics.simulation import compile_kernels, kernels_cached
    from cmsim.progress import progress_enabled

    if args._compile_noticed:
        return
    args._compile_noticed = True
    if integrates:
        compile_kernels()
    elif not args.json and not kernels_cached() and progress_enabled():
        print("cmsim: compiling numba kernels (first run only; later runs load them from "
              "the cache)...", file=sys.stderr)


#: Exit status when stdout is closed before the result is written (128 + SIGPIPE).
BROKEN_PIPE_STATUS = 141


def main(argv=None):
    """Entry point of the ``cmsim`` console script; returns the exit status.

    A reader that closes stdout early (``cmsim ... | head``) ends the command quietly with
    :data:`BROKEN_PIPE_STATUS` (the Python documentation's recipe: the rest of stdout goes
    to ``os.devnull``, so the interpreter's own flush at exit does not fail either).

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default ``sys.argv[1:]``).
    """
    try:
        status = _main(argv)
        sys.stdout.flush()
        return status
    except BrokenPipeError:
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):   # stdout is no file (a capture)
            pass
        return BROKEN_PIPE_STATUS


def console():
    """The ``cmsim`` console script, ``python -m cmsim`` and ``python -m cmsim.cli``:
    :func:`main`, then the process ends at once.

    Once the command is done, the interpreter's own teardown (freeing every module, numba's
    and scipy's included: 0.2-0.5 s, longer than a machine comparison's features) does
    nothing a user sees. So stdout and stderr are flushed and the exit handlers run
    (logging, multiprocessing, temporary directories), then :func:`os._exit` ends the
    process with the command's status. Where another thread is still alive, the
    interpreter ends as usual (it joins them).
    """
    status = main()
    run_exit_handlers = getattr(atexit, "_run_exitfuncs", None)
    if threading.active_count() > 1 or run_exit_handlers is None:
        sys.exit(status)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):      # a reader gone: what it missed is lost either way
            pass
    run_exit_handlers()
    os._exit(status)


def _main(argv):
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    parser = build_parser()
    args = argparse.Namespace(json="--json" in argv, command=argv[0] if argv else None,
                              warnings=[])
    try:
        args = parser.parse_args(_plain_negative_numbers(argv))
        args.warnings = []
        options = options_of(parser, args.command)
        args.warn = lambda text: args.warnings.append(user_message(text, options)[0])
        args._compile_noticed = False
        args.notice_compile = lambda integrates=True: _notice_compile(args, integrates)
        try:
            check_paths(args, args.command, options)
            res = _run_warned(args)
        except ParameterError as exc:
            msg, option = user_message(exc, options)
            raise CLIError(msg, 2, option=option) from None
        except WorkersDied as exc:
            raise CLIError(f"{exc}; re-run the same command to resume (with fewer --workers "
                           f"if memory is short)", 1) from None
        except IntegrationDiverged as exc:
            msg, option = user_message(exc, options)
            extra = {}
            if getattr(exc, "summary", None) is not None:
                extra["summary"] = exc.summary.to_dict()
            raise CLIError(msg, 3, option=option, extra=extra) from None
    except CLIError as exc:
        return _fail(parser, args, str(exc), exc.status, exc.option, exc.extra)
    except KeyboardInterrupt:
        return _fail(parser, args, "interrupted", 130)
    except BrokenPipeError:
        raise                                   # main's: stdout closed early, not an error
    except Exception as exc:  # noqa: BLE001 - the last line of defence
        if os.environ.get("CMSIM_DEBUG"):
            raise
        detail = " ".join(str(exc).split())[:300]
        return _fail(parser, args, f"internal error ({type(exc).__name__}: {detail}); please "
                                   f"report it with the command line (CMSIM_DEBUG=1 shows the "
                                   f"traceback)", 1)
    if isinstance(res, dict) and args.warnings:
        res = {**res, "warnings": list(args.warnings)}
    if not args.json:
        for text in args.warnings:
            print(f"cmsim {args.command}: warning: {text}", file=sys.stderr)
        print(args.text(res))
    else:
        print(json.dumps(finite(res)))
    return 0


def _run_warned(args):
    """``args.func(args)`` with every :class:`~cmsim.errors.RecordWarning` (a measured record
    read despite a doubt) and :class:`~cmsim.errors.ModelWarning` (a formula used beyond its
    fit) the library issues said through ``args.warn``, once per text; other warnings pass
    on as they came, once per text and place, after the recording has ended (passed on
    inside it, each was recorded again, and the first RuntimeWarning a command raised made
    it loop for ever)."""
    caught = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", RecordWarning)
            warnings.simplefilter("always", ModelWarning)
            return args.func(args)
    finally:
        said = set()
        for w in caught:
            if issubclass(w.category, (RecordWarning, ModelWarning)):
                if str(w.message) not in said:
                    said.add(str(w.message))
                    args.warn(str(w.message))
            elif (key := (w.category, str(w.message), w.filename, w.lineno)) not in said:
                said.add(key)
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _fail(parser, args, message, status, option=None, extra=None):
    message = " ".join(str(message).split())
    command = getattr(args, "command", None)
    prog = f"cmsim {command}" if command in subparsers(parser) else "cmsim"
    if option is None and status in (2, 3):     # bad input or a diverged run: name the option
        option = option_named_in(message, options_of(parser, command))
    print(f"{prog}: error: {message}", file=sys.stderr)
    if getattr(args, "json", False):
        out = {"error": message, "status": status, "option": option, **(extra or {})}
        if getattr(args, "warnings", None):
            out["warnings"] = list(args.warnings)
        print(json.dumps(finite(out)))
    return status
