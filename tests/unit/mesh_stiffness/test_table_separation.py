"""Mesh tables with a non-zero unloaded separation e(s) (a user's measured or modified table).

Tier (a) closed form. The dynamics computes each pair's force as k(s)·max(δ − e(s), 0). With
a constant separation e the forces at equilibrium are unchanged (they balance the same torque
through the same stiffness), so every translation is unchanged and the static transmission
error along the line of action, r_b1·DTE, moves by exactly e. Checked on the quasi-static
states of the paper's 28:28 pair and of a 28:42 pair, in single and double contact.

Both signs: a negative e (interference: thicker teeth) and a positive one (backlash: the
teeth touch after the gears have turned through e; a uniformly positive e used to make the
table's mean stiffness zero and the model unbuildable, found by this test).
"""

import dataclasses

import numpy as np
import pytest

import cmsim
from cmsim.dynamics.model import build_model
from cmsim.dynamics.quasistatic import quasi_static_state
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.rig import GearPair

PAPER = cmsim.Rig.paper_2016()
RIGS = {
    "28:28": PAPER,
    "28:42": dataclasses.replace(PAPER, gears=GearPair(
        PAPER.gears.driving, dataclasses.replace(PAPER.gears.driven, n_teeth=42))),
}
OP = cmsim.OperatingPoint(1200.0, 60.0)
K_PAIR = 3e8


def _static_dte_um(rig, separation_m, t):
    table = MeshStiffnessTable.constant(rig.gears, K_PAIR)
    table = dataclasses.replace(table, separation_m=np.full_like(table.separation_m,
                                                                 separation_m))
    model = build_model(rig, OP, (table, None))
    q = quasi_static_state(model, t)
    z1, z2 = rig.gears.driving.n_teeth, rig.gears.driven.n_teeth
    dte = q[model.index("theta_1G1")] - z2 / z1 * q[model.index("theta_2G1")]
    return dte * rig.gears.driving.base_radius_m * 1e6, q, model


@pytest.mark.parametrize("t", [0.0, 7e-4], ids=["single-contact", "double-contact"])
@pytest.mark.parametrize("name", list(RIGS))
@pytest.mark.parametrize("e_um", [-5.0, -1.5, 2.0, 40.0])
def test_constant_separation_shifts_the_static_te_by_itself(name, t, e_um):
    rig = RIGS[name]
    dte0, q0, model = _static_dte_um(rig, 0.0, t)
    dte1, q1, _ = _static_dte_um(rig, e_um * 1e-6, t)
    assert dte1 - dte0 == pytest.approx(e_um, rel=2e-4)
    trans = model.translational_mask
    np.testing.assert_allclose(q1[trans], q0[trans], rtol=0, atol=1e-4 * np.abs(q0[trans]).max())


def test_the_table_reports_its_separation():
    table = MeshStiffnessTable.constant(PAPER.gears, K_PAIR)
    e = np.linspace(-2e-6, 3e-6, table.position_m.size)
    table = dataclasses.replace(table, separation_m=e)
    s = table.position_m
    mid = 0.5 * (s[3] + s[4])
    assert table.separation_at(mid) == pytest.approx(0.5 * (e[3] + e[4]), rel=1e-12)
    assert table.separation_at(s[0] - 1.0) == pytest.approx(e[0], rel=1e-12)
    assert table.separation_at(s[-1] + 1.0) == pytest.approx(e[-1], rel=1e-12)
