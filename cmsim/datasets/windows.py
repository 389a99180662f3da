"""Windows of a dataset: THE window rule (:func:`window_starts` and its checks), the
train/val/test split of groups (:func:`split_of`), and the windowed Parquet layout
(:func:`to_parquet`): one row per window, ready for ML loaders.

The windows are those of :meth:`cmsim.datasets.Dataset.to_arrays` (the file is written from
:meth:`~cmsim.datasets.Dataset.iter_arrays`, batch by batch, one Parquet row group per batch,
so memory stays bounded by one batch), with the same default channels: the ones a real
machine could measure (:func:`cmsim.run.is_measurable`).

Columns
-------
* one column per channel, named after it (``accel_1b1_y``, ``tacho``): the window's samples,
  ``list<float32>`` of ``window`` values. One column per channel rather than one list of
  lists: the columns say which channel is which, a reader loads only the channels it asks for
  (``pandas.read_parquet(path, columns=[...])`` reads no other bytes), and the HuggingFace
  ``datasets`` Parquet loader maps each to ``Sequence(float32)``;
* ``record_id``, ``window_index`` (int, from 0 in each record), ``start_s`` (window start, s);
* ``label`` (the manifest's ``fault_label``), ``fault_component``, ``severity`` (the
  manifest's ``fault_severity``, the fault's main size in SI; null when healthy);
* ``speed_rpm``, ``torque_nm``, ``radial_load_n`` (operating point), ``fs_hz`` (Hz);
* ``group`` and ``split``: see below.

The Parquet schema metadata key ``cmsim`` holds JSON: the channels and their units, window,
hop, ``group_by``, seed, fractions and the split rule.

Groups and splits
-----------------
``group`` is the value of the manifest column ``group_by`` (default ``record_id``: every
record is its own simulated machine; name another column, e.g. ``rig_name``, when records
share one). ``split`` (``train``, ``val`` or ``test``) is a function of the group, the seed and
the fractions alone (:func:`split_of`), so windows of one record (or machine) never straddle
two splits, and a record keeps its split when the dataset grows or is exported again.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write
from cmsim.errors import ParameterError

__all__ = ["to_parquet", "split_of", "check_fractions", "window_starts", "check_window",
           "check_window_fits", "SPLITS"]

#: Split names, in the order of the fractions.
SPLITS = ("train", "val", "test")

#: Manifest columns copied to every window row: (manifest column, Parquet column).
_ROW_COLUMNS = (("fault_label", "label"), ("fault_component", "fault_component"),
                ("fault_severity", "severity"), ("speed_rpm", "speed_rpm"),
                ("torque_nm", "torque_nm"), ("radial_load_n", "radial_load_n"))


def window_starts(n_samples, window, hop):
    """Start sample of every window of a record (the rule of :meth:`Dataset.record_windows`).

    Parameters
    ----------
    n_samples, window, hop : int
        Record length, samples per window, samples between starts.

    Returns
    -------
    ndarray of int, shape (max(0, (n_samples - window) // hop + 1),)

    Examples
    --------
    >>> window_starts(10, 4, 3).tolist()
    [0, 3, 6]
    """
    n = max(0, (int(n_samples) - int(window)) // int(hop) + 1)
    return int(hop) * np.arange(n)


def check_window(window, hop):
    """``(window, hop)`` as ints, each a positive integer (``hop`` None: ``window``).

    Parameters
    ----------
    window : int
        Samples per window.
    hop : int or None
        Samples between window starts.
    """
    hop = window if hop is None else hop
    for name, v in (("window", window), ("hop", hop)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ParameterError(f"{name} must be a positive integer, got {v!r}", param=name)
    return int(window), int(hop)


def check_window_fits(window, n_samples, record_id):
    """A window no longer than a record: else no window would come out of it.

    Parameters
    ----------
    window, n_samples : int
        Samples per window and of the record.
    record_id : str
        The record, for the message.
    """
    if window > n_samples:
        raise ParameterError(f"window must be at most the record length, {n_samples} samples "
                             f"(record {record_id}), got {window}", param="window",
                             allowed=f"<= {n_samples}")


def check_fractions(fractions):
    """``fractions`` (train, val, test) as floats, each in [0, 1], summing to 1.

    Parameters
    ----------
    fractions : sequence of 3 float

    Returns
    -------
    tuple of float
    """
    try:
        f = tuple(float(v) for v in fractions)
    except (TypeError, ValueError):
        f = ()
    if len(f) != 3 or not all(math.isfinite(v) and 0 <= v <= 1 for v in f) \
            or abs(sum(f) - 1) > 1e-9:
        raise ParameterError(f"fractions must be three numbers in [0, 1] (train, val, test) "
                             f"summing to 1, got {fractions!r}", param="fractions",
                             allowed="3 numbers in [0, 1] summing to 1")
    return f


def split_of(group, seed=0, fractions=(0.8, 0.1, 0.1)):
    """The split of a group: ``u`` = the first 8 bytes of SHA-256(``"<seed>:<group>"``) read
    as an unsigned integer over 2⁶⁴, uniform in [0, 1); ``train`` if ``u`` < f_train, ``val``
    if ``u`` < f_train + f_val, else ``test``. It depends on nothing else (not the order or
    number of records), so the fractions are met on average, not exactly.

    Parameters
    ----------
    group : str
        The group (a record id by default).
    seed : int
        Seed of the split (another seed, another draw of the groups).
    fractions : sequence of 3 float
        Expected shares of train, val, test (:func:`check_fractions`).

    Returns
    -------
    str
        One of :data:`SPLITS`.

    Examples
    --------
    >>> split_of("000003") == split_of("000003")
    True
    >>> split_of("000003", fractions=(0, 0, 1))
    'test'
    """
    f = check_fractions(fractions)
    digest = hashlib.sha256(f"{int(seed)}:{group}".encode("utf-8")).digest()
    u = int.from_bytes(digest[:8], "big") / 2.0 ** 64
    edges = np.cumsum(f)
    for name, edge in zip(SPLITS, edges):
        if u < edge:
            return name
    return SPLITS[-1]


def _schema(channels, meta):
    import pyarrow as pa
    fields = [(c, pa.list_(pa.float32())) for c in channels]
    fields += [("record_id", pa.string()), ("window_index", pa.int32()),
               ("start_s", pa.float64()), ("label", pa.string()),
               ("fault_component", pa.string()), ("severity", pa.float64()),
               ("speed_rpm", pa.float64()), ("torque_nm", pa.float64()),
               ("radial_load_n", pa.float64()), ("fs_hz", pa.float64()),
               ("group", pa.string()), ("split", pa.string())]
    return pa.schema(fields, metadata={"cmsim": json.dumps(meta)})


def _text(v):
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else str(v)


def _number(v):
    return math.nan if v is None else float(v)


def _record_values(ds, record_id, group_by, seed, fractions):
    """The manifest values every window of a record carries, with its group and split."""
    row = ds.record(str(record_id)).row
    values = {dst: (_text if dst in ("label", "fault_component") else _number)(row.get(src))
              for src, dst in _ROW_COLUMNS}
    group = str(row[group_by])
    return {**values, "fs_hz": float(row.get("fs_hz") or ds.fs_hz), "group": group,
            "split": split_of(group, seed, fractions)}


def _batch_table(ds, schema, channels, X, groups_rid, hop, group_by, seed, fractions):
    """One row group: the windows ``X`` of a batch of :meth:`Dataset.iter_arrays`."""
    import pyarrow as pa
    n, _, window = X.shape
    cols = {}
    offsets = pa.array(np.arange(n + 1, dtype=np.int32) * window)
    for k, c in enumerate(channels):
        cols[c] = pa.ListArray.from_arrays(offsets, pa.array(X[:, k, :].reshape(-1)))
    per_record = {}
    index, start, out = [], [], {dst: [] for _, dst in _ROW_COLUMNS}
    out.update(fs_hz=[], group=[], split=[])
    last, k = None, 0
    for rid in groups_rid:
        k = k + 1 if rid == last else 0
        last = rid
        if rid not in per_record:
            per_record[rid] = _record_values(ds, rid, group_by, seed, fractions)
        values = per_record[rid]
        index.append(k)
        start.append(k * hop / values["fs_hz"])
        for key, column in out.items():
            column.append(values[key])
    cols.update(record_id=[str(r) for r in groups_rid], window_index=index, start_s=start,
                **out)
    return pa.Table.from_pydict(cols, schema=schema)


def to_parquet(dataset, path, window=2048, hop=None, channels=None, include_simulated=False,
               group_by="record_id", seed=0, fractions=(0.8, 0.1, 0.1), batch_records=16):
    """Write the windows of a dataset as one Parquet file (module docstring), atomically.

    Parameters
    ----------
    dataset : cmsim.datasets.Dataset
        The dataset (``cmsim.datasets.load(DIR)``).
    path : str or path-like
        The ``.parquet`` file; an interrupted write leaves no file.
    window, hop, channels, include_simulated
        As in :meth:`cmsim.datasets.Dataset.to_arrays` (default channels: measurable ones).
    group_by : str
        Manifest column whose value is a window's ``group``.
    seed : int
        Seed of :func:`split_of`.
    fractions : sequence of 3 float
        Expected train, val, test shares of the groups.
    batch_records : int
        Records per Parquet row group (memory holds one batch).

    Returns
    -------
    dict
        ``path``, ``rows`` (windows), ``records``, ``row_groups``, ``channels``, ``units``,
        ``window``, ``hop``, ``group_by``, ``seed``, ``fractions``, ``splits`` (windows per
        split) and ``groups`` (groups per split).
    """
    import pyarrow.parquet as pq

    ds = dataset
    channels = ds.select_channels(channels, include_simulated)
    fractions = check_fractions(fractions)
    if group_by not in ds.manifest.columns:
        raise ParameterError(f"group_by must be a manifest column {list(ds.manifest.columns)}, "
                             f"got {group_by!r}", param="group_by")
    if isinstance(batch_records, bool) or not isinstance(batch_records, (int, np.integer)) \
            or batch_records < 1:
        raise ParameterError(f"batch_records must be a positive integer, got "
                             f"{batch_records!r}", param="batch_records")
    window, hop = check_window(window, hop)
    batches = ds.iter_arrays(channels, window, hop, records=None,
                             batch_records=int(batch_records))
    units = {c: ds.unit(c) for c in channels}
    meta = {"channels": channels, "units": units, "window": int(window), "hop": hop,
            "group_by": group_by, "seed": int(seed), "fractions": list(fractions),
            "split_rule": "sha256('<seed>:<group>')[:8] / 2**64 against cumulative fractions",
            "dataset": str(ds.spec.get("name") or ds.directory.name)}
    schema = _schema(channels, meta)
    counts = {s: 0 for s in SPLITS}
    groups = {s: set() for s in SPLITS}
    stats = {"rows": 0, "row_groups": 0, "records": set()}

    def write(fh):
        with pq.ParquetWriter(fh, schema) as writer:
            for X, _, rids in batches:
                table = _batch_table(ds, schema, channels, X, rids, hop, group_by, seed,
                                     fractions)
                writer.write_table(table)
                stats["rows"] += table.num_rows
                stats["row_groups"] += 1
                stats["records"].update(rids.tolist())
                for g, s in zip(table.column("group").to_pylist(),
                                table.column("split").to_pylist()):
                    counts[s] += 1
                    groups[s].add(g)

    atomic_write(Path(path), write)
    return {"path": str(path), "rows": stats["rows"], "records": len(stats["records"]),
            "row_groups": stats["row_groups"], "channels": channels, "units": units,
            "window": int(window), "hop": hop, "group_by": group_by, "seed": int(seed),
            "fractions": list(fractions), "splits": counts,
            "groups": {s: len(g) for s, g in groups.items()}}
