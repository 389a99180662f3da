"""``.mat`` — MATLAB v4–v7.2 (:func:`scipy.io.loadmat`): every numeric vector is a channel
named by its variable (the CWRU files: ``X097_DE_time``, ``X097_FE_time``), an n × k matrix
(a DAQ export's ``data``) k channels ``data_0`` ... ``data_{k-1}`` (its columns when n > k);
a vector ``t`` or ``time`` (``time_s``, ``t_ms``) is the time base, not a channel: its steps
must be even, and give the rate; a scalar whose name ends in ``RPM`` (``X097RPM``) is the
shaft speed (several of different values are refused as ambiguous), a scalar ``fs``,
``Fs``, ``fs_hz`` or ``sample_rate`` the sample rate (it must agree with a time vector), a
struct ``units`` (channel → text) the units; the fields of a struct are read the same way,
named ``struct.field`` (``rec.acc`` at the rate ``rec.fs``; two levels deep); other
scalars, strings and cells are skipped. A v7.3 file (HDF5) is read with h5py when it is
installed, else refused with what to do."""

from __future__ import annotations

import io

import numpy as np
from scipy.io import loadmat, savemat

from cmsim._io import atomic_write_bytes
from cmsim.errors import ParameterError
from cmsim.measured.readers._common import (TIME_NAME, SignalFile, channel_1d, one_rate,
                                            time_rate)

__all__ = []   # read and write: through READERS and WRITERS of the package


#: Scalar names of a ``.mat`` file that hold the sample rate, Hz.
_MAT_RATE_NAMES = ("fs", "fs_hz", "sample_rate", "samplerate", "sampling_rate")


#: Levels of nested structs whose fields are read (a struct ``rec`` with fields ``acc`` and
#: ``fs`` is the channel ``rec.acc`` at the rate ``rec.fs``).
STRUCT_DEPTH = 2


def _flattened(variables, prefix="", depth=0):
    """``(name, value)`` of every top-level variable and, down to :data:`STRUCT_DEPTH`
    levels, of every field of a struct (``rec.acc``); a struct's ``units`` stays whole."""
    for name, value in variables.items():
        if not prefix and name.startswith("__"):
            continue
        full = prefix + str(name)
        if isinstance(value, dict) and name != "units" and depth < STRUCT_DEPTH:
            yield from _flattened(value, full + ".", depth + 1)
        else:
            yield full, value


def _mat_channels(path, name, a):
    """The channels of one ``.mat`` variable: a vector is one channel; an n × k matrix (a
    DAQ export's ``data``) is k channels ``name_0`` ... ``name_{k-1}`` — its columns when
    n > k, else its rows."""
    if a.ndim == 2 and min(a.shape) > 1:
        cols = a if a.shape[0] > a.shape[1] else a.T
        return {f"{name}_{i}": np.asarray(cols[:, i], dtype=float)
                for i in range(cols.shape[1])}
    return {name: channel_1d(path, name, a)}


def read(path, names=None):
    """Channels of a MATLAB ``.mat`` file and what it states (module docstring)."""
    try:
        variables = loadmat(path, squeeze_me=True, simplify_cells=True)
    except NotImplementedError:            # a v7.3 file: HDF5 inside
        variables = _read_mat73(path)
    signals, rates, speeds, units, time, counts = {}, {}, {}, {}, None, set()
    for name, value in _flattened(variables):
        leaf = name.rsplit(".", 1)[-1]
        if leaf == "units" and isinstance(value, dict):
            prefix = name[:-len(leaf)]
            units.update({prefix + str(k): str(v) for k, v in value.items()})
            continue
        if isinstance(value, dict):
            continue                       # a struct nested deeper than STRUCT_DEPTH
        a = np.asarray(value)
        if a.dtype.kind not in "iuf":
            continue                       # strings, cells, logicals, complex
        if a.size == 1:
            if leaf.lower().endswith("rpm"):
                speeds[name] = float(a.reshape(-1)[0])
            elif leaf.lower() in _MAT_RATE_NAMES:
                rates[name] = float(a.reshape(-1)[0])
            continue
        m = TIME_NAME.match(leaf)
        if m and (a.ndim == 1 or 1 in a.shape) and a.size > 1:
            time = name
            rates[name] = time_rate(path, name, a.reshape(-1),
                                     next((g for g in m.groups() if g), "s"))
            continue
        channels = _mat_channels(path, name, a)
        signals.update(channels)
        if a.dtype.kind in "iu":
            counts.update(channels)
    if len(set(speeds.values())) > 1:
        raise ParameterError(f"record {path}: the speed is ambiguous: "
                             + ", ".join(f"{k} = {v:g}" for k, v in speeds.items())
                             + "; keep one rpm variable (or give --speed-rpm after removing "
                               "the others)", param="record",
                             allowed="one rpm value per file")
    rate = one_rate(path, rates, 1e-3)
    return SignalFile(signals, rate, units, next(iter(speeds.values()), None),
                      rate_from=(f"its time vector {time!r}" if time
                                 else "its sample-rate variable"), counts=frozenset(counts))


def _read_mat73(path):
    """The top-level numeric variables of a MATLAB v7.3 (HDF5) file, through h5py."""
    try:
        import h5py
    except ImportError:
        raise ParameterError(f"record {path}: a MATLAB v7.3 file (HDF5 inside), which scipy "
                             f"cannot read; save it in MATLAB with save(name, '-v7') or "
                             f"install h5py (pip install h5py)", param="record",
                             allowed="a MATLAB v4-v7.2 .mat file, or h5py installed") \
            from None
    with h5py.File(path, "r") as f:       # MATLAB stores column-major: transpose back
        return {k: np.asarray(v).T for k, v in f.items()
                if isinstance(v, h5py.Dataset) and v.dtype.kind in "iuf"}


def write(path, signals, rate_hz, units):
    """Write channels to a MATLAB ``.mat`` file that :func:`read` reads back the same, atomically."""
    out = {k: v.reshape(-1, 1) for k, v in signals.items()}
    out["fs_hz"] = float(rate_hz)
    if units:
        out["units"] = {k: str(v) for k, v in units.items()}
    buf = io.BytesIO()
    savemat(buf, out, long_field_names=True)
    atomic_write_bytes(path, buf.getvalue())
