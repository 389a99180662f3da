"""``cmsim mesh-table``: torque-dependent pair stiffness tables (paper 001 §6.1)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

from cmsim.cli.contract import CLIError, ranged
from cmsim.cli.options import add_rig_options, load_rig
from cmsim.rig import RANGES, Range


def register(sub):
    """Add the ``mesh-table`` parser."""
    p = sub.add_parser("mesh-table", help="torque-dependent pair stiffness tables",
                       description="Pair stiffness vs position on the line of action for "
                                   "each torque (paper 001 section 6.1): quasi-static orbits "
                                   "over a bearing cycle, their centroids, then one mesh cycle "
                                   "with the gear centres there.")
    loaded = Range(0.0, RANGES["torque_nm"].hi, lo_open=True, unit=RANGES["torque_nm"].unit)
    p.add_argument("--torque-nm", type=ranged(loaded), nargs="+", required=True,
                   help="output torques, N m (> 0: a table is a loaded contact)")
    p.add_argument("--method", choices=("hybrid", "potential-energy"), default="hybrid",
                   help="hybrid FE + Weber-Banaschek (default) or potential energy")
    p.add_argument("--centres", choices=("centroid", "nominal"), default="centroid",
                   help="gear centres of the mesh-cycle sweep (default: orbit centroids)")
    p.add_argument("--speed-rpm", type=ranged(RANGES["speed_rpm"]), default=1000.0,
                   help="speed of the quasi-static orbits, rpm")
    p.add_argument("--steps", type=ranged(Range(8, 100_000, integer=True)), default=120,
                   help="driving-gear angles per mesh cycle")
    p.add_argument("--out", type=Path, metavar="TABLE.npz",
                   help="write the tables (for cmsim simulate --mesh-table)")
    add_rig_options(p, friction=False)
    p.set_defaults(func=run, text=text)


def run(args):
    """Build the tables (and the FE influence coefficients, cached) and write them."""
    from cmsim.dynamics.torque_tables import torque_tables

    rig = load_rig(args)
    if rig.gears is None:
        raise CLIError(f"--rig {args.rig}: mesh-table needs a rig with gears", option="--rig")
    args.notice_compile(integrates=False)
    start = time.perf_counter()
    mesh_model = None
    cache = None
    if args.method == "hybrid":
        from cmsim.mesh_stiffness.hybrid import HybridMeshModel
        mesh_model = HybridMeshModel.from_pair(rig.gears)
        info = mesh_model.driving.meta
        cache = {"status": info.get("cache"), "key": info.get("key"),
                 "build_s": info.get("build_seconds"),
                 "load_s": time.perf_counter() - start}

    def progress(i, n, row):
        if not args.json and sys.stderr.isatty():
            print(f"  {i}/{n}: {row['torque_nm']:g} N m", file=sys.stderr)

    tables = torque_tables(rig, args.torque_nm, args.method, mesh_model=mesh_model,
                           speed_rpm=args.speed_rpm, n_steps=args.steps,
                           centres=args.centres, progress=progress)
    if args.out:
        tables.save(args.out)
    return {"method": args.method, "rig": rig.name, "centres": args.centres,
            "tables": list(tables.summary), "influence_cache": cache,
            "seconds": time.perf_counter() - start, "out": str(args.out) if args.out else None}


def text(res):
    """The tables' mean and peak-to-peak stiffness and loaded contact ratio."""
    lines = [f"{res['method']} mesh stiffness of {res['rig']} ({res['seconds']:.1f} s)",
             f"{'torque_nm':>10}  {'mean_k_N/m':>11}  {'p2p_k_N/m':>11}  {'contact_ratio':>13}"]
    for row in res["tables"]:
        lines.append(f"{row['torque_nm']:10g}  {row['mean_stiffness_n_per_m']:11.4g}  "
                     f"{row['peak_to_peak_stiffness_n_per_m']:11.4g}  "
                     f"{row['loaded_contact_ratio']:13.3f}")
    if res["out"]:
        lines.append(f"wrote {res['out']}")
    return "\n".join(lines)
