"""``cmsim evaluate``: score a diagnostic algorithm on a dataset, or a classifier trained on
cmsim data on measured records (sim-to-real)."""

from __future__ import annotations

import sys
from pathlib import Path

from cmsim.cli.contract import CLIError, ranged
from cmsim.cli.options import add_trust_option
from cmsim.errors import ParameterError
from cmsim.rig import RANGES, Range


def register(sub):
    """Add the ``evaluate`` parser."""
    p = sub.add_parser("evaluate", help="score a diagnostic algorithm on a dataset",
                       description="Run a diagnostic function over every record of a dataset "
                                   "(cmsim dataset --out, or a folder of measured records with "
                                   "metadata.json) and report accuracy, macro-F1, the confusion "
                                   "matrix, per-class ROC AUC and detection against severity at "
                                   "5 % false alarms. See cmsim.diagnostics for the function's "
                                   "signature. What the function prints goes to stderr; what it "
                                   "raises (sys.exit too) is that record's error, with its "
                                   "traceback in --json and --report, and so is ending the "
                                   "process (os._exit, a crash: it runs in a child process). "
                                   "Exit status 2 if no record was answered.")
    p.add_argument("dir", type=Path, metavar="DIR", nargs="?", help="dataset directory")
    p.add_argument("--algorithm", metavar="MODULE:FUNCTION",
                   help="built-in (envelope, tsa, sideband), package.module:function or "
                        "path/file.py:function (required with DIR)")
    p.add_argument("--train", type=Path, nargs="+", metavar="DIR",
                   help="sim-to-real: generated dataset(s) to train on (one per seed; mean "
                        "and std over them)")
    p.add_argument("--test", type=Path, metavar="FOLDER",
                   help="sim-to-real: folder of measured records (metadata.json)")
    p.add_argument("--classifier", choices=("envelope", "forest", "logistic"),
                   help="sim-to-real classifier (cmsim.diagnostics.syn2real)")
    p.add_argument("--window", type=ranged(Range(256, 1 << 20, integer=True)), metavar="N",
                   help="sim-to-real: samples per window (default ~0.34 s: 4096 at 12 kHz)")
    p.add_argument("--max-test-windows", type=ranged(Range(1, 100_000, integer=True)),
                   metavar="N", help="sim-to-real: first N windows of each test record only")
    p.add_argument("--seed", type=ranged(RANGES["seed"]),
                   help="sim-to-real: random state of the learned model (default 0)")
    p.add_argument("--report", type=Path, metavar="OUT.html",
                   help="write an HTML page with the plots")
    add_trust_option(p)
    p.set_defaults(func=run, text=text)


def run(args):
    """Score the algorithm (or run the sim-to-real evaluation)."""
    from cmsim.diagnostics import evaluate, load_algorithm, load_dataset
    from cmsim.diagnostics.report import write_report

    if args.train or args.test is not None or args.classifier is not None:
        return _syn2real(args)
    if args.dir is None:
        raise CLIError("DIR is required (or --train DIR --test FOLDER --classifier NAME)",
                       option="DIR")
    if args.algorithm is None:
        raise CLIError("argument --algorithm: is required with DIR (see cmsim evaluate "
                       "--help)", option="--algorithm")
    func = load_algorithm(args.algorithm)
    try:
        dataset = load_dataset(args.dir, trust_metadata=args.trust_metadata)
    except ParameterError as exc:  # the message starts with the directory
        raise CLIError(f"DIR {exc}", option="DIR") from None
    if len(dataset.manifest) == 0:
        raise CLIError(f"DIR {args.dir}: the dataset has no records", option="DIR")
    progress = None
    if not args.json and sys.stderr.isatty():
        def progress(done, total):
            print(f"\rcmsim evaluate: {done}/{total} records", end="", file=sys.stderr,
                  flush=True)
    ev = evaluate(dataset, func, progress=progress, isolated=True)
    if progress is not None:
        print(file=sys.stderr)
    out = ev.to_dict()
    out["algorithm"] = args.algorithm
    out["dataset"] = str(args.dir)
    _check_answered(ev, args, out)
    if ev.unreadable:
        rid, why = ev.unreadable[0]
        args.warn(f"{len(ev.unreadable)} of {len(dataset.manifest)} records could not be "
                  f"read and were skipped (first: {rid}: {why})")
    out["report"] = str(write_report(ev, args.report)) if args.report else None
    return out


def _check_answered(ev, args, out):
    """An evaluation that scored nothing is an error (exit 2): the dataset gave no readable
    record (DIR), or the algorithm answered none (--algorithm). With --json the error
    object holds the evaluation, each record's error with its traceback."""
    m = ev.metrics
    if m["n_scored"]:
        return
    if not ev.records:
        rid, why = ev.unreadable[0]
        raise CLIError(f"DIR {args.dir}: no record could be read ({len(ev.unreadable)} "
                       f"unreadable; first: {rid}: {why})", option="DIR",
                       extra={"evaluation": out})
    first = ev.records[0]
    raise CLIError(f"--algorithm {args.algorithm} answered no record: it failed on all "
                   f"{m['n_failed']} (first: {first.record_id}: {first.error}; every "
                   f"traceback: --json)", option="--algorithm", extra={"evaluation": out})


def _syn2real(args):
    from cmsim.datasets import load
    from cmsim.diagnostics.syn2real import evaluate_syn2real, measured_windows, training_channel

    if args.dir is not None or args.algorithm is not None:
        raise CLIError("--train: give either DIR --algorithm NAME or --train DIR --test FOLDER "
                       "--classifier NAME, not both", option="--train")
    for opt, value in (("--train", args.train), ("--test", args.test),
                       ("--classifier", args.classifier)):
        if not value:
            raise CLIError(f"{opt} is required with --train/--test/--classifier", option=opt)
    if args.report is not None:
        raise CLIError("--report: not available with --train (use --json)", option="--report")
    for d in args.train:
        try:
            ds = load(d)
        except ParameterError as exc:
            raise CLIError(f"--train {exc}", option="--train") from None
        if len(ds) == 0:
            raise CLIError(f"--train {d}: the dataset has no ok record", option="--train")
        try:
            training_channel(ds)
        except ParameterError as exc:
            raise CLIError(f"--train {d}: {exc}", option="--train") from None
    try:
        test = measured_windows(args.test, window=args.window,
                                max_windows=args.max_test_windows,
                                trust_metadata=args.trust_metadata)
    except (ParameterError, OSError, ValueError, KeyError) as exc:
        raise CLIError(f"--test {args.test}: {exc}", option="--test") from None
    if test.skipped:
        rid, why = next(iter(test.skipped.items()))
        n = len(test.skipped) + len(set(test.groups))
        args.warn(f"--test {args.test}: {len(test.skipped)} of {n} records could not be read "
                  f"and were skipped (first: {rid}: {why})")
    out = evaluate_syn2real(args.train, args.test, args.classifier, test=test,
                            seed=args.seed or 0)
    out["train"] = [str(d) for d in args.train]
    return out


def _text_syn2real(res):
    def ms(v):
        return f"{100 * v['mean']:.1f} +- {100 * v['std']:.1f} %"
    lines = [f"{res['classifier']} trained on {len(res['train'])} synthetic set(s), tested on "
             f"{res['test']} ({res['n_test_windows']} windows of {res['window']} samples, "
             f"{res['n_test_records']} records)",
             f"balanced accuracy {ms(res['balanced_accuracy'])}, macro-AUROC "
             f"{ms(res['macro_auroc'])}",
             "recall: " + ", ".join(f"{c} {ms(v)}" for c, v in res["per_class_recall"].items()),
             "confusion (rows truth, summed over runs): " + str(res["confusion_matrix"])]
    lines += [f"test record {rid} skipped: {why}"
              for rid, why in res.get("skipped_test_records", {}).items()]
    return "\n".join(lines)


def _number(value):
    """True for a finite number (a metric that exists: not None, not NaN)."""
    return isinstance(value, (int, float)) and value == value and abs(value) != float("inf")


def text(res):
    """The scores in words."""
    if "classifier" in res:
        return _text_syn2real(res)
    m = res["metrics"]
    lines = [f"{res['algorithm']} on {res['dataset']}: {m['n_scored']}/{m['n_records']} "
             f"records answered, {m['n_failed']} raised",
             f"accuracy {m['accuracy']:.3f} (chance {m['chance_accuracy']:.3f}), macro-F1 "
             f"{m['macro_f1']:.3f}" if m["n_scored"] else "no record answered"]
    if m["auc"]:
        lines.append("ROC AUC: " + ", ".join(
            f"{k} {v:.3f}" for k, v in m["auc"].items() if v == v))
    det = m["detection"]
    if m["n_scored"] and (det["threshold"] is None or det["threshold"] != det["threshold"]):
        lines.append("no healthy record answered: detection against severity not scored")
    for cls, c in det["classes"].items() if det["threshold"] == det["threshold"] else ():
        least = c["min_detected_severity"]
        lines.append(f"{cls}: detected {c['detection_rate_all']:.2f} at 5 % false alarms, "
                     + (f"smallest severity detected {least:.3g}" if _number(least)
                        else "no record detected"))
    for rid, err in res["errors"].items():
        lines.append(f"record {rid}: {err}")
    for rid, why in res["unreadable"].items():
        lines.append(f"record {rid} skipped: {why}")
    if res["report"]:
        lines.append(f"wrote {res['report']}")
    return "\n".join(lines)
