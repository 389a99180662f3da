"""Hidden effects in real data, and what a sensor can see (issue 16, item 7).

A machine is calibrated on the first half of a real healthy record (CWRU ``normal_0``,
SpectraQuest ``h30hz0``: ``cmsim calibrate`` with its signature library); into the
**held-out second half**, which no calibration saw, cmsim-simulated faults are injected
through the machine's path (:func:`cmsim.machine.change.apply_change`: the fault's model run
against the healthy run of the same seed, laid on the real segments) over a size grid, each
size ``--trials`` times with other model seeds (cage phases, slip) and noise draws; ``cmsim
compare --machine`` must name each. The untouched held-out half must read ``none``.

It prints, per machine and fault, the share named right at each size, the smallest size
named ``--trials`` × 0.9 times or more (the detectability), and the share named among the
injections that raise the fault's family by 6 dB or more and 3 σ over the baseline's own
level (its envelope lines or sidebands, the path-free features of its family, read by the
comparison). ``--plot`` draws the named share against the size.

Run: ``python benchmarks/bench_detectability.py [--data DIR] [--trials 10] [--workers 2]
[--machines cwru spectraquest] [--json OUT] [--plot PNG] [--markdown OUT]``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from cmsim.discrepancy import CAUSES, compare                       # noqa: E402
from cmsim.discrepancy.causes import ModelSetup                     # noqa: E402
from cmsim.discrepancy.evaluator import path_free                   # noqa: E402
from cmsim.discrepancy.judge import judge, standing_out             # noqa: E402
from cmsim.discrepancy.machine_checks import detectability          # noqa: E402
from cmsim.discrepancy.signatures import build_library, change_of   # noqa: E402
from cmsim.machine import calibrate, model_force                    # noqa: E402
from cmsim.machine.change import apply_change                       # noqa: E402
from cmsim.measured import data_root, read_record, record_from_run  # noqa: E402
from cmsim.run import Run, signal_info                              # noqa: E402

#: Machines: (name, dataset folder, healthy record, channel or None, faults injected).
MACHINES = {
    "cwru": ("cwru_bearing_12k_de", "normal_0.npz", "DE",
             ("bearing_outer_race", "bearing_inner_race", "bearing_ball")),
    "spectraquest": ("spectraquest_gearbox_gfd", "h30hz0.npz", None,
                     ("tooth_fault", "eccentricity", "bearing_outer_race",
                      "bearing_inner_race")),
}

#: Sizes injected per cause parameter kind (log-spaced), SI.
SIZES = {"size_m": np.geomspace(3e-5, 1.5e-3, 7), "lost_height_m": np.geomspace(1e-4, 3e-3, 7),
         "amplitude_m": np.geomspace(4e-6, 1.5e-4, 7)}

#: Share of trials named for a size to count as seen.
SEEN = 0.9

#: A family raised this much over the baseline's own level (dB) must be named.
FAMILY_RISE_DB = 6.0


def halves(folder, name, channel):
    rec = read_record(Path(folder) / name, channel=channel)
    d = rec.signal.size / rec.fs_hz
    return rec.span(0.0, d / 2), rec.span(d / 2)


def machine_of(key, data):
    folder, name, channel, _ = MACHINES[key]
    first, held = halves(Path(data) / folder, name, channel)
    t0 = time.perf_counter()
    m = calibrate([first])
    m = m.with_library(build_library(m))
    return m, held, time.perf_counter() - t0


def inject(machine, held, cause, component, value, seed):
    """The held-out half with ``cause`` at ``value`` laid on it (model seed ``seed``)."""
    n = int(round(machine.segment_s * held.fs_hz))
    k = held.signal.size // n
    segs = held.signal[:k * n].reshape(k, n).astype(float)
    nominal = ModelSetup(rig=machine.rig, op=machine.op, machine=machine)
    setup = cause.extend(nominal, {**cause.start(machine.rig), cause.params[0].name: value},
                         component)

    def force_of(st):
        return model_force(st.rig, st.op, machine.model_signal, machine.fs_hz, k * n /
                           machine.fs_hz, seed, faults=st.faults,
                           mixed_friction=st.mixed_friction)

    change = change_of(setup, nominal, force_of, machine.fs_hz, seed)
    y = apply_change(machine, segs, change, np.random.default_rng([seed, 77])).ravel()
    run = Run(np.arange(y.size) / held.fs_hz, {held.channel: y}, {"fs_hz": held.fs_hz},
              source="measured")
    return record_from_run(run, held.channel, held.rig, held.op,
                           model_signal=held.model_signal, components=dict(held.components),
                           unit_scale=held.unit_scale)


def family_rise(res, cause, component):
    """(largest rise in dB over the baseline of the cause's path-free family features,
    largest rise of those that stand out over it as the judge reads a family: 3 σ and 6 dB,
    :func:`~cmsim.discrepancy.judge.standing_out`): a rise within a noisy feature's own
    spread is no rise of the family."""
    fam = set(CAUSES[cause]().family([d["feature"] for d in res["discrepancies"]], component))
    mine = [d for d in res["discrepancies"]
            if d["feature"] in fam and path_free(d["feature"]) and d["feature"].endswith("_db")]
    meas, ref, sigma = (np.array([d[k] for d in mine], dtype=float)
                        for k in ("measured", "simulated", "sigma"))
    rise = meas - ref
    out = standing_out(range(len(mine)), meas, ref, sigma, [d["feature"] for d in mine])
    return float(max(rise, default=0.0)), float(max(rise[out], default=0.0))


def _job(args):
    key, data, trials = args
    machine, held, cal_s = machine_of(key, data)
    sensor = signal_info(machine.model_signal).component
    rows = []
    c0 = compare(held, machine=machine)
    rows.append({"machine": key, "cause": None, "finding": c0.finding, "wall_s": c0.wall_s})
    for name in MACHINES[key][3]:
        cause = CAUSES[name]()
        comps = [sensor] if cause.kind == "bearing" else cause.components(machine.rig, sensor)
        pname = cause.params[0].name
        for comp in comps:
            for value in SIZES[pname]:
                for t in range(trials):
                    rec = inject(machine, held, cause, comp, float(value), 1000 + 37 * t)
                    r = judge(rec, machine, refine=0)
                    got = (r["finding"], None if r["cause"] is None
                           else r["cause"]["component"])
                    rows.append({"machine": key, "cause": name, "component": comp,
                                 "value": float(value), "trial": t, "finding": got[0],
                                 "named": got == (name, comp) or (
                                     got[0] == name and cause.kind is None),
                                 **dict(zip(("family_rise_db", "family_out_db"),
                                            family_rise(r, name, comp))),
                                 "wall_s": r["wall_s"]})
    det = detectability(machine)
    return {"machine": key, "calibration_s": cal_s, "rows": rows,
            "library_detectability": det, "fs_hz": machine.fs_hz,
            "components": dict(machine.components)}


def summarise(results, trials):
    lines = ["| machine | fault | where | named at each size (of %d) | seen from (9 in 10) | "
             "library's estimate | named where the family stood out (≥ 6 dB and ≥ 3 σ) |"
             % trials,
             "|---|---|---|---|---|---|---|"]
    for res in results:
        key, rows = res["machine"], res["rows"]
        untouched = [r for r in rows if r["cause"] is None]
        est = {(d["cause"], d["component"]): d["smallest"]
               for d in res["library_detectability"]}
        for (cause, comp) in sorted({(r["cause"], r["component"]) for r in rows
                                     if r["cause"]}):
            mine = [r for r in rows if r["cause"] == cause and r["component"] == comp]
            values = sorted({r["value"] for r in mine})
            share = {v: sum(r["named"] for r in mine if r["value"] == v) for v in values}
            seen = next((v for v in values if share[v] >= SEEN * trials
                         and all(share[w] >= SEEN * trials for w in values if w > v)), None)
            k = 1e3 if CAUSES[cause]().params[0].name.endswith("_m") else 1.0
            unit = " mm" if k == 1e3 else ""
            raised = [r for r in mine if r.get("family_out_db", r["family_rise_db"])
                      >= FAMILY_RISE_DB]
            rose = [r for r in mine if r["family_rise_db"] >= FAMILY_RISE_DB]
            rate = (f"{sum(r['named'] for r in raised)} of {len(raised)}" if raised else "-")
            if len(rose) != len(raised):
                rate += (f" ({sum(r['named'] for r in rose)} of {len(rose)} counting rises "
                         "within the feature's spread)")
            cells = ", ".join(f"{k * v:.2g}: {share[v]}" for v in values)
            e = est.get((cause, comp))
            where = res["components"].get(comp, comp) if comp else "-"
            lines.append(f"| {key} | {cause} | {where} | {cells} | "
                         f"{'-' if seen is None else f'{k * seen:.2g}{unit}'} | "
                         f"{'-' if e is None else f'{k * e:.2g}{unit}'} | {rate} |")
        lines.append(f"| {key} | untouched held-out half | - | "
                     f"{', '.join(r['finding'] for r in untouched)} | | | |")
    return lines


def plot(results, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(results), figsize=(5.5 * len(results), 4), squeeze=False)
    for ax, res in zip(axes[0], results):
        rows = [r for r in res["rows"] if r["cause"]]
        for cause, comp in sorted({(r["cause"], r["component"]) for r in rows}):
            mine = [r for r in rows if r["cause"] == cause and r["component"] == comp]
            values = sorted({r["value"] for r in mine})
            k = 1e3 if CAUSES[cause]().params[0].name.endswith("_m") else 1.0
            share = [np.mean([r["named"] for r in mine if r["value"] == v]) for v in values]
            where = res["components"].get(comp, comp) if comp else ""
            ax.semilogx([k * v for v in values], share, "o-",
                        label=f"{cause.replace('_', ' ')} {where}".strip())
        ax.axhline(SEEN, color="k", lw=0.6, ls="--")
        ax.set_title(f"{res['machine']}: faults injected into the held-out healthy half")
        ax.set_xlabel("size, mm (eccentricity: mm of run-out)")
        ax.set_ylabel("share named by compare --machine")
        ax.set_ylim(-0.05, 1.05)
        ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=data_root())
    ap.add_argument("--trials", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--machines", nargs="+", choices=sorted(MACHINES),
                    default=sorted(MACHINES))
    ap.add_argument("--json", type=Path)
    ap.add_argument("--plot", type=Path)
    ap.add_argument("--markdown", type=Path)
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    with ProcessPoolExecutor(a.workers) as pool:
        results = list(pool.map(_job, [(k, a.data, a.trials) for k in a.machines]))
    lines = summarise(results, a.trials)
    print("\n".join(lines))
    for res in results:
        walls = [r["wall_s"] for r in res["rows"] if r.get("wall_s") is not None]
        print(f"{res['machine']}: calibration with the library {res['calibration_s']:.0f} s; "
              f"comparison {np.median(walls):.2f} s median, {max(walls):.2f} s max")
    print(f"total {time.perf_counter() - t0:.0f} s")
    if a.json:
        a.json.write_text(json.dumps(results, indent=1, default=float))
    if a.markdown:
        a.markdown.write_text("\n".join(lines) + "\n")
    if a.plot:
        plot(results, a.plot)


if __name__ == "__main__":
    main()
