"""Records per hour against batch size; `cmsim dataset` against the one-record bound (issue 49).

python benchmarks/bench_batch.py [--spec datasets/gear_faults.toml] [--records N]
                                 [--sizes 1,8,16,32,64] [--rounds R] [--command]
                                 [--plot docs/img/records_per_batch.png] [--json FILE]

Prints, all measured in this one run, rounds interleaved so every figure meets the same
machine load (the machine is shared: the ratios carry, the absolute figures do not):

1. the CPU (model name, cores, load average) and the SIMD width numba's LLVM uses for the
   batch kernel's loops over the records (a probe compiled here: zmm = 512-bit, 8 float64
   lanes; ymm = 256-bit);
2. the one-record bound: ``cmsim simulate`` of the spec's rig at its sample rate, 1 s,
   ``--sensors`` (a fresh process), the integration's wall time from its JSON; records per
   hour if 2 workers did nothing but that integration, one record at a time;
3. ``generate_dataset(spec, batch_size=B, workers=2)`` for each batch size B in a fresh
   process (start-up, imports, kernel loading and the manifest included): wall time,
   records per hour, its ratio to the bound, the CPU per record of the process and its
   workers with the bound's ratio to it (what the wall ratio is on 2 idle cores: on a
   shared machine the wall figures carry the other processes' load), and the peak resident
   memory of the largest worker (``getrusage``); B = 1 is each record alone on the
   single-run kernel (the reference), B > 1 the batch kernel (``cmsim.dynamics.batch``);
4. with ``--command``: ``cmsim dataset SPEC --workers 2`` itself on the spec as shipped (its
   own record count, its default batch size), as a user runs it, against the bound.

With ``--machine BASELINE`` (a healthy record, e.g. CWRU's ``normal_0.npz`` under
``CMSIM_DATA``), the spec is made machine-calibrated first: a machine is calibrated on the
record (:func:`cmsim.machine.calibrate`, no library: a dataset needs none) into the temporary
folder, and the spec's ``[rig]`` replaced by ``[machine] file`` (without the settings the
machine owns, its channel the machine's). No machine file ships: it holds the baseline's
samples.

``--plot`` draws records per hour against batch size with the bound (docs/benchmarks.md).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_dataset import cpu_info, simd_width  # noqa: E402  (one CPU description)

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}

#: A child process: one dataset run; prints its wall time and its workers' peak memory.
GENERATE = r"""
import json, resource, sys, time
t0 = time.perf_counter()
from cmsim.datasets import DatasetSpec, generate_dataset
from cmsim.datasets.spec_toml import read_toml
raw = read_toml(sys.argv[1])
raw["dataset"]["records"] = int(sys.argv[3])
spec = DatasetSpec.from_dict(raw, base_dir=__import__("pathlib").Path(sys.argv[1]).parent)
s = generate_dataset(spec, sys.argv[2], workers=2, batch_size=int(sys.argv[4]))
me, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
print(json.dumps({"wall_s": time.perf_counter() - t0, "failed": s.records_failed,
                  "cpu_s": me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime,
                  "worker_rss_kb": kids.ru_maxrss}))
"""


def machine_spec(spec_path, baseline, tmp):
    """The spec ``spec_path`` through a machine calibrated on ``baseline`` (module docstring):
    the path of the spec written in ``tmp``."""
    import tomli_w

    from cmsim.datasets.spec_toml import MACHINE_OWNS, read_toml
    from cmsim.machine import calibrate
    from cmsim.measured import read_record
    machine = calibrate([read_record(baseline)])
    machine.save(Path(tmp) / "machine.toml")
    raw = read_toml(spec_path)
    raw.pop("rig", None)
    raw["machine"] = {"file": "machine.toml"}
    raw["dataset"]["name"] = f"{raw['dataset']['name']}_machine"
    for name in MACHINE_OWNS:
        raw.get("nuisances", {}).pop(name, None)
    raw.setdefault("sensor", {})["channels"] = [machine.channel]
    out = Path(tmp) / "machine_spec.toml"
    out.write_text(tomli_w.dumps(raw))
    return out


def spec_rig_args(spec_path, tmp):
    """``cmsim simulate`` options of the spec's rig and sample rate at a middle operating
    point (the one-record bound's run)."""
    from cmsim.datasets import DatasetSpec
    spec = DatasetSpec.load(spec_path)
    rig_file = Path(tmp) / "rig.toml"
    spec.rig.save(rig_file)
    op = spec.record_operating_point(spec.record(0))
    args = ["--rig", str(rig_file), "--speed-rpm", f"{op.speed_rpm:g}",
            "--fs-hz", f"{spec.fs_hz:g}", "--duration-s", f"{spec.duration_s:g}", "--sensors"]
    if spec.rig.gears is not None:
        args += ["--torque-nm", f"{op.torque_nm:g}"]
    else:
        args += ["--radial-load-n", f"{op.radial_load_n:g}"]
    return args, spec


def bound_run(args, tmp):
    """One ``cmsim simulate`` (fresh process): its integration wall time, s."""
    done = subprocess.run([sys.executable, "-m", "cmsim", "simulate", *args, "--json", "--out",
                           str(Path(tmp) / "bound.npz")], capture_output=True, text=True,
                          env=ENV, check=True)
    return float(json.loads(done.stdout)["wall_s"])


def generate_run(spec_path, records, batch, tmp):
    """One dataset run in a fresh process: ``(wall s, peak RSS of the largest worker MiB,
    CPU s of the process and its workers)``."""
    out = tempfile.mkdtemp(dir=tmp)
    done = subprocess.run([sys.executable, "-c", GENERATE, str(spec_path), str(Path(out) / "ds"),
                           str(records), str(batch)], capture_output=True, text=True, env=ENV)
    if done.returncode != 0:
        raise SystemExit(f"generate_dataset failed: {done.stderr[-2000:]}")
    res = json.loads(done.stdout.strip().splitlines()[-1])
    assert res["failed"] == 0
    return res["wall_s"], res["worker_rss_kb"] / 1024.0, res["cpu_s"]


def command_run(spec_path, tmp):
    """``cmsim dataset SPEC --workers 2`` as shipped (fresh process): ``(wall s, records)``."""
    out = Path(tempfile.mkdtemp(dir=tmp)) / "ds"
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "cmsim", "dataset", str(spec_path), "--out",
                           str(out), "--workers", "2", "--json"], capture_output=True,
                          text=True, env=ENV)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        raise SystemExit(f"cmsim dataset failed ({done.returncode}): {done.stderr[-2000:]}")
    summary = json.loads(done.stdout)
    assert summary["records_failed"] == 0
    return wall, summary["records_total"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spec", default=str(ROOT / "datasets" / "gear_faults.toml"))
    ap.add_argument("--records", type=int, default=128,
                    help="records of each batch-size run (default 128)")
    ap.add_argument("--sizes", default="1,8,16,32,64")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--command", action="store_true",
                    help="also run `cmsim dataset SPEC` on the spec as shipped")
    ap.add_argument("--machine", metavar="BASELINE",
                    help="make the spec machine-calibrated on this healthy record first")
    ap.add_argument("--plot", type=Path)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    name, cores, load = cpu_info()
    width = simd_width()
    print(f"CPU: {name}, {cores} cores usable; load average {load[0]:.2f} {load[1]:.2f} "
          f"{load[2]:.2f}")
    print(f"SIMD: {width}")
    res = {"cpu": name, "cores": cores, "load": load, "simd": width,
           "spec": Path(args.spec).name, "records": args.records, "sizes": sizes}
    with tempfile.TemporaryDirectory(prefix="bench_batch_") as tmp:
        if args.machine:
            args.spec = str(machine_spec(args.spec, args.machine, tmp))
            res["machine"] = args.machine
        rig_args, spec = spec_rig_args(args.spec, tmp)
        bound_run(rig_args, tmp)                           # warm: kernels from the cache
        generate_run(args.spec, 4, 2, tmp)
        bounds, walls, cpus, rss, commands = [], {b: [] for b in sizes}, {b: [] for b in sizes}, \
            {}, []
        for _ in range(args.rounds):                       # interleaved rounds
            bounds.append(bound_run(rig_args, tmp))
            for b in sizes:
                w, m, c = generate_run(args.spec, args.records, b, tmp)
                walls[b].append(w)
                cpus[b].append(c)
                rss[b] = max(rss.get(b, 0.0), m)
            if args.command:
                commands.append(command_run(args.spec, tmp))
        bound = float(np.median(bounds))
        per_hour_bound = 2 * 3600.0 / bound
        print(f"\none-record bound: cmsim simulate {' '.join(rig_args[2:])}: integration "
              f"{bound * 1e3:.0f} ms (median of {len(bounds)}: "
              f"{', '.join(f'{b * 1e3:.0f}' for b in bounds)}) -> {per_hour_bound:.0f} "
              f"records/hour on 2 workers")
        print(f"\ngenerate_dataset, {args.records} records of {spec.name}, 2 workers, fresh "
              f"process (median of {args.rounds} rounds, interleaved):")
        print("  (CPU: the process and its workers, per record; the CPU ratio is the bound over "
              "it, what the wall ratio is on 2 idle cores)")
        print(f"  {'batch':>5} {'wall s':>8} {'records/h':>10} {'ratio':>6} {'CPU ms/rec':>11} "
              f"{'CPU ratio':>9} {'worker MiB':>11}")
        rows = []
        for b in sizes:
            w = float(np.median(walls[b]))
            cpu_rec = float(np.median(cpus[b])) / args.records
            rate = 3600.0 * args.records / w
            rows.append({"batch": b, "wall_s": w, "walls_s": walls[b], "records_per_hour": rate,
                         "ratio_to_bound": rate / per_hour_bound, "worker_rss_mib": rss[b],
                         "cpu_per_record_s": cpu_rec, "cpus_s": cpus[b],
                         "cpu_ratio_to_bound": bound / cpu_rec,
                         "cpu_records_per_hour": 2 * 3600.0 / cpu_rec})
            print(f"  {b:>5} {w:8.1f} {rate:10.0f} {rate / per_hour_bound:6.2f} "
                  f"{cpu_rec * 1e3:11.1f} {bound / cpu_rec:9.2f} {rss[b]:11.0f}")
        res.update(bound_wall_s=bound, bounds_s=bounds, bound_per_hour=per_hour_bound,
                   rows=rows)
        if commands:
            w = float(np.median([c[0] for c in commands]))
            n = commands[0][1]
            rate = 3600.0 * n / w
            print(f"\ncmsim dataset {Path(args.spec).name} ({n} records, 2 workers, start-up "
                  f"included; median of {len(commands)}): wall {w:.1f} s -> {rate:.0f} "
                  f"records/hour, ratio to the bound {rate / per_hour_bound:.2f}   "
                  f"[targets: >= 0.8, then >= 100000 records/hour]")
            res["command"] = {"wall_s": w, "walls_s": [c[0] for c in commands], "records": n,
                              "records_per_hour": rate, "ratio_to_bound": rate / per_hour_bound}
    if args.json:
        args.json.write_text(json.dumps(res, indent=1, default=float))
    if args.plot:
        plot(res, args.plot)
    return 0


def plot(res, path):
    """Records per hour against batch size, with the one-record bound."""
    from cmsim.spectra.plots import agg_figure
    fig = agg_figure((6.4, 3.8))
    ax = fig.add_subplot(1, 1, 1)
    rows = res["rows"]
    b = [r["batch"] for r in rows]
    ax.plot(b, [r["records_per_hour"] for r in rows], "-o", color="C0",
            label="generate_dataset, 2 workers, wall (1 = each record alone)")
    if all("cpu_records_per_hour" in r for r in rows):
        ax.plot(b, [r["cpu_records_per_hour"] for r in rows], "--s", color="C1",
                label="the same in CPU: records per hour on 2 idle cores")
    ax.axhline(res["bound_per_hour"], color="C3", ls="--",
               label="one-record bound (integration alone, 2 workers)")
    if "command" in res:
        ax.axhline(res["command"]["records_per_hour"], color="C2", ls=":",
                   label="cmsim dataset as shipped")
    ax.set_xscale("log", base=2)
    ax.set_xticks(b)
    ax.set_xticklabels([str(x) for x in b])
    ax.set_xlabel("records integrated together (batch size)")
    ax.set_ylabel("records per hour")
    ax.set_ylim(0, None)
    ax.set_title(f"{res['spec']}: {res['records']} one-second records\n{res['cpu']}; "
                 f"{res['simd']}", fontsize=8)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    sys.exit(main())
