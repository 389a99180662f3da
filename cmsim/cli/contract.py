"""The one way the command line validates, names and reports.

1. Every numeric option is declared with its :class:`~cmsim.rig.ranges.Range` (``ranged``):
   the ranges of values a user also sets elsewhere come from :data:`cmsim.rig.RANGES`, those
   of presentation options (``--top``) are declared with the option. argparse checks the
   range while parsing, so the message names the option as typed (``argument --top: must be
   an integer in [1, 1000], got 0``).
2. Every :class:`~cmsim.errors.ParameterError` the library raises carries the Python name of
   its parameter (``.param``); :func:`user_message` rewrites it, and any other Python name of
   an option of the command, into the option (``max_peaks`` → ``--top``) through
   :data:`PARAM_TO_DEST`. Library warnings (:func:`cmsim.rig.plausibility.load_warnings`) go
   through the same rewriting. A name in double quotes is a key of a file the user wrote
   (``metadata.json "fs_hz"``), not an option, and is left as it is, as is a name that is
   part of a path (``/tmp/out``).
3. Files named by options are checked (:func:`check_paths`, by :data:`PATHS`) or loaded
   through :func:`load_file`, which turns any reading error into one line naming the option.
4. Anything else is an internal error: exit 1, one line, "please report".
"""

from __future__ import annotations

import argparse
import os
import re
import tempfile
from pathlib import Path

from cmsim._io import READ_ERRORS, finite
from cmsim.errors import ParameterError

__all__ = ["CLIError", "Parser", "ranged", "subparsers", "options_of", "user_message",
           "option_named_in", "check_paths", "load_file", "finite", "PATHS", "PARAM_TO_DEST"]

#: Python names used by the library -> dest of the option that sets them.
PARAM_TO_DEST = {
    "max_peaks": "top", "top_n": "top", "n_positions": "positions",
    "cage_speed_rms": "cage_slip", "ball_rms_rad": "ball_jitter_rad",
    "correlation_s": "slip_correlation_s", "n_steps": "steps", "torques_nm": "torque_nm",
    "speeds_rpm": "speed_rpm", "friction_coefficient": "friction", "frictions": "friction",
    "clearances_m": "clearance_m", "max_freq_hz": "max_hz", "signals": "signal",
    "signal": "channel",
    "mesh": "mesh", "method": "method", "centres": "centres",
    "noise_rms": "sensor_noise", "fs_out_hz": "sensor_fs_hz",
    "algorithm": "algorithm", "dataset": "dir", "record": "run",
}

#: One-word Python names the library uses in messages for what an option sets.
_ALWAYS_REWRITE = {"substeps"}

#: Path options: dest (or (command, dest)) -> "file" (must exist), "dir" (must exist), "out"
#: (a new file), "outdir" (a new or existing directory).
PATHS = {"rig": "file", "faults": "file", "mesh_table": "file", "run": "file", "dir": "dir",
         "out": "out", "plot": "out", ("sweep", "out"): "outdir",
         ("evaluate", "report"): "out", ("dataset", "spec"): "file",
         ("dataset", "out"): "outdir", ("export", "out"): "outdir",
         ("compare", "report"): "outdir",
         ("evaluate", "train"): "dir", ("evaluate", "test"): "dir",
         ("calibrate", "out"): "out", ("calibrate", "report"): "outdir", "machine": "file"}


class CLIError(Exception):
    """An error the CLI reports in one line, with its exit status and JSON extras.

    Parameters
    ----------
    message : str
        The line, naming the option as typed.
    status : int
        Exit status (2 bad input, 3 diverged, 130 interrupted).
    option : str, optional
        The option the message is about (``--top``).
    extra : dict, optional
        More keys of the JSON error object.
    """

    def __init__(self, message, status=2, *, option=None, extra=None):
        super().__init__(message)
        self.status, self.option, self.extra = status, option, dict(extra or {})


class Parser(argparse.ArgumentParser):
    """argparse that raises instead of printing usage and exiting (one line, --json aware).

    Abbreviated options are refused (``--torque`` is not ``--torque-nm``): an abbreviation
    that works today would silently mean another option when one is added.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message):
        """Raise :class:`CLIError` with argparse's ``message`` (never exit)."""
        m = re.search(r"(?:argument|unrecognized arguments:|required:) ([^\s:,]+)", message)
        raise CLIError(f"{message} (see {self.prog} --help)", 2,
                       option=m.group(1).split("/")[-1] if m else None)


def ranged(rng):
    """argparse type: a number within ``rng`` (a :class:`~cmsim.rig.ranges.Range`), else a
    message with the range; its ``allowed`` attribute holds the range as text, its
    ``range`` the range itself.

    Examples
    --------
    >>> from cmsim.rig import RANGES
    >>> ranged(RANGES["substeps"])("3")
    3
    """
    def parse(text):
        try:
            v = int(text) if rng.integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {rng.allowed}, got {text!r}") from None
        if not rng.contains(v):
            # a negative number in exponent notation reaches here written out (argparse
            # takes "-1e-320" for an option): shown as a number, not 300 digits
            shown = text if len(text) <= 24 else f"{v:.6g}"
            raise argparse.ArgumentTypeError(f"must be {rng.allowed}, got {shown}")
        return v

    parse.__name__ = "int" if rng.integer else "float"
    parse.allowed = rng.allowed
    parse.range = rng
    return parse


def subparsers(parser):
    """{command: subparser} of the ``cmsim`` parser."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _option_name(action):
    """The option as a user types it (``--top``), or the metavar of a positional."""
    if action.option_strings:
        return max(action.option_strings, key=len)
    return action.metavar or action.dest.upper()


def options_of(parser, command):
    """{dest: option as typed} of one command of ``parser``."""
    sub = subparsers(parser).get(command)
    if sub is None:
        return {}
    return {a.dest: _option_name(a) for a in sub._actions if a.dest != "help"}


def user_message(exc, options):
    """``(message, option)`` of a library error or warning with its Python names replaced
    by the options typed.

    Parameters
    ----------
    exc : ParameterError or str
        The error (its ``param`` names the option) or a warning's text.
    options : dict
        {dest: option} of the command (:func:`options_of`).
    """
    msg = " ".join(str(exc).split())
    param = getattr(exc, "param", None)
    names = {}
    for name, dest in list(PARAM_TO_DEST.items()) + [(d, d) for d in options]:
        if dest in options:
            names[name] = options[dest]
    option = None
    if param and param.startswith("-"):
        option = param
    elif param in names:
        option = names[param]
    for name, opt in sorted(names.items(), key=lambda kv: -len(kv[0])):
        # a flag the library names as its keyword set (force=True) is the option alone
        msg = re.sub(rf"(?<![\w.\-]){re.escape(name)}=True\b", opt, msg)
        if name == param or "_" in name or name in _ALWAYS_REWRITE:
            msg = re.sub(rf"(?<![\w.\[\-\"/\\]){re.escape(name)}(?![\w\[\"/\\])", opt,
                         msg)
    if option is not None and option not in msg:
        msg = f"{option}: {msg}"
    return msg, option or option_named_in(msg, options)


def option_named_in(message, options):
    """The option (as typed) a message names first, or None: what an error is about when
    the library could not say (a derived value out of range, a run that diverged).

    Parameters
    ----------
    message : str
        The message, its Python names already replaced by the options.
    options : dict
        {dest: option} of the command (:func:`options_of`).

    Examples
    --------
    >>> option_named_in("diverged; use --substeps > 1 or a higher --fs-hz",
    ...                 {"fs_hz": "--fs-hz", "substeps": "--substeps"})
    '--substeps'
    """
    found = [(m.start(), opt) for opt in set(options.values()) if opt != "--json"
             for m in [re.search(rf"(?<![\w\-]){re.escape(opt)}(?![\w\-])", message)] if m]
    return min(found)[1] if found else None


def check_paths(args, command, options):
    """Input files exist and are files; outputs are not directories and have a parent a
    file can be written in.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed options.
    command : str
        The command (``PATHS`` may key on it).
    options : dict
        {dest: option} of the command.
    """
    for dest, option in options.items():
        kind = PATHS.get((command, dest), PATHS.get(dest))
        value = getattr(args, dest, None)
        if kind is None or value is None:
            continue
        for path in map(Path, value if isinstance(value, list) else [value]):
            if kind == "file" and not path.is_file():
                why = "is a directory" if path.is_dir() else "does not exist"
                raise CLIError(f"{option} {path}: {why} (expected a file)", option=option)
            if kind == "dir" and not path.is_dir():
                why = "is a file" if path.exists() else "does not exist"
                raise CLIError(f"{option} {path}: {why} (expected a directory)", option=option)
            if kind == "out" and path.is_dir():
                raise CLIError(f"{option} {path}: is a directory (expected a file name)",
                               option=option)
            if kind == "outdir" and path.exists() and not path.is_dir():
                raise CLIError(f"{option} {path}: is a file (expected a directory, new or "
                               f"an existing one)", option=option)
            if kind in ("out", "outdir") and not path.resolve().parent.is_dir():
                raise CLIError(f"{option} {path}: directory {path.parent} does not exist",
                               option=option)
            if kind in ("out", "outdir"):
                where = path if kind == "outdir" and path.is_dir() else path.resolve().parent
                why = _cannot_write_in(where)
                if why:
                    raise CLIError(f"{option} {path}: cannot write in {where} ({why})",
                                   option=option)


def _cannot_write_in(directory):
    """Why no file can be made in ``directory`` (its permissions, a read-only or virtual
    file system), or None: tried by making and removing an empty file there, the one test
    every file system answers truly, before any work whose result would have nowhere to
    go."""
    try:
        fd, name = tempfile.mkstemp(prefix=".cmsim-write-check-", dir=directory)
    except OSError as exc:
        return exc.strerror or type(exc).__name__
    os.close(fd)
    os.remove(name)
    return None


def load_file(option, path, loader, what):
    """``loader(path)``, any failure to read it reported as one line naming ``option``.

    Parameters
    ----------
    option : str
        The option as typed (``--rig``).
    path : str or pathlib.Path
        The file.
    loader : callable
        Reads it.
    what : str
        What the file should be, for the message (``"a rig TOML file"``).
    """
    try:
        return loader(path)
    except ParameterError as exc:
        detail = getattr(exc, "detail", None) or str(exc)
        raise CLIError(f"{option} {path}: {detail}", option=option) from None
    except READ_ERRORS as exc:
        raise CLIError(f"{option} {path}: not {what} ({type(exc).__name__}: "
                       f"{' '.join(str(exc).split()) or 'unreadable'})", option=option) from None
