"""``.npz`` — one 1-D array per channel (keys = channel names; ``t``, ``meta`` and ``source``
of a saved :class:`~cmsim.run.Run` are skipped; a column or row vector, shape (n, 1) or
(1, n), is read as the 1-D channel it is; any other 2-D array is refused, never dropped).
Optional ``fs_hz`` (a scalar: the rate; also ``fs``, ``sample_rate``, ``samplerate`` or
``sampling_rate``, of one value) and ``units`` (a JSON object string, channel → unit, as
:func:`write` writes them; plain text is the unit of every channel). An array of one value
is never a channel."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from cmsim._io import atomic_savez
from cmsim.errors import ParameterError
from cmsim.measured.readers._common import SignalFile, channel_1d, one_rate

__all__ = ["npz_names"]   # read and write: through READERS and WRITERS


#: Array names of a saved run (and of :func:`write`'s ``.npz``) that are not channels.
_NOT_CHANNELS = ("t", "meta", "source", "fs_hz", "units")


#: Names of a one-value array that holds the sample rate, Hz (``fs_hz`` is what
#: :func:`write` writes; the others are what a lab's script may have saved).
_RATE_NAMES = ("fs_hz", "fs", "sample_rate", "samplerate", "sampling_rate")


def read(path, names=None):
    """Channels of an ``.npz`` file and what it states (module docstring)."""
    if not zipfile.is_zipfile(path):            # numpy would read it as a pickle, and say so
        raise ParameterError(f"record {path}: is not an .npz (zip) archive: not a file "
                             "numpy.savez wrote, or one truncated or damaged", param="record",
                             allowed="an .npz archive")
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    one_value = {k for k, a in arrays.items() if a.size == 1 and a.ndim <= 1}
    rates = {k: float(arrays[k].reshape(-1)[0]) for k in _RATE_NAMES if k in one_value}
    signals = {k: channel_1d(path, k, a) for k, a in arrays.items()   # one value: no channel
               if k not in _NOT_CHANNELS and k not in one_value}
    units = {}
    if "units" in arrays:
        text = str(arrays["units"])
        try:
            units = json.loads(text)            # what write() stores: channel -> unit
        except ValueError:
            units = {k: text for k in signals}  # one unit for every channel
        if not isinstance(units, dict):
            units = {k: str(units) for k in signals}
    key = next(iter(rates), None)
    return SignalFile(signals, one_rate(path, rates) if rates else None, units,
                      rate_from=f"its \"{key}\" array",
                      counts=frozenset(k for k in signals if arrays[k].dtype.kind in "iu"))


def write(path, signals, rate_hz, units):
    """Write channels to an ``.npz`` file that :func:`read` reads back the same, atomically."""
    atomic_savez(path, **signals, fs_hz=np.float64(rate_hz), units=np.array(json.dumps(units)))


def npz_names(path):
    """Array names of an ``.npz`` (empty when it is not one or is unreadable: the reader then
    names the damage).

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    set of str
    """
    if Path(path).suffix.lower() != ".npz":
        return set()
    try:
        with np.load(path, allow_pickle=False) as z:
            return set(z.files)
    except Exception:  # noqa: BLE001 - any failure is the reader's to report
        return set()
