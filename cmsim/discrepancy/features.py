"""A record's features, segment by segment, and their model-uncertainty floor.

The features themselves are :func:`cmsim.features.relative_features` (the one feature
extractor): ratios and shape statistics that compare a model with a measurement whose
absolute scale is unknown. A record is cut into segments of equal length; the spread of a
feature over the segments is part of its noise (:mod:`cmsim.discrepancy.compare`).
"""

from __future__ import annotations

import numpy as np

from cmsim.errors import ParameterError
from cmsim.features import relative_features

__all__ = ["record_features", "feature_floor", "segments", "DB_FLOOR", "LOG_FLOOR"]

#: Least model uncertainty of a dB column (a line's level, a band's share), dB.
DB_FLOOR = 1.5
#: Least model uncertainty of a log column (kurtosis, crest), natural-log units.
LOG_FLOOR = 0.1


def feature_floor(name):
    """Model-uncertainty floor of a feature column, in its own unit.

    Parameters
    ----------
    name : str
        Column name (``*_log`` columns are natural logs, the others dB).

    Returns
    -------
    float
    """
    return LOG_FLOOR if name.endswith("_log") else DB_FLOOR


def segments(n_samples, fs_hz, seg_s, max_segments=None):
    """(start, stop) sample indices of consecutive segments of ``seg_s`` seconds.

    Parameters
    ----------
    n_samples : int
        Samples in the record.
    fs_hz : float
        Sample rate, Hz.
    seg_s : float
        Segment length, s.
    max_segments : int, optional
        At most this many segments, spread evenly over the record.

    Returns
    -------
    list of (int, int)
    """
    n = int(round(seg_s * fs_hz))
    k = n_samples // n
    if max_segments is not None and k > max_segments:
        starts = np.linspace(0, n_samples - n, max_segments).astype(int)
    else:
        starts = np.arange(k) * n
    return [(int(s), int(s) + n) for s in starts]


def record_features(x, fs_hz, freqs, bearings, seg_s, max_segments=None):
    """Features of every segment of a record.

    Parameters
    ----------
    x : ndarray
        Record.
    fs_hz : float
        Sample rate, Hz.
    freqs : RigFrequencies
        Frequencies at the record's speed.
    bearings : sequence of str
        Bearings whose defect families are read.
    seg_s : float
        Segment length, s.
    max_segments : int, optional
        At most this many segments, spread over the record.

    Returns
    -------
    (list of str, ndarray of shape (n_segments, n_features))
    """
    rows = [relative_features(x[a:b], fs_hz, freqs, bearings)
            for a, b in segments(x.size, fs_hz, seg_s, max_segments)]
    if not rows:
        raise ParameterError(f"record shorter than one {seg_s:g}-s segment", param="RECORD")
    names = list(rows[0])
    return names, np.array([[r[k] for k in names] for r in rows], dtype=float)
