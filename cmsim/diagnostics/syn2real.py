"""Sim-to-real benchmark: train a bearing-fault classifier on cmsim data, test it on real records.

Layout of the windows (issue 15)
    Every record is cut into windows of ``window`` samples (default 4096 = 0.34 s at 12 kHz)
    starting every ``hop`` samples: training (synthetic) records with ``hop = window // 2``
    (1-s records give 4 half-overlapping windows), test (measured) records with
    ``hop = window`` (no overlap: a 10-s CWRU record gives 29 windows). A window carries the
    id of its record (``groups``); the training side holds only synthetic records and the
    test side only measured ones, so no window of a record is on both sides
    (:func:`check_disjoint` asserts it for every evaluation).

Features (:func:`envelope_features`), in shaft orders so that a model trained at one speed
transfers to another
    The envelope-families extractor of :mod:`cmsim.features.envelope` in a fixed bank of
    bands (:func:`~cmsim.features.envelope.band_bank_features`): each window is band-passed
    in overlapping bands of width fs/8 spaced fs/16 (12 kHz: 500-2000, 1250-2750, ...,
    4250-5750 Hz); at each line of the bearing's families (BPFO ×1, 2, 3; BPFI ×1, 2 and ± the
    shaft rate; 2 BSF ×1, 2 and ± FTF; FTF; shaft ×1, 2; placed at the window's orders × its
    shaft rate) the line (the one line rule; the ±1.5 bins of a 0.34-s window hold the slip,
    :data:`~cmsim.features.lines.EXACT_TOLERANCE`) over its local median. Features: log of that ratio, the largest and the median over the
    bands, per line; each family's mean log ratio in its best band; the log kurtosis of the
    window and the largest log kurtosis of a band envelope. All ratios are dimensionless, so
    the unknown units and gains of a real accelerometer do not matter.

Classifiers (:data:`CLASSIFIERS`)
    ``envelope`` — the training-free envelope rule of :mod:`cmsim.diagnostics.baselines`
    (the family scores of :mod:`cmsim.features.envelope`) read from the best of the bands
    above: the family with the largest mean ratio, or healthy when that ratio is
    below one threshold, chosen on the training windows (largest balanced accuracy).
    ``forest`` — a scikit-learn random forest on the features (``pip install cmsim[ml]``),
    ``logistic`` — a scikit-learn logistic regression on the standardised features.

Scores (:func:`score_windows`): balanced accuracy (mean recall over the classes present in
the test set), per-class recall, macro-AUROC (one class against the rest, mean over the test
classes), the confusion matrix, and record-level votes (majority of a record's windows).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cmsim.datasets import load
from cmsim.diagnostics.metrics import confusion_matrix, roc_auc
from cmsim.errors import ParameterError
from cmsim.features.envelope import ENVELOPE_LINE_NAMES, FAULT_FAMILIES, band_bank_features
from cmsim.features.lines import EXACT_TOLERANCE
from cmsim.frequencies import BearingFrequencies
from cmsim.measured import load_measured
from cmsim.measured.schema import read_metadata

try:                                    # optional: pip install cmsim[ml]
    from sklearn.ensemble import RandomForestClassifier
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler
except ImportError:                     # pragma: no cover
    RandomForestClassifier = None

__all__ = ["WindowSet", "synthetic_windows", "training_channel", "measured_windows",
           "envelope_features",
           "FEATURE_LINES", "CLASSIFIERS", "make_classifier", "EnvelopeRule",
           "score_windows", "check_disjoint", "evaluate_syn2real", "DEFAULT_WINDOW"]

#: Samples per window at 12 kHz (0.34 s); :func:`default_window` scales it with fs.
DEFAULT_WINDOW = 4096
#: Fault classes in the order the confusion matrix lists them.
CLASS_ORDER = ("healthy", "inner_race", "ball", "outer_race")


@dataclass(frozen=True, eq=False)
class WindowSet:
    """Windows of one side of the benchmark.

    Attributes
    ----------
    x : numpy.ndarray, shape (n, window)
        Signal windows (mean removed), float32, any unit.
    y : numpy.ndarray of str, shape (n,)
        Label of each window's record (answer key: for scoring and training only).
    groups : numpy.ndarray of str, shape (n,)
        Record id of each window.
    orders : numpy.ndarray, shape (n, 4)
        BPFO, BPFI, BSF, FTF of each window's record in shaft orders.
    shaft_hz : numpy.ndarray, shape (n,)
        Shaft rate of each window's record, Hz.
    fs_hz : float
        Sample rate, Hz.
    skipped : dict of str to str
        Records left out, record id → why (a measured record that could not be read or
        whose metadata its own lines refuse: one never stops the others).
    """

    x: np.ndarray
    y: np.ndarray
    groups: np.ndarray
    orders: np.ndarray
    shaft_hz: np.ndarray
    fs_hz: float
    skipped: dict = field(default_factory=dict)

    def __len__(self):
        return len(self.y)


def default_window(fs_hz):
    """Window length, samples: about 0.34 s (4096 at 12 kHz), a power of two."""
    return int(2 ** round(math.log2(DEFAULT_WINDOW * fs_hz / 12_000.0)))


def _cut(x, window, hop, limit=None):
    x = np.asarray(x, dtype=np.float32)
    starts = list(range(0, x.size - window + 1, hop))
    if limit is not None:
        starts = starts[:limit]
    if not starts:
        raise ParameterError(f"window: a record of {x.size} samples is shorter than the "
                             f"window of {window} samples", param="window")
    w = np.stack([x[s:s + window] for s in starts])
    return w - w.mean(axis=1, keepdims=True)


def _orders(bf):
    fr = bf.shaft_hz
    return np.array([bf.bpfo_hz / fr, bf.bpfi_hz / fr, bf.bsf_hz / fr, bf.ftf_hz / fr])


def _assemble(parts, fs_hz, skipped=None):
    xs, ys, gs, os_, fs = zip(*parts)
    return WindowSet(np.concatenate(xs), np.concatenate(ys), np.concatenate(gs),
                     np.concatenate(os_), np.concatenate(fs), float(fs_hz),
                     dict(skipped or {}))


def training_channel(ds):
    """The channel a classifier trains on in a generated dataset: its machine's, else its
    first housing accelerometer (``accel_*``).

    Parameters
    ----------
    ds : cmsim.datasets.Dataset

    Returns
    -------
    str

    Raises
    ------
    ParameterError
        The dataset has no such channel.
    """
    machine = (ds.spec.get("machine") or {}).get("machine", {}).get("channel")
    accel = [machine] if machine else [c for c in ds.channels if c.startswith("accel_")]
    if not accel:
        raise ParameterError(f"the dataset has no accel_* channel to train on (only states "
                             f"and forces, {len(ds.channels)} channels; a spec makes one with "
                             f"[sensor] channels = [\"accel_1b1_y\"])", param="channel")
    return accel[0]


def synthetic_windows(dataset, channel=None, window=None, hop=None, bearing=None,
                      max_records=None):
    """Windows of a generated cmsim dataset (:func:`cmsim.datasets.load`).

    Parameters
    ----------
    dataset : cmsim.datasets.Dataset or str or Path
    channel : str, optional
        Default: the channel of the machine the dataset was made through, else the first
        ``accel_*`` channel.
    window : int, optional
        Samples per window (default :func:`default_window`).
    hop : int, optional
        Samples between window starts (default ``window // 2``).
    bearing : str, optional
        Bearing whose frequencies label the lines (default: the first of the rig).
    max_records : int, optional
        Use only the first records (tests).

    Returns
    -------
    WindowSet
    """
    ds = load(dataset) if isinstance(dataset, (str, Path)) else dataset
    if channel is None:
        channel = training_channel(ds)
    if channel not in ds.channels:
        raise ParameterError(f"channel: {channel!r} is not in the dataset "
                             f"{list(ds.channels)}", param="channel")
    window = int(window or default_window(ds.fs_hz))
    hop = int(hop or window // 2)
    ok = ds.manifest[ds.manifest["status"] == "ok"]
    ids = list(ok["record_id"])[:max_records]
    parts = []
    for rid in ids:
        rec = ds.record(rid)
        w = _cut(rec.signals[channel], window, hop)
        bf = rec.frequencies.bearing(bearing)
        n = len(w)
        parts.append((w, np.full(n, rec.labels["fault_label"], dtype=object),
                      np.full(n, f"syn:{rid}", dtype=object), np.tile(_orders(bf), (n, 1)),
                      np.full(n, bf.shaft_hz)))
    return _assemble(parts, ds.fs_hz)


def _measured_channel(folder, bearing):
    meta = read_metadata(folder)
    sensors = meta.get("sensors") or {}
    bearings = list(((meta.get("geometry") or {}).get("bearings") or {}))
    key = bearing or (bearings[0] if bearings else None)
    for ch, s in sensors.items():
        if s.get("near") == key:
            return ch, key
    if len(meta.get("channels") or {}) == 1:
        return next(iter(meta["channels"])), key
    raise ParameterError(f"{folder}: no sensor near bearing {key!r} in metadata.json; give "
                         f"the channel", param="channel")


def measured_windows(folder, channel=None, window=None, hop=None, bearing=None,
                     max_windows=None, trust_metadata=False):
    """Windows of a folder of measured records (``metadata.json`` schema). A record that
    cannot be read (missing, damaged, its metadata refused by its own lines) is left out
    and named in :attr:`WindowSet.skipped`; the others are windowed.

    Parameters
    ----------
    folder : str or Path
    channel : str, optional
        Default: the sensor the metadata puts near ``bearing``.
    window : int, optional
        Default :func:`default_window`.
    hop : int, optional
        Default ``window`` (no overlap).
    bearing : str, optional
        Bearing key of ``geometry.bearings`` (default the first).
    max_windows : int, optional
        At most this many windows per record (the first ones; tests).
    trust_metadata : bool
        Read every record's stated rate and speed unchecked
        (:func:`cmsim.measured.read_record`).

    Returns
    -------
    WindowSet
        Labels from the answer key, for scoring only; the features never read them.

    Raises
    ------
    ParameterError
        No record of the folder could be read (the first one's reason), a channel missing
        from a record, records at different rates, a record shorter than the window.
    """
    ds = load_measured(folder, trust_metadata=trust_metadata)
    if not len(ds):
        raise ParameterError(next(iter(ds.unreadable.values()), f"{folder}: no recording"),
                             param="dataset")
    ch, key = _measured_channel(folder, bearing) if channel is None else (channel, bearing)
    parts, fs0 = [], None
    for rec in ds:
        sig = rec.signals
        if ch not in sig:
            raise ParameterError(f"channel: {ch!r} is not in record {rec.record_id} "
                                 f"({sorted(sig)})", param="channel")
        fs0 = fs0 or rec.fs_hz
        if abs(rec.fs_hz - fs0) > 1e-6 * fs0:
            raise ParameterError(f"{folder}: records at different sample rates", param="dataset")
        win = int(window or default_window(rec.fs_hz))
        w = _cut(sig[ch], win, int(hop or win), max_windows)
        bf = rec.frequencies.bearing(key)
        n = len(w)
        label = ds.answer_key(rec.record_id)["fault_label"]
        parts.append((w, np.full(n, label, dtype=object),
                      np.full(n, f"real:{rec.record_id}", dtype=object),
                      np.tile(_orders(bf), (n, 1)), np.full(n, bf.shaft_hz)))
    return _assemble(parts, fs0, ds.unreadable)


# ---------------------------------------------------------------------- features
#: Names of the feature lines (see the module docstring).
FEATURE_LINES = ENVELOPE_LINE_NAMES
_FAMILIES = FAULT_FAMILIES


def envelope_features(ws):
    """Order-normalised envelope-spectrum features of every window (module docstring).

    Parameters
    ----------
    ws : WindowSet

    Returns
    -------
    features : numpy.ndarray, shape (n, n_features)
    names : list of str
    family_ratio : numpy.ndarray, shape (n, 3)
        Family score (geometric-mean line-to-median ratio) of outer race, inner race, ball
        in the band where it is largest: the scores of the envelope rule.
    """
    bearings = [BearingFrequencies(shaft_hz=fr, bpfo_hz=o[0] * fr, bpfi_hz=o[1] * fr,
                                   bsf_hz=o[2] * fr, ftf_hz=o[3] * fr, bpf_hz=math.nan)
                for fr, o in zip(ws.shaft_hz, ws.orders)]
    # the windows' ±1.5 bins already hold the slip (cmsim.features.lines: EXACT_TOLERANCE)
    return band_bank_features(ws.x, ws.fs_hz, bearings, tolerance=EXACT_TOLERANCE)


# ---------------------------------------------------------------------- classifiers
class EnvelopeRule:
    """Training-free envelope rule; only its healthy threshold is set on the training side.

    Parameters
    ----------
    classes : sequence of str
        Classes it may answer (a rule for a set without healthy records never says healthy).
    """

    def __init__(self, classes=CLASS_ORDER):
        self.classes = [c for c in CLASS_ORDER if c in classes]
        self.threshold = 1.0

    def _fam(self, family_ratio):
        cols = [i for i, c in enumerate(_FAMILIES) if c in self.classes]
        return family_ratio[:, cols], [_FAMILIES[i] for i in cols]

    def decide(self, family_ratio, threshold):
        """Labels for a threshold (top family, healthy below it).

        Parameters
        ----------
        family_ratio : numpy.ndarray, shape (n, 3)
            From :func:`envelope_features`.
        threshold : float
            Healthy below this ratio.
        """
        r, fams = self._fam(family_ratio)
        top = np.array(fams, dtype=object)[r.argmax(axis=1)]
        if "healthy" in self.classes:
            top = np.where(r.max(axis=1) > threshold, top, "healthy")
        return top

    def fit(self, family_ratio, y):
        """Choose the threshold with the best balanced accuracy on the training windows.

        Parameters
        ----------
        family_ratio : numpy.ndarray, shape (n, 3)
            Of the training windows.
        y : numpy.ndarray of str, shape (n,)
            Their labels.
        """
        if "healthy" in self.classes:
            cands = np.quantile(family_ratio.max(axis=1), np.linspace(0.01, 0.99, 99))
            best = max(cands, key=lambda t: _balanced(y, self.decide(family_ratio, t)))
            self.threshold = float(best)
        return self

    def predict(self, family_ratio):
        """(labels, scores (n, n_classes) in ``self.classes`` order).

        Parameters
        ----------
        family_ratio : numpy.ndarray, shape (n, 3)
            Of the windows to classify.
        """
        r, fams = self._fam(family_ratio)
        cols = []
        for c in self.classes:
            cols.append(-r.max(axis=1) if c == "healthy" else r[:, fams.index(c)])
        return self.decide(family_ratio, self.threshold), np.stack(cols, axis=1)


class _Sklearn:
    def __init__(self, kind, seed):
        if RandomForestClassifier is None:                    # pragma: no cover
            raise ParameterError(f"classifier: {kind!r} needs scikit-learn "
                                 f"(pip install cmsim[ml])", param="classifier")
        if kind == "forest":
            self.model = RandomForestClassifier(n_estimators=300, min_samples_leaf=3,
                                                max_features="sqrt", class_weight="balanced",
                                                random_state=seed, n_jobs=1)
        else:
            self.model = make_pipeline(StandardScaler(), LogisticRegression(
                C=0.3, class_weight="balanced", max_iter=2000, random_state=seed))

    def fit(self, feats, y):
        self.model.fit(feats, y)
        self.classes = [c for c in CLASS_ORDER if c in set(self.model.classes_)]
        return self

    def predict(self, feats):
        p = self.model.predict_proba(feats)
        order = [list(self.model.classes_).index(c) for c in self.classes]
        p = p[:, order]
        return np.array(self.classes, dtype=object)[p.argmax(axis=1)], p


#: Classifier names of ``cmsim evaluate --classifier``.
CLASSIFIERS = ("envelope", "forest", "logistic")


def make_classifier(name, seed=0, classes=CLASS_ORDER):
    """A classifier of :data:`CLASSIFIERS` (``fit`` then ``predict`` → labels, scores).

    Parameters
    ----------
    name : str
    seed : int
        Random state of a learned model.
    classes : sequence of str
        Training classes (the envelope rule's answers).
    """
    if name == "envelope":
        return EnvelopeRule(classes)
    if name in ("forest", "logistic"):
        return _Sklearn(name, seed)
    raise ParameterError(f"classifier: must be one of {list(CLASSIFIERS)}, got {name!r}",
                         param="classifier")


# ---------------------------------------------------------------------- scores
def _balanced(y, pred):
    cls = sorted(set(y))
    return float(np.mean([np.mean(pred[y == c] == c) for c in cls]))


def check_disjoint(train, test):
    """Raise if a record has windows on both sides (leakage).

    Parameters
    ----------
    train, test : WindowSet
    """
    both = set(train.groups) & set(test.groups)
    if both:
        raise ParameterError(f"records on both sides of the split: {sorted(both)[:5]}",
                             param="groups")


def score_windows(y, pred, scores, classes, groups=None):
    """Scores of window predictions.

    Parameters
    ----------
    y, pred : numpy.ndarray of str, shape (n,)
        True and predicted labels.
    scores : numpy.ndarray, shape (n, len(classes))
        Per-class scores (higher = more likely).
    classes : sequence of str
        Columns of ``scores``.
    groups : numpy.ndarray of str, optional
        Record of each window: adds record-level majority votes.

    Returns
    -------
    dict
        ``balanced_accuracy``, ``per_class_recall``, ``macro_auroc``, ``auroc``,
        ``confusion_matrix`` (``classes``, ``matrix`` rows = truth), ``n_windows`` and
        ``records`` (per record: truth, vote, vote share).
    """
    y = np.asarray(y, dtype=object)
    pred = np.asarray(pred, dtype=object)
    present = [c for c in CLASS_ORDER if c in set(y)]
    recall = {c: float(np.mean(pred[y == c] == c)) for c in present}
    auroc = {}
    for c in present:
        if c in classes and len(present) > 1:
            auroc[c] = roc_auc(y == c, scores[:, list(classes).index(c)])
    labels = [c for c in CLASS_ORDER if c in set(y) | set(pred)]
    _, cm = confusion_matrix(list(y), list(pred), classes=labels)
    out = {"balanced_accuracy": float(np.mean(list(recall.values()))),
           "per_class_recall": recall,
           "macro_auroc": float(np.nanmean(list(auroc.values()))) if auroc else math.nan,
           "auroc": auroc,
           "confusion_matrix": {"classes": labels, "matrix": np.asarray(cm).tolist()},
           "n_windows": int(len(y))}
    if groups is not None:
        recs = {}
        for g in dict.fromkeys(groups):
            m = groups == g
            vals, counts = np.unique(pred[m].astype(str), return_counts=True)
            recs[str(g).split(":", 1)[-1]] = {"truth": str(y[m][0]),
                                              "vote": str(vals[counts.argmax()]),
                                              "share": float(counts.max() / m.sum())}
        out["records"] = recs
        out["record_accuracy"] = float(np.mean([r["truth"] == r["vote"]
                                                for r in recs.values()]))
    return out


def _fit_predict(name, seed, train, ftrain, test, ftest):
    classes = [c for c in CLASS_ORDER if c in set(train.y)]
    clf = make_classifier(name, seed, classes)
    if name == "envelope":
        clf.fit(ftrain[2], train.y)
        pred, sc = clf.predict(ftest[2])
    else:
        clf.fit(ftrain[0], train.y)
        pred, sc = clf.predict(ftest[0])
    return pred, sc, clf.classes


def _mean_std(runs):
    """Mean and std (over runs) of every number of the run dicts, nested."""
    first = runs[0]
    if isinstance(first, dict):
        keys = [k for k in first if all(isinstance(r, dict) and k in r for r in runs)]
        return {k: _mean_std([r[k] for r in runs]) for k in keys}
    if isinstance(first, (int, float)) and not isinstance(first, bool):
        v = np.asarray(runs, float)
        return {"mean": float(np.nanmean(v)), "std": float(np.nanstd(v))}
    return first


def evaluate_syn2real(train_dirs, test_folder, classifier="forest", *, window=None,
                      train_hop=None, test_hop=None, channel=None, test_channel=None,
                      max_train_records=None, max_test_windows=None, seed=0, test=None):
    """Train on each synthetic dataset, test on the measured folder; mean ± std over them.

    Parameters
    ----------
    train_dirs : sequence of str or Path
        Generated datasets (one per seed of the synthetic generation).
    test_folder : str or Path
        Folder with ``metadata.json`` and ``.npz`` records.
    classifier : str
        One of :data:`CLASSIFIERS`.
    window : int, optional
        Samples per window (default :func:`default_window` of the test rate).
    train_hop, test_hop : int, optional
        Window hops (defaults ``window // 2`` and ``window``).
    channel, test_channel : str, optional
        Training and test channels (defaults: first ``accel_*``; sensor near the bearing).
    max_train_records : int, optional
        First records of each training set only.
    max_test_windows : int, optional
        First windows of each test record only.
    seed : int
        Base random state of the learned model (run k uses ``seed + k``).
    test : WindowSet, optional
        Precomputed test windows (saves re-reading them).

    Returns
    -------
    dict
        ``runs`` (the scores of each training set), ``summary`` (mean and std of every
        number over the runs), and the layout (``window``, hops, channels, windows counts).
    """
    dirs = [Path(d) for d in ([train_dirs] if isinstance(train_dirs, (str, Path))
                              else train_dirs)]
    if test is None:
        test = measured_windows(test_folder, test_channel, window, test_hop,
                                max_windows=max_test_windows)
    win = test.x.shape[1]
    ftest = envelope_features(test)
    runs = []
    for k, d in enumerate(dirs):
        train = synthetic_windows(d, channel, win, train_hop, max_records=max_train_records)
        if abs(train.fs_hz - test.fs_hz) > 1e-3 * test.fs_hz:
            raise ParameterError(f"train: sample rate {train.fs_hz:g} Hz differs from the "
                                 f"test records' {test.fs_hz:g} Hz", param="train")
        check_disjoint(train, test)
        ftrain = envelope_features(train)
        pred, sc, classes = _fit_predict(classifier, seed + k, train, ftrain, test, ftest)
        res = score_windows(test.y, pred, sc, classes, test.groups)
        res["train_dir"] = str(d)
        res["n_train_windows"] = int(len(train))
        res["n_train_records"] = int(len(set(train.groups)))
        runs.append(res)
    summary = _mean_std([{k: v for k, v in r.items() if k not in ("records",
                                                                  "confusion_matrix")}
                         for r in runs])
    return {"classifier": classifier, "test": str(test_folder), "window": int(win),
            "train_hop": int(train_hop or win // 2), "test_hop": int(test_hop or win),
            "n_test_windows": int(len(test)), "n_test_records": int(len(set(test.groups))),
            "skipped_test_records": dict(test.skipped),
            "balanced_accuracy": summary["balanced_accuracy"],
            "per_class_recall": summary["per_class_recall"],
            "macro_auroc": summary["macro_auroc"],
            "confusion_matrix": runs[0]["confusion_matrix"] if len(runs) == 1 else {
                "classes": runs[0]["confusion_matrix"]["classes"],
                "matrix": np.sum([r["confusion_matrix"]["matrix"] for r in runs
                                  if r["confusion_matrix"]["classes"]
                                  == runs[0]["confusion_matrix"]["classes"]],
                                 axis=0).tolist()},
            "summary": summary, "runs": runs}
