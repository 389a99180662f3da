"""The decision of a comparison against a machine (cmsim.discrepancy.judge.decide_record).

Tier (a) closed form: a hand-made signature library (the baseline at 0 on every feature, an
outer-race entry that lifts its envelope lines and a noise entry that lifts every shape band)
and records made of known departures. A record within the baseline's spread is ``none``; a
cause whose prediction reads the whole record is named; where none does, a fault is named on
its own family only if that family stands out (3 σ and 6 dB over the baseline) — a family
lifted 4 dB over a record that departs elsewhere is ``unexplained``, one lifted 8 dB is the
outer race; a noise cause that would make the record quieter is no candidate.
"""

from dataclasses import replace

import numpy as np
import pytest

from cmsim.discrepancy.columns import compared_columns, feature_sigma
from cmsim.discrepancy.judge import FAMILY_RISE_DB, decide_record
from cmsim.discrepancy.ranking import NEAR_TIE
from cmsim.machine.library import SignatureEntry, SignatureLibrary

NAMES = ("env_bpfo_1b1_h1_db", "env_bpfo_1b1_h2_db", "kurtosis_log", "crest_log",
         "shape_b0_db", "shape_b1_db", "level_db")
ENV, SHAPE, LEVEL = [0, 1], [4, 5], 6


def _library():
    m = len(NAMES)
    outer = np.zeros((3, m))
    outer[:, ENV] = np.array([[0.0], [5.0], [20.0]])           # sizes 0.03, 0.3, 3 mm
    noise = np.zeros((2, m))
    noise[:, SHAPE] = np.array([[2.0], [12.0]])                 # the bands fill
    noise[:, LEVEL] = [1.0, 10.0]                               # louder
    noise[:, ENV] = [-1.0, -6.0]                                # the lines drown
    return SignatureLibrary(
        names=NAMES, mean=np.zeros(m), spread=np.ones(m), realisation=np.zeros(m),
        entries=(SignatureEntry("bearing_outer_race", "1b1", "documented", "size_m",
                                (3e-5, 3e-4, 3e-3), outer),
                 SignatureEntry("noise", None, "documented", "noise_ratio", (0.2, 2.0),
                                noise)),
        segment_s=0.5, segments=8, speed_rpm=1797.0, torque_nm=0.0, radial_load_n=98.0)


def _baseline_at_zero(names, spread, *entries):
    """A library whose baseline reads 0 on every feature, with the given spread and
    entries (one record's segments: 8)."""
    m = len(names)
    return SignatureLibrary(names=names, mean=np.zeros(m), spread=spread,
                            realisation=np.zeros(m), entries=entries, segment_s=0.5,
                            segments=8, speed_rpm=1797.0, torque_nm=0.0, radial_load_n=98.0)


def _outer_race_family_lifted(family, quiet, lift):
    """decide_record on a record whose outer-race ``family`` columns (spread 3.5 dB: σ 1.9)
    are lifted by ``lift`` dB over a baseline at 0, its ``quiet`` columns (spread 1) at it;
    the library's outer race lifts the family 0, 5 and 20 dB over its three sizes."""
    names = tuple(family) + tuple(quiet)
    m, k = len(names), len(family)
    outer = np.zeros((3, m))
    outer[:, :k] = np.array([[0.0], [5.0], [20.0]])
    spread = np.ones(m)
    spread[:k] = 3.5
    lib = _baseline_at_zero(
        names, spread,
        SignatureEntry("bearing_outer_race", "1b1", "documented", "size_m",
                       (3e-5, 3e-4, 3e-3), outer))
    li = np.arange(m)
    meas = np.zeros(m)
    meas[:k] = lift
    return decide_record(lib, li, list(names), meas, feature_sigma(lib, li, list(names), 8),
                         "1b1")


def _decide(meas):
    lib = _library()
    li = np.arange(len(NAMES))
    sigma = feature_sigma(lib, li, list(NAMES), 8)
    return decide_record(lib, li, list(NAMES), np.asarray(meas, dtype=float), sigma, "1b1")


def test_a_record_within_the_spread_is_none():
    d = _decide([0.3, -0.2, 0.02, 0.0, 0.4, -0.3, 0.1])
    assert d["finding"] == "none" and d["top"] is None


def test_a_cause_whose_prediction_reads_the_whole_record_is_named():
    d = _decide([-3.5, -3.5, 0.0, 0.0, 7.0, 7.0, 5.5])           # noise at about 1 (log)
    assert (d["finding"], d["decided_on"]) == ("noise", "whole")
    assert 0.5 < d["top"]["value"] < 2.0


def test_a_cause_excluded_at_one_component_is_not_read_there():
    d = _decide([20.0, 20.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert (d["finding"], d["top"]["component"]) == ("bearing_outer_race", "1b1")
    lib = _library()
    li = np.arange(len(NAMES))
    sigma = feature_sigma(lib, li, list(NAMES), 8)
    meas = np.array([20.0, 20.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    d = decide_record(lib, li, list(NAMES), meas, sigma, "1b1",
                      excluded={("bearing_outer_race", "1b1")})
    assert d["finding"] != "bearing_outer_race"
    assert all(r["name"] != "bearing_outer_race" for r in d["ranked"])
    # another component's exclusion leaves it
    d = decide_record(lib, li, list(NAMES), meas, sigma, "1b1",
                      excluded={("bearing_outer_race", "2b1")})
    assert d["finding"] == "bearing_outer_race"


@pytest.mark.parametrize("lift, finding", [(4.0, "unexplained"), (8.0, "bearing_outer_race")])
def test_a_fault_named_on_its_family_only_where_the_family_stands_out(lift, finding):
    """The record's envelope lines lifted by ``lift`` dB and its low bands moved far where no
    cause of the library moves them: no prediction reads most of the record, so only a family
    standing out names a fault (and 4 dB, though many σ, is under the 6 dB)."""
    assert 4.0 < FAMILY_RISE_DB < 8.0
    d = _decide([lift, lift, 0.0, 0.0, -30.0, -30.0, 0.0])
    assert d["finding"] == finding, [(r["name"], r["evidence"], r["nameable"])
                                     for r in d["ranked"]]
    if finding != "unexplained":
        assert d["decided_on"] == "family" and d["top"]["component"] == "1b1"


@pytest.mark.parametrize("other, finding", [(0.0, "bearing_outer_race"),
                                            (10.0, "unexplained")])
def test_a_fault_is_named_on_its_family_only_where_its_whole_change_reads_the_record(
        other, finding):
    """A record whose outer-race family stands 8 dB over the baseline and whose low bands
    moved far where no cause moves them, read by an outer race whose change also lifts the
    inner race's family by ``other`` dB at every size, which the record kept at the
    baseline: where the fault's whole change, at every size, takes the record farther from
    its prediction than the baseline alone is, its family standing out does not make it the
    record's fault (a size whose change does not is read first: the test below)."""
    names = ("env_bpfo_1b1_h1_db", "env_bpfo_1b1_h2_db", "env_bpfi_1b1_h1_db",
             "env_bpfi_1b1_h2_db", "shape_b0_db", "shape_b1_db")
    outer = np.zeros((3, len(names)))
    outer[:, :2] = np.array([[0.0], [5.0], [20.0]])
    outer[:, 2:4] = other
    spread = np.ones(len(names))
    spread[:4] = 3.5
    lib = _baseline_at_zero(names, spread,
                            SignatureEntry("bearing_outer_race", "1b1", "documented", "size_m",
                                           (3e-5, 3e-4, 3e-3), outer))
    li = np.arange(len(names))
    meas = np.array([8.0, 8.0, 0.0, 0.0, -30.0, -30.0])
    d = decide_record(lib, li, list(names), meas, feature_sigma(lib, li, list(names), 8),
                      "1b1")
    row = d["by_signature"][0]
    assert row["name"] == "bearing_outer_race" and row["stands_out"]
    assert row["delta_chi2"] > 0.0 and (row["total"] > 0.0) == (other == 0.0)
    assert d["finding"] == finding, (row["delta_chi2"], row["total"])


def test_a_fault_s_signature_is_read_at_a_variant_whose_whole_change_reads_the_record():
    """The same record and outer race as above, its 3x-path variant lifting the inner race's
    family 10 dB with its own (the model's impacts through a loud path lifted the mesh's
    sidebands 38 dB where the angle generator's record kept them), and a line-contact variant
    that lifts the outer race's family alone, less: the family is read at the variant whose
    whole change takes the record nearer than the baseline alone, and the outer race is
    named on it; with that variant gone, the loud one is read and nothing is named."""
    names = ("env_bpfo_1b1_h1_db", "env_bpfo_1b1_h2_db", "env_bpfi_1b1_h1_db",
             "env_bpfi_1b1_h2_db", "shape_b0_db", "shape_b1_db")
    sizes = (3e-5, 3e-4, 3e-3)
    loud, quiet = np.zeros((3, len(names))), np.zeros((3, len(names)))
    loud[:, :2] = np.array([[0.0], [5.0], [20.0]])
    loud[:, 2:4] = 10.0
    quiet[:, :2] = np.array([[0.0], [3.0], [9.0]])
    spread = np.ones(len(names))
    spread[:4] = 3.5
    entries = (SignatureEntry("bearing_outer_race", "1b1", "documented; path x3", "size_m",
                              sizes, loud),
               SignatureEntry("bearing_outer_race", "1b1", "line contact", "size_m", sizes,
                              quiet))
    li = np.arange(len(names))
    meas = np.array([8.0, 8.0, 0.0, 0.0, -30.0, -30.0])
    got = {}
    for kept in (entries, entries[:1]):
        lib = _baseline_at_zero(names, spread, *kept)
        got[len(kept)] = decide_record(lib, li, list(names), meas,
                                       feature_sigma(lib, li, list(names), 8), "1b1")
    row = got[2]["by_signature"][0]
    assert (row["name"], row["variant"]) == ("bearing_outer_race", "line contact")
    assert row["total"] > 0.0 and row["stands_out"]
    assert (got[2]["finding"], got[2]["decided_on"]) == ("bearing_outer_race", "family")
    assert got[1]["by_signature"][0]["total"] < 0.0
    assert got[1]["finding"] == "unexplained"


@pytest.mark.parametrize("env, finding", [(0.0, "bearing_outer_race"), (8.0, "unexplained")])
def test_a_family_the_best_reshaping_reading_lifts_as_far_names_no_fault(env, finding):
    """The record's envelope lines 8 dB over the baseline, its kurtosis up and its low bands
    moved far where no cause moves them: no cause reads most of the record. A load change
    reads its kurtosis and lifts the envelope lines by ``env`` dB (a torque moves which balls
    carry the load, and with them the ball-pass lines): where it lifts them as far as the
    record, they stand out over no one's prediction but the baseline's, and the outer race
    is not named on them (cmsim's own torque mismatch was named an inner race so)."""
    from cmsim.discrepancy.judge import MIN_EVIDENCE

    outer = np.zeros((3, len(NAMES)))
    outer[:, ENV] = np.array([[0.0], [5.0], [20.0]])
    load = np.zeros((2, len(NAMES)))
    load[:, 2] = [0.0, 3.0]                                      # kurtosis_log
    load[1, ENV] = env
    lib = replace(_library(), entries=(
        SignatureEntry("bearing_outer_race", "1b1", "documented", "size_m",
                       (3e-5, 3e-4, 3e-3), outer),
        SignatureEntry("torque_mismatch", None, "documented", "load_factor", (1.0, 3.0),
                       load)))
    li = np.arange(len(NAMES))
    meas = np.array([8.0, 8.0, 3.0, 0.0, -30.0, -30.0, 0.0])
    d = decide_record(lib, li, list(NAMES), meas, feature_sigma(lib, li, list(NAMES), 8),
                      "1b1")
    load_row = next(r for r in d["ranked"] if r["name"] == "torque_mismatch")
    assert d["decided_on"] in ("family", "") and load_row["evidence"] >= MIN_EVIDENCE
    row = next(r for r in d["by_signature"] if r["name"] == "bearing_outer_race")
    assert row["stands_out"] and row["total"] > 0.0
    assert d["finding"] == finding, [(r["name"], r["evidence"]) for r in d["ranked"]]


def test_a_cause_that_adds_power_is_no_candidate_for_a_quieter_record():
    """The shape bands moved as noise moves them, but the record is 12 dB quieter: noise
    cannot make a machine quieter."""
    d = _decide([-3.5, -3.5, 0.0, 0.0, 7.0, 7.0, -12.0])
    assert d["finding"] != "noise"
    assert all(r["name"] != "noise" for r in d["ranked"])


@pytest.mark.parametrize("lift, finding", [(4.0, "none"), (7.0, "bearing_outer_race")])
def test_one_family_standing_clearly_out_of_a_quiet_record_is_a_departure(lift, finding):
    """The envelope lines lifted by ``lift`` dB on a record otherwise at its baseline, among
    many quiet features: over all of them the record reads within the spread (χ² per
    feature under the ``none`` level, no feature at the alarm z), yet a family 7 dB and
    3 σ over the baseline, which the outer race's prediction reads, is that fault; 4 dB
    stays ``none``."""
    from cmsim.discrepancy.judge import ALARM_Z, FAMILY_Z, NONE_CHI2_PER_FEATURE

    quiet = tuple(f"raw_fr_h{k}_db" for k in range(1, 31))
    d = _outer_race_family_lifted(NAMES[:2], quiet, lift)
    assert d["chi2"] / d["n_eff"] <= NONE_CHI2_PER_FEATURE          # quiet over all
    assert np.abs(d["z"]).max() < ALARM_Z
    assert (d["z"][0] >= FAMILY_Z) == (lift == 7.0)
    assert d["finding"] == finding


@pytest.mark.parametrize("lift, finding", [(4.0, "none"), (8.0, "unexplained")])
def test_a_family_standing_out_in_one_band_alone_is_a_departure(lift, finding):
    """A spall's family read band by band (weightless in the χ²) lifted by ``lift`` dB in one
    band, the record otherwise at its baseline: χ² per feature 0, no feature at the alarm z.
    8 dB and 4 σ over the baseline is outside its spread, so the record is not ``none``; no
    cause's prediction reads it (the lifted column weighs nothing), so it is
    ``unexplained``, departing there. 4 dB stays ``none``."""
    from cmsim.discrepancy.judge import ALARM_Z, FAMILY_Z, NONE_CHI2_PER_FEATURE
    from cmsim.discrepancy.evaluator import weight

    band = "env_bpfo_1b1_h1_bb4_db"
    assert weight(band) == 0.0
    d = _outer_race_family_lifted((band,), tuple(f"raw_fr_h{k}_db" for k in range(1, 11)),
                                  lift)
    assert d["chi2"] / d["n_eff"] <= NONE_CHI2_PER_FEATURE and np.abs(d["z"]).max() < ALARM_Z
    assert (d["z"][0] >= FAMILY_Z) == (lift == 8.0)
    assert d["finding"] == finding
    assert int(np.argmax(np.abs(d["z"]))) == 0                  # where it departs


@pytest.mark.parametrize("moved, finding", [(4.0, "none"), (7.0, "transfer_path"),
                                            (-7.0, "transfer_path")])
def test_a_band_of_the_shape_moved_either_way_is_a_departure(moved, finding):
    """Two bands of the spectrum's shape moved by ``moved`` dB the opposite ways (a resonance
    moving from one band to the next; spread 1 dB, so 7 dB is 6 σ) and twenty raw lines at
    the baseline: χ² per feature within the spread and no feature at the alarm z. 7 dB
    either way departs, and the library's moved path that makes it is named; 4 dB, under
    the 6 dB of a band that stands out, stays ``none``."""
    from cmsim.discrepancy.judge import ALARM_Z, NONE_CHI2_PER_FEATURE

    names = ("shape_b4_db", "shape_b5_db") + tuple(f"raw_fr_h{k}_db" for k in range(1, 21))
    m = len(names)
    path = np.zeros((3, m))
    path[:, :2] = np.array([[-7.0, 7.0], [0.0, 0.0], [7.0, -7.0]])
    lib = _baseline_at_zero(names, np.ones(m), SignatureEntry(
        "transfer_path", None, "documented", "frequency_factor", (0.8, 1.0, 1.25), path))
    li = np.arange(m)
    meas = np.zeros(m)
    meas[:2] = [moved, -moved]
    d = decide_record(lib, li, list(names), meas, feature_sigma(lib, li, list(names), 8),
                      "1b1")
    assert d["chi2"] / d["n_eff"] <= NONE_CHI2_PER_FEATURE and np.abs(d["z"]).max() < ALARM_Z
    assert d["finding"] == finding
    if finding != "none":
        assert d["top"]["value"] == pytest.approx(1.25 if moved > 0 else 0.8, rel=0.05)


@pytest.mark.parametrize("other, finding", [(6.0, "bearing_outer_race"),
                                            (7.0, "torque_mismatch")])
def test_a_fault_whose_family_stands_out_wins_a_near_tie_on_the_whole_record(other, finding):
    """An outer race lifts its envelope lines 12 dB (its family stands out) and a torque
    mismatch explains the shaft lines and the level the record lifted by ``other`` dB: at
    6 dB the torque mismatch reads the whole record a little better, within the near tie,
    and the fault whose family stands out is named; at 7 dB the outer race holds under 0.8
    of the torque mismatch's evidence, no tie, and the better reading stands."""

    names = ("env_bpfo_1b1_h1_db", "env_bpfo_1b1_h2_db", "raw_fr_h1_db", "raw_fr_h2_db",
             "level_db", "raw_bpfi_1b1_db", "raw_bpfi_1b2_db")
    m = len(names)
    outer = np.zeros((3, m))
    outer[:, :2] = np.array([[0.0], [4.0], [16.0]])
    outer[:, 4] = [0.0, 0.5, 2.0]                          # an impact adds a little power
    torque = np.zeros((2, m))
    torque[:, 2:5] = np.array([[0.0], [9.0]])
    spread = np.ones(m)
    spread[:2] = 3.0
    lib = _baseline_at_zero(
        names, spread,
        SignatureEntry("bearing_outer_race", "1b1", "documented", "size_m",
                       (3e-5, 3e-4, 3e-3), outer),
        SignatureEntry("torque_mismatch", None, "documented", "torque_factor",
                       (1.0, 3.0), torque))
    li = np.arange(m)
    meas = np.zeros(m)
    meas[:2], meas[2:5] = 12.0, other
    d = decide_record(lib, li, list(names), meas, feature_sigma(lib, li, list(names), 8),
                      "1b1")
    by = {r["name"]: r for r in d["ranked"]}
    assert d["ranked"][0]["name"] == "torque_mismatch"          # the better whole reading
    assert by["bearing_outer_race"]["stands_out"] and not by["torque_mismatch"]["stands_out"]
    tie = by["bearing_outer_race"]["evidence"] >= NEAR_TIE * by["torque_mismatch"]["evidence"]
    assert tie == (other == 6.0)
    assert (d["finding"], d["decided_on"]) == (finding, "whole")


def _across_loads(monkeypatch, shift):
    """The closed-form library read at another load, the model's change between the loads
    being ``shift``."""
    from types import SimpleNamespace

    import cmsim.discrepancy.operating_point as operating_point
    from cmsim.rig import OperatingPoint

    monkeypatch.setattr(operating_point, "operating_shift",
                        lambda machine, lib, op, threads=1: shift)
    machine = SimpleNamespace(op=OperatingPoint(speed_rpm=1797.0, torque_nm=0.0,
                                                radial_load_n=98.0))
    moved, note = operating_point.at_operating_point(
        machine, _library(), OperatingPoint(speed_rpm=1797.0, torque_nm=0.0,
                                           radial_load_n=400.0))
    assert "within that change's own size" in note
    return moved


def _decide_on(lib, meas):
    li = np.arange(len(NAMES))
    sigma = feature_sigma(lib, li, list(NAMES), 8)
    return decide_record(lib, li, list(NAMES), np.asarray(meas, dtype=float), sigma, "1b1")


def test_a_record_across_loads_is_read_within_the_model_s_load_change(monkeypatch):
    """The model says the other load quiets the broadband 12 dB; the machine's healthy record
    at that load stays on its baseline (SpectraQuest's does: its sidebands and bands sit where
    they were at 0 %). Read with the change as exact it departs 12 σ on every band; read
    within the change's own size it is ``none``. A family the load does not move, lifted
    20 dB, is still the outer race."""
    shift = np.zeros(len(NAMES))
    shift[SHAPE] = -12.0
    shift[LEVEL] = -3.0
    moved = _across_loads(monkeypatch, shift)
    np.testing.assert_allclose(moved.mean, shift)
    np.testing.assert_allclose(moved.realisation, np.abs(shift))
    healthy = [0.3, -0.2, 0.02, 0.0, 0.4, -0.3, 0.1]
    assert _decide_on(moved, healthy)["finding"] == "none"
    exact = replace(moved, realisation=np.zeros(len(NAMES)))
    assert _decide_on(exact, healthy)["finding"] != "none"      # the check can fail
    faulty = [20.0, 20.0, 0.0, 0.0, 0.4, -0.3, 0.1]
    assert _decide_on(moved, faulty)["finding"] == "bearing_outer_race"


GEAR_NAMES = ("sb1_fr1_k1_db", "sb1_fr1_k2_db", "sb1_fr1_k3_db", "raw_fr_h1_db",
              "env_fr_h1_db", "shape_b0_db", "shape_b1_db")
SB, ONCE = [0, 1, 2], [3, 4]


def _gear_library():
    """A speed fluctuation lifts every shaft-rate sideband of the mesh and lowers the 1×
    lines a little; an eccentricity lifts its 1× lines and hardly the sidebands."""
    m = len(GEAR_NAMES)
    fluct = np.zeros((3, m))
    fluct[:, SB] = np.array([[0.5], [5.0], [15.0]])
    fluct[:, ONCE] = np.array([[0.0], [-0.5], [-1.5]])
    ecc = np.zeros((3, m))
    ecc[:, SB] = np.array([[0.0], [0.3], [1.0]])
    ecc[:, ONCE] = np.array([[0.5], [3.0], [8.0]])
    return SignatureLibrary(
        names=GEAR_NAMES, mean=np.zeros(m), spread=np.ones(m), realisation=np.zeros(m),
        entries=(SignatureEntry("speed_fluctuation", None, "documented", "relative_amplitude",
                                (1e-3, 1e-2, 1e-1), fluct),
                 SignatureEntry("eccentricity", "1G1", "documented", "amplitude_m",
                                (2e-6, 2e-5, 1.5e-4), ecc)),
        segment_s=0.5, segments=8, speed_rpm=1500.0, torque_nm=20.0, radial_load_n=0.0)


@pytest.mark.parametrize("once, finding", [(0.0, "speed_fluctuation"),
                                           (-1.5, "speed_fluctuation"),
                                           (4.0, "speed_fluctuation"),
                                           (-5.5, "speed_fluctuation"),
                                           (12.0, "eccentricity"),
                                           (-12.0, "eccentricity")])
def test_a_mesh_modulation_with_a_moved_once_per_rev_line_is_an_eccentric_gear(once, finding):
    """The sidebands risen 15 dB, as the speed fluctuation makes them and the eccentricity
    does not; the 1× lines as the fluctuation leaves them (0, −1.5 dB), within the 6 dB a
    family must stand out by (4 dB over them, 4 dB under), or 12 dB over them, which a
    speed fluctuation cannot make: an eccentric gear's mass turning off-centre while its
    run-out modulates the mesh (EccentricityCause.absorbs). Its mass adds to the rotor's
    residual unbalance at its own phase, so the raw 1× line may as well fall 10.5 dB under
    the fluctuation's prediction (EccentricityCause.either_way; the angle generator's
    eccentric gear of seed 3 lowered it 9.3 dB)."""
    lib = _gear_library()
    li = np.arange(len(GEAR_NAMES))
    meas = np.array([15.0, 15.0, 15.0, once, once, 0.0, 0.0])
    sigma = feature_sigma(lib, li, list(GEAR_NAMES), 8)
    d = decide_record(lib, li, list(GEAR_NAMES), meas, sigma, "1b1")
    assert d["finding"] == finding, [(r["name"], r["chi2"]) for r in d["ranked"]]
    if finding == "eccentricity":
        assert (d["top"]["component"], d["decided_on"]) == ("1G1", "beside")
        assert [r["name"] for r in d["ties"]] == ["speed_fluctuation"]
        assert [GEAR_NAMES[i] for i in d["top"]["out"]] == (
            ["raw_fr_h1_db", "env_fr_h1_db"] if once > 0 else ["raw_fr_h1_db"])
    if finding == "eccentricity" and once > 0:
        # its size read where its family stands out: the largest, whose 1x lines rise 8 dB
        assert d["top"]["value"] == pytest.approx(1.5e-4)


@pytest.mark.parametrize("gate, finding", [("run", "eccentricity"),
                                           ("realisation", "speed_fluctuation")])
def test_a_family_stands_out_by_the_model_s_run_spread_not_by_its_background_s(gate, finding):
    """The 1x lines 12 dB over the fluctuation's prediction where the baseline holds them
    steadily (the angle generator's eccentric gears of machines 9 and 10): the twin's
    background drawn afresh spreads them by 5 dB (``realisation``, the chi2's), the model's
    runs on the machine's own lines by none (``run_spread``). The gate of a family that
    stands out reads the run spread; read by the realisation spread (2.3 sigma, under
    FAMILY_Z) the eccentric gear yields to the speed fluctuation."""
    lib = _gear_library()
    realisation = np.zeros(len(GEAR_NAMES))
    realisation[ONCE] = 5.0
    lib = replace(lib, realisation=realisation, run_spread=np.zeros(len(GEAR_NAMES)))
    li = np.arange(len(GEAR_NAMES))
    meas = np.array([15.0, 15.0, 15.0, 12.0, 12.0, 0.0, 0.0])
    sigma = feature_sigma(lib, li, list(GEAR_NAMES), 8)
    standing = feature_sigma(lib, li, list(GEAR_NAMES), 8, standing=gate == "run")
    d = decide_record(lib, li, list(GEAR_NAMES), meas, sigma, "1b1", gate_sigma=standing)
    assert d["finding"] == finding
    assert np.all(standing[ONCE] < sigma[ONCE]) == (gate == "run")


@pytest.mark.parametrize("lift, finding", [(3.0, "tooth_fault"), (12.0, "bearing_outer_race")])
def test_a_fault_with_none_of_its_family_risen_yields_to_one_whose_family_stands_out(
        lift, finding):
    """A gear machine's outer race (the angle generator's): its impacts ring a band the mesh
    does not reach, so the band the envelope is read in moves there and the spectrum's shape
    with it — which a tooth fault's impacts make too, and read best over the whole record,
    though none of its sidebands rose. Its envelope lines stand ``lift`` dB over the
    baseline, which the tooth fault's prediction leaves: 12 dB (3 σ and 6 dB over that
    prediction) is the outer race, however far behind on the whole record; 3 dB stays the
    tooth fault's reading."""

    quiet = tuple(f"raw_fr_h{k}_db" for k in range(1, 61))
    names = (("env_bpfo_1b1_h1_db", "env_bpfo_1b1_h2_db", "sb1_fr1_k1_db", "sb1_fr1_k2_db")
             + tuple(f"shape_b{k}_db" for k in range(10)) + quiet)
    m = len(names)
    tooth = np.zeros((3, m))
    tooth[:, 2:4] = np.array([[0.0], [0.3], [1.0]])       # its sidebands hardly move
    tooth[:, 4:14] = np.array([[0.0], [2.0], [8.0]])      # its impacts reshape the spectrum
    outer = np.zeros((3, m))
    outer[:, :2] = np.array([[0.0], [8.0], [24.0]])
    outer[:, 4:14] = np.array([[0.0], [0.2], [1.0]])
    spread = np.ones(m)
    spread[:2] = 3.0
    lib = _baseline_at_zero(
        names, spread,
        SignatureEntry("tooth_fault", "1G1", "documented", "lost_height_m",
                       (1e-4, 5e-4, 3e-3), tooth),
        SignatureEntry("bearing_outer_race", "1b1", "documented", "size_m",
                       (3e-5, 3e-4, 3e-3), outer))
    li = np.arange(m)
    meas = np.zeros(m)
    meas[:2], meas[4:14] = lift, 8.0
    d = decide_record(lib, li, list(names), meas, feature_sigma(lib, li, list(names), 8),
                      "1b1")
    by = {r["name"]: r for r in d["ranked"]}
    assert d["ranked"][0]["name"] == "tooth_fault"               # the better whole reading
    assert not by["tooth_fault"]["stands_out"]
    assert by["bearing_outer_race"]["stands_out"] == (lift == 12.0)
    assert by["bearing_outer_race"]["evidence"] < NEAR_TIE * by["tooth_fault"]["evidence"]
    assert (d["finding"], d["decided_on"]) == (finding, "whole")
    if finding == "bearing_outer_race":
        assert [r["name"] for r in d["ties"]][:1] == ["tooth_fault"]


def test_a_line_two_families_share_is_read_as_either_where_the_library_tells_them_apart():
    """The angle generator's ball (2·BSF 3 % over BPFI) lifts one envelope line both
    families' windows hold: the record reads the two columns alike, the library (the model
    makes each fault's line where its kinematics put it) does not. Each keeps its column,
    and the ball, whose prediction leaves the inner race's sidebands where they are, is
    named; with the ball's column dropped as a copy, the inner race was. Columns the library
    reads alike too (the two shafts of a 1:1 rig) stay one."""
    names = ("env_bpfi_1b1_h1_db", "env_bsf2_1b1_h1_db", "env_bpfi_1b1_sb_db",
             "kurtosis_log", "crest_log")
    m = len(names)
    sizes = (3e-5, 3e-4, 3e-3)
    inner, ball = np.zeros((3, m)), np.zeros((3, m))
    inner[:, 0] = inner[:, 2] = [0.0, 10.0, 20.0]    # BPFI and its shaft-rate sidebands
    ball[:, 1] = [0.0, 10.0, 20.0]                   # 2·BSF
    lib = _baseline_at_zero(
        names, np.full(m, 2.0),
        SignatureEntry("bearing_inner_race", "1b1", "documented", "size_m", sizes, inner),
        SignatureEntry("bearing_ball", "1b1", "documented", "size_m", sizes, ball))
    rng = np.random.default_rng(0)
    fit, held = rng.normal(0.0, 1.0, (4, m)), rng.normal(0.0, 1.0, (4, m))
    for rows in (fit, held):
        rows[:, 0] += 20.0
        rows[:, 1] = rows[:, 0]                      # one line in both windows
    li, ri, cnames = compared_columns(list(names), lib, fit, held)
    assert cnames == list(names)
    meas = fit[:, ri].mean(axis=0)
    d = decide_record(lib, li, cnames, meas, feature_sigma(lib, li, cnames, 4), "1b1")
    assert (d["finding"], d["top"]["component"]) == ("bearing_ball", "1b1")

    alike = replace(lib, entries=tuple(replace(e, features=e.features[:, [0, 0, 2, 3, 4]])
                                       for e in lib.entries))
    assert compared_columns(list(names), alike, fit, held)[2] == [
        "env_bpfi_1b1_h1_db", "env_bpfi_1b1_sb_db", "kurtosis_log", "crest_log"]


def _reshaped_by_a_load(low, high, unnameable_fault=False):
    """decide_record on a record whose eight lines a load change moves +10 dB (its library
    entry at the larger of two sizes; spread 1 dB), the record's moved ``low`` dB on half of
    them and ``high`` on the others; with ``unnameable_fault``, an outer race on the other
    shaft whose change reads the record 2 dB off everywhere and whose family (not among the
    features) does not stand out."""
    names = ("raw_fr_h1_db", "raw_fr_h2_db", "raw_fr_h3_db", "raw_fr_h4_db",
             "gmf1_rel_db", "gmf2_rel_db", "gmf3_rel_db", "gmf4_rel_db")
    m = len(names)
    load = np.zeros((2, m))
    load[1] = 10.0
    load[0] = 5.0
    meas = np.zeros(m)
    meas[0::2], meas[1::2] = low, high
    entries = [SignatureEntry("torque_mismatch", None, "documented", "load_factor",
                              (2.0, 4.0), load)]
    if unnameable_fault:
        entries.append(SignatureEntry("bearing_outer_race", "1b2", "documented", "size_m",
                                      (3e-5, 3e-4), np.vstack([meas + 2.0, meas + 2.0])))
    lib = _baseline_at_zero(names, np.ones(m), *entries)
    li = np.arange(m)
    sigma = feature_sigma(lib, li, list(names), 8)
    return decide_record(lib, li, list(names), meas, sigma, "1b1"), (meas, sigma, names)


@pytest.mark.parametrize("low, high, fault, finding", [
    (7.0, 13.0, False, "torque_mismatch"),      # within the strict share
    (3.0, 17.0, False, "torque_mismatch"),      # within its prediction's own error
    (3.0, 17.0, True, "unexplained"),           # a fault that cannot be named reads it better
    (-2.0, 22.0, False, "unexplained")])        # beyond its prediction's error
def test_a_reshaping_cause_is_named_within_its_prediction_s_own_error(low, high, fault,
                                                                       finding):
    """A load change the library predicts at +10 dB on eight lines, read on a record that moved
    them 3 and 17 dB: its prediction misses by 7 dB where the baseline's spread is 1, so it
    removes less than MIN_SHARE of the record's departure. But the library's change is one
    run of the model and the record another (cmsim's own torque mismatch at 3.4 times the
    load: bearing envelope lines 11-12 dB off its prediction), so where no family names a
    fault, a reshaping cause is named if it removes that share within PREDICTION_ERROR of the
    change it predicts, and if no cause reads the record better: a fault that cannot be named
    (its family does not stand out) reading it better leaves it ``unexplained``; so does a
    miss far beyond that error."""
    from cmsim.discrepancy.judge import MIN_SHARE, PREDICTION_ERROR, within_error
    d, (meas, sigma, names) = _reshaped_by_a_load(low, high, fault)
    assert d["finding"] == finding, [(r["name"], r["evidence"]) for r in d["ranked"]]
    load = next(r for r in d["ranked"] if r["name"] == "torque_mismatch")
    excess = d["chi2"] - d["n_eff"]
    if (low, high) == (3.0, 17.0):
        assert load["evidence"] < MIN_SHARE * excess <= d["chi2"] - within_error(
            load, meas, np.zeros(len(names)), sigma, list(names))
        assert 0.2 <= PREDICTION_ERROR <= 0.5
    if finding == "torque_mismatch":
        assert d["decided_on"] == ("whole" if low == 7.0 else "within error")
        assert d["top"]["value"] > 2.5


@pytest.mark.parametrize("sb_rise, finding", [(0.0, "tooth_fault"),
                                               (10.0, "bearing_outer_race")])
def test_a_near_tie_is_told_apart_on_what_each_fault_adds_not_on_a_family_that_fell(
        sb_rise, finding):
    """A record whose outer-race envelope line fell 20 dB (the band the envelope is read in
    moved, as under any impulsive fault), its second harmonic up 8 dB, its once-per-revolution
    sidebands up 8 and the envelope line's shaft sidebands up ``sb_rise``: an outer race
    (which lowers the line as far, lifts the harmonic and 70 % of the once-per-revolution
    sidebands) reads the whole record best, a broken tooth (the line lowered, the sidebands
    lifted) within the near tie, and both lift the line's sidebands as the record does. On
    its own signature the outer race's evidence is mostly the line that fell, which the
    tooth's signature does not hold; on what each lifts, the tooth's sidebands outweigh the
    outer race's harmonic, and the harmonic with the line's sidebands outweighs them."""
    names = ("env_bpfo_1b1_h1_db", "env_bpfo_1b1_h2_db", "sb1_fr1_k1_db", "sb1_fr1_k2_db",
             "env_bpfo_1b1_sb_db")
    m = len(names)
    meas = np.array([-20.0, 8.0, 8.0, 8.0, sb_rise])
    outer = np.zeros((2, m))
    outer[1] = [-20.0, 8.0, 5.6, 5.6, sb_rise]
    tooth = np.zeros((2, m))
    tooth[1] = [-20.0, 0.0, 8.0, 8.0, sb_rise]
    outer[0], tooth[0] = outer[1] / 2, tooth[1] / 2
    lib = _baseline_at_zero(
        names, np.ones(m),
        SignatureEntry("bearing_outer_race", "1b1", "documented", "size_m", (1e-4, 1e-3),
                       outer),
        SignatureEntry("tooth_fault", "1G1", "documented", "lost_height_m", (1e-4, 1e-3),
                       tooth))                  # on the input gear: the input's sidebands
    li = np.arange(m)
    d = decide_record(lib, li, list(names), meas, feature_sigma(lib, li, list(names), 8),
                      "1b1")
    whole = {r["name"]: r["evidence"] for r in d["ranked"]}
    assert whole["bearing_outer_race"] > whole["tooth_fault"] >= NEAR_TIE * whole[
        "bearing_outer_race"]
    own = {r["name"]: r["delta_chi2"] for r in d["by_signature"]}
    assert own["bearing_outer_race"] > own["tooth_fault"]      # the fall, counted
    assert (d["finding"], d["decided_on"]) == (finding, "whole")


RING_NAMES = ("env_bpfi_1b2_h1_db", "env_bpfi_1b2_h2_db", "env_bsf2_1b1_h1_db",
              "env_bsf2_1b1_h2_db", "raw_bpfo_1b1_db", "raw_bpfo_1b2_db", "raw_fr_h1_db",
              "raw_fr_h2_db", "shape_b0_db", "shape_b1_db", "shape_b2_db")


@pytest.mark.parametrize("bpfi, bsf, finding", [((12.0, 12.0), (7.0, 7.0), "bearing_inner_race"),
                                                ((12.0, 0.0), (0.0, 0.0), "transfer_path"),
                                                ((0.0, 0.0), (0.0, 0.0), "transfer_path")])
def test_a_ringing_fault_seen_through_another_sensor_is_named_beside_a_moved_path(bpfi, bsf,
                                                                                 finding):
    """A bearing fault's impacts ring the structure where the baseline showed nothing: the
    spectrum moves as a moved path moves it (a bearing defect's ``absorbs``), and little
    else of its modelled change reaches another bearing's sensor (CWRU's drive-end faults
    on the fan-end accelerometer read as a transfer path, every one). Its family standing
    12 dB over the path's prediction in two harmonics names it beside the path; of two
    families that stand out there, the one that stands out farthest (a fan-end ball family
    7 dB up, caught by the inner race's sidebands, whose whole-record reading is the
    nearer). One harmonic alone is within what a moved path's refiltering leaves (cmsim's
    own moved path lifted a ball family's band 7.8 dB over its prediction); with no family
    risen, the moved path."""
    m = len(RING_NAMES)
    moved = np.array([-10.0, -10.0, -10.0, -10.0, 10.0, -10.0, 10.0])   # raw lines, shape
    path = np.zeros((3, m))
    path[:, 4:] = np.outer([0.0, 0.5, 1.0], moved)
    inner = np.zeros((3, m))
    inner[:, :2] = np.array([[0.0], [0.5], [1.0]])      # the model's change here: small
    ball = np.zeros((3, m))
    ball[:, 2:4] = np.array([[0.0], [3.5], [7.0]])
    lib = _baseline_at_zero(
        RING_NAMES, np.ones(m),
        SignatureEntry("transfer_path", None, "documented", "frequency_factor",
                       (1.0, 1.3, 1.6), path),
        SignatureEntry("bearing_inner_race", "1b2", "documented", "size_m",
                       (3e-5, 3e-4, 3e-3), inner),
        SignatureEntry("bearing_ball", "1b1", "documented", "size_m",
                       (3e-5, 3e-4, 3e-3), ball))
    li = np.arange(m)
    meas = np.concatenate([bpfi, bsf, moved])
    names = list(RING_NAMES)
    d = decide_record(lib, li, names, meas, feature_sigma(lib, li, names, 8), "1b1")
    assert d["finding"] == finding, [(r["name"], r["component"], r["chi2"]) for r in d["ranked"]]
    assert d["ranked"][0]["name"] == "transfer_path"          # it reads the record best
    if finding == "bearing_inner_race":
        assert (d["top"]["component"], d["decided_on"]) == ("1b2", "beside")
        assert [r["name"] for r in d["ties"]] == ["transfer_path"]
        chi = {r["name"]: r["chi2"] for r in d["ranked"]}
        assert chi["bearing_ball"] < chi["bearing_inner_race"]   # the nearer, not named


def test_a_gear_s_family_is_its_own_shaft_s_sidebands():
    """A gear modulates the mesh at its own shaft's rate: the family of a gear fault on the
    input gear (1G1) holds the input shaft's sidebands (fr1), on the output gear (2G1) the
    output's (fr2); before, each held every sideband, and an input-gear eccentricity
    injected into SpectraQuest's held-out half whose model run lifted the output shaft's
    first sideband 7-13 dB at every size (a run-to-run difference of the light mesh, not the
    run-out's change) was read as an input-gear tooth fault, its family standing out on that
    sideband. A rotating force (unbalance, misalignment) is laid on the sensor's bearing:
    its sidebands are the sensor's shaft's. A record whose one departure is the output
    shaft's sideband is never a fault of the input gear."""
    from cmsim.discrepancy import CAUSES

    names = ("sb1_fr1_k1_db", "sb23_fr1_k1_db", "sb1_fr2_k1_db", "sb23_fr2_k1_db",
             "gmf1_rel_db", "kurtosis_log", "shape_b0_db", "shape_b1_db")
    for cause, own in (("eccentricity", ["sb1_{}_k1_db"]),
                       ("tooth_fault", ["sb1_{}_k1_db", "sb23_{}_k1_db"])):
        for gear, fr in (("1G1", "fr1"), ("2G1", "fr2")):
            family = CAUSES[cause]().family(names, gear)
            assert [k for k in family if k.startswith("sb")] == [p.format(fr) for p in own]
    # a rotating force is laid on the sensor's bearing: its sidebands are that shaft's
    for shaft, fr in ((1, "fr1"), (2, "fr2")):
        family = CAUSES["misalignment"]().family(names, None, shaft)
        assert [k for k in family if k.startswith("sb")] == [f"sb1_{fr}_k1_db",
                                                              f"sb23_{fr}_k1_db"]
    assert len([k for k in CAUSES["unbalance"]().family(names, None) if k.startswith("sb")]) == 2
    m = len(names)
    entries = []
    for gear, cols in (("1G1", [0, 1]), ("2G1", [2, 3])):
        tooth = np.zeros((3, m))
        tooth[:, cols] = np.array([[0.0], [6.0], [20.0]])
        tooth[:, 5] = [0.0, 0.05, 0.3]
        entries.append(SignatureEntry("tooth_fault", gear, "documented", "lost_height_m",
                                      (1e-4, 5e-4, 3e-3), tooth))
    spread = np.ones(m)
    spread[:4] = 3.0
    lib = _baseline_at_zero(names, spread, *entries)
    li = np.arange(m)
    meas = np.zeros(m)
    meas[2] = 12.0
    d = decide_record(lib, li, list(names), meas, feature_sigma(lib, li, list(names), 8),
                      "1b1")
    assert d["top"] is None or d["top"]["component"] == "2G1", \
        (d["finding"], [(r["name"], r["component"], r["evidence"]) for r in d["ranked"]])
