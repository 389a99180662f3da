"""Export a generated dataset in the schema of the ``bearing-datasets`` index: one Parquet row
per signal, so cmsim data mix with public bearing datasets.

Columns (one row per record and vibration channel):

* ``dataset``, ``signal_id`` (``<dataset>/<record_id>/<channel>``), ``record_id``,
  ``channel``, ``unit`` (``m/s^2``), ``signal`` (list of float32), ``n_samples``, ``fs``
  (Hz), ``duration_s``;
* ``speed_rpm``, ``load`` (radial load on the bearing, N; the torque for a gear rig),
  ``load_unit``;
* ``fault_type`` (``"healthy"``, ``"localized"`` for race/ball defects, else the cmsim fault
  name), ``fault_location`` (``"none"``, ``"inner_race"``, ``"outer_race"``, ``"ball"``,
  ``"gear"``, ``"bearing"``), ``fault_size_mm`` (the fault's main size, mm; NaN when
  healthy), ``fault_severity_level`` (0 healthy, 1-3 the tertile of the size among the
  records of the same fault label);
* ``bpfo``, ``bpfi``, ``bsf``, ``ftf``: the bearing's defect frequencies in shaft orders
  (BSF = ball spin, one race), of the faulty bearing or the first one;
* ``bearing_id`` (virtual: ``cmsim:<rig>:<bearing>:<record_id>``), ``fault_origin``
  (``"simulated"``), ``rig``.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_bytes
from cmsim.datasets.load import load
from cmsim.errors import ParameterError

__all__ = ["to_bearing_datasets", "bearing_datasets_frame"]

_LOCAL = {"inner_race", "outer_race", "ball"}
_GEAR = {"tooth_crack", "tooth_spall", "tooth_breakage", "eccentricity", "profile_error"}


def _location(label):
    if label == "healthy":
        return "none"
    if label in _LOCAL:
        return label
    if label in _GEAR:
        return "gear"
    return "bearing" if label in ("wear", "off_size_ball") else label


def bearing_datasets_frame(dataset, channels=None):
    """The rows of :func:`to_bearing_datasets` as a DataFrame.

    Parameters
    ----------
    dataset : cmsim.datasets.Dataset or str or Path
    channels : sequence of str, optional
        Default: every ``accel_*`` channel.

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    ds = load(dataset) if isinstance(dataset, (str, Path)) else dataset
    chans = list(channels) if channels else [c for c in ds.channels if c.startswith("accel_")]
    if not chans:
        raise ParameterError("channels: the dataset has no accel_* channel", param="channels")
    for c in chans:
        if c not in ds.channels:
            raise ParameterError(f"channels: {c!r} is not in {list(ds.channels)}",
                                 param="channels")
    man = ds.manifest[ds.manifest["status"] == "ok"].copy()
    level = np.zeros(len(man), int)
    for lab, idx in man.groupby("fault_label").groups.items():
        if lab == "healthy":
            continue
        sev = man.loc[idx, "fault_severity"].to_numpy(float)
        edges = np.nanquantile(sev, [1 / 3, 2 / 3]) if np.isfinite(sev).any() else [0, 0]
        pos = [man.index.get_loc(i) for i in idx]
        level[pos] = 1 + np.searchsorted(edges, sev, side="right")
    rows = []
    name = str((getattr(ds, "spec", None) or {}).get("name") or "cmsim")
    for k, (_, row) in enumerate(man.iterrows()):
        rec = ds.record(row["record_id"])
        comp = row.get("fault_component") or ""
        bf = rec.frequencies.bearing(comp if comp in rec.frequencies.bearings else None)
        fr = bf.shaft_hz
        label = row["fault_label"]
        gear = rec.rig.gears is not None
        sig = rec.signals
        for ch in chans:
            x = np.asarray(sig[ch], np.float32)
            rows.append({
                "dataset": name, "signal_id": f"{name}/{row['record_id']}/{ch}",
                "record_id": row["record_id"], "channel": ch, "unit": "m/s^2",
                "signal": x, "n_samples": int(x.size), "fs": float(rec.fs_hz),
                "duration_s": x.size / float(rec.fs_hz),
                "speed_rpm": float(row["speed_rpm"]),
                "load": float(row["torque_nm"] if gear else row["radial_load_n"]),
                "load_unit": "N m" if gear else "N",
                "fault_type": "healthy" if label == "healthy" else (
                    "localized" if label in _LOCAL else label),
                "fault_location": _location(label),
                "fault_size_mm": 1e3 * float(row["fault_severity"])
                if label in _LOCAL else math.nan,
                "fault_severity_level": int(level[k]),
                "bpfo": bf.bpfo_hz / fr, "bpfi": bf.bpfi_hz / fr, "bsf": bf.bsf_hz / fr,
                "ftf": bf.ftf_hz / fr,
                "bearing_id": f"cmsim:{rec.rig.name}:{comp or 'none'}:{row['record_id']}",
                "fault_origin": "simulated", "rig": rec.rig.name})
    return pd.DataFrame(rows)


def to_bearing_datasets(dataset, out, channels=None):
    """Write ``out`` (Parquet, atomically): one row per signal (module docstring).

    Parameters
    ----------
    dataset : cmsim.datasets.Dataset or str or Path
    out : str or Path
        The ``.parquet`` file to write.
    channels : sequence of str, optional

    Returns
    -------
    pathlib.Path
    """
    df = bearing_datasets_frame(dataset, channels)
    buf = io.BytesIO()
    df.to_parquet(buf, index=False)
    out = Path(out)
    atomic_write_bytes(out, buf.getvalue())
    return out
