"""Benchmark of the discrepancy loop (issue 12): hidden-effect accuracy, severity, gain, timing.

Run: ``python benchmarks/bench_compare.py [--seeds N] [--budget B] [--json OUT]``.
For each effect of :data:`cmsim.discrepancy.synthetic.HIDDEN_EFFECTS` and for records with
no hidden effect, ``--seeds`` records are generated (random severity, nuisances) and
compared; prints the top-1 accuracy per effect, the confusion matrix, the severity recovery
(share within a factor 2), the held-out gain and the false-alarm rate.
"""

import argparse
import json
import math
import time
from collections import Counter, defaultdict

from cmsim.discrepancy import compare
from cmsim.discrepancy.synthetic import HIDDEN_EFFECTS, hidden_effect_record

SEVERITY_FACTOR = 2.0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--budget", type=int, default=40)
    ap.add_argument("--effects", nargs="*", default=None)
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    effects = (a.effects or list(HIDDEN_EFFECTS)) + ["none"]
    confusion = defaultdict(Counter)
    rows = []
    for eff in effects:
        for s in range(a.seeds):
            t0 = time.perf_counter()
            h = hidden_effect_record(None if eff == "none" else eff, 1000 + s)
            c = compare(h.record, budget=a.budget, seed=s)
            got = c.finding
            confusion[eff][got] += 1
            fitted = next(iter(c.parameters.values()), None)
            ok_sev = (fitted is not None and h.value is not None and got == eff
                      and abs(math.log(fitted / h.value)) <= math.log(SEVERITY_FACTOR))
            rows.append({"effect": eff, "seed": s, "finding": got, "true_value": h.value,
                         "fitted": fitted, "severity_ok": ok_sev,
                         "gain_relative": c.gain["relative"], "simulations": c.simulations,
                         "chi2_per_feature": c.chi2_per_feature,
                         "top": c.causes[0]["name"] if c.causes else None,
                         "top_score": c.causes[0]["score"] if c.causes else None,
                         "wall_s": time.perf_counter() - t0})
            print(f"{eff:20s} seed {s}: {got:20s} true {h.value} fitted {fitted} "
                  f"gain {c.gain['relative']:.2f} sims {c.simulations} "
                  f"chi2/f {c.chi2_per_feature:.2f} top {rows[-1]['top']} "
                  f"{rows[-1]['top_score']:.2f} "
                  f"{rows[-1]['wall_s']:.1f} s", flush=True)
    names = sorted({g for c in confusion.values() for g in c} | set(effects))
    print("\nconfusion (rows: hidden effect, columns: finding)")
    short = {n: "".join(w[:3] for w in n.split("_"))[:7] for n in names}
    print(" " * 20 + " ".join(f"{short[n]:>7s}" for n in names))
    for eff in effects:
        print(f"{eff:20s}" + " ".join(f"{confusion[eff][n]:7d}" for n in names))
    print("\neffect               top1   severity(x2)  mean gain")
    summary = {}
    for eff in effects:
        rs = [r for r in rows if r["effect"] == eff]
        acc = sum(r["finding"] == eff for r in rs) / len(rs)
        sev = [r["severity_ok"] for r in rs if r["finding"] == eff and eff != "none"]
        gain = [r["gain_relative"] for r in rs if r["finding"] == eff and eff != "none"]
        summary[eff] = {"top1": acc, "severity_within_x2": (sum(sev) / len(sev)) if sev else None,
                        "mean_gain": (sum(gain) / len(gain)) if gain else None}
        print(f"{eff:20s} {acc:5.2f}   {summary[eff]['severity_within_x2']}   "
              f"{summary[eff]['mean_gain']}")
    walls = [r["wall_s"] for r in rows]
    print(f"\nmean wall {sum(walls) / len(walls):.1f} s, mean simulations "
          f"{sum(r['simulations'] for r in rows) / len(rows):.1f}")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"rows": rows, "summary": summary,
                       "confusion": {k: dict(v) for k, v in confusion.items()}}, fh, indent=1)


if __name__ == "__main__":
    main()
