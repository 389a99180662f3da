"""Shaft lines read over a floor that fell (cmsim.discrepancy.shaft_lines): the floor's change
in closed form, and which rows it holds back. The judge's whole path is in test_judge.py."""

from types import SimpleNamespace

import numpy as np
import pytest

from cmsim.discrepancy.shaft_lines import (FLOOR_BORNE_SHARE, LINE_RISE_DB, floor_borne,
                                           floor_change_db, held_lines, line_fell)
from cmsim.frequencies import BearingFrequencies, RigFrequencies

FS = 12_000.0
NAMES = ["raw_fr_h1_db", "raw_fr_h2_db", "gmf2_rel_db", "shape_b3_db"]
FREQS = RigFrequencies(fr1_hz=30.0, bearings={
    "1b1": BearingFrequencies(30.0, 12.0, 107.0, 163.0, 70.0, 107.0)})


def _noise(seed, rms, seconds=4.0):
    return rms * np.random.default_rng(seed).standard_normal(int(seconds * FS))


def _record(x, unit_scale=1.0):
    return SimpleNamespace(signal=x, fs_hz=FS, unit_scale=unit_scale,
                           model_frequencies=lambda speed_rpm=1800.0: FREQS)


def _machine(baseline, unit_scale=1.0):
    return SimpleNamespace(baseline=SimpleNamespace(records=tuple(baseline)),
                           unit_scale=unit_scale, op=SimpleNamespace(speed_rpm=1800.0))


def _row(evidence, name="misalignment"):
    """A decision row whose evidence per feature is ``evidence`` (all judged on)."""
    return {"name": name, "per_feature": dict(evidence), "judged_on": list(evidence)}


def test_the_floor_s_change_is_the_broadband_s_in_closed_form():
    machine = _machine([_noise(1, 1.0)])
    # the median of a white spectrum scales with its RMS: half the RMS, -6.02 dB
    assert floor_change_db(_record(_noise(2, 0.5)), machine, 0.5) == pytest.approx(
        -6.02, abs=0.3)
    assert floor_change_db(_record(_noise(3, 1.0)), machine, 0.5) == pytest.approx(0.0,
                                                                                 abs=0.3)
    # read in m/s²: a record in a unit twice the baseline's, at half the numbers, is level
    assert floor_change_db(_record(_noise(2, 0.5), unit_scale=2.0), machine, 0.5) == \
        pytest.approx(0.0, abs=0.3)
    # where neither unit is known, both are the sensor's; where one only, nothing is read
    assert floor_change_db(_record(_noise(2, 0.5), None), _machine([_noise(1, 1.0)], None),
                           0.5) == pytest.approx(-6.02, abs=0.3)
    assert floor_change_db(_record(_noise(2, 0.5), None), machine, 0.5) is None
    assert floor_change_db(_record(_noise(2, 0.5)), _machine([]), 0.5) is None


def test_lines_that_rose_only_over_a_fallen_floor_are_held():
    base = np.zeros(len(NAMES))
    meas = np.array([8.5, 10.2, 0.0, 0.0])          # SpectraQuest's broken tooth, over the floor
    row = _row({"raw_fr_h1_db": 57.7, "raw_fr_h2_db": 62.9, "shape_b3_db": 3.0})
    rises = floor_borne(row, NAMES, meas, base, -8.6)
    assert rises == pytest.approx({"raw_fr_h1_db": -0.1, "raw_fr_h2_db": 1.6})
    # one line that rose the asked dB in absolute level: the cause reads a line of its own
    assert floor_borne(row, NAMES, meas, base, LINE_RISE_DB - 10.2) is None
    assert floor_borne(row, NAMES, meas, base, 0.0) is None


def test_a_cause_drawing_most_of_its_evidence_elsewhere_or_from_fallen_lines_is_not_held():
    base = np.zeros(len(NAMES))
    meas = np.array([8.5, 10.2, 5.0, 0.0])
    lines = 40.0
    rest = lines * (1.0 - FLOOR_BORNE_SHARE) / FLOOR_BORNE_SHARE + 1.0
    assert floor_borne(_row({"raw_fr_h1_db": lines, "gmf2_rel_db": rest}, "eccentricity"),
                       NAMES, meas, base, -8.6) is None
    # noise reads the lines fallen under a floor that rose: no line of it rose over its floor
    fallen = np.array([-8.5, -10.2, 0.0, 0.0])
    assert floor_borne(_row({"raw_fr_h1_db": 50.0, "raw_fr_h2_db": 50.0}, "noise"), NAMES,
                       fallen, base, 9.0) is None


def test_the_decision_is_taken_again_without_every_cause_the_floor_carries():
    base = np.zeros(len(NAMES))
    meas = np.array([8.5, 10.2, 0.0, 0.0])
    top = _row({"raw_fr_h1_db": 57.7, "raw_fr_h2_db": 62.9})
    other = _row({"raw_fr_h1_db": 61.6}, "unbalance")
    own = _row({"gmf2_rel_db": 20.0}, "tooth_fault")
    decision = {"top": top, "ranked": [top, other, own], "by_signature": [own, other]}
    quiet, loud = _noise(1, 1.0), _noise(2, 10 ** (-8.6 / 20))
    asked = []
    again = {"top": own, "finding": "tooth_fault"}

    def redecide(excluded):
        asked.append(set(excluded))
        return again

    got, notes = held_lines(decision, NAMES, meas, base,
                            floor_change_db(_record(loud), _machine([quiet]), 0.5), redecide)
    assert got is again and asked == [{"misalignment", "unbalance"}]
    assert "misalignment, unbalance not named" in notes[0]
    # the same lines over a floor that stayed: the decision stands, nothing asked again
    got, notes = held_lines(decision, NAMES, meas, base,
                            floor_change_db(_record(_noise(3, 1.0)), _machine([quiet]), 0.5),
                            redecide)
    assert got is decision and notes == [] and len(asked) == 1


@pytest.mark.parametrize("over_floor, floor_db, fell", [
    (-26.1, 24.9, False),       # a broken tooth's impacts lifted the floor 24.9 dB
    (-28.0, 0.0, True),
    (-2.0, 0.0, False),         # under a line's rise asked
    (-8.0, 4.0, True),
    (-8.0, None, True),         # the floor's change unknown: as read
])
def test_a_shaft_line_read_fallen_fell_only_where_it_fell_in_absolute_level(over_floor,
                                                                           floor_db, fell):
    """A shaft line read over its floor falls by the floor's rise alone where its level held
    (the angle generator's tooth fault: the 1x line 26.1 dB down over a floor 24.9 dB up); it
    fell where the line's change with the floor's reaches LINE_RISE_DB down."""
    assert line_fell("raw_fr_h1_db", 10.0 + over_floor, 10.0, floor_db) is fell
    assert line_fell("gmf2_rel_db", 10.0 + over_floor, 10.0, floor_db) is True
    assert floor_db is None or (over_floor + floor_db <= -LINE_RISE_DB) is fell
