"""Signal files of measured records: file I/O only (no metadata, no inference).

One reader per file type in :data:`READERS`, each ``reader(path, names) -> (signals,
rate_hz)``: ``signals`` maps a channel name to a float64 1-D array, ``rate_hz`` is the sample
rate the file itself stores (WAV) or None. Types today:

* ``.npz`` — one 1-D array per channel (keys = channel names; ``t``, ``meta`` and ``source``
  of a saved :class:`~cmsim.run.Run` are skipped; a column or row vector, shape (n, 1) or
  (1, n), is read as the 1-D channel it is; any other 2-D array is refused, never dropped);
* ``.csv`` — one column per channel, a header row of channel names;
* ``.wav`` — one channel per WAV channel, named by ``names`` (the entry's ``channels``) when
  they match in number, else ``ch0``, ``ch1``, ...; the WAV rate is the sample rate.

A new type (``.mat``, ``.uff``, ``.tdms``) is one function added to :data:`READERS`.
:func:`read_signals` turns whatever a reader raises on a damaged file (truncated, not of its
type) into one :class:`~cmsim.errors.ParameterError` naming the file.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from scipy.io import wavfile

from cmsim.errors import ParameterError

__all__ = ["READERS", "read_signals", "resolve_path"]

#: Array names of a saved run that are not channels.
_NOT_CHANNELS = ("t", "meta", "source")


def _channel_1d(path, name, a):
    """A stored array as a 1-D channel: (n,), (n, 1) and (1, n) are one channel; any other
    shape is refused (a silently dropped channel would let another one be compared)."""
    a = np.asarray(a)
    if a.ndim == 2 and 1 in a.shape:
        a = a.reshape(-1)
    if a.ndim != 1:
        raise ParameterError(f"record {path}: channel {name!r} has shape {a.shape}; store "
                             f"one 1-D array per channel (e.g. {name}_0, {name}_1, ... for "
                             f"the columns)", param="record", allowed="1-D arrays")
    return np.asarray(a, dtype=float)


def _read_npz(path, names=None):
    with np.load(path, allow_pickle=False) as z:
        return {k: _channel_1d(path, k, z[k]) for k in z.files if k not in _NOT_CHANNELS}, None


def _read_csv(path, names=None):
    import pandas as pd
    df = pd.read_csv(path)
    return {str(c): df[c].to_numpy(dtype=float) for c in df.columns}, None


def _read_wav(path, names=None):
    rate, x = wavfile.read(path)
    x = np.asarray(x, dtype=float)
    x = x[:, None] if x.ndim == 1 else x
    names = list(names or [])
    if len(names) != x.shape[1]:
        names = [f"ch{i}" for i in range(x.shape[1])]
    return {n: x[:, i] for i, n in enumerate(names)}, float(rate)


#: File suffix → reader ``(path, names) -> (signals, rate_hz or None)``.
READERS = {".npz": _read_npz, ".csv": _read_csv, ".wav": _read_wav}


def resolve_path(path):
    """The signal file ``path``, or ``$CMSIM_DATA/path`` for a relative path not found as is.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ParameterError
        The file exists in neither place.
    """
    p = Path(path)
    if p.exists():
        return p
    root = os.environ.get("CMSIM_DATA")
    if root and not p.is_absolute():
        q = Path(root) / p
        if q.exists():
            return q
    where = f" (nor under CMSIM_DATA={root})" if root else " (set CMSIM_DATA to a data root)"
    raise ParameterError(f"record {path} does not exist{where}", param="record",
                         allowed=f"an existing {', '.join(READERS)} file")


def read_signals(path, names=None):
    """Channels of a signal file.

    Parameters
    ----------
    path : pathlib.Path
        The file; its suffix selects the reader in :data:`READERS`.
    names : sequence of str, optional
        Channel names for formats that do not store them (WAV).

    Returns
    -------
    signals : dict of str to numpy.ndarray
        Channel name → float64 samples, shape (n,) each.
    rate_hz : float or None
        Sample rate stored in the file (WAV), Hz, else None.

    Raises
    ------
    ParameterError
        Unsupported file type; a file its reader cannot read (truncated, damaged, not of
        its type); a channel that is not 1-D.
    """
    path = Path(path)
    reader = READERS.get(path.suffix.lower())
    if reader is None:
        raise ParameterError(f"record {path}: unsupported file type {path.suffix!r}",
                             param="record", allowed=", ".join(READERS))
    try:
        return reader(path, names)
    except ParameterError:
        raise
    except Exception as exc:  # noqa: BLE001 - any reader failure is a damaged file
        detail = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise ParameterError(f"record {path}: cannot be read as a {path.suffix} file "
                             f"({type(exc).__name__}: {detail}); the file is truncated or "
                             f"damaged: copy or export it again", param="record",
                             allowed=f"a readable {path.suffix} file") from None
