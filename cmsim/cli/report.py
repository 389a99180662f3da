"""``cmsim report``: HTML report (waterfalls, orbits, DTE) of a sweep directory."""

from __future__ import annotations

import sys
from pathlib import Path

from cmsim.cli.contract import CLIError, ranged
from cmsim.errors import ParameterError
from cmsim.rig import Range


def register(sub):
    """Add the ``report`` parser."""
    p = sub.add_parser("report", help="HTML report (waterfalls, orbits, DTE) of a sweep",
                       description="Write DIR/report.html and its PNG figures from the run "
                                   "files of a sweep directory.")
    p.add_argument("dir", type=Path, metavar="DIR", help="sweep directory (cmsim sweep --out)")
    p.add_argument("--signal", nargs="+", metavar="NAME",
                   help="signals drawn as waterfalls (default: dte_um F_1b1_loa F_1b1_oloa)")
    p.add_argument("--top", type=ranged(Range(1, 100, integer=True)), default=8,
                   help="labelled peaks listed per run")
    p.add_argument("--max-hz", type=ranged(Range(0.0, 1.0e7, lo_open=True, unit="Hz")),
                   metavar="F", help="upper frequency of the waterfalls, Hz (default 6.5 GMF)")
    p.set_defaults(func=run, text=text)


def run(args):
    """Build the report."""
    from cmsim.datasets.report import DEFAULT_SIGNALS, build_report

    try:
        res = build_report(args.dir, tuple(args.signal) if args.signal else DEFAULT_SIGNALS,
                           top_n=args.top, max_freq_hz=args.max_hz,
                           progress=not args.json and sys.stderr.isatty())
    except ParameterError as exc:
        if exc.param is None:  # about the directory or its runs
            raise CLIError(f"DIR {args.dir}: {exc}", option="DIR") from None
        raise
    out = res.to_dict()
    if out["failed"]:
        args.warn(f"{out['n_failed']} of {out['n_runs'] + out['n_failed']} grid points failed "
                  f"and are not in the report: " + "; ".join(
                      f"{f['name']} ({f['error']})" for f in out["failed"]))
    return out


def text(res):
    """What was written and how long it took."""
    lines = [f"wrote {res['html']} with {len(res['figures'])} figures "
             f"({', '.join(res['figures'])})",
             f"runs {res['n_runs']}" + (f", {res['n_failed']} failed grid points listed "
                                        f"({', '.join(f['name'] for f in res['failed'])})"
                                        if res["n_failed"] else ""),
             f"report {res['total_s']:.2f} s: load {res['load_s']:.2f} s, spectra "
             f"{res['spectra_s']:.2f} s, plots {res['plot_s']:.2f} s, html {res['write_s']:.2f} s"]
    if res["dominant_signal"]:
        lines.append(f"dominant GMF harmonic of {res['dominant_signal']}: " + ", ".join(
            f"{r['name']}: {r['dominant_gmf_harmonic']}" for r in res["runs"]))
    return "\n".join(lines)
