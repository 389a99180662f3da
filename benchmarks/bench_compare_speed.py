"""Speed of the machine twin (issue 16: calibration with its signature library <= 3 min, a
comparison against it <= 2 s for a 10-s record, on 2 cores).

For a gear machine (paper rig, a hidden tooth fault) and a bearing machine (CWRU-like rig, a
hidden outer-race defect) of :mod:`cmsim.discrepancy.synthetic`: the machine is calibrated on
a 10-s healthy baseline and its signature library built on 2 processes (each timed, as
``cmsim calibrate`` does them), then a 10-s record is compared against it ``--repeats``
times in this process (the comparison: features and matching, one refining simulation) and
as ``cmsim compare --machine`` runs it, a new process each time (start-up, imports and the
numba cache included). Prints the CPU, each wall time, the median comparison over the
record's duration (the realtime factor a monitoring loop cares for) and the command's over
the comparison's (what start-up costs), measured side by side.

Run: ``python benchmarks/bench_compare_speed.py [--repeats 3] [--kinds gear bearing]
[--json OUT]``. Nothing else should run meanwhile: the library uses both cores.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench_dataset import cpu_info  # the one CPU description of the benchmarks

from cmsim.discrepancy import compare
from cmsim.discrepancy.signatures import build_library
from cmsim.discrepancy.synthetic import hidden_effect_record
from cmsim.machine import calibrate

DURATION_S = 10.0
EFFECT = {"gear": "tooth_fault", "bearing": "bearing_outer_race"}


def _save_record(record, path):
    """The record as a file ``cmsim compare`` reads (npz + metadata-free options)."""
    np.savez(path, DE=record.signal.astype(np.float32))


def run_kind(kind, repeats, tmp):
    """Calibration and library walls, and the comparison walls of one machine."""
    baseline = hidden_effect_record(None, 0, rig_kind=kind, sim_seed=7,
                                    duration_s=DURATION_S).record
    t0 = time.perf_counter()
    machine = calibrate([baseline], seed=0)
    t1 = time.perf_counter()
    machine = machine.with_library(build_library(machine, seed=0, workers=2))
    t2 = time.perf_counter()
    path = Path(tmp) / f"{kind}.toml"
    machine.save(path)
    record = hidden_effect_record(EFFECT[kind], 0, duration_s=DURATION_S).record
    inproc, findings = [], set()
    for _ in range(repeats):
        c = compare(record, machine=machine, seed=0)
        inproc.append(c.wall_s)
        findings.add(c.finding)
        print(f"  {kind}: compare {c.wall_s:.2f} s, {c.finding}", flush=True)
    rec_file = Path(tmp) / f"{kind}_record.npz"
    _save_record(record, rec_file)
    cli = []
    rig = Path(tmp) / f"{kind}_rig.toml"
    machine.rig.save(rig)
    for _ in range(repeats):
        t = time.perf_counter()
        out = subprocess.run([sys.executable, "-m", "cmsim", "compare", str(rec_file),
                              "--machine", str(path), "--rig", str(rig), "--fs-hz",
                              f"{record.fs_hz:g}", "--speed-rpm", f"{record.op.speed_rpm:g}",
                              "--channel", "DE", "--json"],
                             capture_output=True, text=True)
        cli.append(time.perf_counter() - t)
        res = json.loads(out.stdout)
        print(f"  {kind}: cmsim compare {cli[-1]:.2f} s, {res.get('finding')}", flush=True)
    return {"kind": kind, "calibration_s": t1 - t0, "library_s": t2 - t1,
            "entries": len(machine.library.entries), "compare_s": inproc, "command_s": cli,
            "findings": sorted(findings)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--kinds", nargs="*", default=["gear", "bearing"],
                    choices=["gear", "bearing"])
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    name, cores, load = cpu_info()
    print(f"CPU: {name}, {cores} cores usable, load average {load[0]:.1f}")
    with tempfile.TemporaryDirectory() as tmp:
        out = [run_kind(k, a.repeats, tmp) for k in a.kinds]
    print("| machine | calibration s | library s (entries) | compare s (median) | "
          "compare / record duration | cmsim compare s (median) | command / compare |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for r in out:
        c, k = statistics.median(r["compare_s"]), statistics.median(r["command_s"])
        print(f"| {r['kind']} ({', '.join(r['findings'])}) | {r['calibration_s']:.0f} | "
              f"{r['library_s']:.0f} ({r['entries']}) | {c:.2f} | {c / DURATION_S:.3f} | "
              f"{k:.2f} | {k / c:.1f} |")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"cpu": name, "cores": cores, "results": out}, fh, indent=1)


if __name__ == "__main__":
    main()
