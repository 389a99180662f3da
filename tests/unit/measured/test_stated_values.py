"""What a recording states, taken as it is meant (issue 48, silent wrong answers 4, 6, 7).

Tier: behaviour. The caller's --speed-rpm replaces the metadata's speed and says so; a CSV
written without a header keeps its first row and names its channels as a WAV's are; a unit
written in a file or metadata.json is checked against the unit table: an unknown one is
refused in one line, a velocity or a displacement is differentiated to the model's
acceleration and the record says so.
"""

import json
import shutil

import numpy as np
import pytest

from cmsim.cli import main
from cmsim.errors import ParameterError, RecordWarning
from cmsim.measured import data_root, read_record
from cmsim.measured.readers import read_file
from cmsim.measured.schema import rig_geometry
from cmsim.rig import preset

CWRU = data_root() / "cwru_bearing_12k_de"
needs_cwru = pytest.mark.skipif(not (CWRU / "metadata.json").is_file(),
                                reason="../shared/datasets/cwru_bearing_12k_de absent")


@needs_cwru
def test_speed_rpm_replaces_the_metadata_speed_and_says_so(capsys):
    """spectrum --speed-rpm 1801.6 on a record documented at 1797 rpm labels at 1801.6
    (it kept 1797 without a word), with one warning naming the option and both values."""
    path = str(CWRU / "IR007_0.npz")
    assert main(["spectrum", path, "--speed-rpm", "1801.6", "--top", "3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["families"]["fr"] == pytest.approx(1801.6 / 60, rel=1e-9)
    said = [w for w in out["warnings"] if "replaces" in w]
    assert len(said) == 1 and "--speed-rpm 1801.6 replaces 1797 rpm" in said[0], said
    assert "speed_rpm" not in out["inferred"]           # used as given, not refined


def _metadata(folder, channels, unit=None, fs_hz=12000.0):
    """A metadata.json for a bearing rig (the CWRU preset's geometry) beside the file."""
    meta = {"fs_hz": fs_hz, "geometry": rig_geometry(preset("cwru_6205")),
            "sensors": {c: {"near": "1b1", "unit": unit} for c in channels},
            "recordings": [{"file": "r.csv", "shaft_speed_rpm": 1797.0}]}
    (folder / "metadata.json").write_text(json.dumps(meta))


def test_a_csv_without_a_header_keeps_its_first_row(tmp_path):
    """A headerless CSV: every row is data (the first was eaten as channel names such as
    "-0.083..."), the channels named ch0, ch1 (or the entry's names), a first column rising
    evenly is the time base."""
    rng = np.random.default_rng(0)
    x = rng.standard_normal((5000, 2))
    np.savetxt(tmp_path / "r.csv", x, delimiter=",")
    f = read_file(tmp_path / "r.csv")
    assert list(f.signals) == ["ch0", "ch1"] and f.rate_hz is None
    np.testing.assert_allclose(f.signals["ch0"], x[:, 0])
    t = np.arange(5000) / 12000.0
    np.savetxt(tmp_path / "t.csv", np.column_stack([t, x]), delimiter=";")
    f = read_file(tmp_path / "t.csv", ["DE", "FE"])
    assert list(f.signals) == ["DE", "FE"] and f.rate_hz == pytest.approx(12000.0)
    np.testing.assert_allclose(f.signals["FE"], x[:, 1])


@pytest.mark.parametrize("where", ["file", "metadata"])
def test_an_unknown_unit_is_refused_in_one_line(tmp_path, capsys, where):
    """A channel in "furlongs" (written in the CSV header or in metadata.json) is refused,
    naming the unit, where it is written and the known units; it was compared as if it
    had no unit."""
    x = np.random.default_rng(1).standard_normal(8192)
    head = "DE [furlongs]" if where == "file" else "DE"
    np.savetxt(tmp_path / "r.csv", x, header=head, comments="", delimiter=",")
    _metadata(tmp_path, ["DE"], unit="furlongs" if where == "metadata" else None)
    with pytest.raises(ParameterError, match=r"'furlongs', a unit cmsim does not know; "
                                             r"known: g, m/s2"):
        read_record(tmp_path / "r.csv")
    assert main(["spectrum", str(tmp_path / "r.csv"), "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert ("the file" if where == "file" else "metadata.json") in err, err


@pytest.mark.parametrize("unit, order, factor", [("mm/s", 1, 1e-3), ("um", 2, 1e-6),
                                                 ("in/s", 1, 0.0254)])
def test_a_velocity_or_displacement_is_differentiated_and_said(tmp_path, unit, order,
                                                               factor):
    """A channel in mm/s (or µm, in/s) is read as the acceleration the model makes, in
    m/s² (amplitude (2πf)^order × factor × A at every frequency), and a RecordWarning and
    the notes say so; it was compared with the acceleration model as it was."""
    fs, n = 12000.0, 24000
    t = np.arange(n) / fs
    x = 3.0 * np.sin(2 * np.pi * 500.0 * t) + 1.0 * np.sin(2 * np.pi * 1500.0 * t)
    np.savetxt(tmp_path / "r.csv", x, header=f"DE [{unit}]", comments="", delimiter=",")
    _metadata(tmp_path, ["DE"])
    with pytest.warns(RecordWarning, match=rf"'DE' is a \w+ in '{unit}'.*differentiated"):
        rec = read_record(tmp_path / "r.csv")
    a = rec.signals["DE"][2400:-2400]           # 0.625-Hz bins: the tones on bins
    spec = np.abs(np.fft.rfft(a * np.hanning(a.size))) / (np.hanning(a.size).sum() / 2)
    freq = np.fft.rfftfreq(a.size, 1 / fs)
    for f0, amp in ((500.0, 3.0), (1500.0, 1.0)):
        want = amp * factor * (2 * np.pi * f0) ** order
        assert spec[np.argmin(abs(freq - f0))] == pytest.approx(want, rel=0.02)
    assert rec.meta["units"]["DE"] == "m/s^2" and rec.unit_scale == 1.0
    assert any("differentiated" in s for s in rec.meta["notes"])


def test_units_of_the_cwru_metadata_still_read(tmp_path):
    """"g (believed)" (a unit and a remark) and "unknown" are not refused."""
    from cmsim.measured.schema import unit_kind
    assert unit_kind("g (believed)") == ("acceleration", 9.80665)
    assert unit_kind("unknown") == (None, None) and unit_kind(None) == (None, None)
    assert unit_kind("V") == ("other", None)
    if (CWRU / "metadata.json").is_file():
        shutil.copytree(CWRU, tmp_path / "cwru")
        assert read_record(tmp_path / "cwru" / "normal_0.npz").unit_scale == 9.80665


def test_a_file_key_is_not_read_as_an_option(tmp_path, capsys):
    """An .npz states its rate in an array named fs_hz: a message quotes the key (it read
    "its --fs-hz array" on the command line, an option the file does not have)."""
    x = np.random.default_rng(2).standard_normal(8192)
    np.savez(tmp_path / "r.npz", DE=x, fs_hz=np.float64(12000.0))
    assert main(["spectrum", str(tmp_path / "r.npz"), "--fs-hz", "48000", "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert 'its "fs_hz" array says sample rate 12000 Hz but --fs-hz says 48000 Hz' in err, err


def test_a_nominal_speed_the_shaft_comb_confirms_is_not_moved_by_the_coarse_search():
    """A nominal 965 rpm whose shaft comb stands clear at 964.5 rpm (0.05 % off) was moved
    1 % (955.35 or 974.65 rpm) to where the rig's families' lines stood highest in steps of
    1 %, and the findings with it (a probe's healthy gear record named a tooth fault). A
    comb that confirms the speed keeps it; with no clear comb the coarse search still
    moves it."""
    from types import SimpleNamespace

    from cmsim.measured.record import _refined_speed

    fs, f = 12_000.0, 964.5 / 60.0
    t = np.arange(int(10 * fs)) / fs
    rng = np.random.default_rng(0)
    comb = sum(np.sin(2 * np.pi * k * f * t + k) for k in (1, 2, 3, 4)) \
        + 0.05 * rng.standard_normal(t.size)
    check = SimpleNamespace(verdict="agrees", speed_scale=1.01,
                            family=SimpleNamespace(family=SimpleNamespace(name="BPFO")))
    inferred = {}
    speed, uncertainty = _refined_speed(comb, fs, 965.0, None, check, 0.03, inferred)
    assert speed == 965.0 and uncertainty < 0.03 and not inferred
    noise = rng.standard_normal(t.size)
    speed, _ = _refined_speed(noise, fs, 965.0, None, check, 0.03, inferred)
    assert speed == pytest.approx(974.65) and "searched within its 3 %" in (
        inferred["speed_rpm"]["how"])


@pytest.mark.parametrize("unit, factor", [("g's", 9.80665), ("Gs", 9.80665), ("m/s/s", 1.0),
                                          ("mm/s/s", 1e-3)])
def test_lab_spellings_of_an_acceleration_unit_are_read(unit, factor):
    """``g's``, ``Gs`` and ``m/s/s`` (US lab sheets) were refused as unknown units."""
    from cmsim.measured.schema import unit_kind

    assert unit_kind(unit) == ("acceleration", pytest.approx(factor))


def test_an_undocumented_speed_of_a_gear_rig_is_read_on_its_mesh_lines():
    """The comb's grid moved the third mesh harmonic (90 shaft orders of a 30-tooth pinion)
    5.7 bins from one point to the next: the mesh lines fell between the points, and the
    healthy record of the angle-domain generator's gear machine 3 read 0.2 % fast (its
    second healthy record 0.1 % slow, and `unexplained` against the first). Read within
    0.01 % now."""
    from cmsim.discrepancy.angle_domain import draw_machine, synthesise
    from cmsim.measured.inference import estimate_shaft_hz

    m = draw_machine(3, kind="gear")
    x = synthesise(m, None, 1.0, duration_s=10.0, seed=100)
    got, _ = estimate_shaft_hz(x, m.fs_hz, lo_hz=5.0, hi_hz=100.0, teeth=m.teeth)
    assert got == pytest.approx(m.speed_rpm / 60.0, rel=1e-4)
