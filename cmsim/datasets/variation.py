"""What a spec can vary: named settings of the operating point or of the rig, and their values.

A *setting* is what a :class:`~cmsim.datasets.spec.DatasetSpec` draws or lays on a grid for
each record; a :class:`Variation` names one setting and lists its values (one axis of a grid:
a sweep's records are the Cartesian product of its variations). A setting is one of

operating-point fields
    ``speed_rpm``, ``torque_nm``, ``radial_load_n``, ``radial_load_angle_rad``
    (:class:`~cmsim.rig.OperatingPoint`).
named rig transformations (:data:`RIG_TRANSFORMS`)
    ``clearance_m`` → :meth:`Rig.with_clearance <cmsim.rig.Rig.with_clearance>` (every
    bearing; negative = preload), ``friction`` → :meth:`Rig.with_friction
    <cmsim.rig.Rig.with_friction>` (mesh friction coefficient).
any rig field, by its dotted path
    ``lubricant.dynamic_viscosity_pa_s``, ``mesh_contact.damping_ratio``,
    ``shafts.0.bearing_1.clearance_m`` (a number indexes a tuple), ``output_inertia_kg_m2``.
    The rig is rebuilt with :func:`dataclasses.replace` along the path, so each component
    checks the new value as it would on construction.

A new kind of axis (a fault, a sensor setting) is one more entry in :data:`RIG_TRANSFORMS`
(or a dotted path), never a new loop. A value ``None`` means "leave the base setting" (the
record id then leaves the setting out). Operating-point fields and the named transformations
are checked against :data:`cmsim.rig.RANGES`; a dotted field is checked by its component.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError
from cmsim.rig import RANGES, OperatingPoint, Rig

__all__ = ["Variation", "RigTransform", "OPERATING_POINT_FIELDS", "RIG_TRANSFORMS", "setting_kind",
           "apply_rig_setting", "value_token", "allowed_settings"]

#: Operating-point fields a variation may name.
OPERATING_POINT_FIELDS = tuple(f.name for f in dataclasses.fields(OperatingPoint))


@dataclass(frozen=True)
class RigTransform:
    """A named change of the rig, ``apply(rig, value) -> Rig``, and its token in record ids.

    Attributes
    ----------
    apply : callable
        ``apply(rig, value)`` returns the changed rig.
    token : callable
        ``token(value)`` returns the part of a record id, e.g. ``"c15um"``.
    check : callable
        ``check(label, value)`` returns the checked value or raises ``ParameterError``.
    needs_gears : bool
        Only meaningful on a rig with gears.
    """

    apply: object
    token: object
    check: object = None
    needs_gears: bool = False


#: Named rig transformations (name → :class:`RigTransform`). Add an entry to add an axis.
RIG_TRANSFORMS = {
    "clearance_m": RigTransform(apply=Rig.with_clearance,
                                token=lambda v: f"c{v * 1e6:g}um",
                                check=RANGES["clearance_m"].check),
    "friction": RigTransform(apply=Rig.with_friction, token=lambda v: f"f{v:g}",
                             check=RANGES["friction"].check,
                             needs_gears=True),
}

#: Record-id tokens of the operating-point fields.
_OP_TOKENS = {"speed_rpm": lambda v: f"n{v:g}rpm", "torque_nm": lambda v: f"T{v:g}Nm",
              "radial_load_n": lambda v: f"Fr{v:g}N",
              "radial_load_angle_rad": lambda v: f"phi{v:g}rad"}


def allowed_settings(rig=None):
    """Human-readable list of the settings a variation may name (for error messages)."""
    fields = [f.name for f in dataclasses.fields(Rig)]
    return (f"operating-point fields {list(OPERATING_POINT_FIELDS)}, rig transformations "
            f"{sorted(RIG_TRANSFORMS)}, or a dotted rig field path (e.g. "
            f"'lubricant.dynamic_viscosity_pa_s', 'shafts.0.bearing_1.clearance_m'; rig fields "
            f"{fields})")


def setting_kind(name, rig):
    """``"operating_point"``, ``"transform"`` or ``"rig_field"``; unknown names raise.

    Parameters
    ----------
    name : str
        Setting name (see the module docstring).
    rig : Rig
        Base rig, against which a dotted path is resolved.

    Raises
    ------
    ParameterError
        Naming the setting and listing the allowed ones.
    """
    if not isinstance(name, str) or not name:
        raise ParameterError(f"a variation needs a setting name (str), got {name!r}; "
                             f"allowed: {allowed_settings()}")
    if name in OPERATING_POINT_FIELDS:
        return "operating_point"
    if name in RIG_TRANSFORMS:
        if RIG_TRANSFORMS[name].needs_gears and not rig.has_gears:
            raise ParameterError(f"variation {name!r} needs a rig with gears (this rig has none)")
        return "transform"
    obj = rig
    for i, part in enumerate(name.split(".")):
        where = ".".join(name.split(".")[:i]) or "the rig"
        if isinstance(obj, tuple):
            if not part.isdigit() or int(part) >= len(obj):
                raise ParameterError(f"unknown variation {name!r}: {where} is a tuple of "
                                     f"{len(obj)}, index it with 0..{len(obj) - 1}")
            obj = obj[int(part)]
        elif dataclasses.is_dataclass(obj):
            names = [f.name for f in dataclasses.fields(obj)]
            if part not in names:
                if i == 0:
                    raise ParameterError(f"unknown variation {name!r}; allowed: "
                                         f"{allowed_settings()}")
                raise ParameterError(f"unknown variation {name!r}: {where} "
                                     f"({type(obj).__name__}) has no field {part!r}; its "
                                     f"fields: {names}")
            obj = getattr(obj, part)
        else:
            raise ParameterError(f"unknown variation {name!r}: {where} is a value "
                                 f"({type(obj).__name__}), not a component with fields")
    if dataclasses.is_dataclass(obj) or isinstance(obj, tuple):
        raise ParameterError(f"variation {name!r} names a component ({type(obj).__name__}), "
                             f"not a value; name one of its fields")
    if obj is None:
        raise ParameterError(f"variation {name!r}: this rig has no such value (it is None)")
    return "rig_field"


def _replace_path(obj, parts, value):
    if not parts:
        return value
    head, rest = parts[0], parts[1:]
    if isinstance(obj, tuple):
        i = int(head)
        return obj[:i] + (_replace_path(obj[i], rest, value),) + obj[i + 1:]
    return dataclasses.replace(obj, **{head: _replace_path(getattr(obj, head), rest, value)})


def apply_rig_setting(rig, name, value):
    """``rig`` with setting ``name`` (a transformation or a dotted field path) set to ``value``.

    ``None`` returns ``rig`` unchanged. The changed component validates the value.
    """
    if value is None:
        return rig
    if name in RIG_TRANSFORMS:
        return RIG_TRANSFORMS[name].apply(rig, value)
    return _replace_path(rig, name.split("."), value)


def value_token(name, value):
    """Part of a record id for ``name = value`` ("" for None), e.g. ``"T10Nm"``, ``"f0.03"``,
    ``"lubricant-dynamic_viscosity_pa_s0.004"``."""
    if value is None:
        return ""
    if name in _OP_TOKENS:
        return _OP_TOKENS[name](value)
    if name in RIG_TRANSFORMS:
        return RIG_TRANSFORMS[name].token(value)
    return f"{name.replace('.', '-')}{value:g}"


def _check_value(label, name, value):
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{label} must be a number, got {value!r}")
    if name in RIG_TRANSFORMS and RIG_TRANSFORMS[name].check is not None:
        return RIG_TRANSFORMS[name].check(label, value)
    if isinstance(value, (int, np.integer)) and name not in OPERATING_POINT_FIELDS:
        return int(value)                  # an integer rig field (a number of balls)
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{label} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ParameterError(f"{label} must be a finite number, got {value!r}")
    return v


@dataclass(frozen=True)
class Variation:
    """One axis of a grid: a setting and the values it takes.

    Attributes
    ----------
    name : str
        The setting (module docstring): an operating-point field (``"torque_nm"``), a rig
        transformation (``"clearance_m"``, ``"friction"``) or a dotted rig field path.
    values : tuple
        Its values, in the setting's SI unit (finite numbers, no repeats; ``None`` = the base
        value). Integers given for a dotted rig field stay integers (a number of balls);
        operating-point and transformation values become floats.

    Examples
    --------
    >>> Variation("torque_nm", [10, 50.0]).values
    (10.0, 50.0)
    """

    name: str
    values: tuple

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ParameterError(f"a variation needs a setting name (str), got {self.name!r}")
        values = self.values
        if values is None or isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
            values = (values,)
        out = tuple(_check_value(f"{self.name}[{i}]", self.name, v)
                    for i, v in enumerate(values))
        if not out:
            raise ParameterError(f"{self.name} must hold at least one value")
        if len(set(out)) != len(out):
            raise ParameterError(f"{self.name} must not repeat a value, got {list(out)}")
        object.__setattr__(self, "values", out)

    @classmethod
    def coerce(cls, item):
        """A :class:`Variation` from itself, a ``(name, values)`` pair or a
        ``{"name": ..., "values": ...}`` dict."""
        if isinstance(item, cls):
            return item
        if isinstance(item, dict):
            unknown = set(item) - {"name", "values"}
            if unknown or "name" not in item or "values" not in item:
                raise ParameterError(f"a variation is {{'name': ..., 'values': [...]}}, got "
                                     f"keys {sorted(item)}")
            return cls(item["name"], item["values"])
        if isinstance(item, (tuple, list)) and len(item) == 2:
            return cls(item[0], item[1])
        raise ParameterError(f"a variation is Variation(name, values), (name, values) or "
                             f"{{'name': ..., 'values': [...]}}, got {item!r}")

    def to_dict(self):
        """``{"name": ..., "values": [...]}``."""
        return {"name": self.name, "values": list(self.values)}
