"""Calibrate a machine on healthy baseline records: what the model cannot know of it.

From one or more healthy records of one machine (same channel and sample rate), every
segment of :data:`SEGMENT_S` alternately goes to the **fit** set (even) and the
**held-out** set (odd). On the fit set:

1. **Spectrum and lines.** The averaged power spectrum (Hann) of the segments; its narrow
   lines are the bins standing :data:`LINE_MIN_DB` over a running median of ±
   :data:`FLOOR_HALF_WIDTH_HZ` (lines have no width there, the broadband has); the running
   mean with the lines' bins masked is the smooth **background spectrum** B(f) (a running
   median alone would sit 0.3-1.6 dB under the mean of a noisy estimate).
2. **Model force.** The nominal (healthy) model at the record's operating point is
   simulated for :data:`N_SEEDS` seeds; its force spectrum gives the lines the model makes
   (GMF harmonics, the ball pass of the sensor's bearing: those standing 20 dB over the
   force's own floor) and its broadband level.
3. **Transfer path.** Its *shape* is that of the background, √B(f) smoothed over
   :data:`PATH_SMOOTHING_OCTAVE` octave: a machine's structure shapes both its broadband
   excitation and the response to the model's forces (the assumption behind choosing a
   demodulation band where the background resonates, Randall & Antoni 2011). A 1/12-octave
   smoothing resolves resonances down to about 3 % damping (half-power width 2ζf ≥ f/16)
   and averages the spectral estimate over enough bins to leave a ±0.5 dB scatter. Below
   :data:`HOUSING_BAND_LOW`·fs the path falls as f² (stiffness-controlled); read over the
   model's force, it is held above the force's anti-alias passband (:func:`_path_shape`).
   Its
   *gain* is pinned where a model line (GMF harmonics on a gear rig, the sensor bearing's
   ball pass on a bearing rig) stands in the record too (the ratio of the measured line to
   the model's, interpolated in log frequency between such lines). Beyond the highest such
   line (a bearing's ball pass pins only the first few hundred hertz, under the housing
   band) the gain is read from the **modulation** of the record's broadband
   (:func:`_modulation_pins`): the background is stationary, the model's force is
   modulated at its bearing's defect frequencies, so the depth of that modulation in the
   record over the force's is the share of the band's power the force makes through the
   path — what splits the record's broadband between path × force and background, which
   its spectrum alone cannot. Where neither reads it
   (a healthy ball bearing's ball pass is usually below the floor) the gain is that of the
   rig's nominal housing path averaged over 0.05-0.45·fs, lowered if that would show a model
   line the record does not, and the machine file says so: fault sizes read through such a
   path carry that uncertainty. Where the background is not the path's (white sensor noise
   under a model's lines) the pins read alike through the background *over the model's
   broadband force* instead. Both shapes are read to the end (path, background): the one
   that keeps more pins is kept, on as many the one whose twin is nearer the *fit*
   segments' features (:data:`MISFIT_CAP`; pins below :data:`HOUSING_BAND_LOW`·fs, all a
   bearing baseline has, cannot tell the shapes apart, both falling as f² there, and the
   scatter of their corrections chose by rounding), and with no pin at all the
   background's own (a twin matches a healthy record's broadband through either).
   A gearbox's mesh harmonics are always the
   model's lines; a healthy bearing's ball-pass line is disowned when the gain it implies
   would show another harmonic the record lacks (:func:`_pins`).
4. **Background.** The coloured noise is B(f) less what the model's broadband force puts
   there through the path (at least 1 − :data:`MAX_SHARE` of B); the lines are the measured
   lines less what the model's own lines put there through the path (powers subtracted, the
   lines matched within :data:`LINE_TOLERANCE` as the pins are), each filed as an order of
   the input or output shaft when it sits on one (so it follows the speed), else at its
   frequency (the mains, other machines). The **rotating forces** of an unbalance or a
   misalignment reach the sensor at the sensor bearing's shaft orders 1-3 through gains of
   their own: the baseline's line at each order over the force of a residual unbalance of
   grade :data:`BALANCE_GRADE_MM_S` (:func:`_shaft_gains`), so that they are sized as a
   trend against the baseline's own lines.
5. **Bearing clearance.** A healthy ball bearing under load makes a comb of ball-pass lines
   (varying compliance) whose level its clearance sets: strong with a clearance (fewer
   balls loaded), weak in line contact or under a preload. A machine's clearance is rarely
   documented, and a model comb the record lacks beside a mesh harmonic cannot be taken out
   by a smooth path (at 20 N m the default rig's sixth ball pass sits 5 Hz from its GMF).
   On a gear rig steps 2-4 are read for the documented clearance and for each of
   :data:`CLEARANCE_CANDIDATES_M`; another is kept only when its twin is nearer the fit
   segments by :data:`CLEARANCE_EVIDENCE` (capped misfit) and no farther uncapped. On a
   bearing rig the ball pass is the family the path is pinned on, and its absent harmonics
   cap the path (step 3); there the documented clearance stays: a preloaded CWRU twin fitted
   its healthy baseline better (held-out χ²/feature 1.27 → 0.74) but named none of the six
   fault records, 4 of which the twin at the documented 5 µm names.
6. **Spread and fit quality.** :func:`cmsim.features.relative_features` of every baseline
   segment give each feature's mean and segment-to-segment spread; the kept twin (model
   force → path + background, :data:`N_TWIN_SEEDS` new seeds, a segment each) is compared
   with the held-out segments feature by feature: z = (twin − baseline) / spread, and,
   since one record is one realisation of the model's random parts (cage phases, slip)
   while the twin averages several, also over √(spread² + the twin's own spread²).

The operating point is the record's (speed read from the signal); the speed wobble is the
relative RMS of the strongest shaft-order line's instantaneous frequency, less what the noise
under the line makes of it, recorded for information — or not identifiable (None) when no
shaft order stands :data:`WOBBLE_MIN_SNR` over its noise.

References
----------
.. [1] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial",
   MSSP 25 (2011) 485-520.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from cmsim.errors import ParameterError
from cmsim.features.relative import segment_samples, segments
from cmsim.frequencies import rig_frequencies
from cmsim.machine.baseline import Baseline
from cmsim.machine.calibration.background_lines import MESH_FAMILY_SIDEBANDS, _lines_and_floor
from cmsim.machine.calibration.gains import (BALANCE_GRADE_MM_S, SHAFT_ORDERS, _shaft_gains,
                                             _shaft_words)
from cmsim.machine.calibration.path_reading import (BROADBAND_SHARE, FORCE_MODULATION_MIN_SIGMA,
                                                    HOUSING_BAND_LOW, MAX_SHARE,
                                                    MODEL_LINE_MIN_DB, MODULATION_MIN_SIGMA,
                                                    PATH_SMOOTHING_OCTAVE, PIN_CONSISTENCY,
                                                    _reading)
from cmsim.machine.calibration.quality import (WOBBLE_MIN_SNR, _misfit, _speed_wobble,
                                               feature_rows)
from cmsim.machine.machine import Machine, model_force
from cmsim.measured.schema import undocumented_load
from cmsim.run import signal_info
from cmsim.spectra.floor import segment_psd
from cmsim.spectra.line_detector import (FLOOR_HALF_WIDTH_HZ, LINE_MIN_DB, LINE_TOLERANCE,
                                          MAX_LINES, line_free)
from cmsim.spectra.misfit import Z_CAP, robust_loss

__all__ = ["calibrate", "feature_rows", "SEGMENT_S", "N_SEEDS", "N_TWIN_SEEDS", "LINE_MIN_DB",
           "FLOOR_HALF_WIDTH_HZ", "LINE_TOLERANCE", "MAX_LINES", "PATH_SMOOTHING_OCTAVE",
           "MODEL_LINE_MIN_DB", "PIN_CONSISTENCY", "BROADBAND_SHARE", "MISFIT_CAP",
           "FORCE_MODULATION_MIN_SIGMA", "MAX_SHARE", "MODULATION_MIN_SIGMA", "WOBBLE_MIN_SNR",
           "MESH_FAMILY_SIDEBANDS", "HOUSING_BAND_LOW", "BALANCE_GRADE_MM_S", "SHAFT_ORDERS",
           "CLEARANCE_CANDIDATES_M", "CLEARANCE_EVIDENCE"]

#: Segment length, s (the segments compare reads).
SEGMENT_S = 0.5

#: Seeds of the nominal model simulated for the force spectrum.
N_SEEDS = 3

#: Seeds (one segment each) of the twin compared with the held-out baseline segments.
N_TWIN_SEEDS = 6

#: Cap on a feature's z (over the baseline's segment-to-segment spread) in the misfit that
#: chooses the path's shape: THE misfit's cap (:func:`cmsim.spectra.misfit.robust_loss`,
#: capped), so a feature the twin misses by far counts as 4σ and one feature does not decide
#: it. The twin's own spread is not in it: a twin made noisy by a wrong shape must not look
#: nearer for it.
MISFIT_CAP = Z_CAP

#: Bearing clearances tried besides the documented one, m: line contact and a light preload
#: (:meth:`Rig.with_clearance <cmsim.rig.Rig.with_clearance>`; negative is a preload).
CLEARANCE_CANDIDATES_M = (0.0, -5e-6)

#: Factor by which another clearance's twin must be nearer the fit segments (capped misfit,
#: :data:`MISFIT_CAP`) than the documented clearance's to replace it: the documented value is
#: the prior, and a twin's misfit on ~5 segments scatters by some tens of percent.
CLEARANCE_EVIDENCE = 1.5


def _clearance_words(c):
    """A clearance in words: "15 µm clearance", "line contact", "5 µm preload"."""
    if c == 0.0:
        return "line contact (no clearance)"
    return f"{abs(c) * 1e6:g} µm {'clearance' if c > 0 else 'preload'}"


def calibrate(records, *, seg_s=SEGMENT_S, n_seeds=N_SEEDS, seed=0, name=None):
    """Calibrate the twin of a machine on its healthy baseline record(s).

    Parameters
    ----------
    records : sequence of MeasuredRecord
        Healthy records of one machine (:func:`cmsim.measured.read_record`, or a part of
        one: :meth:`MeasuredRecord.span <cmsim.measured.MeasuredRecord.span>`), same channel
        and sample rate; the model rig and operating point of the first are the machine's.
    seg_s : float
        Segment length, s (each record needs at least 4 segments).
    n_seeds : int
        Model simulations for the force spectrum.
    seed : int
        Seed of the model simulations and of the twin's background.
    name : str, optional
        Name of the machine (default: the first record's file).

    Returns
    -------
    Machine

    Raises
    ------
    ParameterError
        No record, records of different channels or sample rates, too short a record.
    """
    records = list(records)
    if not records:
        raise ParameterError("calibrate needs at least one baseline record", param="baseline")
    ref = records[0]
    fs = ref.fs_hz
    for r in records[1:]:
        if r.channel != ref.channel or abs(r.fs_hz / fs - 1.0) > 1e-3:
            raise ParameterError(f"baseline records must share a channel and a sample rate: "
                                 f"{ref.channel} at {fs:g} Hz vs {r.channel} at {r.fs_hz:g} Hz",
                                 param="baseline")
    fit, held = [], []
    for r in records:
        x = r.signal
        segs = [x[a:b] for a, b in segments(x.size, fs, seg_s)]
        if len(segs) < 4:
            raise ParameterError(f"baseline {r.record_id or r.path or 'record'} gives "
                                 f"{len(segs)} segments of {seg_s:g} s; needs >= 4",
                                 param="baseline")
        fit += segs[0::2]
        held += segs[1::2]
    rig, op = ref.rig, ref.op
    freqs = rig_frequencies(rig, op)
    bearing = signal_info(ref.model_signal).component
    shaft_hz = (freqs.fr1_hz, freqs.fr2_hz if freqs.fr2_hz is not None else freqs.fr1_hz)
    fr = freqs.bearing(bearing).shaft_hz                       # the sensor bearing's shaft
    notes = [f"operating point: {op.speed_rpm:.2f} rpm from the record; torque "
             f"{op.torque_nm:g} N m and radial load {op.radial_load_n:g} N as the record's "
             "model assumes (the load is not identified from a healthy record)"]

    # 1. the record: spectrum, its lines, the smooth background spectrum
    freq, psd = segment_psd(fit, fs)
    df = freq[1] - freq[0]
    lines, floor = _lines_and_floor(freq, psd)

    # the baseline's spread (step 6; each reading of steps 2-5 below is scored against it)
    bearings = list(rig.bearing_names)
    names, all_rows = feature_rows(fit + held, fs, freqs, bearings, ref.unit_scale)
    # a feature a segment cannot read (a line beyond its resolution) is NaN there; one no
    # two segments read has no spread and is left out
    seen = np.sum(np.isfinite(all_rows), axis=0) >= 2
    spread = {k: (float(np.nanmean(all_rows[:, i])), float(np.nanstd(all_rows[:, i], ddof=1)))
              for i, k in enumerate(names) if seen[i]}
    fit_rows, held_rows = all_rows[:len(fit)], all_rows[len(fit):]

    wobble = _speed_wobble(np.concatenate([r.signal for r in records]), fs, freqs.fr1_hz)
    longest = max(records, key=lambda r: r.signal.size).signal
    baseline = {"freq": freq, "floor": floor, "lines": lines, "fit": fit,
                "keep": line_free(freq, psd)}
    calibrated_on = tuple(f"{r.record_id or r.path or 'record'}"
                          + (f" [{r.meta['span_s'][0]:g}, {r.meta['span_s'][1]:g}] s"
                             if r.meta.get("span_s") else "")
                          + " (even segments fit, odd held out)" for r in records)

    def twin_on(model_rig):
        """Steps 2-4 on one model rig: (capped misfit, chi2 per feature, machine, twin's
        feature rows), the misfits the twin's against the fit segments."""
        # 2. the nominal model's force
        run_s = segment_samples(fs, seg_s) / fs          # a segment's samples exactly
        force_runs = [model_force(model_rig, op, ref.model_signal, fs, run_s, seed + 7777 * s)
                      for s in range(n_seeds)]
        twin_forces = [model_force(model_rig, op, ref.model_signal, fs, run_s,
                                   seed + 1 + 7777 * (s + n_seeds)) for s in range(N_TWIN_SEEDS)]
        forces = [force[edge:edge + n] for force, edge, n in force_runs]
        _, pf = segment_psd(forces, fs)

        # 3-4. the path and the background, read twice: the path's shape that of the
        # background, or of the background over the model's broadband force; its gain
        # pinned by the model lines the record shows and bounded by those it does not show.
        # Of the two, the one whose twin is nearer the fit segments is kept.
        force_lines, pf_floor = _lines_and_floor(freq, pf)
        strong = [(f, a) for f, a in force_lines
                  if pf[int(round(f / df))] >= 10.0 ** (MODEL_LINE_MIN_DB / 10.0)
                  * pf_floor[int(round(f / df))]]
        spectra = dict(baseline, pf_floor=pf_floor, force_lines=force_lines, strong=strong,
                       forces=force_runs + twin_forces, force_keep=line_free(freq, pf))
        shaft = _shaft_gains(lines, model_rig, bearing, fr, df, force_runs)
        candidates = []
        for forced in (False, True):
            path, background, chain_notes, n_pins = _reading(forced, spectra, fs, freqs,
                                                             bearing, shaft_hz, ref, longest)
            machine = Machine(
                name=name or (ref.record_id or "machine"), rig=model_rig,
                shaft_gain=shaft[0],
                channel=ref.channel, model_signal=ref.model_signal, fs_hz=fs, op=op,
                path=path, background=background, unit=path.unit,
                unit_scale=ref.unit_scale, components=dict(ref.components), segment_s=seg_s,
                speed_wobble=wobble, calibrated_on=calibrated_on,
                notes=tuple(notes + chain_notes + [_shaft_words(shaft, fr)]))
            twin = [machine.sensor_signal(force, edge, n, seed + 31 * s)
                    for s, (force, edge, n) in enumerate(twin_forces)]
            _, twin_rows = feature_rows(twin, fs, freqs, bearings, ref.unit_scale)
            z_fit, _ = _misfit(names, twin_rows, fit_rows, spread)
            score = float(np.mean(robust_loss(np.array(list(z_fit.values()))))) \
                if z_fit else 0.0                                   # capped: THE misfit
            chi2_fit = float(np.mean([v * v for v in z_fit.values()])) if z_fit else 0.0
            candidates.append((-n_pins, score, forced, machine, twin_rows, chi2_fit))
        if not any(c[0] for c in candidates):
            # no model line pins the path: its gain is a prior, and a twin can match a
            # healthy record's broadband through either shape, so the fit does not tell
            # them apart
            _, score, forced, machine, twin_rows, chi2_fit = candidates[0]
            why = "no model line pins the path"
        else:
            (neg_pins, score, forced, machine, twin_rows, chi2_fit), other = sorted(
                candidates, key=lambda c: c[:3])
            why = (f"it keeps more pins ({-neg_pins} against {-other[0]})"
                   if neg_pins != other[0] else
                   f"its twin's misfit on the fit segments, chi2 per feature with z capped at "
                   f"{MISFIT_CAP:g}, {score:.2f} against {other[1]:.2f} for the other shape")
        shape_words = ("the background over the model's broadband force" if forced
                       else "the background's own")
        machine = replace(machine, notes=machine.notes + (f"path shape: {shape_words} ({why})",))
        return score, chi2_fit, machine, twin_rows

    # 5. the bearings' clearance (gear rigs): a healthy bearing's ball passes under load
    # (varying compliance) make a comb of lines whose level the clearance sets, and a
    # baseline shows it or not; the documented clearance is kept unless another one's twin
    # is nearer the fit segments by CLEARANCE_EVIDENCE (capped) and no farther uncapped
    first = twin_on(rig)
    documented = {b.clearance_m for s in rig.shafts for b in (s.bearing_1, s.bearing_2)}
    tried = [(c, twin_on(rig.with_clearance(c)))
             for c in (CLEARANCE_CANDIDATES_M if rig.gears is not None else ())
             if documented != {c}]
    better = [(c, reading) for c, reading in tried
              if reading[0] * CLEARANCE_EVIDENCE <= first[0] and reading[1] <= first[1]]
    if better:
        c, (score, _, machine, twin_rows) = min(better, key=lambda cr: cr[1][0])
        machine = replace(machine, notes=machine.notes + (
            f"bearing clearance: {_clearance_words(c)} instead of the model rig's "
            f"{', '.join(_clearance_words(d) for d in sorted(documented))}: its twin's "
            f"misfit on the fit segments (chi2 per feature with z capped at {MISFIT_CAP:g}) "
            f"is {score:.2f} against {first[0]:.2f} (the clearance sets the level of a healthy "
            "bearing's ball-pass comb and how many balls carry the load)",))
    else:
        score, _, machine, twin_rows = first
        why = (f"no other clearance's twin nearer the fit segments by {CLEARANCE_EVIDENCE:g}x"
               if tried else "a bearing rig's clearance is not read")
        machine = replace(machine, notes=machine.notes + (
            f"bearing clearance: the model rig's "
            f"{', '.join(_clearance_words(d) for d in sorted(documented))} kept ({why})",))

    # 6. the twin on the held-out segments
    z, z_model = _misfit(names, twin_rows, held_rows, spread)
    worst = max(z, key=lambda k: abs(z[k])) if z else None
    worst_m = max(z_model, key=lambda k: abs(z_model[k])) if z_model else None
    quality = {"z": z, "worst_feature": worst,
               "worst_z": float(z[worst]) if worst else float("nan"),
               "chi2_per_feature": float(np.mean([v * v for v in z.values()])) if z else 0.0,
               "z_with_model_spread": z_model, "worst_feature_with_model_spread": worst_m,
               "worst_z_with_model_spread": float(z_model[worst_m]) if worst_m
               else float("nan"),
               "chi2_per_feature_with_model_spread":
                   float(np.mean([v * v for v in z_model.values()])) if z_model else 0.0,
               "n_features": len(z), "held_out_segments": len(held),
               "twin_segments": int(twin_rows.shape[0])}
    # the loads no baseline file documents are the model's assumption (a run made here
    # carries its own)
    files = [r for r in records if r.path]
    assumed = tuple(f for f in ("torque_nm", "radial_load_n") if files and all(
        f in undocumented_load(r.meta.get("recording")) for r in files))
    return replace(machine, spread=spread, fit_quality=quality, assumed_load=assumed,
                   baseline=Baseline(tuple(r.signal for r in records), fs))
