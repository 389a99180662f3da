"""What a calibrated machine's library says of the machine itself, before any record: the
smallest size of each fault its sensor can see (:func:`detectability`, the library's own
predictions judged as a record is) and whether its baseline is stationary enough to judge
records against (:func:`baseline_consistency`, its halves judged against each other).
``cmsim calibrate`` prints both; they stand on the comparison's own decision, σ and χ²
(:mod:`cmsim.discrepancy.judge`).
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.discrepancy.causes import CAUSES
from cmsim.discrepancy.evaluator import weight
from cmsim.discrepancy.columns import chi2_rows, compared_columns, feature_sigma, interpolated
from cmsim.discrepancy.judge import (ALARM_Z, INTERPOLATION_STEPS, NONE_CHI2_PER_FEATURE,
                                     decide_record)
from cmsim.errors import ParameterError
from cmsim.frequencies import rig_frequencies
from cmsim.machine.baseline import Baseline
from cmsim.machine.calibration import feature_rows
from cmsim.run import signal_info

__all__ = ["detectability", "baseline_consistency", "DETECT_FIT_SEGMENTS"]


#: Fit segments a record's mean is taken over when the library judges its own predictions
#: (:func:`detectability`): a 10-s record read on 16 half-second segments.
DETECT_FIT_SEGMENTS = 8


def detectability(machine, causes=None):
    """What this machine's sensor can see: per fault of the library on the sensor's bearing
    (a bearing defect), a gear, or rig-wide, the smallest size at which the library's own
    prediction — the baseline with the fault's change at the calibrated path's gain and the
    documented clearance, read as the mean of :data:`DETECT_FIT_SEGMENTS` fit segments — is
    named that fault by the comparison's decision
    (:func:`~cmsim.discrepancy.judge.decide_record`), the grid read between its points as a
    comparison reads it; None where no size of the grid is.

    A noiseless estimate from the library (the record's own segment noise and a machine's
    drift are in σ, not in the prediction): the injection benchmark
    (benchmarks/bench_detectability.py) measures the same on held-out baseline segments.

    Parameters
    ----------
    machine : cmsim.machine.Machine
        With its signature library.
    causes : sequence of str, optional
        Default: every fault (a cause with a signature) of the library.

    Returns
    -------
    list of dict
        ``cause``, ``component`` (model key), ``parameter``, ``smallest`` (or None),
        ``largest_tried``.
    """
    lib = machine.library
    if lib is None:
        raise ParameterError("the machine holds no signature library: cmsim calibrate builds "
                             "it", param="machine")
    li = np.array([i for i, m in enumerate(lib.mean) if math.isfinite(m)], dtype=int)
    names = [lib.names[i] for i in li]
    sigma = feature_sigma(lib, li, names, DETECT_FIT_SEGMENTS)
    gate = feature_sigma(lib, li, names, DETECT_FIT_SEGMENTS, standing=True)
    sensor = signal_info(machine.model_signal).component
    out = []
    for e in lib.entries:
        cause = CAUSES.get(e.cause)
        if cause is None or cause.signature is None or e.variant != "documented" \
                or (causes is not None and e.cause not in causes):
            continue
        if cause.kind == "bearing" and e.component != sensor:
            continue
        values, table = interpolated(e.values, e.features[:, li], INTERPOLATION_STEPS)
        smallest = None
        for v, row in zip(values, table):
            if not np.all(np.isfinite(row)):
                continue
            d = decide_record(lib, li, names, row, sigma, sensor, gate_sigma=gate)
            if d["finding"] == e.cause and d["top"]["component"] == e.component:
                smallest = float(v)
                break
        out.append({"cause": e.cause, "component": e.component, "parameter": e.parameter,
                    "smallest": smallest, "largest_tried": float(e.values[-1])})
    return out


def baseline_consistency(machine):
    """The machine's baseline judged against itself, as a record is judged: the mean of its
    odd segments against the mean of its even ones, and, of a baseline of several records,
    each record against the others, with the comparison's σ
    (:func:`~cmsim.discrepancy.columns.feature_sigma`) and χ²
    (:func:`~cmsim.discrepancy.columns.chi2_rows`). A baseline whose halves or records differ
    by more than a record may before it departs (χ² per feature over
    :data:`~cmsim.discrepancy.judge.NONE_CHI2_PER_FEATURE`, or a feature
    :data:`~cmsim.discrepancy.judge.ALARM_Z` σ off) is not stationary, or not one healthy
    machine: healthy records may read as departures, and a fault one of its records holds as
    none (the halves interleave every record's segments, so they alone cannot see a faulty
    record among healthy ones).

    Parameters
    ----------
    machine : cmsim.machine.Machine
        With its baseline and signature library.

    Returns
    -------
    dict
        ``chi2_per_feature``, ``worst_feature``, ``worst_z``, ``n_features``, ``departs``
        (of the halves); ``records``: per baseline record (several only) ``record``,
        ``chi2_per_feature``, ``worst_feature``, ``worst_z``, ``departs``, against the others.
    """
    lib = machine.library
    rig_freqs = rig_frequencies(machine.rig, machine.op)
    per_record = [feature_rows(Baseline((r,), machine.baseline.fs_hz).segments(lib.segment_s),
                               machine.fs_hz, rig_freqs, list(machine.rig.bearing_names),
                               machine.unit_scale) for r in machine.baseline.records]
    names = per_record[0][0]
    rows = np.vstack([r for _, r in per_record])
    even, odd = rows[0::2], rows[1::2]
    li, ri, cnames = compared_columns(names, lib, even, odd)
    out = _judged(odd[:, ri], even[:, ri], lib, li, cnames)
    out["records"] = []
    if len(per_record) > 1:
        named = machine.calibrated_on
        for k, (_, own) in enumerate(per_record):
            others = np.vstack([r for j, (_, r) in enumerate(per_record) if j != k])
            got = _judged(own[:, ri], others[:, ri], lib, li, cnames)
            out["records"].append({"record": named[k] if k < len(named) else f"record {k + 1}",
                                   **got})
    return out


def _judged(a_rows, b_rows, lib, li, cnames):
    """The mean of some baseline segments against the mean of others, as a record is
    judged against its machine: χ² per feature, the worst feature's z, whether it departs."""
    with np.errstate(all="ignore"):
        a, b = np.nanmean(a_rows, axis=0), np.nanmean(b_rows, axis=0)
    sigma = feature_sigma(lib, li, cnames, a_rows.shape[0])
    chi = float(chi2_rows(a, b[None, :], sigma, cnames)[0][0])
    n_eff = float(sum(weight(k) for k in cnames))
    z = (a - b) / sigma
    worst = int(np.nanargmax(np.abs(z))) if z.size else None
    out = {"chi2_per_feature": chi / max(n_eff, 1e-9), "n_features": len(cnames),
           "worst_feature": None if worst is None else cnames[worst],
           "worst_z": float("nan") if worst is None else float(z[worst])}
    out["departs"] = bool(out["chi2_per_feature"] > NONE_CHI2_PER_FEATURE
                          or (worst is not None and abs(out["worst_z"]) >= ALARM_Z))
    return out
