"""One value of a dataset spec: a constant, a choice among values, or a bounded distribution.

A spec value is written as a number (a constant: the same in every record, not part of a
record's name), a list (the values of a grid axis; under random sampling one is drawn
uniformly) or a table ``{distribution = "uniform" | "loguniform" | "normal" | "choice",
min, max, mean, std, values}`` (a normal draw is clipped to ``[min, max]``). Bounds come
from :data:`cmsim.rig.RANGES` (or the spec module's nuisance ranges); every error names the
dotted key (``operating.speed_rpm.max``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError

__all__ = ["Distribution", "DISTRIBUTIONS", "spec_error", "spec_number"]

#: Kinds of :class:`Distribution`.
DISTRIBUTIONS = ("constant", "uniform", "loguniform", "normal", "choice")

_DIST_KEYS = {"distribution", "min", "max", "mean", "std", "values"}


def spec_error(key, msg):
    """A :class:`~cmsim.errors.ParameterError` whose message starts with the spec key.

    Parameters
    ----------
    key : str
        Dotted spec key (``"operating.speed_rpm.max"``), recorded as the error's ``param``.
    msg : str
        What is wrong.
    """
    return ParameterError(f"{key}: {msg}", param=key)


def spec_number(key, v):
    """``float(v)``, or an error naming ``key`` if ``v`` is not a finite number.

    Parameters
    ----------
    key : str
        Dotted spec key.
    v : object
        The value.
    """
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise spec_error(key, f"must be a finite number, got {v!r}")
    return float(v)


@dataclass(frozen=True)
class Distribution:
    """One spec value: a constant, a choice among values, or a bounded distribution.

    Attributes
    ----------
    kind : str
        One of :data:`DISTRIBUTIONS`.
    lo, hi : float
        Bounds (uniform, loguniform, the clip of normal); NaN if unused.
    mean, std : float
        Of a normal draw; NaN if unused.
    values : tuple
        The constant (one value) or the choices (``None`` = the base rig's own value).

    Examples
    --------
    >>> Distribution.parse("operating.torque_nm", [10, 50]).values
    (10.0, 50.0)
    """

    kind: str
    lo: float = math.nan
    hi: float = math.nan
    mean: float = math.nan
    std: float = math.nan
    values: tuple = ()

    @classmethod
    def parse(cls, key, raw, bounds=None, numeric=True):
        """Parse a spec value at ``key``, checked against ``bounds``.

        Parameters
        ----------
        key : str
            Dotted spec key (named in errors).
        raw : object
            A fixed value, a list of choices, or a table with ``min``/``max`` (and a
            distribution).
        bounds : cmsim.rig.Range, optional
            The range every value must lie in.
        numeric : bool
            Whether the values are numbers (else labels, left unchecked).

        Returns
        -------
        Distribution
        """
        def check(k, v):
            if not numeric:
                return v
            v = spec_number(k, v)
            if bounds is not None and not bounds.contains(v):
                raise spec_error(k, f"must be {bounds.allowed}, got {v:g}")
            return v

        if isinstance(raw, dict):
            unknown = set(raw) - _DIST_KEYS
            if unknown:
                raise spec_error(f"{key}.{sorted(unknown)[0]}",
                                 f"unknown key; allowed: {sorted(_DIST_KEYS)}")
            kind = raw.get("distribution", "choice" if "values" in raw else "uniform")
            if kind not in DISTRIBUTIONS:
                raise spec_error(f"{key}.distribution",
                                 f"must be one of {list(DISTRIBUTIONS)}, got {kind!r}")
            if kind in ("choice", "constant"):
                vals = raw.get("values")
                if not isinstance(vals, list) or not vals:
                    raise spec_error(f"{key}.values", "must be a non-empty list")
                return cls(kind, values=tuple(check(f"{key}.values[{i}]", v)
                                              for i, v in enumerate(vals)))
            for need in ("min", "max") if kind != "normal" else ("mean", "std"):
                if need not in raw:
                    raise spec_error(f"{key}.{need}", f"is required for a {kind} distribution")
            lo = check(f"{key}.min", raw["min"]) if "min" in raw else (
                bounds.lo if bounds else -math.inf)
            hi = check(f"{key}.max", raw["max"]) if "max" in raw else (
                bounds.hi if bounds else math.inf)
            if not lo <= hi:
                raise spec_error(f"{key}.max", f"must be >= min ({lo:g}), got {hi:g}")
            if kind == "loguniform" and lo <= 0:
                raise spec_error(f"{key}.min", f"must be > 0 for a loguniform distribution, "
                                               f"got {lo:g}")
            if kind == "normal":
                mean = check(f"{key}.mean", raw["mean"])
                std = spec_number(f"{key}.std", raw["std"])
                if std < 0:
                    raise spec_error(f"{key}.std", f"must be >= 0, got {std:g}")
                if not lo <= mean <= hi:
                    raise spec_error(f"{key}.mean", f"must be in [min, max] = [{lo:g}, {hi:g}]")
                return cls(kind, lo, hi, mean, std)
            return cls(kind, lo, hi)
        if isinstance(raw, list):
            if not raw:
                raise spec_error(key, "must not be an empty list")
            return cls("choice", values=tuple(check(f"{key}[{i}]", v) for i, v in enumerate(raw)))
        return cls("constant", values=(check(key, raw),))

    @property
    def is_grid_axis(self):
        """True for a list of values (a grid axis, named in record ids), False otherwise."""
        return self.kind == "choice"

    @property
    def extremes(self):
        """The smallest and largest values it can give (``None`` values left out)."""
        if self.kind in ("choice", "constant"):
            vals = [v for v in self.values if v is not None]
            if not vals:
                return (None, None)
            if isinstance(vals[0], str):
                return tuple(self.values)
            return (min(vals), max(vals))
        return (self.lo, self.hi)

    def draw(self, rng):
        """One value from ``rng`` (a constant draws nothing).

        Parameters
        ----------
        rng : numpy.random.Generator
            The record's generator.
        """
        if self.kind == "constant":
            return self.values[0]
        if self.kind == "choice":
            return self.values[int(rng.integers(len(self.values)))]
        if self.kind == "uniform":
            return float(rng.uniform(self.lo, self.hi))
        if self.kind == "loguniform":
            return float(math.exp(rng.uniform(math.log(self.lo), math.log(self.hi))))
        return float(np.clip(rng.normal(self.mean, self.std), self.lo, self.hi))

    def to_dict(self):
        """JSON-ready form."""
        return {k: list(v) if isinstance(v, tuple) else v
                for k, v in dataclasses.asdict(self).items()
                if not (isinstance(v, float) and math.isnan(v))}
