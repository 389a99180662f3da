"""Discrepancy loop (issue 12): records, blindness to the answer key, hidden effects, CLI.

Tier: behaviour tests against hidden truth (records made by the model with one hidden effect
and nuisances the pipeline is not told about) plus contract tests of the record reader.
The hidden-effect tests use a few seeds (the large version is benchmarks/bench_compare.py);
the ones that run several comparisons are marked slow.
"""

import json
import math
import os
import shutil
import wave

import numpy as np
import pytest

from cmsim.discrepancy import CAUSES, Cause, compare, register_cause
from cmsim.discrepancy.causes import applicable_causes
from cmsim.discrepancy.compare import DEFAULT_BUDGET
from cmsim.discrepancy.ranking import MIN_SIGNATURE_DELTA_CHI2
from cmsim.measured import RECORDING_KEYS, data_root, estimate_shaft_hz, read_record
from cmsim.discrepancy.synthetic import cwru_like_rig, hidden_effect_record
from cmsim.errors import ParameterError, RecordWarning
from cmsim.features import relative_features
from cmsim.frequencies import rig_frequencies

DATA = data_root()
REQUIRED = ("eccentricity", "tooth_fault", "bearing_outer_race", "bearing_inner_race",
            "bearing_ball", "rolling_slip", "clearance", "preload", "friction",
            "torque_mismatch", "speed_fluctuation", "transfer_path", "noise")

#: Severity recovered within this factor (log error <= log 2).
SEVERITY_FACTOR = 2.0


def _write_dataset(folder, x, fs, *, name="rec.npz", extra=None, speed_rpm=1797.0,
                   fs_in_meta=True):
    folder.mkdir(parents=True, exist_ok=True)
    np.savez(folder / name, DE=np.asarray(x, dtype=np.float32))
    rec = {"file": name, "n_samples": int(len(x)), "shaft_speed_rpm": speed_rpm,
           "channels": ["DE"], **(extra or {})}
    if fs_in_meta:
        rec["fs_hz"] = fs
    meta = {"fs_hz": fs if fs_in_meta else None,
            "channels": {"DE": "drive end"},
            "sensors": {"DE": {"near": "drive_end", "direction": "radial", "unit": "g"}},
            # the rig the records are made on (cwru_like_rig): both its bearings, so that
            # the reader's rate/speed check sees every family the signal holds
            "geometry": {"gears": None, "bearings": {
                "drive_end": {"n_balls": 9, "ball_diameter_mm": 7.94,
                              "pitch_diameter_mm": 39.04, "contact_angle_deg": 0.0,
                              "shaft": "input"},
                "fan_end": {"n_balls": 8, "ball_diameter_mm": 6.75,
                            "pitch_diameter_mm": 28.5, "contact_angle_deg": 0.0,
                            "shaft": "input"}}},
            "recordings": [rec]}
    (folder / "metadata.json").write_text(json.dumps(meta))
    return folder / name


def test_catalogue_holds_the_issue_causes():
    assert set(REQUIRED) <= set(CAUSES)
    for name in REQUIRED:
        c = CAUSES[name]()
        for p in c.params:
            lo, hi = p.bounds
            assert 0 < lo < hi, (name, p.name)
            assert all(lo <= v <= hi for v in p.probes), (name, p.name)
            assert lo <= p.middle() <= hi
        assert c.post_dynamics or all(p.probes for p in c.params), name
    names = {c.name for c in applicable_causes(cwru_like_rig())}
    assert "bearing_outer_race" in names and "eccentricity" not in names


def test_a_user_cause_is_one_small_class():
    @register_cause
    class _Gain(Cause):
        name = "test_only_gain"
        parameter = "noise_ratio"
        bounds = (0.01, 1.0)
        probes = (0.5,)

        def apply(self, setup, value, component):
            from dataclasses import replace
            return replace(setup, noise_ratio=value)
    try:
        assert any(c.name == "test_only_gain" for c in applicable_causes(cwru_like_rig()))
    finally:
        del CAUSES["test_only_gain"]


def test_features_do_not_depend_on_scale():
    fs = 12000.0
    rng = np.random.default_rng(0)
    t = np.arange(6000) / fs
    x = np.sin(2 * np.pi * 30 * t) + 0.3 * rng.standard_normal(t.size)
    freqs = rig_frequencies(cwru_like_rig(), __import__("cmsim").OperatingPoint(1800.0))
    a = relative_features(x, fs, freqs, ["1b1"])
    b = relative_features(1234.5 * x, fs, freqs, ["1b1"])
    assert a.keys() == b.keys()
    for k in a:
        assert a[k] == pytest.approx(b[k], abs=1e-6), k
    assert a["raw_fr_h1_db"] > 20.0          # the 30-Hz line stands out of the floor


def test_speed_estimate_finds_the_shaft_comb():
    fs = 12000.0
    t = np.arange(48000) / fs
    rng = np.random.default_rng(1)
    x = sum(np.sin(2 * np.pi * k * 29.3 * t) / k for k in range(1, 5))
    x = x + 0.5 * rng.standard_normal(t.size)
    f, score = estimate_shaft_hz(x, fs, lo_hz=10.0, hi_hz=60.0)
    assert f == pytest.approx(29.3, rel=2e-3)
    assert score > 10.0


def test_reader_ignores_the_answer_key_and_infers_speed(tmp_path):
    fs = 12000.0
    t = np.arange(60000) / fs
    x = np.sin(2 * np.pi * 29.95 * t) + 0.1 * np.random.default_rng(2).standard_normal(t.size)
    p = _write_dataset(tmp_path / "d", x, fs, extra={"condition": "faulty",
                                                    "fault_location": "inner_race",
                                                    "fault_diameter_in": 0.007})
    rec = read_record(p)
    assert rec.fs_hz == pytest.approx(fs)
    assert rec.model_signal == "accel_1b1_y" and rec.components["1b1"] == "drive_end"
    assert rec.run.source == "measured"
    text = json.dumps(rec.run.meta)
    for word in ('"condition"', '"fault_location"', "faulty", "rec.npz", "fault_diameter"):
        assert word not in text
    assert "condition" not in RECORDING_KEYS
    # speed left out: estimated from the spectrum and reported as inferred
    p2 = _write_dataset(tmp_path / "e", x, fs, speed_rpm=None)
    rec2 = read_record(p2)
    assert rec2.inferred["speed_rpm"]["value"] == pytest.approx(60 * 29.95, rel=3e-3)


def test_reader_csv_wav_and_errors(tmp_path, monkeypatch):
    fs = 8000.0
    x = np.random.default_rng(3).standard_normal(8000)
    folder = tmp_path / "f"
    p = _write_dataset(folder, x, fs)
    import pandas as pd
    pd.DataFrame({"DE": x}).to_csv(folder / "rec.csv", index=False)
    meta = json.loads((folder / "metadata.json").read_text())
    meta["recordings"].append(dict(meta["recordings"][0], file="rec.csv"))
    meta["recordings"].append(dict(meta["recordings"][0], file="rec.wav"))
    (folder / "metadata.json").write_text(json.dumps(meta))
    with wave.open(str(folder / "rec.wav"), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(int(fs))
        w.writeframes((x / np.abs(x).max() * 30000).astype("<i2").tobytes())
    a = read_record(folder / "rec.csv").signal
    assert np.allclose(a, x - x.mean(), atol=1e-6)
    with pytest.warns(RecordWarning, match="integer counts"):   # int16, no calibration
        w = read_record(folder / "rec.wav", channel="DE")
    assert w.fs_hz == pytest.approx(fs) and w.signal.size == x.size
    monkeypatch.setenv("CMSIM_DATA", str(tmp_path))
    assert read_record("f/rec.npz").fs_hz == pytest.approx(fs)
    with pytest.raises(ParameterError, match="channel"):
        read_record(p, channel="nosuch")
    with pytest.raises(ParameterError, match="does not exist"):
        read_record(tmp_path / "nosuch.npz")
    bare = tmp_path / "bare"
    bare.mkdir()
    np.savez(bare / "x.npz", DE=x)
    with pytest.raises(ParameterError, match="metadata.json"):
        read_record(bare / "x.npz")


def _hidden(effect, seed, sim_seed=0):
    """A hidden-effect record and its comparison (the seeds of bench_compare.py's seed
    ``seed - 1000``, so a test row is a benchmark row)."""
    h = hidden_effect_record(effect, seed)
    return h, compare(h.record, seed=sim_seed)


def test_inner_race_is_found_sized_and_the_gain_is_positive():
    h, c = _hidden("bearing_inner_race", 1002)      # on the drive end, 0.68 mm
    assert c.finding == "bearing_inner_race"
    assert c.component == h.component
    fitted = c.parameters["size_m"]
    assert abs(math.log(fitted / h.value)) <= math.log(SEVERITY_FACTOR)
    assert c.gain["relative"] > 0.3
    assert c.gain["after"] < c.gain["before"]
    assert c.simulations <= DEFAULT_BUDGET
    d = c.to_dict()
    for key in ("discrepancies", "causes", "finding", "gain", "simulations", "wall_s"):
        assert key in d
    assert {"before", "after", "relative"} <= set(d["gain"])
    assert {"feature", "measured", "simulated"} <= set(d["discrepancies"][0])
    assert {"name", "component", "score", "parameters"} <= set(d["causes"][0])
    json.dumps(d)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason=(
    "finding (issue 25): an inner-race defect on the fan-end bearing read through the "
    "drive-end sensor (seed 1000) is named a ball defect of that bearing: the lower shaft "
    "sideband of its BPFI (148.2 - 29.95 = 118.2 Hz) sits within 1 % of the bearing's 2xBSF "
    "(119.4 Hz), so the ball's signature gains 56 against the inner race's 45 (0.797 of it, "
    "just under a near tie); over every feature the inner race explains twice as much (279 "
    "against 129), but a cause is judged on its own signature. Tried and reverted (2026-11-26): "
    "judging two faults that stand out on the union of their families names it, but turns "
    "the real CWRU OR007_at6_0 against its machine into an inner race (the inner race's "
    "simulation moves the BPFO columns by 49, more than the outer race's 43, through the "
    "envelope floor, with no line shared); counting only columns whose lines meet within "
    "2 % finds the fan-end BPFO +- fr (121.4 Hz) on the same 2xBSF and names an outer race"))
def test_inner_race_on_the_far_bearing_whose_sideband_falls_on_2bsf():
    h, c = _hidden("bearing_inner_race", 1000)
    assert h.component == "fan_end"
    assert c.finding == "bearing_inner_race"


def test_clean_record_reports_no_discrepancy():
    h, c = _hidden(None, 1000)
    assert c.finding == "none"
    assert c.parameters == {}
    assert c.causes[0]["delta_chi2"] < MIN_SIGNATURE_DELTA_CHI2


#: Effects named in every seed of the benchmark (benchmarks/bench_compare.py, 4 seeds), with
#: the factor within which their severity is recovered there (None: not identifiable beyond
#: a threshold, see docs/validation.md).
NAMED = {"bearing_outer_race": 2.0, "bearing_ball": 2.0, "clearance": 2.0,
         "transfer_path": 2.0, "noise": 2.0, "rolling_slip": 2.0, "preload": None,
         "speed_fluctuation": 2.0, "tooth_fault": None}


#: Least held-out gain of a named effect. The outer race on seed 1000 is the lowest: 0.29 since
#: rk4 integrates the 12-kHz bearing records (the fit stops at 1.9 mm for the true 1.25 mm;
#: ode3 reached 0.78 at 1.48 mm), 0.50-0.69 on sim seed 1 and record seeds 1001 and 1003.
MIN_NAMED_GAIN = 0.25


#: Effects the documented model does not name on seed 1000 (the transfer path since the band
#: rule reads the prediction residual): a strict xfail says when that changes. (Misalignment,
#: missed while the shaft forces modulated the whole bearing force — under its negative
#: static load the rotating force cancelled —, is named since.)
NOT_NAMED = {
    "transfer_path": "housing modes moved x0.67: the path's evidence is 24.6 (the shape bands "
                     "+2.5 to +5.3 each, the envelope families -4 to +5.5 as the band each "
                     "segment's residual picks moves with the modes) against the 30 a "
                     "reshaping cause needs; with the signal's own kurtogram band it was named",
}


def _not_named(effect):
    return pytest.param(effect, marks=pytest.mark.xfail(reason=NOT_NAMED[effect], strict=True)) \
        if effect in NOT_NAMED else effect


@pytest.mark.slow
@pytest.mark.parametrize("effect", [_not_named(e) for e in sorted(NAMED)])
def test_hidden_effect_is_named(effect):
    h, c = _hidden(effect, 1000)
    assert c.finding == effect
    assert c.gain["relative"] > MIN_NAMED_GAIN
    if NAMED[effect] is not None:
        fitted = c.parameters[CAUSES[effect]().params[0].name]
        assert abs(math.log(fitted / h.value)) <= math.log(NAMED[effect])


@pytest.mark.slow
@pytest.mark.parametrize("effect", ["unbalance", "misalignment"])
def test_hidden_shaft_force_is_named(effect):
    """A rotating shaft force of 0.66 of the static load (seed 1000) is named, and the fit
    lowers the held-out χ²: its family (the 1x/2x lines) moves towards the record, and the
    once-per-revolution swing of the load lifts the kurtosis the nominal model lacks."""
    h, c = _hidden(effect, 1000)
    assert c.finding == effect
    assert c.gain["relative"] > MIN_NAMED_GAIN
    fitted = c.parameters["relative_amplitude"]
    assert abs(math.log(fitted / h.value)) <= math.log(2.0)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason=(
    "finding (issue 25): clean seed 2001 reads chi2/feature 2.70 against the 2.5 of "
    "'unexplained' (2000: 2.17, 2002: 0.54) since the band rule reads the prediction "
    "residual: in every run of the documented model the fan-end bearing's BPFO stands "
    "11-14 dB over the envelope floor, in the record 0-2 dB (z -6.9; the same with the "
    "signal's own kurtogram band, so a gap the chi2 carried before). The benchmark's clean "
    "seeds 1000-1002 stay at 0.3-1.1, and its records with an effect the catalogue misses "
    "read 2.6-3.1: the threshold is not moved for this record."))
def test_no_false_alarm_on_clean_records():
    findings = [_hidden(None, 2000 + s)[1].finding for s in range(3)]
    assert findings.count("none") == 3


@pytest.mark.slow
def test_same_result_without_answer_key_and_renamed(tmp_path):
    """A real-data layout with the answer key removed and the file renamed gives the same
    comparison (the pipeline never reads them)."""
    h = hidden_effect_record("bearing_outer_race", 1001)
    x = h.record.run["DE"]
    key = {"condition": "faulty", "fault_location": "outer_race", "fault_diameter_in": 0.02}
    a = _write_dataset(tmp_path / "a", x, 12000.0, name="OR021_at6_2.npz", extra=key)
    b = _write_dataset(tmp_path / "b", x, 12000.0, name="x7.npz")
    ra, rb = compare(read_record(a), budget=20), compare(read_record(b), budget=20)
    da, db = ra.to_dict(), rb.to_dict()
    for d in (da, db):
        d.pop("wall_s")
    assert json.dumps(da, default=float) == json.dumps(db, default=float)


def test_cli_compare_json(tmp_path, capsys):
    from cmsim.cli import main
    h = hidden_effect_record(None, 1002)
    p = _write_dataset(tmp_path / "c", h.record.run["DE"], 12000.0)
    status = main(["compare", str(p), "--json", "--budget", "12", "--report",
                   str(tmp_path / "rep")])
    out = json.loads(capsys.readouterr().out)
    assert status == 0, out
    for key in ("discrepancies", "causes", "finding", "gain", "simulations", "wall_s"):
        assert key in out
    assert out["simulations"] <= 12
    assert out["workers"] == min(2, os.cpu_count() or 1)    # the command's default
    html = (tmp_path / "rep" / "compare.html").read_text()
    assert "data:image/png;base64" in html and out["finding"] in html


def test_a_record_without_a_unit_says_what_its_path_free_reading_lacks(tmp_path):
    """Path-free, the model's sensor noise is the record's own floor only when its unit is
    known; without one it is an assumed share of the model's RMS, and the result says so and
    how to state the unit (five shared fault records read so: two named, five with it)."""
    import dataclasses

    h = hidden_effect_record(None, 1003)
    rec = read_record(_write_dataset(tmp_path / "u", h.record.run["DE"], 12000.0))
    with_unit = compare(rec, budget=12)
    without = compare(dataclasses.replace(rec, unit_scale=None), budget=12)
    assert with_unit.mode == without.mode == "path-free"
    assert not any("unit" in n for n in with_unit.notes)
    assert [n for n in without.notes if "states no unit" in n and "--unit" in n]


def test_every_line_feature_says_where_it_reads_in_hz():
    """The output an engineer acts on names each feature's band or line in Hz (issue 25): a
    bearing family at the record's rates, by the record's name of the bearing; a mesh
    harmonic and its shaft-rate sidebands; a shape band by its edges."""
    from cmsim.discrepancy.compare import _where_it_reads, feature_label
    from cmsim.features.relative import shape_band_edges
    from cmsim.rig import OperatingPoint, Rig
    rig = Rig.paper_2016()
    freqs = rig_frequencies(rig, OperatingPoint(1200.0, 50.0))
    bf, edges = freqs.bearing("1b1"), shape_band_edges(20_000.0, 2.0)
    names = {"1b1": "drive_end"}
    x = _where_it_reads("env_bpfi_1b1_h2_db", edges, freqs, names)
    assert x["line_hz"] == [pytest.approx(2 * bf.bpfi_hz)] and "drive-end" in x["reads"]
    x = _where_it_reads("env_bsf2_1b1_h1_db", edges, freqs, names)
    assert x["line_hz"] == [pytest.approx(2 * bf.bsf_hz)]
    x = _where_it_reads("env_bpfo_1b1_sb_db", edges, freqs, names)
    assert sorted(x["line_hz"]) == pytest.approx(sorted(
        h * bf.bpfo_hz + s * bf.shaft_hz for h in (1, 2) for s in (-1, 1)))
    x = _where_it_reads("sb23_fr1_k2_db", edges, freqs, names)
    assert sorted(x["line_hz"]) == pytest.approx(sorted(
        2 * freqs.gmf_hz + s * n * freqs.fr1_hz for n in (2, 3) for s in (-1, 1)))
    gmf3 = _where_it_reads("gmf3_rel_db", edges, freqs)
    assert gmf3["line_hz"] == [pytest.approx(3 * freqs.gmf_hz)]
    fr2 = _where_it_reads("raw_fr_h2_db", edges, freqs)
    assert fr2["line_hz"] == [pytest.approx(2 * freqs.fr1_hz)]
    assert _where_it_reads("shape_b1_db", edges, freqs) == {"band_hz": [edges[1], edges[2]]}
    assert _where_it_reads("kurtosis_log", edges, freqs) == {}
    d = {"feature": "raw_bpfo_1b2_db", **_where_it_reads("raw_bpfo_1b2_db", edges, freqs, names)}
    assert feature_label(d) == (f"raw_bpfo_1b2_db (BPFO of the 1b2 bearing, "
                                f"{freqs.bearing('1b2').bpfo_hz:.1f} Hz)")


@pytest.mark.skipif(not (DATA / "cwru_bearing_12k_de").is_dir(), reason="shared data absent")
def test_real_record_reads_with_documented_geometry():
    rec = read_record(DATA / "cwru_bearing_12k_de" / "normal_0.npz")
    assert rec.channel == "DE" and rec.fs_hz == pytest.approx(12000.0)
    b = rec.rig.bearings[0]
    assert b.n_balls == 9 and b.ball_diameter_m == pytest.approx(7.94e-3)
    gear = DATA / "spectraquest_gearbox_gfd" / "h30hz0.npz"
    if gear.exists():
        g = read_record(gear)
        assert "fs_hz" in g.inferred
        # the metadata's own reading of the spectra: fs ~ 12.97 kHz if the input is at 30 Hz
        assert g.fs_hz == pytest.approx(12970.0, rel=0.02)


def test_friction_cause_is_the_mixed_lubrication_model():
    """Issue 13: the ``friction`` extension is parameterised by the composite roughness and
    the oil viscosity, and the dynamics' tooth friction follows them through the film ratio
    (rougher → more asperity friction; more viscous oil → thicker film → less)."""
    from cmsim import OperatingPoint, Rig
    from cmsim.discrepancy.causes import ModelSetup
    from cmsim.losses import LossSettings, run_losses
    from cmsim.mesh_stiffness.table import MeshStiffnessTable

    cause = CAUSES["friction"]()
    assert [p.name for p in cause.params] == ["roughness_m", "viscosity_pa_s"]
    rig, op = Rig.paper_2016(), OperatingPoint(1000.0, 50.0)
    base = ModelSetup(rig=rig, op=op)
    table = MeshStiffnessTable.potential_energy(rig.gears)

    def mean_mu(roughness, viscosity):
        st = cause.extend(base, {"roughness_m": roughness, "viscosity_pa_s": viscosity}, None)
        assert st.mixed_friction and st.rig.lubricant.surface_roughness_m == roughness
        mu = run_losses(st.rig, st.op, table, LossSettings()).friction_table
        return float(np.mean(mu[mu > 0]))

    eta = rig.lubricant.dynamic_viscosity_pa_s
    smooth, rough = mean_mu(1e-7, eta), mean_mu(2e-6, eta)
    assert rough > 1.1 * smooth
    assert mean_mu(2e-6, 5 * eta) < rough
    assert base.dynamics_key() != cause.extend(base, {"roughness_m": 2e-6,
                                                      "viscosity_pa_s": eta}, None).dynamics_key()


def test_hidden_effect_is_applied_at_its_drawn_severity():
    """The generator really puts the drawn value in the record (a hidden noise ratio of
    0.8-3 raises the RMS over the clean record's)."""
    clean = hidden_effect_record(None, 77).record.signal
    h = hidden_effect_record("noise", 77)
    assert 0.8 <= h.value <= 3.0
    assert np.std(h.record.signal) > math.sqrt(1.0 + 0.5 * h.value ** 2) * np.std(clean)


def test_the_finding_reads_as_an_engineer_says_it():
    from cmsim.discrepancy.compare import describe
    words = describe("bearing_inner_race", "drive_end", {"size_m": 4e-4, "noise_ratio": 0.1},
                     {"size_m": (2e-4, 8e-4)})
    assert words == "inner-race defect, drive-end bearing, size about 0.4 mm (0.2-0.8 mm)"
    hi = CAUSES["bearing_ball"]().params[0].bounds[1]
    assert "at the bound" in describe("bearing_ball", "drive_end", {"size_m": hi}, {})
    assert describe("none", None, {}, {}).startswith("no departure")
    assert "no cause" in describe("unexplained", None, {}, {})
