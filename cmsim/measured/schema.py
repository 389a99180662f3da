"""The ``metadata.json`` schema of measured records: what the pipeline reads, what it never reads.

A folder of measured records holds one ``metadata.json`` (the schema of
``../shared/datasets/README.md``) and one signal file per recording. The folder keys
:data:`FOLDER_KEYS` and, of each ``recordings[]`` entry, the keys :data:`RECORDING_KEYS` are
all the pipeline reads. Everything else of an entry — the answer key ``condition``,
``fault``, every ``fault_*`` field, expected defect frequencies, provenance — and the file
name never reach a diagnosis or a comparison (the file name only locates its entry).
:func:`answer_key` reads the answer key for scoring only (the diagnostics harness and the
benchmarks).

Unit constants are defined here once: :data:`LBF_N` (pound-force), :data:`INCH_M` (inch) and
:data:`STANDARD_GRAVITY_M_S2` (the ``g`` of an accelerometer's unit).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from cmsim.errors import ParameterError
from cmsim.rig import RANGES

__all__ = ["RECORDING_KEYS", "NUMERIC_KEYS", "FOLDER_KEYS", "ANSWER_KEYS", "LBF_N", "INCH_M",
           "STANDARD_GRAVITY_M_S2", "ACCELERATION_UNITS", "read_metadata", "recording_entry",
           "is_answer_key", "answer_key", "label_of", "documented_speed_rpm",
           "documented_radial_load_n", "unit_scale_of", "rig_geometry",
           "documented_speed", "SPEED_KEYS", "TORQUE_KEYS", "RADIAL_KEYS", "undocumented_load",
           "checked_unit", "OTHER_UNITS", "VELOCITY_UNITS", "UNIT_SPELLINGS",
           "DISPLACEMENT_UNITS", "UNKNOWN_UNIT", "known_units", "unit_kind"]

#: Keys of a ``recordings[]`` entry the pipeline reads; everything else is ignored.
RECORDING_KEYS = ("file", "n_samples", "fs_hz", "shaft_speed_rpm", "shaft_speed_hz",
                  "shaft_speed_rpm_nominal", "shaft_speed_hz_nominal", "torque_nm",
                  "motor_load_hp", "radial_load_lbs", "radial_load_n", "load_percent",
                  "channels", "segment", "calibration")

#: Numeric keys of a recording (and the folder's ``fs_hz``) → the name of their range in
#: :data:`cmsim.rig.RANGES`; ``null`` means undocumented, anything else must be in range.
NUMERIC_KEYS = {"fs_hz": "record_fs_hz", "n_samples": "n_samples",
                "shaft_speed_rpm": "speed_rpm", "shaft_speed_rpm_nominal": "speed_rpm",
                "shaft_speed_hz": "shaft_speed_hz", "shaft_speed_hz_nominal": "shaft_speed_hz",
                "torque_nm": "torque_nm", "motor_load_hp": "motor_load_hp",
                "radial_load_lbs": "radial_load_lbs", "radial_load_n": "radial_load_n",
                "load_percent": "load_percent", "calibration": "calibration"}

#: Keys of a recording entry that document its torque (a gear rig's) and its radial load.
TORQUE_KEYS = ("torque_nm", "load_percent")
RADIAL_KEYS = ("radial_load_n", "radial_load_lbs")


def undocumented_load(entry):
    """The loads of an operating point (``torque_nm``, ``radial_load_n``) a recording entry
    documents none of the keys of (:data:`TORQUE_KEYS`, :data:`RADIAL_KEYS`): the model
    assumes them."""
    return tuple(field for field, keys in (("torque_nm", TORQUE_KEYS),
                                           ("radial_load_n", RADIAL_KEYS))
                 if not any((entry or {}).get(k) is not None for k in keys))


#: Folder-level keys the pipeline reads (``fs_note`` only to cross-check an inferred rate).
FOLDER_KEYS = ("fs_hz", "fs_note", "channels", "sensors", "geometry")

#: Answer-key fields of a recording (with every key starting with ``fault``): for scoring only.
ANSWER_KEYS = ("condition", "fault")

#: Newtons per pound-force (0.45359237 kg × 9.80665 m/s², exact by definition).
LBF_N = 4.4482216152605

#: Metres per inch (exact by definition).
INCH_M = 0.0254

#: Standard gravity, m/s² (the ``g`` of an accelerometer unit; exact by definition).
STANDARD_GRAVITY_M_S2 = 9.80665

#: Accelerometer units cmsim converts to m/s² (the first word of a metadata ``unit``).
ACCELERATION_UNITS = {"g": STANDARD_GRAVITY_M_S2, "m/s2": 1.0, "m/s^2": 1.0, "m/s²": 1.0,
                      "mm/s2": 1e-3, "mm/s^2": 1e-3}

#: Other spellings of those units lab sheets write (read as the unit they spell, listed as it).
UNIT_SPELLINGS = {"g's": "g", "gs": "g", "m/s/s": "m/s2", "mm/s/s": "mm/s2", "mm/s²": "mm/s2"}


def read_metadata(folder, missing_ok=False):
    """The ``metadata.json`` of a folder, as parsed JSON (a dict with ``recordings``).

    Parameters
    ----------
    folder : str or pathlib.Path
        Folder of measured records.
    missing_ok : bool
        Return None when the folder has no ``metadata.json`` (the record's file and the
        caller then state what the metadata would).

    Returns
    -------
    dict or None

    Raises
    ------
    ParameterError
        No ``metadata.json``, not valid JSON, or no ``recordings`` list.
    """
    path = Path(folder) / "metadata.json"
    if missing_ok and not path.exists():
        return None
    if not path.is_file():
        raise ParameterError(f"no metadata.json in {Path(folder)} (the record format is the "
                             f"metadata.json schema of the datasets README)", param="record",
                             allowed="a file in a folder with metadata.json")
    try:
        meta = json.loads(path.read_text())
    except (ValueError, OSError) as exc:
        raise ParameterError(f"{path}: not valid JSON ({exc})", param="record") from None
    if not isinstance(meta, dict) or not isinstance(meta.get("recordings", []), list):
        raise ParameterError(f"{path}: not a dataset metadata file (no recordings list)",
                             param="record")
    checked_numbers(meta, "fs_hz", path)
    return meta


def checked_numbers(values, keys, where):
    """``values`` with each of ``keys`` (of :data:`NUMERIC_KEYS`) that is not ``null``
    checked against its range; a string (``"12k"``), a boolean or a value out of range is
    one error naming the file and the key.

    Parameters
    ----------
    values : dict
        The folder's keys or one recording entry.
    keys : str or sequence of str
        Keys to check (those absent or ``null`` are undocumented, not wrong).
    where : str or pathlib.Path
        What to name in the message (``.../metadata.json`` or ``... recordings[2]``).

    Returns
    -------
    dict
        ``values`` with the checked numbers as floats (ints for an integer range).
    """
    out = dict(values)
    for key in [keys] if isinstance(keys, str) else keys:
        if out.get(key) is None:
            continue
        try:    # a key of the file, in quotes: never read as a command's option
            out[key] = RANGES[NUMERIC_KEYS[key]].check(f'"{key}"', out[key])
        except ParameterError as exc:
            raise ParameterError(f"{where}: {exc}; write a plain JSON number (e.g. 12000, "
                                 f"not \"12k\") or null when undocumented", param="record",
                                 allowed=exc.allowed) from None
    return out


def is_answer_key(key):
    """True for a recording key of the answer key (``condition``, ``fault``, ``fault_*``).

    Parameters
    ----------
    key : str
    """
    return key in ANSWER_KEYS or key.startswith("fault")


def recording_entry(meta, file_name, metadata_path="metadata.json"):
    """The readable keys (:data:`RECORDING_KEYS`) of the entry of ``file_name``.

    Parameters
    ----------
    meta : dict
        Parsed ``metadata.json``.
    file_name : str
        Name of the signal file (locates the entry; it is not returned).
    metadata_path : str or pathlib.Path
        The ``metadata.json`` the entry comes from (named in messages).

    Returns
    -------
    dict
        Empty when the folder has no entry for the file.

    Raises
    ------
    ParameterError
        A numeric key that is neither ``null`` nor a number in its range
        (:func:`checked_numbers`).
    """
    for i, rec in enumerate(meta.get("recordings") or []):
        if isinstance(rec, dict) and rec.get("file") == file_name:
            entry = {k: rec[k] for k in RECORDING_KEYS if k in rec and k != "file"}
            return checked_numbers(entry, [k for k in NUMERIC_KEYS if k in entry],
                                   f"{metadata_path} recordings[{i}] ({file_name})")
    return {}


def label_of(rec):
    """Class of a recording from its answer key (for scoring only).

    ``condition == "healthy"`` → ``"healthy"``; a ``fault_location`` starting with
    ``inner_race`` / ``outer_race`` / ``ball`` → that class; a ``fault`` naming a broken tooth
    → ``"tooth_breakage"``, a crack → ``"tooth_crack"``; else the fault text.

    Parameters
    ----------
    rec : dict
        One entry of ``recordings[]`` of ``metadata.json``.

    Returns
    -------
    str
    """
    if str(rec.get("condition", "")).lower() == "healthy":
        return "healthy"
    loc = str(rec.get("fault_location") or "").lower()
    for cls in ("inner_race", "outer_race", "ball"):
        if loc.startswith(cls):
            return cls
    fault = str(rec.get("fault") or "").lower()
    if "tooth" in fault and ("broken" in fault or "break" in fault):
        return "tooth_breakage"
    if "crack" in fault:
        return "tooth_crack"
    return fault.replace(" ", "_") or loc.replace(" ", "_") or "unknown"


def answer_key(rec):
    """The answer key of a recording, for scoring only.

    Parameters
    ----------
    rec : dict
        One entry of ``recordings[]``.

    Returns
    -------
    dict
        ``fault_label`` (:func:`label_of`), ``fault_severity`` (``fault_diameter_in`` in m,
        else NaN) and ``condition``.
    """
    dia = rec.get("fault_diameter_in")
    return {"fault_label": label_of(rec),
            "fault_severity": float(dia) * INCH_M if dia else math.nan,
            "condition": rec.get("condition")}


#: Speed keys of a recording entry, in the order they are read, with their factor to rpm.
SPEED_KEYS = (("shaft_speed_rpm", 1.0), ("shaft_speed_hz", 60.0),
              ("shaft_speed_rpm_nominal", 1.0), ("shaft_speed_hz_nominal", 60.0))


def documented_speed(entry):
    """``(rpm, 'metadata.json "key"')`` of the entry's first speed key (:data:`SPEED_KEYS`),
    else ``(None, None)``: the value and the phrase naming its source in a message.

    Parameters
    ----------
    entry : dict
        Readable keys of the entry (:func:`recording_entry`).

    Returns
    -------
    rpm : float or None
    phrase : str or None
    """
    key = next((k for k, _ in SPEED_KEYS if entry.get(k) is not None), None)
    return documented_speed_rpm(entry), (f'metadata.json "{key}"' if key else None)


def documented_speed_rpm(entry):
    """Input-shaft speed of a recording entry, rpm, or None when undocumented.

    Reads, in this order, ``shaft_speed_rpm``, ``shaft_speed_hz``,
    ``shaft_speed_rpm_nominal``, ``shaft_speed_hz_nominal``.

    Parameters
    ----------
    entry : dict
        Readable keys of the entry (:func:`recording_entry`).

    Returns
    -------
    float or None
    """
    for key, factor in SPEED_KEYS:
        if entry.get(key) is not None:
            return factor * float(entry[key])
    return None


def documented_radial_load_n(entry):
    """Radial load of a recording entry, N (``radial_load_n``, else ``radial_load_lbs``
    converted with :data:`LBF_N`), or 0 when undocumented.

    Parameters
    ----------
    entry : dict
        Readable keys of the entry.

    Returns
    -------
    float
    """
    if entry.get("radial_load_n") is not None:
        return float(entry["radial_load_n"])
    if entry.get("radial_load_lbs") is not None:
        return LBF_N * float(entry["radial_load_lbs"])
    return 0.0


#: Units a channel may be given in that have no scale to m/s² (compared by shape only).
OTHER_UNITS = ("V", "mV")

#: Velocity units and their factor to m/s (a velocity record is differentiated to the
#: model's quantity, an acceleration, and the record says so).
VELOCITY_UNITS = {"m/s": 1.0, "mm/s": 1e-3, "in/s": INCH_M, "ips": INCH_M}

#: Displacement units and their factor to m (differentiated twice).
DISPLACEMENT_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "mil": 1e-3 * INCH_M}

#: What a metadata ``unit`` says when the unit is not known: no unit, not a wrong one.
UNKNOWN_UNIT = "unknown"


def known_units():
    """Every unit the table knows, in the order ``--help`` lists them: accelerations,
    velocities, displacements, then units without a scale (volts).

    Returns
    -------
    tuple of str
    """
    return (tuple(ACCELERATION_UNITS) + tuple(VELOCITY_UNITS) + tuple(DISPLACEMENT_UNITS)
            + OTHER_UNITS)


def unit_kind(unit, where="unit"):
    """``(quantity, factor)`` of a channel's unit: ``("acceleration", factor to m/s²)``,
    ``("velocity", factor to m/s)``, ``("displacement", factor to m)``, ``("other",
    None)`` for volts, ``(None, None)`` for no unit or ``"unknown"``. The first word is
    read (``"g (believed)"`` is ``g``), in any case but a unit's own (``mm`` is not ``Mm``).

    Parameters
    ----------
    unit : str or None
        The unit a file, metadata.json or the caller states.
    where : str
        What states it, for the message (``record x.csv: channel 'DE' (the file)``).

    Returns
    -------
    (str or None, float or None)

    Raises
    ------
    ParameterError
        A unit the table does not know (``furlongs``), listing the known ones.

    Examples
    --------
    >>> unit_kind("mm/s")
    ('velocity', 0.001)
    >>> unit_kind("g (believed)")
    ('acceleration', 9.80665)
    """
    text = str(unit or "").strip()
    word = text.split()[0] if text else ""
    if not word or word.lower() == UNKNOWN_UNIT:
        return None, None
    word = UNIT_SPELLINGS.get(word.lower(), word)
    for kind, table in (("acceleration", ACCELERATION_UNITS), ("velocity", VELOCITY_UNITS),
                        ("displacement", DISPLACEMENT_UNITS)):
        found = table.get(word, table.get(word.lower()))
        if found is not None:
            return kind, float(found)
    if word.lower() in {u.lower() for u in OTHER_UNITS}:
        return "other", None
    known = ", ".join(known_units())
    raise ParameterError(f"{where} is in {text!r}, a unit cmsim does not know; known: {known} "
                         f"(or \"{UNKNOWN_UNIT}\"): correct the unit where it is written",
                         param="record", allowed=known)


def checked_unit(unit, param="unit"):
    """``unit`` (stripped) when the unit table knows it (:func:`known_units`, any case),
    None when empty or None; anything else is refused, listing the known units.

    Parameters
    ----------
    unit : str or None
        A unit given from outside (``--unit``).
    param : str
        What an error is about.

    Returns
    -------
    str or None

    Raises
    ------
    ParameterError
        A unit the table does not know (``furlongs``), or a blank one.
    """
    if unit is None:
        return None
    text = str(unit).strip()
    known = known_units()
    if text.lower() not in {k.lower() for k in known}:
        raise ParameterError(f"{param} {unit!r} is not a unit cmsim knows; allowed: "
                             f"{', '.join(known)}", param=param, allowed=", ".join(known))
    return text


def unit_scale_of(unit):
    """Factor from an accelerometer unit (``"g"``, ``"g (believed)"``, ``"m/s^2"``) to m/s²,
    or None for anything else (volts, an unknown unit).

    Parameters
    ----------
    unit : str or None

    Returns
    -------
    float or None
    """
    if not isinstance(unit, str) or not unit.strip():
        return None
    return ACCELERATION_UNITS.get(unit.strip().split()[0].lower())


def rig_geometry(rig):
    """The ``geometry`` block of ``metadata.json`` that documents a cmsim rig: what
    :func:`cmsim.measured.model_rig.model_rig` and
    :func:`~cmsim.measured.model_rig.documented_frequencies` read back.

    Parameters
    ----------
    rig : cmsim.rig.Rig

    Returns
    -------
    dict
        ``gears``: one stage (``input_teeth``, ``output_teeth``, ``module_mm``,
        ``pressure_angle_deg``, ``face_width_mm``) or None for a bearing rig; ``bearings``:
        per bearing node (``1b1``, ``1b2``, ...; the ``near`` of a cmsim sensor) its
        ``n_balls``, ``ball_diameter_mm``, ``pitch_diameter_mm``, ``contact_angle_deg`` (the
        effective one), ``shaft`` (``input`` or ``output``) and ``outer_ring_fixed``.
    """
    gears = None
    if rig.gears is not None:
        g1, g2 = rig.gears.driving, rig.gears.driven
        gears = [{"stage": 1, "input_teeth": int(g1.n_teeth), "output_teeth": int(g2.n_teeth),
                  "module_mm": 1e3 * g1.module_m,
                  "pressure_angle_deg": math.degrees(g1.pressure_angle_rad),
                  "face_width_mm": 1e3 * min(g1.face_width_m, g2.face_width_m),
                  "documented": True}]
    shaft_of = [i for i, s in enumerate(rig.shafts) for _ in s.bearings]
    bearings = {name: {"model": f"cmsim rig {rig.name!r}, bearing {name}",
                       "n_balls": int(b.n_balls), "ball_diameter_mm": 1e3 * b.ball_diameter_m,
                       "pitch_diameter_mm": 1e3 * b.pitch_diameter_m,
                       "contact_angle_deg": math.degrees(b.effective_contact_angle_rad),
                       "shaft": "input" if i == 0 else "output", "location": name,
                       "outer_ring_fixed": b.outer_ring_speed_ratio == 0}
                for name, b, i in zip(rig.bearing_names, rig.bearings, shaft_of)}
    return {"gears": gears, "bearings": bearings}
