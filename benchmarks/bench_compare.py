"""Benchmark of the discrepancy loop (issue 12): hidden-effect accuracy, severity, gain, timing.

Run: ``python benchmarks/bench_compare.py [--seeds N] [--budget B] [--workers W]
[--json OUT]``. For each effect of :data:`cmsim.discrepancy.synthetic.HIDDEN_EFFECTS` and for
records with no hidden effect (on the bearing rig and on the gear rig), ``--seeds`` records
are generated (random severity, component and nuisances) and compared, ``--workers``
comparisons at a time; prints the top-1 accuracy per effect, the confusion matrix, the
severity recovery (share within a factor 2 of the hidden value), the held-out gain, the
false-alarm rate and the time per comparison. ``--json`` keeps every record's ranking (each
cause's Δχ² and score) so the decision thresholds can be studied offline.
"""

import argparse
import json
import math
import time
from collections import Counter, defaultdict
from concurrent.futures import ProcessPoolExecutor

from cmsim.discrepancy import compare
from cmsim.discrepancy.compare import DEFAULT_BUDGET
from cmsim.discrepancy.synthetic import HIDDEN_EFFECTS, hidden_effect_record

SEVERITY_FACTOR = 2.0
SEED0 = 1000


def one(job):
    """Generate and compare one record; the row of the report."""
    eff, s, budget = job
    effect = None if eff.startswith("none") else eff
    h = hidden_effect_record(effect, SEED0 + s, rig_kind="gear" if eff == "none_gear" else None)
    t0 = time.perf_counter()
    c = compare(h.record, budget=budget, seed=s)
    wall = time.perf_counter() - t0
    fitted = next(iter(c.parameters.values()), None)
    ok_sev = (fitted is not None and h.value is not None and c.finding == effect
              and abs(math.log(fitted / h.value)) <= math.log(SEVERITY_FACTOR))
    return {"effect": eff, "seed": s, "finding": c.finding, "component": c.component,
            "true_component": h.component, "true_value": h.value, "fitted": fitted,
            "severity_ok": ok_sev, "gain": c.gain, "simulations": c.simulations,
            "chi2_per_feature": c.chi2_per_feature, "n_features": c.n_features,
            "causes": [{k: r[k] for k in ("name", "component", "score", "delta_chi2")}
                       for r in c.causes], "wall_s": wall}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--budget", type=int, default=None)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--effects", nargs="*", default=None)
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    budget = a.budget or DEFAULT_BUDGET
    effects = a.effects or (list(HIDDEN_EFFECTS) + ["none", "none_gear"])
    jobs = [(e, s, budget) for s in range(a.seeds) for e in effects]
    rows = []
    t_all = time.perf_counter()
    with ProcessPoolExecutor(a.workers) as pool:
        for r in pool.map(one, jobs):
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
    print("\nconfusion (rows: hidden effect, columns: finding)")
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
    fa = sum(r["finding"] != "none" for r in clean) / max(len(clean), 1)
    walls = [r["wall_s"] for r in rows]
    print(f"\ntop-1 over hidden effects {top1:.3f}, false alarms {fa:.3f}")
    print(f"mean wall per comparison {sum(walls) / len(walls):.1f} s (max {max(walls):.1f}), "
          f"mean simulations {sum(r['simulations'] for r in rows) / len(rows):.1f}, "
          f"total {time.perf_counter() - t_all:.0f} s on {a.workers} workers")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"rows": rows, "summary": summary, "top1": top1, "false_alarms": fa,
                       "confusion": {k: dict(v) for k, v in confusion.items()}}, fh,
                      indent=1, default=float)


if __name__ == "__main__":
    main()
