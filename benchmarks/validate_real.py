"""Run ``cmsim compare`` on every recording of the shared datasets (docs/validation.md), in
both modes: against a machine calibrated on a healthy baseline, and without one.

Run: ``python benchmarks/validate_real.py [--data DIR] [--workers W] [--out FILE.md]
[--json FILE] [--render FILE] [--channel NAME]``. ``--data`` defaults to ``$CMSIM_DATA`` or
``../shared/datasets``; ``--channel`` reads every record on another sensor than its default
(``--datasets cwru_bearing_12k_de --channel FE``: the drive-end faults through the fan-end
accelerometer, calibrated on that sensor's own baseline).

* **Calibrated** (``compare --machine``): in a folder with healthy records, a machine is
  calibrated (:func:`cmsim.machine.calibrate` and its signature library,
  :func:`cmsim.discrepancy.signatures.build_library`) on the **first half** of each healthy
  record
  and never scored on it; every other record is compared against the machine of the baseline
  at its own documented load (``motor_load_hp``, ``load_percent``, ``radial_load_lbs``), the
  healthy record by its second half; records are also compared across loads (against the
  machine of every other load) and marked so.
* **Calibration-free** (``compare``): every recording against the nominal model (the
  documented housing path where the rig has one, else path-free evidence only).

The same code, bounds and thresholds for all (nothing is tuned to a file). Which records are
healthy is what a user knows of their baseline; the fault fields (``fault*``) are read by this
script only, after the comparison, to fill the "truth" and "match" columns.
"""

import argparse
import json
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from _decisions import spy_on_decisions

from cmsim.discrepancy import compare
from cmsim.discrepancy.signatures import build_library
from cmsim.machine import Machine, calibrate
from cmsim.measured import data_root, read_record

#: Catalogue finding that matches a metadata fault location or fault (first word of it).
MATCH = {"inner_race": "bearing_inner_race", "outer_race": "bearing_outer_race",
         "ball": "bearing_ball", "broken": "tooth_fault"}

#: Where the machines of a run are written (one per healthy record, calibrated once).
MACHINE_DIR = Path(tempfile.gettempdir()) / "cmsim-validate-real"

#: Documented load keys of a recording (the operating point a baseline is matched on).
LOAD_KEYS = ("motor_load_hp", "load_percent", "radial_load_lbs")


def _half(rec, which):
    d = rec.signal.size / rec.fs_hz
    return rec.span(0.0, d / 2) if which == "first" else rec.span(d / 2)


def calibrate_half(job):
    """(baseline path, machine file, calibration wall s): the machine of the first half of a
    healthy record with its signature library (what ``cmsim calibrate`` writes), written
    beside the other machine files of this run; with ``reuse``, an earlier run's file of it
    is read instead (the calibration is deterministic: the judge's rules can be iterated on
    without 5 minutes of calibrations each time)."""
    baseline, reuse, channel = job
    t0 = time.perf_counter()
    out = MACHINE_DIR / (f"{Path(baseline).parent.name}_{Path(baseline).stem}"
                         + (f"_{channel}" if channel else "") + ".toml")
    if reuse and out.is_file():
        return str(baseline), str(out), 0.0
    machine = calibrate([_half(read_record(baseline, channel=channel), "first")])
    machine = machine.with_library(build_library(machine))
    machine.save(out)
    return str(baseline), str(out), time.perf_counter() - t0


def one(job):
    """Compare one recording (job: mode, path, baseline path or None, whether the record is
    the baseline itself, the baseline's machine file or None)."""
    mode, path, baseline, is_baseline, channel, machine_file = job
    rec = read_record(path, channel=channel)
    machine, quality = None, None
    if machine_file is not None:
        machine = Machine.load(machine_file)
        quality = {k: machine.fit_quality.get(k) for k in
                   ("worst_feature", "worst_z", "chi2_per_feature")}
        if is_baseline:
            rec = _half(rec, "second")
    seen = spy_on_decisions()
    t1 = time.perf_counter()
    c = compare(rec, machine=machine).to_dict()
    c["decide"] = seen.get("decide")
    c.pop("spectra", None)
    c["wall_s"] = time.perf_counter() - t1
    c["calibration"] = quality
    c["baseline"] = None if baseline is None else Path(baseline).name
    return f"{mode}|{path}|{baseline}", c


def truth_of(rec):
    """(truth text, expected finding or None) from a recording's answer-key fields."""
    if rec.get("condition") == "healthy":
        return "healthy", "none"
    loc = rec.get("fault_location") or rec.get("fault") or rec.get("fault_type") or "fault"
    size = rec.get("fault_diameter_in")
    text = loc.split(" (")[0] + (f" {size} in" if size else "")
    return text, MATCH.get(loc.split(" ")[0])


def load_of(rec):
    return next((rec[k] for k in LOAD_KEYS if rec.get(k) is not None), None)


def jobs_of(folders):
    """Every (mode, path, baseline, is_baseline) job with its answer key and label."""
    jobs, keys = [], {}
    for folder in folders:
        meta = json.loads((folder / "metadata.json").read_text())
        recs = meta["recordings"]
        healthy = [r for r in recs if r.get("condition") == "healthy"]
        for r in recs:
            p = folder / r["file"]
            jobs.append(("free", p, None, False))
            keys[("free", str(p), None)] = truth_of(r) + ("",)
            for h in healthy:
                if load_of(h) != load_of(r):
                    label = f"across loads ({load_of(h)} → {load_of(r)})"
                else:
                    label = "second half" if r is h else "same load"
                jobs.append(("machine", p, folder / h["file"], r is h))
                keys[("machine", str(p), str(folder / h["file"]))] = truth_of(r) + (label,)
    return jobs, keys


def row(name, c, truth, expected, label):
    disc = ", ".join(f"{d['feature']} z {d['z']:+.1f}" for d in c["discrepancies"][:3])
    comp = f" ({c['component']})" if c["component"] else ""
    ranked = ", ".join(f"{r['name']} {r['delta_chi2']:.0f}" for r in c["causes"][:3])
    ties = ", ".join(t["name"] for t in c.get("near_ties", []))
    g = c["gain"]
    match = "–" if expected is None else (
        "yes" if c["finding"] == expected else
        "no fault named" if c["finding"] in ("none", "unexplained") else "no")
    if expected == "none":
        match = "yes" if c["finding"] == "none" else (
            "unexplained" if c["finding"] == "unexplained" else "false alarm")
    base = f"{c['baseline']} ({label})" if c["baseline"] else c["mode"]
    return (f"| {name} | {base} | {disc} | **{c['finding']}**{comp}"
            f"{' (near tie: ' + ties + ')' if ties else ''} | {c['words']} | {ranked} | "
            f"{c['chi2_per_feature']:.2f} | {g['before']:.2f} → {g['after']:.2f} | "
            f"{c['wall_s']:.0f} | {truth} | {match} |")


def summary(results, keys, folders):
    lines = ["| dataset | mode | faults named right | bearing on the drive end | "
             "wrong cause | nothing / unexplained | healthy: no finding |",
             "|---|---|---|---|---|---|---|"]
    for folder in folders:
        for mode in ("machine", "free"):
            for scope in (("same load", "second half"), ("across loads",)):
                rows = [(c, keys[k]) for k, c in results.items()
                        if k[0] == mode and Path(k[1]).parent == folder
                        and (mode == "free" or keys[k][2].startswith(scope))]
                if mode == "free" and scope != ("same load", "second half"):
                    continue
                if not rows:
                    continue
                faulty = [(c, t) for c, t in rows if t[1] not in (None, "none")]
                healthy = [(c, t) for c, t in rows if t[1] == "none"]
                right = [c for c, t in faulty if c["finding"] == t[1]]
                de = [c for c in right if c["component"] in (None, "drive_end")]
                wrong = [c for c, t in faulty if c["finding"] not in (t[1], "none",
                                                                       "unexplained")]
                nothing = [c for c, t in faulty if c["finding"] in ("none", "unexplained")]
                ok = [c for c, t in healthy if c["finding"] == "none"]
                name = {"machine": "calibrated" + (", across loads"
                                                    if scope == ("across loads",) else ""),
                        "free": "calibration-free"}[mode]
                lines.append(f"| {folder.name} | {name} | {len(right)} of {len(faulty)} | "
                             f"{len(de)} | {len(wrong)} | {len(nothing)} | "
                             f"{len(ok)} of {len(healthy)} |")
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--data", type=Path, default=data_root())
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--modes", nargs="+", choices=("machine", "free"),
                    default=("machine", "free"), help="the nominal models to run")
    ap.add_argument("--datasets", nargs="+", default=None,
                    help="folder names under --data (default every folder with metadata)")
    ap.add_argument("--reuse-machines", action="store_true",
                    help=f"read the machine files an earlier run left in {MACHINE_DIR} "
                         "instead of calibrating again")
    ap.add_argument("--channel", default=None,
                    help="read every record on this channel (CWRU's FE: the drive-end faults "
                         "through the fan-end accelerometer); default each record's own")
    ap.add_argument("--render", type=Path, default=None,
                    help="only re-render the tables from a --json file of an earlier run")
    a = ap.parse_args(argv)
    folders = sorted(p for p in a.data.iterdir() if (p / "metadata.json").is_file()
                     and (a.datasets is None or p.name in a.datasets))
    jobs, keys = jobs_of(folders)
    jobs = [j for j in jobs if j[0] in a.modes]
    if a.render:
        results = json.loads(a.render.read_text())
    else:
        t0 = time.perf_counter()
        results = {}
        MACHINE_DIR.mkdir(parents=True, exist_ok=True)
        with ProcessPoolExecutor(a.workers) as pool:
            baselines = sorted({str(j[2]) for j in jobs if j[2] is not None})
            machines = {}
            for base, file, wall in pool.map(calibrate_half, [(b, a.reuse_machines, a.channel)
                                                              for b in baselines]):
                machines[base] = file
                print(f"calibrated {Path(base).name} (first half) in {wall:.1f} s", flush=True)
            jobs = [(*j, a.channel, None if j[2] is None else machines[str(j[2])])
                    for j in jobs]
            # the path-free comparisons (10-30 s each) first, the machine's (0.2-2 s) after:
            # the short ones fill the workers' ends instead of one long one running alone
            jobs.sort(key=lambda j: j[0] != "free")
            t1 = time.perf_counter()
            for key, c in pool.map(one, jobs):
                results[key] = c
                print(key, c["finding"], c["component"], f"{c['wall_s']:.1f} s", flush=True)
        t2 = time.perf_counter()
        print(f"total {t2 - t0:.0f} s on {a.workers} workers: calibrations {t1 - t0:.0f} s, "
              f"comparisons {t2 - t1:.0f} s ({len(jobs)} records)")
    if a.json and not a.render:
        a.json.write_text(json.dumps(results, indent=1, default=float))
    res = {}
    for key, c in results.items():
        mode, path, base = key.split("|")
        res[(mode, path, None if base == "None" else base)] = c
    lines = ["## Summary", ""] + summary(res, keys, folders)
    for folder in folders:
        lines += [f"\n### {folder.name}\n",
                  "| recording | nominal model | largest departures (z) | finding | in words "
                  "| top causes (Δχ² on their signature) | χ²/feature | held-out χ²/feature "
                  "before → after | wall s | truth | match |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for mode in ("machine", "free"):
            for (m, p, b), c in res.items():
                if m == mode and Path(p).parent == folder:
                    truth, expected, label = keys[(m, p, b)]
                    lines.append(row(Path(p).name, c, truth, expected, label))
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        a.out.write_text(text)


if __name__ == "__main__":
    main()
