"""The model of a measured record from its metadata: rig, operating point, characteristic lines.

* :func:`model_rig` — the rig the model simulates for a record: with gear tooth counts, the
  paper rig with those counts and the documented bearings at their shafts' nodes (the
  paper's 209 where none is documented); else a rotor of :data:`DEFAULT_ROTOR_MASS_KG` on
  the documented bearings (bearing ``1b1`` = the one the sensor sits near). What was
  assumed is returned as notes.
* :func:`documented_frequencies` — the characteristic frequencies of the documented geometry
  at a speed (bearing keys as in the metadata): what a diagnosis is given.
* :func:`model_operating_point` — the operating point the model runs at: the documented
  radial load plus, on a bearing rig, the assumed rotor's weight; on a gear rig the
  documented torque, else one assumed from ``load_percent``.
"""

from __future__ import annotations

import math
from dataclasses import replace

from cmsim.errors import ParameterError, check_range
from cmsim.frequencies import RigFrequencies, bearing_frequencies
from cmsim.measured.schema import STANDARD_GRAVITY_M_S2, documented_radial_load_n
from cmsim.rig import OperatingPoint, Rig, RollingBearing, Rotor

__all__ = ["model_rig", "documented_frequencies", "documented_geometry", "BEARING_NUMBERS",
           "model_operating_point", "NO_GEOMETRY", "documented_operating_point",
           "DEFAULT_ROTOR_MASS_KG", "DEFAULT_CLEARANCE_M"]

#: Rotor mass assumed for a bearing rig whose rotor is not documented, kg.
DEFAULT_ROTOR_MASS_KG = 10.0

#: Radial clearance assumed for a documented bearing (not documented in the records), m.
DEFAULT_CLEARANCE_M = 5e-6


#: The numbers of a documented bearing's geometry (all three, or none: undocumented).
BEARING_NUMBERS = ("n_balls", "ball_diameter_mm", "pitch_diameter_mm")


def _whole(value, where):
    """A count written as a JSON number or a number in quotes (``25``, ``25.0``, ``"25"``),
    as an int >= 1; anything else one error naming where it is."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if isinstance(value, bool) or not (v >= 1 and v == int(v)):
        raise ParameterError(f"metadata.json {where} must be a whole number >= 1, got "
                             f"{value!r}", param="geometry", allowed="a whole number >= 1")
    return int(v)


def _shaft(value, where):
    """``input`` or ``output`` from a bearing's ``shaft`` (default ``input``): a text that
    names one of them and not the other (``"input shaft (pinion)"``) is that one; any other
    text is refused — a bearing put on the wrong shaft turns at the wrong rate."""
    if value is None:
        return "input"
    text = str(value).lower()
    found = [w for w in ("input", "output") if w in text]
    if len(found) != 1:
        raise ParameterError(f"metadata.json {where} {value!r}: say which shaft the bearing "
                             f"is on, input or output (the gear stage's input_teeth or "
                             f"output_teeth side)", param="geometry", allowed="input, output")
    return found[0]


def documented_geometry(geometry):
    """The ``geometry`` of ``metadata.json`` as the model reads it, and what was assumed.

    Tooth counts and ball counts may be written in quotes (``"25"``); a bearing whose
    ball count and diameters are all ``null`` (known by its designation only) is
    undocumented, as one not listed is; one that gives some of them and not all is
    refused, naming it; a bearing's ``shaft`` is ``input`` or ``output`` (a text naming
    one of them, ``"input shaft (pinion)"``, is that one).

    Parameters
    ----------
    geometry : dict or None

    Returns
    -------
    geometry : dict
        ``gears`` (stages with both tooth counts, as ints) and ``bearings`` (each with its
        three numbers and its ``shaft``).
    notes : list of str
    """
    geometry = geometry or {}
    gears = []
    for i, stage in enumerate(geometry.get("gears") or []):
        if not isinstance(stage, dict) or stage.get("input_teeth") is None \
                or stage.get("output_teeth") is None:
            continue
        gears.append({**stage, **{k: _whole(stage[k], f"geometry.gears[{i}].{k}")
                                  for k in ("input_teeth", "output_teeth")}})
    bearings, notes = {}, []
    for key, b in (geometry.get("bearings") or {}).items():
        b = b if isinstance(b, dict) else {}
        given = [k for k in BEARING_NUMBERS if b.get(k) is not None]
        if not given:
            notes.append(f"bearing {key}: its ball count and diameters are not documented"
                         + (f" ({b['model']})" if b.get("model") else "")
                         + ": read as undocumented")
            continue
        where = f"geometry.bearings.{key}"
        if len(given) < len(BEARING_NUMBERS):
            missing = [k for k in BEARING_NUMBERS if k not in given]
            raise ParameterError(f"metadata.json {where} gives {', '.join(given)} but not "
                                 f"{', '.join(missing)}: give all three (the bearing's "
                                 f"catalogue values) or null them all", param="geometry",
                                 allowed=", ".join(BEARING_NUMBERS))
        bearings[key] = {**b, "n_balls": _whole(b["n_balls"], f"{where}.n_balls"),
                         "shaft": _shaft(b.get("shaft"), f"{where}.shaft")}
    return {**geometry, "gears": gears, "bearings": bearings}, notes


def _bearing(geom, like=None):
    """The model bearing of a documented geometry; with ``like``, that bearing's clearance,
    masses and damping (a gear rig's undocumented properties), else the defaults. A
    documented contact angle above 0 (an angular-contact bearing) sets the cage kinematics'
    angle; 0, a deep-groove bearing's nominal, leaves the operating angle its clearance
    gives, as the model computes it."""
    try:
        n = int(geom["n_balls"])
        d = float(geom["ball_diameter_mm"]) * 1e-3
        pd_ = float(geom["pitch_diameter_mm"]) * 1e-3
        angle = float(geom.get("contact_angle_deg") or 0.0)
    except (KeyError, TypeError, ValueError):
        raise ParameterError(f"bearing geometry needs n_balls, ball_diameter_mm and "
                             f"pitch_diameter_mm, got {geom!r}", param="geometry.bearings")
    angle = math.radians(check_range("geometry.bearings contact_angle_deg", angle, 0.0, 45.0,
                                     unit="deg (a radial ball bearing's model)"))
    if like is None:
        return RollingBearing.from_pitch(n, d, pd_, clearance_m=DEFAULT_CLEARANCE_M,
                                         contact_angle_rad=angle or None)
    g = RollingBearing.from_pitch(n, d, pd_)
    return replace(like, contact_angle_rad=angle or like.contact_angle_rad,
                   **{k: getattr(g, k) for k in (
                       "n_balls", "ball_diameter_m", "inner_raceway_diameter_m",
                       "outer_raceway_diameter_m", "inner_groove_radius_m",
                       "outer_groove_radius_m")})


def _gear_rig(stage, bearings, near):
    """Paper rig with the documented tooth counts (other gear data undocumented) and the
    documented bearings: on each shaft (``shaft``: ``input``, the default, or ``output``)
    in the metadata's order, the sensor's first, at nodes b1 then b2; a node with no
    documented bearing keeps the paper's. Returns the rig and node → metadata key."""
    base = Rig.paper_2016()
    g = base.gears
    z1, z2 = int(stage["input_teeth"]), int(stage["output_teeth"])
    pair = replace(g, driving=replace(g.driving, n_teeth=z1),
                   driven=replace(g.driven, n_teeth=z2))
    keys = sorted(bearings, key=lambda k: k != near)
    shafts, names = [], {}
    for i, (shaft, which) in enumerate(zip(base.shafts, ("input", "output"))):
        on = [k for k in keys if bearings[k]["shaft"] == which]
        if len(on) > 2:
            raise ParameterError(f"metadata.json documents {len(on)} bearings on the {which} "
                                 f"shaft ({', '.join(on)}); a gear rig's shaft has two",
                                 param="geometry.bearings", allowed="at most 2 per shaft")
        nodes = {}
        for node, key in zip(("bearing_1", "bearing_2"), on):
            nodes[node] = _bearing(bearings[key], like=getattr(shaft, node))
            names[f"{i + 1}b{node[-1]}"] = key
        shafts.append(replace(shaft, **nodes))
    return replace(base, gears=pair, shafts=tuple(shafts)), names


#: What to do when nothing states a recording's geometry (the start of the message).
NO_GEOMETRY = ("the recording has no geometry: give --rig FILE.toml (a rig TOML, see "
               "docs/guide/measured.md: cmsim.rig.preset('cwru_6205').save(...) or "
               "Rig.save) or a metadata.json with geometry")


def model_rig(geometry, near=None):
    """The model rig of a record's documented geometry.

    Parameters
    ----------
    geometry : dict or None
        ``geometry`` of ``metadata.json`` (``gears``, ``bearings``).
    near : str, optional
        Bearing key the compared sensor sits near (becomes ``1b1`` of a bearing rig).

    Returns
    -------
    rig : cmsim.rig.Rig
    components : dict of str to str
        Model component → dataset name (``{"1b1": "drive_end", "1b2": "fan_end"}``).
    notes : list of str
        What was assumed.

    Raises
    ------
    ParameterError
        Neither bearing geometry nor gear tooth counts.
    """
    geometry, notes = documented_geometry(geometry)
    bearings = geometry["bearings"]
    gears = geometry["gears"]
    if gears:
        rig, names = _gear_rig(gears[0], bearings, near)
        kept = [n for n in rig.bearing_names if n not in names]
        notes.append("gear data beyond tooth counts undocumented: the paper rig's gears with "
                     "the documented tooth counts")
        if kept:
            notes.append(f"bearing{'s' if len(kept) > 1 else ''} {', '.join(kept)} "
                         "undocumented: the paper rig's 209")
        return rig, {"1G1": "input gear", "2G1": "output gear", **names}, notes
    if not bearings:
        raise ParameterError(f"{NO_GEOMETRY}; metadata.json states neither bearing geometry "
                             f"nor gear tooth counts", param="geometry",
                             allowed="geometry.bearings or geometry.gears")
    keys = list(bearings)
    first = near if near in bearings else keys[0]
    other = next((k for k in keys if k != first), first)
    rig = Rig.rotor_on_bearings(_bearing(bearings[first]),
                                Rotor(mass_kg=DEFAULT_ROTOR_MASS_KG, inertia_kg_m2=0.02),
                                bearing_2=_bearing(bearings[other]))
    return rig, {"1b1": first, "1b2": other}, notes + [
        f"rotor {DEFAULT_ROTOR_MASS_KG:g} kg assumed (undocumented)"]


def documented_frequencies(geometry, shaft_hz):
    """Characteristic frequencies of the documented geometry at an input-shaft rate.

    Parameters
    ----------
    geometry : dict or None
        ``geometry`` of ``metadata.json``.
    shaft_hz : float
        Input-shaft rate, Hz.

    Returns
    -------
    cmsim.frequencies.RigFrequencies
        Shaft rates and GMF of the first stage with tooth counts; bearings by their metadata
        keys (a bearing on the ``output`` shaft turns at the output rate).
    """
    geometry = documented_geometry(geometry)[0]
    gears = geometry["gears"]
    fr2 = gmf = None
    if gears:
        z1, z2 = gears[0]["input_teeth"], gears[0]["output_teeth"]
        fr2, gmf = shaft_hz * z1 / z2, shaft_hz * z1
    out = {}
    for name, b in geometry["bearings"].items():
        rate = fr2 if b.get("shaft") == "output" and fr2 is not None else shaft_hz
        out[name] = bearing_frequencies(
            rate, int(b["n_balls"]), 1e-3 * float(b["ball_diameter_mm"]),
            1e-3 * float(b["pitch_diameter_mm"]),
            math.radians(float(b.get("contact_angle_deg") or 0.0)))
    return RigFrequencies(fr1_hz=shaft_hz, fr2_hz=fr2, gmf_hz=gmf, bearings=out)


def documented_operating_point(entry, speed_rpm):
    """The documented operating point: speed, torque (0 when undocumented), radial load.

    Parameters
    ----------
    entry : dict
        Readable keys of the recording entry.
    speed_rpm : float
        Input-shaft speed (documented or inferred), rpm.

    Returns
    -------
    cmsim.rig.OperatingPoint
    """
    return OperatingPoint(speed_rpm=float(speed_rpm),
                          torque_nm=float(entry.get("torque_nm") or 0.0),
                          radial_load_n=documented_radial_load_n(entry))


def model_operating_point(entry, rig, speed_rpm, notes):
    """The operating point the model of a record runs at.

    Parameters
    ----------
    entry : dict
        Readable keys of the recording entry.
    rig : cmsim.rig.Rig
        Model rig.
    speed_rpm : float
        Input-shaft speed (documented or inferred), rpm.
    notes : list of str
        Assumptions made here are appended.

    Returns
    -------
    cmsim.rig.OperatingPoint
        Radial load: the documented one plus, without gears, the assumed rotor's weight,
        pointing down; torque: documented, else 5 + 0.4·``load_percent`` N·m (20 N·m without
        it) on a gear rig.
    """
    radial = documented_radial_load_n(entry)
    torque = 0.0
    if rig.gears is None:
        radial += DEFAULT_ROTOR_MASS_KG * STANDARD_GRAVITY_M_S2
    elif entry.get("torque_nm") is not None:
        torque = float(entry["torque_nm"])
    else:
        pct = entry.get("load_percent")
        torque = 20.0 if pct is None else 5.0 + 0.4 * float(pct)
        notes.append(f"output torque {torque:g} N m assumed (no torque documented)"
                     if pct is None else
                     f"output torque {torque:g} N m assumed from load_percent={pct:g} "
                     "(brake capacity undocumented)")
    return OperatingPoint(speed_rpm=float(speed_rpm), torque_nm=torque, radial_load_n=radial,
                          radial_load_angle_rad=-math.pi / 2)
