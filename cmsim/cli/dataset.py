"""``cmsim dataset``: a labelled fault dataset from a TOML spec, resumable."""

from __future__ import annotations

import sys
from pathlib import Path

from cmsim.cli.contract import CLIError, load_file, ranged
from cmsim.rig import RANGES


def register(sub):
    """Add the ``dataset`` parser."""
    p = sub.add_parser("dataset", help="generate a labelled fault dataset from a TOML spec",
                       description="Generate the records of a dataset spec (datasets/*.toml) "
                                   "on local worker processes or a Dask cluster; each record "
                                   "is saved to DIR/records/ as it finishes and listed in "
                                   "DIR/manifest.parquet. Re-running the same command "
                                   "resumes: finished records are not recomputed.")
    p.add_argument("spec", metavar="SPEC", help="dataset spec (TOML)")
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="dataset directory")
    p.add_argument("--workers", type=ranged(RANGES["workers"]), default=None,
                   help="local worker processes (default: number of CPUs)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="dask.distributed scheduler address (tcp://host:8786); its workers "
                        "must see DIR (needs the 'dask' extra)")
    p.add_argument("--verify", action="store_true",
                   help="check the SHA-256 of every finished record when resuming")
    p.add_argument("--force", action="store_true",
                   help="replace a dataset of a different spec in DIR")
    p.set_defaults(func=run, text=text)


def run(args):
    """Generate (or resume) the dataset."""
    from cmsim.datasets import DatasetSpec, generate_dataset
    from cmsim.datasets.manifest import check_manifest
    from cmsim.datasets.pool import check_scheduler

    spec = load_file("SPEC", args.spec, DatasetSpec.load, "a dataset spec TOML file")
    if args.scheduler is not None:
        check_scheduler(args.scheduler)
    check_manifest(args.out)    # a resumed directory's manifest is input (footer only: the
    args.notice_compile()       # run reads its rows once)
    progress = not args.json and sys.stderr.isatty()
    try:
        summary = generate_dataset(spec, args.out, workers=args.workers,
                                   scheduler=args.scheduler, progress=progress,
                                   verify=args.verify, force=args.force)
    except KeyboardInterrupt as exc:
        raise CLIError(f"interrupted ({getattr(exc, 'signal_name', 'SIGINT')}); "
                       f"{interrupted_words(args.out, 'records')}", 130) from None
    res = summary.to_dict()
    if summary.records_failed:
        args.warn(f"{summary.records_failed} records failed (status 'failed' in "
                  f"{res['manifest']}, with their error)")
    return res


def text(res):
    """Records written, time spent, where the manifest is."""
    lines = [f"{res['records_total']} records in {res['dir']}: {res['records_written']} "
             f"written, {res['records_skipped']} already there, {res['records_failed']} failed",
             f"wall {res['wall_s']:.2f} s on {res['workers']} {res['runner']} workers; "
             f"integration {res['integration_s']:.2f} s, setup {res['setup_s']:.2f} s, "
             f"sensors {res['sensors_s']:.2f} s, save {res['save_s']:.2f} s",
             f"manifest {res['manifest']}"]
    lines += [f"failed {f['record_id']}: {f['error']}" for f in res["failed"][:5]]
    return "\n".join(lines)


def interrupted_words(out, what):
    """What an interrupted dataset job (``dataset``, ``sweep``) left in its folder ``out``,
    in words: how many of its ``what`` (records, runs) were finished and kept, and how to
    resume."""
    from cmsim.datasets.manifest import read_rows

    rows = read_rows(out) if Path(out).is_dir() else None
    done = 0 if rows is None else int((rows["status"] == "ok").sum())
    if not done:
        return f"no {what} were finished yet; re-run the same command to start"
    return f"{done} finished {what} are kept in {out}; re-run the same command to resume"

