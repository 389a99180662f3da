"""Roller bearings (load exponent p = 1.1): the separate force loop against a hand calculation.

Tier (a) closed form. Exponents other than 1.5 run their own ball loop in
:mod:`cmsim.bearings._kernels` (and through it in the dynamics kernel), so the ball tests do
not cover it. Checked here for p = 1.1, and for p = 1.5 on the same grid:

* the force F = k Σ H(δ_i) δ_i^p (cos θ_i, sin θ_i), δ_i = x cos θ_i + y sin θ_i − c,
  computed with numpy, against :func:`~cmsim.bearings.forces.bearing_force` and against the
  bearing force the dynamics kernel reports (``F_1b1_x/y``) for a rotor rig at rest;
* the tangent stiffness against a central finite difference of the force;
* the force against the gradient of the strain energy k/(p+1) Σ H(δ) δ^(p+1).
"""

import dataclasses
import math

import numpy as np
import pytest

import cmsim
from cmsim.bearings.forces import bearing_force, bearing_strain_energy, bearing_tangent_stiffness
from cmsim.dynamics.model import build_model
from cmsim.rig import Rig, Rotor

BALL = Rig.paper_2016().bearings[0]
K_ROLLER = 3.0e9                       # N/m^1.1, a cylindrical-roller order of magnitude
ROLLER = dataclasses.replace(BALL, load_exponent=1.1, stiffness_n_per_m_p=K_ROLLER,
                             clearance_m=5e-6, n_balls=11)
BALL_K = dataclasses.replace(BALL, stiffness_n_per_m_p=1.2e10, n_balls=11, clearance_m=5e-6)

# offsets (m) and cage angles (rad) with no element close to δ = 0, where δ^p is not smooth
POINTS = [(12e-6, 3e-6, 0.1), (-4e-6, 20e-6, 0.7), (25e-6, -18e-6, 2.0), (1e-6, -30e-6, 4.4)]


def _hand_force(brg, k, x, y, cage):
    theta = cage + 2 * math.pi * np.arange(brg.n_balls) / brg.n_balls
    d = np.clip(x * np.cos(theta) + y * np.sin(theta) - brg.clearance_m, 0.0, None)
    f = k * d ** brg.load_exponent
    return np.array([np.sum(f * np.cos(theta)), np.sum(f * np.sin(theta))])


def _min_overlap(brg, x, y, cage):
    theta = cage + 2 * math.pi * np.arange(brg.n_balls) / brg.n_balls
    return np.min(np.abs(x * np.cos(theta) + y * np.sin(theta) - brg.clearance_m))


@pytest.mark.parametrize("brg, k", [(ROLLER, K_ROLLER), (BALL_K, 1.2e10)], ids=["p1.1", "p1.5"])
@pytest.mark.parametrize("x, y, cage", POINTS)
def test_force_matches_the_hand_calculation(brg, k, x, y, cage):
    assert _min_overlap(brg, x, y, cage) > 0.3e-6
    want = _hand_force(brg, k, x, y, cage)
    assert np.linalg.norm(want) > 10.0
    np.testing.assert_allclose(bearing_force(brg, x, y, cage), want, rtol=1e-12,
                               atol=1e-9 * np.linalg.norm(want))


def test_roller_and_ball_laws_differ():
    """The check above can tell p = 1.1 from p = 1.5 at these offsets."""
    x, y, cage = POINTS[0]
    f11 = _hand_force(ROLLER, K_ROLLER, x, y, cage)
    f15 = _hand_force(dataclasses.replace(ROLLER, load_exponent=1.5), K_ROLLER, x, y, cage)
    assert np.linalg.norm(f11 - f15) > 0.5 * np.linalg.norm(f11)


@pytest.mark.parametrize("brg", [ROLLER, BALL_K], ids=["p1.1", "p1.5"])
@pytest.mark.parametrize("x, y, cage", POINTS)
def test_tangent_stiffness_is_the_derivative_of_the_force(brg, x, y, cage):
    h = 1e-10
    fd = np.empty((2, 2))
    for j, (dx, dy) in enumerate(((h, 0.0), (0.0, h))):
        fp = np.array(bearing_force(brg, x + dx, y + dy, cage))
        fm = np.array(bearing_force(brg, x - dx, y - dy, cage))
        fd[:, j] = (fp - fm) / (2 * h)
    kt = bearing_tangent_stiffness(brg, x, y, cage)
    np.testing.assert_allclose(kt, fd, rtol=1e-5, atol=1e-6 * np.abs(fd).max())
    np.testing.assert_allclose(kt, kt.T, rtol=1e-12)


@pytest.mark.parametrize("x, y, cage", POINTS)
def test_roller_force_is_the_gradient_of_the_strain_energy(x, y, cage):
    h = 1e-10
    gx = (bearing_strain_energy(ROLLER, x + h, y, cage)
          - bearing_strain_energy(ROLLER, x - h, y, cage)) / (2 * h)
    gy = (bearing_strain_energy(ROLLER, x, y + h, cage)
          - bearing_strain_energy(ROLLER, x, y - h, cage)) / (2 * h)
    np.testing.assert_allclose(bearing_force(ROLLER, x, y, cage), (gx, gy), rtol=1e-5)


@pytest.mark.parametrize("brg, k", [(ROLLER, K_ROLLER), (BALL_K, 1.2e10)], ids=["p1.1", "p1.5"])
def test_dynamics_kernel_uses_the_roller_law(brg, k):
    """The bearing force the time integration applies, at t = 0 with zero velocity."""
    rig = Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01),
                                bearing_2=dataclasses.replace(brg, clearance_m=-2e-6))
    op = cmsim.OperatingPoint(1500.0, 0.0, radial_load_n=500.0)
    phases = [0.4, 1.9]
    model = build_model(rig, op, cage_phases_rad=phases)
    q = np.zeros(model.n_dof)
    offsets = {"1b1": (12e-6, 3e-6), "1b2": (-4e-6, 20e-6)}
    for name, (x, y) in offsets.items():
        q[model.index(f"x_{name}")] = x
        q[model.index(f"y_{name}")] = y
    _, diag = model.rhs(0.0, np.concatenate([q, np.zeros(model.n_dof)]), want_diag=True)
    for (name, (x, y)), phase, b in zip(offsets.items(), phases, rig.bearings):
        want = _hand_force(b, k, x, y, phase)
        got = [diag[model.output_force_names.index(f"F_{name}_{d}")] for d in "xy"]
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-6 * np.linalg.norm(want))
