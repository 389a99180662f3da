"""The contract of :mod:`cmsim.frequencies` beyond the formulas: names, bounds, messages.

Tier: behaviour contracts, written to kill the mutants that ``mutmut`` left alive in
``cmsim/frequencies.py`` (benchmarks/mutation/README.md): the family keys, frozen results,
every argument's bounds (the boundary value itself accepted or refused as documented) with
the parameter and its unit named in the error, the mapping access and the dict round trip.
"""

import dataclasses
import math
import re

import numpy as np
import pytest

from cmsim.errors import ParameterError
from cmsim.frequencies import (FAMILY_KEYS, BearingFrequencies, RigFrequencies,
                               bearing_frequencies, peak_families, rig_frequencies)
from cmsim.rig import OperatingPoint, Rig

GEOM = dict(n_balls=9, ball_diameter_m=7.94e-3, pitch_diameter_m=39.04e-3)


def _raises(pattern, **kw):
    with pytest.raises(ParameterError, match=pattern):
        bearing_frequencies(**{"shaft_hz": 30.0, **GEOM, **kw})


def test_family_keys():
    assert FAMILY_KEYS == ("GMF", "BPF", "fr", "BPFO", "BPFI", "BSF", "FTF", "fr1", "fr2")
    f = rig_frequencies(Rig.paper_2016(), OperatingPoint(1000.0))
    assert set(f.families()) == set(FAMILY_KEYS) - {"fr1", "fr2"}   # 28:28: one shaft rate


def test_results_are_frozen():
    bf = bearing_frequencies(30.0, **GEOM)
    with pytest.raises(dataclasses.FrozenInstanceError):
        bf.bpfo_hz = 1.0
    f = RigFrequencies(fr1_hz=30.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        f.fr1_hz = 1.0


@pytest.mark.parametrize("kw, pattern", [
    (dict(shaft_hz=-1.0), r"^shaft_hz must be .*>= 0 Hz\b"),
    (dict(n_balls=2), r"^n_balls must be an integer >= 3, got 2$"),
    (dict(n_balls=True), r"^n_balls must be an integer >= 3, got True$"),
    (dict(n_balls=9.0), r"^n_balls must be an integer >= 3, got 9\.0$"),
    (dict(ball_diameter_m=0.0), r"^ball_diameter_m must be .*> 0 m\b"),
    (dict(pitch_diameter_m=7.94e-3), r"^pitch_diameter_m must be .*> 0\.00794 m \(> ball_diameter_m\)"),
    (dict(contact_angle_rad=0.5 * math.pi),
     r"^contact_angle_rad must be .*\[0, 1\.5707963267948966\) rad\b"),
    (dict(contact_angle_rad=-0.01), r"^contact_angle_rad must be"),
    (dict(outer_ring_hz=float("nan")), r"^outer_ring_hz must be .*\bHz\b"),
])
def test_bad_arguments_are_named_with_their_bounds(kw, pattern):
    _raises(pattern, **kw)


@pytest.mark.parametrize("kw", [dict(shaft_hz=0.0), dict(n_balls=3), dict(n_balls=np.int64(9)),
                                dict(pitch_diameter_m=7.95e-3), dict(contact_angle_rad=0.0),
                                dict(contact_angle_rad=1.57), dict(outer_ring_hz=-50.0)])
def test_boundary_arguments_are_accepted(kw):
    bf = bearing_frequencies(**{"shaft_hz": 30.0, **GEOM, **kw})
    assert all(v >= 0 and math.isfinite(v) for v in bf.to_dict().values())


def test_stopped_shaft_and_co_rotating_outer_ring():
    assert all(v == 0.0 for v in bearing_frequencies(0.0, **GEOM).to_dict().values())
    bf = bearing_frequencies(30.0, **GEOM, outer_ring_hz=30.0)   # rings locked together
    assert bf.ftf_hz == pytest.approx(30.0, rel=1e-12)
    assert bf.bpfo_hz == pytest.approx(0.0, abs=1e-9)
    assert bf.bpfi_hz == pytest.approx(0.0, abs=1e-9)
    assert bf.bsf_hz == pytest.approx(0.0, abs=1e-9)
    fam = RigFrequencies(fr1_hz=30.0, bearings={"b": bf}).families()
    assert set(fam) == {"fr", "BPF", "FTF"}                    # zero rates left out


def test_bearing_frequencies_mapping_access():
    bf = bearing_frequencies(30.0, **GEOM)
    assert list(bf.to_dict()) == ["shaft_hz", "ftf_hz", "bpfo_hz", "bpfi_hz", "bsf_hz",
                                  "bpf_hz"]
    assert bf["bpfo_hz"] == bf.bpfo_hz
    with pytest.raises(KeyError, match=r"""^"no bearing frequency 'bpfx_hz'; have \['shaft_hz'.*'bpf_hz'\]"$"""):
        bf["bpfx_hz"]


def test_rig_frequencies_mapping_and_round_trip():
    rig = Rig.paper_2016()
    f = rig_frequencies(rig, OperatingPoint(1200.0))
    d = f.to_dict()
    assert list(d) == ["shaft_hz", "output_shaft_hz", "gmf_hz", *rig.bearing_names]
    assert d["shaft_hz"] == pytest.approx(20.0) and d["gmf_hz"] == pytest.approx(560.0)
    assert RigFrequencies.from_dict(d) == f
    assert f["gmf_hz"] == f.gmf_hz and "gmf_hz" in f and "bpfo_hz" not in f
    assert list(iter(f)) == list(d)
    assert f.get("nothing", 7) == 7 and f.get("shaft_hz") == pytest.approx(20.0)
    with pytest.raises(KeyError, match=r"""^"no frequency 'GMF'; have \['shaft_hz'.*'2b2'\]"$"""):
        f["GMF"]
    assert f.shaft_rates_hz == {"fr1": 20.0, "fr2": pytest.approx(20.0)}
    assert f.has_gears and f.bearing_names == rig.bearing_names
    assert f.bearing() is f.bearings["1b1"] and f.bearing("2b2") is f.bearings["2b2"]
    with pytest.raises(ParameterError, match=r"^bearing must be one of \['1b1', '1b2', "
                                             r"'2b1', '2b2'\], got '3b1'$"):
        f.bearing("3b1")
    assert peak_families(d, "2b1") == f.families("2b1")
    assert f.families("2b1")["fr"] == pytest.approx(20.0)


def test_rig_frequencies_without_gears_and_bad_inputs():
    f = RigFrequencies(fr1_hz=29.95)
    assert not f.has_gears and f.shaft_rates_hz == {"fr1": 29.95}
    assert f.to_dict() == {"shaft_hz": 29.95}
    with pytest.raises(ParameterError, match="^these frequencies hold no bearing$"):
        f.bearing()
    with pytest.raises(ParameterError, match=r"^fr1_hz must be .*>= 0 Hz\b"):
        RigFrequencies(fr1_hz=-1.0)
    with pytest.raises(ParameterError, match=re.escape("bearings['DE'] must be a "
                                                       "BearingFrequencies, got dict")):
        RigFrequencies(fr1_hz=1.0, bearings={"DE": {}})
    with pytest.raises(ParameterError, match=r"^expected a dict written by "
                                             r"RigFrequencies\.to_dict \(with 'shaft_hz'\)$"):
        RigFrequencies.from_dict({"gmf_hz": 1.0})
    with pytest.raises(ParameterError, match=r"^freqs must be a RigFrequencies or its "
                                             r"to_dict\(\) \(no bearing entries found\)$"):
        peak_families({"shaft_hz": 1.0})
    with pytest.raises(ParameterError, match=r"^freqs must be a RigFrequencies, got list$"):
        peak_families([1.0])
    assert isinstance(bearing_frequencies(1.0, **GEOM), BearingFrequencies)


def test_bearing_rig_and_slow_shafts():
    """No gears: no output shaft and no GMF (None, not a falsy placeholder); a shaft slower
    than 1 Hz keeps its families (only zero rates are dropped)."""
    brg = Rig.paper_2016().bearings[0]
    from cmsim.rig import Rotor
    rig = Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01))
    f = rig_frequencies(rig, OperatingPoint(30.0))
    assert f.fr2_hz is None and f.gmf_hz is None and not f.has_gears
    assert f.fr1_hz == pytest.approx(0.5, rel=1e-12)
    fam = f.families()
    assert set(fam) == {"fr", "BPF", "BPFO", "BPFI", "BSF", "FTF"}
    assert fam["fr"] == pytest.approx(0.5, rel=1e-12)
    assert 0.0 < fam["FTF"] < 1.0
