"""The robust χ² of a comparison (issue 25).

Tier: closed form — a feature adds z² up to Z_CAP σ and Z_CAP² beyond, except the overall
level (:data:`RISING`) and, against a calibrated machine, every feature but the kurtosis
and crest factor, whose loss keeps rising beyond Z_CAP linearly with the value and slope of
z² there (Huber's); a feature's weight multiplies it; a feature the model lost counts as 3σ
off.
"""

import math

import pytest

from cmsim.discrepancy.causes import STATISTICS
from cmsim.discrepancy.evaluator import RISING, Z_CAP, chi2, loss, rises, weight


@pytest.mark.parametrize("name", ["shape_b3_db", "kurtosis_log", "level_db"])
@pytest.mark.parametrize("z", [0.0, 0.5, 1.0, 3.9, Z_CAP])
def test_within_z_cap_a_feature_adds_its_z_squared(name, z):
    assert loss(name, z) == pytest.approx(z * z)


def test_beyond_z_cap_a_feature_is_capped_but_the_level_rises_with_z_squared_s_slope():
    assert "level_db" in RISING
    assert loss("shape_b3_db", 30.0) == loss("shape_b3_db", Z_CAP + 0.1) == Z_CAP ** 2
    eps = 1e-6
    assert loss("level_db", Z_CAP + eps) == pytest.approx(Z_CAP ** 2, abs=1e-4)
    slope_in = (loss("level_db", Z_CAP) - loss("level_db", Z_CAP - eps)) / eps
    slope_out = loss("level_db", Z_CAP + 1.0) - loss("level_db", Z_CAP)
    assert slope_in == pytest.approx(2.0 * Z_CAP, rel=1e-4)
    assert slope_out == pytest.approx(2.0 * Z_CAP)
    # linear: equal steps far out add equal amounts, far less than z² would
    assert loss("level_db", 30.0) - loss("level_db", 20.0) == pytest.approx(
        loss("level_db", 20.0) - loss("level_db", 10.0))
    assert loss("level_db", 25.0) < 0.4 * 25.0 ** 2


def test_a_cause_that_brings_a_far_off_level_nearer_gains_and_one_that_takes_it_farther_pays():
    """A record 20 dB under its twin's level (σ 0.8 dB, z 25): a cause bringing the level
    11 dB nearer must lower the χ², one taking it 15 dB farther must raise it (a cap at
    Z_CAP² read all three the same, and still does on a spectral-shape band)."""
    for name, rises in (("level_db", True), ("shape_b5_db", False)):
        meas, sigma = {name: -49.6}, {name: 0.8}
        nominal = chi2(meas, {name: -29.6}, sigma, [name])
        nearer = chi2(meas, {name: -40.6}, sigma, [name])
        farther = chi2(meas, {name: -14.6}, sigma, [name])
        if rises:
            assert nearer < nominal - 10.0 * Z_CAP
            assert farther > nominal + 10.0 * Z_CAP
        else:
            assert nearer == nominal == farther


def test_weights_and_a_lost_feature():
    meas = {"shape_b1_db": -10.0, "kurtosis_log": 1.0}
    sigma = {"shape_b1_db": 1.0, "kurtosis_log": 0.1}
    sim = {"shape_b1_db": -12.0, "kurtosis_log": math.nan}
    got = chi2(meas, sim, sigma, ["shape_b1_db", "kurtosis_log"])
    assert got == pytest.approx(weight("shape_b1_db") * 4.0 + weight("kurtosis_log") * 9.0)
    assert chi2(meas, None, sigma, ["shape_b1_db"]) == math.inf


def test_against_a_calibrated_machine_every_feature_but_the_statistics_rises():
    """A far-off band against the machine's own twin rises (a cause that brings it nearer
    explains more); against an uncalibrated model it stays capped; the kurtosis and crest
    factor stay capped everywhere (every impulsive fault moves them)."""
    assert set(STATISTICS) == {"kurtosis_log", "crest_log"}
    for name in ("shape_b5_db", "env_bpfo_1b1_h1_db", "raw_fr_h1_db", "level_db"):
        assert rises(name, calibrated=True)
        assert rises(name) is (name in RISING)
        assert loss(name, 30.0, calibrated=True) == pytest.approx(Z_CAP * (60.0 - Z_CAP))
    for name in STATISTICS:
        assert not rises(name, calibrated=True)
        assert loss(name, 30.0, calibrated=True) == Z_CAP ** 2
    meas, sigma = {"shape_b5_db": -49.6}, {"shape_b5_db": 0.8}
    nominal, nearer = ({"shape_b5_db": v} for v in (-29.6, -40.6))
    names = ["shape_b5_db"]
    assert chi2(meas, nearer, sigma, names) == chi2(meas, nominal, sigma, names)
    # 11 dB nearer at σ 0.8: 13.75σ less, at the linear slope 2·Z_CAP, weighted
    gain = chi2(meas, nominal, sigma, names, True) - chi2(meas, nearer, sigma, names, True)
    assert gain == pytest.approx(weight("shape_b5_db") * 2.0 * Z_CAP * 11.0 / 0.8)
