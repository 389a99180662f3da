"""Characteristic frequencies (cmsim.frequencies): bearing kinematics with one or both rings
rotating, GMF, the typed RigFrequencies record.

Test tier: closed form (textbook bearing formulas, hand-computed for the CWRU 6205 bearing;
the paper rig's 3.6342 bearing cycles per gear turn, Fernandez-del-Rincon et al. 2016 §5).
"""

import math

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.rig import OperatingPoint, Rig
from cmsim.bearings.kinematics import cage_ratios
from cmsim.frequencies import (BearingFrequencies, RigFrequencies, bearing_frequencies,
                              peak_families, rig_frequencies)

# CWRU drive-end bearing SKF 6205-2RS JEM: 9 balls, d = 7.94 mm, D = 39.04 mm, α = 0
N_BALLS, D_BALL, D_PITCH = 9, 7.94e-3, 39.04e-3


def test_cwru_6205_at_1797_rpm_matches_hand_computed_values():
    fr = 1797 / 60                      # 29.95 Hz
    g = D_BALL / D_PITCH                # 0.203381
    # hand: BPFO = 4.5·29.95·(1 − 0.203381) = 107.364; BPFI = 4.5·29.95·1.203381 = 162.186
    # BSF = (39.04 / 15.88)·29.95·(1 − 0.203381²) = 2.458438·29.95·0.958636 = 70.585
    # FTF = 29.95/2·(1 − 0.203381) = 11.929
    f = bearing_frequencies(fr, N_BALLS, D_BALL, D_PITCH)
    assert f.bpfo_hz == pytest.approx(107.36, abs=0.01)
    assert f.bpfi_hz == pytest.approx(162.19, abs=0.01)
    assert f.bsf_hz == pytest.approx(70.58, abs=0.01)
    assert f.ftf_hz == pytest.approx(11.93, abs=0.01)
    assert f.bpfo_hz == pytest.approx(N_BALLS / 2 * fr * (1 - g), rel=1e-12)
    assert f.bpf_hz == pytest.approx(f.bpfo_hz, rel=1e-12)      # fixed outer ring


def test_contact_angle_lowers_gamma():
    f0 = bearing_frequencies(30.0, N_BALLS, D_BALL, D_PITCH, 0.0)
    f1 = bearing_frequencies(30.0, N_BALLS, D_BALL, D_PITCH, math.radians(40))
    assert f1.bpfo_hz > f0.bpfo_hz and f1.bpfi_hz < f0.bpfi_hz


def test_outer_ring_co_rotating_at_shaft_speed_has_no_relative_motion():
    f = bearing_frequencies(25.0, N_BALLS, D_BALL, D_PITCH, 0.2, outer_ring_hz=25.0)
    assert f.bpfo_hz == pytest.approx(0.0, abs=1e-12)
    assert f.bpfi_hz == pytest.approx(0.0, abs=1e-12)
    assert f.bsf_hz == pytest.approx(0.0, abs=1e-12)
    assert f.ftf_hz == pytest.approx(25.0, rel=1e-12)             # cage turns with both rings
    assert f.bpf_hz == pytest.approx(N_BALLS * 25.0, rel=1e-12)  # balls pass a fixed load


@pytest.mark.parametrize("outer_hz", [-40.0, -10.0, 0.0, 7.0, 60.0])
def test_both_rings_rotating_invariants(outer_hz):
    fi = 25.0
    g = D_BALL / D_PITCH
    f = bearing_frequencies(fi, N_BALLS, D_BALL, D_PITCH, outer_ring_hz=outer_hz)
    # the cage rate lies between the ring rates, so BPFO + BPFI = N |f_i − f_o|
    assert f.bpfo_hz + f.bpfi_hz == pytest.approx(N_BALLS * abs(fi - outer_hz), rel=1e-12)
    # defect and spin rates only depend on the relative ring speed: add a common rotation
    shifted = bearing_frequencies(fi + 5.0, N_BALLS, D_BALL, D_PITCH, outer_ring_hz=outer_hz + 5.0)
    for name in ("bpfo_hz", "bpfi_hz", "bsf_hz"):
        assert getattr(shifted, name) == pytest.approx(getattr(f, name), rel=1e-12, abs=1e-12)
    cage = fi * (1 - g) / 2 + outer_hz * (1 + g) / 2
    assert f.ftf_hz == pytest.approx(abs(cage), rel=1e-12)


def test_paper_rig_gmf_and_bearing_cycles_per_gear_turn():
    rig = Rig.paper_2016()
    f = rig_frequencies(rig, OperatingPoint(speed_rpm=1000.0))
    assert isinstance(f, RigFrequencies)
    assert f.fr1_hz == pytest.approx(1000 / 60)
    assert f.gmf_hz == pytest.approx(466.67, abs=0.005)
    assert f.fr2_hz == pytest.approx(1000 / 60)       # 28/28 teeth
    assert f.bearing_names == rig.bearing_names
    for name in rig.bearing_names:
        b = f.bearing(name)
        assert b.bpf_hz / b.shaft_hz == pytest.approx(3.6342, abs=5e-4)
        assert b.bpf_hz == pytest.approx(b.bpfo_hz, rel=1e-12)


def test_rig_frequencies_follow_gear_ratio_and_outer_ring_speed():
    from dataclasses import replace
    rig = Rig.paper_2016()
    wheel = replace(rig.gears.driven, n_teeth=42)
    sh2 = rig.shafts[1]
    sh2 = replace(sh2, bearing_1=replace(sh2.bearing_1, outer_ring_speed_ratio=-1.0))
    rig2 = replace(rig, gears=replace(rig.gears, driven=wheel), shafts=(rig.shafts[0], sh2))
    f = rig_frequencies(rig2, OperatingPoint(speed_rpm=1200.0))
    assert f.fr2_hz == pytest.approx(20.0 * 28 / 42)
    assert f.gmf_hz == pytest.approx(28 * 20.0)
    assert f.bearing("2b2").shaft_hz == pytest.approx(20.0 * 28 / 42)
    b = rig2.shafts[1].bearing_1
    ref = bearing_frequencies(f.bearing("2b1").shaft_hz, b.n_balls, b.ball_diameter_m,
                              b.pitch_diameter_m, b.effective_contact_angle_rad,
                              outer_ring_hz=-f.bearing("2b1").shaft_hz)
    assert f.bearing("2b1").bpfi_hz == pytest.approx(ref.bpfi_hz, rel=1e-12)
    assert f.bearing("2b1").bpfo_hz > f.bearing("2b2").bpfo_hz    # counter-rotating outer ring
    fam = f.families("2b1")
    assert fam["fr"] == pytest.approx(f.bearing("2b1").shaft_hz)
    assert set(fam) == {"GMF", "BPF", "fr", "BPFO", "BPFI", "BSF", "FTF", "fr1"}
    assert fam["fr1"] == pytest.approx(20.0)        # the other gear shaft: the input
    assert "fr2" in f.families("1b1") and "fr1" not in f.families("1b1")
    assert set(rig_frequencies(rig, OperatingPoint(speed_rpm=1200.0)).families()) == {
        "GMF", "BPF", "fr", "BPFO", "BPFI", "BSF", "FTF"}        # 28:28: one shaft rate
    assert peak_families(f, "2b1") == fam


def test_cage_rate_is_the_kinematics_cage_formula():
    """FTF/f_shaft equals K_in of bearings.kinematics (the one cage formula) for a fixed
    outer ring, and the model's ball pass equals N·K_in·f_shaft."""
    rig = Rig.paper_2016()
    f = rig_frequencies(rig, OperatingPoint(speed_rpm=900.0))
    for name, brg in zip(rig.bearing_names, rig.bearings):
        k_in, _ = cage_ratios(brg)
        b = f.bearing(name)
        assert b.ftf_hz == pytest.approx(k_in * b.shaft_hz, rel=1e-12)
        assert b.bpf_hz == pytest.approx(brg.n_balls * k_in * b.shaft_hz, rel=1e-12)


def test_dict_round_trip_and_mapping_access():
    f = rig_frequencies(Rig.paper_2016(), OperatingPoint(speed_rpm=1000.0))
    d = f.to_dict()
    assert set(d) == {"shaft_hz", "output_shaft_hz", "gmf_hz", "1b1", "1b2", "2b1", "2b2"}
    assert RigFrequencies.from_dict(d) == f
    assert f["1b1"]["bpf_hz"] == pytest.approx(f.bearing("1b1").bpf_hz, rel=1e-15)
    assert f["gmf_hz"] == pytest.approx(f.gmf_hz, rel=1e-15)
    with pytest.raises(ParameterError, match="bearing must be one of"):
        f.bearing("9b9")


def test_measured_record_frequencies_without_gears():
    """A measured record: one named bearing, no gears, no GMF family."""
    brg = bearing_frequencies(1797 / 60, N_BALLS, D_BALL, D_PITCH)
    f = RigFrequencies(fr1_hz=1797 / 60, bearings={"DE": brg})
    assert not f.has_gears and f.gmf_hz is None
    fam = f.families("DE")
    assert "GMF" not in fam
    assert fam["BPFO"] == pytest.approx(brg.bpfo_hz, rel=1e-15)
    with pytest.raises(ParameterError, match="BearingFrequencies"):
        RigFrequencies(fr1_hz=10.0, bearings={"DE": {"bpfo_hz": 1.0}})


def test_peak_families_drop_zero_frequencies():
    f = {"shaft_hz": 10.0, "1b1": {"shaft_hz": 10.0, "ftf_hz": 10.0, "bpfo_hz": 0.0,
                                   "bpfi_hz": 0.0, "bsf_hz": 0.0, "bpf_hz": 90.0}}
    assert set(peak_families(f)) == {"fr", "FTF", "BPF"}
    with pytest.raises(ParameterError, match="bearing"):
        peak_families(f, "9b9")


@pytest.mark.parametrize("kwargs, name", [
    (dict(shaft_hz=-1.0), "shaft_hz"),
    (dict(n_balls=2), "n_balls"),
    (dict(n_balls=9.0), "n_balls"),
    (dict(ball_diameter_m=0.0), "ball_diameter_m"),
    (dict(pitch_diameter_m=5e-3), "pitch_diameter_m"),
    (dict(contact_angle_rad=2.0), "contact_angle_rad"),
    (dict(outer_ring_hz=float("nan")), "outer_ring_hz"),
])
def test_bad_bearing_inputs_name_the_parameter(kwargs, name):
    args = dict(shaft_hz=10.0, n_balls=9, ball_diameter_m=D_BALL, pitch_diameter_m=D_PITCH)
    args.update(kwargs)
    with pytest.raises(ParameterError, match=name):
        bearing_frequencies(**args)


def test_values_are_plain_floats():
    f = rig_frequencies(Rig.paper_2016(), OperatingPoint(speed_rpm=600.0))
    assert isinstance(f.bearing("1b1"), BearingFrequencies)
    assert all(isinstance(v, float) for v in f.bearing("1b1").to_dict().values())
    assert np.isfinite(f.gmf_hz)
