"""Judging a record against its machine: the baseline is the healthy prediction, the model
supplies what each cause changes (issue 16; DESIGN.md, "How a machine judges a record").

1. **Features.** The record is cut into the machine's segments (at most ``max_segments``,
   spread over it); the even ones are the **fit** set, the odd ones the **held-out** set.
   Features are those of the library (:func:`~cmsim.machine.calibration.feature_rows`:
   :func:`cmsim.features.relative_features` at the record's own speed, each bearing's
   defect families in every band of the fixed bank,
   :func:`cmsim.features.band_family_columns`, and ``level_db`` in m/s² when both the
   record's unit and the machine's are known — each through its own unit). The band-by-band
   families weigh nothing in the χ² (:func:`~cmsim.discrepancy.evaluator.weight`): they
   tell where a family stands out over the baseline (step 4), whichever band its impacts
   ring in.
2. **Departure.** Each feature of the record (its mean over the fit segments) is compared
   with the machine's baseline (:class:`~cmsim.machine.library.SignatureLibrary`, the mean
   over its segments): z = (record − baseline) / σ, σ² the baseline's segment-to-segment
   spread² over each mean's segments (1/n_fit + 1/n_baseline), + the model's realisation
   spread² (what one healthy run differs from another by, which averaging segments does not
   remove; the gate of a family that stands out,
   :func:`~cmsim.discrepancy.stand_out.standing_out`, reads the model's run spread there
   instead: :attr:`~cmsim.machine.library.SignatureLibrary.run_spread`)
   + a floor (:data:`~cmsim.discrepancy.columns.FLOOR_SHARE` of
   :func:`~cmsim.discrepancy.evaluator.feature_floor`). χ²₀ is the
   robust χ² of the record against the baseline (:func:`~cmsim.discrepancy.evaluator.chi2`,
   calibrated: far departures rise). A record whose χ²₀ per feature stays within
   :data:`NONE_CHI2_PER_FEATURE` and no feature of which departs by :data:`ALARM_Z` σ is
   ``none``: within the machine's own spread, unless a structure-ringing fault's family
   stands out over the baseline (step 4), in whatever band, or a band of the spectrum's
   shape moved as far from it, either way (:func:`~cmsim.discrepancy.stand_out.shape_moved`).
   A record documented at another load than the machine's is read against the baseline
   moved by the model's change between the two loads, every prediction with it, and each
   feature's σ widened by that change's own size (:mod:`cmsim.discrepancy.operating_point`):
   how a gearbox answers its load is the model's guess, not the machine's measurement.
3. **Matching.** Every entry of the library (a cause on a component, a nuisance variant, a
   grid of sizes) is compared with the record the same way; between two sizes of the grid the
   features are interpolated (:data:`INTERPOLATION_STEPS`, linear in log size), so the size is
   read between the grid's points without a new simulation. A cause's χ² is its best over its
   sizes and variants (the nuisances profiled); its **evidence** is Δχ² = χ²₀ − χ²_cause.
   A prediction that moves the level against the record's clear change of level
   (:data:`LEVEL_DIRECTION_Z`) is no candidate.
4. **Decision**, in two steps:

   a. *The whole record.* The cause whose prediction reads the record best is named when
      its evidence reaches :data:`MIN_EVIDENCE` and removes :data:`MIN_SHARE` of the record's
      departure (χ²₀ − the number of features, what a record of the baseline itself reads),
      a noise only where no band of the spectrum's shape moved away
      (:func:`~cmsim.discrepancy.ranking.decide`'s rule) — a load, a clearance, a changed
      path or a louder machine reshape every feature and are told apart here, as are faults
      the model makes the way the machine does. Faults within
      :data:`~cmsim.discrepancy.ranking.NEAR_TIE` of the best one's evidence are told apart
      by their evidence on their own signatures, over the features their change lifts above
      the baseline (and the statistics): a family that fell, as the envelope's band moves
      under any impulsive fault, is no fault's. A fault is a
      candidate here where its family stands out (below), or where its prediction reads the
      whole record within the baseline's spread (:data:`NONE_CHI2_PER_FEATURE`). A reshaping
      cause that reads best yields to a fault whose own change holds it
      (:attr:`~cmsim.discrepancy.causes.Cause.absorbs`: an eccentric gear's run-out modulates
      the mesh as a speed fluctuation does; a spall's impacts, ringing the structure where
      the baseline showed nothing, move the spectrum as a moved path or more noise does,
      and seen from another bearing's sensor little else of its change reaches the record)
      where that fault's family stands out over the
      reshaping cause's prediction on a feature it does not raise (the once-per-revolution
      line an eccentric gear's mass lifts and a speed fluctuation lowers), or either way
      where the fault adds to what the machine has at its own phase (that mass's force to
      the rotor's residual unbalance: the line falls as well as rises); its size is read
      with its change laid beside the reshaping cause's. Of several such faults, the one on
      the sensor's shaft, then the one whose family stands out farthest (another family's
      window may catch the sidebands of the one that rose).
   b. *A family that stands out.* Where no cause reads the whole record (a real machine
      rings a spall's impacts at a resonance its healthy baseline never showed, which the
      calibrated path cannot know), a fault is named on its own signature
      (:func:`~cmsim.discrepancy.ranking.decide`: its evidence on the features it moves, its
      family moved towards the record), provided one feature of its family stands
      :data:`~cmsim.discrepancy.stand_out.FAMILY_Z` σ and
      :data:`~cmsim.discrepancy.stand_out.FAMILY_RISE_DB` over the baseline and its change,
      at the variant and size its signature reads best, reads the record's features nearer than
      the baseline alone over all of them as its signature weighs them (its row's
      ``total``; the path profiled out as below) — that variant and size chosen among those
      whose change does so, where one does (:data:`INCONSISTENT`); a fault that rings the
      structure must also stand out so over the prediction of the reshaping cause that
      reads the record best, if one reaches :data:`MIN_EVIDENCE` (a load moves the
      ball-pass lines too). A cause whose change is impacts ringing the structure
      (:attr:`~cmsim.discrepancy.causes.Cause.rings_structure`) is judged there with the
      path profiled out: each feature that depends on the transfer path, and the
      kurtosis and crest factor, counts for it what it counts for the baseline, neither for
      nor against (the model's impacts through CWRU's baseline path rang 3 kHz lower than
      its outer-race records'; a family that stands out is not vetoed by a statistic the
      model makes differently — its load zone, once per revolution in the model, every
      ball pass on a record — and a louder broadband, which any impulsive cause makes,
      credits none).

   c. *Within its prediction's own error.* Where neither names a cause, the reshaping cause
      that reads the whole record best of every cause (a fault that cannot be named reading
      it better leaves it unexplained) is named if it removes :data:`MIN_SHARE` of the
      departure with each feature's σ widened by
      :data:`~cmsim.discrepancy.reshaping.PREDICTION_ERROR` of the change it predicts there:
      the library's change is one run of the model at the grid's sizes, the record's
      another at its own (a load 3.4 times the baseline's moved cmsim's own bearing
      envelope lines 11-12 dB from the library's prediction, its cages and slip at that
      load), an error the baseline's spread does not hold. The ranking and steps a and b
      read the plain σ.

   A cause named on shaft lines that rose only over a spectrum floor that fell, none of them
   :data:`~cmsim.discrepancy.shaft_lines.LINE_RISE_DB` up in absolute level, is not named:
   the record is decided again without it (:mod:`cmsim.discrepancy.shaft_lines`). A record
   that departs and that no step explains is ``unexplained``, with where it departs.
5. **Which bearing's line.** A named bearing fault whose fundamental shares its line, at the
   segments' resolution, with a harmonic of a shaft whose envelope comb rose over the
   baseline's, while its window beside that harmonic did not, is not named: the line is the
   shaft's once-per-revolution event (a broken tooth's impacts), and the record is decided
   again without that fault on that bearing. A named bearing fault whose fundamental shares
   its line with another bearing fault's that stands out as far yields to it
   where the whole record, read at its full resolution, puts the line in the other's window
   alone (``decided_on`` ``"full resolution"``), and one whose fundamental stands out in no
   band, only a harmonic, to one whose fundamental does (``"fundamental"``). Where nothing
   is named, a bearing fault whose fundamental and second harmonic stand well over the
   baseline's over the whole record is (``"whole-record family"``;
   :mod:`cmsim.discrepancy.resolution`).
6. **Gain.** On the held-out segments, χ² per feature against the baseline (``before``) and
   against the baseline with the named cause's change (``after``).
"""

from __future__ import annotations

import math
import time

import numpy as np

from cmsim.discrepancy.causes import CAUSES, STATISTICS
from cmsim.discrepancy.columns import chi2_rows, compared_columns, feature_sigma, interpolated
from cmsim.discrepancy.evaluator import path_free, rises, weight
from cmsim.discrepancy.operating_point import at_operating_point, record_load
from cmsim.discrepancy.ranking import (NEAR_TIE, SEVERITY_DELTA_CHI2, _consistent,
                                       added_evidence, decide)
from cmsim.discrepancy.reshaping import PREDICTION_ERROR, absorbed_by, within_error
from cmsim.discrepancy.resolution import (FUNDAMENTALS, buried_family, resolve_line,
                                          shaft_comb)
from cmsim.discrepancy.shaft_lines import floor_change_db, held_lines
from cmsim.discrepancy.signatures import BAND_FAMILIES, build_library, simulate_entry
from cmsim.discrepancy.stand_out import FAMILY_RISE_DB, FAMILY_Z, shape_moved, standing_out
from cmsim.errors import ParameterError
from cmsim.features import segments
from cmsim.machine.calibration import feature_rows
from cmsim.rig import Rig
from cmsim.run import signal_info
from cmsim.spectra.misfit import misfit

__all__ = ["judge", "decide_record", "standing_out", "shape_moved", "NONE_CHI2_PER_FEATURE",
           "ALARM_Z", "MIN_EVIDENCE", "MIN_SHARE", "INTERPOLATION_STEPS", "FAMILY_Z",
           "FAMILY_RISE_DB", "LEVEL_DIRECTION_Z", "INCONSISTENT",
           "PREDICTION_ERROR", "within_error"]

#: χ² per feature against the baseline within which a record reads ``none``.
NONE_CHI2_PER_FEATURE = 2.5

#: A feature this many σ from the baseline departs whatever the others read.
ALARM_Z = 8.0

#: Least evidence (Δχ² over every feature) of a cause named on the whole record.
MIN_EVIDENCE = 16.0

#: Least share of the record's departure (χ²₀ − features) a cause named on the whole record
#: removes.
MIN_SHARE = 0.5

#: Points read between two sizes of a library entry (interpolated features).
INTERPOLATION_STEPS = 4

#: A record whose level departs from the baseline's by this many σ tells the direction of
#: its change: a prediction that moves the level the other way is not a candidate (power
#: added cannot make a machine quieter, a cause that removes power cannot make it louder).
#: Without it the least-squares fit of the other features, which a quieter record's flatter
#: spectrum can resemble, named noise on a preloaded machine 19 dB under its baseline.
LEVEL_DIRECTION_Z = 3.0

#: Added, in the choice of a fault's variant and size on its own signature, to one whose
#: change takes the record's features further from it than the baseline alone: any that
#: does not is read first, and one that does only where no other is left.
INCONSISTENT = 1e9


def _record_rows(record, machine, seg_s, max_segments):
    x = record.signal
    spans = segments(x.size, record.fs_hz, seg_s, max_segments)
    if len(spans) < 4:
        raise ParameterError(f"record of {x.size / record.fs_hz:.3g} s gives {len(spans)} "
                             f"segments of {seg_s:g} s; needs >= 4", param="record")
    scale = record.unit_scale if machine.unit_scale is not None else None
    names, rows = feature_rows([x[a:b] for a, b in spans], record.fs_hz,
                               record.model_frequencies(), list(machine.rig.bearing_names),
                               scale, bands=BAND_FAMILIES)
    return names, rows


def decide_record(lib, li, names, meas, sigma, sensor_bearing, causes=None, gate_sigma=None,
                  excluded=(), floor_db=None):
    """Steps 2-4 of the module docstring on a record's mean features.

    Parameters
    ----------
    lib : SignatureLibrary
        The machine's library.
    li : numpy.ndarray of int
        The compared features' columns in the library.
    names : sequence of str
        Their names.
    meas, sigma : numpy.ndarray
        The record's mean of each compared feature and its σ.
    sensor_bearing : str
        The model bearing the sensor sits on.
    causes : sequence of str, optional
        The causes considered (default every one of the library).
    gate_sigma : numpy.ndarray, optional
        The σ of the gate of a family that stands out
        (:func:`~cmsim.discrepancy.stand_out.standing_out`,
        :func:`~cmsim.discrepancy.stand_out.shape_moved`; default ``sigma``): the baseline's
        spread with the model's run spread
        (:func:`~cmsim.discrepancy.columns.feature_sigma`'s ``standing``).
    excluded : collection of (str, str or None)
        (cause, component) pairs not considered.
    floor_db : float, optional
        The record's raw floor over the baseline's, dB
        (:func:`~cmsim.discrepancy.shaft_lines.floor_change_db`): a shaft line read fallen
        over its floor is fallen only where it fell in absolute level
        (:func:`~cmsim.discrepancy.reshaping.absorbed_by`).

    Returns
    -------
    dict
        ``finding``, ``top`` (its row or None), ``ties``, ``ranked`` (each cause's best on
        the whole record), ``by_signature`` (each cause's best on its own signature, the
        path profiled out for a structure-ringing fault), ``decided_on`` (``"whole"``,
        ``"beside"`` (a fault whose change holds the whole record's best reading), ``"family"``,
        ``"within error"`` (step 4c) or ``""``), ``chi2`` (χ²₀), ``n_eff``, ``z`` (departures).
    """
    base = lib.mean[li][None, :]
    gate = sigma if gate_sigma is None else gate_sigma
    # each feature's robust loss is read once and weighed twice: as the whole record's χ²
    # weighs it, and as a fault's own signature does (chi2_rows's misfit, its shares)
    w = np.array([weight(k) for k in names])
    w_sig = np.array([weight(k, signature=True) for k in names])
    rising = np.array([rises(k, True) for k in names], dtype=bool)
    loss0 = misfit(meas, base, sigma, 1.0, rising)[1]
    per0, per0s = w * loss0, w_sig * loss0
    chi0 = float(per0.sum(axis=1)[0])
    n_eff = float(sum(weight(k) for k in names))
    z0 = (meas - lib.mean[li]) / sigma

    path_dep = np.array([not path_free(k) or k in STATISTICS for k in names], dtype=bool)
    level = names.index("level_db") if "level_db" in names else None
    direction = 0.0
    if level is not None and abs(z0[level]) >= LEVEL_DIRECTION_Z:
        direction = math.copysign(1.0, z0[level])
    # the shaft the sensor's bearing turns with ("<shaft>b<k>"): a rotating force's sidebands
    shaft = Rig.shaft_of(sensor_bearing)
    ranked, by_signature, tables = {}, {}, {}
    for e in lib.entries:
        if (causes is not None and e.cause not in causes) or (e.cause, e.component) in excluded:
            continue
        cause = CAUSES[e.cause]()
        values, table = interpolated(e.values, e.features[:, li], INTERPOLATION_STEPS)
        ok = np.any(np.isfinite(table), axis=1)
        if direction:
            ok &= (table[:, level] - lib.mean[li][level]) * direction > 0.0
        if not np.any(ok):
            continue
        tables.setdefault((e.cause, e.component), []).append((e, values[ok], table[ok]))
        loss = misfit(meas, table, sigma, 1.0, rising)[1]
        per_full, per_sig = w * loss, w_sig * loss
        chi = per_full.sum(axis=1)
        per_prof = per_sig
        if cause.rings_structure and np.any(path_dep):
            per_prof = np.where(path_dep, per0s[0], per_sig)
        judged = cause.judged_on(names, e.component, shaft)
        sel = np.array([k in judged for k in names], dtype=bool)
        # a fault's own signature is read at the variant and size that reads its family
        # best of those whose change does not take the record's features, all of them as
        # the signature weighs them, further from it than the baseline alone: a variant
        # that reads the family but lifts what the record did not move is not its change
        # (an outer race's family read by a 3x path's change that lifted the mesh's
        # sidebands 38 dB, where the record's had not moved, was no candidate at all)
        penalty = np.where((per0s[0] - per_prof).sum(axis=1) > 0.0, 0.0, INCONSISTENT)
        for store, per, p0, score, rank in (
                (ranked, per_full, per0, np.where(ok, chi, np.inf), 0.0),
                (by_signature, per_prof, per0s,
                 np.where(ok, per_prof[:, sel].sum(axis=1), np.inf), penalty)):
            rank = score + rank             # the score, an inconsistent change's after all
            b = int(np.argmin(rank))
            key = (e.cause, e.component)
            if key in store and rank[b] >= store[key]["rank"]:
                continue
            within = values[score <= score[b] + SEVERITY_DELTA_CHI2]
            delta = p0[0] - per[b]
            store[key] = {"name": e.cause, "cause": cause, "component": e.component,
                          "variant": e.variant, "parameter": e.parameter,
                          "value": float(values[b]),
                          "range": (float(within.min()), float(within.max())),
                          "chi2": float(per[b].sum()), "score": float(score[b]),
                          "rank": float(rank[b]),
                          "prediction": table[b], "judged_on": judged,
                          "family": cause.family(names, e.component, shaft),
                          "per_feature": dict(zip(names, delta.tolist())),
                          "total": float(delta.sum()), "delta_chi2": float(delta[sel].sum()),
                          "evidence": float(chi0 - per[b].sum())}
    rows_out = sorted(ranked.values(), key=lambda r: r["chi2"])
    for r in list(rows_out) + list(by_signature.values()):
        # a fault that rings the structure is named only where its own family stands out
        # over the baseline: its evidence elsewhere (a broadband that lowers the raw lines
        # over their median, the statistics) any impulsive cause would share
        fam = [names.index(k) for k in r["family"] if path_free(k)]
        out = standing_out(fam, meas, lib.mean[li], gate, names)
        r["family_z"] = float(max((z0[i] for i in fam), default=0.0))
        r["stands_out"] = bool(out)
        r["out"] = out
        r["nameable"] = not r["cause"].rings_structure or bool(out)

    # a. the cause whose prediction reads the whole record best, if it explains it (a fault
    # whose family does not stand out only where its prediction reads the whole record
    # within the baseline's spread: its change is then the record's)
    cands = [r for r in rows_out if _consistent(r) and (
        r["nameable"] or r["chi2"] / max(n_eff, 1e-9) <= NONE_CHI2_PER_FEATURE)]
    excess = max(chi0 - n_eff, 0.0)

    def explains(r):
        return r["evidence"] >= MIN_EVIDENCE and r["evidence"] >= MIN_SHARE * excess

    departs = chi0 / max(n_eff, 1e-9) > NONE_CHI2_PER_FEATURE or (
        z0.size > 0 and float(np.nanmax(np.abs(z0))) >= ALARM_Z) or (
        # a family that stands clearly out, of the cause that reads the record best and
        # explains it, is a departure however quiet the rest (a 1x line 11.7 dB, 7.6 σ,
        # over the baseline's, the record otherwise within its spread, read none)
        bool(cands) and cands[0]["stands_out"] and explains(cands[0])) or (
        # a spall's family standing out over the baseline in some band is outside the
        # baseline's spread, however quiet the rest (the angle generator's gear machines:
        # an outer race 7.8 dB and 3.3 sigma up in the two top bands alone read none)
        any(r["stands_out"] and r["cause"].rings_structure for r in by_signature.values())) or (
        # a band of the spectrum's shape that moved as far, either way, too: they share one
        # family's weight, so resonances moved by 20 % (bands 5-8 sigma, 6-7 dB) read none
        bool(shape_moved(meas, lib.mean[li], gate, names)))
    finding, top, ties, how = "none", None, [], ""
    if departs:
        if cands and explains(cands[0]):
            top, how = cands[0], "whole"
            ties = [r for r in cands[1:] if r["evidence"] >= NEAR_TIE * top["evidence"]]
            # a fault whose own family stands clearly out where the winner's prediction
            # leaves it wins a near tie on the whole record against a cause whose family
            # does not (an outer race that lifted its envelope lines 19 dB tied a torque
            # mismatch, 137 against 139; a clearance that lifts the cage line itself keeps
            # it against a ball defect whose family holds that line)
            # nor, however far ahead, is a fault named on the whole record with none of its
            # own family risen, where another fault's family stands out over its prediction
            # (a gear machine's outer race: the envelope lines 25 dB up, read best as a
            # tooth fault whose sidebands stayed where they were)
            rivals = ties if top["cause"].signature is None else cands[1:]
            out = [r for r in rivals if r["cause"].signature is not None
                   and standing_out(r["out"], meas, top["prediction"], gate, names)]
            if out and not top["stands_out"]:
                new = max(out, key=lambda r: r["family_z"])
                ties = [r for r in [top] + ties if r is not new]
                top = new
            absorbed = absorbed_by(top, rows_out, tables, lib.mean[li], meas, sigma, gate,
                                    names, sensor_bearing, floor_db)
            if absorbed is not None:
                ties, top, how = [top], absorbed, "beside"
            elif top["cause"].signature is not None:
                # faults the whole record cannot tell apart are told apart by their own
                # signatures (a broken tooth's once-per-revolution impacts light a bearing's
                # envelope lines too; its sidebands are its own), on what each adds
                tied = {(r["name"], r["component"]) for r in [top] + ties
                        if r["cause"].signature is not None}
                own = [r for r in by_signature.values() if (r["name"], r["component"]) in tied
                       and r["nameable"]]
                best = max(own, key=lambda r: added_evidence(r, lib.mean[li]), default=None)
                if best is not None and (best["name"], best["component"]) != (
                        top["name"], top["component"]):
                    new = next(r for r in cands if (r["name"], r["component"])
                               == (best["name"], best["component"]))
                    ties = [r for r in [top] + ties if r is not new]
                    top = new
        else:
            # b. no cause reads the whole record: a fault whose own family stands out over
            # the baseline, judged on its signature (ranking.decide) — where its change, at
            # the variant and size its signature reads best, takes the record's features
            # nearer than the baseline alone, over all of them as its signature weighs them
            # and with the path profiled out for a change ringing the structure (``total``:
            # the angle generator's unbalance read as a misalignment whose 2× line the record
            # lacks, −52). Read at that one variant and size only: another within the
            # signature's range might read the record better and is not asked. A fault that
            # rings the structure must also stand out over the prediction of the reshaping
            # cause that reads the record best: a load moves which balls carry it, and with
            # them the ball-pass lines (cmsim's own torque mismatch of seed 3 was read as an
            # inner race whose lines its load change lifts as far)
            reshaped = next((r["prediction"] for r in cands if r["cause"].signature is None
                             and r["evidence"] >= MIN_EVIDENCE), None)
            faults = [r for r in by_signature.values()
                      if r["cause"].signature is not None and r["nameable"]
                      and r["total"] > 0.0 and (
                          reshaped is None or not r["cause"].rings_structure
                          or standing_out(r["out"], meas, reshaped, gate, names))]
            top, ties = decide(sorted(faults, key=lambda r: -r["delta_chi2"]),
                               sensor_bearing, chi0)
            how = "family" if top is not None else ""
            # c. the reshaping cause that reads the record best of all, within its
            # prediction's own error
            if (top is None and cands and cands[0] is rows_out[0]
                    and cands[0]["cause"].signature is None
                    and cands[0]["evidence"] >= MIN_EVIDENCE
                    and chi0 - within_error(cands[0], meas, lib.mean[li], sigma, names)
                    >= MIN_SHARE * excess):
                top, how = cands[0], "within error"
                ties = [r for r in cands[1:] if r["evidence"] >= NEAR_TIE * top["evidence"]]
        finding = top["name"] if top is not None else "unexplained"
    return {"finding": finding, "top": top, "ties": ties, "ranked": rows_out,
            "by_signature": sorted(by_signature.values(),   # the faults first
                                   key=lambda r: (r["cause"].signature is None,
                                                  -r["delta_chi2"])),
            "decided_on": how, "chi2": chi0, "n_eff": n_eff, "z": z0}


def judge(record, machine, *, max_segments=16, causes=None, refine=1, workers=1,
          library_progress=None):
    """Compare a record with its machine (module docstring).

    Parameters
    ----------
    record : MeasuredRecord
        The record (same channel, sample rate and rig as the machine).
    machine : cmsim.machine.Machine
        Calibrated on the machine's healthy baseline; its signature library is built here
        when it has none (slow: ``cmsim calibrate`` stores it).
    max_segments : int
        Segments read from the record (spread over it), >= 4.
    causes : sequence of str, optional
        The causes considered (default every one of the library).
    refine : int
        Simulations that refine the named cause's size (0: the library's interpolation
        alone); each lays the cause at its fitted size on the baseline anew, and is kept
        when it reads the record better.
    workers : int
        Processes that build a missing library; with 2 or more, the model's two runs of a
        refinement or a load change go side by side on two threads.
    library_progress : callable, optional
        Progress of a library built here.

    Returns
    -------
    dict
        ``finding``, ``cause`` (the named cause's row or None), ``ranked`` (every cause's
        best: name, component, variant, value, χ², evidence), ``near_ties``,
        ``discrepancies``, ``chi2_per_feature``, ``n_features``, ``gain``, ``notes``,
        ``wall_s`` and what the comparison was read on.
    """
    start = time.perf_counter()
    notes = []
    lib = machine.library
    if lib is None:
        t0 = time.perf_counter()
        lib = build_library(machine, workers=workers, progress=library_progress,
                            causes=None if causes is None else [CAUSES[c]() for c in causes])
        notes.append(f"the machine held no signature library: built here in "
                     f"{time.perf_counter() - t0:.0f} s for "
                     f"{'every cause' if causes is None else 'the causes asked'} "
                     "(cmsim calibrate stores it)")
    if record.unit_scale is None and machine.unit_scale is not None:
        notes.append("the record's unit is unknown: its absolute level is not compared")
    op, load_note = record_load(record, machine)
    lib, shift_note = at_operating_point(machine, lib, op, threads=min(2, workers))
    notes.extend(n for n in (load_note, shift_note) if n)
    names, rows = _record_rows(record, machine, lib.segment_s, max_segments)
    fit, held = rows[0::2], rows[1::2]
    li, ri, cnames = compared_columns(names, lib, fit, held)
    with np.errstate(all="ignore"):
        meas = np.nanmean(fit[:, ri], axis=0)
        meas_held = np.nanmean(held[:, ri], axis=0)
    n_fit = int(np.min(np.sum(np.isfinite(fit[:, ri]), axis=0))) if ri.size else 1
    sigma = feature_sigma(lib, li, cnames, n_fit)
    sensor = signal_info(machine.model_signal).component
    gate = feature_sigma(lib, li, cnames, n_fit, standing=True)
    held, combed = set(), set()
    floor_db = floor_change_db(record, machine, lib.segment_s)

    def decide(out=(), pairs=()):
        held.update(out)
        combed.update(pairs)
        return decide_record(lib, li, cnames, meas, sigma, sensor, causes if not held else [
            c for c in causes or {e.cause for e in lib.entries} if c not in held],
            gate_sigma=gate, excluded=combed, floor_db=floor_db)

    d = decide()
    d, why = held_lines(d, cnames, meas, lib.mean[li], floor_db, decide)
    notes.extend(why)
    baseline = machine.baseline.records if machine.baseline else ()
    for _ in range(len(machine.rig.bearing_names) * len(FUNDAMENTALS)):
        got = shaft_comb(record, baseline, machine.op.speed_rpm, lib.segment_s, d)
        if got is None:
            break
        d = decide(pairs=[(got[0]["name"], got[0]["component"])])
        notes.append(got[1])
    resolved = resolve_line(record, lib.segment_s, d, cnames, meas, lambda cols: standing_out(
        cols, meas, lib.mean[li], gate, cnames)) or buried_family(
            record, baseline, machine.op.speed_rpm, d)
    if resolved is not None:
        new, how, why = resolved
        d["ties"] = [r for r in [d["top"]] + d["ties"] if r is not new and r is not None]
        d.update(top=new, finding=new["name"], decided_on=how)
        notes.append(why)
    top, z0, n_eff, chi0 = d["top"], d["z"], d["n_eff"], d["chi2"]
    if top is not None and "beside" in top:
        b = top["beside"]
        notes.append(f"named beside a {b['name'].replace('_', ' ')} ({b['parameter']} about "
                     f"{b['value']:.3g}) that reads the rest of the record's change: its own "
                     "change is read on the features of its family that one does not raise, "
                     "where it stands out over it ("
                     + ", ".join(cnames[i] for i in top["out"]) + "); read its size as a trend")
    fitted, simulations = None, 0
    if top is not None and refine > 0 and top["name"] in CAUSES and "beside" not in top:
        got = simulate_entry(machine, lib, CAUSES[top["name"]](), top["component"],
                             top["variant"], top["value"], threads=min(2, workers))
        simulations = 1
        if got is not None and list(got[0]) == list(lib.names):
            pred = got[1][li]
            chi = float(chi2_rows(meas, pred[None, :], sigma, cnames)[0][0])
            fitted = got[2]
            top["refined_chi2"] = chi
            if chi < top["chi2"]:
                top.update(chi2=chi, prediction=pred)
    base = lib.mean[li][None, :]
    before = float(chi2_rows(meas_held, base, sigma, cnames)[0][0]) / n_eff
    after = before if top is None else float(
        chi2_rows(meas_held, top["prediction"][None, :], sigma, cnames)[0][0]) / n_eff
    order = np.argsort(-np.abs(np.nan_to_num(z0)))
    discrepancies = [{"feature": cnames[i], "measured": float(meas[i]),
                      "simulated": float(lib.mean[li][i]), "sigma": float(sigma[i]),
                      "z": float(z0[i])} for i in order]
    return {"finding": d["finding"], "cause": top, "ranked": d["ranked"],
            "by_signature": d["by_signature"],
            "near_ties": d["ties"], "decided_on": d["decided_on"],
            "discrepancies": discrepancies, "chi2": chi0,
            "chi2_per_feature": chi0 / max(n_eff, 1e-9), "n_features": len(cnames),
            "gain": {"before": before, "after": after,
                     "relative": 0.0 if before <= 0 else 1.0 - after / before,
                     "baseline_level": 1.0,
                     "on": "held-out segments (odd): chi2 per feature against the baseline, "
                           "and against the baseline with the named cause's change"},
            "segments": int(rows.shape[0]), "segment_s": lib.segment_s, "columns": cnames,
            "sensor_bearing": sensor, "notes": notes, "library": lib, "op": op,
            "fitted_segments": fitted, "simulations": simulations,
            "wall_s": time.perf_counter() - start}
