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
    # closed form: without gears torsion and translation decouple. Torsion: the chain
    # ground (imposed speed) -k_c- J_b1 -k_t1- J_disk -k_t2- J_b2
    import scipy.linalg
    s = rig.shafts[0]
    kc, (kt1, kt2) = rig.input_coupling.stiffness_nm_per_rad, s.torsional_stiffness_nm_per_rad
    k_rot = np.array([[kc + kt1, -kt1, 0.0], [-kt1, kt1 + kt2, -kt2], [0.0, -kt2, kt2]])
    j_rot = np.diag([b.inertia_kg_m2, 0.01, b.inertia_kg_m2])
    f_rot = np.sqrt(scipy.linalg.eigvalsh(k_rot, j_rot)) / (2 * np.pi)
    # translation: b1 -k_f1- disk -k_f2- b2 in x and y, each bearing's 2x2 stiffness to ground
    k_tr = np.zeros((6, 6))
    for i, j, k in ((0, 1, s.flexural_stiffness_n_per_m[0]), (1, 2, s.flexural_stiffness_n_per_m[1])):
        for d in range(2):
            a, c = 2 * i + d, 2 * j + d
            k_tr[[a, c], [a, c]] += k
            k_tr[a, c] -= k
            k_tr[c, a] -= k
    kb = res.bearing_stiffness_n_per_m
    assert kb.shape == (2, 2, 2)
    np.testing.assert_allclose(kb, np.transpose(kb, (0, 2, 1)), rtol=1e-9)
    assert np.all(np.linalg.eigvalsh(kb) > 1e6)        # loaded: positive definite
    k_tr[0:2, 0:2] += kb[0]
    k_tr[4:6, 4:6] += kb[1]
    m_tr = np.diag(np.repeat([b.mass_kg, 4.0, b.mass_kg], 2))
    f_tr = np.sqrt(scipy.linalg.eigvalsh(k_tr, m_tr)) / (2 * np.pi)
    rot = [f for f, t in zip(res.frequencies_hz, res.types) if t == "R"]
    trans = [f for f, t in zip(res.frequencies_hz, res.types) if t == "T"]
    np.testing.assert_allclose(rot, f_rot, rtol=1e-6)
    np.testing.assert_allclose(trans, f_tr, rtol=1e-6)
