"""The manifest of a sweep directory: what was asked, and per run what was done.

``DIR/manifest.json`` (format ``cmsim-sweep-manifest``, version 1) holds ``spec``
(:meth:`SweepSpec.to_dict <cmsim.datasets.spec.SweepSpec.to_dict>`), ``created``,
``updated`` and ``runs``: per case name, the run file (``runs/<name>.npz``), status
(``"done"`` / ``"failed"`` with its ``error``), operating point, varied settings, seed, file
size, wall-time split and the features of :data:`FEATURE_SIGNALS` from the one feature
extractor (:func:`cmsim.features.run_features`). Every write replaces the file atomically.

It also decides whether a run file on disk is a complete run of a case
(:func:`file_matches`), which is what makes a sweep resumable.
"""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_text
from cmsim.datasets.spec import SweepSpec, mesh_key
from cmsim.errors import ParameterError
from cmsim.features import N_GMF_HARMONICS, run_features

__all__ = ["MANIFEST_NAME", "RUNS_DIR", "FEATURE_SIGNALS", "read_manifest", "write_manifest",
           "new_manifest", "spec_difference", "case_entry", "run_file", "file_matches",
           "manifest_features", "file_sha256"]

#: File name of the manifest inside a sweep directory.
MANIFEST_NAME = "manifest.json"

#: Sub-directory of the run files.
RUNS_DIR = "runs"

#: Signals whose features are stored in the manifest (those present in a run).
FEATURE_SIGNALS = ("F_1b1_loa", "F_1b1_oloa", "dte_um")

_FORMAT = "cmsim-sweep-manifest"
_VERSION = 1


def _now():
    return time.strftime("%Y-%m-%dT%H:%M:%S%z")


def normalised(obj):
    """``obj`` as it reads back from JSON (tuples → lists, ints kept)."""
    return json.loads(json.dumps(obj))


def file_sha256(path, chunk_bytes=1 << 20):
    """SHA-256 of a file's bytes, hex.

    Parameters
    ----------
    path : str or Path
        The file.
    chunk_bytes : int
        Read size, bytes.

    Returns
    -------
    str
    """
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(chunk_bytes), b""):
            digest.update(block)
    return digest.hexdigest()


def run_file(out_dir, case):
    """Path of the run file of ``case`` in sweep directory ``out_dir``."""
    return Path(out_dir) / RUNS_DIR / f"{case.name}.npz"


def read_manifest(out_dir):
    """The manifest of a sweep directory as a dict, or None if there is none.

    Raises :class:`ParameterError` if the file exists but is not a cmsim sweep manifest.
    """
    path = Path(out_dir) / MANIFEST_NAME
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None
    except json.JSONDecodeError as exc:
        raise ParameterError(f"{path} is not valid JSON: {exc}") from None
    if not isinstance(data, dict) or data.get("format") != _FORMAT:
        raise ParameterError(f"{path} is not a cmsim sweep manifest")
    if data.get("version") != _VERSION:
        raise ParameterError(f"{path} has manifest version {data.get('version')!r}; this "
                             f"cmsim reads version {_VERSION}")
    return data


def new_manifest(spec):
    """An empty manifest for ``spec``."""
    return {"format": _FORMAT, "version": _VERSION, "created": _now(),
            "spec": normalised(spec.to_dict()), "runs": {}}


def write_manifest(out_dir, manifest):
    """Stamp ``manifest["updated"]`` and write it atomically to ``out_dir``."""
    manifest["updated"] = _now()
    atomic_write_text(Path(out_dir) / MANIFEST_NAME, json.dumps(manifest, indent=1) + "\n")


def spec_difference(old, new):
    """What differs between a stored spec dict ``old`` and the spec ``new``, as a list of
    setting names (``"duration_s"``, ``"variations: torque_nm"``, ``"fixed: speed_rpm"``).

    Both are compared in the variations form, so a spec stored in the older form and one
    written with variations are compared setting by setting.
    """
    new_d = json.loads(json.dumps(new.to_dict(older_form=False)))
    try:
        old_d = json.loads(json.dumps(SweepSpec.from_dict(old).to_dict(older_form=False)))
    except (ParameterError, TypeError, ValueError):
        old_d = old
    out = []
    for key in sorted(set(old_d) | set(new_d)):
        a, b = old_d.get(key), new_d.get(key)
        if a == b:
            continue
        if key == "variations" and isinstance(a, list) and isinstance(b, list):
            va = {v.get("name"): v.get("values") for v in a if isinstance(v, dict)}
            vb = {v["name"]: v["values"] for v in b}
            names = [n for n in [*vb, *va] if va.get(n) != vb.get(n)]
            if [v.get("name") for v in a if isinstance(v, dict)] != list(vb) and not names:
                names = ["order"]
            out += [f"variations: {n}" for n in dict.fromkeys(names)]
        elif key == "fixed" and isinstance(a, dict) and isinstance(b, dict):
            out += [f"fixed: {n}" for n in sorted(set(a) | set(b)) if a.get(n) != b.get(n)]
        else:
            out.append(key)
    return out


def manifest_features(run, signals=FEATURE_SIGNALS, n_harmonics=N_GMF_HARMONICS, top_n=5):
    """Features of a run for the manifest, per signal (:func:`cmsim.features.run_features`).

    Parameters
    ----------
    run : cmsim.run.Run
        Simulated run.
    signals : sequence of str
        Signals to summarise (those absent from the run are left out).
    n_harmonics : int
        GMF harmonics measured (default :data:`cmsim.features.N_GMF_HARMONICS`).
    top_n : int
        Largest labelled peaks kept per signal.

    Returns
    -------
    dict
        Per signal, :meth:`cmsim.features.FeatureRow.to_summary`: ``dominant_gmf_harmonic``,
        ``gmf_harmonics`` (signal unit), ``top_peaks`` and ``features`` (flat columns, NaN as
        None).
    """
    return {name: run_features(run, name, n_gmf_harmonics=n_harmonics,
                               top_n=top_n).to_summary()
            for name in signals if name in run.signals}


def case_entry(spec, case, result):
    """The manifest row of ``case`` from a worker's ``result`` dict."""
    op = spec.case_operating_point(case)
    params = case.params
    return {"index": case.index, "file": f"{RUNS_DIR}/{case.name}.npz",
            "status": result["status"],
            "operating_point": {"speed_rpm": op.speed_rpm, "torque_nm": op.torque_nm,
                                "radial_load_n": op.radial_load_n},
            "friction": params.get("friction"), "clearance_m": params.get("clearance_m"),
            "values": params, "seed": case.seed,
            **{k: result[k] for k in ("bytes", "sha256", "error", "features", "timing_s",
                                      "pid", "adopted") if k in result},
            "finished": _now()}


def file_matches(spec, case, path, entry=None):
    """True if ``path`` is a complete run of ``case`` (and matches ``entry`` if given).

    With ``entry``: its status is done, and the file has its size and SHA-256 checksum (a
    file corrupted in place, even to the same size, is not a match). Compared: case name,
    seed, operating point, rig, sampling, duration, the spec's mesh (files written before the
    mesh was recorded count as the default mesh), faults and loss settings.
    """
    path = Path(path)
    if not path.is_file():
        return False
    if entry is not None:
        if entry.get("status") != "done" or entry.get("bytes") != path.stat().st_size:
            return False
        if "sha256" in entry and entry["sha256"] != file_sha256(path):
            return False
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
    except Exception:                      # unreadable or foreign file: recompute it
        return False
    if not isinstance(meta, dict):
        return False
    op = meta.get("operating_point", {})
    sc = meta.get("sweep_case", {})
    want = spec.case_operating_point(case)
    return (sc.get("name") == case.name and meta.get("seed") == case.seed
            and sc.get("mesh") == normalised(mesh_key(spec.mesh))
            and op.get("speed_rpm") == want.speed_rpm and op.get("torque_nm") == want.torque_nm
            and op.get("radial_load_n") == want.radial_load_n
            and op.get("radial_load_angle_rad", want.radial_load_angle_rad)
            == want.radial_load_angle_rad
            and meta.get("fs_hz") == spec.fs_hz and meta.get("warmup_s") == spec.warmup_s
            and meta.get("substeps") == spec.substeps
            and abs(meta.get("duration_s", -1.0) - spec.duration_s) <= 0.5 / spec.fs_hz
            and normalised(meta.get("rig")) == normalised(spec.case_rig(case).to_dict())
            and [{k: v for k, v in f.items() if k != "label"} for f in meta.get("faults", [])]
            == normalised([f.to_dict() for f in spec.faults])
            and normalised((meta.get("losses") or {}).get("settings"))
            == normalised(spec.to_dict().get("losses")))
