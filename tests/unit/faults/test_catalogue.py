"""Fault catalogue: validation, text/TOML round trips, compiled arrays.

Tier (a) closed form: the ball-drop depth of a defect (sagitta of the chord on the ball, by
hand), the trapezoid profile, spall/breakage/relief bands placed where the involute geometry
puts them, CWRU 6205 defect frequencies (published ratios 3.5848/5.4152/2.357/0.3983 × shaft
rate). Plus input checks: every bad input is refused with a message naming the parameter.
"""

import math

from dataclasses import replace

import numpy as np
import pytest

from cmsim.dynamics.model import build_model
from cmsim.errors import ParameterError
from cmsim.faults import (FAULT_TYPES, BallDefect, OuterRaceDefect, RollingSlip, ToothCrack,
                          ToothSpall,
                          compile_faults, fault_frequencies, fault_from_dict, load_faults,
                          operating_modulation, parse_fault, rig_with_faults, slip_from_faults)
from cmsim.faults.bearing import (BearingWear, ball_drop_m, defect_profile, track_share,
                                  wandering_offset)
from cmsim.faults.compile import DEFECT_COLUMNS, check_faults
from cmsim.faults.gear import BREAKAGE_SEPARATION_M, roll_length_m
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.rig import OperatingPoint, Rig, RollingBearing, Rotor

ALL = [
    "outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4",
    "inner_race:bearing=2b2,size_mm=0.5,depth_m=1e-4,angle_deg=30",
    "ball:bearing=1b2,size_m=1e-3,depth_m=1e-4,ball=3",
    "wear:bearing=1b1,clearance_growth_m=1e-5",
    "off_size_ball:bearing=2b1,diameter_excess_m=2e-6,ball=1",
    "rolling_slip:cage_speed_rms=0.01",
    "eccentricity:gear=1,amplitude_m=2e-5,phase_rad=0.5",
    "tooth_crack:gear=1,depth_mm=2,tooth=3",
    "tooth_spall:gear=2,width_mm=1,depth_m=2e-5,tooth=5",
    "tooth_breakage:gear=1,lost_height_mm=1,tooth=7",
    "profile_error:gear=1,tip_relief_m=1e-5",
    "speed_fluctuation:relative_amplitude=0.01,frequency_hz=5",
    "torque_ripple:relative_amplitude=0.05,order=2",
]


@pytest.fixture(scope="module")
def rig():
    return Rig.paper_2016()


@pytest.fixture(scope="module")
def table(rig):
    return MeshStiffnessTable.potential_energy(rig.gears)


@pytest.fixture(scope="module")
def cwru():
    return Rig.rotor_on_bearings(RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3),
                                 Rotor(5.0, 0.01), name="CWRU")


def test_catalogue_complete():
    assert set(FAULT_TYPES) == {
        "eccentricity", "tooth_crack", "tooth_spall", "tooth_breakage", "profile_error",
        "outer_race", "inner_race", "ball", "wear", "off_size_ball", "rolling_slip",
        "speed_fluctuation", "torque_ripple"}


@pytest.mark.parametrize("text", ALL)
def test_parse_dict_round_trip(text, rig):
    f = parse_fault(text)
    assert fault_from_dict(f.to_dict()) == f
    f.validate(rig)
    assert f.label.startswith(f.name)


def test_toml_round_trip(tmp_path):
    import tomli_w
    faults = tuple(parse_fault(t) for t in ALL)
    path = tmp_path / "faults.toml"
    path.write_text(tomli_w.dumps({"faults": [f.to_dict() for f in faults]}))
    assert load_faults(path) == faults
    spec = {"faults": [{"type": "speed_fluctuation", "spectrum": [[5.0, 0.01, 0.0],
                                                                   [9.0, 0.02, 1.0]]}]}
    (sf,) = load_faults(spec)
    assert sf.lines() == ((5.0, 0.01, 0.0), (9.0, 0.02, 1.0))


@pytest.mark.parametrize("text, param", [
    ("no_such_fault:bearing=1b1", "type"),
    ("outer_race:bearing=9b9,size_m=1e-3,depth_m=1e-4", "bearing"),
    ("outer_race:bearing=1b1,size_m=-1e-3,depth_m=1e-4", "size_m"),
    ("outer_race:bearing=1b1,size_m=1e-3,depth_m=-1e-4", "depth_m"),
    ("outer_race:bearing=1b1,size_m=0.03,depth_m=1e-4", "size_m"),     # > ball spacing
    ("outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4,colour=red", "colour"),
    ("outer_race:bearing=1b1,size_m=1e-3,size_mm=1,depth_m=1e-4", "size_mm"),
    ("ball:bearing=1b1,size_m=0.013,depth_m=1e-4", "size_m"),          # > ball diameter
    ("ball:bearing=1b1,size_m=1e-3,depth_m=1e-4,ball=9", "ball"),
    ("wear:bearing=1b1,clearance_growth_m=1e-3", "clearance_growth_m"),
    ("eccentricity:gear=3,amplitude_m=1e-5", "gear"),
    ("eccentricity:gear=1,amplitude_m=0", "amplitude_m"),
    ("eccentricity:gear=1,amplitude_m=1e-5,mass_share=1.5", "mass_share"),
    ("tooth_crack:gear=1,depth_mm=5", "depth_m"),                      # tip past centreline
    ("tooth_crack:gear=1,depth_mm=1,tooth=28", "tooth"),
    ("tooth_crack:gear=1,depth_mm=1,angle_deg=0", "angle_rad"),
    ("tooth_spall:gear=1,width_mm=20,depth_m=1e-5", "width_m"),
    ("tooth_spall:gear=1,width_mm=1,depth_m=1e-5,radius_m=0.05", "radius_m"),
    ("tooth_breakage:gear=1,lost_height_mm=8", "lost_height_m"),
    ("profile_error:gear=1", "wear_depth_m"),
    ("speed_fluctuation:relative_amplitude=0.6,frequency_hz=5", "relative_amplitude"),
    ("speed_fluctuation:relative_amplitude=0.1", "frequency_hz"),
    ("torque_ripple:relative_amplitude=0.1,order=2,frequency_hz=3", "frequency_hz"),
    ("off_size_ball:bearing=1b1,diameter_excess_m=5e-4", "diameter_excess_m"),
])
def test_bad_input_refused_naming_parameter(text, param, rig):
    with pytest.raises(ParameterError) as err:
        parse_fault(text).validate(rig)
    assert err.value.param == param
    assert param in str(err.value)


def test_a_repeated_key_is_refused_not_the_last_one_kept():
    with pytest.raises(ParameterError, match="size_m is given twice") as err:
        parse_fault("outer_race:bearing=1b1,size_m=1e-3,size_m=2e-3,depth_m=1e-4")
    assert err.value.param == "size_m"


@pytest.mark.parametrize("first, second, words", [
    ("outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4",
     "outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4", "same fault"),
    ("tooth_crack:gear=1,depth_mm=1,tooth=3", "tooth_crack:gear=1,depth_mm=2,tooth=3",
     "tooth 3 of gear 1"),
    ("tooth_breakage:gear=2,lost_height_mm=1", "tooth_breakage:gear=2,lost_height_mm=2",
     "tooth 0 of gear 2"),
    ("eccentricity:gear=1,amplitude_m=2e-5", "eccentricity:gear=1,amplitude_m=1e-5",
     "eccentricity of gear 1"),
    ("wear:bearing=1b1,clearance_growth_m=1e-5", "wear:bearing=1b1,clearance_growth_m=2e-5",
     "wear of bearing 1b1"),
    ("inner_race:bearing=1b1,size_m=1e-3,depth_m=1e-4",
     "inner_race:bearing=1b1,size_m=2e-3,depth_m=1e-4", "bearing 1b1"),
    ("rolling_slip:cage_speed_rms=0.01", "rolling_slip:cage_speed_rms=0.02", "rolling_slip"),
])
def test_two_faults_on_one_site_are_refused(first, second, words, rig):
    """The model would keep the last eccentricity, multiply two cracks of one tooth or add
    two wears of one bearing: nobody described that fault, so it is refused."""
    faults = [parse_fault(first), parse_fault(second)]
    with pytest.raises(ParameterError, match="faults\\[1\\]") as err:
        check_faults(rig, faults)
    assert words in str(err.value) and err.value.param == "faults"


def test_distinct_sites_and_summed_modulations_stay_allowed(rig):
    check_faults(rig, [parse_fault("tooth_crack:gear=1,depth_mm=1,tooth=3"),
                       parse_fault("tooth_crack:gear=1,depth_mm=1,tooth=4"),
                       parse_fault("tooth_crack:gear=2,depth_mm=1,tooth=3"),
                       parse_fault("outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4"),
                       parse_fault("outer_race:bearing=1b1,size_m=1e-3,depth_m=1e-4,"
                                   "angle_rad=1"),
                       parse_fault("speed_fluctuation:relative_amplitude=0.01,frequency_hz=5"),
                       parse_fault("speed_fluctuation:relative_amplitude=0.01,frequency_hz=9")])


@pytest.mark.parametrize("text, words", [
    ('[fault]\ntype = "ball"\nbearing = "1b1"\nsize_m = 5e-4\ndepth_m = 1e-4\n',
     "[fault] (write [[faults]])"),
    ("", "defines no fault"),
    ("faults = []\n", "defines no fault"),
    ('severity = 2\n[[faults]]\ntype = "wear"\nbearing = "1b1"\nclearance_growth_m = 1e-5\n',
     "'severity'"),
])
def test_a_faults_file_that_defines_no_fault_or_unknown_keys_is_refused(text, words, tmp_path):
    """Read as a healthy run before: ``[fault]`` for ``[[faults]]``, an empty file."""
    path = tmp_path / "f.toml"
    path.write_text(text)
    with pytest.raises(ParameterError) as err:
        load_faults(path)
    assert words in str(err.value)


def test_gear_fault_on_gearless_rig_refused(cwru):
    with pytest.raises(ParameterError, match="gear"):
        compile_faults(cwru, [parse_fault("eccentricity:gear=1,amplitude_m=1e-5")], None)


def test_ball_drop_by_hand():
    """1 mm defect, ball radius 3.97 mm: sagitta 3.97 − sqrt(3.97² − 0.5²) mm = 31.61 µm."""
    rb, length = 3.97e-3, 1.0e-3
    sag = rb - math.sqrt(rb ** 2 - 0.25e-6)
    assert ball_drop_m(rb, length, 1e-3) == pytest.approx(sag, rel=1e-12)
    assert sag == pytest.approx(31.61e-6, abs=0.01e-6)
    assert ball_drop_m(rb, length, 10e-6) == pytest.approx(10e-6)     # shallow: the depth
    assert ball_drop_m(rb, 9e-3, 0.5e-3) == pytest.approx(0.5e-3)     # wider than the ball


def test_defect_row_and_trapezoid(cwru):
    """CWRU 0.007" (0.178 mm) outer-race fault at 6 o'clock: row by hand."""
    f = OuterRaceDefect(bearing="1b1", size_m=0.178e-3, depth_m=0.28e-3)
    row = compile_faults(cwru, [f], None).bearing_defects[0]
    brg = cwru.bearings[0]
    ro, rb = 0.5 * brg.outer_raceway_diameter_m, 0.5 * brg.ball_diameter_m
    drop = rb - math.sqrt(rb ** 2 - (0.089e-3) ** 2)
    assert row[0] == 0 and row[1] == 1 and row[7] == -1
    assert row[2] == pytest.approx(-0.5 * math.pi)                    # load zone, down
    assert row[3] == pytest.approx(0.089e-3 / ro)
    assert row[4] == pytest.approx(drop, rel=1e-9)
    assert row[5] == pytest.approx(row[3])        # sagitta-limited: falls over L/2
    assert row[6] == pytest.approx(0.2 * row[5])  # abrupt exit
    hw = row[3]
    a = row[2] + hw * np.array([-1.5, -1.0, -0.5, 0.0, 0.5, 0.9, 1.0, 1.5])
    p = defect_profile(a, row[2], hw, row[5], row[6])
    np.testing.assert_allclose(p, [0, 0, 0.5, 1.0, 1.0, 0.5, 0, 0], atol=1e-9)


def test_load_zone_default_follows_load(rig, cwru):
    op = OperatingPoint(speed_rpm=1797, radial_load_n=500, radial_load_angle_rad=0.3)
    f = OuterRaceDefect(bearing="1b2", size_m=0.5e-3, depth_m=1e-4)
    assert compile_faults(cwru, [f], None, op=op).bearing_defects[0, 2] == pytest.approx(0.3)
    alpha = rig.gears.working_pressure_angle_rad
    rows = compile_faults(rig, [f, OuterRaceDefect(bearing="2b1", size_m=0.5e-3,
                                                   depth_m=1e-4)]).bearing_defects
    np.testing.assert_allclose(rows[:, 2], [-alpha, math.pi - alpha])
    g = OuterRaceDefect(bearing="1b2", size_m=0.5e-3, depth_m=1e-4, angle_rad=1.0)
    assert compile_faults(rig, [g]).bearing_defects[0, 2] == pytest.approx(1.0)


def test_ball_defect_row(rig):
    f = BallDefect(bearing="1b2", size_m=1e-3, depth_m=5e-6, ball=4, phase_rad=0.2)
    row = compile_faults(rig, [f]).bearing_defects[0]
    rb = 0.5 * rig.bearings[1].ball_diameter_m
    assert (row[0], row[1], row[7]) == (1, 3, 4)
    assert row[3] == pytest.approx(0.5e-3 / rb)
    assert row[4] == pytest.approx(5e-6)                        # shallower than the sagitta
    assert row[5] == pytest.approx(math.sqrt(2 * rb * 5e-6 - 25e-12) / rb)


def test_healthy_arrays_are_neutral(rig, table):
    fa = compile_faults(rig, [], table)
    assert fa.tooth_factor1.shape == (28, table.position_m.size)
    assert fa.bearing_defects.shape == (0, len(DEFECT_COLUMNS))
    assert not fa.active
    np.testing.assert_allclose(fa.tooth_grid_m, [table.position_m[0], table.spacing_m])


def test_tooth_tables_where_geometry_puts_them(rig, table):
    pair = rig.gears
    s = table.position_m
    fs = [parse_fault("tooth_crack:gear=1,depth_mm=2,tooth=3"),
          parse_fault("tooth_spall:gear=2,width_mm=1,depth_m=2e-5,tooth=5"),
          parse_fault("tooth_breakage:gear=1,lost_height_mm=1,tooth=7"),
          parse_fault("tooth_spall:gear=1,width_mm=1,depth_m=2e-5,face_fraction=0.5"),
          parse_fault("eccentricity:gear=2,amplitude_m=2e-5,phase_rad=0.5")]
    fa = compile_faults(rig, fs, table)
    # crack: only tooth 3 of gear 1, a loss somewhere, never a gain
    f1 = fa.tooth_factor1
    assert np.all(np.delete(f1, [0, 3], axis=0) == 1.0)
    assert 0.8 < f1[3].min() < 0.99 and f1[3].max() <= 1.0
    # spall on gear 2 tooth 5 (full face): separation 20 µm around the pitch point, width
    # along the line of action = involute arc 1 mm → roll band [λ_lo, λ_hi]
    g2 = pair.driven
    lam_p = roll_length_m(g2, g2.pitch_radius_m)
    sig = lam_p ** 2 / (2 * g2.base_radius_m)
    lam = [math.sqrt(2 * g2.base_radius_m * (sig + d)) for d in (-0.5e-3, 0.5e-3)]
    L = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)
    inside = (s > L - lam[1] + table.spacing_m) & (s < L - lam[0] - table.spacing_m)
    outside = (s < L - lam[1] - table.spacing_m) | (s > L - lam[0] + table.spacing_m)
    assert np.allclose(fa.tooth_sep2[5][inside], 2e-5) and inside.sum() >= 3
    assert np.all(fa.tooth_sep2[5][outside] == 0.0)
    # partial-face spall on gear 1 tooth 0: stiffness halved over its band, no separation
    assert f1[0].min() == pytest.approx(0.5) and np.all(fa.tooth_sep1[0] == 0.0)
    # breakage: no contact beyond the roll of the new tip radius on gear 1 tooth 7
    g1 = pair.driving
    lam_b = roll_length_m(g1, g1.tip_radius_m - 1e-3)
    sep = fa.tooth_sep1[7]
    np.testing.assert_allclose(sep[s > lam_b + table.spacing_m], BREAKAGE_SEPARATION_M,
                               rtol=1e-12)
    assert np.all(sep[s < lam_b - table.spacing_m] == 0.0)
    # (amplitude, phase, the mass on the offset centre: the whole gear's by default)
    np.testing.assert_allclose(fa.eccentricity, [[0, 0, 0], [2e-5, 0.5, g2.mass_kg]])


def test_tip_relief_linear_on_every_tooth(rig, table):
    f = parse_fault("profile_error:gear=1,tip_relief_m=1e-5,tip_relief_start_radius_m=0.046")
    sep = compile_faults(rig, [f], table).tooth_sep1
    assert np.all(sep == sep[0])                                   # all teeth
    g1 = rig.gears.driving
    lam_s = roll_length_m(g1, 0.046)
    s = table.position_m
    assert np.all(sep[0][s <= lam_s] == 0.0)
    k = np.nonzero((s > lam_s) & (sep[0] < 1e-5))[0]
    slope = np.diff(sep[0][k]) / np.diff(s[k])
    assert np.ptp(slope) < 1e-9 * abs(slope[0]) + 1e-12 and slope[0] > 0
    assert sep[0].max() == pytest.approx(1e-5)


def test_off_size_ball_and_wear(rig):
    fs = [parse_fault("off_size_ball:bearing=2b1,diameter_excess_m=2e-6,ball=1"),
          parse_fault("wear:bearing=1b1,clearance_growth_m=1e-5")]
    fa = compile_faults(rig, fs)
    assert fa.ball_offset_m.shape == (4, 9)
    assert fa.ball_offset_m[2, 1] == pytest.approx(2e-6)
    assert np.count_nonzero(fa.ball_offset_m) == 1
    worn = rig_with_faults(rig, fs)
    assert worn.bearings[0].clearance_m == pytest.approx(rig.bearings[0].clearance_m + 1e-5)
    assert worn.bearings[1].clearance_m == pytest.approx(rig.bearings[1].clearance_m)
    assert rig_with_faults(rig, []) is rig


def test_slip_and_modulation(rig):
    fs = [parse_fault(t) for t in ALL]
    assert slip_from_faults(fs) == RollingSlip(cage_speed_rms=0.01, ball_rms_rad=0.0,
                                               correlation_s=5e-3)
    assert slip_from_faults(fs[:3]) is None
    op = OperatingPoint(speed_rpm=1200.0, torque_nm=20.0)
    speed, torque = operating_modulation(fs, op, rig)
    t = np.linspace(0, 1, 1001)
    np.testing.assert_allclose(speed(t), 1 + 0.01 * np.sin(2 * np.pi * 5 * t), atol=1e-12)
    np.testing.assert_allclose(torque(t), 1 + 0.05 * np.sin(2 * np.pi * 40.0 * t), atol=1e-12)
    with pytest.raises(ParameterError, match="order"):
        operating_modulation(fs)[1]
    assert operating_modulation(fs[:3]) == (None, None)


def test_cwru_frequencies(cwru):
    """Published CWRU 6205-2RS ratios at 1797 rpm within 0.5 %."""
    op = OperatingPoint(speed_rpm=1797.0)
    fs = [parse_fault("outer_race:bearing=1b1,size_mm=0.178,depth_mm=0.28"),
          parse_fault("inner_race:bearing=1b1,size_mm=0.178,depth_mm=0.28"),
          parse_fault("ball:bearing=1b1,size_mm=0.178,depth_mm=0.28")]
    key = list(fault_frequencies(cwru, op, fs).values())
    fr = 1797.0 / 60.0
    assert key[0]["bpfo_hz"] / fr == pytest.approx(3.5848, rel=5e-3)
    assert key[1]["bpfi_hz"] / fr == pytest.approx(5.4152, rel=5e-3)
    assert key[2]["bsf_hz"] / fr == pytest.approx(2.357, rel=5e-3)
    assert key[2]["two_bsf_hz"] == pytest.approx(2 * key[2]["bsf_hz"])
    assert key[0]["ftf_hz"] / fr == pytest.approx(0.3983, rel=5e-3)


def test_gear_fault_frequencies(rig):
    """A tooth fault's key frequencies come from its own gear: on a 28:37 pair the driven
    gear turns at fr1·28/37 (a 28:28 pair could not tell the gears apart)."""
    pair = replace(rig.gears, driven=replace(rig.gears.driven, n_teeth=37))
    rig = replace(rig, gears=pair)
    op = OperatingPoint(speed_rpm=1000.0, torque_nm=10.0)
    # two spalls of one tooth that differ only in their face share: distinct faults with
    # one label (the same fault twice is refused: test_two_faults_on_one_site_are_refused)
    key = fault_frequencies(rig, op, [ToothSpall(gear=2, width_m=1e-3, depth_m=2e-5),
                                      ToothCrack(gear=1, depth_m=1e-3),
                                      ToothSpall(gear=2, width_m=1e-3, depth_m=2e-5,
                                                 face_fraction=0.5)])
    driven, driving, again = key.values()
    fr1 = 1000 / 60
    assert driven["gmf_hz"] == driving["gmf_hz"] == pytest.approx(28 * fr1, rel=1e-12)
    assert driven["shaft_hz"] == pytest.approx(fr1 * 28 / 37, rel=1e-12)
    assert driving["shaft_hz"] == pytest.approx(fr1, rel=1e-12)
    assert len(key) == 3 and again == driven                       # duplicate labels kept


def test_rig_toml_with_faults(tmp_path, rig):
    """A rig file carries a [[faults]] list: Rig.load reads the rig, load_faults the faults."""
    faults = tuple(parse_fault(t) for t in ALL[:4])
    path = tmp_path / "rig.toml"
    rig.save(path, faults=faults)
    assert Rig.load(path) == rig
    assert load_faults(path, rig_file=True) == faults


def test_ball_track_share_closed_form():
    """Overlap of a pit of half-width h with a band of half-width a (ball radii) over the
    narrower: 1 while the pit is inside the band or covers it, linear to 0 as it leaves,
    0 beyond a + h."""
    z = np.array([0.0, 0.15, 0.2, 0.25, 0.3, -0.2])
    a, h = 0.2, 0.05                                   # pit narrower than the band
    np.testing.assert_allclose(track_share(z, a + h, h), [1.0, 1.0, 0.5, 0.0, 0.0, 0.5])
    a, h = 0.05, 0.2                                   # pit wider: full depth on the track
    np.testing.assert_allclose(track_share(z, a + h, h), [1.0, 1.0, 0.5, 0.0, 0.0, 0.5])


def test_spin_axis_walk_decorrelates_at_its_correlation_time():
    """Isotropic rotational diffusion: E[n(t)·p] = exp(−t/τ) n(0)·p (2000 walkers from the
    defect's pole), and |n| stays 1 so the offset stays in [−1, 1]."""
    rng = np.random.default_rng(5)
    tau, dt, n = 0.2, 0.002, 301
    z = np.array([wandering_offset(1.0, tau, n, dt, rng) for _ in range(2000)])
    assert np.all(np.abs(z) <= 1.0 + 1e-12)
    for k in (50, 100, 200, 300):
        assert abs(z[:, k].mean() - math.exp(-k * dt / tau)) < 0.03, k


def test_ball_defect_row_track_width_from_hertz(cwru):
    """The track half-width is the Hertz band across the track plus half the pit, and grows
    as the cube root of the ball load."""
    rig = cwru
    f = BallDefect("1b1", 4e-4, 2e-4, axis_offset=0.3, wander_s=0.5)
    cols = dict(zip(DEFECT_COLUMNS, f.defect_row(rig, 100.0)))
    cols8 = dict(zip(DEFECT_COLUMNS, f.defect_row(rig, 800.0)))
    rb = 0.5 * rig.bearings[0].ball_diameter_m
    band, band8 = ((c["track_rad"] - c["half_width_rad"]) * rb for c in (cols, cols8))
    assert 0.3e-3 < band < 1.0e-3
    assert band8 / band == pytest.approx(2.0, rel=1e-9)
    assert (cols["axis_offset"], cols["wander_s"]) == (0.3, 0.5)
    with pytest.raises(ParameterError, match="axis_offset"):
        BallDefect("1b1", 4e-4, 2e-4, axis_offset=1.5)


@pytest.mark.parametrize("size_m", [1e-4, 7.5e-4, 3e-3])
@pytest.mark.parametrize("load_n", [10.0, 1000.0])
def test_ball_defect_on_the_track_keeps_its_full_depth(cwru, size_m, load_n):
    """axis_offset = 0 (the default) is the Sawalhi-Randall defect, whatever the pit's width
    against the contact band: the runs' track grid is all ones."""
    row = BallDefect("1b1", size_m, 2e-4).defect_row(cwru, load_n)
    cols = dict(zip(DEFECT_COLUMNS, row))
    assert track_share(0.0, cols["track_rad"], cols["half_width_rad"]) == 1.0


def test_faults_are_validated_once_against_the_rig_as_given(rig, table, monkeypatch):
    """check_faults returns a tuple that remembers the rig it was checked on: what reads it
    later for that rig (wear, kernel arrays, answer key) does not validate it again. Wear is
    checked on the rig as given; applied first, a growth above half its allowed margin was
    refused (the worn rig's own margin is smaller)."""
    brg = rig.bearings[0]
    margin = 0.05 * brg.ball_diameter_m - brg.clearance_m
    faults = (OuterRaceDefect("1b1", 1e-3, 5e-5), BearingWear("1b1", 0.8 * margin))
    checked = check_faults(rig, faults)
    assert checked == faults and check_faults(rig, checked) is checked
    op = OperatingPoint(speed_rpm=1000.0, torque_nm=10.0)
    model = build_model(rig, op, (table, None), faults=checked)
    assert model.rig.bearings[0].clearance_m == pytest.approx(brg.clearance_m + 0.8 * margin)
    calls = []
    monkeypatch.setattr(BearingWear, "validate", lambda self, r: calls.append(r) or self)
    worn = rig_with_faults(rig, checked)
    compile_faults(rig, checked, table, op=op)
    fault_frequencies(rig, op, checked)
    assert calls == []
    check_faults(worn, checked)                   # another rig: validated again
    assert calls == [worn]
