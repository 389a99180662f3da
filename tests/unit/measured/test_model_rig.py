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
