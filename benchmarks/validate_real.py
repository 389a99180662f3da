"""Run ``cmsim compare`` on every recording of the shared datasets (docs/validation.md).

Run: ``python benchmarks/validate_real.py [--data DIR] [--workers W] [--out FILE.md]
[--json FILE]``. ``--data`` defaults to ``$CMSIM_DATA`` or ``../shared/datasets``. Every
recording is compared with its default channel, the same code, bounds and thresholds for all
(nothing is tuned to a file). The answer key (``condition``, ``fault*`` fields) is read from
metadata.json **after** the comparison, by this script only, to fill the "truth" and "match"
columns; the pipeline never sees it.
"""

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from cmsim.discrepancy import compare
from cmsim.measured import data_root, read_record

#: Catalogue finding that matches a metadata fault location or fault (first word of it).
MATCH = {"inner_race": "bearing_inner_race", "outer_race": "bearing_outer_race",
         "ball": "bearing_ball", "broken": "tooth_fault"}


def one(path):
    t0 = time.perf_counter()
    c = compare(read_record(path)).to_dict()
    c["wall_s"] = time.perf_counter() - t0
    return str(path), c


def truth_of(rec):
    """(truth text, expected finding or None) from a recording's answer-key fields."""
    cond = rec.get("condition")
    if cond == "healthy":
        return "healthy", "none"
    loc = rec.get("fault_location") or rec.get("fault") or rec.get("fault_type") or "fault"
    size = rec.get("fault_diameter_in")
    text = loc.split(" (")[0] + (f" {size} in" if size else "")
    key = loc.split(" ")[0]
    return text, MATCH.get(key)


def row(name, c, truth, expected):
    disc = ", ".join(f"{d['feature']} {d['measured']:.1f} vs {d['simulated']:.1f}"
                     for d in c["discrepancies"][:3])
    comp = f" ({c['component']})" if c["component"] else ""
    params = "; ".join(f"{k}={v:.3g}" for k, v in c["parameters"].items()) or "–"
    inferred = "; ".join(f"inferred {k}={v['value']:.6g}" for k, v in c["inferred"].items())
    if inferred:
        params += "; " + inferred
    g = c["gain"]
    ranked = ", ".join(f"{r['name']} {r['delta_chi2']:.0f}" for r in c["causes"][:3])
    if expected is None:
        match = "–"
    else:
        match = "yes" if c["finding"] == expected else (
            "no fault named" if c["finding"] == "none" else "no")
    return (f"| {name} | {disc} | {c['finding']}{comp} | {ranked} | {params} | "
            f"{g['before']:.2f} → {g['after']:.2f} ({g['relative']:.2f}) | "
            f"{c['simulations']} / {c['wall_s']:.0f} | {truth} | {match} |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--data", type=Path, default=data_root())
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--render", type=Path, default=None,
                    help="only re-render the tables from a --json file of an earlier run")
    a = ap.parse_args(argv)
    folders = sorted(p for p in a.data.iterdir() if (p / "metadata.json").is_file())
    jobs, keys = [], {}
    for folder in folders:
        meta = json.loads((folder / "metadata.json").read_text())
        for rec in meta["recordings"]:
            jobs.append(folder / rec["file"])
            keys[str(folder / rec["file"])] = truth_of(rec)
    if a.render:
        results = json.loads(a.render.read_text())
    else:
        with ProcessPoolExecutor(a.workers) as pool:
            results = dict(pool.map(one, jobs))
    lines = []
    for folder in folders:
        lines += [f"\n### {folder.name}\n",
                  "| recording | nominal model wrong on (largest z) | cause named (component) "
                  "| top causes (Δχ²) | fitted parameters | held-out χ²/feature before → after "
                  "(relative gain) | sims / wall s | truth | match |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for p in jobs:
            if p.parent == folder:
                truth, expected = keys[str(p)]
                lines.append(row(p.name, results[str(p)], truth, expected))
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        a.out.write_text(text)
    if a.json and not a.render:
        a.json.write_text(json.dumps(results, indent=1, default=float))


if __name__ == "__main__":
    main()
