"""The fault catalogue's common ground: the :class:`Fault` base, the registry and the parsers.

A fault is a frozen value (SI units, validated on construction) that changes the model before
it is built — the mesh table per tooth, a bearing race, the kinematics or the operating
conditions — never the output signal (issue 16; DESIGN.md). Every catalogue entry

* is a frozen dataclass deriving from :class:`Fault` with a class attribute ``name`` (the
  stable string typed on the command line and in TOML, e.g. ``"outer_race"``);
* checks its own fields in ``__post_init__`` (:class:`~cmsim.errors.ParameterError` naming
  the field and its range) and its fit to a rig in :meth:`Fault.validate`;
* has a :attr:`Fault.label` (for people and for ML labels) and round-trips through
  :meth:`Fault.to_dict` / :func:`fault_from_dict`.

Text forms: ``parse_fault("outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4")`` (the CLI's
``--fault``) and ``load_faults(path_or_dict)`` (a ``[[faults]]`` list of tables with
``type = "..."``). Keys ending in ``_mm`` / ``_deg`` are converted to the ``_m`` / ``_rad``
field of the same stem, as in rig files.

Layering: this package imports :mod:`cmsim.rig`, :mod:`cmsim.frequencies`,
:mod:`cmsim.bearings` and :mod:`cmsim.mesh_stiffness`; never dynamics or anything above.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
import typing
from pathlib import Path

from cmsim.errors import ParameterError, check_range

__all__ = ["Fault", "FAULT_TYPES", "register", "fault_from_dict", "parse_fault",
           "load_faults", "faults_to_toml_list", "first_clash", "check_bearing", "check_gear"]

#: Registered catalogue entries, ``name -> class`` (filled by :func:`register`).
FAULT_TYPES: dict = {}

_UNIT_ALIASES = {"_mm": ("_m", 1e-3), "_deg": ("_rad", math.pi / 180.0)}


class Fault:
    """Base of every catalogue entry (a frozen dataclass subclass registered by name).

    Subclasses set ``name`` (class attribute) and implement :attr:`label`; they may override
    :meth:`validate` to check that the fault fits a rig.
    """

    #: Stable catalogue name (CLI, TOML, run meta).
    name: typing.ClassVar[str] = ""

    @property
    def label(self):
        """Short human/ML label, e.g. ``"outer_race@1b1 size=1.0mm depth=0.1mm"``."""
        raise NotImplementedError

    @property
    def site(self):
        """Where the fault sits when only one of its kind can sit there, as words
        (``"tooth_crack on tooth 3 of gear 1"``), else ``None``: two faults of one model on
        the same site are refused (:func:`first_clash`), as are two equal faults."""
        return None

    def validate(self, rig):
        """Check the fault against ``rig`` (component exists, defect fits); return ``self``.

        Raises
        ------
        ParameterError
            Naming the parameter and its allowed range on this rig.
        """
        return self

    def to_dict(self):
        """``{"type": name, <field>: value, ...}`` (SI values; ``None`` fields left out)."""
        out = {"type": self.name}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if v is None:
                continue
            if isinstance(v, tuple):
                v = [list(x) if isinstance(x, tuple) else x for x in v]
            out[f.name] = v
        return out

    @classmethod
    def from_dict(cls, data):
        """This entry from a :meth:`to_dict`-style mapping (``type`` optional, must match)."""
        data = dict(data)
        kind = data.pop("type", cls.name)
        if kind != cls.name:
            raise ParameterError(f"type must be {cls.name!r} for {cls.__name__}, got {kind!r}",
                                 param="type")
        return cls(**_convert_fields(cls, data))


def register(cls):
    """Class decorator: add a catalogue entry to :data:`FAULT_TYPES` under ``cls.name``."""
    if not cls.name or cls.name in FAULT_TYPES:
        raise ValueError(f"fault name {cls.name!r} empty or already registered")
    FAULT_TYPES[cls.name] = cls
    return cls


def _allowed_names():
    return ", ".join(sorted(FAULT_TYPES))


def _field_kind(cls, name):
    """'int', 'float', 'str', 'tuple' or 'any' from a field's annotation."""
    ann = str({f.name: f.type for f in dataclasses.fields(cls)}[name])
    for kind in ("tuple", "int", "float", "str"):
        if kind in ann:
            return kind
    return "any"


#: Text-to-number parsers of the numeric field kinds, with the allowed text of their errors.
_NUMBER_PARSERS = {"int": (int, "an integer"), "float": (float, "a number")}


def _coerce(cls, key, value):
    """Convert a value read from text/TOML to the field's type; refuse what does not fit."""
    kind = _field_kind(cls, key)
    if value is None:
        return None
    if kind == "tuple":
        if not isinstance(value, (list, tuple)):
            raise ParameterError(f"{key} must be a list, got {value!r}", param=key,
                                 allowed="a list")
        return tuple(tuple(float(y) for y in x) if isinstance(x, (list, tuple)) else float(x)
                     for x in value)
    if isinstance(value, bool):
        raise ParameterError(f"{key} must be a {kind}, got {value!r}", param=key, allowed=kind)
    if kind in _NUMBER_PARSERS:
        parse, allowed = _NUMBER_PARSERS[kind]
        if isinstance(value, str):
            try:
                return parse(value)
            except ValueError:
                raise ParameterError(f"{key} must be {allowed}, got {value!r}", param=key,
                                     allowed=allowed) from None
        if kind == "int" and isinstance(value, float) and value.is_integer():
            return int(value)
        return value
    if kind == "str":
        return str(value)
    return value


def _convert_fields(cls, data):
    """Apply unit aliases (``_mm``, ``_deg``), refuse unknown or doubled keys, coerce types."""
    names = {f.name for f in dataclasses.fields(cls)}
    out, given = {}, {}
    for key, value in data.items():
        target = key
        for alias, (si, factor) in _UNIT_ALIASES.items():
            if key.endswith(alias) and key[: -len(alias)] + si in names:
                target = key[: -len(alias)] + si
                value = check_range(key, _coerce(cls, target, value)) * factor
        if target not in names:
            raise ParameterError(f"unknown parameter {key!r} for fault {cls.name!r}; allowed: "
                                 f"{', '.join(sorted(names))}", param=key,
                                 allowed=", ".join(sorted(names)))
        if target in given:
            raise ParameterError(f"{given[target]} and {key} are both given (the same setting "
                                 "in two units); keep one", param=key)
        given[target] = key
        out[target] = _coerce(cls, target, value)
    return out


def fault_from_dict(data):
    """A fault from a mapping with ``type`` (see :meth:`Fault.to_dict`).

    Raises
    ------
    ParameterError
        Unknown ``type`` (the message lists the catalogue), unknown or invalid parameters.
    """
    if not isinstance(data, dict):
        raise ParameterError(f"a fault must be a table with 'type', got {data!r}",
                             param="faults")
    kind = data.get("type")
    if kind not in FAULT_TYPES:
        raise ParameterError(f"type must be one of {_allowed_names()}, got {kind!r}",
                             param="type", allowed=_allowed_names())
    return FAULT_TYPES[kind].from_dict(data)


def parse_fault(text):
    """A fault from its command-line form ``"name:key=value,key=value"``.

    Examples
    --------
    >>> from cmsim.faults import parse_fault
    >>> f = parse_fault("outer_race:bearing=1b1,size_mm=1,depth_m=1e-4")
    >>> f.name, f.bearing, round(f.size_m, 6)
    ('outer_race', '1b1', 0.001)
    """
    if not isinstance(text, str) or not text.strip():
        raise ParameterError(f"fault must be 'name:key=value,...', got {text!r}",
                             param="fault", allowed="name:key=value,...")
    name, _, rest = text.strip().partition(":")
    data = {"type": name.strip()}
    for item in filter(None, (x.strip() for x in rest.split(","))):
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise ParameterError(f"fault parameter {item!r} must read key=value",
                                 param="fault", allowed="key=value")
        key = key.strip()
        if key in data:
            raise ParameterError(f"{key} is given twice ({data[key]} and {value.strip()}); "
                                 "give each parameter once", param=key)
        data[key] = value.strip()
    return fault_from_dict(data)


def load_faults(source, *, rig_file=False):
    """Faults from a TOML file or an already-parsed mapping holding a ``[[faults]]`` list.

    Parameters
    ----------
    source : str, Path or dict
        Path of a TOML file, or its parsed content.
    rig_file : bool
        ``False`` (default): a faults file, which holds a non-empty ``[[faults]]`` list and
        nothing else — a file that defines no fault (empty, or ``[fault]`` for
        ``[[faults]]``) or has keys it does not know is refused, not read as "healthy".
        ``True``: a rig file, whose other tables are the rig's (:meth:`cmsim.rig.Rig.load`
        checks them) and whose ``[[faults]]`` list is optional.

    Returns
    -------
    tuple of Fault
        In file order (empty only for a rig file without a ``faults`` list).

    Raises
    ------
    ParameterError
        An unreadable file, an unknown key (named), no fault in a faults file, or a bad
        entry (``faults[i]: ...``).
    """
    if isinstance(source, dict):
        data = source
    else:
        path = Path(source)
        try:
            with path.open("rb") as fh:
                data = tomllib.load(fh)
        except FileNotFoundError:
            raise ParameterError(f"faults file {path} does not exist", param="faults") from None
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise ParameterError(f"faults file {path} cannot be read as TOML: {exc}",
                                 param="faults") from None
    if not rig_file:
        _check_faults_file_keys(data)
    items = data.get("faults", [])
    if not isinstance(items, list):
        raise ParameterError("faults must be a list of tables ([[faults]])", param="faults")
    if not items and not rig_file:
        raise ParameterError(f"defines no fault: {_FAULTS_FILE_FORM}", param="faults")
    out = []
    for i, item in enumerate(items):
        try:
            out.append(fault_from_dict(item))
        except ParameterError as exc:
            raise ParameterError(f"faults[{i}]: {exc}", param=exc.param,
                                 allowed=exc.allowed) from None
    return tuple(out)


#: What a faults file holds, for its error messages.
_FAULTS_FILE_FORM = ('a faults file holds [[faults]] tables, each with type = "<name>" and '
                     "the fault's fields")


def _check_faults_file_keys(data):
    """Refuse any top-level key of a faults file but ``faults``, naming it (``[fault]``)."""
    for key, value in data.items():
        if key != "faults":
            what = f"table [{key}]" if isinstance(value, dict) else f"key {key!r}"
            hint = " (write [[faults]])" if key in ("fault", "Faults", "FAULTS") else ""
            raise ParameterError(f"unknown {what}{hint}; {_FAULTS_FILE_FORM}", param=key,
                                 allowed="faults")


def first_clash(faults):
    """The first two of ``faults`` that cannot both be in one model, or ``None``.

    Two equal faults (the same fault given twice) clash, and so do two on the same
    :attr:`Fault.site` (two cracks on one tooth, two eccentricities of one gear): the
    model would silently keep the last or pile them up into something nobody described.

    Parameters
    ----------
    faults : sequence of Fault

    Returns
    -------
    tuple (int, int, str) or None
        Indices ``(i, j)``, ``i < j``, and why they clash, in words.
    """
    seen = {}
    for j, f in enumerate(faults):
        for key, why in ((("same", f), "is the same fault as"),
                         (("site", f.site), f"is a second {f.site} beside")):
            if key[1] is None:
                continue
            if key in seen:
                return seen[key], j, why
            seen[key] = j
    return None


def faults_to_toml_list(faults):
    """The ``[[faults]]`` list (plain dicts) of ``faults`` for a TOML writer."""
    return [f.to_dict() for f in faults]


# ---------------------------------------------------------------------- helpers for entries
def check_bearing(rig, bearing):
    """Index of bearing ``bearing`` in ``rig.bearing_names``; refuse an unknown name."""
    names = rig.bearing_names
    if bearing not in names:
        raise ParameterError(f"bearing must be one of {', '.join(names)}, got {bearing!r}",
                             param="bearing", allowed=", ".join(names))
    return names.index(bearing)


def check_gear(rig, gear):
    """The :class:`~cmsim.rig.SpurGear` number ``gear`` (1 driving, 2 driven) of ``rig``."""
    if not rig.has_gears:
        raise ParameterError(f"gear must name a gear of the rig, but rig {rig.name!r} has no "
                             "gears", param="gear", allowed="a rig with gears")
    if gear not in (1, 2):
        raise ParameterError(f"gear must be 1 (driving) or 2 (driven), got {gear!r}",
                             param="gear", allowed="1 or 2")
    return rig.gears.driving if gear == 1 else rig.gears.driven


def check_int(name, value, lo, hi=None):
    """Refuse a non-integer (or boolean) ``value`` outside [lo, hi]; return it as int."""
    allowed = f"an integer >= {lo}" if hi is None else f"an integer in [{lo}, {hi}]"
    if isinstance(value, bool) or not isinstance(value, int) or value < lo \
            or (hi is not None and value > hi):
        raise ParameterError(f"{name} must be {allowed}, got {value!r}", param=name,
                             allowed=allowed)
    return int(value)


def check_angle(name, value):
    """Refuse an angle or phase outside [−2π, 2π] rad; return it as float."""
    return check_range(name, value, -2 * math.pi, 2 * math.pi, unit="rad")


def mm(x):
    """Metres as a short millimetre string for labels."""
    return f"{1e3 * x:.3g}mm"
