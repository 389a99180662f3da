"""A record's columns read against a machine's signature library: which features are
compared (:func:`compared_columns`), their σ (:func:`feature_sigma`, :func:`sigma_of`), the
χ² of predicted rows (:func:`chi2_rows`, THE misfit of :mod:`cmsim.spectra.misfit`) and a
library entry's grid read between its points (:func:`interpolated`) — what the judge
(:mod:`cmsim.discrepancy.judge`), the machine's own checks
(:mod:`cmsim.discrepancy.machine_checks`) and the benchmarks stand on.
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.discrepancy.evaluator import feature_floor, rises, weight
from cmsim.spectra.misfit import misfit

__all__ = ["compared_columns", "feature_sigma", "sigma_of", "chi2_rows", "interpolated",
           "FLOOR_SHARE"]

#: The model-uncertainty floor of a feature's σ against a baseline, as a share of
#: :func:`~cmsim.discrepancy.evaluator.feature_floor` (the baseline is measured, not modelled).
FLOOR_SHARE = 0.5


def chi2_rows(meas, pred, sigma, names):
    """Robust χ² of predicted feature rows against measured features: THE misfit
    (:func:`cmsim.spectra.misfit.misfit`), each feature weighted by
    :func:`~cmsim.discrepancy.evaluator.weight`, calibrated (every feature but the statistics
    rises beyond its cap: :func:`~cmsim.discrepancy.evaluator.rises`).

    Parameters
    ----------
    meas, sigma : numpy.ndarray, shape (m,)
        Measured features and their uncertainties.
    pred : numpy.ndarray, shape (r, m)
        Predicted features, a row each.
    names : sequence of str
        Feature names (their weights and rules).

    Returns
    -------
    (numpy.ndarray of shape (r,), numpy.ndarray of shape (r, m))
        χ² of each row and each feature's share of it.
    """
    return misfit(meas, pred, sigma, np.array([weight(k) for k in names]),
                  np.array([rises(k, True) for k in names], dtype=bool))


def interpolated(values, table, steps):
    """(values, table) of a library entry with ``steps`` points between consecutive values
    (log-linear), as a comparison reads the grid.

    Parameters
    ----------
    values : sequence of float
        The entry's parameter values, increasing.
    table : numpy.ndarray, shape (len(values), n)
        Its features at each value.
    steps : int
        Points per interval.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
    """
    values = np.asarray(values, dtype=float)
    if values.size < 2:
        return values, table
    u = np.log(values) if np.all(values > 0) else values
    out_u, out_t = [], []
    for i in range(values.size - 1):
        for t in np.arange(steps) / steps:
            out_u.append(u[i] + t * (u[i + 1] - u[i]))
            out_t.append(table[i] + t * (table[i + 1] - table[i]))
    out_u.append(u[-1])
    out_t.append(table[-1])
    back = np.exp(out_u) if np.all(values > 0) else np.asarray(out_u)
    return back, np.asarray(out_t)


def compared_columns(names, lib, fit, held):
    """The features a record and its machine's library are compared on: read by both,
    finite in the record's fit and held-out rows and in the baseline's mean, one of each set
    of columns the record and the library both read alike (the two shafts of a 1:1 rig).
    Two families whose lines lie within the line rule's tolerance of each other read one line
    of the record alike, but not the library's: the model makes each fault's line where its
    kinematics put it, so each family keeps its column and the record's one line is read as
    either (the angle generator's ball at 2·BSF, 3 % over the BPFI it shared a window with,
    was read as an inner race: the ball's own line was dropped as a copy of it).

    Parameters
    ----------
    names : sequence of str
        The record's feature names (the columns of ``fit`` and ``held``).
    lib : SignatureLibrary
    fit, held : numpy.ndarray, shape (segments, len(names))
        The record's fit and held-out segment rows.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, list of str)
        Library columns, record columns and the names compared.
    """
    li, ri, seen = [], [], []
    for j, k in enumerate(names):
        if k not in lib.names:
            continue
        i = lib.column(k)
        col = np.concatenate([fit[:, j], held[:, j]])
        if not (np.any(np.isfinite(fit[:, j])) and np.any(np.isfinite(held[:, j]))
                and math.isfinite(lib.mean[i])):
            continue
        if any(np.array_equal(col, c, equal_nan=True) and _read_alike(lib, i, s)
               for c, s in seen):
            continue
        seen.append((col, i))
        li.append(i)
        ri.append(j)
    return (np.array(li, dtype=int), np.array(ri, dtype=int), [lib.names[i] for i in li])


def _read_alike(lib, i, j):
    """Whether the library's columns ``i`` and ``j`` hold the same numbers (its baseline's
    mean, spread and run-to-run spreads, every entry's prediction)."""
    cols = [i, j]
    return (np.array_equal(*lib.mean[cols], equal_nan=True)
            and np.array_equal(*lib.spread[cols], equal_nan=True)
            and np.array_equal(*lib.realisation[cols], equal_nan=True)
            and np.array_equal(*lib.run_spread[cols], equal_nan=True)
            and all(np.array_equal(*e.features[:, cols].T, equal_nan=True)
                    for e in lib.entries))


def feature_sigma(lib, li, names, n_fit, *, standing=False):
    """σ of each compared feature (:mod:`cmsim.discrepancy.judge`, step 2): with the
    library's realisation spread (the χ²'s), or with ``standing`` its run spread (the gate of
    a family that stands out: :attr:`~cmsim.machine.library.SignatureLibrary.run_spread`).

    Parameters
    ----------
    lib : SignatureLibrary
        The machine's library.
    li : numpy.ndarray of int
        The compared features' columns in the library.
    names : sequence of str
        Their names.
    n_fit : int
        Segments the record's mean is taken over.
    standing : bool
        The run spread instead of the realisation spread.

    Returns
    -------
    numpy.ndarray
    """
    run = lib.run_spread if standing else lib.realisation
    return sigma_of(lib.spread[li], run[li], names, n_fit, lib.segments)


def sigma_of(spread, realisation, names, n_fit, n_baseline):
    """σ of features against a baseline (:mod:`cmsim.discrepancy.judge`, step 2), from the
    baseline's segment-to-segment ``spread``, the ``realisation`` spread (run to run) and the
    judge's floor: spread²·(1/n_fit + 1/n_baseline) + realisation² + floor² (NaN spreads
    count 0).

    Parameters
    ----------
    spread, realisation : numpy.ndarray
        Per feature.
    names : sequence of str
        Their names (the floor is the feature kind's).
    n_fit, n_baseline : int
        Segments the record's and the baseline's means are taken over.

    Returns
    -------
    numpy.ndarray
    """
    floor = np.array([FLOOR_SHARE * feature_floor(k) for k in names])
    return np.sqrt(np.nan_to_num(spread) ** 2 * (1.0 / max(n_fit, 1) + 1.0 / n_baseline)
                   + np.nan_to_num(realisation) ** 2 + floor ** 2)
