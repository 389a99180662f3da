"""Unloaded and lightly loaded gearboxes are real operating points (issue 10, defect 1).

Tier (a) closed form and regression: with no load the nominal geometry is an equilibrium and
the run starts there; below 1 N·m the Hertzian contacts barely close and the start follows
the equilibrium down from a firm load (continuation); every seed runs.
"""

import numpy as np
import pytest

import cmsim
from cmsim.dynamics import build_model, simulate
from cmsim.dynamics.quasistatic import initial_state
from cmsim.dynamics.tooth_contact import resolve_mesh

RIG = cmsim.Rig.paper_2016()


def test_no_load_starts_from_nominal_geometry():
    model = build_model(RIG, cmsim.OperatingPoint(1000.0),
                        resolve_mesh(RIG, "potential-energy", 0.0))
    q, method = initial_state(model)
    assert method == "nominal geometry"
    assert np.all(q == 0.0)
    # and it is an equilibrium: no force anywhere at rest
    assert np.max(np.abs(model.static_residual(0.0, q))) < 1e-3   # N (rounding of δ ~ 1e-12 m)


def test_default_operating_point_runs_and_shows_separation():
    """No torque: nothing holds gear 2 against gear 1, the squeeze film pushes the flanks
    apart and the DTE goes negative (separation); the mesh force stays ~0."""
    run = simulate(RIG, cmsim.OperatingPoint(1000.0), 0.2, seed=1)
    assert run.meta["initial_state_method"] == "nominal geometry"
    dte = run["dte_um"]
    assert np.all(np.isfinite(dte))
    assert dte[-1] < -1.0                             # flanks apart by more than 1 µm
    assert np.max(run["Fmesh_total"]) < 1.0           # no load carried


@pytest.mark.slow
@pytest.mark.parametrize("torque_nm", [0.0, 0.2, 0.5, 1.0, 2.0])
@pytest.mark.parametrize("clearance_m", [0.015e-3, 0.0])
def test_light_loads_run_for_every_seed(torque_nm, clearance_m):
    rig = RIG.with_clearance(clearance_m)
    op = cmsim.OperatingPoint(1000.0, torque_nm)
    methods = set()
    for seed in range(40):
        run = simulate(rig, op, 0.004, seed=seed, mesh="potential-energy", warmup_s=0.002)
        assert np.all(np.isfinite(run["dte_um"]))
        methods.add(run.meta["initial_state_method"])
    assert "nominal geometry (no equilibrium found)" not in methods
    if torque_nm > 0:
        # a loaded mesh: mean DTE positive (contact closed) and the load carried
        assert np.mean(run["dte_um"]) > 0
        rb = rig.gears.driving.base_radius_m
        driving = torque_nm * rig.gears.driving.n_teeth / rig.gears.driven.n_teeth
        assert np.mean(run["Fmesh_total"]) == pytest.approx(driving / rb / np.cos(0), rel=0.2)


def test_a_static_residual_reads_as_the_right_hand_side_on_fresh_scratch():
    """The quasi-static solve's residual (one numba call on buffers the model keeps, its
    scratch reset each call) is M·q̈ of the right-hand side evaluated on new scratch arrays,
    to the bit, whatever residual the model evaluated before (the scratch's angle anchors
    and contact warm starts would otherwise carry over)."""
    model = build_model(RIG, cmsim.OperatingPoint(1200.0, torque_nm=50.0),
                        resolve_mesh(RIG, "potential-energy", 50.0))
    q, _ = initial_state(model)
    rng = np.random.default_rng(3)
    for t in (0.0, 0.0123, 0.0123, 0.4):
        qi = q * (1.0 + 1e-3 * rng.standard_normal(q.size))
        fresh = model.mass * model.rhs(t, np.concatenate([qi, np.zeros(q.size)]))[q.size:]
        assert np.array_equal(model.static_residual(t, qi), fresh), t
