"""``cmsim compare``: a measured record against the model — where they differ, the likely
cause, its fit and the gain on held-out segments."""

from __future__ import annotations

from pathlib import Path

from cmsim.cli.contract import load_file, ranged
from cmsim.rig import RANGES, Range, Rig


def register(sub):
    """Add the ``compare`` parser."""
    p = sub.add_parser("compare", help="compare a measured record with the model, name the "
                                       "cause, fit it and measure the gain",
                       description="RECORD is a .npz/.csv/.wav file in a folder whose "
                                   "metadata.json gives rig, fs, speed and load (relative "
                                   "paths are also looked up under CMSIM_DATA). The answer "
                                   "key (condition, fault fields, file name) is never read.")
    p.add_argument("record", metavar="RECORD", help="measured recording")
    p.add_argument("--channel", metavar="NAME", help="channel (default: the first near a "
                                                     "documented bearing)")
    p.add_argument("--rig", metavar="FILE.toml",
                   help="model rig (default: built from metadata.json geometry)")
    p.add_argument("--report", type=Path, metavar="DIR", help="write DIR/compare.html")
    p.add_argument("--budget", type=ranged(Range(10, 10000, integer=True)), default=None,
                   metavar="N", help="most simulations: ranking, fit and held-out "
                                     "re-simulations (default 140, at least 10)")
    p.add_argument("--seed", type=ranged(RANGES["seed"]), default=0,
                   help="seed of the model simulations")
    p.set_defaults(func=run, text=text)


def run(args):
    """Read the record, compare, write the report."""
    from cmsim.discrepancy import compare
    from cmsim.measured import read_record
    from cmsim.discrepancy.report import write_report

    rig = load_file("--rig", args.rig, Rig.load, "a rig TOML file") if args.rig else None
    record = read_record(args.record, channel=args.channel, rig=rig)
    kw = {} if args.budget is None else {"budget": args.budget}
    res = compare(record, seed=args.seed, **kw)
    out = res.to_dict()
    out["report"] = str(write_report(res, args.report)) if args.report else None
    return out


def text(res):
    """The finding, the gain, the leading causes and discrepancies."""
    lines = [f"finding: {res['finding']}" + (f" on {res['component']}" if res["component"]
                                              else "") + (f" {res['parameters']}"
                                                          if res["parameters"] else "")]
    g = res["gain"]
    lines.append(f"held-out discrepancy (chi2 per feature): {g['before']:.3g} -> "
                 f"{g['after']:.3g} (relative gain {g['relative']:.2f})")
    for c in res["causes"][:5]:
        lines.append(f"  {c['name']:20s} {str(c['component']):10s} score {c['score']:.3f}")
    for d in res["discrepancies"][:5]:
        lines.append(f"  {d['feature']:24s} measured {d['measured']:.3g} simulated "
                     f"{d['simulated']:.3g} (z {d['z']:.1f})")
    for k, v in res["inferred"].items():
        lines.append(f"inferred {k}: {v['value']:.6g} ({v['how']})")
    lines.append(f"{res['simulations']} simulations, {res['wall_s']:.1f} s")
    if res["report"]:
        lines.append(f"wrote {res['report']}")
    return "\n".join(lines)
