"""Cost of a run with every loss on against the same run without (issue 13: <= 1.3x).

Side by side on the paper's rig at 3000 rpm, 50 N·m: resisting torques of windage, pumping
and bearing friction as ``loads`` and the mixed-lubrication ``friction_table``, against the
plain run; best of ``--repeat`` integration wall times (compilation excluded), alternated.

    python benchmarks/bench_losses.py [--duration-s 0.5] [--repeat 5] [--json]
"""

import argparse
import json
import time

from cmsim.dynamics import simulate
from cmsim.dynamics.tooth_contact import resolve_mesh
from cmsim.losses import friction_table_for, operating_losses, power_balance
from cmsim.rig import OperatingPoint, Rig


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration-s", type=float, default=0.5)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    rig, op = Rig.paper_2016(), OperatingPoint(3000.0, 50.0)
    tab = resolve_mesh(rig, None, op.torque_nm)[0]
    start = time.perf_counter()
    losses = operating_losses(rig, op, mesh_table=tab)
    mu = friction_table_for(rig, op, tab, rig.lubricant.surface_roughness_m,
                            rig.lubricant.dynamic_viscosity_pa_s)
    setup_s = time.perf_counter() - start
    kw_on = {"loads": losses.loads(), "friction_table": mu}
    best = {"off": float("inf"), "on": float("inf")}
    total = {"off": float("inf"), "on": float("inf")}
    for _ in range(args.repeat):
        for key, kw in (("off", {}), ("on", kw_on)):
            t0 = time.perf_counter()
            run = simulate(rig, op, args.duration_s, seed=1, **kw)
            total[key] = min(total[key], time.perf_counter() - t0)
            best[key] = min(best[key], run.meta["wall_s"])
    t0 = time.perf_counter()
    pb = power_balance(run, kw_on["loads"], mu, tab)
    balance_s = time.perf_counter() - t0
    out = {"duration_s": args.duration_s, "integration_off_s": best["off"],
           "integration_on_s": best["on"], "ratio_integration": best["on"] / best["off"],
           "simulate_off_s": total["off"], "simulate_on_s": total["on"],
           "ratio_simulate": (total["on"] + setup_s) / total["off"],
           "loss_setup_s": setup_s, "power_balance_s": balance_s, "closure": pb.closure}
    if args.json:
        print(json.dumps(out))
    else:
        for k, v in out.items():
            print(f"{k:>20}: {v:.4g}")
    return out


if __name__ == "__main__":
    main()
