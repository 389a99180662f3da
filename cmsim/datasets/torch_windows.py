"""A thin PyTorch dataset over a generated dataset: the windows of ``to_arrays``, one by one.

:class:`WindowDataset` is a map-style dataset (``len`` and ``[i]``) that a
``torch.utils.data.DataLoader`` batches, shuffles and spreads over workers. Item ``i`` is
window ``i`` of :meth:`cmsim.datasets.Dataset.to_arrays` with the same arguments — same
windowing code (:meth:`~cmsim.datasets.Dataset.record_windows`), same order, same default
channels (the measurable ones) — as ``(x, label_index, group)``: ``x`` a float32 tensor of
shape (channels, window), ``label_index`` the position of the window's label in
:attr:`WindowDataset.classes` (sorted labels of every record of the dataset, not only the
chosen ones, so a train and a test loader over parts of one dataset number the labels alike;
or the ``classes`` given), ``group`` the record id.

torch is imported when a dataset is made, not with this module: without it the constructor
raises one :class:`ModuleNotFoundError` naming the extra (``pip install cmsim[torch]``),
not the first item a DataLoader asks for.

>>> from torch.utils.data import DataLoader                       # doctest: +SKIP
>>> wins = WindowDataset("out/ci", window=2048)                   # doctest: +SKIP
>>> for x, y, group in DataLoader(wins, batch_size=32, shuffle=True):  # doctest: +SKIP
...     pass
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cmsim.datasets.load import Dataset, load
from cmsim.datasets.windows import check_window, check_window_fits, window_starts
from cmsim.errors import ParameterError

__all__ = ["WindowDataset"]


def _torch():
    """The torch module, or one error naming the extra that installs it."""
    try:
        import torch
    except ImportError:
        raise ModuleNotFoundError("cmsim.datasets.torch_windows.WindowDataset needs PyTorch, "
                                  "an optional dependency: pip install cmsim[torch]",
                                  name="torch") from None
    return torch


class WindowDataset:
    """The windows of :meth:`cmsim.datasets.Dataset.to_arrays` as a PyTorch dataset.

    Parameters
    ----------
    dataset : cmsim.datasets.Dataset or str or path-like
        A dataset or its directory.
    channels, window, hop, label, records, include_simulated
        As in :meth:`~cmsim.datasets.Dataset.to_arrays`.
    classes : sequence, optional
        The labels, in the order of the label indices (default: the sorted distinct labels
        of every ok record of the dataset, whatever ``records`` chooses). Each chosen
        record's label must be among them.
    cache_records : int
        Records kept in memory (read ones are reused while a DataLoader walks windows in
        order; with shuffling each item may read its record again).

    Attributes
    ----------
    channels : list of str
    classes : list
        The labels (default: sorted, of the whole dataset); an item's label index points
        into it.
    index : ndarray of int, shape (n_windows, 2)
        Per window: the record's position in the manifest and the window's start sample.
    """

    def __init__(self, dataset, channels=None, window=2048, hop=None, label="fault_label",
                 records=None, include_simulated=False, classes=None, cache_records=4):
        _torch()
        self.dataset = dataset if isinstance(dataset, Dataset) else load(Path(dataset))
        ds = self.dataset
        self.channels = ds.select_channels(channels, include_simulated)
        self.window, self.hop = check_window(window, hop)
        if label not in ds.manifest.columns:
            raise ParameterError(f"label must be a manifest column, got {label!r}",
                                 param="label")
        chosen = ds._select(records)
        parts = []
        for pos in chosen:
            n = ds.manifest["n_samples"].iloc[pos] if "n_samples" in ds.manifest.columns \
                else None
            rec = ds._record_at(pos)
            n = int(n) if n is not None and n == n else rec.signals[self.channels[0]].size
            check_window_fits(self.window, n, rec.record_id)
            starts = window_starts(n, self.window, self.hop)
            parts.append(np.column_stack([np.full(starts.size, pos), starts]))
        self.index = np.concatenate(parts) if parts else np.empty((0, 2), int)
        column = ds.manifest[label].to_numpy()
        if classes is None:
            self.classes = sorted({v for v in column[ds._select(None)]}, key=str)
        else:
            self.classes = list(classes)
            missing = sorted({str(v) for v in column[chosen] if v not in self.classes})
            if missing:
                raise ParameterError(f"classes {self.classes} lack the label(s) "
                                     f"{', '.join(missing)} of the chosen records",
                                     param="classes", allowed="every label of the records")
        self._label = {pos: self.classes.index(column[pos]) for pos in chosen}
        self._cache, self._cache_records = {}, max(1, int(cache_records))

    def __len__(self):
        """Number of windows."""
        return len(self.index)

    def _windows(self, pos):
        if pos not in self._cache:
            if len(self._cache) >= self._cache_records:
                self._cache.pop(next(iter(self._cache)))
            rec = self.dataset._record_at(pos)
            self._cache[pos] = (self.dataset.record_windows(rec, self.channels, self.window,
                                                            self.hop), rec.record_id)
        return self._cache[pos]

    def __getitem__(self, i):
        """``(x, label_index, group)`` of window ``i``: x a float32 tensor (channels, window).

        Parameters
        ----------
        i : int
            Window index, ``0 <= i < len(self)`` (negative counts from the end).
        """
        torch = _torch()
        n = len(self.index)
        if not -n <= int(i) < n:
            raise IndexError(f"window {i} out of range [0, {n})")
        pos, start = (int(v) for v in self.index[int(i)])
        windows, record_id = self._windows(pos)
        return (torch.from_numpy(np.ascontiguousarray(windows[start // self.hop])),
                self._label[pos], record_id)
