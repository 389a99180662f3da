"""The HTML reports a user reads (issue 48): no raw JSON, no "None" in a table, titles that
fit their figure, axis units without the metadata's remarks.

Test tier: behaviour (no physics judged). One comparison with a report, read as text.
"""

import json
import re

import numpy as np

from cmsim.cli import main
from cmsim.discrepancy.report import _in_words
from cmsim.discrepancy.synthetic import hidden_effect_record
from cmsim.machine.report import _unit_symbol


def test_values_read_as_words():
    assert _in_words({"size_m": 0.000312345, "bearing": "1b1", "x": None}) == \
        "size_m 0.0003123, bearing 1b1, x —"
    assert _in_words({"speed_rpm": {"value": 1797.0, "how": "comb"}}, "(", ")") == \
        "(speed_rpm (value 1797, how comb))"
    assert _in_words({}) == "" and _in_words(None, "(", ")") == ""


def test_an_axis_unit_drops_the_metadatas_remark():
    assert _unit_symbol("g (believed)") == "g" and _unit_symbol("m/s^2") == "m/s^2"
    assert _unit_symbol(None) == "unit" and _unit_symbol("unknown") == "unit"


def test_the_compare_report_shows_no_json_and_no_none(tmp_path, capsys):
    h = hidden_effect_record("bearing_outer_race", 1003)
    folder = tmp_path / "rec"
    folder.mkdir()
    np.savez(folder / "r.npz", DE=np.asarray(h.record.run["DE"], np.float32))
    geometry = {"gears": None, "bearings": {"de": {
        "n_balls": 9, "ball_diameter_mm": 7.94, "pitch_diameter_mm": 39.04}}}
    (folder / "metadata.json").write_text(json.dumps({
        "fs_hz": 12000.0, "sensors": {"DE": {"near": "de", "unit": "g (believed)"}},
        "geometry": geometry,
        "recordings": [{"file": "r.npz", "shaft_speed_rpm": h.record.op.speed_rpm}]}))
    assert main(["compare", str(folder / "r.npz"), "--budget", "12", "--report",
                 str(tmp_path / "rep"), "--json"]) == 0
    capsys.readouterr()
    page = (tmp_path / "rep" / "compare.html").read_text()
    text = re.sub(r'src="data:[^"]*"', "", page)
    assert not re.search(r'\{&quot;|\{"', text), "raw JSON in the report"
    assert ">None<" not in text and "(None)" not in text


def test_a_size_read_as_a_trend_carries_no_range():
    """A cause named on a library variant whose change is scaled off the calibrated path's
    gain: its size is a trend, so the words give no range around it (CWRU's 0.18-mm inner
    race read "about 2.5 mm (2.5-3 mm) ... read its size as a trend"); on the path's own
    gain they do."""
    from cmsim.discrepancy.compare import _a_trend, _variant_words, describe

    params, ranges = {"size_m": 2.5e-3}, {"size_m": (2.5e-3, 3e-3)}
    top = {"variant": "5 um preload; path x0.3"}
    words = describe("bearing_inner_race", "drive_end", params,
                     {} if _a_trend(top) else ranges, against="baseline")
    words += _variant_words(top["variant"])
    assert "2.5-3 mm" not in words and "read its size as a trend" in words, words
    assert not _a_trend({"variant": "5 um preload"})
    assert "2.5-3 mm" in describe("bearing_inner_race", "drive_end", params, ranges,
                                  against="baseline")
