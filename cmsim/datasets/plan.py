"""What a spec draws for one record (:class:`RecordPlan`) and the fault types it draws from.

A :class:`~cmsim.datasets.spec.DatasetSpec` turns a record index into a :class:`RecordPlan`
(its settings, nuisances, labelled fault and simulation seed) before anything is simulated;
the plan is the record's answer key. :class:`FaultChoice` is one entry of the spec's
``[[faults.types]]``: a catalogue fault type, the components it may hit, its fields as
:class:`~cmsim.datasets.distribution.Distribution` s and its weight. :data:`NUISANCES` are the
nuisance settings a record draws, in the order it draws them.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from cmsim.datasets.distribution import Distribution, spec_error, spec_number
from cmsim.errors import ParameterError
from cmsim.faults import FAULT_TYPES, RollingSlip, SpeedFluctuation, check_faults
from cmsim.rig import RANGES, Range

__all__ = ["RecordPlan", "FaultChoice", "SEVERITY_FIELDS", "NUISANCES", "PER_MODE",
           "fault_answer_key"]

#: Main size of each fault type: the record's ``fault_severity`` (SI).
SEVERITY_FIELDS = {"outer_race": "size_m", "inner_race": "size_m", "ball": "size_m",
                   "wear": "clearance_growth_m", "off_size_ball": "diameter_excess_m",
                   "tooth_crack": "depth_m", "tooth_spall": "width_m",
                   "tooth_breakage": "lost_height_m", "eccentricity": "amplitude_m",
                   "profile_error": "wear_depth_m", "speed_fluctuation": "relative_amplitude",
                   "torque_ripple": "relative_amplitude", "rolling_slip": "cage_speed_rms"}

#: Nuisances a record draws, in this order, with their ranges: the sensor noise and the cage
#: slip are :data:`cmsim.rig.RANGES` entries; a speed wobble (relative amplitude and
#: frequency of a speed fluctuation) and the housing modes are drawn only here.
NUISANCES = {"sensor_noise_m_s2": RANGES["sensor_noise_m_s2"],
             "speed_wobble": Range(0.0, 0.1),
             "speed_wobble_hz": Range(0.0, 1.0e4, unit="Hz"),
             "slip": RANGES["cage_slip"],
             "housing_mode_hz": Range(1.0, 1.0e6, unit="Hz"),
             "housing_damping": Range(1.0e-4, 0.5)}

#: Nuisances drawn once per housing mode (columns ``<name>_1`` .. ``<name>_n``), and only
#: when the spec gives them: domain randomisation of the transfer path (the
#: :class:`~cmsim.rig.HousingPath` field each one sets).
PER_MODE = {"housing_mode_hz": "natural_frequencies_hz", "housing_damping": "damping_ratios"}


@dataclass(frozen=True)
class FaultChoice:
    """One entry of ``[[faults.types]]``: a fault type, its components, fields and weight.

    Attributes
    ----------
    type : str
        Catalogue name (:data:`cmsim.faults.FAULT_TYPES`).
    component_key : str
        ``"bearing"``, ``"gear"`` or ``""`` (the field that names the component).
    components : tuple
        Bearing names or gear numbers, one drawn per record.
    fields : tuple of (str, Distribution)
        The fault's other fields.
    weight : float
        Relative weight among the spec's fault types (> 0).
    """

    type: str
    component_key: str
    components: tuple
    fields: tuple
    weight: float

    @classmethod
    def parse(cls, key, table, rig):
        """Parse one ``[[faults.types]]`` table; both ends of every range must make a valid
        fault on ``rig``.

        Parameters
        ----------
        key : str
            Its spec key (``"faults.types[0]"``), named in errors.
        table : dict
            The parsed TOML table.
        rig : cmsim.rig.Rig
            The spec's rig.

        Returns
        -------
        FaultChoice
        """
        if not isinstance(table, dict):
            raise spec_error(key, "must be a table")
        kind = table.get("type")
        if kind not in FAULT_TYPES:
            raise spec_error(f"{key}.type", f"must be one of {sorted(FAULT_TYPES)}, got {kind!r}")
        fault_cls = FAULT_TYPES[kind]
        names = {f.name for f in dataclasses.fields(fault_cls)}
        comp_key = "bearing" if "bearing" in names else "gear" if "gear" in names else ""
        components = ()
        if comp_key:
            components = _components(key, comp_key, table.get(comp_key), rig)
        weight = spec_number(f"{key}.weight", table.get("weight", 1.0))
        if weight <= 0:
            raise spec_error(f"{key}.weight", f"must be > 0, got {weight:g}")
        fields = []
        for name, raw in table.items():
            if name in ("type", "weight", comp_key):
                continue
            if name not in names:
                raise spec_error(f"{key}.{name}", f"unknown field of {kind}; allowed: "
                                                  f"{sorted(names - {comp_key})}")
            fields.append((name, Distribution.parse(f"{key}.{name}", raw)))
        severity = SEVERITY_FIELDS.get(kind)
        if severity in names and severity not in dict(fields):
            raise spec_error(f"{key}.{severity}", f"the severity of {kind} is required (a "
                                                  f"value or a range)")
        for pick in (0, -1):
            kw = {n: d.extremes[pick] for n, d in fields}
            if comp_key:
                kw[comp_key] = components[0]
            try:
                check_faults(rig, [fault_cls(**kw)])
            except ParameterError as exc:
                raise spec_error(f"{key}.{getattr(exc, 'param', None) or severity}",
                                 f"{exc} (at the {'lower' if pick == 0 else 'upper'} end of "
                                 f"the range)") from None
            except TypeError as exc:
                raise spec_error(key, str(exc)) from None
        return cls(kind, comp_key, components, tuple(fields), weight)

    def to_dict(self):
        """JSON-ready form."""
        return {"type": self.type, "component_key": self.component_key,
                "components": list(self.components), "weight": self.weight,
                "fields": {k: d.to_dict() for k, d in self.fields}}


def _components(key, comp_key, raw, rig):
    if raw is None:
        raw = list(rig.bearing_names) if comp_key == "bearing" else [1]
    raw = raw if isinstance(raw, list) else [raw]
    if not raw:
        raise spec_error(f"{key}.{comp_key}", "must not be empty")
    for i, c in enumerate(raw):
        if comp_key == "bearing" and c not in rig.bearing_names:
            raise spec_error(f"{key}.bearing[{i}]", f"unknown bearing {c!r}; this rig has "
                                                    f"{list(rig.bearing_names)}")
        if comp_key == "gear" and (rig.gears is None or c not in (1, 2)):
            raise spec_error(f"{key}.gear[{i}]", "must be 1 or 2 on a rig with gears"
                                                 if rig.gears is not None else
                                                 "this rig has no gears")
    return tuple(raw)


@dataclass(frozen=True)
class RecordPlan:
    """Everything a spec draws for one record, before it is simulated (its answer key).

    Attributes
    ----------
    index : int
        Record number (0 ..).
    record_id : str
        File stem and manifest key: ``"000042"`` (random sampling) or the index and the
        record's grid values, ``"003_n1000rpm_T40Nm"`` (grid sampling; ``_r<k>`` for repeat
        k when the spec repeats its grid points).
    sim_seed : int
        Seed of the simulation (cage phases, slip) and of the sensor noise.
    params : dict
        Drawn parameters, one flat column each: every setting of the spec (``speed_rpm``,
        ``torque_nm``, ``clearance_m``, a dotted rig field ...), ``runup``,
        ``end_speed_rpm``, ``sensor_noise_m_s2``, ``speed_wobble``, ``speed_wobble_hz``,
        ``slip`` (and ``housing_mode_hz_<k>``, ``housing_damping_<k>`` when drawn).
    fault : Fault or None
        The labelled fault: the one drawn from the spec's fault types, else the first of the
        faults every record carries, else None (healthy).
    faults : tuple of Fault
        Every fault built into the record's model: the spec's fixed faults, the drawn one,
        then the nuisances' speed wobble and rolling slip.
    repeat : int
        Repeat number of the record's grid point (0 for random sampling).
    """

    index: int
    record_id: str
    sim_seed: int
    params: dict
    fault: object
    faults: tuple = ()
    repeat: int = 0

    @property
    def fault_label(self):
        """``"healthy"`` or the labelled fault's type."""
        return fault_answer_key(self.fault)[0]

    @property
    def fault_component(self):
        """Bearing name, ``"G<k>"`` for a gear, or ``""``."""
        return fault_answer_key(self.fault)[1]

    @property
    def fault_severity(self):
        """The labelled fault's main size (SI, :data:`SEVERITY_FIELDS`), NaN when healthy."""
        return fault_answer_key(self.fault)[2]


def fault_answer_key(fault):
    """The answer key of a labelled fault: its label, component and severity.

    Parameters
    ----------
    fault : Fault or None
        A catalogue fault (:mod:`cmsim.faults`); None for a healthy record.

    Returns
    -------
    label : str
        ``"healthy"`` or the fault's type.
    component : str
        Bearing name, ``"G<k>"`` for a gear, or ``""``.
    severity : float
        The fault's main size (SI, :data:`SEVERITY_FIELDS`), NaN when healthy.
    """
    if fault is None:
        return "healthy", "", math.nan
    if hasattr(fault, "bearing"):
        component = str(fault.bearing)
    elif hasattr(fault, "gear"):
        component = f"G{fault.gear}"
    else:
        component = ""
    return fault.name, component, float(getattr(fault, SEVERITY_FIELDS.get(fault.name, ""),
                                                math.nan))


def nuisance_faults(params):
    """Speed wobble and rolling slip of a record's ``params`` as catalogue faults (not labels).

    Parameters
    ----------
    params : dict
        A :attr:`RecordPlan.params`.

    Returns
    -------
    list of Fault
    """
    out = []
    if params["speed_wobble"] > 0:
        out.append(SpeedFluctuation(relative_amplitude=params["speed_wobble"],
                                    frequency_hz=params["speed_wobble_hz"]))
    if params["slip"] > 0:
        out.append(RollingSlip(cage_speed_rms=params["slip"]))
    return out
