"""Exceptions raised by cmsim, and the helpers that check a parameter's range, choice or type.

A :class:`ParameterError` carries the name of the parameter it is about (``.param``, the
Python name, e.g. ``"max_peaks"``) and its allowed range as text (``.allowed``), so a front end
can say the same thing in its own words: the command line replaces ``.param`` with the option
the user typed (``--top``), see :mod:`cmsim.cli`.
"""

from __future__ import annotations

import math
import numbers
import re

__all__ = ["ParameterError", "RecordWarning", "ModelWarning", "IntegrationDiverged",
           "WorkersDied", "check_range", "within", "check_choice", "check_type", "format_range",
           "format_value"]

_LEADING_NAME = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)(?= (?:must|needs|=|is|has|exceeds)\b)")


class ParameterError(ValueError):
    """A parameter is outside its allowed range; the message names it and the range.

    Parameters
    ----------
    message : str
        One line naming the parameter, its allowed range and the value given.
    param : str, optional
        Name of the parameter (Python name); by default the message's first word when the
        message reads ``"<name> must ..."`` (or ``needs``, ``=``, ``is``, ``has``).
    allowed : str, optional
        The allowed range as text, e.g. ``"> 0 kg"`` or ``"[1, 1000]"``.
    """

    def __init__(self, message, *, param=None, allowed=None):
        super().__init__(message)
        if param is None:
            m = _LEADING_NAME.match(str(message))
            param = m.group(1) if m else None
        self.param = param
        self.allowed = allowed


class RecordWarning(UserWarning):
    """A measured record is read, but something it states is doubtful (its lines
    contradict its sample rate or speed, weakly): the user should hear it. The command
    line prints each as a warning (with ``--json``, in the object's ``warnings``)."""


class ModelWarning(UserWarning):
    """A model is used beyond what one of its formulas was fitted on (a tooth shape outside
    Sainsot's fillet-foundation fit): the result stands, and the user should hear it in one
    line (the command line says it as a warning, never as Python's source-path warning)."""


class IntegrationDiverged(RuntimeError):
    """The time integration produced non-finite or runaway values."""


class WorkersDied(RuntimeError):
    """Worker processes of a dataset run kept dying (killed, out of memory) and the run
    stopped; the records finished before are kept (re-run to resume)."""


def format_value(value):
    """A value as a user reads it: ``nan``, ``1e+20``, ``'abc'`` (never ``np.float64(nan)``)."""
    if isinstance(value, bool):
        return repr(value)
    if isinstance(value, numbers.Real):
        return f"{float(value):g}"
    return repr(value)


def format_range(lo=-math.inf, hi=math.inf, *, lo_open=False, hi_open=False, unit="",
                 integer=False):
    """Readable allowed range: ``"in (0, 0.1] m"``, ``"> 0 kg"``, ``"<= 5"``, ``"finite"``.

    An infinite bound is never printed (infinity is always rejected). A bound reads as typed
    back: ``0.3`` as ``0.3``, but 2π in full (``6.283185307179586``, not ``6.28319``, which
    lies outside a range ending at 2π).
    """
    kind = "an integer" if integer else "a number"

    def num(x):
        if integer:
            return str(int(x))
        short = f"{x:g}"
        return short if float(short) == float(x) else repr(float(x))

    if math.isinf(lo) and math.isinf(hi):
        text = f"{'an integer' if integer else 'a finite number'}"
    elif math.isinf(hi):
        text = f"{kind} {'>' if lo_open else '>='} {num(lo)}"
    elif math.isinf(lo):
        text = f"{kind} {'<' if hi_open else '<='} {num(hi)}"
    else:
        text = (f"{kind} in {'(' if lo_open else '['}{num(lo)}, {num(hi)}"
                f"{')' if hi_open else ']'}")
    return text + (f" {unit}" if unit else "")


def within(v, lo, hi, *, lo_open=False, hi_open=False):
    """THE range rule: ``v`` (a float) is finite and within [lo, hi], a bound excluded when
    open (:func:`check_range` and :meth:`cmsim.rig.Range.contains` both apply it).

    Parameters
    ----------
    v : float
        The value.
    lo, hi : float
        The bounds.
    lo_open, hi_open : bool
        Whether a bound itself is excluded.

    Returns
    -------
    bool

    Examples
    --------
    >>> within(1.0, 0.0, 1.0), within(1.0, 0.0, 1.0, hi_open=True)
    (True, False)
    """
    return math.isfinite(v) and not (v < lo or v > hi or (lo_open and v == lo)
                                     or (hi_open and v == hi))


def check_range(name, value, lo=-math.inf, hi=math.inf, *, lo_open=False, hi_open=False,
                unit=""):
    """Return ``float(value)`` or raise :class:`ParameterError` naming ``name``.

    Parameters
    ----------
    name : str
        Parameter name (e.g. ``"speed_rpm"``); recorded as the error's ``param``.
    value : float
        Value to check; NaN, infinities and booleans are always rejected.
    lo, hi : float
        Allowed range.
    lo_open, hi_open : bool
        Whether the bounds themselves are excluded.
    unit : str
        Unit shown in the message.

    Examples
    --------
    >>> check_range("torque_nm", 10.0, 0.0, lo_open=True)
    10.0
    >>> try:
    ...     check_range("mass_kg", float("inf"), 0.0, lo_open=True, unit="kg")
    ... except ParameterError as exc:
    ...     print(exc)
    mass_kg must be a number > 0 kg, got inf
    """
    def refuse(got):
        allowed = format_range(lo, hi, lo_open=lo_open, hi_open=hi_open, unit=unit)
        return ParameterError(f"{name} must be {allowed}, got {got}", param=name,
                              allowed=allowed)

    if isinstance(value, bool):
        raise refuse(repr(value))
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise refuse(format_value(value)) from None
    if not within(v, lo, hi, lo_open=lo_open, hi_open=hi_open):
        raise refuse(format_value(v))
    return v


def check_choice(name, value, allowed):
    """Return ``value`` if it is one of ``allowed`` (a tuple or list of options), else raise
    :class:`ParameterError` naming ``name`` (its ``param``) and the options as given.

    >>> check_choice("plane", "strain", ("strain", "stress"))
    'strain'
    """
    if value not in allowed:
        raise ParameterError(f"{name} must be one of {allowed!r}, got {value!r}", param=name,
                             allowed=", ".join(map(repr, allowed)))
    return value


def check_type(name, value, cls):
    """Return ``value`` if it is an instance of ``cls``, else raise :class:`ParameterError`
    naming ``name`` (its ``param``) and both types: ``gear must be a SpurGear, got int``."""
    if not isinstance(value, cls):
        raise ParameterError(f"{name} must be a {cls.__name__}, got {type(value).__name__}",
                             param=name, allowed=f"a {cls.__name__}")
    return value
