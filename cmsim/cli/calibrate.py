"""``cmsim calibrate``: a machine's twin from healthy baseline records of that machine."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from cmsim.cli.contract import CLIError, load_file, ranged
from cmsim.cli.options import add_recording_options, number, recording_values
from cmsim.errors import ParameterError
from cmsim.rig import RANGES, Range, Rig


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
                                   "feature; then the signature library: what each cause of "
                                   "the catalogue, over a grid of its sizes, changes on the "
                                   "baseline as the model predicts it (compare --machine "
                                   "matches a record against it). Writes the machine file "
                                   "for --machine, the baseline's samples in it.")
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
    p.add_argument("--resample-hz", type=number("record_fs_hz"), metavar="HZ",
                   help="low-pass and resample each baseline to this rate first (at most its "
                        "own, a fraction of it): a machine for records made at a lower rate "
                        "than the baseline (MFPT: baselines at 97656.25 Hz, faults at "
                        "48828.125 Hz)")
    p.add_argument("--seed", type=ranged(Range(0, 2 ** 32 - 1, integer=True)), default=0,
                   help="seed of the model simulations")
    p.add_argument("--report", type=Path, metavar="DIR",
                   help="write DIR/calibration.html (spectra, path, fit quality)")
    p.add_argument("--workers", type=ranged(RANGES["workers"]), default=None,
                   help="processes that build the signature library (default: 2 where "
                        "there are 2 CPUs or more; the same library with any number)")
    p.set_defaults(func=run, text=text)


def read_records(paths, channel, rig_file, span, values=None, resample_hz=None):
    """The measured records of ``paths`` (each cut to ``span`` when given, then resampled
    to ``resample_hz``), with the recording options' ``values``
    (:func:`~cmsim.cli.options.recording_values`)."""
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
        if resample_hz is not None and resample_hz > rec.fs_hz:
            raise CLIError(f"--resample-hz {resample_hz:g}: must be at most the baseline's "
                           f"rate, {rec.fs_hz:g} Hz ({path})", option="--resample-hz")
        if resample_hz is not None and resample_hz != rec.fs_hz:
            try:
                rec = rec.resampled(resample_hz)
            except ParameterError as exc:
                raise CLIError(f"--resample-hz {resample_hz:g}: {path} is at {rec.fs_hz:g} "
                               f"Hz: {' '.join(str(exc).split())}",
                               option="--resample-hz") from None
        records.append(rec)
    return records


def run(args):
    """Calibrate, build the signature library and write the machine file."""
    from cmsim.discrepancy.machine_checks import baseline_consistency, detectability
    from cmsim.discrepancy.signatures import build_library
    from cmsim.machine import calibrate
    from cmsim.machine.report import write_calibration_report

    _check_out(args)
    _check_distinct_baselines(args.baseline)
    if args.span is not None and not args.span[0] < args.span[1]:
        raise CLIError(f"--span {args.span[0]:g} {args.span[1]:g}: START must be below STOP",
                       option="--span")
    records = read_records(args.baseline, args.channel, args.rig, args.span,
                           recording_values(args), args.resample_hz)
    args.notice_compile()
    machine = calibrate(records, seed=args.seed)
    workers = args.workers or min(2, os.cpu_count() or 1)
    show = not args.json and sys.stderr.isatty()

    def progress(done, total, elapsed_s):
        if show:
            print(f"\rcmsim calibrate: signature library {done}/{total} ({elapsed_s:.0f} s)",
                  end="", file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    machine = machine.with_library(build_library(machine, seed=args.seed, workers=workers,
                                                 progress=progress))
    library_s = time.perf_counter() - t0
    if show:
        print(file=sys.stderr)
    machine.save(args.out)
    q = machine.fit_quality
    consistency = baseline_consistency(machine)
    _warn_consistency(args, consistency)
    detectable = detectability(machine)
    out = {"machine": str(args.out), "name": machine.name, "channel": machine.channel,
           "fs_hz": machine.fs_hz, "speed_rpm": machine.op.speed_rpm,
           "speed_wobble": machine.speed_wobble, "lines": len(machine.background.lines),
           "calibrated_on": list(machine.calibrated_on), "notes": list(machine.notes),
           "inferred": {r.record_id: dict(r.inferred) for r in records if r.inferred},
           "fit_quality": {"worst_feature": q.get("worst_feature"),
                           "worst_z": q.get("worst_z"),
                           "chi2_per_feature": q.get("chi2_per_feature"),
                           "n_features": q.get("n_features")},
           "baseline_consistency": consistency,
           "detectability": detectable, "components": dict(machine.components),
           "library": {"entries": len(machine.library.entries),
                       "causes": sorted({e.cause for e in machine.library.entries}),
                       "segments": machine.library.segments, "wall_s": library_s,
                       "workers": workers},
           "report": None}
    if args.report:
        out["report"] = str(write_calibration_report(machine, records, args.report,
                                                     detectable=detectable,
                                                     consistency=consistency))
    return out


def _found(path):
    """The input as it will be read (also under CMSIM_DATA), or None where there is none:
    reading it then says so."""
    from cmsim.measured.readers import resolve_path

    try:
        return resolve_path(path).resolve()
    except ParameterError:
        return None


def _check_distinct_baselines(paths):
    """Each healthy record once: a record given twice would count its segments twice in the
    baseline's spread, which would then read narrower than the machine's own."""
    seen = {}
    for path in paths:
        found = _found(path)
        if found in seen:
            raise CLIError(f"BASELINE {path}: given twice (also as {seen[found]}); give each "
                           f"healthy record once", option="BASELINE")
        if found is not None:
            seen[found] = path


def _check_out(args):
    """--out is a new file (or --force), and never an input: refused before any work."""
    out = Path(args.out).resolve()
    for option, path in [("--rig", args.rig)] + [("BASELINE", b) for b in args.baseline]:
        if path is None:
            continue
        found = _found(path)
        if out in (Path(path).resolve(), found):
            raise CLIError(f"--out {args.out}: is the {option} input"
                           f"{'' if found in (None, Path(path).resolve()) else f' ({found})'}"
                           "; write the machine to another file", option="--out")
    if out.exists() and not args.force:
        raise CLIError(f"--out {args.out}: exists; give --force to overwrite it (or a new "
                       f"file)", option="--out")


def _warn_consistency(args, c):
    """Warn when the baseline, judged against itself as compare judges a record (its odd
    segments against its even ones, the same σ and χ²), departs: healthy records of this
    machine may then read as departures."""
    from cmsim.discrepancy.judge import ALARM_Z, NONE_CHI2_PER_FEATURE

    for r in c.get("records", ()):
        if r["departs"]:
            args.warn(f"baseline {r['record']} differs from the other baseline records by "
                      f"chi2 per feature {r['chi2_per_feature']:.2f} (worst "
                      f"{r['worst_feature']} z {r['worst_z']:+.1f}), as a record departs "
                      "from its machine: it may not be of the same healthy machine at the same "
                      "operating point (a fault in it would read as none); calibrate without "
                      "it, or check it")
    if not c["departs"]:
        return
    args.warn(f"the baseline's own halves differ by chi2 per feature "
              f"{c['chi2_per_feature']:.2f} (worst {c['worst_feature']} z "
              f"{c['worst_z']:+.1f}), beyond what compare lets a record of this machine depart "
              f"before naming anything (chi2 per feature {NONE_CHI2_PER_FEATURE:g}, a "
              f"feature {ALARM_Z:g} spreads off): the baseline is not stationary, and healthy "
              "records may read as departures; calibrate on a longer or steadier baseline")


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
    from cmsim.machine.report import detectability_rows

    lib = res["library"]
    lines.append(f"signature library: {lib['entries']} entries of {len(lib['causes'])} causes "
                 f"on {lib['segments']} baseline segments, {lib['wall_s']:.0f} s on "
                 f"{lib['workers']} processes")
    c = res["baseline_consistency"]
    lines.append(f"baseline against itself (odd segments against even, as compare judges a "
                 f"record): chi2 per feature {c['chi2_per_feature']:.2f}, worst "
                 f"{c['worst_feature']} z {c['worst_z']:+.1f}")
    lines.append("what this sensor can see (smallest size compare names, from the library):")
    lines += [f"  {a:20s} {b:12s} {s}" for a, b, s in
              detectability_rows(res["detectability"], res["components"])]
    lines += [f"calibrated on {c}" for c in res["calibrated_on"]]
    lines += [f"note: {n}" for n in res["notes"]]
    lines += [f"inferred {k} of {record}: {v['value']:.6g} ({v['how']})"
              for record, inferred in res.get("inferred", {}).items()
              for k, v in inferred.items()]
    lines.append(f"wrote {res['machine']}")
    if res["report"]:
        lines.append(f"wrote {res['report']}")
    return "\n".join(lines)
