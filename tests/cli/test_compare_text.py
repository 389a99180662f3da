"""`cmsim compare`'s text: the leading causes' evidence says what it was measured on, as the
decision measured it (each fault's own features when named on its family and without a
machine; every feature when a machine's whole-record reading named it)."""

import pytest

from cmsim.cli.compare import text

CAUSE = {"name": "bearing_outer_race", "component": "drive_end", "delta_chi2": 42.0,
         "judged_on": 7, "delta_chi2_all": 55.0}


def _res(mode, decided_on):
    return {"words": "outer-race defect", "finding": "bearing_outer_race",
            "component": "drive_end", "mode": mode, "record": {"machine": "m"},
            "not_judged": [], "near_ties": [], "departures": [], "discrepancies": [],
            "gain": {"before": 3.0, "after": 1.0, "relative": 0.67}, "causes": [CAUSE],
            "decided_on": decided_on, "notes": [], "inferred": {}, "simulations": 1,
            "wall_s": 0.4, "report": None}


@pytest.mark.parametrize("mode, decided_on, header, row", [
    ("machine", "whole", "leading causes, by their evidence against the machine's baseline "
     "(Δχ² over every feature", "evidence    42.0\n"),
    ("machine", "family", "leading faults, by their evidence against the machine's baseline "
     "on the features their own signature moves", "evidence    42.0 on 7 features\n"),
    ("path-free", "", "leading causes, by their evidence (Δχ²) on the features each moves",
     "evidence    42.0 on 7 features (all: 55.0)\n")])
def test_the_leading_causes_say_what_their_evidence_was_measured_on(mode, decided_on, header,
                                                                     row):
    out = text(_res(mode, decided_on))
    assert header in out
    assert f"bearing_outer_race   drive_end  {row}" in out + "\n"
    assert ("named because" in out) == (mode == "machine")
