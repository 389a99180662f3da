"""Power balance of simulated runs with every loss on (issue 13).

Tier: closed form (conservation of energy): input power through the input coupling =
output power + dissipation by source + change of stored energy, from the run's own signals.

The closure is checked against the losses themselves (P_in − P_out, 2 % of the input here):
a kernel that loses the tooth friction's sliding direction (``ff = μ·F``) leaves the
balance's closure at 1.5 % of the input, barely over a 1 % tolerance, but at 400 % of the
losses.
"""

import json

import pytest

from cmsim.dynamics import simulate
from cmsim.errors import ParameterError
from cmsim.dynamics.tooth_contact import resolve_mesh
from cmsim.losses import friction_table_for, operating_losses, power_balance
from cmsim.rig import OperatingPoint, Rig


@pytest.fixture(scope="module")
def setup():
    rig = Rig.paper_2016()
    op = OperatingPoint(3000.0, 50.0)
    tab = resolve_mesh(rig, None, op.torque_nm)[0]
    losses = operating_losses(rig, op, mesh_table=tab)
    mu = friction_table_for(rig, op, tab, rig.lubricant.surface_roughness_m,
                            rig.lubricant.dynamic_viscosity_pa_s)
    return rig, op, tab, losses, mu


def test_energy_balance_closes_with_every_loss_on(setup):
    rig, op, tab, losses, mu = setup
    loads = losses.loads()
    run = simulate(rig, op, 0.1, seed=3, warmup_s=0.1, loads=loads, friction_table=mu)
    pb = power_balance(run, loads, mu, tab)
    assert pb.closure_of_losses < 0.01           # of the losses themselves (P_in − P_out)
    assert pb.closure < 0.01                     # of the input power
    # the sources carry what the loss model put in
    torque_sources = ("windage", "meshing", "bearing_viscous", "bearing_load", "oil_jet")
    assert pb.losses_w["loads"] == pytest.approx(
        sum(losses.power_w[k] for k in torque_sources), rel=0.01)
    assert pb.losses_w["tooth_friction"] == pytest.approx(losses.power_w["tooth_friction"],
                                                          rel=0.15)
    assert pb.efficiency == pytest.approx(losses.efficiency, abs=0.002)


def test_balance_of_a_lossless_run_and_a_missing_source(setup):
    rig, op, tab, losses, mu = setup
    run = simulate(rig, op, 0.05, seed=4, warmup_s=0.1)
    pb = power_balance(run)
    assert pb.losses_w["tooth_friction"] == 0.0 and pb.losses_w["loads"] == 0.0
    assert pb.closure < 1e-3
    # forgetting the loads the run was made with leaves them in the residual
    loads = losses.loads()
    run2 = simulate(rig, op, 0.05, seed=4, warmup_s=0.1, loads=loads)
    assert power_balance(run2, loads).closure_of_losses < 0.05
    assert power_balance(run2).residual_w == pytest.approx(
        power_balance(run2, loads).losses_w["loads"], rel=0.05)


def test_a_run_made_with_every_loss_on_carries_its_breakdown_and_balance(setup):
    """``simulate(losses=...)`` puts the same loads and film friction in the run as the
    hand-made run above, and its meta carries the quasi-static breakdown and the run's own
    power balance (closing within 1 %)."""
    rig, op, tab, losses, mu = setup
    run = simulate(rig, op, 0.1, seed=3, warmup_s=0.1, losses=True)
    info = run.meta["losses"]
    assert info["quasi_static"]["power_w"] == pytest.approx(losses.power_w, rel=1e-9)
    bal = info["balance"]
    assert bal["closure_of_losses"] < 0.01       # of the losses: the strong check
    assert bal["closure"] < 0.01
    assert bal["losses_w"]["loads"] == pytest.approx(
        sum(v for k, v in losses.power_w.items() if k != "tooth_friction"), rel=0.01)
    assert bal["losses_w"]["tooth_friction"] == pytest.approx(
        losses.power_w["tooth_friction"], rel=0.15)
    hand = simulate(rig, op, 0.1, seed=3, warmup_s=0.1, loads=losses.loads(),
                    friction_table=mu)
    assert float(abs(run["dte_um"] - hand["dte_um"]).max()) < 1e-9
    with pytest.raises(ParameterError, match="losses"):
        simulate(rig, op, 0.01, losses=True, loads=losses.loads())


def test_cli_losses_flag(tmp_path, capsys):
    from cmsim.cli import main
    argv = ["simulate", "--speed-rpm", "3000", "--torque-nm", "50", "--duration-s", "0.05",
            "--losses", "--json"]
    assert main(argv) == 0
    res = json.loads(capsys.readouterr().out)["losses"]
    assert res["closure_of_losses"] < 0.01
    assert 0.95 < res["efficiency"] < 1.0 and res["closure"] < 0.01
    assert res["power_w"]["tooth_friction"] > res["power_w"]["windage"] > 0
    assert main(argv + ["--friction", "0.05"]) == 2
    assert "--friction" in json.loads(capsys.readouterr().out)["error"]
