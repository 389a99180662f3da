"""Rig parameters: paper defaults, TOML round trip, unit aliases, validation, topologies.

Tier (a) closed form: gear and bearing geometry from Tables 1-2 and NOTES.md.
"""

import math

import pytest

import cmsim
import cmsim.dynamics
from cmsim.errors import ParameterError
from cmsim.rig import Rig, RollingBearing, SpurGear


def test_paper_rig_geometry():
    rig = Rig.paper_2016()
    g = rig.gears
    assert rig.n_dof == 19
    assert rig.node_names == ("1b1", "1G1", "1b2", "2b1", "2G1", "2b2")
    assert g.driving.base_radius_m == pytest.approx(41.769e-3, rel=1e-4)
    assert g.driving.base_pitch_m == pytest.approx(9.373e-3, rel=1e-3)
    assert g.contact_ratio == pytest.approx(1.638, abs=1e-3)
    assert 1 / g.driving.base_radius_m == pytest.approx(23.94, abs=0.01)  # N per N m
    b = rig.bearings[0]
    assert b.pitch_diameter_m == pytest.approx(65e-3, rel=1e-4)
    assert b.diametral_clearance_m == pytest.approx(0.015e-3, rel=1e-3)
    assert [x.mass_kg for x in rig.bearings] == [0.4901, 0.245, 0.245, 0.4901]


def test_toml_round_trip(tmp_path):
    rig = Rig.paper_2016().with_friction(0.03).with_clearance(-1e-6)
    path = tmp_path / "rig.toml"
    rig.save(path)
    assert Rig.load(path) == rig
    text = path.read_text()
    assert text.startswith("# cmsim rig description")
    assert "format_version = 1" in text


def test_unit_aliases_are_converted(tmp_path):
    data = Rig.paper_2016().to_dict()
    for gear in (data["gears"]["driving"], data["gears"]["driven"]):
        gear["pressure_angle_deg"] = 25.0
        del gear["pressure_angle_rad"]
        gear["module_mm"] = 4.0
        del gear["module_m"]
    data["shafts"][0]["bearing_1"]["clearance_mm"] = 0.01
    del data["shafts"][0]["bearing_1"]["clearance_m"]
    rig = Rig.from_dict(data)
    assert rig.bearings[0].clearance_m == pytest.approx(1e-5)
    assert rig.gears.driving.pressure_angle_rad == pytest.approx(math.radians(25))
    assert rig.gears.driving.module_m == pytest.approx(4e-3)


def test_unknown_key_and_version_are_rejected(tmp_path):
    data = Rig.paper_2016().to_dict()
    data["gears"]["driving"]["modul_m"] = 3e-3
    with pytest.raises(ParameterError, match="unknown key rig.gears.driving.modul_m"):
        Rig.from_dict(data)
    data = Rig.paper_2016().to_dict()
    data["format_version"] = 99
    with pytest.raises(ParameterError, match="format_version"):
        Rig.from_dict(data)
    path = tmp_path / "bad.toml"
    path.write_text("name = [")
    with pytest.raises(ParameterError, match="not valid TOML"):
        Rig.load(path)


def test_general_gear_geometry():
    g = SpurGear(n_teeth=17, module_m=2e-3, face_width_m=20e-3, profile_shift=0.3,
                 bore_radius_m=0.01)
    assert g.tip_radius_m == pytest.approx(17e-3 + 2e-3 * 1.3)
    assert g.root_radius_m == pytest.approx(17e-3 - 2e-3 * 0.95)
    pair = cmsim.GearPair(g, SpurGear(n_teeth=45, module_m=2e-3, face_width_m=20e-3,
                                      bore_radius_m=0.02))
    assert pair.working_centre_distance_m > pair.standard_centre_distance_m
    assert pair.ratio == pytest.approx(45 / 17)


def test_bearing_from_catalogue_data():
    b = RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3, clearance_m=5e-6)
    assert b.pitch_diameter_m == pytest.approx(39.04e-3)
    assert b.effective_contact_angle_rad == 0.0  # no diametral clearance in the raceways
    with pytest.raises(ParameterError, match="clearance_m"):
        RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3, clearance_m=8e-3)


def test_topology_validation():
    rig = Rig.paper_2016()
    with pytest.raises(ParameterError, match="exactly 2 shafts"):
        Rig(name="x", shafts=rig.shafts[:1], gears=rig.gears, output_coupling=cmsim.Coupling(),
            output_inertia_kg_m2=1e-4)
    with pytest.raises(ParameterError, match="rotor"):
        Rig(name="x", shafts=rig.shafts[:1])
    bearing_rig = Rig.rotor_on_bearings(rig.bearings[0], cmsim.Rotor(3.0, 0.01))
    assert bearing_rig.n_dof == 9
    assert bearing_rig.node_names == ("1b1", "1D1", "1b2")


def test_bearing_rig_simulates():
    rig = Rig.rotor_on_bearings(Rig.paper_2016().bearings[0], cmsim.Rotor(3.0, 0.01))
    run = cmsim.dynamics.simulate(rig, cmsim.OperatingPoint(1800, radial_load_n=500.0), 0.05,
                                  seed=2)
    assert "dte" not in run.signals
    total = run["F_1b1_loa"].mean() + run["F_1b2_loa"].mean()
    assert total == pytest.approx(500.0, rel=0.01)
