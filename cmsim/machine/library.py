"""A machine's signature library: what each cause, at each size, does to the features of the
machine's own healthy baseline, as the model predicts it — computed once at calibration
(:func:`cmsim.discrepancy.signatures.build_library`), stored in the machine file, read by
every comparison against the machine.

The library holds

* the **reference**: each feature's mean over the baseline's segments, its segment-to-segment
  spread, and its realisation spread (how far another healthy run of the model moves it
  through the baseline: cage phases, slip — what one record of a healthy machine differs
  from another by beyond the spread within one);
* one **entry** per cause, component and nuisance variant (the load zone of a bearing
  defect's model: its clearance, its load; the path's gain where a change rings the
  structure; the load modulation a rotating force swings against its line): the cause's
  parameter values (a grid over its
  bounds) and, per value, the mean of each feature over the baseline's segments with the
  cause's change laid on them (:func:`cmsim.machine.change.apply_change`).
"""

from __future__ import annotations

import base64
import math
import zlib
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError

__all__ = ["SignatureLibrary", "SignatureEntry", "LIBRARY_FORMAT_VERSION"]

#: Version of the library's table in a machine file.
LIBRARY_FORMAT_VERSION = 1


def _pack(a):
    a = np.ascontiguousarray(np.asarray(a, dtype="<f4"))
    return base64.b64encode(zlib.compress(a.tobytes(), 6)).decode("ascii")


def _unpack(text, shape):
    try:
        raw = zlib.decompress(base64.b64decode(text, validate=True))
    except (ValueError, zlib.error) as exc:
        raise ParameterError(f"the signature library is damaged ({exc})",
                             param="machine") from None
    a = np.frombuffer(raw, dtype="<f4").astype(float)
    if a.size != math.prod(shape):
        raise ParameterError("the signature library is damaged (a table of the wrong size)",
                             param="machine")
    return a.reshape(shape)


@dataclass(frozen=True, eq=False)
class SignatureEntry:
    """What one cause on one component does to the baseline's features, over its sizes.

    Attributes
    ----------
    cause : str
        Catalogue name (:data:`cmsim.discrepancy.CAUSES`).
    component : str or None
        Model component it sits on (a bearing or gear key; None rig-wide).
    variant : str
        The model's nuisance variant (``"documented"``; ``"clearance 0 um"`` ...).
    parameter : str
        The parameter the values are of (SI unit in its name).
    values : tuple of float
        The parameter's values, increasing.
    features : numpy.ndarray, shape (len(values), n_features)
        Mean of each feature of the library's ``names`` at each value (NaN where unread).
    """

    cause: str
    component: str | None
    variant: str
    parameter: str
    values: tuple
    features: np.ndarray


@dataclass(frozen=True, eq=False)
class SignatureLibrary:
    """The signature library of a machine (module docstring).

    Attributes
    ----------
    names : tuple of str
        Feature names, the columns of every table.
    mean, spread, realisation : numpy.ndarray, shape (n_features,)
        The baseline's mean, its segment-to-segment spread and the model's realisation
        spread through the baseline (NaN where unread).
    entries : tuple of SignatureEntry
    segment_s : float
        Segment length the features are read on, s.
    segments : int
        Baseline segments the means are taken over.
    speed_rpm, torque_nm, radial_load_n : float
        Operating point the library was computed at (the machine's).
    seed : int
        Seed of the model runs.
    """

    names: tuple
    mean: np.ndarray
    spread: np.ndarray
    realisation: np.ndarray
    entries: tuple
    segment_s: float
    segments: int
    speed_rpm: float
    torque_nm: float
    radial_load_n: float
    seed: int = 0

    def __post_init__(self):
        m = len(self.names)
        for name in ("mean", "spread", "realisation"):
            v = np.asarray(getattr(self, name), dtype=float)
            if v.shape != (m,):
                raise ParameterError(f"library {name} has shape {v.shape}, expected ({m},)",
                                     param="machine")
            object.__setattr__(self, name, v)
        for e in self.entries:
            if np.shape(e.features) != (len(e.values), m):
                raise ParameterError(f"library entry {e.cause} has a table of shape "
                                     f"{np.shape(e.features)}", param="machine")
        object.__setattr__(self, "names", tuple(self.names))
        object.__setattr__(self, "entries", tuple(self.entries))

    def column(self, name):
        """Index of feature ``name``."""
        return self.names.index(name)

    def to_dict(self):
        """Plain dict for the machine file: an index of the entries (readable) and every
        table as float32, zlib-compressed, base64."""
        rows = np.vstack([self.mean, self.spread, self.realisation]
                         + [e.features for e in self.entries])
        return {"format_version": LIBRARY_FORMAT_VERSION, "names": list(self.names),
                "segment_s": self.segment_s, "segments": self.segments,
                "speed_rpm": self.speed_rpm, "torque_nm": self.torque_nm,
                "radial_load_n": self.radial_load_n, "seed": self.seed,
                "entries": [{"cause": e.cause, "component": e.component or "",
                             "variant": e.variant, "parameter": e.parameter,
                             "values": [float(v) for v in e.values]} for e in self.entries],
                "rows": int(rows.shape[0]), "tables_float32_zlib_base64": _pack(rows)}

    @classmethod
    def from_dict(cls, data):
        """The library of :meth:`to_dict` output.

        Parameters
        ----------
        data : dict
            The machine file's ``[library]`` table.
        """
        if data.get("format_version") != LIBRARY_FORMAT_VERSION:
            raise ParameterError(f"signature library format_version "
                                 f"{data.get('format_version')!r} is not supported (this cmsim "
                                 f"reads {LIBRARY_FORMAT_VERSION}); run cmsim calibrate again",
                                 param="machine")
        names = tuple(data["names"])
        rows = _unpack(data["tables_float32_zlib_base64"], (int(data["rows"]), len(names)))
        entries, i = [], 3
        for e in data["entries"]:
            k = len(e["values"])
            entries.append(SignatureEntry(str(e["cause"]), e["component"] or None,
                                          str(e["variant"]), str(e["parameter"]),
                                          tuple(float(v) for v in e["values"]), rows[i:i + k]))
            i += k
        if i != rows.shape[0]:
            raise ParameterError("the signature library is damaged (its index and tables "
                                 "disagree)", param="machine")
        return cls(names=names, mean=rows[0], spread=rows[1], realisation=rows[2],
                   entries=tuple(entries), segment_s=float(data["segment_s"]),
                   segments=int(data["segments"]), speed_rpm=float(data["speed_rpm"]),
                   torque_nm=float(data["torque_nm"]),
                   radial_load_n=float(data["radial_load_n"]), seed=int(data["seed"]))
