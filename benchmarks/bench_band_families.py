"""Envelope families read band by band against the baseline in the same band (issue 47's
"envelope families per band"): how many of the angle-domain generator's bearing defects would
stand out, and how many of its healthy records would not.

Run: ``python benchmarks/bench_band_families.py [--generator angle|model] [--seeds N]
[--json OUT]`` (angle: about 10 s for 8 seeds on one core, no calibration and no model run;
model: cmsim's own records and another healthy realisation as the baseline, as
``bench_compare.py --generator model --machine`` makes them, about 20 s).

For each machine of :mod:`cmsim.discrepancy.angle_domain` (the same machines and records as
``bench_compare.py --generator angle``: bearing machines on even seeds, gear machines on odd
ones), or of cmsim's model (``--generator model``: a bearing and a gear machine per seed),
its healthy baseline and its outer-race, inner-race, ball and healthy records are cut into
half-second segments. Every segment's band columns
(:func:`cmsim.features.band_family_columns`, what the judge reads: the lines of BPFO, BPFI
and 2·BSF over the envelope spectrum's median, dB, in each band of the fixed bank) are read
for the defect's bearing (every bearing on a healthy record).

A family **stands out** where its line, in one band, rises over the baseline's mean in
the same band by the judge's rule (:func:`cmsim.discrepancy.stand_out.standing_out`:
:data:`~cmsim.discrepancy.stand_out.FAMILY_Z` σ and :data:`~cmsim.discrepancy.stand_out.FAMILY_RISE_DB`
dB; σ of :func:`~cmsim.discrepancy.columns.sigma_of`: the baseline's segment-to-segment
spread over both means' segments and the judge's floor, and with ``--realisations N`` the
spread of the baseline's mean and N other healthy records' of the same machine, as the
library's realisation spread). The report gives, per
record, the families that stand out and each family's largest rise, then the counts: the
true family standing out, the true family rising most, and healthy records in which any
family stands out (false alarms). The answer key is read only to score.
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np
from bench_compare import SEED0, _angle_case, _model_case

from cmsim.discrepancy.angle_domain import draw_machine, write_machine
from cmsim.discrepancy.columns import sigma_of
from cmsim.discrepancy.stand_out import standing_out
from cmsim.discrepancy.synthetic import hidden_effect_record
from cmsim.features import N_ENVELOPE_BANDS, band_family_columns, segments
from cmsim.measured import read_record

#: Lines of each family read (``envelope_lines`` names).
FAMILIES = {"bpfo": ("bpfo_1",), "bpfi": ("bpfi_1",), "bsf2": ("bsf2_1",)}
TRUE_FAMILY = {"bearing_outer_race": "bpfo", "bearing_inner_race": "bpfi",
               "bearing_ball": "bsf2"}
KEYS = [k for ks in FAMILIES.values() for k in ks]
SEG_S = 0.5
MAX_SEGMENTS = 16


def band_lines(record, bearing):
    """(segments, bands, lines) levels in dB of one bearing's family lines in every band
    (:func:`cmsim.features.band_family_columns`, what the judge reads)."""
    freqs = record.model_frequencies()
    bf = {bearing: freqs.bearing(bearing)}
    fs = record.fs_hz
    x = np.asarray(record.signal, dtype=float)
    rows = []
    for a, b in segments(x.size, fs, SEG_S, MAX_SEGMENTS):
        f = band_family_columns(x[a:b] - x[a:b].mean(), fs, freqs.fr1_hz, bf)
        rows.append([[f[_column(k, bearing, j)] for k in KEYS]
                     for j in range(N_ENVELOPE_BANDS)])
    return np.array(rows)


def _column(key, bearing, band=None):
    """The ``env_*`` column of line ``key`` (``bpfo_1`` …) of ``bearing`` (in ``band``)."""
    fam, h = key.split("_")
    return f"env_{fam}_{bearing}_h{h}" + ("" if band is None else f"_bb{band}") + "_db"


def other_healthy(generator, s, kind, j):
    """Healthy record ``j`` (0, 1, …) of machine ``s`` other than its baseline and the
    records compared: another run of the same machine, what the realisation spread is read
    from."""
    if generator == "angle":
        with tempfile.TemporaryDirectory() as tmp:
            write_machine(tmp, draw_machine(SEED0 + s, kind),
                          [("baseline", None, 0.0, 1), ("other", None, 0.0, 10 + j)])
            return read_record(Path(tmp) / "other.npz")
    return hidden_effect_record(None, SEED0 + s, rig_kind=kind,
                                sim_seed=SEED0 + s + 500_000 + 1_000 * j).record


def reference(base, bearing, others=()):
    """A machine's reference for ``bearing``: its baseline's band lines (segments, bands,
    lines) and the realisation spread per column — with ``others`` (other healthy records of
    the machine) that of the baseline's mean and theirs, as the library's; else 0."""
    fb = band_lines(base, bearing)
    means = [np.nanmean(fb, axis=0).ravel()]
    means += [np.nanmean(band_lines(o, bearing), axis=0).ravel() for o in others]
    realisation = (np.nanstd(np.vstack(means), axis=0, ddof=1) if others
                   else np.zeros_like(means[0]))
    return fb, realisation


def compare(ref, rec, bearing):
    """Per family of ``bearing``: whether it stands out in any band against the machine's
    :func:`reference` ``ref``, and its largest rise (dB)."""
    fb, realisation = ref
    fr = band_lines(rec, bearing)
    mean_b, mean_r = np.nanmean(fb, axis=0).ravel(), np.nanmean(fr, axis=0).ravel()
    spread = np.nanstd(fb, axis=0, ddof=1).ravel()
    names = [_column(k, bearing, j) for j in range(fb.shape[1]) for k in KEYS]
    sigma = sigma_of(spread, realisation, names, fr.shape[0], fb.shape[0])
    out = set(standing_out(range(len(names)), mean_r, mean_b, sigma, names))
    result = {}
    for fam, ks in FAMILIES.items():
        cols = [b * len(KEYS) + KEYS.index(k) for b in range(fb.shape[1]) for k in ks]
        rise = mean_r[cols] - mean_b[cols]
        result[fam] = {"stands_out": any(c in out for c in cols),
                       "max_rise_db": float(np.nanmax(rise))}
    return result


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--generator", choices=("angle", "model"), default="angle")
    ap.add_argument("--seeds", type=int, default=None,
                    help="machines (default 8 angle, 3 model, as bench_compare.py reads them)")
    ap.add_argument("--realisations", type=int, default=0,
                    help="other healthy records per machine whose spread joins σ (default 0: "
                         "the baseline's segments alone)")
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    kept = {}
    seeds = a.seeds or (8 if a.generator == "angle" else 3)
    rows = []
    for s in range(seeds):
        kind = "gear" if s % 2 else "bearing"
        effects = ((*TRUE_FAMILY, "none_gear" if kind == "gear" else "none")
                   if a.generator == "angle" else (*TRUE_FAMILY, "none", "none_gear"))
        for eff in effects:
            with tempfile.TemporaryDirectory() as tmp:
                rec, base, sev, comp = (_angle_case(eff, s, tmp) if a.generator == "angle"
                                        else _model_case(eff, s))
            if a.generator == "model":
                kind = "gear" if eff == "none_gear" else "bearing"
            names = list(rec.model_frequencies().bearing_names)
            # a defect's own bearing (the angle generator's sits on the first); a healthy
            # record alarms where any bearing's family stands out
            keys = {"drive_end": "1b1", "fan_end": "1b2"}        # the model's locations
            read = (names if eff.startswith("none") else
                    [keys.get(comp, comp) if keys.get(comp, comp) in names else names[0]])
            if (s, kind) not in kept:  # each machine's other runs made once, and its
                kept[(s, kind)] = [other_healthy(a.generator, s, kind, j)    # reference
                                   for j in range(a.realisations)]           # read once
            for b in read:
                if (s, kind, b) not in kept:
                    kept[(s, kind, b)] = reference(base, b, kept[(s, kind)])
            per = [compare(kept[(s, kind, b)], rec, b) for b in read]
            r = {f: {"stands_out": any(p[f]["stands_out"] for p in per),
                     "max_rise_db": max(p[f]["max_rise_db"] for p in per)} for f in FAMILIES}
            top = max(r, key=lambda f: r[f]["max_rise_db"])
            rows.append({"seed": s, "machine": kind, "effect": eff, "severity": sev,
                         "families": r, "largest": top})
            size = "-" if sev is None else f"{sev:.3g}"
            print(f"seed {s} {kind:7s} {eff:20s} size {size} on {read[0] if len(read) == 1 else 'every bearing'}  stands out: "
                  f"{[f for f in r if r[f]['stands_out']]}  largest rise (dB): "
                  + ", ".join(f"{f} {r[f]['max_rise_db']:.1f}" for f in r), flush=True)
    print("\nmachine  defect               true family stands out   true family rises most")
    for kind in ("bearing", "gear"):
        for eff, fam in TRUE_FAMILY.items():
            rs = [r for r in rows if r["machine"] == kind and r["effect"] == eff]
            if not rs:
                continue
            print(f"{kind:8s} {eff:20s} {sum(r['families'][fam]['stands_out'] for r in rs):6d} "
                  f"of {len(rs):<14d} {sum(r['largest'] == fam for r in rs):6d} of {len(rs)}")
    clean = [r for r in rows if r["effect"].startswith("none")]
    alarms = sum(any(v["stands_out"] for v in r["families"].values()) for r in clean)
    print(f"healthy records with a family standing out: {alarms} of {len(clean)}")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
