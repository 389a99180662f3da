"""Speed of a comparison against a machine file (issue 25: calibration <= 2 min, a comparison
<= 30 s for a 10-s record on 2 cores), one process against two, side by side.

For a gear machine (paper rig, a hidden tooth fault) and a bearing machine (CWRU-like rig, a
hidden outer-race defect) of :mod:`cmsim.discrepancy.synthetic`: the machine is calibrated on
a 10-s healthy baseline (timed), then a 10-s record is compared against it with
``workers=1`` and ``workers=2`` in alternating order, ``--pairs`` times. Prints each wall
time, the ratio of each pair (one process / two) with its median, and whether the two give
the same comparison (finding, every cause's evidence, every discrepancy's z: they must).

Run: ``python benchmarks/bench_compare_speed.py [--pairs 2] [--kinds gear bearing]
[--json OUT]`` (about 6 min on 2 cores). Nothing else should run meanwhile: a comparison
with two processes needs both cores.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

from bench_dataset import cpu_info  # the one CPU description of the benchmarks

from cmsim.discrepancy import compare
from cmsim.discrepancy.synthetic import hidden_effect_record
from cmsim.machine import calibrate

DURATION_S = 10.0
EFFECT = {"gear": "tooth_fault", "bearing": "bearing_outer_race"}


def signature(c):
    """What must not depend on the number of processes."""
    return (c.finding, c.component, c.simulations,
            [(r["name"], r["component"], r["delta_chi2"]) for r in c.causes],
            [(d["feature"], d["z"]) for d in c.discrepancies], c.gain["after"])


def run_kind(kind, pairs):
    """Calibration wall and the paired comparison walls of one machine."""
    baseline = hidden_effect_record(None, 0, rig_kind=kind, sim_seed=7,
                                    duration_s=DURATION_S).record
    t0 = time.perf_counter()
    machine = calibrate([baseline], seed=0)
    cal_s = time.perf_counter() - t0
    record = hidden_effect_record(EFFECT[kind], 0, duration_s=DURATION_S).record
    walls, sigs = {1: [], 2: []}, {1: set(), 2: set()}
    for i in range(pairs):
        for w in ((1, 2) if i % 2 == 0 else (2, 1)):
            c = compare(record, machine=machine, seed=0, workers=w)
            walls[w].append(c.wall_s)
            sigs[w].add(repr(signature(c)))
            print(f"  {kind}: workers {w}: {c.wall_s:.1f} s, {c.finding}", flush=True)
    ratios = [a / b for a, b in zip(walls[1], walls[2])]
    return {"kind": kind, "calibration_s": cal_s, "walls": walls, "ratios": ratios,
            "same": len(sigs[1] | sigs[2]) == 1, "finding": c.finding}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pairs", type=int, default=2)
    ap.add_argument("--kinds", nargs="*", default=["gear", "bearing"],
                    choices=["gear", "bearing"])
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    name, cores, load = cpu_info()
    print(f"CPU: {name}, {cores} cores usable, load average {load[0]:.1f}")
    out = [run_kind(k, a.pairs) for k in a.kinds]
    print("| machine | calibration s | 1 process s | 2 processes s | ratio (median, range) "
          "| same result |")
    print("| --- | --- | --- | --- | --- | --- |")
    for r in out:
        w1, w2, q = r["walls"][1], r["walls"][2], r["ratios"]
        print(f"| {r['kind']} ({r['finding']}) | {r['calibration_s']:.1f} | "
              f"{min(w1):.1f}-{max(w1):.1f} | {min(w2):.1f}-{max(w2):.1f} | "
              f"{statistics.median(q):.2f} ({min(q):.2f}-{max(q):.2f}) | "
              f"{'yes' if r['same'] else 'NO'} |")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"cpu": name, "cores": cores, "results": out}, fh, indent=1)
    if not all(r["same"] for r in out):
        raise SystemExit("the comparison depends on the number of processes")


if __name__ == "__main__":
    main()
