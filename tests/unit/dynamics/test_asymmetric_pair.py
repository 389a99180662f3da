"""An unequal gear pair (28:42): quantities that a Z1/Z2 or r_b1/r_b2 swap would change.

Tier (a) closed form. Every other dynamics test uses the paper's 28:28 pair, where a formula
with the two gears (or the two shafts' speeds) swapped gives the same numbers. Here the
driven gear has 42 teeth, so each check below differs by a factor 1.5 under such a swap:

* the output shaft turns at fr1·Z1/Z2 (slope of ``theta_2J2``) and the DTE spectrum peaks at
  the GMF Z1·fr1 of :class:`~cmsim.frequencies.RigFrequencies`;
* ``dte`` is θ_1G1 − (Z2/Z1)·θ_2G1 from the recorded rotations, ``dte_um`` is r_b1·dte;
* the mean mesh force balances the load torque on the driven gear, T/r_b2, and the couplings
  twist in the ratio of the shaft torques, T·Z1/Z2 on the input and T on the output;
* in a quasi-static state with a constant-stiffness table, the mesh compression computed from
  the states, r_b1·θ_1G1 − r_b2·θ_2G1 + n·(c_1G1 − c_2G1), equals each loaded pair's
  force / k.

Runs use the fast potential-energy table (no FE build); the module takes a few seconds.
"""

import dataclasses
import math

import numpy as np
import pytest

import cmsim
from cmsim.dynamics import simulate
from cmsim.dynamics.model import build_model
from cmsim.dynamics.quasistatic import quasi_static_state
from cmsim.frequencies import rig_frequencies
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.rig import GearPair

PAPER = cmsim.Rig.paper_2016()
Z1, Z2 = 28, 42
PAIR = GearPair(PAPER.gears.driving, dataclasses.replace(PAPER.gears.driven, n_teeth=Z2))
RIG = dataclasses.replace(PAPER, gears=PAIR, name="paper rig with a 42-tooth wheel")
TORQUE = 60.0
OP = cmsim.OperatingPoint(1200.0, TORQUE)
FS = 20_000.0


@pytest.fixture(scope="module")
def run():
    return simulate(RIG, OP, 0.2, mesh="potential-energy", fs_hz=FS, seed=1)


def _deviation(run, name, omega):
    return run[name] - omega * run.t


def test_the_pair_is_valid_and_unequal():
    assert PAIR.ratio == pytest.approx(1.5, rel=1e-12)
    # zero-backlash centre distance of unshifted gears: m (Z1 + Z2) / 2
    assert PAIR.working_centre_distance_m == pytest.approx(3.175e-3 * 70 / 2, rel=1e-12)
    assert 1.2 < PAIR.contact_ratio < 2.0
    assert PAIR.driven.base_radius_m == pytest.approx(1.5 * PAIR.driving.base_radius_m, rel=1e-12)


def test_output_shaft_rate_and_gmf(run):
    f = rig_frequencies(RIG, OP)
    assert f.fr1_hz == pytest.approx(20.0, rel=1e-12)
    assert f.fr2_hz == pytest.approx(20.0 * Z1 / Z2, rel=1e-12)
    assert f.gmf_hz == pytest.approx(Z1 * 20.0, rel=1e-12)
    for name, rate in (("theta_1G1", f.fr1_hz), ("theta_2G1", f.fr2_hz),
                       ("theta_2J2", f.fr2_hz)):
        slope = np.polyfit(run.t, run[name], 1)[0] / (2 * math.pi)
        assert slope == pytest.approx(rate, rel=1e-5), name
    x = run["dte"] - run["dte"].mean()
    spec = np.abs(np.fft.rfft(x * np.hanning(x.size)))
    freq = np.fft.rfftfreq(x.size, 1.0 / FS)
    above = freq > 100.0
    assert freq[above][np.argmax(spec[above])] == pytest.approx(f.gmf_hz, abs=2 * FS / x.size)


def test_dte_from_the_recorded_rotations(run):
    dte = run["theta_1G1"] - (Z2 / Z1) * run["theta_2G1"]      # nominal rotations cancel
    np.testing.assert_allclose(run["dte"], dte, rtol=0, atol=1e-9)
    np.testing.assert_allclose(run["dte_um"], run["dte"] * PAIR.driving.base_radius_m * 1e6,
                               rtol=1e-12)
    # a loaded mesh: the static transmission error is positive and a few tens of µm
    assert 1.0 < run["dte_um"].mean() < 200.0


def test_mesh_force_and_coupling_torques_balance_the_load(run):
    rb1, rb2 = PAIR.driving.base_radius_m, PAIR.driven.base_radius_m
    assert run["Fmesh_total"].mean() == pytest.approx(TORQUE / rb2, rel=0.01)
    om1 = OP.omega_rad_s
    om2 = om1 * Z1 / Z2
    k_in = PAPER.input_coupling.stiffness_nm_per_rad
    k_out = PAPER.output_coupling.stiffness_nm_per_rad
    # input coupling: imposed rotation Ω1·t on one end, node 1b1 on the other
    t_in = -k_in * _deviation(run, "theta_1b1", om1).mean()
    t_out = k_out * (_deviation(run, "theta_2b2", om2) - _deviation(run, "theta_2J2", om2)).mean()
    assert t_out == pytest.approx(TORQUE, rel=0.01)
    assert t_in == pytest.approx(TORQUE * Z1 / Z2, rel=0.01)
    assert t_in == pytest.approx(run["Fmesh_total"].mean() * rb1, rel=0.01)


@pytest.mark.parametrize("t", [0.0, 1.3e-4, 7e-4])
def test_quasi_static_mesh_compression_from_the_states(t):
    k = 3e8
    model = build_model(RIG, OP, (MeshStiffnessTable.constant(PAIR, k), None))
    q = quasi_static_state(model, t)
    _, diag = model.rhs(t, np.concatenate([q, np.zeros(model.n_dof)]), want_diag=True)
    forces = np.array([d for d, name in zip(diag, model.output_force_names)
                       if name.startswith("Fmesh")])
    assert forces.sum() == pytest.approx(TORQUE / PAIR.driven.base_radius_m, rel=1e-6)
    alpha = PAIR.working_pressure_angle_rad
    n = np.array([-math.cos(alpha), math.sin(alpha)])        # force of gear 1 on gear 2
    i1, i2 = model.index("x_1G1"), model.index("x_2G1")
    delta = (PAIR.driving.base_radius_m * q[i1 + 2] - PAIR.driven.base_radius_m * q[i2 + 2]
             + n @ (q[i1:i1 + 2] - q[i2:i2 + 2]))
    # the most loaded pair is an involute contact: its force is k·δ (corner contacts near the
    # tips carry a few per cent of it at other δ)
    assert forces.max() / k == pytest.approx(delta, rel=1e-4)
    assert 1e-6 < delta < 1e-5
