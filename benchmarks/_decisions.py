"""The decision inputs of a comparison, kept and replayed.

:func:`spy_on_decisions` keeps what :func:`cmsim.discrepancy.ranking.decide` was given (each
ranked cause's evidence per feature, and the features it was judged on), so that a row of
``bench_compare.py`` or ``validate_real.py`` carries it under ``"decide"``;
:func:`replay` decides those rows again with the current rule, without a simulation — a
change to the decision rule is measured on every recorded comparison in seconds::

    python benchmarks/_decisions.py bench.json real.json

A rule that needs more than the recorded evidence (the features' line frequencies, the
nominal χ² per feature) cannot be replayed from these rows.
"""

import importlib
import json
import sys


def spy_on_decisions():
    """Wrap :func:`cmsim.discrepancy.compare.decide` in this process (once) and return the
    dict where the last call's inputs are kept under ``"decide"``."""
    cm = importlib.import_module("cmsim.discrepancy.compare")
    seen = getattr(cm.decide, "seen", None)
    if seen is not None:
        seen.clear()
        return seen
    original = cm.decide
    seen = {}

    def decide(ranked, sensor_bearing, chi_nominal):
        seen["decide"] = {
            "sensor_bearing": sensor_bearing, "chi_nominal": chi_nominal,
            "ranked": [{"name": r["name"], "component": r["component"],
                        "fault": r["cause"].signature is not None,
                        "delta_chi2": r["delta_chi2"], "judged_on": r["judged_on"],
                        "per_feature": r["per_feature"]} for r in ranked]}
        return original(ranked, sensor_bearing, chi_nominal)

    decide.seen = seen
    cm.decide = decide
    return seen


def replay(recorded):
    """(finding or None, near ties) of the current rule on one recorded ``"decide"`` dict."""
    from cmsim.discrepancy.causes import CAUSES
    from cmsim.discrepancy.ranking import decide
    ranked = []
    for r in recorded["ranked"]:
        cause = CAUSES[r["name"]]()
        ranked.append({**r, "cause": cause,
                       "family": cause.family(r["judged_on"], r["component"])})
    top, ties = decide(ranked, recorded["sensor_bearing"], recorded["chi_nominal"])
    return (None if top is None else top["name"]), [t["name"] for t in ties]


def main(paths):
    """Print every recorded finding the current rule changes, per file."""
    for path in paths:
        d = json.loads(open(path).read())
        rows = d["rows"] if isinstance(d, dict) and "rows" in d else d
        items = rows.items() if isinstance(rows, dict) else enumerate(rows)
        n = changed = 0
        for key, row in items:
            if not isinstance(row, dict) or row.get("decide") is None:
                continue
            n += 1
            new, _ = replay(row["decide"])
            old = row["finding"] if row["finding"] not in ("none", "unexplained") else None
            if new != old:
                changed += 1
                print(f"{path}: {row.get('effect', key)} {row.get('seed', '')}: "
                      f"{old or '-'} -> {new or '-'}")
        print(f"{path}: {n} recorded decisions, {changed} changed")


if __name__ == "__main__":
    main(sys.argv[1:])
