"""What every format's reader shares: :class:`SignalFile`, 1-D channels, a sample rate
from a step or a time base, an optional library named by its extra."""

from __future__ import annotations

import importlib
import math
import re
from pathlib import Path
from typing import NamedTuple

import numpy as np

from cmsim.errors import ParameterError

__all__ = ["SignalFile", "channel_1d", "optional_module", "rate_of_step", "time_rate",
           "even_time", "rate_within", "one_rate", "TIME_NAME", "TIME_STEP_TOLERANCE"]


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
    counts : frozenset of str
        Channels stored as integers and not scaled by the reader: counts of a converter,
        which need a calibration to be a physical quantity.
    said : tuple of str
        Corrections the reader made to what the file states, each one line for the user
        (:func:`~cmsim.measured.readers.read_file` warns them): a header-less time column
        read in ms.
    """

    signals: dict
    rate_hz: float | None = None
    units: dict = {}
    speed_rpm: float | None = None
    calibration: float | None = None
    rate_from: str = "the file header"
    counts: frozenset = frozenset()
    said: tuple = ()


#: Fewest stamps a time base is read from (:func:`even_time`).
MIN_TIME_STAMPS = 8


def channel_1d(path, name, a):
    """A stored array as a 1-D channel of real samples: (n,), (n, 1) and (1, n) are one
    channel; any other shape is refused (a silently dropped channel would let another one be
    compared), and so are samples that are not real numbers (complex values — a spectrum, an
    FRF or an analytic signal — would lose their imaginary part in the conversion, text
    would not convert)."""
    a = np.asarray(a)
    if a.dtype.kind not in "biuf":
        what = "complex values" if a.dtype.kind == "c" else f"{a.dtype} values"
        raise ParameterError(f"record {path}: channel {name!r} holds {what}, not real "
                             f"samples; store the real time history (a spectrum or an FRF "
                             f"is not one)", param="record", allowed="real samples")
    if a.ndim == 2 and 1 in a.shape:
        a = a.reshape(-1)
    if a.ndim != 1:
        raise ParameterError(f"record {path}: channel {name!r} has shape {a.shape}; store "
                             f"one 1-D array per channel (e.g. {name}_0, {name}_1, ... for "
                             f"the columns)", param="record", allowed="1-D arrays")
    return np.asarray(a, dtype=float)


def optional_module(module, extra, path):
    """``import module``, or one line naming the extra that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ParameterError(f"record {path}: reading and writing {Path(path).suffix} files "
                             f"needs {module}, an optional dependency: pip install "
                             f"cmsim[{extra}]", param="record",
                             allowed=f"{module} installed (cmsim[{extra}])") from None


def rate_of_step(step, digits=None):
    """The sample rate of a sample spacing ``step`` (s); with ``digits``, the spacing was
    printed with that many significant digits, and the rate is the one with the fewest
    digits whose spacing prints the same (1.95313e-05 s → 51200 Hz, not 51199.87)."""
    rate = 1.0 / float(step)
    if digits is None:
        return rate
    ulp = 10.0 ** (math.floor(math.log10(abs(step))) - digits + 1)
    return rate_within(step, 0.5000001 * ulp)


#: A CSV time column's name (``t``, ``time``, ``zeit``, ``time_s``, ``Time (s)``,
#: ``time [ms]``, ``Time [sec]``, ``time [us]``, any case) → its groups the unit (``s`` when
#: none is written; :data:`TIME_UNITS`).
TIME_NAME = re.compile(r"^(?:t|time|zeit)(?:_(s|sec|ms|us|µs)|\s*\[\s*(s|sec|ms|us|µs)\s*\]"
                       r"|\s*\(\s*(s|sec|ms|us|µs)\s*\))?$", re.IGNORECASE)

#: A time column's unit → seconds.
TIME_UNITS = {"s": 1.0, "sec": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}

#: Largest relative departure of one time step of a CSV from the mean step that still
#: counts as evenly spaced (time stamps printed to 2 significant digits of the step).
TIME_STEP_TOLERANCE = 0.1

#: Coarsest print resolution of a time base, in sample steps, that still gives its rate:
#: stamps printed to a resolution q sit within q/2 of the even instants, so repeated or
#: skipped stamps (0.0001 s printed at 12 kHz: steps of 0 and 0.0001) are rounding, not a
#: gap; coarser than two steps, the rate would rest on the first and last stamps alone.
TIME_MAX_RESOLUTION_STEPS = 2.0


def _print_resolutions(t):
    """The decimal resolution each value of ``t`` was printed to — the coarsest power of ten
    it is a multiple of (1e-4 for 0.0123; four decimals, or six significant digits, print
    that way) — or None where a value lies on no decimal grid coarser than 1e-12 of the
    largest (binary floats, never printed)."""
    scale = max(float(np.max(np.abs(t))), 1e-300)
    res = np.full(t.shape, np.nan)
    for d in range(-3, 16):
        q = 10.0 ** -d
        if q < 1e-12 * scale:
            break
        k = t / q
        res[np.isnan(res) & (np.abs(k - np.round(k)) <= 1e-6)] = q
    return None if np.isnan(res).any() else res


def even_time(t):
    """The step of a time base ``t`` (any unit) and how far its stamps lie from the even
    instants, or None where it is no time base: at least 8 values rising in even steps —
    within :data:`TIME_STEP_TOLERANCE` of the mean step, or, for stamps printed to a
    decimal resolution (their median) of at most :data:`TIME_MAX_RESOLUTION_STEPS` steps,
    each within half its own resolution of the even instants (the rounding: a repeated
    stamp is no gap) — what no vibration channel does.

    Returns
    -------
    (step, spread) : tuple of float, or None
        The step (the straight line through the stamps) and the stamps' largest distance
        from that line: their printing's rounding, or a clock's jitter.
    """
    t = np.asarray(t, dtype=float)
    if t.size < MIN_TIME_STAMPS or not np.all(np.isfinite(t)):
        return None
    steps = np.diff(t)
    step = (t[-1] - t[0]) / (t.size - 1)
    if not step > 0:
        return None
    i = np.arange(t.size) - 0.5 * (t.size - 1)
    slope = float(np.dot(i, t - t.mean()) / np.dot(i, i))
    spread = float(np.max(np.abs(t - t.mean() - slope * i)))
    if np.all(np.abs(steps - step) <= TIME_STEP_TOLERANCE * step):
        return slope, spread
    q = _print_resolutions(t)
    if q is None or np.any(steps < 0) or np.median(q) > TIME_MAX_RESOLUTION_STEPS * step:
        return None
    per = step / float(np.median(q))   # steps per resolution, known to per/(n-1)
    if abs(per - round(per)) <= 2.0 * per / (t.size - 1):
        return None      # the even instants print exactly at this resolution: no rounding
    # the line through the stamps, each weighted by its resolution (six significant digits
    # print the first second finer than the next)
    w = q ** -2.0
    tm, im = np.average(t, weights=w), np.average(i, weights=w)
    slope = float(np.sum(w * (i - im) * (t - tm)) / np.sum(w * (i - im) ** 2))
    off = np.abs(t - tm - slope * (i - im))
    if np.any(off > 0.6 * q):
        return None
    return slope, float(np.max(off))


def time_rate(path, name, t, unit="s", said=None):
    """The sample rate of a time column or vector ``t`` (a unit of :data:`TIME_UNITS`; a
    CSV's time column, a ``.mat`` file's ``t``), checked for even steps (:func:`even_time`:
    stamps printed coarser than a step are read through their rounding): a gap or a jump
    back is refused, naming the step farthest from the mean. The rate is the one with the
    fewest digits whose step the stamps allow (12 kHz from stamps printed to 0.1 ms, not
    11999.7 Hz). Stamps printed coarser than :data:`TIME_MAX_RESOLUTION_STEPS` steps (1 ms
    at 12 kHz) but even within their rounding give no rate: None, and why is appended to
    ``said`` (the rate must then be stated another way)."""
    t = np.asarray(t, dtype=float) * TIME_UNITS[unit.lower()]
    if t.size < MIN_TIME_STAMPS:
        raise ParameterError(f"record {path}: time {name!r} holds {t.size} stamps, too few to "
                             f"read a sample rate from (at least {MIN_TIME_STAMPS}; a record "
                             f"needs thousands of samples)", param="record",
                             allowed=f">= {MIN_TIME_STAMPS} time stamps")
    found = even_time(t)
    if found is not None:
        step, spread = found
        # stamps within ±spread of a line pin its step to within 2·spread over the record
        return rate_within(step, max(2.0 * spread / (t.size - 1), 1e-12 * step))
    steps = np.diff(t)
    step = (t[-1] - t[0]) / (t.size - 1)
    q = _print_resolutions(t) if t.size >= 8 and np.all(np.isfinite(t)) else None
    if said is not None and q is not None and step > 0 and np.all(steps >= 0) \
            and np.median(q) >= (1.0 - 1e-9) * TIME_MAX_RESOLUTION_STEPS * step \
            and np.all(np.abs(t - t[0] - step * np.arange(t.size)) <= 1.1 * q):
        said.append(f"record {path}: time {name!r} is printed to {np.median(q):.3g} s, "
                    f"coarser than two samples ({step:.3g} s apart): it gives no sample rate "
                    f"and cannot show a gap; the rate is taken from where else it is stated")
        return None
    off = np.abs(steps - step)
    i = int(np.argmax(np.where(np.isfinite(off), off, np.inf))) if steps.size else 0
    raise ParameterError(
        f"record {path}: time {name!r} is not evenly spaced (step {i} from "
        f"{t[i]:.9g} s to {t[i + 1]:.9g} s, the mean step is {step:.6g} s); cmsim reads "
        f"evenly sampled records: export without gaps, or cut the record at the gap",
        param="record", allowed="evenly spaced time stamps")


def rate_within(step, tolerance):
    """The sample rate with the fewest significant digits whose step lies within
    ``tolerance`` (s) of ``step``."""
    rate = 1.0 / float(step)
    for k in range(1, 16):
        r = float(f"{rate:.{k}g}")
        if abs(1.0 / r - step) <= tolerance:
            return r
    return rate


def one_rate(path, rates, tolerance=0.0):
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
