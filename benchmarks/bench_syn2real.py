"""Sim-to-real benchmark (issues 15, 25): train on cmsim data only, test on the real CWRU and
MFPT records of ../shared/datasets; mean ± std over seeds of the generation and training; the
ablation (transfer-path randomisation, load zone, slip, defect edge profile removed in turn;
and a ball pit anywhere on the ball with a wandering spin axis added); and the CWRU set made
through a machine calibrated on the first half of the healthy record, the only real data it
sees (``machine``: its windows are left out of the test), with the ball's pit anywhere on the
ball and a wandering spin axis (``machine+spin_axis_wander``) and with the spec's fixed axis.

    python benchmarks/bench_syn2real.py [--seeds 10] [--records 160] [--ablation-seeds 3]
        [--mfpt-seeds 5] [--mfpt-records 60] [--workers 2] [--cache DIR] [--json OUT]
        [--skip cwru ablation mfpt machine]

Datasets are generated once per (variant, seed) into ``--cache`` (resumable) and reused.
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from cmsim.datasets import DatasetSpec, generate_dataset         # noqa: E402
from cmsim.datasets.spec_toml import through_machine                # noqa: E402
from cmsim.measured import data_root                            # noqa: E402
from cmsim.diagnostics.syn2real import evaluate_syn2real, measured_windows  # noqa: E402


def ablate(data, variant):
    """Spec dict with one piece of physics / randomisation removed (or added); variants
    joined by ``+`` are applied in turn (``machine+spin_axis_wander``)."""
    d = copy.deepcopy(data)
    for v in variant.split("+"):
        d = _ablate_one(d, v)
    return d


def _ablate_one(d, variant):
    if variant == "no_transfer_randomisation":
        d["nuisances"].pop("housing_mode_hz", None)
        d["nuisances"].pop("housing_damping", None)
    elif variant == "no_load_zone":
        d["operating"]["radial_load_n"] = 0.0
    elif variant == "no_slip":
        d["nuisances"]["slip"] = 0.0
    elif variant == "no_defect_profile":
        for t in d["faults"]["types"]:
            t.pop("exit_ramp_fraction", None)
    elif variant == "spin_axis_wander":
        # added physics, not a removal: the ball's pit anywhere on the ball (sine of its
        # latitude uniform) and a wandering spin axis (correlation time 0.05-5 s)
        for t in d["faults"]["types"]:
            if t["type"] == "ball":
                t["axis_offset"] = {"distribution": "uniform", "min": -1.0, "max": 1.0}
                t["wander_s"] = {"distribution": "loguniform", "min": 0.05, "max": 5.0}
    elif variant == "machine":
        # the housing path, sensor noise and channel are the machine's
        d = through_machine(d, MACHINE_FILE)
        d["dataset"]["name"] += "_machine"
    elif variant != "full":
        raise ValueError(variant)
    return d


#: Where the benchmark writes the machine calibrated on CWRU normal_0's first half.
MACHINE_FILE = Path.home() / ".cache" / "cmsim-syn2real" / "cwru_normal_0_first_half.toml"

#: The part of the healthy CWRU record the machine is calibrated on, s.
CALIBRATION_SPAN_S = (0.0, 5.0)


def calibrate_cwru(folder):
    """Calibrate the CWRU machine on the first half of normal_0 (MACHINE_FILE)."""
    from cmsim.machine import calibrate
    from cmsim.measured import read_record
    rec = read_record(Path(folder) / "normal_0.npz")
    machine = calibrate([rec.span(*CALIBRATION_SPAN_S)])
    MACHINE_FILE.parent.mkdir(parents=True, exist_ok=True)
    machine.save(MACHINE_FILE)
    return machine


def without_calibration_windows(ws, record="normal_0"):
    """The test windows less those of the calibration span of ``record``."""
    import numpy as np
    from cmsim.diagnostics.syn2real import WindowSet
    keep = np.ones(len(ws), dtype=bool)
    idx = np.flatnonzero(ws.groups == f"real:{record}")
    win = ws.x.shape[1]
    for k, i in enumerate(idx):
        start = k * win / ws.fs_hz
        if start < CALIBRATION_SPAN_S[1] and start + win / ws.fs_hz > CALIBRATION_SPAN_S[0]:
            keep[i] = False
    return WindowSet(ws.x[keep], ws.y[keep], ws.groups[keep], ws.orders[keep],
                     ws.shaft_hz[keep], ws.fs_hz)


def make(spec_path, variant, seed, records, cache, workers):
    data = tomllib.loads(Path(spec_path).read_text())
    data = ablate(data, variant)
    data["dataset"]["seed"] = int(data["dataset"]["seed"]) + 1000 * seed
    data["dataset"]["records"] = records
    spec = DatasetSpec.from_dict(data, base_dir=Path(spec_path).parent)
    out = Path(cache) / f"{spec.name}_{variant}_s{seed}_n{records}"
    t = time.perf_counter()
    s = generate_dataset(spec, out, workers=workers)
    return out, time.perf_counter() - t, s.records_written


def run(spec, test_folder, variant, seeds, records, cache, workers, classifiers, log,
        channel=None):
    dirs, gen_s, written = [], 0.0, 0
    for k in range(seeds):
        d, t, w = make(spec, variant, k, records, cache, workers)
        dirs.append(d)
        gen_s += t
        written += w
    test = measured_windows(test_folder, channel=channel)
    if "machine" in variant.split("+"):
        test = without_calibration_windows(test)
    out = {"variant": variant, "seeds": seeds, "records": records,
           "generation_s": gen_s, "records_written": written}
    for clf in classifiers:
        t = time.perf_counter()
        res = evaluate_syn2real(dirs, test_folder, clf, test=test, channel=channel,
                                test_channel=channel)
        res["wall_s"] = time.perf_counter() - t
        out[clf] = res
        ba = res["balanced_accuracy"]
        log(f"{Path(spec).stem} {variant} {clf}: balanced {100 * ba['mean']:.1f} +- "
            f"{100 * ba['std']:.1f} %, recall " + ", ".join(
                f"{c} {100 * v['mean']:.0f}" for c, v in res["per_class_recall"].items())
            + f", macro-AUROC {100 * res['macro_auroc']['mean']:.1f}"
            + (f" (gen {gen_s:.0f} s for {written} new records)" if written else ""))
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=10)
    p.add_argument("--records", type=int, default=160)
    p.add_argument("--ablation-seeds", type=int, default=3)
    p.add_argument("--mfpt-seeds", type=int, default=5)
    p.add_argument("--mfpt-records", type=int, default=60)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--cache", default=str(Path.home() / ".cache" / "cmsim-syn2real"))
    p.add_argument("--json", default=None)
    p.add_argument("--skip", nargs="*", default=[],
                   choices=["cwru", "ablation", "mfpt", "machine"])
    a = p.parse_args(argv)

    def log(msg):
        print(msg, flush=True)

    root = data_root()
    res = {}
    cwru = ROOT / "datasets" / "cwru_syn2real.toml"
    if "cwru" not in a.skip:
        res["cwru"] = run(cwru, root / "cwru_bearing_12k_de", "full", a.seeds, a.records,
                          a.cache, a.workers, ("envelope", "forest", "logistic"), log)
    if "machine" not in a.skip:
        calibrate_cwru(root / "cwru_bearing_12k_de")
        # the ball's pit anywhere on the ball with a wandering spin axis, and the spec's
        # fixed axis on the rolling track beside it
        res["cwru_machine"] = {v: run(cwru, root / "cwru_bearing_12k_de", v, a.seeds,
                                      a.records, a.cache, a.workers,
                                      ("envelope", "forest", "logistic"), log, channel="DE")
                               for v in ("machine+spin_axis_wander", "machine")}
    if "ablation" not in a.skip:
        res["ablation"] = [run(cwru, root / "cwru_bearing_12k_de", v, a.ablation_seeds,
                               a.records, a.cache, a.workers, ("forest", "logistic"), log)
                           for v in ("no_transfer_randomisation", "no_load_zone", "no_slip",
                                     "no_defect_profile", "spin_axis_wander")]
    if "mfpt" not in a.skip:
        res["mfpt"] = run(ROOT / "datasets" / "mfpt_syn2real.toml", root / "mfpt_bearing",
                          "full", a.mfpt_seeds, a.mfpt_records, a.cache, a.workers,
                          ("envelope", "forest", "logistic"), log)
    if a.json:
        Path(a.json).write_text(json.dumps(res, indent=1, default=str))


if __name__ == "__main__":
    main()
