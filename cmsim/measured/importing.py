"""A folder of recordings documented as ``metadata.json``: what ``cmsim import`` writes.

:func:`folder_metadata` reads every signal file of a folder (every suffix of
:data:`~cmsim.measured.readers.READERS`) and writes down, in the schema
:mod:`~cmsim.measured.schema` reads, what the files state (channel names, sample rate,
units, a ``.mat`` file's shaft speed) and what the caller gives for what they do not
(``fs_hz``, ``speed_rpm``, ``unit``, ``calibration``; a WAV's channel names), with the rule
of :mod:`~cmsim.measured.stated`: the file first, then a ``metadata.json`` already in the
folder, then the arguments (two sources that disagree are refused, naming both values).
The geometry and the answer key are left for the user to add: nothing in a signal file
states them; every key of an existing ``metadata.json`` that import does not produce
itself (geometry, sensor positions, a recording's condition or answer key) is kept. A file
cmsim wrote (an ``.npz`` with a ``meta`` array: a run or a dataset record) states its own
rate, speed and rig and needs no metadata: it is left out and named. A file that cannot
be read, or whose statements disagree with the folder's metadata, is left out and named
with the reason; the others are documented (one bad file never stops the folder). A
``metadata.json`` that cmsim wrote itself (``source`` starting ``cmsim``: an earlier import
or an export) holds copies of what the files stated: where a file states a value, the file
wins over that copy (the file was re-recorded or re-exported), and nothing is refused.
:func:`write_folder_metadata` writes the result atomically and never overwrites an
existing file unless told to.
"""

from __future__ import annotations

import json
from pathlib import Path

from cmsim._io import atomic_write_text
from cmsim.errors import ParameterError
from cmsim.measured.readers import READERS, is_cmsim_run, read_file
from cmsim.measured.schema import (checked_numbers, checked_unit, documented_speed,
                                   read_metadata, recording_entry)
from cmsim.measured.stated import (CALIBRATION_TOLERANCE, HEADER_RATE_TOLERANCE,
                                   SPEED_TOLERANCE, agreed, agreed_unit)

__all__ = ["folder_metadata", "write_folder_metadata", "signal_files"]


def signal_files(folder):
    """The signal files of ``folder`` that cmsim reads, sorted by name (hidden files and
    ``metadata.json`` left out).

    Parameters
    ----------
    folder : str or pathlib.Path

    Returns
    -------
    list of pathlib.Path
    """
    return sorted(p for p in Path(folder).iterdir()
                  if p.is_file() and not p.name.startswith(".")
                  and p.suffix.lower() in READERS)


def _channel_names(path, f, channels):
    """The channel names an entry documents: the file's, or ``channels`` — naming a file's
    unnamed channels (WAV ``ch0``, ...) in order, else choosing among the file's names."""
    names = list(f.signals)
    if not channels:
        return names
    unnamed = names == [f"ch{i}" for i in range(len(names))]
    if unnamed:
        if len(channels) != len(names):
            raise ParameterError(f"channel: record {path} holds {len(names)} unnamed "
                                 f"signal(s) ({', '.join(names)}) but channel gives "
                                 f"{len(channels)} names ({', '.join(channels)}); give one "
                                 f"name per signal, in the file's order", param="channel",
                                 allowed=f"{len(names)} names")
        return list(channels)
    missing = [c for c in channels if c not in names]
    if missing:
        raise ParameterError(f"channel {missing[0]!r} is not in {path}; available: "
                             f"{sorted(names)}", param="channel", allowed=", ".join(names))
    return list(channels)


def folder_metadata(folder, *, fs_hz=None, speed_rpm=None, channels=None, unit=None,
                    calibration=None, keep=None):
    """``metadata.json`` of a folder of recordings, from what the files state and the
    arguments give.

    Parameters
    ----------
    folder : str or pathlib.Path
        Folder with one signal file per recording.
    fs_hz : float, optional
        Sample rate, Hz, of the files that do not state one (one that does must agree).
    speed_rpm : float, optional
        Input-shaft speed, rpm (a file that states one must agree).
    channels : sequence of str, optional
        Names of a file's unnamed channels (a WAV's, in order), or the channels to document
        of files that name theirs (each must be in the file).
    unit : str, optional
        Unit of every channel whose file and the folder's metadata state none (``g``,
        ``m/s^2``, ``V``; :func:`~cmsim.measured.schema.checked_unit`), the rule of
        :func:`~cmsim.measured.record.read_record`.
    calibration : float, optional
        Physical units per stored sample value, for files that store counts or volts and
        state no factor.
    keep : dict, optional
        Metadata whose keys are kept where import does not produce them (default the
        folder's ``metadata.json``, also read as a source of the values).

    Returns
    -------
    metadata : dict
        In the schema of :mod:`~cmsim.measured.schema`: ``fs_hz`` (the files' common rate or
        null), ``channels``, ``sensors`` (units), ``geometry`` (null unless ``keep`` has
        it: not stated by any file), ``recordings``; every other key of ``keep`` as it is.
    undocumented : list of str
        What neither a file, the folder's metadata nor an argument states (``x.npz: sample
        rate``).
    skipped : list of str
        Files cmsim wrote (runs, dataset records), left out: they need no metadata.
    unreadable : list of (str, str)
        Files left out, with why: a file that cannot be read, or whose statements disagree
        with the folder's metadata.

    Raises
    ------
    ParameterError
        No measured recording in the folder, or none readable (the first one's reason); a
        ``metadata.json`` that is not valid; a channel not in a file; an argument that a
        file's statement contradicts.
    """
    folder = Path(folder)
    unit = checked_unit(unit)
    stated = read_metadata(folder, missing_ok=True) or {}
    keep = stated if keep is None else keep
    where = folder / "metadata.json"
    files = signal_files(folder)
    skipped = [p.name for p in files if is_cmsim_run(p)]
    files = [p for p in files if p.name not in skipped]
    if not files:
        found = (f" (only files cmsim wrote, which need no metadata: {', '.join(skipped)})"
                 if skipped else "")
        raise ParameterError(f"{folder} holds no measured recording ({', '.join(READERS)} "
                             f"files){found}", param="dataset",
                             allowed="a folder with signal files")
    sensors_stated = stated.get("sensors") if isinstance(stated.get("sensors"), dict) else {}
    own = str(stated.get("source") or "").startswith("cmsim")
    recordings, units, unit_from, undocumented, unreadable = [], {}, {}, [], []
    for path in files:
        try:
            entry, names, f = _documented(path, stated, where, channels, own, fs_hz, speed_rpm,
                                          calibration)
            found = {}                    # one unit per channel name over the folder
            for name in names:
                sensor = sensors_stated.get(name) if isinstance(sensors_stated.get(name),
                                                                dict) else {}
                doc_unit = None if own and f.units.get(name) else sensor.get("unit")
                found[name] = agreed_unit(path, name, [
                    (unit_from.get(name), "record", units.get(name)),
                    ("the file", "record", f.units.get(name)),
                    ('metadata.json "sensors"', "record", doc_unit), ("unit", "unit", unit)])
        except ParameterError as exc:
            if exc.param != "record":             # an argument's fault: every file's
                raise
            unreadable.append((path.name, " ".join(str(exc).split())))
            continue
        recordings.append(entry)
        undocumented += [f"{path.name}: {what}" for what, v in
                         (("sample rate", entry["fs_hz"]),
                          ("shaft speed", entry["shaft_speed_rpm"])) if v is None]
        for name, u in found.items():
            if u is not None and name not in units:
                units[name] = u
                unit_from[name] = path.name if f.units.get(name) else "unit"
    if not recordings:
        name, why = unreadable[0]
        raise ParameterError(f"{folder}: no recording could be read ({len(unreadable)} "
                             f"left out; first: {why})", param="dataset",
                             allowed="a folder with a readable signal file")
    rates = {r["fs_hz"] for r in recordings}
    all_channels = sorted({c for r in recordings for c in r["channels"]})
    undocumented += [f"unit of {c}" for c in all_channels if c not in units]
    meta = {"dataset": folder.resolve().name,
            "source": "cmsim import: channel names, rates, units and speeds the files "
                      "state, the rest from its options; add geometry and the answer key "
                      "by hand",
            "fs_hz": rates.pop() if len(rates) == 1 else None,
            "channels": {c: f"channel {c} of the recordings" for c in all_channels},
            "sensors": {c: {"near": "unknown", "direction": "unknown",
                            "unit": units.get(c)} for c in all_channels},
            "geometry": {"gears": None, "bearings": None},
            "recordings": recordings}
    return _merged(keep, meta), undocumented, skipped, unreadable


def _documented(path, stated, where, channels, own, fs_hz, speed_rpm, calibration):
    """``(recordings entry, channel names, SignalFile)`` of one file: what it states, then
    the folder's metadata (a copy cmsim wrote, ``own``, only where the file is silent),
    then the arguments, by the rule of :mod:`~cmsim.measured.stated`."""
    doc = recording_entry(stated, path.name, where)
    f = read_file(path, channels or doc.get("channels"))
    names = _channel_names(path, f, channels)
    first = f.signals[names[0]]
    doc_rate = doc.get("fs_hz") or stated.get("fs_hz")
    rpm_doc, rpm_key = documented_speed(doc)
    doc_scale = doc.get("calibration")
    if own:                         # cmsim's copy of what the file stated: the file wins
        doc_rate = None if f.rate_hz is not None else doc_rate
        rpm_doc = None if f.speed_rpm is not None else rpm_doc
        doc_scale = None if f.calibration is not None else doc_scale
    rate, _ = agreed(path, "sample rate", [
        (f.rate_from, "record", f.rate_hz), ('metadata.json "fs_hz"', "record", doc_rate),
        ("fs_hz", "fs_hz", fs_hz)], HEADER_RATE_TOLERANCE, " Hz")
    speed, _ = agreed(path, "speed", [("the file", "record", f.speed_rpm),
                                      (rpm_key, "record", rpm_doc),
                                      ("speed_rpm", "speed_rpm", speed_rpm)],
                      SPEED_TOLERANCE, " rpm")
    scale, _ = agreed(path, "units per stored value", [
        ("the file", "record", f.calibration),
        ('metadata.json "calibration"', "record", doc_scale),
        ("calibration", "calibration", calibration)], CALIBRATION_TOLERANCE)
    entry = {"file": path.name, "n_samples": int(first.size), "fs_hz": rate,
             "shaft_speed_rpm": speed, "channels": names}
    if scale is not None and f.calibration is None:
        entry["calibration"] = scale
    return entry, names, f


def _merged(kept, made):
    """``made`` over ``kept``: every key of ``kept`` that import does not produce stays as it
    is (the description, geometry, sensor positions, a recording's condition and answer
    key); what import produces (rates, speeds, units, channels of each file) replaces it."""
    if not isinstance(kept, dict) or not kept:
        return made
    out = dict(kept)
    for key in ("dataset", "source", "geometry"):     # descriptions the user wrote win
        out.setdefault(key, made[key])
    out["fs_hz"] = made["fs_hz"]
    old_channels = kept.get("channels") if isinstance(kept.get("channels"), dict) else {}
    out["channels"] = {**made["channels"], **old_channels}
    old_sensors = kept.get("sensors") if isinstance(kept.get("sensors"), dict) else {}
    out["sensors"] = dict(old_sensors)
    for c, s in made["sensors"].items():
        old = old_sensors.get(c) if isinstance(old_sensors.get(c), dict) else {}
        out["sensors"][c] = {**s, **old, "unit": s["unit"] if s["unit"] else old.get("unit")}
    old_recs = {r.get("file"): r for r in kept.get("recordings") or []
                if isinstance(r, dict)}
    out["recordings"] = [{**old_recs.get(r["file"], {}), **r} for r in made["recordings"]]
    return out


def write_folder_metadata(path, metadata, *, force=False):
    """Write ``metadata`` to ``path`` atomically, checked as :func:`read_metadata` reads it.

    Parameters
    ----------
    path : str or pathlib.Path
        The ``metadata.json`` to write.
    metadata : dict
        From :func:`folder_metadata` (or edited).
    force : bool
        Overwrite an existing file.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ParameterError
        The file exists and ``force`` is False; a numeric key out of its range.
    """
    path = Path(path)
    if path.exists() and not force:
        raise ParameterError(f"out: {path} exists; give force=True to overwrite it", param="out",
                             allowed="a new file, or force")
    checked_numbers(metadata, "fs_hz", path)
    for i, rec in enumerate(metadata.get("recordings") or []):
        recording_entry({"recordings": [rec]}, rec.get("file"), f"{path} recordings[{i}]")
    atomic_write_text(path, json.dumps(metadata, indent=1) + "\n")
    return path
