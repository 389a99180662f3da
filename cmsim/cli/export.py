"""``cmsim export``: a run or a dataset as files ML tools and other software load."""

from __future__ import annotations

from pathlib import Path

from cmsim.cli.contract import CLIError, ranged
from cmsim.cli.options import number
from cmsim.rig import Range

#: The formats of ``--format``: :data:`cmsim.datasets.export.FORMATS`, written out so that
#: building the parser imports none of the library (tests/cli/test_export.py checks that the
#: two agree).
FORMATS = ("npz", "csv", "wav", "mat", "uff", "tdms", "parquet")


def register(sub):
    """Add the ``export`` parser."""
    p = sub.add_parser("export", help="write a run or a dataset as npz, csv, wav, mat, uff, "
                                      "tdms or parquet files",
                       description="Write a saved run (cmsim simulate --out) or a dataset "
                                   "(cmsim dataset) into the new folder OUT: one signal file "
                                   "per run or record with metadata.json (rate, units, "
                                   "operating point, answer key) and, for a dataset, "
                                   "labels.csv (label, severity, operating point, group, "
                                   "split). A dataset as parquet is one row per window "
                                   "(windows.parquet, for pandas, pyarrow and HuggingFace "
                                   "datasets). Default channels: those a real machine "
                                   "measures (accelerations, tacho); name simulated ones "
                                   "(dte_um, F_1b1_loa) with --channels.")
    p.add_argument("source", type=Path, metavar="RUN|DATASET",
                   help="a run file (.npz) or a dataset directory")
    p.add_argument("--format", required=True, choices=FORMATS,
                   help="file format, each read back with its rate and units by cmsim "
                        "compare, spectrum and calibrate (wav: float32 at full scale, the "
                        "calibration factor, channels and units in its INFO comment; uff: "
                        "type 58 sets, needs pyuff; tdms: needs npTDMS)")
    p.add_argument("--out", type=Path, required=True, metavar="OUT",
                   help="folder to make (refused if it exists, unless --force)")
    p.add_argument("--channels", nargs="+", metavar="NAME",
                   help="channels to write (default: the measurable ones)")
    p.add_argument("--force", action="store_true", help="replace an existing OUT")
    p.add_argument("--window", type=ranged(Range(1, 10 ** 9, integer=True)),
                   help="samples per window of --format parquet of a dataset (default 2048)")
    p.add_argument("--hop", type=ranged(Range(1, 10 ** 9, integer=True)),
                   help="samples between window starts (default: --window)")
    p.add_argument("--group-by", default="record_id", metavar="COLUMN",
                   help="manifest column whose value groups records for the split (default "
                        "record_id: each record its own machine)")
    p.add_argument("--split-seed", type=number("seed"), default=0,
                   help="seed of the train/val/test split of the groups (default 0)")
    p.add_argument("--fractions", type=ranged(Range(0.0, 1.0)), nargs=3,
                   default=[0.8, 0.1, 0.1], metavar=("TRAIN", "VAL", "TEST"),
                   help="expected shares of the groups in train, val, test (sum 1; default "
                        "0.8 0.1 0.1)")
    p.set_defaults(func=run, text=text)


def run(args):
    """Export; bad input names the option."""
    from cmsim.datasets.export import export

    source = Path(args.source)
    is_dataset = source.is_dir() and (source / "dataset.json").is_file()
    is_run = source.is_file() and source.suffix.lower() == ".npz"
    if not (is_dataset or is_run):
        why = "does not exist" if not source.exists() else (
            "is a directory without dataset.json" if source.is_dir() else "is not a .npz file")
        raise CLIError(f"RUN|DATASET {source}: {why}; expected a run file (.npz of cmsim "
                       f"simulate --out) or a dataset directory (cmsim dataset --out)",
                       option="RUN|DATASET")
    if args.out.exists() and not args.force:
        raise CLIError(f"--out {args.out}: exists; give --force to replace it (or a new "
                       f"folder)", option="--out")
    if args.out.exists() and not args.out.is_dir():
        raise CLIError(f"--out {args.out}: is a file (expected a folder)", option="--out")
    if not args.out.resolve().parent.is_dir():
        raise CLIError(f"--out {args.out}: directory {args.out.parent} does not exist",
                       option="--out")
    if abs(sum(args.fractions) - 1.0) > 1e-9:
        raise CLIError(f"--fractions must sum to 1, got {' '.join(map(str, args.fractions))}",
                       option="--fractions")
    windowed = is_dataset and args.format == "parquet"
    for opt, value in (("--window", args.window), ("--hop", args.hop)):
        if value is not None and not windowed:
            raise CLIError(f"{opt} applies to --format parquet of a dataset only",
                           option=opt)
    if is_run and args.group_by != "record_id":
        raise CLIError("--group-by applies to a dataset only", option="--group-by")
    return export(source, args.out, args.format, args.channels, force=args.force,
                  window=args.window, hop=args.hop, group_by=args.group_by,
                  seed=args.split_seed, fractions=tuple(args.fractions))


def text(res):
    """What was written where."""
    lines = [f"{res['kind']} exported as {res['format']} to {res['out']}: {res['files']} "
             f"file(s), {res['records']} record(s), channels "
             + ", ".join(f"{c} [{u}]" for c, u in res["units"].items())
             + f" at {res['fs_hz']:g} Hz"]
    w = res.get("windows")
    if w:
        lines.append(f"{w['rows']} windows of {w['window']} samples (hop {w['hop']}) in "
                     f"{w['row_groups']} row groups; split by {w['group_by']}: "
                     + ", ".join(f"{s} {n} windows / {w['groups'][s]} groups"
                                 for s, n in w["splits"].items()))
    return "\n".join(lines)
