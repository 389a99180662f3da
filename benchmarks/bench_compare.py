"""Benchmark of the discrepancy loop (issues 12, 25): hidden-effect accuracy, severity, gain,
false alarms, timing — on two generators, with and without a calibrated machine.

Run: ``python benchmarks/bench_compare.py [--generator model|angle] [--machine] [--seeds N]
[--first-seed S] [--budget B] [--workers W] [--effects ...] [--json OUT]``.

* ``--generator model`` (:mod:`cmsim.discrepancy.synthetic`): records made by cmsim's own
  model with one hidden effect of the cause catalogue and measurement-chain nuisances; the
  rig's housing path is documented (the ``documented`` nominal model).
* ``--generator angle`` (:mod:`cmsim.discrepancy.angle_domain`): records of a generator that
  shares no code with the model (angle-domain synthesis, a housing, background and mesh
  levels drawn per machine), written as a measured folder and read through
  :func:`cmsim.measured.read_record`, the rig built from the metadata (the ``path-free``
  nominal model).
* ``--machine``: each machine's healthy baseline record (another realisation) is calibrated
  first (:func:`cmsim.machine.calibrate`, then its signature library,
  :func:`cmsim.discrepancy.signatures.build_library`: what ``cmsim calibrate`` does), once
  per machine, and every effect on that machine is compared against it (its baseline the
  healthy prediction, :mod:`cmsim.discrepancy.judge`).

For each effect and ``--seeds`` machines a record is compared; the report gives the top-1
accuracy per effect, the confusion matrix, the severity recovery (generator ``model``), the
held-out gain, the false-alarm rate (a cause named on a record with no hidden effect) and
the time per comparison.
"""

import argparse
import json
import math
import tempfile
import time
from collections import Counter, defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from _decisions import spy_on_decisions

from cmsim.discrepancy import compare
from cmsim.discrepancy.angle_domain import EFFECTS as ANGLE_EFFECTS
from cmsim.discrepancy.angle_domain import GEAR_ONLY, draw_machine, write_machine
from cmsim.discrepancy.compare import DEFAULT_BUDGET
from cmsim.discrepancy.signatures import build_library
from cmsim.discrepancy.synthetic import GEAR_EFFECTS, HIDDEN_EFFECTS, hidden_effect_record
from cmsim.machine import Machine, calibrate
from cmsim.measured import read_record

SEVERITY_FACTOR = 2.0
SEED0 = 1000


def _model_case(eff, s):
    effect = None if eff.startswith("none") else eff
    kind = "gear" if eff == "none_gear" or effect in GEAR_EFFECTS else "bearing"
    h = hidden_effect_record(effect, SEED0 + s, rig_kind=kind)
    base = hidden_effect_record(None, SEED0 + s, rig_kind=kind, sim_seed=SEED0 + s + 300_000)
    return h.record, base.record, h.value, h.component


def _angle_case(eff, s, folder):
    effect = None if eff.startswith("none") else eff
    kind = "gear" if eff == "none_gear" or effect in GEAR_ONLY else (
        "gear" if s % 2 else "bearing")
    m = draw_machine(SEED0 + s, kind)
    severity = 0.7 + 0.8 * ((s * 7919) % 100) / 100.0
    write_machine(folder, m, [("baseline", None, 0.0, 1), ("record", effect, severity, 2)])
    # where the generator puts it: a bearing fault on the drive end, a gear fault on the
    # input gear (its once-per-revolution event is the input shaft's)
    where = ("drive_end" if effect and effect.startswith("bearing") else
             "input gear" if effect in GEAR_ONLY else None)
    return (read_record(Path(folder) / "record.npz"), read_record(Path(folder) / "baseline.npz"),
            severity, where)


def _compare(record, machine, budget, s):
    seen = spy_on_decisions()
    t0 = time.perf_counter()
    c = compare(record, machine=machine, budget=budget, seed=s)
    return c, time.perf_counter() - t0, seen.get("decide")


def _row(eff, s, c, wall, decided, value, component, generator, calibration_s=None):
    effect = None if eff.startswith("none") else eff
    fitted = next(iter(c.parameters.values()), None)
    ok_sev = (generator == "model" and fitted is not None and value is not None
              and c.finding == effect and abs(math.log(fitted / value))
              <= math.log(SEVERITY_FACTOR))
    return {"effect": eff, "seed": s, "finding": c.finding, "component": c.component,
            "true_component": component, "true_value": value, "fitted": fitted,
            "severity_ok": ok_sev, "gain": c.gain, "simulations": c.simulations,
            "chi2_per_feature": c.chi2_per_feature, "n_features": c.n_features,
            "mode": c.mode, "near_ties": c.near_ties,
            "causes": [{k: r[k] for k in ("name", "component", "score", "delta_chi2",
                                           "delta_chi2_all")} for r in c.causes],
            "wall_s": wall, "calibration_s": calibration_s, "decide": decided}


def one(job):
    """Generate and compare one record without a machine; the row of the report."""
    eff, s, budget, generator, _ = job
    with tempfile.TemporaryDirectory() as tmp:
        record, _, value, component = (_model_case(eff, s) if generator == "model"
                                       else _angle_case(eff, s, tmp))
        c, wall, decided = _compare(record, None, budget, s)
    return [_row(eff, s, c, wall, decided, value, component, generator)]


def machine_jobs(job):
    """One machine (its healthy baseline calibrated and its signature library built once),
    then every effect of ``effects`` on it: the rows of the report."""
    effects, s, budget, generator, cache = job
    rows = []
    machine = calibration_s = None
    kept = (None if cache is None else
            Path(cache) / f"{generator}_{_machine_key(effects[0], s, generator)[0]}_{s}.toml")
    with tempfile.TemporaryDirectory() as tmp:
        for eff in effects:
            record, baseline, value, component = (_model_case(eff, s) if generator == "model"
                                                  else _angle_case(eff, s, tmp))
            if machine is None and kept is not None and kept.is_file():
                machine = Machine.load(kept)
            if machine is None:
                t0 = time.perf_counter()
                machine = calibrate([baseline], seed=s)
                machine = machine.with_library(build_library(machine, seed=s))
                calibration_s = time.perf_counter() - t0
                if kept is not None:
                    machine.save(kept)
            c, wall, decided = _compare(record, machine, budget, s)
            rows.append(_row(eff, s, c, wall, decided, value, component, generator,
                             calibration_s))
    return rows


def _machine_key(eff, s, generator):
    """What a record's machine depends on (its effects share it)."""
    effect = None if eff.startswith("none") else eff
    if generator == "model":
        return "gear" if eff == "none_gear" or effect in GEAR_EFFECTS else "bearing", s
    return ("gear" if eff == "none_gear" or effect in GEAR_ONLY
            else ("gear" if s % 2 else "bearing")), s


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--generator", choices=("model", "angle"), default="model")
    ap.add_argument("--machine", action="store_true")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=0,
                    help="the machines' seeds start here: seeds a rule was not made looking at "
                         "check it honestly")
    ap.add_argument("--budget", type=int, default=None)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--effects", nargs="*", default=None)
    ap.add_argument("--clean-seeds", type=int, default=None,
                    help="seeds of the records with no hidden effect (default --seeds)")
    ap.add_argument("--json", default=None)
    ap.add_argument("--machine-cache", type=Path, default=None,
                    help="keep each calibrated machine (with its library) in this folder and "
                         "read it back on a later run: the judge's rules can be iterated on "
                         "without the calibrations (a machine depends only on its seed)")
    a = ap.parse_args(argv)
    budget = a.budget or DEFAULT_BUDGET
    catalogue = list(HIDDEN_EFFECTS) if a.generator == "model" else list(ANGLE_EFFECTS)
    effects = a.effects or (catalogue + ["none", "none_gear"])
    clean_seeds = a.seeds if a.clean_seeds is None else a.clean_seeds
    jobs = [(e, s, budget, a.generator, a.machine)
            for s in range(a.first_seed, a.first_seed + max(a.seeds, clean_seeds))
            for e in effects
            if s - a.first_seed < (clean_seeds if e.startswith("none") else a.seeds)]
    run = one
    if a.machine:            # one task per machine: its library is built once
        groups = defaultdict(list)
        for e, s, *_ in jobs:
            groups[_machine_key(e, s, a.generator)].append(e)
        if a.machine_cache is not None:
            a.machine_cache.mkdir(parents=True, exist_ok=True)
        jobs = [(effs, key[1], budget, a.generator, a.machine_cache)
                for key, effs in groups.items()]
        run = machine_jobs
    rows = []
    t_all = time.perf_counter()
    with ProcessPoolExecutor(a.workers) as pool:
        for r in (x for batch in pool.map(run, jobs) for x in batch):
            rows.append(r)
            top = r["causes"][0] if r["causes"] else {"name": None, "delta_chi2": 0.0}
            print(f"{r['effect']:20s} seed {r['seed']}: {r['finding']:20s} "
                  f"true {r['true_value']} fitted {r['fitted']} "
                  f"gain {r['gain']['relative']:.2f} sims {r['simulations']} "
                  f"chi2/f {r['chi2_per_feature']:.2f} top {top['name']} "
                  f"d {top['delta_chi2']:.0f} {r['wall_s']:.1f} s", flush=True)
    truth = {e: (e if not e.startswith("none") else "none") for e in effects}
    confusion = defaultdict(Counter)
    for r in rows:
        confusion[r["effect"]][r["finding"]] += 1
    names = sorted({g for c in confusion.values() for g in c} | set(truth.values()))
    print(f"\ngenerator {a.generator}, {'with' if a.machine else 'without'} a machine; "
          "confusion (rows: hidden effect, columns: finding)")
    short = {n: "".join(w[:3] for w in n.split("_"))[:7] for n in names}
    print(" " * 20 + " ".join(f"{short[n]:>7s}" for n in names))
    for eff in effects:
        print(f"{eff:20s}" + " ".join(f"{confusion[eff][n]:7d}" for n in names))
    print("\neffect               top1   severity(x2)  mean gain")
    summary = {}
    for eff in effects:
        rs = [r for r in rows if r["effect"] == eff]
        hit = [r for r in rs if r["finding"] == truth[eff]]
        sev = [r["severity_ok"] for r in hit if truth[eff] != "none"]
        gain = [r["gain"]["relative"] for r in hit if truth[eff] != "none"]
        summary[eff] = {"top1": len(hit) / len(rs),
                        "severity_within_x2": (sum(sev) / len(sev)) if sev else None,
                        "mean_gain": (sum(gain) / len(gain)) if gain else None}
        print(f"{eff:20s} {summary[eff]['top1']:5.2f}   {summary[eff]['severity_within_x2']}"
              f"   {summary[eff]['mean_gain']}")
    faulty = [r for r in rows if not r["effect"].startswith("none")]
    clean = [r for r in rows if r["effect"].startswith("none")]
    top1 = sum(r["finding"] == r["effect"] for r in faulty) / max(len(faulty), 1)
    fa = sum(r["finding"] not in ("none", "unexplained") for r in clean) / max(len(clean), 1)
    walls = [r["wall_s"] for r in rows]
    where = sum(r["finding"] == r["effect"] and r["true_component"] in (None, r["component"])
                for r in faulty) / max(len(faulty), 1)
    print(f"\ntop-1 over hidden effects {top1:.3f} ({where:.3f} named where it sits: the "
          f"bearing or gear too), false alarms {fa:.3f} "
          f"({sum(r['finding'] == 'unexplained' for r in clean)} clean records unexplained)")
    cal = sorted({r["calibration_s"] for r in rows if r.get("calibration_s") is not None})
    if cal:
        print(f"calibration with the signature library: {min(cal):.0f}-{max(cal):.0f} s per "
              f"machine ({len(cal)} machines, {a.workers} machines at a time)")
    print(f"mean wall per comparison {sum(walls) / len(walls):.1f} s (max {max(walls):.1f}), "
          f"mean simulations {sum(r['simulations'] for r in rows) / len(rows):.1f}, "
          f"total {time.perf_counter() - t_all:.0f} s on {a.workers} workers")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"rows": rows, "summary": summary, "top1": top1, "top1_where": where,
                       "false_alarms": fa,
                       "generator": a.generator, "machine": a.machine,
                       "confusion": {k: dict(v) for k, v in confusion.items()}}, fh,
                      indent=1, default=float)


if __name__ == "__main__":
    main()
