"""Signal files of measured records: file I/O only (no metadata, no inference).

One module per file type, each with ``read(path, names)`` returning a :class:`SignalFile` —
the channels (name → float64 1-D array, in the file's physical unit) and what the file
itself states: sample rate, unit of each channel, shaft speed, WAV calibration factor (each
None when the file is silent on it) — and ``write(path, signals, rate_hz, units)`` beside it,
so the rate and unit conventions of a format are written once, and a file cmsim writes reads
back the same. :data:`READERS` and :data:`WRITERS` map a suffix to them; :func:`read_file`
also takes a reader that returns the older pair ``(signals, rate_hz)``.

Types, and what each states (each module's docstring gives the layout):

* :mod:`~cmsim.measured.readers.npz` — ``.npz``: arrays by channel name, ``fs_hz``, ``units``;
* :mod:`~cmsim.measured.readers.csv` — ``.csv``: a header row (``name [unit]``), a time
  column, or no header at all;
* :mod:`~cmsim.measured.readers.wav` — ``.wav``: the header rate, cmsim's ``LIST/INFO``
  comment (names, units, calibration);
* :mod:`~cmsim.measured.readers.mat` — ``.mat`` (v4–v7.2, v7.3 through h5py): variables,
  matrices, a time vector, ``XnnnRPM``, ``fs``;
* :mod:`~cmsim.measured.readers.uff` — ``.uff`` / ``.unv``: type-58 sets (pyuff);
* :mod:`~cmsim.measured.readers.tdms` — ``.tdms``: NI TDMS channels (npTDMS).

What they share (:class:`SignalFile`, 1-D channels, rates from a step or a time base, an
optional library named by its extra) is in :mod:`~cmsim.measured.readers._common`.
:func:`read_file` turns whatever a reader raises on a damaged file (truncated, not of its
type) into one :class:`~cmsim.errors.ParameterError` naming the file; a missing optional
library is one line naming the extra to install.
"""

from __future__ import annotations

import math
import os
import warnings
from pathlib import Path

import numpy as np

from cmsim.errors import ParameterError, RecordWarning
from cmsim.measured.readers import csv, mat, npz, tdms, uff, wav
from cmsim.measured.readers._common import SignalFile
from cmsim.measured.readers.npz import npz_names

__all__ = ["READERS", "WRITERS", "SignalFile", "read_file", "read_signals", "resolve_path",
           "write_signals", "is_cmsim_run", "npz_names"]

#: File suffix → reader ``(path, names) -> SignalFile`` (or ``(signals, rate_hz)``).
READERS = {".npz": npz.read, ".csv": csv.read, ".wav": wav.read, ".mat": mat.read,
           ".uff": uff.read, ".unv": uff.read, ".tdms": tdms.read}

#: File suffix → writer ``(path, signals, rate_hz, units)``, beside each reader.
WRITERS = {".npz": npz.write, ".csv": csv.write, ".wav": wav.write, ".mat": mat.write,
           ".uff": uff.write, ".unv": uff.write, ".tdms": tdms.write}


def is_cmsim_run(path):
    """Whether ``path`` is a file cmsim wrote (a run of ``cmsim simulate``/``sweep`` or a
    ``cmsim dataset`` record): an ``.npz`` holding a ``meta`` array. Such a file states its
    own rate, speed and rig; it is not a measured recording.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    bool
    """
    return "meta" in npz_names(path)


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


def read_file(path, names=None):
    """Channels of a signal file and what the file states about them.

    Parameters
    ----------
    path : str or pathlib.Path
        The file; its suffix selects the reader in :data:`READERS`.
    names : sequence of str, optional
        Channel names for formats that do not store them (WAV).

    Returns
    -------
    SignalFile

    Warns
    -----
    RecordWarning
        Each correction the reader made (:attr:`SignalFile.said`).

    Raises
    ------
    ParameterError
        Unsupported file type; a file its reader cannot read (truncated, damaged, not of
        its type, a v7.3 ``.mat`` without h5py, a UFF with no type-58 set); a channel that
        is not 1-D; the optional library of the type not installed.
    """
    path = Path(path)
    reader = READERS.get(path.suffix.lower())
    if path.is_dir():
        raise ParameterError(f"record {path}: is a directory (expected a recording file: "
                             f"{', '.join(READERS)})", param="record",
                             allowed=", ".join(READERS))
    if reader is None:
        raise ParameterError(f"record {path}: unsupported file type {path.suffix!r}",
                             param="record", allowed=", ".join(READERS))
    try:
        out = reader(path, names)
    except ParameterError:
        raise
    except Exception as exc:  # noqa: BLE001 - any reader failure is a damaged file
        detail = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise ParameterError(f"record {path}: cannot be read as a {path.suffix} file "
                             f"({type(exc).__name__}: {detail}); the file is truncated or "
                             f"damaged: copy or export it again", param="record",
                             allowed=f"a readable {path.suffix} file") from None
    out = out if isinstance(out, SignalFile) else SignalFile(*out)
    for text in out.said:
        warnings.warn(text, RecordWarning, stacklevel=2)
    return out


def read_signals(path, names=None):
    """Channels of a signal file and the sample rate it stores (:func:`read_file` without
    the units, speed and calibration).

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
        Sample rate stored in the file, Hz, else None.
    """
    f = read_file(path, names)
    return f.signals, f.rate_hz


def write_signals(path, signals, rate_hz, units=None):
    """Write channels to a signal file that :func:`read_file` reads back the same
    (samples, rate, units), atomically; the suffix selects the format (:data:`WRITERS`).

    Parameters
    ----------
    path : str or pathlib.Path
        ``.npz``, ``.csv``, ``.wav`` (float32 at full scale, the calibration factor stated
        in its ``LIST/INFO`` comment), ``.mat`` (v5, channels as column vectors, ``fs_hz``
        and a ``units`` struct), ``.uff``/``.unv`` (one type-58 set per channel, the unit in
        its ordinate label; pyuff) or ``.tdms`` (npTDMS).
    signals : dict of str to array_like
        Channel name → samples, shape (n,) each, all of one length; float32 samples are
        stored as float32 where the format keeps the type (``.npz``, ``.mat``, ``.tdms``),
        the rest as float64.
    rate_hz : float
        Sample rate, Hz (> 0; a whole number for WAV).
    units : dict of str to str or str, optional
        Unit of each channel, or one unit for all.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ParameterError
        Unsupported suffix, no channel, channels of different lengths or not 1-D, a rate
        that is not > 0, a missing optional library.
    """
    path = Path(path)
    writer = WRITERS.get(path.suffix.lower())
    if writer is None:
        raise ParameterError(f"{path}: cannot write {path.suffix!r} files", param="path",
                             allowed=", ".join(WRITERS))
    if not signals:
        raise ParameterError(f"{path}: no channel to write", param="signals")
    arrays = {}
    for k, v in signals.items():
        v = np.asarray(v)
        arrays[str(k)] = v.astype(np.float32 if v.dtype == np.float32 else float, copy=False)
    lengths = {k: v.shape for k, v in arrays.items()}
    if any(len(s) != 1 for s in lengths.values()) or len(set(lengths.values())) != 1:
        raise ParameterError(f"{path}: channels must be 1-D and of one length, got "
                             f"{lengths}", param="signals", allowed="1-D arrays of one length")
    if not (isinstance(rate_hz, (int, float, np.number)) and math.isfinite(rate_hz)
            and rate_hz > 0):
        raise ParameterError(f"rate_hz must be > 0 Hz, got {rate_hz!r}", param="rate_hz",
                             allowed="> 0 Hz")
    if isinstance(units, str):
        units = {k: units for k in arrays}
    writer(path, arrays, float(rate_hz), {k: str(v) for k, v in (units or {}).items() if v})
    return path
