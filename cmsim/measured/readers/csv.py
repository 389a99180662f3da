"""``.csv`` — one column per channel, a header row of channel names, separated by ``,``, ``;``
or tabs (sniffed; a ``;`` file may use decimal commas); a header ``name [unit]`` or
``name (unit)`` states the unit; a first column named ``t`` or ``time``, bare or with its
unit (``time_s``, ``Time (s)``, ``time [ms]``; any case) is the time axis, not a channel:
its steps must be even (within :data:`~cmsim.measured.readers._common.TIME_STEP_TOLERANCE`),
and give the rate. A file whose first line is all numbers has no header: every row is data,
the channels are named as a WAV's (``names``, else ``ch0``, ...) and a first column rising
in even steps is the time in seconds."""

from __future__ import annotations

import csv
import re

import numpy as np

from cmsim._io import atomic_write_text
from cmsim.measured.readers._common import (TIME_NAME, TIME_STEP_TOLERANCE, SignalFile,
                                            time_rate)

__all__ = []   # read and write: through READERS and WRITERS of the package


_CSV_UNIT = re.compile(r"^(.*\S)\s*(?:\[([^\]]*)\]|\(([^)]*)\))$")


def _csv_dialect(path):
    """``(delimiter, decimal)`` of a CSV, sniffed from its first lines: ``,``, ``;`` or
    a tab; a ``;`` file whose numbers carry a decimal comma (European locale) reads them."""
    with open(path, newline="", encoding="utf-8", errors="replace") as fh:
        head = [fh.readline() for _ in range(5)]
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


def _csv_has_header(path, sep, decimal):
    """False when every field of the first line is a number: a CSV written without a header
    row (its first row is data, not channel names)."""
    with open(path, newline="", encoding="utf-8", errors="replace") as fh:
        first = next(csv.reader(fh, delimiter=sep), [])
    return not (first and all(_is_number(c, decimal) for c in first if c.strip()))


def _evenly_rising(t):
    """Whether a column is a time base: at least 8 values rising in even steps (within
    :data:`TIME_STEP_TOLERANCE`), what no vibration channel does."""
    steps = np.diff(np.asarray(t, dtype=float))
    step = steps.mean() if steps.size >= 7 else 0.0
    return bool(step > 0 and np.all(np.abs(steps - step) <= TIME_STEP_TOLERANCE * step))


def read(path, names=None):
    """Channels of a ``.csv`` file and what it states (module docstring)."""
    import pandas as pd
    sep, decimal = _csv_dialect(path)
    if not _csv_has_header(path, sep, decimal):
        return _read_headerless(path, sep, decimal, names)
    df = pd.read_csv(path, sep=sep, decimal=decimal)
    cols = [str(c) for c in df.columns]
    rate = None
    m = TIME_NAME.match(cols[0].strip()) if cols else None
    if m and len(df) > 1:
        unit = next((g for g in m.groups() if g), "s")
        rate = time_rate(path, cols[0], df[df.columns[0]].to_numpy(dtype=float), unit)
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


def _read_headerless(path, sep, decimal, names):
    """A CSV without a header row: every row is data. A first column rising in even steps
    (with others beside it) is the time base, in seconds, or where it counts 1, 2, 3 ... the
    samples' index (no rate); the channels are named by
    ``names`` (the entry's ``channels``) when they match in number, else ``ch0``,
    ``ch1``, ... as a WAV's are."""
    import pandas as pd
    data = pd.read_csv(path, sep=sep, decimal=decimal, header=None).to_numpy(dtype=float)
    rate = None
    if data.shape[1] > 1 and data.shape[0] > 1 and _evenly_rising(data[:, 0]):
        first = data[:, 0]
        if not np.array_equal(np.diff(first), np.ones(first.size - 1)):
            rate = time_rate(path, "column 1", first)
        # else the samples' numbers 0, 1, 2, ... (or 1, 2, 3, ...): an index, no rate (it
        # read as time in s, 1 Hz, which refused the rate --fs-hz stated)
        data = data[:, 1:]
    names = list(names or [])
    if len(names) != data.shape[1]:
        names = [f"ch{i}" for i in range(data.shape[1])]
    return SignalFile({n: data[:, i] for i, n in enumerate(names)}, rate, {},
                      rate_from="its first column (rising evenly: the time, in s)")


def write(path, signals, rate_hz, units):
    """Write channels to a ``.csv`` file that :func:`read` reads back the same, atomically."""
    import pandas as pd
    n = len(next(iter(signals.values())))
    cols = {"time_s": np.arange(n) / float(rate_hz)}
    for k, v in signals.items():
        cols[f"{k} [{units[k]}]" if units.get(k) else k] = np.asarray(v, dtype=float)
    atomic_write_text(path, pd.DataFrame(cols).to_csv(index=False, float_format="%.17g"))
