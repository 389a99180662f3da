"""Which bearing's line (cmsim.discrepancy.resolution): a line two families share at the
segments' resolution is given to the one whose window holds it over the whole record, a
family no segment showed is named where the whole record shows it over the baseline, and a
bearing's line that is a shaft's harmonic is the shaft's where its comb rose."""

from types import SimpleNamespace

import numpy as np
import pytest

from cmsim.discrepancy import resolution
from cmsim.discrepancy.resolution import (
    BURIED_RISE_DB,
    COMB_RISE_DB,
    FULL_RESOLUTION_MAX_S,
    RESOLUTION_DB,
    buried_family,
    overlapping,
    resolve_line,
    shaft_comb,
)
from cmsim.frequencies import BearingFrequencies, RigFrequencies

FS = 12_000.0
# the drive end's 2xBSF (2 x 89 = 178 Hz) and the fan end's BPFO (171.8 Hz): 3.6 % apart,
# inside each other's window at 2 Hz (0.5-s segments), apart at 0.33 Hz (3 s)
FREQS = RigFrequencies(fr1_hz=30.0, bearings={
    "1b1": BearingFrequencies(30.0, 12.0, 150.0, 230.0, 89.0, 150.0),
    "1b2": BearingFrequencies(30.0, 11.8, 171.8, 262.0, 70.0, 171.8)})
NAMES = ["env_bpfo_1b2_h1_db", "env_bsf2_1b1_h1_db", "env_bpfi_1b1_h1_db"]


def _record(rate_hz, seconds=3.0, seed=0):
    """Impacts at ``rate_hz`` ringing a 3-kHz resonance, in white noise."""
    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    t = np.arange(n) / FS
    hits = np.zeros(n)
    hits[(np.arange(0.0, seconds, 1.0 / rate_hz) * FS).astype(int)] = 1.0
    ring = np.exp(-600.0 * t[:200]) * np.sin(2 * np.pi * 3000.0 * t[:200])
    x = np.convolve(hits, ring)[:n] + 0.05 * rng.standard_normal(n)
    return SimpleNamespace(signal=x, fs_hz=FS, model_frequencies=lambda: FREQS)


def _row(name, component, nameable=True, out=None, total=1.0, family_z=5.0, names=NAMES):
    """A row whose fundamental stands out (``out`` None) or the columns ``out``."""
    if out is None:
        fam = {"bearing_outer_race": "bpfo", "bearing_inner_race": "bpfi", "bearing_ball": "bsf2"}
        out = [i for i, k in enumerate(names) if k == f"env_{fam.get(name)}_{component}_h1_db"]
    return {"name": name, "component": component, "nameable": nameable, "out": out,
            "total": total, "family_z": family_z}


def _decision(top, *others):
    return {"top": top, "ranked": [top, *others], "by_signature": [], "ties": []}


def test_two_lines_share_a_window_within_the_tolerance_and_one_and_a_half_bins_each():
    # 178 - 3.56 - 3 = 171.44 Hz <= 171.8 + 3.44 + 3 = 178.24 Hz at 2 Hz
    assert overlapping(178.0, 171.8, 2.0)
    # 178 - 3.56 - 3 = 171.44 Hz > 165 + 3.3 + 3 = 171.3 Hz
    assert not overlapping(178.0, 165.0, 2.0)
    assert overlapping(178.0, 165.0, 3.0)            # both windows hold the bin at 171 Hz


@pytest.mark.parametrize("rate_hz, named", [(176.6, "bearing_ball"),            # 2xBSF, slip
                                            (170.9, "bearing_outer_race")])     # BPFO, slip
def test_the_line_goes_to_the_family_whose_window_holds_it_over_the_whole_record(rate_hz,
                                                                                   named):
    top = _row("bearing_outer_race", "1b2")
    ball = _row("bearing_ball", "1b1")
    meas = np.array([25.0, 25.0, 3.0])
    got = resolve_line(_record(rate_hz), 0.5, _decision(top, ball), NAMES, meas,
                       lambda cols: list(cols))
    if named == "bearing_outer_race":
        assert got is None
    else:
        row, how, why = got
        assert row is ball and how == "full resolution"
        assert "the ball defect of the 1b1 bearing" in why
        assert "the outer-race defect of the 1b2 bearing" in why


def test_a_rival_named_on_the_whole_record_keeps_it_when_the_fundamentals_coincide():
    # the ball's 2xBSF 2 % from the named inner race's BPFI: no resolution tells them apart
    freqs = RigFrequencies(fr1_hz=30.0, bearings={
        "1b1": BearingFrequencies(30.0, 12.0, 150.0, 181.0, 92.0, 150.0)})
    rec = _record(183.0)
    rec.model_frequencies = lambda: freqs
    names = ["env_bpfi_1b1_h1_db", "env_bsf2_1b1_h1_db"]
    got = resolve_line(rec, 0.5, _decision(_row("bearing_inner_race", "1b1", names=names),
                                           _row("bearing_ball", "1b1", names=names)),
                       names, np.array([25.0, 25.0]), lambda cols: list(cols))
    assert got is None


def test_a_rival_that_does_not_stand_out_or_cannot_be_named_is_not_asked():
    top = _row("bearing_outer_race", "1b2")
    rec = _record(176.6)
    meas = np.array([25.0, 25.0, 3.0])
    assert resolve_line(rec, 0.5, _decision(top, _row("bearing_ball", "1b1")), NAMES, meas,
                        lambda cols: []) is None
    assert resolve_line(rec, 0.5, _decision(top, _row("bearing_ball", "1b1", nameable=False)),
                        NAMES, meas, lambda cols: list(cols)) is None
    # a named cause that is not a bearing fault is left to the judge
    assert resolve_line(rec, 0.5, _decision(_row("clearance", None), _row("bearing_ball", "1b1")),
                        NAMES, meas, lambda cols: list(cols)) is None


def test_the_margin_is_what_a_steady_line_gains_from_segments_to_a_short_record():
    # 0.5-s segments to a 3-s record: 10 log10(6) = 7.8 dB; the margin stays below it
    assert RESOLUTION_DB < 10.0 * np.log10(3.0 / 0.5)


def test_a_fault_standing_out_on_a_harmonic_alone_yields_to_one_whose_fundamental_stands_out():
    # the inner race stands out on its 2nd harmonic only (another family's 3rd); the outer
    # race's fundamental in the rule's band and two of the bank's
    names = ["env_bpfi_1b1_h1_db", "env_bpfi_1b1_h2_db", "env_bpfo_1b1_h1_db",
             "env_bpfo_1b1_h1_bb2_db", "env_bpfo_1b1_h1_bb3_db"]
    inner = _row("bearing_inner_race", "1b1", out=[1], names=names)
    outer = _row("bearing_outer_race", "1b1", out=[2, 3, 4], names=names, family_z=2.6)
    rec = _record(150.0)                       # BPFO of 1b1: the outer race's own line
    meas = np.array([3.0, 20.0, 15.0, 15.0, 15.0])
    got = resolve_line(rec, 0.5, _decision(inner, outer), names, meas,
                       lambda cols: list(cols))
    assert got is not None and got[0] is outer and got[1] == "fundamental"
    assert "stands out in no band" in got[2]
    # nor where the outer race's line the segments read is not its own over the whole record
    # (impacts at 176.6 Hz: BPFO's window at 150 Hz holds only the floor at 0.33 Hz)
    assert resolve_line(_record(176.6), 0.5, _decision(inner, outer), names, meas,
                        lambda cols: list(cols)) is None
    # not where the inner race's own fundamental stands out in some band, nor for a rival
    # whose change reads the record no nearer than the baseline
    inner_own = _row("bearing_inner_race", "1b1", out=[0, 1], names=names)
    assert resolve_line(rec, 0.5, _decision(inner_own, outer), names, meas,
                        lambda cols: []) is None
    # nor for a fault named with nothing of its own standing out (read on the whole record)
    quiet = _row("bearing_inner_race", "1b1", out=[], names=names)
    assert resolve_line(rec, 0.5, _decision(quiet, outer), names, meas,
                        lambda cols: list(cols)) is None
    worse = _row("bearing_outer_race", "1b1", out=[2, 3, 4], names=names, total=-3.0)
    assert resolve_line(rec, 0.5, _decision(inner, worse), names, meas,
                        lambda cols: []) is None


def test_a_long_record_is_read_over_its_middle_twelve_seconds():
    top = _row("bearing_outer_race", "1b2")
    ball = _row("bearing_ball", "1b1")
    row, how, why = resolve_line(_record(176.6, seconds=20.0), 0.5, _decision(top, ball),
                                 NAMES, np.array([25.0, 25.0, 3.0]),
                                 lambda cols: list(cols))
    assert row is ball and how == "full resolution"
    assert f"({1.0 / FULL_RESOLUTION_MAX_S:.2g} Hz)" in why


# ---------------------------------------------------------------- a family no segment showed

def _bearing_at(rpm):
    """The drive end's (1b1) and fan end's (1b2) families at ``rpm`` (1800 rpm: 30 Hz)."""
    k = rpm / 1800.0
    return RigFrequencies(fr1_hz=30.0 * k, bearings={
        "1b1": BearingFrequencies(*(k * f for f in (30.0, 12.0, 107.0, 163.0, 70.0, 107.0))),
        "1b2": BearingFrequencies(*(k * f for f in (30.0, 11.5, 121.0, 178.0, 77.0, 121.0)))})


def _geared(seed, impacts_hz=None, rpm=1800.0, seconds=3.0, impact=0.5):
    """A gear mesh (a 2-kHz tone modulated at the shaft rate) in white noise, with impacts
    at ``impacts_hz`` ringing a 3-kHz resonance (a race under the mesh)."""
    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    t = np.arange(n) / FS
    mod = 1.0 + 0.3 * np.cos(2 * np.pi * rpm / 60.0 * t)
    x = mod * np.sin(2 * np.pi * 2000.0 * t) + 0.3 * rng.standard_normal(n)
    if impacts_hz:
        hits = np.zeros(n)
        hits[(np.arange(0.0, seconds, 1.0 / impacts_hz) * FS).astype(int)] = impact
        ring = np.exp(-600.0 * t[:200]) * np.sin(2 * np.pi * 3000.0 * t[:200])
        x += np.convolve(hits, ring)[:n]
    return x


def _geared_record(x, rpm=1800.0):
    return SimpleNamespace(signal=x, fs_hz=FS, components={},
                           model_frequencies=lambda speed_rpm=rpm: _bearing_at(speed_rpm))


def _nothing_named():
    rows = [_row(name, b, nameable=False, out=[]) for b in ("1b1", "1b2")
            for name in ("bearing_outer_race", "bearing_inner_race", "bearing_ball")]
    return {"top": None, "ranked": rows + [_row("clearance", None)], "by_signature": [],
            "ties": []}


def test_a_race_under_the_mesh_is_named_where_the_whole_record_shows_its_family():
    # impacts at the drive end's BPFI with slip; the baseline another realisation without
    baseline = [_geared(1).astype(np.float32)]
    decision = _nothing_named()
    row, how, why = buried_family(_geared_record(_geared(2, impacts_hz=163.0 * 1.01)),
                                  baseline, 1800.0, decision)
    assert (row["name"], row["component"], how) == ("bearing_inner_race", "1b1",
                                                    "whole-record family")
    assert "no segment showed" in why
    # the healthy record of the same machine, and a record with something already named
    assert buried_family(_geared_record(_geared(3)), baseline, 1800.0, decision) is None
    named = dict(decision, top=decision["ranked"][0])
    assert buried_family(_geared_record(_geared(2, impacts_hz=163.0 * 1.01)), baseline,
                         1800.0, named) is None


def test_a_long_baseline_is_read_span_by_span_at_the_record_s_length():
    # a 9-s baseline whose last 3 s carry the same impacts (a healthy machine that shows the
    # line at times): the record's rise is read over the highest span, so nothing rises
    quiet, loud = _geared(1, seconds=6.0), _geared(4, impacts_hz=163.0 * 1.01)
    baseline = [np.concatenate([quiet, loud])]
    rec = _geared_record(_geared(2, impacts_hz=163.0 * 1.01))
    assert buried_family(rec, baseline, 1800.0, _nothing_named()) is None
    assert buried_family(rec, [quiet], 1800.0, _nothing_named()) is not None


def test_impacts_too_weak_for_the_whole_record_to_show_name_nothing():
    baseline = [_geared(1)]
    weak = _geared_record(_geared(2, impacts_hz=163.0, impact=0.05))
    assert buried_family(weak, baseline, 1800.0, _nothing_named()) is None


def test_the_baseline_is_read_at_its_own_speed():
    # ball passes at the fan end's BPFO in both (a healthy machine that shows them), the
    # record 4 % faster: read at each one's speed, the line is the baseline's own
    baseline = [_geared(1, rpm=1800.0, impacts_hz=121.0)]
    faster = _geared_record(_geared(2, rpm=1872.0, impacts_hz=121.0 * 1.04), rpm=1872.0)
    assert buried_family(faster, baseline, 1800.0, _nothing_named()) is None
    # read at the record's speed, the baseline's window would miss its own line
    assert buried_family(faster, baseline, 1872.0, _nothing_named()) is not None


def test_two_bearings_whose_families_share_the_line_name_neither(monkeypatch):
    freqs = _bearing_at(1800.0)
    twin = RigFrequencies(fr1_hz=30.0, bearings={"1b1": freqs.bearing("1b1"),
                                                 "1b2": freqs.bearing("1b1")})
    rec = _geared_record(_geared(2, impacts_hz=163.0 * 1.01))
    rec.model_frequencies = lambda speed_rpm=1800.0: twin
    assert buried_family(rec, [_geared(1)], 1800.0, _nothing_named()) is None
    monkeypatch.setattr(resolution, "BURIED_TIE_DB", 0.0)      # the tie is what refuses
    assert buried_family(rec, [_geared(1)], 1800.0, _nothing_named()) is not None


def test_the_rise_asked_lies_above_what_a_healthy_line_wanders_between_records():
    assert BURIED_RISE_DB > 9.5


# ------------------------------------------------- a bearing's line on a shaft's harmonic

# the drive end's 2xBSF (120 Hz) on the shaft's 4th harmonic; its BPFO (107 Hz) on none
COMBED = RigFrequencies(fr1_hz=30.0, bearings={
    "1b1": BearingFrequencies(30.0, 12.0, 107.0, 163.0, 60.0, 107.0)})


def _combed(x):
    return SimpleNamespace(signal=x, fs_hz=FS, components={"1b1": "drive_end"},
                           model_frequencies=lambda speed_rpm=1800.0: COMBED)


def test_a_bearing_line_that_is_a_risen_shaft_comb_is_the_shaft_s():
    baseline = [_geared(1)]
    ball = _row("bearing_ball", "1b1")
    # a once-per-revolution event: impacts at the shaft rate light its whole comb, 120 Hz too
    rev = _combed(_geared(2, impacts_hz=30.0))
    row, why = shaft_comb(rev, baseline, 1800.0, 0.5, _decision(ball))
    assert row is ball
    assert "the input shaft's 4× (120.0 Hz)" in why and "once-per-revolution" in why
    # a ball defect whose line slips 1.5 % below the harmonic: the window beside it rose
    assert shaft_comb(_combed(_geared(2, impacts_hz=120.0 * 0.985)), baseline, 1800.0, 0.5,
                      _decision(ball)) is None
    # both: the shaft's comb and the ball's own line beside it
    both = _geared(2, impacts_hz=30.0) + _geared(3, impacts_hz=120.0 * 0.985) - _geared(3)
    assert shaft_comb(_combed(both), baseline, 1800.0, 0.5, _decision(ball)) is None
    # a healthy record; a fault whose fundamental shares no harmonic's line; no fault named
    assert shaft_comb(_combed(_geared(3)), baseline, 1800.0, 0.5, _decision(ball)) is None
    assert shaft_comb(rev, baseline, 1800.0, 0.5,
                      _decision(_row("bearing_outer_race", "1b1"))) is None
    assert shaft_comb(rev, baseline, 1800.0, 0.5, _decision(_row("clearance", None))) is None
    assert shaft_comb(rev, baseline, 1800.0, 0.5, _decision(None)) is None
    # nor without a baseline to read the comb's rise over
    assert shaft_comb(rev, [], 1800.0, 0.5, _decision(ball)) is None


def test_the_comb_s_rise_is_read_over_the_baseline_s_own():
    # a machine whose healthy baseline already carries the once-per-revolution comb
    baseline = [_geared(1, impacts_hz=30.0)]
    assert shaft_comb(_combed(_geared(2, impacts_hz=30.0)), baseline, 1800.0, 0.5,
                      _decision(_row("bearing_ball", "1b1"))) is None
    assert COMB_RISE_DB > 5.2       # a bearing defect lifted a comb by up to 5.2 dB


def test_the_window_beside_a_harmonic_leaves_out_the_harmonic_s_leakage():
    """A ball whose 2xBSF lies 2 % over the shaft's 4th harmonic (122.4 against 120 Hz): its
    window beside the harmonic starts 2.5 bins from it, where a once-per-revolution comb's
    line 40-50 dB over the floor still leaks tens of dB over it (the angle generator's gear
    machine 3: a fan-end outer race 1.9 Hz from the input's 4x, its window beside the
    harmonic 'risen' by that leakage alone). Its bins reach as far as its leakage stands
    over the floor; a ball line of its own there still rises."""
    near = RigFrequencies(fr1_hz=30.0, bearings={
        "1b1": BearingFrequencies(30.0, 12.0, 107.0, 163.0, 61.2, 107.0)})
    ball = _row("bearing_ball", "1b1")
    t = 3.0125                  # 361.5 cycles of 120 Hz: the comb's lines between bins
    baseline = [_geared(1, seconds=t)]

    def rec(x):
        return SimpleNamespace(signal=x, fs_hz=FS, components={"1b1": "drive_end"},
                               model_frequencies=lambda speed_rpm=1800.0: near)

    comb = _geared(2, impacts_hz=30.0, impact=20.0, seconds=t)      # 4x: 49 dB over floor
    got = shaft_comb(rec(comb), baseline, 1800.0, 0.5, _decision(ball))
    assert got is not None and got[0] is ball, "the harmonic's leakage read as a line"
    own = comb + _geared(3, impacts_hz=123.6, seconds=t) - _geared(3, seconds=t)
    assert shaft_comb(rec(own), baseline, 1800.0, 0.5, _decision(ball)) is None
