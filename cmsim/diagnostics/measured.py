"""Measured records (a folder with ``metadata.json`` and one ``.npz`` per recording) as a dataset.

The folder follows the schema of ``../shared/datasets/README.md``: ``fs_hz``, ``geometry``
(``bearings``: ``n_balls``, ``ball_diameter_mm``, ``pitch_diameter_mm``,
``contact_angle_deg``, ``shaft``; ``gears``: stages with ``input_teeth``, ``output_teeth``)
and ``recordings[]`` (``file``, ``shaft_speed_rpm`` of the input shaft, load fields, and the
answer key ``condition``, ``fault*``). :func:`load_measured` gives an object with the
interface the harness reads (``manifest``, ``record(id)``, iteration); the characteristic
frequencies come from the documented geometry at the record's speed
(:func:`cmsim.frequencies.bearing_frequencies`), never from a label. The answer key is read
into ``labels`` only, for scoring:

* ``condition == "healthy"`` → ``"healthy"``;
* ``fault_location`` starting with ``inner_race`` / ``outer_race`` / ``ball`` → that class;
* a ``fault`` mentioning a broken tooth → ``"tooth_breakage"``;
* severity: ``fault_diameter_in`` converted to m (CWRU), else NaN.

A folder without a documented sample rate (``fs_hz: null``, the SpectraQuest gearbox) gets
the rate its ``fs_note`` infers (``fs ~= 12.97 kHz``) and says so in ``assumptions``.

:func:`data_root` is where the shared measured data sit: ``$CMSIM_DATA`` if set, else
``../shared/datasets`` next to the repository. Nothing is copied into the repository.
"""

from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cmsim.errors import ParameterError
from cmsim.frequencies import RigFrequencies, bearing_frequencies
from cmsim.rig import OperatingPoint

__all__ = ["MeasuredRecord", "MeasuredDataset", "load_measured", "data_root",
           "MEASURED_DATASETS", "label_of"]

#: Folders of ``../shared/datasets`` scored in the README.
MEASURED_DATASETS = ("cwru_bearing_12k_de", "mfpt_bearing", "spectraquest_gearbox_gfd")

_LB_TO_N = 4.4482216152605
_IN_TO_M = 0.0254


def data_root():
    """Folder of the shared measured datasets: ``$CMSIM_DATA``, else ``../shared/datasets``
    beside the repository root (may not exist)."""
    env = os.environ.get("CMSIM_DATA")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[2].parent / "shared" / "datasets"


def label_of(rec):
    """Class of a recording from its answer key (see the module docstring).

    Parameters
    ----------
    rec : dict
        One entry of ``recordings[]`` of ``metadata.json``.
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


@dataclass(frozen=True, eq=False)
class MeasuredRecord:
    """One measured recording.

    Attributes
    ----------
    record_id : str
        File stem.
    path : pathlib.Path
        The ``.npz`` file.
    fs_hz : float
        Sample rate, Hz.
    operating_point : cmsim.rig.OperatingPoint
        Input-shaft speed and radial load.
    frequencies : cmsim.frequencies.RigFrequencies
        From the documented geometry at this speed.
    labels : dict
        Answer key: ``fault_label``, ``fault_severity`` (m or NaN), ``condition``.
    meta : dict
        The recording's metadata without the answer key.
    """

    record_id: str
    path: Path
    fs_hz: float
    operating_point: OperatingPoint
    frequencies: RigFrequencies
    labels: dict
    meta: dict = field(default_factory=dict)

    @property
    def signals(self):
        """Channel name → float32 array (read from the file on each access)."""
        with np.load(self.path) as z:
            return {k: np.asarray(z[k]) for k in z.files}


_ANSWER_KEYS = ("condition", "fault")


def _fs_from_note(meta):
    m = re.search(r"fs\s*~?=\s*([0-9.]+)\s*kHz", str(meta.get("fs_note", "")))
    return 1e3 * float(m.group(1)) if m else None


def _frequencies(geometry, shaft_hz):
    gears = (geometry or {}).get("gears") or []
    fr2 = gmf = None
    if gears:
        g = gears[0]
        z1, z2 = g.get("input_teeth"), g.get("output_teeth")
        if z1 and z2:
            fr2, gmf = shaft_hz * z1 / z2, shaft_hz * z1
    bearings = {}
    for name, b in ((geometry or {}).get("bearings") or {}).items():
        rate = fr2 if b.get("shaft") == "output" and fr2 is not None else shaft_hz
        bearings[name] = bearing_frequencies(
            rate, int(b["n_balls"]), 1e-3 * float(b["ball_diameter_mm"]),
            1e-3 * float(b["pitch_diameter_mm"]),
            math.radians(float(b.get("contact_angle_deg") or 0.0)))
    return RigFrequencies(fr1_hz=shaft_hz, fr2_hz=fr2, gmf_hz=gmf, bearings=bearings)


class MeasuredDataset:
    """The recordings of one folder, with the harness's dataset interface.

    Attributes
    ----------
    name : str
        Folder name.
    manifest : pandas.DataFrame
        One row per recording: ``record_id``, ``status`` ("ok"), ``path``, ``fs_hz``,
        ``speed_rpm``, ``radial_load_n``, ``fault_label``, ``fault_severity``.
    assumptions : list of str
        What was not documented and had to be assumed (e.g. the sample rate).
    """

    def __init__(self, folder):
        import pandas as pd

        folder = Path(folder)
        meta_path = folder / "metadata.json"
        if not meta_path.is_file():
            raise ParameterError(f"{folder}: no metadata.json (not a measured dataset folder)",
                                 param="dataset")
        try:
            meta = json.loads(meta_path.read_text())
            recs = meta["recordings"]
        except (OSError, ValueError, KeyError) as exc:
            raise ParameterError(f"{meta_path}: not a dataset metadata file "
                                 f"({type(exc).__name__}: {exc})", param="dataset") from None
        self.name = folder.name
        self.folder = folder
        self.assumptions = []
        fs_default = meta.get("fs_hz")
        if fs_default is None:
            fs_default = _fs_from_note(meta)
            if fs_default is not None:
                self.assumptions.append(f"fs_hz undocumented; {fs_default:g} Hz from fs_note "
                                        f"(inferred, unverified)")
        self._records = {}
        rows = []
        for r in recs:
            rid = Path(r["file"]).stem
            fs = r.get("fs_hz") or fs_default
            if fs is None:
                raise ParameterError(f"{meta_path}: recording {rid} has no sample rate",
                                     param="dataset")
            rpm = float(r.get("shaft_speed_rpm") or r.get("shaft_speed_rpm_nominal"))
            load_n = float(r.get("radial_load_lbs") or 0.0) * _LB_TO_N
            op = OperatingPoint(speed_rpm=rpm, radial_load_n=load_n)
            freqs = _frequencies(meta.get("geometry"), rpm / 60.0)
            dia = r.get("fault_diameter_in")
            sev = float(dia) * _IN_TO_M if dia else math.nan
            label = label_of(r)
            labels = {"fault_label": label, "fault_severity": sev,
                      "condition": r.get("condition")}
            public = {k: v for k, v in r.items()
                      if not (k in _ANSWER_KEYS or k.startswith("fault"))}
            self._records[rid] = MeasuredRecord(rid, folder / r["file"], float(fs), op, freqs,
                                                labels, public)
            rows.append({"record_id": rid, "status": "ok", "path": r["file"], "fs_hz": fs,
                         "speed_rpm": rpm, "radial_load_n": load_n, "fault_label": label,
                         "fault_severity": sev})
        self.manifest = pd.DataFrame(rows)

    def record(self, record_id):
        """The :class:`MeasuredRecord` of ``record_id`` (file stem) or of a row index."""
        if isinstance(record_id, (int, np.integer)) and record_id not in self._records:
            record_id = self.manifest["record_id"].iloc[int(record_id)]
        try:
            return self._records[str(record_id)]
        except KeyError:
            raise ParameterError(f"{self.name}: no record {record_id!r}; have "
                                 f"{list(self._records)}", param="record_id") from None

    def __len__(self):
        return len(self._records)

    def __iter__(self):
        return iter(self._records.values())


def load_measured(folder):
    """:class:`MeasuredDataset` of a folder with ``metadata.json``."""
    return MeasuredDataset(folder)
