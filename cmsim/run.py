"""The result of a simulation: time, named signals and metadata, saved as ``.npz``."""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from cmsim._io import atomic_savez
from cmsim.errors import ParameterError

__all__ = ["Run"]


@dataclass(frozen=True)
class Run:
    """Time histories of one simulation.

    Signal names (all shape ``(n_samples,)``, SI units):

    * ``dte`` — dynamic transmission error θ_1G1 − (Z2/Z1)·θ_2G1, rad (paper eq. 10), and
      ``dte_um`` — the same along the line of action, r_b1·DTE, µm;
    * ``F_<bearing>_<x|y|loa|oloa>`` — force transmitted to the housing by bearing
      ``1b1, 1b2, 2b1, 2b2`` (balls + bearing damper), N; LOA is the direction of the nominal
      mesh force on that shaft's gear, OLOA is LOA turned +90°;
    * ``x_<node>``, ``y_<node>`` — centre displacement of each node, m;
    * ``theta_<node>`` — total rotation of each node in its shaft's sense of motion (nominal
      Ω·t plus the dynamic deviation), rad;
    * ``Fmesh_<j>`` — normal force of the tooth pair in potential-contact slot ``j`` (0 = the
      pair entering mesh), N, and ``Fmesh_total``.

    Attributes
    ----------
    t : ndarray, shape (n_samples,)
        Time, s.
    signals : dict of str to ndarray
        Named signals (see above).
    meta : dict
        Rig, operating point, options, seed, version, timing.
    """

    t: np.ndarray
    signals: dict
    meta: dict = field(default_factory=dict)

    def __getitem__(self, name):
        if name == "t":
            return self.t
        try:
            return self.signals[name]
        except KeyError:
            raise KeyError(f"no signal {name!r}; available: {sorted(self.signals)}") from None

    @property
    def fs_hz(self):
        """Sample rate, Hz."""
        return float(self.meta.get("fs_hz", 1.0 / (self.t[1] - self.t[0])))

    @property
    def names(self):
        """Sorted signal names."""
        return sorted(self.signals)

    def to_pandas(self):
        """DataFrame indexed by time with one column per signal."""
        import pandas as pd
        return pd.DataFrame(self.signals, index=pd.Index(self.t, name="t"))

    def save(self, path):
        """Write ``t``, every signal and ``meta`` (JSON string) to ``path`` (atomically)."""
        atomic_savez(path, t=self.t, meta=json.dumps(self.meta), **self.signals)
        return path

    @classmethod
    def load(cls, path):
        """Read a run written by :meth:`save`."""
        try:
            z = np.load(path, allow_pickle=False)
        except FileNotFoundError:
            raise ParameterError(f"run file {path} does not exist") from None
        with z:
            if "t" not in z.files or "meta" not in z.files:
                raise ParameterError(f"{path} is not a cmsim run (needs arrays 't' and 'meta')")
            meta = json.loads(str(z["meta"]))
            signals = {k: z[k] for k in z.files if k not in ("t", "meta")}
            return cls(z["t"], signals, meta)
