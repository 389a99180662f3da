"""The record of one simulated or measured run: time, named signals with a schema, metadata.

A :class:`Run` is what :func:`cmsim.dynamics.simulate` returns and what a measurement is
loaded into, so spectra, features, datasets and the discrepancy loop read both the same way.
It is saved as ``.npz`` (arrays ``t``, ``source``, ``meta`` as a JSON string, one array per
signal).

Signal names
------------
Every signal is a 1-D array sampled at ``t``, in SI units except where the name says otherwise
(``dte_um``). :func:`signal_info` maps a name to its quantity, unit, component and direction:

===========================  ==================  ======  ===============  =====================
name                         quantity            unit    component        direction
===========================  ==================  ======  ===============  =====================
``dte``                      transmission_error  rad     ``mesh``         None
``dte_um``                   transmission_error  µm      ``mesh``         ``loa``
``F_<bearing>_<dir>``        force               N       bearing          ``x y loa oloa``
``Fmesh_<j>``                force               N       ``slot<j>``      ``loa``
``Fmesh_total``              force               N       ``mesh``         ``loa``
``x_<node>``, ``y_<node>``   displacement        m       node             ``x``, ``y``
``theta_<node>``             rotation            rad     node             ``theta``
``accel_<bearing>_<dir>``    acceleration        m/s²    bearing          ``x y``
``tacho``                    tacho               V       ``shaft1``       None
===========================  ==================  ======  ===============  =====================

* ``dte`` is θ_1G1 − (Z2/Z1)·θ_2G1 (paper eq. 10) and ``dte_um`` the same along the line of
  action, r_b1·DTE;
* ``F_<bearing>_<dir>`` is the force transmitted to the housing by a bearing (balls + bearing
  damper), bearings ``1b1 1b2 2b1 2b2``; LOA is the direction of the nominal mesh force on
  that shaft's gear, OLOA is LOA turned +90°;
* ``Fmesh_<j>`` is the normal force of the tooth pair in potential-contact slot ``j``
  (0 = the pair entering mesh);
* nodes are ``<shaft><kind><n>``: bearings ``1b1``, gears ``1G1``, disks ``1D1``, the output
  inertia ``2J2``; ``theta_<node>`` is the total rotation in the shaft's sense of motion
  (nominal Ω·t plus the dynamic deviation);
* ``accel_<bearing>_<dir>`` is a housing acceleration at a bearing and ``tacho`` the raw
  once-per-revolution pulse train of the input shaft, as measured (or made by a sensor model).

Frame: y along the line of centres, x normal to it (DESIGN.md, Conventions).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import re
from dataclasses import dataclass, field

import numpy as np

from cmsim._io import atomic_savez
from cmsim.errors import ParameterError, check_choice
from cmsim.rig import OperatingPoint, Rig

__all__ = ["Run", "SignalInfo", "signal_info", "is_measurable", "SOURCES", "SIGNAL_QUANTITIES",
           "MEASURABLE_QUANTITIES"]

#: Where a run's signals come from.
SOURCES = ("simulated", "measured")

#: Physical quantities of :attr:`SignalInfo.quantity`.
SIGNAL_QUANTITIES = ("transmission_error", "force", "displacement", "rotation",
                     "acceleration", "tacho")

#: Quantities a real machine's sensors give (accelerometers on the housings, a once-per-rev
#: tacho); the others (transmission error, bearing and mesh forces, displacements, rotations)
#: exist in the model only, so ML defaults leave them out (:func:`is_measurable`).
MEASURABLE_QUANTITIES = ("acceleration", "tacho")

#: Array names of a saved run that are not signals.
_RESERVED = ("t", "meta", "source")

_NODE = r"\d+[bGDJ]\d+"
_BEARING = r"\d+b\d+"

#: (pattern, quantity, unit, component, direction); ``{c}``/``{d}`` are filled from the
#: pattern's groups ``c`` (component) and ``d`` (direction).
_SCHEMA = (
    (r"dte", "transmission_error", "rad", "mesh", None),
    (r"dte_um", "transmission_error", "µm", "mesh", "loa"),
    (rf"F_(?P<c>{_BEARING})_(?P<d>x|y|loa|oloa)", "force", "N", "{c}", "{d}"),
    (r"Fmesh_(?P<c>\d+)", "force", "N", "slot{c}", "loa"),
    (r"Fmesh_total", "force", "N", "mesh", "loa"),
    (rf"(?P<d>x|y)_(?P<c>{_NODE})", "displacement", "m", "{c}", "{d}"),
    (rf"theta_(?P<c>{_NODE})", "rotation", "rad", "{c}", "theta"),
    (rf"accel_(?P<c>{_BEARING})_(?P<d>x|y)", "acceleration", "m/s²", "{c}", "{d}"),
    (r"tacho", "tacho", "V", "shaft1", None),
)
_COMPILED = tuple((re.compile(p), *rest) for p, *rest in _SCHEMA)


@dataclass(frozen=True)
class SignalInfo:
    """What a run signal is (see the table in :mod:`cmsim.run`).

    Attributes
    ----------
    quantity : str
        One of :data:`SIGNAL_QUANTITIES`.
    unit : str
        Unit of the samples: ``"N"``, ``"m"``, ``"rad"``, ``"µm"``, ``"m/s²"`` or ``"V"``.
    component : str
        Bearing or node name (``"1b1"``, ``"2J2"``), ``"mesh"``, ``"slot<j>"`` or
        ``"shaft1"``.
    direction : str or None
        ``"x"``, ``"y"``, ``"loa"``, ``"oloa"``, ``"theta"``, or None.
    """

    quantity: str
    unit: str
    component: str
    direction: str | None


def signal_info(name):
    """Quantity, unit, component and direction of a signal name.

    Parameters
    ----------
    name : str
        A signal name of the schema in :mod:`cmsim.run`.

    Returns
    -------
    SignalInfo

    Raises
    ------
    ParameterError
        If the name is not in the schema.

    Examples
    --------
    >>> signal_info("F_1b1_loa")
    SignalInfo(quantity='force', unit='N', component='1b1', direction='loa')
    >>> signal_info("dte_um").unit, signal_info("theta_2J2").component
    ('µm', '2J2')
    """
    for pattern, quantity, unit, component, direction in _COMPILED:
        m = pattern.fullmatch(name)
        if m is not None:
            groups = m.groupdict()
            return SignalInfo(quantity, unit, component.format(**groups),
                              None if direction is None else direction.format(**groups))
    raise ParameterError(f"signal name {name!r} is not in the run schema; allowed patterns: "
                         + ", ".join(p for p, *_ in _SCHEMA))


def is_measurable(name):
    """Whether a real machine could measure the signal ``name``: an acceleration or the tacho
    (:data:`MEASURABLE_QUANTITIES`), or a name outside the schema (a calibrated machine's own
    sensor channel, e.g. ``"DE"``). DTE, forces, displacements and rotations are simulated only.

    Parameters
    ----------
    name : str
        A signal or channel name.

    Returns
    -------
    bool

    Examples
    --------
    >>> [is_measurable(n) for n in ("accel_1b1_y", "tacho", "dte_um", "F_1b1_loa", "DE")]
    [True, True, False, False, True]
    """
    try:
        return signal_info(name).quantity in MEASURABLE_QUANTITIES
    except ParameterError:
        return True


@functools.lru_cache(maxsize=16)
def _rig_from_json(text):
    """The :class:`~cmsim.rig.Rig` of a run's ``meta["rig"]`` (as JSON text), parsed once: a
    rig is a value, and reading one field by field costs milliseconds (every record of a
    dataset reads its rig's bearing names)."""
    return Rig.from_dict(json.loads(text))


@dataclass(frozen=True)
class Run:
    """Time histories of one run, simulated or measured.

    Build variants with :meth:`with_signals` and :meth:`with_meta`, which return new runs.

    Attributes
    ----------
    t : ndarray, shape (n_samples,)
        Time, s.
    signals : dict of str to ndarray, each shape (n_samples,)
        Named signals; the names and their units are the schema of :mod:`cmsim.run`.
    meta : dict
        JSON-ready metadata: ``rig`` (:meth:`cmsim.rig.Rig.to_dict`), ``operating_point``
        (the :class:`~cmsim.rig.OperatingPoint` fields), ``fs_hz``, seed, options, version,
        timing. Read the rig and operating point through :attr:`rig` and
        :attr:`operating_point`.
    source : str
        ``"simulated"`` or ``"measured"`` (:data:`SOURCES`).
    """

    t: np.ndarray
    signals: dict
    meta: dict = field(default_factory=dict)
    source: str = "simulated"

    def __post_init__(self):
        check_choice("source", self.source, SOURCES)
        t = np.asarray(self.t)
        if t.ndim != 1:
            raise ParameterError(f"t must be 1-D, got shape {t.shape}")
        for name, value in self.signals.items():
            if name in _RESERVED:
                raise ParameterError(f"{name!r} cannot name a signal (reserved: {_RESERVED})")
            if np.shape(value) != t.shape:
                raise ParameterError(f"signal {name!r} has shape {np.shape(value)}, "
                                     f"t has {t.shape}")

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

    @property
    def rig(self):
        """The :class:`~cmsim.rig.Rig` the run was made on, or None (a record without one)."""
        data = self.meta.get("rig")
        if data is None:
            return None
        try:
            text = json.dumps(data, sort_keys=True)
        except (TypeError, ValueError):           # not plain JSON: read it as it is
            return Rig.from_dict(data)
        return _rig_from_json(text)

    @property
    def operating_point(self):
        """The run's :class:`~cmsim.rig.OperatingPoint`, or None if the meta has none."""
        data = self.meta.get("operating_point")
        if data is None:
            return None
        try:
            return OperatingPoint(**data)
        except TypeError as exc:
            raise ParameterError(f"run meta 'operating_point': {exc}") from None

    def schema(self):
        """:class:`SignalInfo` of every signal, by name (raises for a name not in the schema)."""
        return {name: signal_info(name) for name in self.names}

    def with_signals(self, **arrays):
        """New run with these signals added or replaced (same ``t``, meta and source)."""
        return dataclasses.replace(self, signals={**self.signals, **arrays})

    def with_meta(self, **items):
        """New run with these meta items added or replaced."""
        return dataclasses.replace(self, meta={**self.meta, **items})

    def summary(self):
        """Summary statistics of the run, JSON-ready.

        Returns
        -------
        dict
            ``source``, ``n_samples``, ``fs_hz``, ``duration_s`` (s); from the meta when
            present (else None): ``seed``, ``sim_s``, ``wall_s``, ``realtime_factor``,
            ``compile_s`` (s), ``mesh``, ``mesh_table``; ``dte_mean_rad``, ``dte_rms_rad``,
            ``dte_mean_um``, ``dte_rms_um`` (None without gears); per bearing force signal
            ``F_<bearing>_loa_mean_n`` and ``F_<bearing>_loa_rms_n`` (N); per acceleration
            signal ``<name>_rms_m_s2``. Every ``rms`` is the RMS about the mean (the standard
            deviation), i.e. of the fluctuation.
        """
        out = {"source": self.source, "n_samples": int(self.t.size), "fs_hz": self.fs_hz,
               "duration_s": self.t.size / self.fs_hz}
        for key in ("seed", "sim_s", "wall_s", "realtime_factor", "compile_s", "mesh",
                    "mesh_table"):
            out[key] = self.meta.get(key)
        out.update(dte_mean_rad=None, dte_rms_rad=None, dte_mean_um=None, dte_rms_um=None)
        for name in ("dte", "dte_um"):
            if name in self.signals:
                unit = "rad" if name == "dte" else "um"
                out[f"dte_mean_{unit}"] = float(np.mean(self.signals[name]))
                out[f"dte_rms_{unit}"] = float(np.std(self.signals[name]))
        for name in self.names:
            if name.startswith("F_") and name.endswith("_loa"):
                out[f"{name}_mean_n"] = float(np.mean(self.signals[name]))
                out[f"{name}_rms_n"] = float(np.std(self.signals[name]))
            elif name.startswith("accel_"):
                out[f"{name}_rms_m_s2"] = float(np.std(self.signals[name]))
        return out

    def to_pandas(self):
        """DataFrame indexed by time with one column per signal."""
        import pandas as pd
        return pd.DataFrame(self.signals, index=pd.Index(self.t, name="t"))

    def save(self, path):
        """Write ``t``, ``source``, every signal and ``meta`` (JSON) to ``path`` (atomically)."""
        atomic_savez(path, t=self.t, source=self.source, meta=json.dumps(self.meta),
                     **self.signals)
        return path

    @classmethod
    def load(cls, path):
        """Read a run written by :meth:`save`, or a dataset record (``cmsim dataset``: its
        channels and ``meta`` without ``t``, whose times follow from ``meta["fs_hz"]`` and
        ``meta["t0_s"]``); files without ``source`` are simulated."""
        try:
            z = np.load(path, allow_pickle=False)
        except FileNotFoundError:
            raise ParameterError(f"run file {path} does not exist") from None
        with z:
            if "meta" not in z.files:
                raise ParameterError(f"{path} is not a cmsim run (needs arrays 't' and 'meta')")
            meta = json.loads(str(z["meta"]))
            source = str(z["source"]) if "source" in z.files else "simulated"
            signals = {k: z[k] for k in z.files if k not in _RESERVED}
            if "t" in z.files:
                return cls(z["t"], signals, meta, source)
            if not signals or not isinstance(meta, dict) or not meta.get("fs_hz"):
                raise ParameterError(f"{path} is not a cmsim run (needs arrays 't' and "
                                     f"'meta', or channels and a meta with fs_hz)")
            n = next(iter(signals.values())).shape[0]
            t = float(meta.get("t0_s") or 0.0) + np.arange(n) / float(meta["fs_hz"])
            return cls(t, signals, meta, source)
