"""Scores of a diagnostic algorithm: accuracy, macro-F1, confusion matrix, ROC AUC, detection.

Every function takes plain sequences (labels as str, scores as float) and returns plain
values, so a user can score predictions made outside the harness with the same definitions.

* **accuracy** — share of records whose predicted label equals the true label;
* **macro-F1** — the unweighted mean over classes of F1 = 2·TP / (2·TP + FP + FN), classes
  being the union of the true and the predicted labels (a class with no true and no predicted
  record cannot occur; F1 of a class never predicted and never present would be 0/0 and is
  not counted), as scikit-learn's ``f1_score(average="macro")``;
* **confusion matrix** — rows = true class, columns = predicted class, counts;
* **ROC AUC** (one-vs-rest) — the probability that a random positive scores above a random
  negative, ties counted one half (the Mann-Whitney U statistic / (n_pos·n_neg));
* **detection threshold** at a false-alarm rate α (5 %) — the (1 − α) quantile (linear
  interpolation, :func:`numpy.quantile` default) of the healthy records' fault scores; a
  record is *detected* when its fault score is strictly above it;
* **detection against severity** — per fault class, the detection rate at each severity and
  the smallest severity detected (:func:`detection_vs_severity`).

References
----------
.. [1] T. Fawcett, "An introduction to ROC analysis", Pattern Recognition Letters 27 (2006)
   861-874 (AUC = Mann-Whitney U / (n_pos·n_neg)).
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.errors import ParameterError, check_range

__all__ = ["accuracy", "confusion_matrix", "f1_scores", "macro_f1", "roc_auc",
           "one_vs_rest_auc", "detection_threshold", "detection_vs_severity",
           "FALSE_ALARM_RATE", "HEALTHY"]

#: Label of a fault-free record.
HEALTHY = "healthy"

#: False-alarm rate on the healthy records at which detection is scored (5 %).
FALSE_ALARM_RATE = 0.05


def _labels(y, name):
    y = [str(v) for v in y]
    if not y:
        raise ParameterError(f"{name} is empty", param=name)
    return y


def _pair(y_true, y_pred):
    t, p = _labels(y_true, "y_true"), _labels(y_pred, "y_pred")
    if len(t) != len(p):
        raise ParameterError(f"y_true and y_pred differ in length ({len(t)} vs {len(p)})",
                             param="y_pred")
    return t, p


def accuracy(y_true, y_pred):
    """Share of correct labels, in [0, 1].

    Parameters
    ----------
    y_true, y_pred : sequence of str, shape (n,)
        True and predicted labels.

    Examples
    --------
    >>> accuracy(["a", "b", "b", "c"], ["a", "b", "c", "c"])
    0.75
    """
    t, p = _pair(y_true, y_pred)
    return sum(a == b for a, b in zip(t, p)) / len(t)


def confusion_matrix(y_true, y_pred, classes=None):
    """Counts of (true, predicted) label pairs.

    Parameters
    ----------
    y_true, y_pred : sequence of str, shape (n,)
        True and predicted labels.
    classes : sequence of str, optional
        Row/column order; default the sorted union of both label sets, ``"healthy"`` first.

    Returns
    -------
    classes : list of str, shape (k,)
    matrix : numpy.ndarray of int, shape (k, k)
        ``matrix[i, j]`` = records of true class i predicted as class j.
    """
    t, p = _pair(y_true, y_pred)
    if classes is None:
        classes = sorted(set(t) | set(p), key=lambda c: (c != HEALTHY, c))
    classes = list(classes)
    index = {c: i for i, c in enumerate(classes)}
    m = np.zeros((len(classes), len(classes)), dtype=int)
    for a, b in zip(t, p):
        if a not in index or b not in index:
            raise ParameterError(f"label {a if a not in index else b!r} is not one of the "
                                 f"classes {classes}", param="classes")
        m[index[a], index[b]] += 1
    return classes, m


def f1_scores(y_true, y_pred):
    """F1 = 2·TP / (2·TP + FP + FN) of each class of the union of true and predicted labels.

    Parameters
    ----------
    y_true, y_pred : sequence of str, shape (n,)
        True and predicted labels.

    Returns
    -------
    dict of str to float
    """
    classes, m = confusion_matrix(y_true, y_pred)
    tp = np.diag(m).astype(float)
    fp = m.sum(axis=0) - tp
    fn = m.sum(axis=1) - tp
    return {c: float(2 * tp[i] / (2 * tp[i] + fp[i] + fn[i])) for i, c in enumerate(classes)}


def macro_f1(y_true, y_pred):
    """Unweighted mean of :func:`f1_scores` over the classes.

    Parameters
    ----------
    y_true, y_pred : sequence of str, shape (n,)
        True and predicted labels.

    Examples
    --------
    >>> round(macro_f1(["a", "a", "b", "b"], ["a", "b", "b", "b"]), 4)   # F1: 2/3, 4/5
    0.7333
    """
    f = f1_scores(y_true, y_pred)
    return float(np.mean(list(f.values())))


def roc_auc(positive, scores):
    """Area under the ROC curve of ``scores`` for the binary labels ``positive``.

    Parameters
    ----------
    positive : sequence of bool, shape (n,)
        True for the positive class.
    scores : sequence of float, shape (n,)
        Higher = more likely positive; NaN scores are left out.

    Returns
    -------
    float
        AUC in [0, 1] (0.5 = chance; ties count one half); NaN without a positive or a
        negative.

    Examples
    --------
    >>> roc_auc([False, False, True, True], [0.1, 0.4, 0.35, 0.8])
    0.75
    """
    pos = np.asarray(positive, dtype=bool)
    s = np.asarray(scores, dtype=float)
    if pos.shape != s.shape:
        raise ParameterError(f"positive and scores differ in shape ({pos.shape} vs {s.shape})",
                             param="scores")
    ok = np.isfinite(s)
    sp, sn = s[ok & pos], s[ok & ~pos]
    if sp.size == 0 or sn.size == 0:
        return math.nan
    greater = (sp[:, None] > sn[None, :]).sum()
    ties = (sp[:, None] == sn[None, :]).sum()
    return float((greater + 0.5 * ties) / (sp.size * sn.size))


def one_vs_rest_auc(y_true, scores):
    """ROC AUC of each class against the others, from per-class scores.

    Parameters
    ----------
    y_true : sequence of str, shape (n,)
        True labels.
    scores : sequence of dict of str to float, shape (n,)
        Per record, class → score (a missing class or a NaN score leaves the record out of
        that class's AUC).

    Returns
    -------
    dict of str to float
        Class → AUC for every class scored in at least one record (NaN where the class has
        no positive or no negative record with a score).
    """
    t = _labels(y_true, "y_true")
    if len(scores) != len(t):
        raise ParameterError(f"y_true and scores differ in length ({len(t)} vs {len(scores)})",
                             param="scores")
    classes = sorted({c for s in scores if s for c in s}, key=lambda c: (c != HEALTHY, c))
    out = {}
    for c in classes:
        s = [float(d.get(c, math.nan)) if d else math.nan for d in scores]
        out[c] = roc_auc([lab == c for lab in t], s)
    return out


def detection_threshold(healthy_scores, false_alarm_rate=FALSE_ALARM_RATE):
    """Fault-score threshold that keeps the false alarms on healthy records at ``false_alarm_rate``.

    Parameters
    ----------
    healthy_scores : sequence of float, shape (n,)
        Fault scores of healthy records (NaN left out).
    false_alarm_rate : float
        α in (0, 1); the threshold is the (1 − α) quantile, linearly interpolated.

    Returns
    -------
    float
        Threshold; a record is detected when its score is strictly above it. NaN without a
        finite healthy score.

    Examples
    --------
    >>> detection_threshold(np.arange(1.0, 21.0))   # 95th percentile of 1..20
    19.05
    """
    a = check_range("false_alarm_rate", false_alarm_rate, 0.0, 1.0, lo_open=True, hi_open=True)
    s = np.asarray(healthy_scores, dtype=float)
    s = s[np.isfinite(s)]
    if s.size == 0:
        return math.nan
    return float(np.quantile(s, 1.0 - a))


def detection_vs_severity(y_true, severity, fault_score, *, false_alarm_rate=FALSE_ALARM_RATE):
    """Detection rate against fault severity at a fixed false-alarm rate on healthy records.

    Parameters
    ----------
    y_true : sequence of str, shape (n,)
        True labels (``"healthy"`` for the fault-free records).
    severity : sequence of float, shape (n,)
        Fault severity (its main size, SI), NaN for healthy records or when unknown.
    fault_score : sequence of float, shape (n,)
        Fault score of each record (higher = more likely faulty).
    false_alarm_rate : float
        α of :func:`detection_threshold`.

    Returns
    -------
    dict
        ``threshold`` (float), ``false_alarm_rate`` (the rate reached on the healthy records)
        and ``classes``: per fault label, ``severity`` (sorted distinct severities),
        ``detection_rate`` (share detected at each), ``n`` (records at each),
        ``min_detected_severity`` (smallest severity with a detected record, NaN if none) and
        ``min_reliable_severity`` (smallest s such that every record of severity >= s is
        detected, NaN if the largest is missed), plus ``detection_rate_all`` over the class.
        Without healthy records the threshold is NaN and nothing is detected.
    """
    t = _labels(y_true, "y_true")
    sev = np.asarray(severity, dtype=float)
    sc = np.asarray(fault_score, dtype=float)
    if not (len(t) == sev.size == sc.size):
        raise ParameterError("y_true, severity and fault_score differ in length",
                             param="fault_score")
    lab = np.asarray(t)
    healthy = lab == HEALTHY
    thr = detection_threshold(sc[healthy], false_alarm_rate)
    det = (sc > thr) if math.isfinite(thr) else np.zeros(sc.size, dtype=bool)
    hs = sc[healthy & np.isfinite(sc)]
    fa = float(np.mean(hs > thr)) if hs.size and math.isfinite(thr) else math.nan
    classes = {}
    for c in sorted(set(t) - {HEALTHY}):
        m = lab == c
        s_c, d_c = sev[m], det[m]
        known = np.isfinite(s_c)
        levels = np.unique(s_c[known])
        rate = [float(d_c[known][s_c[known] == v].mean()) for v in levels]
        n = [int((s_c[known] == v).sum()) for v in levels]
        detected = levels[[r > 0 for r in rate]] if levels.size else levels
        reliable = math.nan
        for v in levels[::-1]:
            if d_c[known][s_c[known] >= v].all():
                reliable = float(v)
            else:
                break
        classes[c] = {"severity": [float(v) for v in levels], "detection_rate": rate, "n": n,
                      "min_detected_severity": float(detected[0]) if detected.size else math.nan,
                      "min_reliable_severity": reliable,
                      "detection_rate_all": float(d_c.mean()) if d_c.size else math.nan}
    return {"threshold": thr, "false_alarm_rate": fa, "classes": classes}
