"""Signal files of measured records: file I/O only (no metadata, no inference).

One reader per file type in :data:`READERS`, each ``reader(path, names)`` returning a
:class:`SignalFile` — the channels (name → float64 1-D array, in the file's physical unit)
and what the file itself states: sample rate, unit of each channel, shaft speed, WAV
calibration factor (each None when the file is silent on it). A reader may also return the
older pair ``(signals, rate_hz)``; :func:`read_file` takes both. The writer of each type sits
beside its reader in :data:`WRITERS` (:func:`write_signals`), so the rate and unit
conventions of a format are written once, and a file cmsim writes reads back the same.

Types, and what each states:

* ``.npz`` — one 1-D array per channel (keys = channel names; ``t``, ``meta`` and ``source``
  of a saved :class:`~cmsim.run.Run` are skipped; a column or row vector, shape (n, 1) or
  (1, n), is read as the 1-D channel it is; any other 2-D array is refused, never dropped).
  Optional ``fs_hz`` (a scalar: the rate) and ``units`` (a JSON object string, channel →
  unit), as :func:`write_signals` writes them.
* ``.csv`` — one column per channel, a header row of channel names, separated by ``,``,
  ``;`` or tabs (sniffed; a ``;`` file may use decimal commas); a header ``name [unit]`` or
  ``name (unit)`` states the unit; a first column named ``t`` or ``time``, bare or with
  its unit (``time_s``, ``Time (s)``, ``time [ms]``; any case) is the time axis, not a
  channel: its steps must be even (within :data:`CSV_STEP_TOLERANCE`), and give the
  rate. A file whose first line is all numbers has no header: every row is data, the
  channels are named as a WAV's (``names``, else ``ch0``, ...) and a first column rising in
  even steps is the time in seconds.
* ``.wav`` — one channel per WAV channel, named by ``names`` (the entry's ``channels``) when
  they match in number, else ``ch0``, ``ch1``, ...; the header rate is the sample rate. The
  samples are read as stored (integer counts of a PCM file, floats of a float file). A
  ``LIST/INFO`` comment ``cmsim {"calibration": c, "channels": [...], "units": [...]}``
  (what :func:`write_signals` writes) states channel names, units and the calibration factor
  ``c`` (physical value = ``c`` × stored sample), which is applied here; without it the
  factor may come from ``metadata.json`` (``calibration`` of the entry, applied by
  :func:`~cmsim.measured.record.read_record`).
* ``.mat`` — MATLAB v4–v7.2 (:func:`scipy.io.loadmat`): every numeric vector is a channel
  named by its variable (the CWRU files: ``X097_DE_time``, ``X097_FE_time``), an n × k
  matrix (a DAQ export's ``data``) k channels ``data_0`` ... ``data_{k-1}`` (its columns
  when n > k); a vector ``t`` or ``time`` (``time_s``, ``t_ms``) is the time base, not a
  channel: its steps must be even, and give the rate; a scalar whose name ends in ``RPM``
  (``X097RPM``) is the shaft speed (several of different values are refused as
  ambiguous), a scalar ``fs``, ``Fs``, ``fs_hz`` or ``sample_rate`` the sample rate (it
  must agree with a time vector), a struct ``units`` (channel → text) the units; other
  scalars, strings and structs are skipped. A v7.3 file (HDF5) is read with h5py when it is
  installed, else refused with what to do.
* ``.uff`` / ``.unv`` — Universal File Format, data sets of type 58 (what Siemens Testlab,
  m+p and most modal/DAQ suites export; pyuff, ``pip install cmsim[uff]``): one channel per
  set, named by its ``id1`` line (else ``response entity:node:direction``); the abscissa
  increment is the sample spacing (its six printed digits rounded back to the rate they
  came from), the ordinate unit label the unit. Sets must be evenly spaced time data at one
  rate; a file with no type-58 set is refused.
* ``.tdms`` — NI TDMS (LabVIEW DAQ; npTDMS, ``pip install cmsim[tdms]``): one channel per
  TDMS channel with data, named ``channel`` (one group) or ``group/channel``; the waveform
  property ``wf_increment`` gives the rate, ``unit_string`` the unit; scaling stored in the
  file is applied (npTDMS).

:func:`read_file` turns whatever a reader raises on a damaged file (truncated, not of its
type) into one :class:`~cmsim.errors.ParameterError` naming the file; a missing optional
library is one line naming the extra to install.
"""

from __future__ import annotations

import csv
import gc
import importlib
import io
import json
import math
import os
import re
import struct
import tempfile
import warnings
from pathlib import Path
from typing import NamedTuple

import numpy as np
from scipy.io import loadmat, savemat, wavfile

from cmsim._io import atomic_savez, atomic_write_bytes, atomic_write_text
from cmsim.errors import ParameterError

__all__ = ["READERS", "WRITERS", "SignalFile", "read_file", "read_signals", "resolve_path",
           "write_signals", "is_cmsim_run", "npz_names"]

#: Array names of a saved run (and of :func:`write_signals`' ``.npz``) that are not channels.
_NOT_CHANNELS = ("t", "meta", "source", "fs_hz", "units")

#: Scalar names of a ``.mat`` file that hold the sample rate, Hz.
_MAT_RATE_NAMES = ("fs", "fs_hz", "sample_rate", "samplerate", "sampling_rate")

#: Prefix of the WAV ``LIST/INFO`` comment cmsim writes and reads.
_WAV_TAG = "cmsim "


class SignalFile(NamedTuple):
    """What one signal file holds and states.

    Attributes
    ----------
    signals : dict of str to numpy.ndarray
        Channel name → float64 samples, shape (n,) each, in the file's physical unit.
    rate_hz : float or None
        Sample rate the file states, Hz.
    units : dict of str to str
        Channel → unit the file states (channels it is silent on are absent).
    speed_rpm : float or None
        Shaft speed the file states, rpm (a CWRU ``XnnnRPM``).
    calibration : float or None
        Factor the reader applied to the stored samples (a WAV's stated calibration).
    rate_from : str
        Where the rate is stated, for messages (``"the WAV header"``).
    """

    signals: dict
    rate_hz: float | None = None
    units: dict = {}
    speed_rpm: float | None = None
    calibration: float | None = None
    rate_from: str = "the file header"


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


def _optional(module, extra, path):
    """``import module``, or one line naming the extra that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ParameterError(f"record {path}: reading and writing {Path(path).suffix} files "
                             f"needs {module}, an optional dependency: pip install "
                             f"cmsim[{extra}]", param="record",
                             allowed=f"{module} installed (cmsim[{extra}])") from None


def _rate_of_step(step, digits=None):
    """The sample rate of a sample spacing ``step`` (s); with ``digits``, the spacing was
    printed with that many significant digits, and the rate is the one with the fewest
    digits whose spacing prints the same (1.95313e-05 s → 51200 Hz, not 51199.87)."""
    rate = 1.0 / float(step)
    if digits is None:
        return rate
    ulp = 10.0 ** (math.floor(math.log10(abs(step))) - digits + 1)
    for k in range(1, 16):
        r = float(f"{rate:.{k}g}")
        if abs(1.0 / r - step) <= 0.5000001 * ulp:
            return r
    return rate


# ---------------------------------------------------------------------- .npz
def _read_npz(path, names=None):
    with np.load(path, allow_pickle=False) as z:
        signals = {k: _channel_1d(path, k, z[k]) for k in z.files if k not in _NOT_CHANNELS}
        rate = float(z["fs_hz"]) if "fs_hz" in z.files and z["fs_hz"].ndim == 0 else None
        units = json.loads(str(z["units"])) if "units" in z.files else {}
    return SignalFile(signals, rate, units, rate_from="its fs_hz array")


def _write_npz(path, signals, rate_hz, units):
    atomic_savez(path, **signals, fs_hz=np.float64(rate_hz), units=np.array(json.dumps(units)))


# ---------------------------------------------------------------------- .csv
_CSV_UNIT = re.compile(r"^(.*\S)\s*(?:\[([^\]]*)\]|\(([^)]*)\))$")

#: A CSV time column's name (``t``, ``time``, ``time_s``, ``Time (s)``, ``time [ms]``, any
#: case) → group 1 the unit (``s`` when none is written).
_CSV_TIME = re.compile(r"^(?:t|time)(?:_(s|ms)|\s*\[\s*(s|ms)\s*\]|\s*\(\s*(s|ms)\s*\))?$",
                       re.IGNORECASE)

#: Largest relative departure of one time step of a CSV from the mean step that still
#: counts as evenly spaced (time stamps printed to 2 significant digits of the step).
CSV_STEP_TOLERANCE = 0.1


def _csv_dialect(path):
    """``(delimiter, decimal)`` of a CSV, sniffed from its first lines: ``,``, ``;`` or
    a tab; a ``;`` file whose numbers carry a decimal comma (European locale) reads them."""
    with open(path, newline="", encoding="utf-8", errors="replace") as fh:
        head = [fh.readline() for _ in range(5)]
    try:
        sep = csv.Sniffer().sniff("".join(head), delimiters=",;\t").delimiter
    except csv.Error:
        sep = ","
    body = "".join(head[1:])
    decimal = "," if sep in ";\t" and re.search(r"\d,\d", body) else "."
    return sep, decimal


def _time_rate(path, name, t, unit="s"):
    """The sample rate of a time column or vector ``t`` (unit ``s`` or ``ms``; a CSV's time
    column, a ``.mat`` file's ``t``), checked for even steps: a gap or a jump back is
    refused, naming where."""
    t = np.asarray(t, dtype=float) * (1e-3 if unit.lower() == "ms" else 1.0)
    steps = np.diff(t)
    step = (t[-1] - t[0]) / (t.size - 1)
    bad = np.flatnonzero(~(np.abs(steps - step) <= CSV_STEP_TOLERANCE * abs(step)))
    if step <= 0 or not np.isfinite(step) or bad.size:
        i = int(bad[0]) if bad.size else 0
        raise ParameterError(
            f"record {path}: time {name!r} is not evenly spaced (step {i} from "
            f"{t[i]:.9g} s to {t[i + 1]:.9g} s, the mean step is {step:.6g} s); cmsim reads "
            f"evenly sampled records: export without gaps, or cut the record at the gap",
            param="record", allowed="evenly spaced time stamps")
    return _rate_of_step(step, digits=12)


def _is_number(text, decimal):
    try:
        float(text.strip().replace(decimal, ".") if decimal != "." else text.strip())
    except ValueError:
        return False
    return True


def _csv_has_header(path, sep, decimal):
    """False when every field of the first line is a number: a CSV written without a header
    row (its first row is data, not channel names)."""
    with open(path, newline="", encoding="utf-8", errors="replace") as fh:
        first = next(csv.reader(fh, delimiter=sep), [])
    return not (first and all(_is_number(c, decimal) for c in first if c.strip()))


def _evenly_rising(t):
    """Whether a column is a time base: at least 8 values rising in even steps (within
    :data:`CSV_STEP_TOLERANCE`), what no vibration channel does."""
    steps = np.diff(np.asarray(t, dtype=float))
    step = steps.mean() if steps.size >= 7 else 0.0
    return bool(step > 0 and np.all(np.abs(steps - step) <= CSV_STEP_TOLERANCE * step))


def _read_csv(path, names=None):
    import pandas as pd
    sep, decimal = _csv_dialect(path)
    if not _csv_has_header(path, sep, decimal):
        return _read_csv_headerless(path, sep, decimal, names)
    df = pd.read_csv(path, sep=sep, decimal=decimal)
    cols = [str(c) for c in df.columns]
    rate = None
    m = _CSV_TIME.match(cols[0].strip()) if cols else None
    if m and len(df) > 1:
        unit = next((g for g in m.groups() if g), "s")
        rate = _time_rate(path, cols[0], df[df.columns[0]].to_numpy(dtype=float), unit)
        df, cols = df.iloc[:, 1:], cols[1:]
    signals, units = {}, {}
    for c, col in zip(cols, df.columns):
        m = _CSV_UNIT.match(c)
        name = m.group(1) if m else c
        unit = ((m.group(2) if m.group(2) is not None else m.group(3)) or "").strip() \
            if m else ""
        if unit:
            units[name] = unit
        signals[name] = df[col].to_numpy(dtype=float)
    return SignalFile(signals, rate, units, rate_from="its time column")


def _read_csv_headerless(path, sep, decimal, names):
    """A CSV without a header row: every row is data. A first column rising in even steps
    (with others beside it) is the time base, in seconds; the channels are named by
    ``names`` (the entry's ``channels``) when they match in number, else ``ch0``,
    ``ch1``, ... as a WAV's are."""
    import pandas as pd
    data = pd.read_csv(path, sep=sep, decimal=decimal, header=None).to_numpy(dtype=float)
    rate = None
    if data.shape[1] > 1 and data.shape[0] > 1 and _evenly_rising(data[:, 0]):
        rate = _time_rate(path, "column 1", data[:, 0])
        data = data[:, 1:]
    names = list(names or [])
    if len(names) != data.shape[1]:
        names = [f"ch{i}" for i in range(data.shape[1])]
    return SignalFile({n: data[:, i] for i, n in enumerate(names)}, rate, {},
                      rate_from="its first column (rising evenly: the time, in s)")


def _write_csv(path, signals, rate_hz, units):
    import pandas as pd
    n = len(next(iter(signals.values())))
    cols = {"time_s": np.arange(n) / float(rate_hz)}
    for k, v in signals.items():
        cols[f"{k} [{units[k]}]" if units.get(k) else k] = np.asarray(v, dtype=float)
    atomic_write_text(path, pd.DataFrame(cols).to_csv(index=False, float_format="%.17g"))


# ---------------------------------------------------------------------- .wav
def _wav_comment(path):
    """The cmsim ``LIST/INFO/ICMT`` comment of a WAV file as a dict (empty without one)."""
    with open(path, "rb") as fh:
        head = fh.read(12)
        if len(head) < 12 or head[:4] not in (b"RIFF", b"RIFX") or head[8:12] != b"WAVE":
            return {}
        end = "<" if head[:4] == b"RIFF" else ">"
        while True:
            ck = fh.read(8)
            if len(ck) < 8:
                return {}
            cid, size = ck[:4], struct.unpack(end + "I", ck[4:])[0]
            if cid != b"LIST":
                fh.seek(size + (size & 1), 1)
                continue
            body = fh.read(size)
            if body[:4] != b"INFO":
                continue
            i = 4
            while i + 8 <= len(body):
                sid, ssize = body[i:i + 4], struct.unpack(end + "I", body[i + 4:i + 8])[0]
                text = body[i + 8:i + 8 + ssize].rstrip(b"\0").decode("utf-8", "replace")
                if sid == b"ICMT" and text.startswith(_WAV_TAG):
                    return json.loads(text[len(_WAV_TAG):])
                i += 8 + ssize + (ssize & 1)


def _read_wav(path, names=None):
    rate, x = wavfile.read(path)
    x = np.asarray(x, dtype=float)
    x = x[:, None] if x.ndim == 1 else x
    stated = _wav_comment(path)
    calibration = stated.get("calibration")
    if calibration is not None:
        x = x * float(calibration)
    names = list(stated.get("channels") or names or [])
    if len(names) != x.shape[1]:
        names = [f"ch{i}" for i in range(x.shape[1])]
    units = {n: u for n, u in zip(names, stated.get("units") or []) if u}
    return SignalFile({n: x[:, i] for i, n in enumerate(names)}, float(rate), units,
                      calibration=None if calibration is None else float(calibration),
                      rate_from="the WAV header")


def _write_wav(path, signals, rate_hz, units):
    """Float32 WAV at full scale ±1: the samples divided by the largest magnitude, that
    factor stated as the calibration in a ``LIST/INFO`` comment with the names and units."""
    if float(rate_hz) != round(float(rate_hz)) or not 0 < rate_hz < 2 ** 32:
        raise ParameterError(f"a WAV header holds a whole sample rate, got {rate_hz:g} Hz; "
                             f"write .npz, .uff or .mat instead", param="rate_hz",
                             allowed="a whole number of Hz")
    names = list(signals)
    x = np.column_stack([np.asarray(signals[k], dtype=float) for k in names])
    peak = float(np.max(np.abs(x))) if x.size else 0.0
    calibration = peak if peak > 0 and math.isfinite(peak) else 1.0
    buf = io.BytesIO()
    wavfile.write(buf, int(rate_hz), (x / calibration).astype(np.float32))
    text = _WAV_TAG + json.dumps({"calibration": calibration, "channels": names,
                                  "units": [units.get(k) for k in names]})
    data = text.encode("utf-8") + b"\0"
    data += b"\0" * (len(data) & 1)
    info = b"INFO" + b"ICMT" + struct.pack("<I", len(data)) + data
    raw = bytearray(buf.getvalue()) + b"LIST" + struct.pack("<I", len(info)) + info
    raw[4:8] = struct.pack("<I", len(raw) - 8)
    atomic_write_bytes(path, bytes(raw))


# ---------------------------------------------------------------------- .mat
def _mat_channels(path, name, a):
    """The channels of one ``.mat`` variable: a vector is one channel; an n × k matrix (a
    DAQ export's ``data``) is k channels ``name_0`` ... ``name_{k-1}`` — its columns when
    n > k, else its rows."""
    if a.ndim == 2 and min(a.shape) > 1:
        cols = a if a.shape[0] > a.shape[1] else a.T
        return {f"{name}_{i}": np.asarray(cols[:, i], dtype=float)
                for i in range(cols.shape[1])}
    return {name: _channel_1d(path, name, a)}


def _read_mat(path, names=None):
    try:
        variables = loadmat(path, squeeze_me=True, simplify_cells=True)
    except NotImplementedError:            # a v7.3 file: HDF5 inside
        variables = _read_mat73(path)
    signals, rates, speeds, units, time = {}, {}, {}, {}, None
    for name, value in variables.items():
        if name.startswith("__"):
            continue
        if name == "units" and isinstance(value, dict):
            units = {str(k): str(v) for k, v in value.items()}
            continue
        a = np.asarray(value)
        if a.dtype.kind not in "iuf":
            continue                       # strings, structs, cells, logicals, complex
        if a.size == 1:
            if name.lower().endswith("rpm"):
                speeds[name] = float(a.reshape(-1)[0])
            elif name.lower() in _MAT_RATE_NAMES:
                rates[name] = float(a.reshape(-1)[0])
            continue
        m = _CSV_TIME.match(name)
        if m and (a.ndim == 1 or 1 in a.shape) and a.size > 1:
            time = name
            rates[name] = _time_rate(path, name, a.reshape(-1),
                                     next((g for g in m.groups() if g), "s"))
            continue
        signals.update(_mat_channels(path, name, a))
    if len(set(speeds.values())) > 1:
        raise ParameterError(f"record {path}: the speed is ambiguous: "
                             + ", ".join(f"{k} = {v:g}" for k, v in speeds.items())
                             + "; keep one rpm variable (or give --speed-rpm after removing "
                               "the others)", param="record",
                             allowed="one rpm value per file")
    rate = _one_rate(path, rates, 1e-3)
    return SignalFile(signals, rate, units, next(iter(speeds.values()), None),
                      rate_from=(f"its time vector {time!r}" if time
                                 else "its sample-rate variable"))


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


def _write_mat(path, signals, rate_hz, units):
    out = {k: v.reshape(-1, 1) for k, v in signals.items()}
    out["fs_hz"] = float(rate_hz)
    if units:
        out["units"] = {k: str(v) for k, v in units.items()}
    buf = io.BytesIO()
    savemat(buf, out, long_field_names=True)
    atomic_write_bytes(path, buf.getvalue())


# ---------------------------------------------------------------------- .uff
def _uff_text(value):
    text = str(value or "").strip()
    return "" if text.upper() == "NONE" else text


def _read_uff(path, names=None):
    pyuff = _optional("pyuff", "uff", path)
    uff = pyuff.UFF(str(path))
    types = [int(t) for t in np.atleast_1d(uff.get_set_types())]
    which = [i for i, t in enumerate(types) if t == 58]
    if not which:
        raise ParameterError(f"record {path}: holds no type-58 data set (function at nodal "
                             f"DOF, the time data Testlab and m+p export); its sets are of "
                             f"type {sorted(set(types)) or 'none'}: export the time "
                             f"histories as UFF 58", param="record",
                             allowed="a UFF file with type-58 sets")
    sets = uff.read_sets(which)
    sets = sets if isinstance(sets, list) else [sets]
    signals, units, rates = {}, {}, {}
    for s in sets:
        name = _uff_text(s.get("id1")) or (f"{_uff_text(s.get('rsp_ent_name')) or 'node'}:"
                                           f"{s.get('rsp_node')}:{s.get('rsp_dir')}")
        base, k = name, 2
        while name in signals:
            name, k = f"{base}_{k}", k + 1
        if not s.get("abscissa_spacing"):
            raise ParameterError(f"record {path}: set {name!r} has uneven abscissa spacing; "
                                 f"cmsim reads evenly sampled time data", param="record")
        signals[name] = np.asarray(s["data"], dtype=float).reshape(-1)
        if np.iscomplexobj(s["data"]):
            raise ParameterError(f"record {path}: set {name!r} holds complex data (a "
                                 f"spectrum or FRF), not a time history", param="record")
        rates[name] = _rate_of_step(s["abscissa_inc"], digits=6)
        unit = _uff_text(s.get("ordinate_axis_units_lab"))
        if unit:
            units[name] = unit
    return SignalFile(signals, _one_rate(path, rates), units,
                      rate_from="its abscissa increment")


def _one_rate(path, rates, tolerance=0.0):
    """The one sample rate of a file's channels (or of its rate statements: a ``.mat``
    file's ``fs`` and time vector), refused when two differ by more than ``tolerance``
    (relative)."""
    values = sorted(set(rates.values()))
    if values and values[-1] - values[0] > tolerance * values[0]:
        raise ParameterError(f"record {path}: states different sample rates ("
                             + ", ".join(f"{k} {v:g} Hz" for k, v in rates.items())
                             + "); export the channels of one rate to one file, or "
                               "correct the one that is wrong",
                             param="record", allowed="one sample rate per file")
    return values[0] if values else None


def _write_uff(path, signals, rate_hz, units):
    pyuff = _optional("pyuff", "uff", path)
    sets = []
    for i, (name, v) in enumerate(signals.items()):
        v = np.asarray(v, dtype=float).reshape(-1)
        sets.append({"type": 58, "binary": 1, "id1": name, "id2": "cmsim",
                     "func_type": 1, "rsp_ent_name": name[:10], "rsp_node": i + 1,
                     "rsp_dir": 0, "ref_node": 0, "ref_dir": 0, "abscissa_spacing": 1,
                     "abscissa_spec_data_type": 17, "abscissa_axis_lab": "Time",
                     "abscissa_axis_units_lab": "s", "ordinate_spec_data_type": 0,
                     "ordinate_axis_lab": name[:20],
                     "ordinate_axis_units_lab": (units.get(name) or "NONE")[:20],
                     "orddenom_spec_data_type": 0, "data": v,
                     "x": np.arange(v.size) / float(rate_hz)})
    # pyuff writes by file name and appends (its "overwrite" mode garbles binary sets):
    # a fresh temporary name beside the target, then a rename
    fd, tmp = tempfile.mkstemp(prefix=f".{Path(path).name}.", suffix=".tmp",
                               dir=Path(path).parent)
    os.close(fd)
    os.unlink(tmp)
    try:
        with warnings.catch_warnings():   # pyuff leaves its text handle to the collector
            warnings.simplefilter("ignore", ResourceWarning)
            pyuff.UFF(tmp).write_sets(sets, mode="add")
            gc.collect()
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


# ---------------------------------------------------------------------- .tdms
def _read_tdms(path, names=None):
    nptdms = _optional("nptdms", "tdms", path)
    f = nptdms.TdmsFile.read(str(path))
    groups = [g for g in f.groups() if any(len(c) for c in g.channels())]
    signals, units, rates = {}, {}, {}
    for g in groups:
        for c in g.channels():
            if not len(c):
                continue
            name = c.name if len(groups) == 1 else f"{g.name}/{c.name}"
            signals[name] = np.asarray(c[:], dtype=float)
            if c.properties.get("wf_increment"):
                rates[name] = _rate_of_step(float(c.properties["wf_increment"]), digits=15)
            unit = str(c.properties.get("unit_string") or "").strip()
            if unit:
                units[name] = unit
    return SignalFile(signals, _one_rate(path, rates), units, rate_from="its wf_increment")


def _write_tdms(path, signals, rate_hz, units):
    nptdms = _optional("nptdms", "tdms", path)
    chans = []
    for name, v in signals.items():
        props = {"wf_increment": 1.0 / float(rate_hz), "wf_start_offset": 0.0}
        if units.get(name):
            props["unit_string"] = units[name]
        chans.append(nptdms.ChannelObject("signals", name, v, properties=props))
    buf = io.BytesIO()
    with nptdms.TdmsWriter(buf) as w:
        w.write_segment([nptdms.GroupObject("signals")] + chans)
    atomic_write_bytes(path, buf.getvalue())


#: File suffix → reader ``(path, names) -> SignalFile`` (or ``(signals, rate_hz)``).
READERS = {".npz": _read_npz, ".csv": _read_csv, ".wav": _read_wav, ".mat": _read_mat,
           ".uff": _read_uff, ".unv": _read_uff, ".tdms": _read_tdms}

#: File suffix → writer ``(path, signals, rate_hz, units)``, beside each reader.
WRITERS = {".npz": _write_npz, ".csv": _write_csv, ".wav": _write_wav, ".mat": _write_mat,
           ".uff": _write_uff, ".unv": _write_uff, ".tdms": _write_tdms}


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

    Raises
    ------
    ParameterError
        Unsupported file type; a file its reader cannot read (truncated, damaged, not of
        its type, a v7.3 ``.mat`` without h5py, a UFF with no type-58 set); a channel that
        is not 1-D; the optional library of the type not installed.
    """
    path = Path(path)
    reader = READERS.get(path.suffix.lower())
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
    return out if isinstance(out, SignalFile) else SignalFile(*out)


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
