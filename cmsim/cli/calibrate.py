"""``cmsim calibrate``: a machine's twin from healthy baseline records of that machine."""

from __future__ import annotations

from pathlib import Path

from cmsim.cli.contract import CLIError, load_file, ranged
from cmsim.cli.options import add_recording_options, recording_values
from cmsim.errors import ParameterError
from cmsim.rig import Range, Rig


def register(sub):
    """Add the ``calibrate`` parser."""
    p = sub.add_parser("calibrate", help="calibrate a machine (transfer path, background) on "
                                         "healthy baseline records",
                       description="Fit what the model cannot know of one machine from "
                                   "records taken when it was healthy: the transfer path from "
                                   "the model's bearing force to the sensor (minimum phase, "
                                   "applied in the time domain), the background (coloured "
                                   "noise and the lines the model does not make), the "
                                   "operating point, and the baseline's own spread of every "
                                   "feature; writes the machine file for --machine.")
    p.add_argument("baseline", nargs="+", metavar="BASELINE",
                   help="healthy record(s) of one machine (.npz/.csv/.wav/.mat/.uff/.tdms; "
                        "what a file does not state from metadata.json beside it, else from "
                        "the options; relative paths also under CMSIM_DATA)")
    p.add_argument("--out", type=Path, required=True, metavar="MACHINE.toml",
                   help="the machine file to write (refused if it exists, unless --force; "
                        "never one of the inputs)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    p.add_argument("--channel", metavar="NAME", help="channel (default: the first near a "
                                                     "documented bearing)")
    p.add_argument("--rig", metavar="FILE.toml",
                   help="model rig (default: built from metadata.json geometry)")
    add_recording_options(p)
    p.add_argument("--span", type=ranged(Range(0.0, 1.0e5, unit="s")), nargs=2,
                   metavar=("START", "STOP"),
                   help="use only this part of each baseline, s (e.g. 0 5: calibrate on "
                        "one half and compare the other)")
    p.add_argument("--seed", type=ranged(Range(0, 2 ** 32 - 1, integer=True)), default=0,
                   help="seed of the model simulations")
    p.add_argument("--report", type=Path, metavar="DIR",
                   help="write DIR/calibration.html (spectra, path, fit quality)")
    p.set_defaults(func=run, text=text)


def read_records(paths, channel, rig_file, span, values=None):
    """The measured records of ``paths`` (each cut to ``span`` when given), with the
    recording options' ``values`` (:func:`~cmsim.cli.options.recording_values`)."""
    from cmsim.measured import read_record

    rig = load_file("--rig", rig_file, Rig.load, "a rig TOML file") if rig_file else None
    records = []
    for path in paths:
        try:
            rec = read_record(path, channel=channel, rig=rig, **(values or {}))
        except ParameterError as exc:
            if exc.param != "record":
                raise
            raise CLIError(f"BASELINE {' '.join(str(exc).split())}", option="BASELINE") \
                from None
        if span is not None:
            rec = rec.span(*span)
        records.append(rec)
    return records


def run(args):
    """Calibrate and write the machine file."""
    from cmsim.machine import calibrate
    from cmsim.machine.report import write_calibration_report

    _check_out(args)
    if args.span is not None and not args.span[0] < args.span[1]:
        raise CLIError(f"--span {args.span[0]:g} {args.span[1]:g}: START must be below STOP",
                       option="--span")
    records = read_records(args.baseline, args.channel, args.rig, args.span,
                           recording_values(args))
    args.notice_compile()
    machine = calibrate(records, seed=args.seed)
    machine.save(args.out)
    q = machine.fit_quality
    _warn_fit(args, q)
    out = {"machine": str(args.out), "name": machine.name, "channel": machine.channel,
           "fs_hz": machine.fs_hz, "speed_rpm": machine.op.speed_rpm,
           "speed_wobble": machine.speed_wobble, "lines": len(machine.background.lines),
           "calibrated_on": list(machine.calibrated_on), "notes": list(machine.notes),
           "inferred": {r.record_id: dict(r.inferred) for r in records if r.inferred},
           "fit_quality": {"worst_feature": q.get("worst_feature"),
                           "worst_z": q.get("worst_z"),
                           "chi2_per_feature": q.get("chi2_per_feature"),
                           "n_features": q.get("n_features")},
           "report": None}
    if args.report:
        out["report"] = str(write_calibration_report(machine, records, args.report))
    return out


def _check_out(args):
    """--out is a new file (or --force), and never an input: refused before any work."""
    from cmsim.measured.readers import resolve_path

    out = Path(args.out).resolve()
    for option, path in [("--rig", args.rig)] + [("BASELINE", b) for b in args.baseline]:
        if path is None:
            continue
        try:                    # the input as it will be read: also under CMSIM_DATA
            found = resolve_path(path).resolve()
        except ParameterError:
            found = None        # no such input: reading it says so, after this check
        if out in (Path(path).resolve(), found):
            raise CLIError(f"--out {args.out}: is the {option} input"
                           f"{'' if found in (None, Path(path).resolve()) else f' ({found})'}"
                           "; write the machine to another file", option="--out")
    if out.exists() and not args.force:
        raise CLIError(f"--out {args.out}: exists; give --force to overwrite it (or a new "
                       f"file)", option="--out")


def _warn_fit(args, q):
    """Warn when the twin misses its own held-out baseline by more than ``compare`` lets a
    record depart before it calls it unexplained: its comparisons then read healthy records
    through offsets the twin does not make."""
    from cmsim.discrepancy.compare import ALARM_Z, UNEXPLAINED_CHI2_PER_FEATURE

    chi = q.get("chi2_per_feature") or 0.0
    if chi <= UNEXPLAINED_CHI2_PER_FEATURE:
        return
    far = sum(abs(z) >= 3.0 for z in q.get("z", {}).values())
    args.warn(f"the twin reproduces its baseline's held-out segments to chi2 per feature "
              f"{chi:.2f}, above the {UNEXPLAINED_CHI2_PER_FEATURE:g} at which compare calls a "
              f"record unexplained ({far} features 3 spreads or more off, worst "
              f"{q['worst_feature']} z {q['worst_z']:.1f}"
              f"{'' if abs(q['worst_z']) < ALARM_Z else ', beyond the alarm z'}): compare "
              "reads records against the twin moved by these offsets, but a cause acting "
              "on those features is judged through a twin that does not make them")


def _wobble(w):
    return "not identifiable" if w is None else f"{100 * w:.2f} % rms"


def text(res):
    """What was fitted and how well."""
    q = res["fit_quality"]
    lines = [f"machine {res['name']} ({res['channel']}, {res['fs_hz']:g} Hz, "
             f"{res['speed_rpm']:.1f} rpm, speed wobble {_wobble(res['speed_wobble'])}): "
             f"{res['lines']} background lines",
             f"fit on held-out baseline segments: worst z {q['worst_z']:.2f} "
             f"({q['worst_feature']}), chi2 per feature {q['chi2_per_feature']:.2f} over "
             f"{q['n_features']} features"]
    lines += [f"calibrated on {c}" for c in res["calibrated_on"]]
    lines += [f"note: {n}" for n in res["notes"]]
    lines += [f"inferred {k} of {record}: {v['value']:.6g} ({v['how']})"
              for record, inferred in res.get("inferred", {}).items()
              for k, v in inferred.items()]
    lines.append(f"wrote {res['machine']}")
    if res["report"]:
        lines.append(f"wrote {res['report']}")
    return "\n".join(lines)
