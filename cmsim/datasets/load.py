"""Read a generated dataset: :func:`load` → :class:`Dataset` (manifest, lazy records, arrays).

>>> ds = load("out/ci")                                          # doctest: +SKIP
>>> ds.manifest.groupby("fault_label").size()                    # doctest: +SKIP
>>> X, y, groups = ds.to_arrays(["accel_1b1_y"], window=2048)    # doctest: +SKIP
>>> ds.to_parquet("windows.parquet", window=2048)                # doctest: +SKIP

Signals are read only when asked for (a record's file is opened when one of its signals is
accessed), so a dataset larger than memory can be explored from a notebook; for training,
:meth:`Dataset.iter_arrays` yields fixed-size batches of windows, and :meth:`Dataset.to_arrays`
takes a subset of records; :meth:`Dataset.to_parquet` writes the same windows as one Parquet
table (:mod:`cmsim.datasets.windows`) and :class:`cmsim.datasets.torch_windows.WindowDataset`
serves them to a PyTorch ``DataLoader``. All of them cut records through
:meth:`Dataset.record_windows` and default to the channels a real machine could measure
(:meth:`Dataset.to_arrays`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from cmsim._io import READ_ERRORS
from cmsim.datasets.manifest import PARQUET_NAME, SPEC_NAME, read_rows
from cmsim.errors import ParameterError
from cmsim.frequencies import rig_frequencies
from cmsim.rig import OperatingPoint, Rig
from cmsim.datasets.windows import (check_window, check_window_fits, to_parquet,
                                    window_starts)
from cmsim.run import is_measurable, signal_info

__all__ = ["load", "Dataset", "DatasetRecord"]


def _read_record_file(path, read):
    """``read(z)`` of the record file ``path`` opened as ``z`` (:func:`numpy.load`); a file
    missing, cut short or corrupt is a :class:`~cmsim.errors.ParameterError` naming it.

    Parameters
    ----------
    path : pathlib.Path
        The record's ``.npz`` file.
    read : callable
        ``read(z) -> value``, e.g. ``lambda z: z["accel_1b1_y"]``.
    """
    try:
        with np.load(path, allow_pickle=False) as z:
            return read(z)
    except READ_ERRORS as exc:
        why = "missing" if isinstance(exc, FileNotFoundError) else \
            f"unreadable ({type(exc).__name__}: {' '.join(str(exc).split())})"
        raise ParameterError(f"record file {path} is {why}; make it again: cmsim dataset "
                             f"SPEC --out {Path(path).parent.parent} --verify",
                             param="record_file") from None


class _LazySignals(Mapping):
    """Mapping name → float32 array, read from the record file on access."""

    def __init__(self, path, names):
        self._path, self._names = path, tuple(names)

    def __getitem__(self, name):
        if name not in self._names:
            raise KeyError(f"no channel {name!r}; available: {list(self._names)}")
        return _read_record_file(self._path, lambda z: z[name])

    def __iter__(self):
        return iter(self._names)

    def __len__(self):
        return len(self._names)


class DatasetRecord:
    """One record of a generated dataset, as loaded (what its spec drew for it is a
    :class:`~cmsim.datasets.plan.RecordPlan`).

    Attributes
    ----------
    record_id : str
    row : dict
        Its manifest row.
    signals : Mapping of str to ndarray
        The channels, float32, read lazily.
    fs_hz : float
        Sample rate, Hz.
    """

    def __init__(self, directory, row, channels, fs_hz):
        self.record_id = str(row["record_id"])
        self.row = row
        self.fs_hz = float(fs_hz)
        self._path = Path(directory) / row["path"]
        self.signals = _LazySignals(self._path, channels)
        self._meta = None

    def __repr__(self):
        return f"DatasetRecord({self.record_id!r}, {self.row.get('fault_label')!r})"

    @property
    def meta(self):
        """The record's stored meta (rig, operating point, faults, answer key, timing)."""
        if self._meta is None:
            self._meta = _read_record_file(self._path, lambda z: json.loads(str(z["meta"])))
        return self._meta

    @property
    def operating_point(self):
        """:class:`~cmsim.rig.OperatingPoint` (the start speed of a run-up)."""
        r = self.row
        return OperatingPoint(speed_rpm=float(r["speed_rpm"]),
                              torque_nm=float(r.get("torque_nm", 0.0) or 0.0),
                              radial_load_n=float(r.get("radial_load_n", 0.0) or 0.0))

    @property
    def rig(self):
        """The record's :class:`~cmsim.rig.Rig` (with its drawn friction and clearance)."""
        return Rig.from_dict(self.meta["rig"])

    @property
    def frequencies(self):
        """:class:`~cmsim.frequencies.RigFrequencies` of the rig at the operating point."""
        return rig_frequencies(self.rig, self.operating_point)

    @property
    def labels(self):
        """The answer key: fault_label, fault_component, fault_severity, faults."""
        return dict(self.meta["labels"])


class Dataset:
    """A generated dataset directory (see :func:`load`).

    Attributes
    ----------
    directory : Path
    manifest : pandas.DataFrame
        One row per record (failed ones included, ``status == "failed"``).
    channels : tuple of str
        The spec's channels (a sweep's records: every signal of its runs).
    fs_hz : float
    spec : dict
        The resolved spec (``dataset.json``).
    """

    def __init__(self, directory):
        self.directory = Path(directory)
        try:
            info = json.loads((self.directory / SPEC_NAME).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            raise ParameterError(f"{self.directory} is not a cmsim dataset (no readable "
                                 f"{SPEC_NAME})", param="dir") from None
        self.spec = info["spec"]
        df = read_rows(self.directory)
        if df is None:
            raise ParameterError(f"{self.directory} has no records yet ({PARQUET_NAME})",
                                 param="dir")
        self.manifest = df
        self.fs_hz = float(self.spec["fs_hz"])
        self._ok = df.index[df["status"] == "ok"].to_numpy()
        if self.spec.get("channels") is not None:
            self.channels = tuple(self.spec["channels"])
        elif len(self._ok):                # full runs (a sweep): the first record's signals
            self.channels = _read_record_file(
                self.directory / df["path"].iloc[self._ok[0]],
                lambda z: tuple(k for k in z.files if k not in ("t", "meta", "source")))
        else:
            self.channels = ()

    def __len__(self):
        """Number of ok records."""
        return len(self._ok)

    def __iter__(self):
        for i in self._ok:
            yield self._record_at(i)

    def _record_at(self, pos):
        row = {k: (None if isinstance(v, float) and math.isnan(v) else v)
               for k, v in self.manifest.iloc[int(pos)].to_dict().items()}
        return DatasetRecord(self.directory, row, self.channels, row.get("fs_hz") or self.fs_hz)

    def record(self, key):
        """A record by ``record_id`` (str) or record index (int).

        Parameters
        ----------
        key : str or int
            The record's id or index.

        Returns
        -------
        DatasetRecord
        """
        col = "record_id" if isinstance(key, str) else "index"
        hits = np.flatnonzero(self.manifest[col].to_numpy() == key)
        if hits.size == 0:
            raise KeyError(f"no record {key!r}")
        pos = hits[0]
        if self.manifest["status"].iloc[pos] != "ok":
            raise KeyError(f"record {key!r} failed: {self.manifest['error'].iloc[pos]}")
        return self._record_at(pos)

    def _select(self, records):
        if records is None:
            return list(self._ok)
        out = []
        for key in records:
            col = "record_id" if isinstance(key, str) else "index"
            hits = np.flatnonzero((self.manifest[col].to_numpy() == key)
                                  & (self.manifest["status"].to_numpy() == "ok"))
            if hits.size == 0:
                raise KeyError(f"no ok record {key!r}")
            out.append(int(hits[0]))
        return out

    def iter_arrays(self, channels=None, window=2048, hop=None, label="fault_label",
                    records=None, batch_records=64, include_simulated=False):
        """Yield ``(X, y, groups)`` batches of windows, ``batch_records`` records at a time
        (memory bounded by one batch); same layout and channel rule as :meth:`to_arrays`.

        Parameters
        ----------
        channels, window, hop, label, records, include_simulated
            As in :meth:`to_arrays`.
        batch_records : int
            Records per batch.

        Yields
        ------
        tuple
            ``(X, y, groups)`` of one batch.
        """
        channels = self.select_channels(channels, include_simulated)
        window, hop = check_window(window, hop)
        if label not in self.manifest.columns:
            raise ParameterError(f"label must be a manifest column, got {label!r}",
                                 param="label")
        chosen = self._select(records)
        if "n_samples" in self.manifest.columns and chosen:
            lengths = self.manifest["n_samples"].to_numpy()[chosen]
            shortest = int(np.argmin(lengths))
            check_window_fits(window, int(lengths[shortest]),
                               self.manifest["record_id"].iloc[chosen[shortest]])
        for start in range(0, len(chosen), int(batch_records)):
            xs, ys, gs = [], [], []
            for pos in chosen[start:start + int(batch_records)]:
                rec = self._record_at(pos)
                w = self.record_windows(rec, channels, window, hop)
                xs.append(w)
                ys.append(np.repeat(np.asarray([rec.row[label]], dtype=object), len(w)))
                gs.append(np.repeat(np.asarray([rec.record_id]), len(w)))
            if xs:
                yield (np.concatenate(xs), np.concatenate(ys), np.concatenate(gs))

    def record_windows(self, record, channels, window, hop):
        """THE windowing of a record (:meth:`iter_arrays`, :meth:`to_arrays`, the Parquet
        export and the PyTorch dataset all cut through it): windows of ``window`` samples
        starting every ``hop`` samples from the first, the last one ending at or before the
        record's end (a shorter tail is dropped).

        Parameters
        ----------
        record : DatasetRecord
        channels : sequence of str
            Channel names, in the order of the output's axis 1 (not checked here).
        window, hop : int
            Samples per window and between window starts.

        Returns
        -------
        ndarray, float32, shape (n_windows, n_channels, window)
        """
        sig = _read_record_file(record._path, lambda z: np.stack([z[c] for c in channels]))
        sig = sig.astype(np.float32, copy=False)
        check_window_fits(window, sig.shape[1], record.record_id)
        idx = window_starts(sig.shape[1], window, hop)[:, None] + np.arange(window)[None, :]
        return np.transpose(sig[:, idx], (1, 0, 2))

    def to_arrays(self, channels=None, window=2048, hop=None, label="fault_label",
                  records=None, include_simulated=False):
        """Windows of every (or the given) ok record as arrays.

        Channel rule (sim-to-real): by default only the channels a real machine could
        measure — housing accelerations ``accel_*``, the ``tacho`` and a calibrated machine's
        own sensor channel (:func:`cmsim.run.is_measurable`). Simulated-only signals (``dte``,
        ``dte_um``, bearing and mesh forces ``F_*``, ``Fmesh_*``, displacements, rotations)
        come only when asked for, by name in ``channels`` or with ``include_simulated``, so a
        model trained on the defaults never sees what a real machine cannot give it.

        Parameters
        ----------
        channels : sequence of str, optional
            Channels to stack, in this order (default: the dataset's measurable channels).
        window : int
            Samples per window.
        hop : int, optional
            Samples between window starts (default ``window``: no overlap).
        label : str
            Manifest column giving ``y``.
        records : sequence of str or int, optional
            Record ids or indices (default every ok record).
        include_simulated : bool
            With ``channels`` None: every channel of the dataset, simulated-only ones too.

        Returns
        -------
        X : ndarray, float32, shape (n_windows, n_channels, window)
        y : ndarray, shape (n_windows,)
            The record's ``label`` value per window.
        groups : ndarray of str, shape (n_windows,)
            Record id per window: windows of one record share a group, so a grouped split
            (``sklearn.model_selection.GroupKFold``) never puts one record in two sets.
        """
        parts = list(self.iter_arrays(channels, window, hop, label, records, batch_records=256,
                                      include_simulated=include_simulated))
        channels = self.select_channels(channels, include_simulated)
        if not parts:
            return (np.empty((0, len(channels), int(window)), np.float32),
                    np.empty(0, object), np.empty(0, str))
        return tuple(np.concatenate(p) for p in zip(*parts))

    def to_parquet(self, path, window=2048, hop=None, channels=None, include_simulated=False,
                   **options):
        """Write the windowed Parquet layout (:func:`cmsim.datasets.windows.to_parquet`).

        Parameters
        ----------
        path : str or path-like
            The ``.parquet`` file (written atomically).
        window, hop, channels, include_simulated
            As in :meth:`to_arrays`.
        **options
            ``group_by``, ``seed``, ``fractions``, ``batch_records`` of
            :func:`~cmsim.datasets.windows.to_parquet`.

        Returns
        -------
        dict
            What was written (:func:`~cmsim.datasets.windows.to_parquet`).
        """
        return to_parquet(self, path, window=window, hop=hop, channels=channels,
                          include_simulated=include_simulated, **options)

    def unit(self, channel):
        """Unit of a channel's samples (``"m/s²"``, ``"V"``, ``"µm"``, ...; a calibrated
        machine's channel: the machine's unit; ``""`` when unknown).

        Parameters
        ----------
        channel : str
        """
        try:
            return signal_info(channel).unit
        except ParameterError:
            machine = (self.spec.get("machine") or {}).get("machine") or {}
            return str(machine.get("unit") or "") if machine.get("channel") == channel else ""

    def select_channels(self, channels=None, include_simulated=False):
        """The channels :meth:`to_arrays` stacks (its channel rule), checked.

        Parameters
        ----------
        channels : str or sequence of str, optional
            Names asked for (each must be in :attr:`channels`); None: the default.
        include_simulated : bool
            With ``channels`` None: every channel, not only the measurable ones.

        Returns
        -------
        list of str
        """
        if channels is None:
            chosen = [c for c in self.channels if include_simulated or is_measurable(c)]
            if not chosen:
                raise ParameterError(
                    f"channels: this dataset has no channel a real machine could measure "
                    f"(accelerations, tacho); ask for simulated ones by name or with "
                    f"include_simulated=True; available: {list(self.channels)}",
                    param="channels")
            return chosen
        channels = [channels] if isinstance(channels, str) else list(channels)
        if not channels:
            raise ParameterError(f"channels must name at least one channel; available: "
                                 f"{list(self.channels)}", param="channels")
        for c in channels:
            if c not in self.channels:
                raise ParameterError(f"channels: {c!r} is not in this dataset "
                                     f"{list(self.channels)}", param="channels")
        return channels


def load(directory):
    """Open a dataset made by :func:`cmsim.datasets.generate_dataset` / ``cmsim dataset``.

    Parameters
    ----------
    directory : str or path-like

    Returns
    -------
    Dataset
    """
    return Dataset(directory)
