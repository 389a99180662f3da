"""``cmsim compare``: a measured record against the model — where they differ, the likely
cause, its fit and the gain on held-out segments."""

from __future__ import annotations

import os
from pathlib import Path

from cmsim.cli.contract import CLIError, load_file, ranged
from cmsim.cli.options import add_recording_options, recording_values
from cmsim.cli.output import inferred_lines
from cmsim.errors import ParameterError
from cmsim.rig import RANGES, Range, Rig


def register(sub):
    """Add the ``compare`` parser."""
    p = sub.add_parser("compare", help="compare a measured record with the model, name the "
                                       "cause, fit it and measure the gain",
                       description="RECORD is a .npz/.csv/.wav/.mat/.uff/.tdms recording; "
                                   "rate, speed, unit and channel names come from the file "
                                   "where it states them, else from metadata.json beside it "
                                   "(rig geometry, load), else from --fs-hz, --speed-rpm, "
                                   "--unit and --rig (relative paths are also looked up "
                                   "under CMSIM_DATA). The answer key (condition, fault "
                                   "fields, file name) is never read.")
    p.add_argument("record", metavar="RECORD", help="measured recording")
    p.add_argument("--channel", metavar="NAME", help="channel (default: the first near a "
                                                     "documented bearing)")
    p.add_argument("--rig", metavar="FILE.toml",
                   help="model rig (default: built from metadata.json geometry)")
    add_recording_options(p)
    p.add_argument("--report", type=Path, metavar="DIR", help="write DIR/compare.html")
    p.add_argument("--budget", type=ranged(Range(10, 10000, integer=True)), default=None,
                   metavar="N", help="most simulations: ranking, fit and held-out "
                                     "re-simulations (default 140, at least 10)")
    p.add_argument("--seed", type=ranged(RANGES["seed"]), default=0,
                   help="seed of the model simulations")
    p.add_argument("--machine", metavar="MACHINE.toml",
                   help="the record's machine (cmsim calibrate on a healthy baseline): the "
                        "nominal model; without it, only path-free evidence is judged "
                        "unless --rig documents the housing path")
    p.add_argument("--workers", type=ranged(RANGES["workers"]), default=None,
                   help="processes that make the model's runs (default: 2 where there are "
                        "2 CPUs or more; the same result with any number)")
    p.add_argument("--span", type=ranged(Range(0.0, 1.0e5, unit="s")), nargs=2,
                   metavar=("START", "STOP"), help="compare only this part of the record, s")
    p.set_defaults(func=run, text=text)


def run(args):
    """Read the record, compare, write the report."""
    from cmsim.discrepancy import compare
    from cmsim.discrepancy.report import write_report
    from cmsim.dynamics.simulation import kernels_cached
    from cmsim.machine import Machine
    from cmsim.measured import read_record

    if args.span is not None and not args.span[0] < args.span[1]:
        raise CLIError(f"--span {args.span[0]:g} {args.span[1]:g}: START must be below STOP",
                       option="--span")
    machine = load_file("--machine", args.machine, Machine.load,
                        "a machine file (cmsim calibrate --out)") if args.machine else None
    rig = load_file("--rig", args.rig, Rig.load, "a rig TOML file") if args.rig else None
    if machine is not None and rig is not None and rig != machine.rig:
        # the machine's rig is what its baseline and library were computed on
        raise CLIError(f"--rig {args.rig}: is not the rig of --machine {args.machine}, which "
                       "brings its own (the model its baseline and signature library were "
                       "computed on); leave --rig out", option="--rig")
    channel = args.channel or (machine.channel if machine is not None else None)
    values = recording_values(args)
    try:
        record = read_record(args.record, channel=channel, rig=rig, **values)
    except ParameterError as exc:
        if exc.param == "rig" and machine is not None and rig is None:
            # a recording without geometry, read on the machine's own rig
            record = read_record(args.record, channel=channel, rig=machine.rig, **values)
        elif exc.param != "--channel" or args.channel is not None or machine is None:
            raise
        else:       # the channel was the machine's, not the user's: the machine does not fit
            raise CLIError(f"--machine {args.machine}: calibrated on channel "
                           f"{machine.channel!r}, which the record does not have ({exc}); a "
                           "machine file belongs to the recordings of the machine it was "
                           "calibrated on", option="--machine") from None
    if args.span is not None:
        record = record.span(*args.span)
    kw = {} if args.budget is None else {"budget": args.budget}
    kw["workers"] = args.workers or min(2, os.cpu_count() or 1)
    # against a machine the model runs only to refine a named cause's size: with the kernels
    # in numba's cache they load when that runs (0.4 s a record with no finding never pays)
    args.notice_compile(integrates=machine is None or not kernels_cached())
    try:
        res = compare(record, machine=machine, seed=args.seed, **kw)
    except ParameterError as exc:
        if exc.param == "machine":
            raise CLIError(f"--machine {args.machine}: {exc}", option="--machine") from None
        raise
    out = res.to_dict()
    out["workers"] = kw["workers"]            # what wall_s was measured on (not the result)
    out["report"] = str(write_report(res, args.report)) if args.report else None
    return out


def text(res):
    """The finding in words, the gain, the leading causes and discrepancies."""
    from cmsim.discrepancy.compare import feature_label

    lines = [f"finding: {res['words']} [{res['finding']}"
             + (f" on {res['component']}" if res["component"] else "") + "]",
             f"nominal model: {res['mode']}"
             + (f" (machine {res['record']['machine']})" if res["record"].get("machine")
                else "")]
    if res["not_judged"]:
        lines.append("not judged without a calibrated machine (they depend on the transfer "
                     "path): " + ", ".join(res["not_judged"]))
    for t in res["near_ties"]:
        lines.append(f"near tie: {t['name']}"
                     + (f" on {t['component']}" if t["component"] else "")
                     + f" (evidence {t['delta_chi2']:.0f})")
    if res["departures"]:
        lines.append("departs from the model in: " + ", ".join(res["departures"]))
    g = res["gain"]
    machine = res["mode"] == "machine"
    like = "the machine's baseline" if machine else "the model's own"
    lines.append(f"held-out discrepancy (chi2 per feature, ~1 for a record like {like}): "
                 f"{g['before']:.3g} -> {g['after']:.3g} (relative gain {g['relative']:.2f})")
    if machine:
        how = {"whole": "its prediction reads the whole record best",
               "beside": "what it changes holds the change that reads the whole record best "
                         "(the near tie), and its own family stands out over that change",
               "family": "its own family stands out over the baseline and no cause reads the "
                         "whole record",
               "within error": "it reads the whole record best of every cause, within "
                               "the error of the model's own change (no family stands out)",
               "full resolution": "its fundamental holds, over the whole record, the line "
                                  "another bearing's family shared in the segments (see the note)",
               "fundamental": "its fundamental stands out where the fault read first stood "
                              "out on a harmonic alone (see the note)",
               "whole-record family": "its fundamental and second harmonic stand well over "
                                      "the baseline's over the whole record, where no "
                                      "segment showed them (see the note)"
               }.get(res.get("decided_on", ""))
        if how:
            lines.append(f"named because {how}")
    family = not machine or res.get("decided_on") == "family"     # evidence on own features
    lines.append(
        "leading faults, by their evidence against the machine's baseline on the features "
        "their own signature moves (Δχ²):" if machine and family else
        "leading causes, by their evidence against the machine's baseline (Δχ² over every "
        "feature: the baseline's χ² less the cause's):" if machine else
        "leading causes, by their evidence (Δχ²) on the features each moves (a fault is named "
        "when its own family stands out, before any cause that reshapes the whole spectrum):")
    for c in res["causes"][:5]:
        lines.append(f"  {c['name']:20s} {c['component'] or '-':10s} evidence "
                     f"{c['delta_chi2']:7.1f}"
                     + (f" on {c['judged_on']} features" if family else "")
                     + ("" if machine else f" (all: {c['delta_chi2_all']:.1f})"))
    lines.append("largest departures of the record from "
                 + ("the machine's baseline:" if machine else "the model:"))
    ref = "baseline" if machine else "simulated"
    for d in res["discrepancies"][:5]:
        lines.append(f"  {feature_label(d)}: measured {d['measured']:.3g} {ref} "
                     f"{d['simulated']:.3g} (z {d['z']:.1f})")
    for n in res.get("notes", []):
        lines.append(f"note: {n}")
    lines += inferred_lines(res["inferred"])
    lines.append(f"{res['simulations']} simulations, {res['wall_s']:.1f} s"
                 + (f" on {res['workers']} processes" if res.get("workers", 1) > 1 else ""))
    if res["report"]:
        lines.append(f"wrote {res['report']}")
    return "\n".join(lines)
