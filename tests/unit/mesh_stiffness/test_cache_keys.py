"""Caches and resume: a changed input must change the key, a swapped run must be recomputed.

Tier: behaviour contracts. A stale cache entry silently gives another gear's stiffness (28-68 %
off between the designs of issue 14), and a resumed sweep that keeps a run file of another
seed or length silently mixes records. Checked:

* the FE influence-coefficient cache key (read from :func:`influence_table` without building
  anything) changes with every :class:`~cmsim.rig.SpurGear` field except the lumped mass and
  inertia, and with the FE settings; it does not change when nothing changes;
* the hybrid-table key :func:`~cmsim.dynamics.tooth_contact.tables_key` changes with each gear
  (either one), bearing, shaft, coupling and friction parameter;
* a resumed sweep recomputes a run file swapped for a valid file of the same case name from
  another seed or another duration.
"""

import dataclasses
import math
import shutil

import pytest

from cmsim.datasets import RECORDS_DIR, DatasetSpec, generate_dataset
from cmsim.dynamics.tooth_contact import tables_key
from cmsim.mesh_stiffness import cache
from cmsim.mesh_stiffness.influence import influence_table
from cmsim.rig import Coupling, Rig, SpurGear
from cmsim.run import Run

PAPER = Rig.paper_2016()
GEAR = PAPER.gears.driving
NOT_IN_FE = {"mass_kg", "inertia_kg_m2"}


class _Key(Exception):
    pass


def _influence_key(monkeypatch, gear, **kw):
    def capture(kind, key):
        raise _Key(key)
    monkeypatch.setattr(cache, "load_entry", capture)
    with pytest.raises(_Key) as info:
        influence_table(gear, **kw)
    return info.value.args[0]


def _changed(value):
    if isinstance(value, bool):
        raise TypeError
    if isinstance(value, int):
        return value + 1
    return value * 1.03 if value != 0 else 0.05


@pytest.mark.parametrize("name", [f.name for f in dataclasses.fields(SpurGear)])
def test_influence_key_follows_every_fe_input(monkeypatch, name):
    base = _influence_key(monkeypatch, GEAR)
    assert _influence_key(monkeypatch, dataclasses.replace(GEAR)) == base
    other = dataclasses.replace(GEAR, **{name: _changed(getattr(GEAR, name))})
    if name in NOT_IN_FE:
        assert _influence_key(monkeypatch, other) == base
    else:
        assert _influence_key(monkeypatch, other) != base


@pytest.mark.parametrize("kw", [dict(plane="stress"), dict(max_offset=2),
                                dict(depth_m=4 * GEAR.module_m),
                                dict(roll_step_m=0.05 * GEAR.module_m)])
def test_influence_key_follows_the_fe_settings(monkeypatch, kw):
    assert _influence_key(monkeypatch, GEAR, **kw) != _influence_key(monkeypatch, GEAR)


def _rig_variants():
    g1, g2 = PAPER.gears.driving, PAPER.gears.driven
    pair = PAPER.gears
    s1, s2 = PAPER.shafts
    b = s1.bearing_1
    out = {}
    for field in ("n_teeth", "module_m", "face_width_m", "profile_shift", "bore_radius_m",
                  "youngs_modulus_pa", "tip_radius_coef"):
        if field == "module_m":   # the pair needs equal modules
            m = _changed(g1.module_m)
            out["gear module"] = dataclasses.replace(pair, driving=dataclasses.replace(
                g1, module_m=m), driven=dataclasses.replace(g2, module_m=m))
            continue
        out[f"driving {field}"] = dataclasses.replace(
            pair, driving=dataclasses.replace(g1, **{field: _changed(getattr(g1, field))}))
        out[f"driven {field}"] = dataclasses.replace(
            pair, driven=dataclasses.replace(g2, **{field: _changed(getattr(g2, field))}))
    rigs = {k: dataclasses.replace(PAPER, gears=v) for k, v in out.items()}
    rigs["centre distance"] = dataclasses.replace(PAPER, gears=dataclasses.replace(
        pair, centre_distance_m=pair.working_centre_distance_m + 2e-5))
    rigs["clearance"] = PAPER.with_clearance(2e-5)
    for field in ("ball_diameter_m", "mass_kg", "n_balls"):
        brg = dataclasses.replace(b, **{field: _changed(getattr(b, field))})
        rigs[f"bearing {field}"] = dataclasses.replace(
            PAPER, shafts=(dataclasses.replace(s1, bearing_1=brg), s2))
    rigs["shaft stiffness"] = dataclasses.replace(PAPER, shafts=(s1, dataclasses.replace(
        s2, flexural_stiffness_n_per_m=(7e8, 6.24e8))))
    rigs["input coupling"] = dataclasses.replace(PAPER, input_coupling=Coupling(5e5, 3.5761))
    rigs["output coupling"] = dataclasses.replace(PAPER, output_coupling=Coupling(4e5, 4.0))
    return rigs


RIG_VARIANTS = _rig_variants()


@pytest.mark.parametrize("what", sorted(RIG_VARIANTS))
def test_hybrid_tables_key_follows_the_rig(what):
    base = tables_key(PAPER)
    assert tables_key(Rig.paper_2016()) == base
    assert tables_key(RIG_VARIANTS[what]) != base


def test_hybrid_tables_key_ignores_what_the_tables_do_not_depend_on():
    """Mesh friction moves the tables by <= 0.05 % of their peak (measured, f = 0 vs 0.05),
    lubricant and housing not at all: a dataset varying them reuses one table set."""
    base = tables_key(PAPER)
    assert tables_key(PAPER.with_friction(0.05)) == base
    assert tables_key(dataclasses.replace(PAPER, housing=dataclasses.replace(
        PAPER.housing, damping_ratios=(0.05, 0.05, 0.05)))) == base


# ---------------------------------------------------------------------- resume
BASE = dict(duration_s=0.02, warmup_s=0.01, mesh="potential-energy")
GRID = [("speed_rpm", [1000.0]), ("torque_nm", [20.0])]


def run_sweep(spec, out):
    """The runner as ``cmsim sweep`` runs it: every finished file's SHA-256 checked."""
    return generate_dataset(spec, out, workers=1, verify=True)


@pytest.fixture(scope="module")
def sweeps(tmp_path_factory):
    root = tmp_path_factory.mktemp("swap")
    out = {}
    for name, kw in (("a", dict(seed=7)), ("seed", dict(seed=8)),
                     ("duration", dict(seed=7, duration_s=0.03))):
        spec = DatasetSpec(GRID, **{**BASE, **kw})
        run_sweep(spec, root / name)
        out[name] = (spec, root / name)
    return out


@pytest.mark.parametrize("donor", ["seed", "duration"])
def test_resume_recomputes_a_swapped_run_file(sweeps, donor, tmp_path):
    spec, src = sweeps["a"]
    out = tmp_path / "a"
    shutil.copytree(src, out)
    (victim,) = (out / RECORDS_DIR).glob("*.npz")
    (foreign,) = (sweeps[donor][1] / RECORDS_DIR).glob("*.npz")
    assert foreign.name == victim.name                 # the same record id
    shutil.copyfile(foreign, victim)
    s = run_sweep(spec, out)
    assert (s.records_written, s.records_skipped) == (1, 0)
    run = Run.load(victim)
    assert run.meta["seed"] == spec.record(0).sim_seed
    assert run.meta["duration_s"] == pytest.approx(spec.duration_s, rel=1e-12)
    assert math.isclose(run.t[0], run.meta["warmup_s"], abs_tol=1e-12)
