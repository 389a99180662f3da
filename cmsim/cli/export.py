"""``cmsim export``: a run or a dataset as files ML tools and other software load."""

from __future__ import annotations

from pathlib import Path

from cmsim.cli.contract import ranged
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
                                   "operating point, the rig's geometry, answer key: cmsim "
                                   "spectrum and compare read the files back with no --rig) "
                                   "and, for a dataset, "
                                   "labels.csv (label, severity, operating point, group, "
                                   "split). A dataset as parquet is one row per window "
                                   "(windows.parquet alone, each window with its record's "
                                   "labels: the folder loads as one table in pandas, pyarrow "
                                   "and HuggingFace datasets). Default channels: those a real machine "
                                   "measures (accelerations, tacho); name simulated ones "
                                   "(dte_um, F_1b1_loa) with --channels.")
    p.add_argument("source", type=Path, metavar="RUN|DATASET",
                   help="a run file (.npz) or a dataset directory")
    p.add_argument("--format", required=True, choices=FORMATS,
                   help="file format: npz, csv, wav, mat, uff and tdms are signal files that "
                        "cmsim spectrum, compare and calibrate read back with their rate, "
                        "units and geometry (wav: float32 at full scale, the calibration "
                        "factor, channels and units in its INFO comment; uff: type 58 sets, "
                        "needs pyuff; tdms: needs npTDMS); parquet is a dataset's windows "
                        "(windows.parquet, one row per window, for ML tools), not a run's")
    p.add_argument("--out", type=Path, required=True, metavar="OUT",
                   help="folder to make (refused if it exists, unless --force)")
    p.add_argument("--channels", nargs="+", metavar="NAME",
                   help="channels to write (default: the measurable ones)")
    p.add_argument("--force", action="store_true",
                   help="replace an existing OUT (never the source or a folder holding it)")
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
    """Export; every check is the library's (its errors name the option as typed)."""
    from cmsim.datasets.export import export

    return export(args.source, args.out, args.format, args.channels, force=args.force,
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
