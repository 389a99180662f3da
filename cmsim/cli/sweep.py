"""``cmsim sweep``: a grid of operating points on worker processes, resumable."""

from __future__ import annotations

import sys
from pathlib import Path

from cmsim.cli.contract import CLIError, ranged
from cmsim.cli.dataset import interrupted_words
from cmsim.errors import IntegrationDiverged
from cmsim.cli.options import (add_fault_options, add_losses_option, add_mesh_options,
                               add_rig_options, add_sampling_options, check_losses_options,
                               faults_of, load_rig, mesh_argument, number, operating_warnings,
                               prepare_tables)
from cmsim.rig import RANGES, OperatingPoint


def register(sub):
    """Add the ``sweep`` parser."""
    p = sub.add_parser("sweep", help="simulate a grid of operating points in parallel",
                       description="Simulate speeds × torques (× frictions × clearances) on "
                                   "worker processes: a grid dataset spec whose records keep "
                                   "every signal; each run is saved to DIR/records/ and listed "
                                   "in DIR/manifest.parquet as it finishes. Re-running the "
                                   "same command resumes: finished runs are skipped.")
    p.add_argument("--torque-nm", type=number("torque_nm"), nargs="+",
                   help="output torques, N m (gear rigs; default 0: unloaded, the teeth may "
                        "separate)")
    p.add_argument("--radial-load-n", type=number("radial_load_n"), metavar="N",
                   help="static radial load on the rotor of a bearing rig, N (default 0)")
    p.add_argument("--speed-rpm", type=number("speed_rpm"), nargs="+", required=True,
                   help="input shaft speeds, rpm")
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="sweep directory")
    add_rig_options(p, many=True)
    add_sampling_options(p, seed_help="base seed; run i gets a seed drawn from "
                                       "SeedSequence([seed, i])")
    p.add_argument("--seed-policy", default="per_run", choices=("per_run", "shared"),
                   help="per_run: independent seed per run; shared: every run uses --seed")
    p.add_argument("--workers", type=ranged(RANGES["workers"]), default=None,
                   help="worker processes (default: number of CPUs)")
    p.add_argument("--force", action="store_true",
                   help="replace a manifest written for a different spec")
    add_mesh_options(p)
    add_fault_options(p)
    add_losses_option(p)
    p.set_defaults(func=run, text=text)


def run(args):
    """Build the sweep's spec (a grid dataset spec whose records keep every signal) from
    the options and run it; runs that failed make the command exit 3."""
    from cmsim.datasets import DatasetSpec, Variation, generate_dataset

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
    prepare_tables(args, rig, mesh, torques or ())  # once, before the workers start
    axes = [("speed_rpm", args.speed_rpm), ("torque_nm", torques), ("friction", args.friction),
            ("clearance_m", args.clearance_m)]
    spec = DatasetSpec([Variation(n, v) for n, v in axes if v],
                       fixed={"radial_load_n": args.radial_load_n} if args.radial_load_n
                       else None, duration_s=args.duration_s, rig=rig, fs_hz=args.fs_hz,
                       warmup_s=args.warmup_s, substeps=args.substeps, seed=args.seed,
                       seed_policy=args.seed_policy, mesh=mesh, faults=faults_of(args, rig),
                       losses=args.losses or None)
    args.notice_compile()
    progress = not args.json and sys.stderr.isatty()
    try:
        summary = generate_dataset(spec, args.out, workers=args.workers, force=args.force,
                                   progress=progress, verify=True)
    except KeyboardInterrupt:
        raise CLIError(f"interrupted; {interrupted_words(args.out, 'runs')}", 130) from None
    if summary.records_failed:
        errors = "; ".join(f"{r}: {e}" for r, e in summary.failed)
        exc = IntegrationDiverged(f"{summary.records_failed} of {summary.records_total} runs "
                                  f"failed ({errors}); the other runs are saved in "
                                  f"{args.out}/manifest.parquet")
        exc.summary = summary
        raise exc
    return summary.to_dict()


def text(res):
    """Runs done, time spent, where the manifest is."""
    lines = [f"{res['records_total']} runs in {res['dir']}: {res['records_written']} "
             f"simulated, {res['records_skipped']} already there ({res['records_adopted']} "
             f"adopted), {res['records_failed']} failed",
             f"wall {res['wall_s']:.2f} s on {res['workers']} workers ({res['start_method']}); "
             f"integration {res['integration_s']:.2f} s, warm-up {res['warmup_s']:.2f} s, "
             f"setup {res['setup_s']:.2f} s, features {res['features_s']:.2f} s, "
             f"save {res['save_s']:.2f} s; utilisation {100 * res['utilisation']:.0f} %",
             f"manifest {res['manifest']}"]
    return "\n".join(lines)
