"""The one manifest of a dataset directory (a sweep's too): Parquet rows, sidecars, resume.

A directory made by :func:`cmsim.datasets.generate_dataset` holds

* ``DIR/dataset.json`` — the resolved spec and its digest (one spec per directory);
* ``DIR/records/<record_id>.npz`` — one file per record (:mod:`cmsim.datasets.records`);
* ``DIR/rows/<record_id>.json`` — the manifest row of a record, written by the worker right
  after its file (also for a failed record, with its error);
* ``DIR/manifest.parquet`` — every row, one per record (its id, index, seed, status and
  error, file path, size and SHA-256, every drawn setting, the answer key, the
  characteristic frequencies, the wall-time split; a full-run record also its features):
  the sidecars are folded into it at the end of a run and when one resumes, never after
  every record, so a 100 000-record dataset never rewrites a large file per record.

Every file is written atomically. Resuming: a record whose row says ``ok`` and whose file
has the recorded size (and SHA-256, with ``verify``), or whose row says ``failed``, is done;
a record file without a row (killed between the two writes) is adopted from the row kept in
its own meta. With ``force``, a directory of another spec keeps the records whose
:meth:`~cmsim.datasets.spec.DatasetSpec.record_key` the new spec gives again (a grid
extended by one value keeps its other points) and drops the rest.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
from pathlib import Path

import numpy as np

from cmsim._io import READ_ERRORS, atomic_write_bytes, atomic_write_text
from cmsim.errors import ParameterError

__all__ = ["PARQUET_NAME", "RECORDS_DIR", "ROWS_DIR", "SPEC_NAME", "FORMAT_VERSION",
           "file_sha256", "json_default", "write_row", "read_rows", "consolidate",
           "open_directory", "done_indices", "read_spec", "check_manifest"]

PARQUET_NAME = "manifest.parquet"
RECORDS_DIR = "records"
ROWS_DIR = "rows"
SPEC_NAME = "dataset.json"
#: ``dataset.json`` format and version this cmsim writes and reads.
FORMAT_VERSION = ("cmsim-dataset", 2)


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


def json_default(obj):
    """``json.dumps(..., default=json_default)`` of rows and record meta: a numpy scalar
    ``obj`` as the Python number it holds; anything else raises ``TypeError``."""
    if isinstance(obj, (np.floating, np.integer, np.bool_)):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def write_row(out_dir, row):
    """Write one record's row as its sidecar ``rows/<record_id>.json`` (atomically).

    The sidecar is not forced to the disk: the record's file, written and synced before it,
    keeps the same row in its meta, and a sidecar a machine crash left empty is skipped and
    the record adopted from its file (:func:`done_indices`); a failed record's lost row only
    runs it again.

    Parameters
    ----------
    out_dir : str or Path
        The dataset directory.
    row : dict
        The manifest row.
    """
    atomic_write_text(Path(out_dir) / ROWS_DIR / f"{row['record_id']}.json",
                      json.dumps(row, default=json_default, allow_nan=True), sync=False)


def read_spec(out_dir):
    """The ``dataset.json`` of a directory as a dict (``spec``, ``digest``), or None.

    Parameters
    ----------
    out_dir : str or Path
        The dataset directory.
    """
    try:
        return json.loads((Path(out_dir) / SPEC_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def read_rows(out_dir, known=None):
    """Every manifest row of ``out_dir`` as a DataFrame (Parquet plus unconsolidated
    sidecars; the latest row of a record wins), sorted by index; None if there is none.

    Parameters
    ----------
    out_dir : str or Path
        The dataset directory.
    known : DataFrame, optional
        Rows read before from the same directory (its Parquet file unchanged since): they
        stand in for the Parquet file, and only the sidecars are read.
    """
    import pandas as pd

    out = Path(out_dir)
    frames = []
    if known is not None:
        frames.append(known)
    elif (out / PARQUET_NAME).is_file():
        frames.append(_read_parquet(out / PARQUET_NAME))
    side = _read_sidecars(out)
    if side:
        frames.append(pd.DataFrame.from_records(side))
    if not frames:
        return None
    df = pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0]
    df = df.drop_duplicates("index", keep="last").sort_values("index", kind="stable")
    return df.reset_index(drop=True)


def check_manifest(out_dir):
    """Refuse a directory whose manifest file is corrupt or not a cmsim manifest, reading only
    its Parquet footer (the rows are read once, by the run): a resumed directory's manifest
    is input, checked before anything is computed.

    Parameters
    ----------
    out_dir : str or Path
        The dataset directory (nothing is checked where it holds no manifest).

    Raises
    ------
    ParameterError
        Naming the file and the fix (every finished record keeps its row in its own file,
        so removing the manifest loses nothing: the next run adopts the records).
    """
    path = Path(out_dir) / PARQUET_NAME
    if path.is_file():
        _manifest_columns(path, lambda: _schema_names(path))


def _schema_names(path):
    import pyarrow.parquet as pq
    return pq.read_schema(path).names


def _manifest_columns(path, read):
    """``read()``'s result, its columns checked; a failure is the ParameterError of
    :func:`check_manifest`."""
    from pyarrow import ArrowException

    try:
        out = read()
    except READ_ERRORS + (ArrowException,) as exc:
        detail = " ".join(str(exc).split())[:200]
        raise ParameterError(f"{path} is corrupt ({type(exc).__name__}: {detail}); remove "
                             f"it and run the command again on this directory: finished "
                             f"records are recovered from their files", param="out") from None
    columns = out if isinstance(out, list) else list(out.columns)
    missing = [c for c in ("record_id", "index", "status", "path") if c not in columns]
    if missing:
        raise ParameterError(f"{path} is not a cmsim manifest (no column {missing[0]!r}); "
                             f"remove it and run the command again on this directory: "
                             f"finished records are recovered from their files", param="out")
    return out


def _read_parquet(path):
    """The manifest file as a DataFrame (:func:`check_manifest`'s errors)."""
    import pandas as pd
    return _manifest_columns(path, lambda: pd.read_parquet(path))


def _read_sidecars(out):
    rows = []
    folder = out / ROWS_DIR
    if not folder.is_dir():
        return rows
    for entry in os.scandir(folder):
        if entry.name.endswith(".json") and not entry.name.startswith("."):
            try:
                with open(entry.path, encoding="utf-8") as fh:
                    rows.append(json.load(fh))
            except (OSError, ValueError):   # half-written by a killed worker: rerun it
                continue
    return rows


def _write_parquet(out, df):
    for col in df.columns:                 # mixed None/str columns stay strings
        if df[col].dtype == object and col not in ("runup",):
            df[col] = df[col].astype("string")
    buf = io.BytesIO()
    df.to_parquet(buf, engine="pyarrow", index=False)
    atomic_write_bytes(out / PARQUET_NAME, buf.getvalue())


def consolidate(out_dir, known=None):
    """Fold the sidecar rows into ``manifest.parquet`` (atomic), then remove them.

    Parameters
    ----------
    out_dir : str or Path
        The dataset folder.
    known : DataFrame, optional
        The directory's rows as :func:`read_rows` gave them earlier under the same
        directory lock (the Parquet file has not changed since): only the sidecars are read
        then, not the manifest again (a resumed 100 000-record dataset reads it once).

    Returns
    -------
    int
        The number of rows in the manifest.
    """
    out = Path(out_dir)
    names = [e.name for e in os.scandir(out / ROWS_DIR)] if (out / ROWS_DIR).is_dir() else []
    names = [n for n in names if n.endswith(".json") and not n.startswith(".")]
    if not names and (out / PARQUET_NAME).is_file():
        if known is not None:
            return len(known)
        import pyarrow.parquet as pq
        return pq.ParquetFile(out / PARQUET_NAME).metadata.num_rows
    df = read_rows(out, known)
    if df is None:
        return 0
    _write_parquet(out, df)
    for n in names:
        (out / ROWS_DIR / n).unlink(missing_ok=True)
    return len(df)


def _spec_difference(a, b):
    """Names of what differs between two stored specs (settings by name)."""
    out = []
    for key in sorted(set(a) | set(b)):
        x, y = a.get(key), b.get(key)
        if x == y:
            continue
        if key == "settings" and isinstance(x, list) and isinstance(y, list):
            sx = {s.get("name"): s for s in x if isinstance(s, dict)}
            sy = {s.get("name"): s for s in y if isinstance(s, dict)}
            names = [n for n in dict.fromkeys([*sy, *sx]) if sx.get(n) != sy.get(n)]
            out += [f"settings: {n}" for n in names] or ["settings: order"]
        else:
            out.append(key)
    return out or ["format"]


def open_directory(spec, out_dir, force):
    """Check (or write) ``dataset.json``: one spec per directory.

    A directory of another spec is an error unless ``force``; then its records that ``spec``
    makes again (same record key) are kept under the new spec and the others removed.

    Parameters
    ----------
    spec : DatasetSpec
        The spec to run.
    out_dir : str or Path
        The dataset directory (exists).
    force : bool
        Replace a dataset of a different spec.

    Returns
    -------
    int
        Records kept from a dataset of another spec (``force``).
    """
    out = Path(out_dir)
    fmt, version = FORMAT_VERSION
    mine = {"format": fmt, "version": version, "digest": spec.digest,
            "spec": json.loads(json.dumps(spec.to_dict(), default=str))}
    old = read_spec(out)
    if old is not None and old.get("digest") != spec.digest:
        if not force:
            diff = _spec_difference(old.get("spec", {}), mine["spec"])
            raise ParameterError(f"{out} holds a dataset of a different spec (differs in "
                                 f"{', '.join(diff)}); use another directory, or force=True "
                                 f"to replace it", param="out")
        kept = _keep_matching(spec, out)
    else:
        kept = 0
    atomic_write_text(out / SPEC_NAME, json.dumps(mine, indent=1) + "\n")
    return kept


def _keep_matching(spec, out):
    """Under ``force``: rows of records ``spec`` makes again move to it; the rest go."""
    df = read_rows(out)
    keep = []
    if df is not None and "record_key" in df:
        for pos, (i, rid, key, st) in enumerate(zip(df["index"], df["record_id"],
                                                    df["record_key"], df["status"])):
            if st == "ok" and 0 <= int(i) < spec.n_records:
                plan = spec.record(int(i))
                if plan.record_id == rid and spec.record_key(plan) == key:
                    keep.append(pos)
    kept = df.iloc[keep].copy() if keep else None
    names = set() if kept is None else set(kept["record_id"])
    for sub in (RECORDS_DIR, ROWS_DIR):
        for p in (out / sub).glob("*"):
            if p.stem not in names or sub == ROWS_DIR:
                p.unlink()
    (out / PARQUET_NAME).unlink(missing_ok=True)
    if kept is not None:
        kept["spec_digest"] = spec.digest
        kept["adopted"] = True
        _write_parquet(out, kept.reset_index(drop=True))
    return len(keep)


def done_indices(spec, out_dir, verify, rows=None):
    """Indices already done in ``out_dir`` (ok with their file intact, or failed), and how
    many were adopted from record files without a row.

    Parameters
    ----------
    spec : DatasetSpec
        The spec being run.
    out_dir : str or Path
        The dataset directory.
    verify : bool
        Also compare every ok file's SHA-256 with its row (reads every file).
    rows : DataFrame, optional
        The directory's rows, already read (:func:`read_rows`); read here when not given.

    Returns
    -------
    done : set of int
    adopted : int
    """
    out = Path(out_dir)
    df = read_rows(out) if rows is None else rows
    done, seen = set(), set()
    if df is not None:
        df = df[df["spec_digest"] == spec.digest] if "spec_digest" in df else df.iloc[:0]
        sizes = df["bytes"].to_numpy() if "bytes" in df else np.full(len(df), np.nan)
        sums = df["sha256"].to_numpy() if "sha256" in df else [None] * len(df)
        for i, st, p, size, digest in zip(df["index"].to_numpy(), df["status"].to_numpy(),
                                           df["path"].to_numpy(), sizes, sums):
            if int(i) >= spec.n_records:
                continue
            if st == "failed":
                done.add(int(i))
                seen.add(os.path.basename(p))
            elif st == "ok":
                try:
                    ok = os.stat(out / p).st_size == size
                except OSError:
                    ok = False
                if ok and verify:
                    ok = file_sha256(out / p) == digest
                if ok:
                    done.add(int(i))
                    seen.add(os.path.basename(p))
    adopted = 0
    for entry in os.scandir(out / RECORDS_DIR):
        name = entry.name
        if not name.endswith(".npz") or name.startswith(".") or name in seen:
            continue
        row = _row_in_file(Path(entry.path), spec)
        if row is None or row["index"] in done or row["index"] >= spec.n_records:
            continue
        row["adopted"] = True
        write_row(out, row)
        done.add(int(row["index"]))
        adopted += 1
    return done, adopted


def _row_in_file(path, spec):
    """The row kept in a complete record file of ``spec``, or None."""
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            row = meta["row"]
            if row.get("spec_digest") != spec.digest or f"{row['record_id']}.npz" != path.name:
                return None
            for c in z.files:              # every array readable (CRC checked)
                z[c]
    except Exception:                      # noqa: BLE001 - unreadable or foreign: rerun it
        return None
    row["bytes"] = path.stat().st_size
    row["sha256"] = file_sha256(path)
    return row
