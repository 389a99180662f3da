"""Rotating shaft forces of unbalance and misalignment laid on a bearing force (issue 25).

Tier: closed form — a force of static level F̄ (either sign: a bearing's reaction points
either way) with a dynamic part: the unbalance of relative amplitude a adds a line of
a·|F̄| at the shaft rate and swings the dynamic part by (1 + a·cos θ); through a machine the
line reaches the sensor through the machine's own gain at that order.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from cmsim.discrepancy.evaluator import _shaft_forces
from cmsim.machine import Background, Machine, TransferPath, rotating_force
from cmsim.rig import OperatingPoint, Rig

FS = 10_000.0
FR = 25.0


def _line(x, f):
    """Amplitude of the line at ``f`` (an integer number of cycles in ``x``)."""
    t = np.arange(x.size) / FS
    return 2.0 * abs(np.mean(x * np.exp(-2j * math.pi * f * t)))


@pytest.mark.parametrize("static", [100.0, -100.0])
def test_an_unbalance_adds_its_line_whatever_the_sign_of_the_load(static):
    t = np.arange(int(FS)) / FS
    dynamic = 5.0 * np.cos(2 * math.pi * 400.0 * t)
    modulated, rotating = _shaft_forces(static + dynamic, FS, FR, ((1, 0.3),), seed=4)
    total = modulated + rotating_force(t.size, FS, FR, rotating)
    assert _line(total, FR) == pytest.approx(0.3 * 100.0, rel=1e-3)
    # the dynamic part swings with the load: sidebands of 0.3/2 of its 5 N at 400 ± 25 Hz
    for f in (375.0, 425.0):
        assert _line(total, f) == pytest.approx(0.15 * 5.0, rel=1e-3)
    assert float(np.mean(modulated)) == pytest.approx(static, abs=1e-9)


def test_through_a_machine_the_line_takes_the_machine_gain_at_its_order():
    rig = Rig.paper_2016()
    path = TransferPath("F_1b1_y", (0.0, FS / 2), (1e-3, 1e-3), "g")
    quiet = Background((0.0, FS / 2), (1e-30, 1e-30))
    m = Machine("m", rig, "acc", "accel_1b1_y", FS, OperatingPoint(FR * 60.0, 50.0), path,
                quiet, shaft_gain={1: 4e-2})
    n = int(FS)
    y = m.sensor_signal(np.zeros(n), 0, n, 0, rotating=(FR, ((1, 30.0, 0.0), (2, 10.0, 0.0))))
    assert _line(y, FR) == pytest.approx(4e-2 * 30.0, rel=1e-3)       # its own gain
    # 2× unpinned: the (flat) path's shape at 1×'s level, 40 times the path's own
    assert _line(y, 2 * FR) == pytest.approx(4e-2 * 10.0, rel=1e-3)
    bare = replace(m, shaft_gain={})
    y = bare.sensor_signal(np.zeros(n), 0, n, 0, rotating=(FR, ((2, 10.0, 0.0),)))
    assert _line(y, 2 * FR) == pytest.approx(1e-3 * 10.0, rel=1e-3)    # the path's alone


@pytest.mark.parametrize("modulation", [0.3, 1.0, 3.0])
def test_the_load_a_rotating_force_swings_is_a_nuisance_its_line_is_not(modulation):
    """``shaft_modulation`` m scales the sidebands the force swings (m·a/2 of the dynamic
    part) and leaves its line (a·|F̄|): a value of every modulation variant sizes the force on
    its line. The library computes those variants for the causes that rotate, after every
    other entry."""
    from cmsim.discrepancy import CAUSES
    from cmsim.discrepancy.causes import ModelSetup
    from cmsim.discrepancy.compare import _variant_words
    from cmsim.discrepancy.signatures import SHAFT_MODULATIONS, _variants

    t = np.arange(int(FS)) / FS
    dynamic = 5.0 * np.cos(2 * math.pi * 400.0 * t)
    modulated, rotating = _shaft_forces(100.0 + dynamic, FS, FR, ((1, 0.3),), seed=4,
                                        modulation=modulation)
    total = modulated + rotating_force(t.size, FS, FR, rotating)
    assert _line(total, FR) == pytest.approx(0.3 * 100.0, rel=1e-3)
    for f in (375.0, 425.0):
        assert _line(total, f) == pytest.approx(modulation * 0.15 * 5.0, rel=1e-3)

    nominal = ModelSetup(rig=Rig.paper_2016(), op=OperatingPoint(1500.0, 50.0))
    for name, rotates in (("unbalance", True), ("misalignment", True),
                          ("bearing_inner_race", False), ("eccentricity", False)):
        got = {label: s.shaft_modulation for label, s in _variants(CAUSES[name](), nominal)}
        want = {f"modulation x{m:g}": m for m in SHAFT_MODULATIONS} if rotates else {}
        assert {k: v for k, v in got.items() if v != 1.0} == want
        assert got["documented"] == 1.0
    assert "3 times its share" in _variant_words("modulation x3")


def test_the_modulation_variants_come_last_and_leave_every_other_entry_its_noise(monkeypatch):
    """A library's entries draw their noise by their job's index: with the modulation
    variants of the rotating causes every other entry keeps the index it had without them
    (a library computed before them is the same where it overlaps), and those variants
    follow, one per modulation, after all the others."""
    from cmsim.discrepancy import signatures
    from cmsim.discrepancy.causes import ModelSetup, applicable_causes

    rig = Rig.paper_2016()
    nominal = ModelSetup(rig=rig, op=OperatingPoint(1500.0, 50.0))
    causes = applicable_causes(rig)

    def indexed():
        jobs, meta = signatures._entry_jobs(causes, rig, "1b1", nominal, 3)
        return {m[:3]: job[1][-1] for job, m in zip(jobs, meta)}

    now = indexed()
    monkeypatch.setattr(signatures, "SHAFT_MODULATIONS", ())
    before = indexed()
    added = set(now) - set(before)
    assert added == {(c, None, f"modulation x{m:g}") for c in ("unbalance", "misalignment")
                     for m in (0.3, 3.0)}
    assert all(now[k] == before[k] for k in before)
    assert sorted(now[k] for k in added) == list(range(len(before), len(now)))
