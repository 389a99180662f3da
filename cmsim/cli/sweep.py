"""``cmsim sweep``: a grid of operating points on worker processes, resumable."""

from __future__ import annotations

import sys
from pathlib import Path

from cmsim.cli.contract import CLIError, ranged
from cmsim.cli.options import (add_fault_options, add_losses_option, add_mesh_options,
                               add_rig_options, add_sampling_options, check_losses_options,
                               faults_of, load_rig, mesh_argument, number, operating_warnings,
                               prepare_tables)
from cmsim.rig import OperatingPoint, Range


def register(sub):
    """Add the ``sweep`` parser."""
    p = sub.add_parser("sweep", help="simulate a grid of operating points in parallel",
                       description="Simulate speeds × torques (× frictions × clearances) on "
                                   "worker processes; each run is saved to DIR/runs/ and "
                                   "recorded in DIR/manifest.json as it finishes. Re-running "
                                   "the same command resumes: finished runs are skipped.")
    p.add_argument("--torque-nm", type=number("torque_nm"), nargs="+",
                   help="output torques, N m (gear rigs; default 0: unloaded, the teeth may "
                        "separate)")
    p.add_argument("--radial-load-n", type=number("radial_load_n"), metavar="N",
                   help="static radial load on the rotor of a bearing rig, N (default 0)")
    p.add_argument("--speed-rpm", type=number("speed_rpm"), nargs="+", required=True,
                   help="input shaft speeds, rpm")
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="sweep directory")
    add_rig_options(p, many=True)
    add_sampling_options(p, seed_help="base seed; run i gets a seed derived from (seed, i)")
    p.add_argument("--seed-policy", default="per_run", choices=("per_run", "shared"),
                   help="per_run: independent seed per run; shared: every run uses --seed")
    p.add_argument("--workers", type=ranged(Range(1, 1024, integer=True)), default=None,
                   help="worker processes (default: number of CPUs)")
    p.add_argument("--force", action="store_true",
                   help="replace a manifest written for a different spec")
    add_mesh_options(p)
    add_fault_options(p)
    add_losses_option(p)
    p.set_defaults(func=run, text=text)


def run(args):
    """Build the sweep's spec from the options and run it."""
    from cmsim.datasets import SweepSpec, run_sweep

    rig = load_rig(args, variants=False)
    torques = args.torque_nm if args.torque_nm is not None else (
        [0.0] if rig.gears is not None else None)
    if args.torque_nm is not None and rig.gears is None:
        raise CLIError("--torque-nm needs a rig with gears (this rig has none; use "
                       "--radial-load-n)", option="--torque-nm")
    if args.radial_load_n is not None and rig.gears is not None:
        raise CLIError("--radial-load-n loads the rotor of a bearing rig; a gear rig is "
                       "loaded by --torque-nm", option="--radial-load-n")
    operating_warnings(args, rig, OperatingPoint(args.speed_rpm[0], max(torques or [0.0]),
                                                 args.radial_load_n or 0.0))
    mesh = mesh_argument(args, rig, torques or ())
    check_losses_options(args)
    prepare_tables(args, rig, mesh)                 # once, before the workers start
    spec = SweepSpec(speeds_rpm=args.speed_rpm, torques_nm=torques,
                     radial_load_n=args.radial_load_n,
                     duration_s=args.duration_s, frictions=args.friction or (None,),
                     clearances_m=args.clearance_m or (None,), rig=rig, fs_hz=args.fs_hz,
                     warmup_s=args.warmup_s, substeps=args.substeps, seed=args.seed,
                     seed_policy=args.seed_policy, mesh=mesh, faults=faults_of(args, rig),
                     losses=args.losses or None)
    args.notice_compile()
    progress = not args.json and sys.stderr.isatty()
    try:
        summary = run_sweep(spec, args.out, workers=args.workers, force=args.force,
                            progress=progress)
    except KeyboardInterrupt:
        raise CLIError(f"interrupted; finished runs are kept in {args.out}/manifest.json, "
                       f"re-run the same command to resume", 130) from None
    return summary.to_dict()


def text(res):
    """Runs done, time spent, where the manifest is."""
    lines = [f"{res['n_runs']} runs in {res['dir']}: {res['completed']} simulated, "
             f"{res['skipped']} already there ({res['adopted']} adopted), "
             f"{len(res['failed'])} failed",
             f"wall {res['wall_s']:.2f} s on {res['workers']} workers ({res['start_method']}); "
             f"integration {res['integration_s']:.2f} s, compile {res['compile_s']:.2f} s, "
             f"setup {res['setup_s']:.2f} s, spectra {res['spectra_s']:.2f} s, "
             f"save {res['save_s']:.2f} s; utilisation {100 * res['utilisation']:.0f} %",
             f"manifest {res['manifest']}"]
    return "\n".join(lines)
