"""A machine's signature library: what each cause, at each size, does to the features of the
machine's own healthy baseline, as the model predicts it — computed once at calibration
(:func:`cmsim.discrepancy.signatures.build_library`), stored in the machine file, read by
every comparison against the machine.

The library holds

* the **reference**: each feature's mean over the baseline's segments, its segment-to-segment
  spread, and two run-to-run spreads of the model beyond the spread within one record: the
  **realisation** spread (another healthy run laid on the baseline, or through the machine's
  twin with its background drawn afresh, lines' phases included: a feature that hangs on
  how a mesh's sidebands are phased swings with them, and so it does under any change the
  library predicts less well — the χ² reads it), and the **run spread** (the same runs, the
  twin's background lines as the machine's own: cage phases and slip alone — what a record
  of a healthy machine differs from its baseline by, which the gate of a family that stands
  out reads);
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

from cmsim.errors import ParameterError, check_range

__all__ = ["SignatureLibrary", "SignatureEntry", "LIBRARY_FORMAT_VERSION"]

#: Version of the library's table in a machine file (2: the run spread's row after the
#: realisation's; a version-1 table is read with its realisation spread as the run spread).
LIBRARY_FORMAT_VERSION = 2


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
    run_spread : numpy.ndarray or None, shape (n_features,)
        The model's run-to-run spread with the machine's own background lines (module
        docstring); None: the realisation spread.
    n_sizes : int or None
        Sizes of a cause's grid the library was built with (those with a denser or a fixed
        grid aside); None in a file written before it was kept.
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
    run_spread: np.ndarray | None = None
    n_sizes: int | None = None

    def __post_init__(self):
        m = len(self.names)
        if self.run_spread is None:
            object.__setattr__(self, "run_spread", self.realisation)
        for name in ("mean", "spread", "realisation", "run_spread"):
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
        rows = np.vstack([self.mean, self.spread, self.realisation, self.run_spread]
                         + [e.features for e in self.entries])
        return {"format_version": LIBRARY_FORMAT_VERSION, "names": list(self.names),
                "segment_s": self.segment_s, "segments": self.segments,
                "speed_rpm": self.speed_rpm, "torque_nm": self.torque_nm,
                "radial_load_n": self.radial_load_n, "seed": self.seed,
                **({} if self.n_sizes is None else {"n_sizes": self.n_sizes}),
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
        version = data.get("format_version")
        if version not in (1, LIBRARY_FORMAT_VERSION):
            raise ParameterError(f"signature library format_version "
                                 f"{data.get('format_version')!r} is not supported (this cmsim "
                                 f"reads 1-{LIBRARY_FORMAT_VERSION}); run cmsim calibrate again",
                                 param="machine")
        check_range('[library] "segment_s"', data["segment_s"], 0.0, 60.0, lo_open=True)
        check_range('[library] "segments"', data["segments"], 1, 100_000)
        if data.get("n_sizes") is not None:
            check_range('[library] "n_sizes"', data["n_sizes"], 1, 1000)
        names = tuple(data["names"])
        rows = _unpack(data["tables_float32_zlib_base64"], (int(data["rows"]), len(names)))
        entries, i = [], (3 if version == 1 else 4)
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
                   run_spread=rows[2] if version == 1 else rows[3],
                   entries=tuple(entries), segment_s=float(data["segment_s"]),
                   segments=int(data["segments"]), speed_rpm=float(data["speed_rpm"]),
                   torque_nm=float(data["torque_nm"]),
                   radial_load_n=float(data["radial_load_n"]), seed=int(data["seed"]),
                   n_sizes=None if data.get("n_sizes") is None else int(data["n_sizes"]))
