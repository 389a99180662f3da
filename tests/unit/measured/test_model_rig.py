"""The model rig of a record's metadata: what the model simulates is what was documented."""

from dataclasses import replace

import pytest

from cmsim.errors import ParameterError
from cmsim.frequencies import rig_frequencies
from cmsim.measured.model_rig import documented_frequencies, model_rig
from cmsim.measured.schema import rig_geometry
from cmsim.rig import OperatingPoint, Rig, RollingBearing


def _gearbox_on_other_bearings():
    base = Rig.paper_2016()
    small = RollingBearing.from_pitch(8, 7.0e-3, 33.0e-3)
    big = RollingBearing.from_pitch(12, 11.0e-3, 60.0e-3)
    s1, s2 = base.shafts
    return replace(base, shafts=(replace(s1, bearing_1=small, bearing_2=big),
                                 replace(s2, bearing_1=big)))


def test_a_gear_rig_simulates_its_documented_bearings_at_their_shafts():
    """The documented bearings sit at their shafts' nodes (the sensor's is read on the right
    shaft), so the model's defect lines are the documented ones; an undocumented node keeps
    the paper's bearing, and the notes say so."""
    rig = _gearbox_on_other_bearings()
    geometry = rig_geometry(rig)
    del geometry["bearings"]["2b2"]
    got, components, notes = model_rig(geometry, near="1b2")
    assert components["1b1"] == "1b2" and components["1b2"] == "1b1"   # the sensor's first
    assert components["2b1"] == "2b1" and "2b2" not in components
    op = OperatingPoint(speed_rpm=1500.0)
    doc = documented_frequencies(geometry, op.shaft_hz)
    model = rig_frequencies(got, op)
    for node, key in components.items():
        if "b" in node:
            assert model.bearing(node).bpfo_hz == pytest.approx(doc.bearing(key).bpfo_hz,
                                                                rel=1e-9)
            assert model.bearing(node).bpfi_hz == pytest.approx(doc.bearing(key).bpfi_hz,
                                                                rel=1e-9)
    paper = Rig.paper_2016().shafts[1].bearing_2
    assert got.shafts[1].bearing_2 == paper
    assert got.shafts[0].bearing_1.clearance_m == paper.clearance_m   # undocumented: paper's
    assert any("2b2" in n and "undocumented" in n for n in notes)
    assert got.gears.driving.n_teeth == rig.gears.driving.n_teeth


def test_a_gear_rig_without_documented_bearings_keeps_the_papers():
    geometry = {"gears": [{"stage": 1, "input_teeth": 32, "output_teeth": 80}],
                "bearings": None}
    got, components, notes = model_rig(geometry)
    assert got.bearings == Rig.paper_2016().bearings
    assert set(components) == {"1G1", "2G1"}
    assert any("1b1, 1b2, 2b1, 2b2" in n for n in notes)


def test_three_bearings_on_one_shaft_of_a_gear_rig_is_bad_metadata():
    b = {"n_balls": 9, "ball_diameter_mm": 8.0, "pitch_diameter_mm": 40.0, "shaft": "input"}
    geometry = {"gears": [{"stage": 1, "input_teeth": 20, "output_teeth": 40}],
                "bearings": {"a": b, "b": b, "c": b}}
    with pytest.raises(ParameterError, match="3 bearings on the input shaft"):
        model_rig(geometry)


def _ball_bearing(**kw):
    return {"n_balls": 9, "ball_diameter_mm": 7.94, "pitch_diameter_mm": 39.04, **kw}


def test_lab_spellings_of_a_gearbox_s_geometry_are_read_as_documented():
    """What a lab writes for the same gearbox (found by a probe of documentation variants,
    2026-12-02): tooth counts in quotes crashed the command ("internal error"); a bearing
    known by its designation alone (numbers null) refused the record; a ``shaft`` that
    names its shaft in words dropped the documented bearings for the paper's silently."""
    words = {"gears": [{"stage": 1, "input_teeth": "25", "output_teeth": 55.0}],
             "bearings": {"de": _ball_bearing(shaft="input shaft (pinion)"),
                          "nde": {"model": "6205", "n_balls": None,
                                  "ball_diameter_mm": None, "pitch_diameter_mm": None},
                          "out": _ball_bearing(shaft="Output")}}
    rig, components, notes = model_rig(words, near="de")
    assert (rig.gears.driving.n_teeth, rig.gears.driven.n_teeth) == (25, 55)
    assert components["1b1"] == "de" and components["2b1"] == "out"
    assert "nde" not in components.values()
    assert any("nde" in n and "6205" in n and "undocumented" in n for n in notes)
    plain = {"gears": [{"stage": 1, "input_teeth": 25, "output_teeth": 55}],
             "bearings": {"de": _ball_bearing(shaft="input"),
                          "out": _ball_bearing(shaft="output")}}
    same, _, _ = model_rig(plain, near="de")
    assert rig.shafts[0].bearing_1 == same.shafts[0].bearing_1
    assert rig.shafts[1].bearing_1 == same.shafts[1].bearing_1
    assert documented_frequencies(words, 25.0).bearing("out").bpfo_hz == pytest.approx(
        documented_frequencies(plain, 25.0).bearing("out").bpfo_hz)


@pytest.mark.parametrize("change, match", [
    ({"input_teeth": "25 teeth"}, "input_teeth must be a whole number"),
    ({"input_teeth": 25.5}, "input_teeth must be a whole number"),
    ({"shaft": "high-speed"}, "shaft 'high-speed': say which shaft"),
    ({"ball_diameter_mm": None}, "gives n_balls, pitch_diameter_mm but not ball_diameter_mm"),
])
def test_a_gearbox_s_geometry_that_cannot_be_read_is_refused_naming_the_key(change, match):
    stage = {"stage": 1, "input_teeth": 25, "output_teeth": 55}
    bearing = _ball_bearing(shaft="input")
    for k, v in change.items():
        (stage if k in stage else bearing)[k] = v
    with pytest.raises(ParameterError, match=match):
        model_rig({"gears": [stage], "bearings": {"de": bearing}}, near="de")


@pytest.mark.parametrize("gears", [None, [{"stage": 1, "input_teeth": 20, "output_teeth": 40}]])
def test_a_documented_contact_angle_sets_the_models_defect_lines(gears):
    """An angular-contact bearing's 40° moves its defect lines (cos α in the cage speed): the
    model rig's lines are the documented ones, on a bearing rig and on a gearbox; a 0° deep
    groove bearing keeps the operating angle its clearance gives; past the model's 45° is
    refused naming the metadata key. (The angle was read for the labels only: the model
    simulated 0°.)"""
    geometry = {"gears": gears, "bearings": {"de": _ball_bearing(contact_angle_deg=40.0,
                                                                 shaft="input")}}
    got, components, _ = model_rig(geometry, near="de")
    node = next(n for n, k in components.items() if k == "de")
    op = OperatingPoint(speed_rpm=1800.0)
    model = rig_frequencies(got, op).bearing(node)
    doc = documented_frequencies(geometry, op.shaft_hz).bearing("de")
    assert model.bpfi_hz == pytest.approx(doc.bpfi_hz, rel=1e-9)
    deep = {"gears": gears, "bearings": {"de": _ball_bearing(contact_angle_deg=0.0,
                                                             shaft="input")}}
    free, comps, _ = model_rig(deep, near="de")
    free_node = next(n for n, k in comps.items() if k == "de")
    assert rig_frequencies(free, op).bearing(free_node).bpfi_hz < 0.97 * model.bpfi_hz \
        or rig_frequencies(free, op).bearing(free_node).bpfi_hz > 1.03 * model.bpfi_hz
    with pytest.raises(ParameterError, match="contact_angle_deg"):
        model_rig({"gears": gears, "bearings": {"de": _ball_bearing(contact_angle_deg=60.0,
                                                                    shaft="input")}})
