"""Linearised modal analysis against paper 001 Tables 5 and 6.

Tier (b) literature. The rotational modes 16-19 are torque independent and must match
within 3 %; the purely translational modes (2, 4, 8, 10, 12, 14) match to 0.5 % with the
physically consistent mesh orientation. The mixed modes are a known deviation: NOTES.md
shows the paper's linear model mirrors the line of action (a sign slip); we keep the
consistent model and check only their trends.
"""

import numpy as np
import pytest

import cmsim
from cmsim.dynamics.modal import MODE_TYPES, modal_analysis

RIG = cmsim.Rig.paper_2016()
TABLE5 = {  # mode: (10, 50, 100 N m)
    2: (472, 922, 1130), 4: (1291, 1775, 2000), 8: (6562, 6650, 6709), 10: (6763, 6967, 7083),
    12: (9701, 9763, 9806), 14: (9847, 10008, 10107), 16: (14382,) * 3, 17: (14702,) * 3,
    18: (15744, 15745, 15746), 19: (15938, 15947, 15952)}
TABLE6_LOW = {2: (1431, 1626, 1766), 4: (1507, 1826, 2036)}


@pytest.fixture(scope="module")
def modes():
    return {t: modal_analysis(RIG, cmsim.OperatingPoint(1000, t)) for t in (10, 50, 100)}


@pytest.fixture(scope="module")
def modes_preload():
    rig = RIG.with_clearance(-1e-6)
    return {t: modal_analysis(rig, cmsim.OperatingPoint(1000, t)) for t in (10, 50, 100)}


def test_nineteen_modes_with_types(modes):
    for res in modes.values():
        assert res.frequencies_hz.shape == (19,)
        assert np.all(np.diff(res.frequencies_hz) >= 0)
        assert set(res.types) <= set(MODE_TYPES)
        assert res.types[15:] == ("R",) * 4


@pytest.mark.parametrize("mode", [16, 17, 18, 19])
def test_rotational_modes_16_to_19(modes, mode):
    for j, t in enumerate((10, 50, 100)):
        assert modes[t].frequencies_hz[mode - 1] == pytest.approx(TABLE5[mode][j], rel=0.03)


@pytest.mark.parametrize("mode", [2, 4, 8, 10, 12, 14])
def test_translational_modes_match_table_5(modes, mode):
    for j, t in enumerate((10, 50, 100)):
        assert modes[t].frequencies_hz[mode - 1] == pytest.approx(TABLE5[mode][j], rel=0.005)
        assert modes[t].types[mode - 1] == "T"


def test_low_modes_rise_with_torque(modes):
    f = np.array([modes[t].frequencies_hz[:5] for t in (10, 50, 100)])
    assert np.all(np.diff(f, axis=0) > 0)


def test_preload_raises_the_low_modes(modes, modes_preload):
    for t in (10, 50, 100):
        assert np.all(modes_preload[t].frequencies_hz[:5] > modes[t].frequencies_hz[:5])
    for mode, values in TABLE6_LOW.items():
        for j, t in enumerate((10, 50, 100)):
            assert modes_preload[t].frequencies_hz[mode - 1] == pytest.approx(values[j], rel=0.01)


def test_bearing_rig_modes():
    b = RIG.bearings[0]
    rig = cmsim.Rig.rotor_on_bearings(b, cmsim.Rotor(mass_kg=4.0, inertia_kg_m2=0.01))
    res = modal_analysis(rig, cmsim.OperatingPoint(1800, radial_load_n=1000.0))
    assert res.frequencies_hz.shape == (9,)
    assert res.mean_mesh_stiffness_n_per_m == 0.0
    assert np.all(res.frequencies_hz > 0)
