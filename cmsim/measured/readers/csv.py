"""``.csv`` — one column per channel, a header row of channel names, separated by ``,``, ``;``
or tabs (sniffed; a ``;`` file may use decimal commas); a header ``name [unit]`` or
``name (unit)`` states the unit, and so does a row of units under the header (``s,g,g``);
a first column named ``t``, ``time`` or ``zeit``, bare or with its unit (``time_s``,
``Time (s)``, ``time [ms]``, ``Time [sec]``, ``time [us]``; any case) is the time axis, not
a channel: its steps must be even (within
:data:`~cmsim.measured.readers._common.TIME_STEP_TOLERANCE`), and give the rate. Lines
starting with ``#`` before the table (a DAQ program's notes) are skipped, a file that is not
UTF-8 is read as Windows-1252, and an empty column without a name (a separator ending every
line) is no channel. A file whose first line is all numbers has no header: every row is
data, the channels are named as a WAV's (``names``, else ``ch0``, ...) and a first column
rising in even steps is the time in seconds (in ms or µs, said, where seconds would sample
slower than a vibration record is), or, counting 0, 1, 2, ..., the samples' index. Time
stamps printed coarser than a step (0.1 ms at 12 kHz) are read through their rounding."""

from __future__ import annotations

import csv
import re

import numpy as np

from cmsim._io import atomic_write_text
from cmsim.measured.readers._common import (TIME_NAME, TIME_UNITS, SignalFile, even_time,
                                            time_rate)
from cmsim.rig.ranges import RANGES

__all__ = []   # read and write: through READERS and WRITERS of the package


#: Least sample rate of a vibration record, Hz (the model's, :data:`~cmsim.rig.ranges.RANGES`):
#: a header-less time column that would sample slower in seconds is in ms or µs.
MIN_VIBRATION_RATE_HZ = RANGES["fs_hz"].lo

#: A header-less time column's candidate units → samples per second per unit of rate.
_PER_SECOND = {u: 1.0 / TIME_UNITS[u] for u in ("s", "ms", "µs")}

_CSV_UNIT = re.compile(r"^(.*\S)\s*(?:\[([^\]]*)\]|\(([^)]*)\))$")


def _layout(path):
    """``(encoding, preamble)`` of a CSV, read from its first 64 KiB: UTF-8 where its bytes
    are (a BOM included), else Windows-1252 (a file a Windows DAQ program wrote, ``m/s²`` in
    one byte; :func:`_table` reads it so where a later byte says so); and how many lines
    starting with ``#`` precede its table (a DAQ program's notes on the device)."""
    with open(path, "rb") as fh:
        raw = fh.read(1 << 16)
    try:
        raw.decode("utf-8")
        encoding = "utf-8-sig"
    except UnicodeDecodeError as exc:       # a character cut at the end of the 64 KiB is not
        encoding = "utf-8-sig" if exc.start >= len(raw) - 3 else "cp1252"
    preamble = 0
    for line in raw.decode(encoding, errors="replace").lstrip("\ufeff").splitlines():
        if not line.lstrip().startswith("#"):
            break
        preamble += 1
    return encoding, preamble


def _table(path, encoding, **kwargs):
    """``pandas.read_csv`` of the file in ``encoding``, in Windows-1252 where it is not
    UTF-8 after all."""
    import pandas as pd
    try:
        return pd.read_csv(path, encoding=encoding, **kwargs)
    except UnicodeDecodeError:
        return pd.read_csv(path, encoding="cp1252", **kwargs)


def _head(path, encoding, preamble, n=5):
    """The first ``n`` lines of a CSV's table (after its preamble)."""
    with open(path, newline="", encoding=encoding, errors="replace") as fh:
        lines = [fh.readline() for _ in range(preamble + n)]
    return lines[preamble:]


def _csv_dialect(head):
    """``(delimiter, decimal)`` of a CSV, sniffed from its first lines (``head``): ``,``,
    ``;`` or a tab; a ``;`` file whose numbers carry a decimal comma (European locale) reads
    them."""
    first, body = head[0].strip().lstrip("\ufeff"), "".join(head[1:])
    if first and not any(c in first for c in ",;\t") and not _is_number(first, "."):
        # one column under a one-name header: a comma between digits is a decimal comma,
        # not a separator (sniffed, it split every number in two)
        return ("\t" if ";" in body else ";"), ("," if re.search(r"\d,\d", body) else ".")
    try:
        sep = csv.Sniffer().sniff("".join(head), delimiters=",;\t").delimiter
    except csv.Error:
        sep = ","
    decimal = "," if sep in ";\t" and re.search(r"\d,\d", body) else "."
    return sep, decimal


def _is_number(text, decimal):
    try:
        float(text.strip().replace(decimal, ".") if decimal != "." else text.strip())
    except ValueError:
        return False
    return True


def _fields(line, sep):
    return next(csv.reader([line], delimiter=sep), [])


def _csv_has_header(head, sep, decimal):
    """False when every field of the first line is a number: a CSV written without a header
    row (its first row is data, not channel names)."""
    first = _fields(head[0], sep)
    return not (first and all(_is_number(c, decimal) for c in first if c.strip()))


def _units_row(head, sep, decimal):
    """The fields of a row of units under the header (``s,g,g``), or None: a second line
    none of whose fields is a number."""
    second = [c.strip() for c in _fields(head[1], sep)] if len(head) > 1 else []
    if second and any(second) and not any(_is_number(c, decimal) for c in second if c):
        return second
    return None


def read(path, names=None):
    """Channels of a ``.csv`` file and what it states (module docstring)."""
    encoding, preamble = _layout(path)
    head = _head(path, encoding, preamble)
    sep, decimal = _csv_dialect(head)
    if not _csv_has_header(head, sep, decimal):
        return _read_headerless(path, sep, decimal, names, encoding, preamble)
    unit_row = _units_row(head, sep, decimal)
    df = _table(path, encoding, sep=sep, decimal=decimal,
                skiprows=list(range(preamble)) + ([preamble + 1] if unit_row else []))
    # a separator at the end of every line (as a spreadsheet exports) makes an empty column
    # without a name: no channel
    df = df[[c for c in df.columns
             if not (str(c).startswith("Unnamed: ") and df[c].isna().all())]]
    cols = [str(c) for c in df.columns]
    if unit_row:                    # a units row: each column's unit, as "name [unit]" does
        cols = [f"{c} [{u}]" if u and not _CSV_UNIT.match(c) else c
                for c, u in zip(cols, unit_row + [""] * len(cols))]
    rate, said = None, []
    m = TIME_NAME.match(cols[0].strip()) if cols else None
    if m and len(df) > 1:
        unit = next((g for g in m.groups() if g), "s")
        rate = time_rate(path, cols[0], df[df.columns[0]].to_numpy(dtype=float), unit, said)
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
    return SignalFile(signals, rate, units, rate_from="its time column", said=tuple(said))


def _read_headerless(path, sep, decimal, names, encoding="utf-8-sig", preamble=0):
    """A CSV without a header row: every row is data. A first column rising in even steps
    (:func:`~cmsim.measured.readers._common.even_time`, with others beside it) is the time
    base — in seconds, or, where seconds would give a rate under the least a vibration
    record is sampled at (:data:`MIN_VIBRATION_RATE_HZ`), in ms or µs, said as a correction
    — or, where it counts 1, 2, 3 ... the samples' index (no rate); the channels are named
    by ``names`` (the entry's ``channels``) when they match in number, else ``ch0``,
    ``ch1``, ... as a WAV's are."""
    data = _table(path, encoding, sep=sep, decimal=decimal, header=None,
                  skiprows=preamble).to_numpy(dtype=float)
    rate, rate_from, said = None, "its first column (rising evenly: the time, in s)", ()
    if data.shape[1] > 1 and data.shape[0] > 1 and even_time(data[:, 0]) is not None:
        first = data[:, 0]
        if not np.array_equal(np.diff(first), np.ones(first.size - 1)):
            rate = time_rate(path, "column 1", first)
            unit = next((u for u in ("s", "ms", "µs") if rate * _PER_SECOND[u]
                         >= MIN_VIBRATION_RATE_HZ), "s")
            if unit != "s":
                rate_from = (f"its first column (rising evenly, read as the time in {unit}: "
                             f"in s it would be {rate:.6g} Hz)")
                said = ((f"record {path}: its first column has no header and rises evenly; in "
                         f"seconds it would sample at {rate:.6g} Hz, under the "
                         f"{MIN_VIBRATION_RATE_HZ:g} Hz a vibration record is sampled at, so "
                         f"it is read as the time in {unit}: {rate * _PER_SECOND[unit]:.6g} Hz "
                         f"(write a header such as 'time [s]' to state the unit)"),)
                rate *= _PER_SECOND[unit]
        # else the samples' numbers 0, 1, 2, ... (or 1, 2, 3, ...): an index, no rate (it
        # read as time in s, 1 Hz, which refused the rate --fs-hz stated)
        data = data[:, 1:]
    names = list(names or [])
    if len(names) != data.shape[1]:
        names = [f"ch{i}" for i in range(data.shape[1])]
    return SignalFile({n: data[:, i] for i, n in enumerate(names)}, rate, {},
                      rate_from=rate_from, said=said)


def write(path, signals, rate_hz, units):
    """Write channels to a ``.csv`` file that :func:`read` reads back the same, atomically."""
    import pandas as pd
    n = len(next(iter(signals.values())))
    cols = {"time_s": np.arange(n) / float(rate_hz)}
    for k, v in signals.items():
        cols[f"{k} [{units[k]}]" if units.get(k) else k] = np.asarray(v, dtype=float)
    atomic_write_text(path, pd.DataFrame(cols).to_csv(index=False, float_format="%.17g"))
