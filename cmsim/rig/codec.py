"""Parameter dataclasses to plain nested dicts (TOML, JSON) and back, every key checked.

:func:`to_plain` writes a frozen dataclass as a dict of its fields (nested dataclasses as
tables, tuples as lists); :func:`from_plain` reads one back into a given class, finding the
class of each nested table from the field's type hint (``shafts: tuple[ShaftLine, ...]``,
``gears: GearPair | None``), so a new component needs no registration here. Unknown keys,
missing required keys, booleans or strings where numbers belong, and the same setting in
two units are refused with the key's full path (``shafts[0].bearing_1.n_balls``). Keys ending
in ``_deg`` or ``_mm`` are converted explicitly to the ``_rad`` / ``_m`` field of the same
stem.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing

import numpy as np

from cmsim.errors import ParameterError

__all__ = ["to_plain", "from_plain", "drop_none"]

#: Key endings accepted on reading and converted: ending → (SI ending, factor).
_UNIT_ALIASES = {"_deg": ("_rad", math.radians(1.0)), "_mm": ("_m", 1e-3)}


def to_plain(obj):
    """``obj`` (a dataclass, tuple or numpy scalar) as plain dicts, lists, floats and ints."""
    if dataclasses.is_dataclass(obj):
        return {f.name: to_plain(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, tuple):
        return [to_plain(x) for x in obj]
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        return float(obj)
    return obj


def drop_none(d):
    """The dict or list ``d`` without ``None`` values, at every depth (TOML has no null)."""
    if isinstance(d, dict):
        return {k: drop_none(v) for k, v in d.items() if v is not None}
    if isinstance(d, list):
        return [drop_none(x) for x in d]
    return d


def _nested_class(hint):
    """The dataclass a field holds (itself, in ``X | None`` or in ``tuple[X, ...]``)."""
    if dataclasses.is_dataclass(hint):
        return hint
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType, tuple):
        for arg in typing.get_args(hint):
            found = _nested_class(arg)
            if found is not None:
                return found
    return None


def _key(where, name):
    """``rig.shafts[0].bearing_1`` + ``n_balls`` → ``shafts[0].bearing_1.n_balls``."""
    path = f"{where}.{name}"
    return path[len("rig."):] if path.startswith("rig.") else path


def _check_numbers(field_type, value, where, key):
    """Refuse booleans, strings and nested lists where a field holds numbers."""
    if not ("float" in field_type or "int" in field_type):
        return
    items = value if isinstance(value, list) else [value]
    for x in items:
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            what = "numbers" if isinstance(value, list) else "a number"
            raise ParameterError(f"{_key(where, key)} must be {what}, got {value!r}",
                                 param=_key(where, key), allowed=what)


def _scale(value, factor):
    if isinstance(value, list):
        return [v * factor for v in value]
    return value * factor


def from_plain(cls, data, where):
    """An instance of dataclass ``cls`` from :func:`to_plain` output.

    Parameters
    ----------
    cls : type
        A frozen dataclass.
    data : dict
        Its fields (nested tables for nested dataclasses).
    where : str
        The path of ``data`` in the file, for messages (``"rig"``, ``"rig.shafts[0]"``).

    Raises
    ------
    ParameterError
        An unknown, missing, duplicated or mistyped key, or a value the class refuses; the
        message names the key's path.
    """
    if not isinstance(data, dict):
        raise ParameterError(f"{where} must be a table, got {type(data).__name__}")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    hints = typing.get_type_hints(cls)
    kwargs = {}
    given = {}
    for key, value in data.items():
        target = key
        for alias, (si, factor) in _UNIT_ALIASES.items():
            if key.endswith(alias) and key[: -len(alias)] + si in fields:
                target = key[: -len(alias)] + si
                _check_numbers(str(fields[target].type), value, where, key)
                value = _scale(value, factor)
        if target not in fields:
            raise ParameterError(f"unknown key {where}.{key}; allowed: {sorted(fields)}")
        if target in given:
            raise ParameterError(f"{_key(where, given[target])} and {_key(where, key)} are both "
                                 f"given (the same setting in two units); keep one",
                                 param=_key(where, key))
        given[target] = key
        sub = _nested_class(hints[target])
        if value is not None and sub is None:
            _check_numbers(str(fields[target].type), value, where, key)
        if sub is not None and value is not None:
            if isinstance(value, list):
                value = tuple(from_plain(sub, v, f"{where}.{target}[{i}]")
                              for i, v in enumerate(value))
            else:
                value = from_plain(sub, value, f"{where}.{target}")
        elif isinstance(value, list):
            value = tuple(value)
        kwargs[target] = value
    missing = [name for name, f in fields.items()
               if name not in kwargs and f.default is dataclasses.MISSING
               and f.default_factory is dataclasses.MISSING]
    if missing:
        raise ParameterError(f"missing key {_key(where, missing[0])!r}"
                             + (f" (and {', '.join(missing[1:])})" if missing[1:] else ""),
                             param=_key(where, missing[0]))
    try:
        return cls(**kwargs)
    except ParameterError as exc:
        if getattr(exc, "located", False):
            raise
        # name the component: "shafts[0].bearing_1.n_balls must be ...", not "n_balls ..."
        msg, param = str(exc), exc.param
        if param and msg.startswith(param) and where != "rig":
            param = _key(where, param)
            msg = param + msg[len(exc.param):]
        elif where != "rig":
            msg = f"{where[len('rig.'):] if where.startswith('rig.') else where}: {msg}"
        err = ParameterError(msg, param=param, allowed=exc.allowed)
        err.located = True
        raise err from None
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{where}: {exc}") from None
