"""THE misfit of features: one robust χ² wherever a record is compared with a prediction.

A feature off by z of its σ adds

* z² up to :data:`Z_CAP`;
* beyond it, :data:`Z_CAP`² where it is **capped** (a misfit no cause can mend — an unknown
  transfer path next to a fault — does not hide what another cause explains), or
  Z_CAP·(2z − Z_CAP) where it **rises** (Huber's loss, continuous in value and slope: a cause
  that brings a far feature 10σ nearer explains more than one that leaves it at 20σ);

times its weight. A feature a prediction could not read (NaN) counts as :data:`MISSING_Z` σ
off. Which features rise and their weights are the comparison's
(:func:`cmsim.discrepancy.evaluator.rises`, :func:`~cmsim.discrepancy.evaluator.weight`);
the comparison against a model (:mod:`cmsim.discrepancy.compare`), against a machine's
baseline (:mod:`cmsim.discrepancy.judge`) and the calibration's choice between readings of a
path (:mod:`cmsim.machine.calibration`) all sum this loss.

References
----------
.. [1] P. J. Huber, "Robust estimation of a location parameter", Ann. Math. Statist. 35
   (1964) 73-101.
"""

from __future__ import annotations

import numpy as np

__all__ = ["robust_loss", "misfit", "Z_CAP", "MISSING_Z"]

#: Where a feature's loss stops growing as z² (capped or rising linearly beyond), σ.
Z_CAP = 4.0

#: A feature a prediction could not read counts as this far off, σ.
MISSING_Z = 3.0


def robust_loss(z, rising=False):
    """The loss of features off by ``z`` σ (module docstring).

    Parameters
    ----------
    z : float or numpy.ndarray
        Departures, σ (their sign is ignored).
    rising : bool or numpy.ndarray of bool
        Whether each rises beyond :data:`Z_CAP` (broadcast against ``z``).

    Returns
    -------
    float or numpy.ndarray

    Examples
    --------
    >>> float(robust_loss(3.0)), float(robust_loss(10.0)), float(robust_loss(10.0, True))
    (9.0, 16.0, 64.0)
    """
    z = np.abs(np.asarray(z, dtype=float))
    out = np.where(z <= Z_CAP, z * z, np.where(rising, Z_CAP * (2.0 * z - Z_CAP),
                                                Z_CAP * Z_CAP))
    return float(out) if out.ndim == 0 else out


def misfit(meas, pred, sigma, weights=1.0, rising=False):
    """Robust χ² of predicted feature rows against measured features.

    Parameters
    ----------
    meas, sigma : numpy.ndarray, shape (m,)
        Measured features and their uncertainties (> 0).
    pred : numpy.ndarray, shape (r, m) or (m,)
        Predicted features, a row each (NaN: not read, :data:`MISSING_Z` σ off).
    weights : float or numpy.ndarray, shape (m,)
        Each feature's weight.
    rising : bool or numpy.ndarray of bool, shape (m,)
        Whether each feature's loss rises beyond :data:`Z_CAP`.

    Returns
    -------
    (numpy.ndarray of shape (r,), numpy.ndarray of shape (r, m))
        χ² of each row and each feature's share of it.

    Examples
    --------
    >>> chi, per = misfit(np.zeros(2), np.array([[1.0, np.nan]]), np.ones(2))
    >>> float(chi[0]), per[0].tolist()
    (10.0, [1.0, 9.0])
    """
    pred = np.atleast_2d(np.asarray(pred, dtype=float))
    z = np.abs(pred - np.asarray(meas, dtype=float)) / np.asarray(sigma, dtype=float)
    z = np.where(np.isfinite(z), z, MISSING_Z)
    per = np.asarray(weights, dtype=float) * robust_loss(z, rising)
    return per.sum(axis=1), per
