"""A compared channel's samples: refused where nothing can be read from them (too few, not
finite, constant), doubted where they were clipped.

A converter or an amplifier driven past its range holds the signal at its rail: the peaks
of impacts are cut, so levels, kurtosis, crest factor and envelope lines read low and a
fault can be missed. Continuous data reach their largest and smallest values once each;
a clipped record sits on them for many samples (the share is stated, the record is still
compared: a warning, not a refusal).
"""

from __future__ import annotations

import numpy as np

from cmsim.errors import ParameterError

__all__ = ["checked_samples", "clipping_doubt", "count_doubt", "MIN_SAMPLES", "CLIPPED_MIN_SAMPLES",
           "CLIPPED_MIN_SHARE", "CLIPPED_MIN_LEVELS"]

#: Fewest samples of the compared channel (the speed and sample-rate inference need a few
#: hundred shaft revolutions' worth of resolution; a kurtogram needs 1024).
MIN_SAMPLES = 4096

#: Samples at the largest or smallest value that make a channel clipped: at least this many
#: and :data:`CLIPPED_MIN_SHARE` of its samples (every shared record has one at each).
CLIPPED_MIN_SAMPLES = 10
CLIPPED_MIN_SHARE = 1e-4

#: Fewest distinct values (to a millionth of its range) of a channel judged for clipping: a
#: periodic signal of P samples a period (a synthetic tone at fs/24) repeats its extremes by
#: construction with at most P values, while a converter driven past its range spans it
#: all (an 8-bit one's 256).
CLIPPED_MIN_LEVELS = 64


def checked_samples(x, channel, name):
    """The compared channel's samples, or the one line that says what is wrong with them:
    too few, some not finite (where the first is), or constant (nothing recorded).

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        The channel's samples.
    channel : str
        Its name, for the message.
    name : str
        The record, for the message.

    Returns
    -------
    numpy.ndarray
        ``x``, checked.
    """
    if x.size < MIN_SAMPLES:
        raise ParameterError(f"record {name}: channel {channel!r} holds {x.size} samples; "
                             f"needs >= {MIN_SAMPLES}", param="record",
                             allowed=f">= {MIN_SAMPLES} samples")
    bad = ~np.isfinite(x)
    if bad.any():
        raise ParameterError(f"record {name}: channel {channel!r} holds {int(bad.sum())} "
                             f"non-finite samples (NaN or inf) of {x.size}, the first at "
                             f"sample {int(np.argmax(bad))}; cmsim does not fill gaps: repair "
                             f"the file or cut it to a finite stretch", param="record",
                             allowed="finite samples")
    if np.ptp(x) == 0.0:
        raise ParameterError(f"record {name}: channel {channel!r} is constant (every sample "
                             f"{x[0]:g}): nothing was recorded; check the sensor, its cable "
                             f"and the channel chosen (--channel)", param="record",
                             allowed="a varying signal")
    return x


def clipping_doubt(x, channel, name):
    """The warning that a channel was clipped, or None.

    Parameters
    ----------
    x, channel, name
        As :func:`checked_samples` (``x`` finite and varying).

    Returns
    -------
    str or None
    """
    hi, lo = float(np.max(x)), float(np.min(x))
    tol = 1e-9 * (hi - lo)
    at = int(np.count_nonzero(x >= hi - tol)) + int(np.count_nonzero(x <= lo + tol))
    if at < max(CLIPPED_MIN_SAMPLES, CLIPPED_MIN_SHARE * x.size) \
            or np.unique(np.round((x - lo) / (hi - lo) * 1e6)).size < CLIPPED_MIN_LEVELS:
        return None
    return (f"record {name}: channel {channel!r} sits at its largest ({hi:.4g}) or smallest "
            f"({lo:.4g}) value in {at} samples ({100.0 * at / x.size:.2g} % of them): it was "
            f"clipped (the converter's or amplifier's range exceeded); the peaks above the "
            f"rail are lost, so levels, kurtosis and envelope lines read low and a fault may "
            f"be missed: record it again with more range")


def count_doubt(x, stated, channel, name):
    """The warning that a channel holds another number of samples than its metadata states
    (``n_samples``), or None: the file was cut or replaced, or the entry is another
    record's — and the rate, speed and load it states may be too.

    Parameters
    ----------
    x, channel, name
        As :func:`checked_samples`.
    stated : int or None
        The metadata's ``n_samples`` (None: not stated).

    Returns
    -------
    str or None
    """
    if stated is None or int(stated) == x.size:
        return None
    return (f"record {name}: metadata.json \"n_samples\" says {int(stated)}, channel "
            f"{channel!r} holds {x.size}: the file was cut or replaced, or the entry is "
            f"another record's (check the rate, speed and load it states)")
