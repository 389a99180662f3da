"""``.npz`` — one 1-D array per channel (keys = channel names; ``t``, ``meta`` and ``source``
of a saved :class:`~cmsim.run.Run` are skipped; a column or row vector, shape (n, 1) or
(1, n), is read as the 1-D channel it is; any other 2-D array is refused, never dropped).
Optional ``fs_hz`` (a scalar: the rate) and ``units`` (a JSON object string, channel →
unit), as :func:`write` writes them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from cmsim._io import atomic_savez
from cmsim.measured.readers._common import SignalFile, channel_1d

__all__ = ["npz_names"]   # read and write: through READERS and WRITERS


#: Array names of a saved run (and of :func:`write`'s ``.npz``) that are not channels.
_NOT_CHANNELS = ("t", "meta", "source", "fs_hz", "units")


def read(path, names=None):
    """Channels of an ``.npz`` file and what it states (module docstring)."""
    with np.load(path, allow_pickle=False) as z:
        signals = {k: channel_1d(path, k, z[k]) for k in z.files if k not in _NOT_CHANNELS}
        rate = float(z["fs_hz"]) if "fs_hz" in z.files and z["fs_hz"].ndim == 0 else None
        units = json.loads(str(z["units"])) if "units" in z.files else {}
    return SignalFile(signals, rate, units, rate_from="its \"fs_hz\" array")


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
