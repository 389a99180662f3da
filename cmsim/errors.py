"""Exceptions raised by cmsim, and the one helper that checks a parameter's range."""

from __future__ import annotations

import math

__all__ = ["ParameterError", "IntegrationDiverged", "check_range"]


class ParameterError(ValueError):
    """A parameter is outside its allowed range; the message names it and the range."""


class IntegrationDiverged(RuntimeError):
    """The time integration produced non-finite or runaway values."""


def check_range(name, value, lo=-math.inf, hi=math.inf, *, lo_open=False, hi_open=False,
                unit=""):
    """Return ``float(value)`` or raise :class:`ParameterError` naming ``name``.

    Parameters
    ----------
    name : str
        Parameter name as the user typed it (e.g. ``"speed_rpm"``).
    value : float
        Value to check; NaN is always rejected.
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
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number, got {value!r}") from None
    left = "(" if lo_open else "["
    right = ")" if hi_open else "]"
    rng = f"{left}{lo:g}, {hi:g}{right}" + (f" {unit}" if unit else "")
    if not math.isfinite(v):
        raise ParameterError(f"{name} must be finite and in {rng}, got {value!r}")
    if v < lo or v > hi or (lo_open and v == lo) or (hi_open and v == hi):
        raise ParameterError(f"{name} must be in {rng}, got {v:g}")
    return v
