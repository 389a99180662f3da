"""The fixed-step integrator and the equations of motion in closed-form limits.

Tier (a) closed form: a linear single-DOF oscillator through the production kernel (exact
solution, observed order of convergence of ode3/rk4/heun), energy conservation of an
undamped bearing rig, and the static limits of the full model (a constant-stiffness mesh on
stiff supports, a rotor on two bearings, bearing reactions balancing the mesh force).
"""

import math
import sys
import types
from dataclasses import replace

import numpy as np
import pytest
from numba import njit
from scipy.optimize import brentq

import cmsim
from cmsim.bearings import bearing_contact_stiffness, bearing_strain_energy
from cmsim.dynamics import build_model, quasi_static_state
from cmsim.dynamics._bearing_kernels import BI_SIZE, BP_CAGE, BP_PHASE, BP_SENSE, BP_SIZE, DF_SIZE
from cmsim.dynamics._mesh_kernels import MI_SIZE, MP_SIZE, no_hybrid
from cmsim.dynamics._rhs_kernels import (KernelParams, integrate_jit, make_integrator_buffers,
                                         make_work, no_profile, no_propagator)
from cmsim.dynamics.integrator import SCHEMES
from cmsim.dynamics.simulation import check_memory, integrate
from cmsim.errors import ParameterError
from cmsim.mesh_stiffness.table import MeshStiffnessTable

M, KS, C, F0, X0 = 2.0, 8.0e6, 40.0, 300.0, 1e-4


def sdof_packed():
    """Kernel arrays of m x'' + c x' + k x = F0 (layout documented in dynamics._rhs_kernels),
    read-only as every model's (:meth:`KernelParams.frozen`): writeable arrays are another
    numba type, and the integrator compiled again for them alone (100 s of a cold CI)."""
    return KernelParams(np.array([1.0 / M]), np.array([[KS, C]]), np.array([F0]), np.zeros(1),
            np.zeros((0, BI_SIZE), dtype=np.int64), np.zeros((0, BP_SIZE)),
            np.zeros((0, 1)), np.zeros((0, 1)), np.zeros((0, 1, 1)),
            np.zeros(MI_SIZE, dtype=np.int64), np.zeros(MP_SIZE), np.zeros(14),
            np.zeros(2), np.zeros(2), np.zeros((1, 2)), np.zeros((1, 2)),
            np.array([[0, 0, 1]], dtype=np.int64), *no_hybrid(), np.zeros((0, DF_SIZE)),
            np.zeros((0, 1)), np.zeros((0, 1)), np.ones((1, 1)), np.ones((1, 1)),
            np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((2, 3)), no_profile(),
            np.zeros(1), np.zeros(1), np.ones((0, 1))).frozen()


def test_the_suite_sees_a_test_that_compiles_an_integrator_again(monkeypatch):
    """tests/conftest.py fails a test that gives an integrator a second specialisation (as
    writeable parameters did twice, unseen): its reading of the signatures, on a small kernel
    called with a writeable and then a read-only array."""
    from tests.conftest import specialisations

    @njit
    def total(a):
        return a.sum()

    mod = types.ModuleType("toy_kernels")
    mod.total = total
    monkeypatch.setitem(sys.modules, "toy_kernels", mod)
    kernels = {"toy_kernels": ("total",), "toy_not_imported": ("integrate",)}
    a = np.ones(3)
    total(a)
    assert {k: len(v) for k, v in specialisations(kernels).items()} == {
        "total": 1, "integrate": 0}
    b = a.view()
    b.setflags(write=False)
    total(b)
    assert len(specialisations(kernels)["total"]) == 2


def sdof_exact(t):
    wn = math.sqrt(KS / M)
    zeta = C / (2 * math.sqrt(KS * M))
    wd = wn * math.sqrt(1 - zeta ** 2)
    xs = F0 / KS
    a = X0 - xs
    return xs + np.exp(-zeta * wn * t) * (a * np.cos(wd * t) + zeta * wn * a / wd * np.sin(wd * t))


def run_sdof(scheme, h, t_end=2e-3):
    tab = SCHEMES[scheme]
    P = sdof_packed()
    n_out = int(round(t_end / h)) + 1
    out = np.empty((n_out, 2))
    status = integrate_jit(np.array([X0, 0.0]), 0.0, h, n_out, 1, 0, tab.a, tab.b, tab.c,
                           no_propagator(tab.b.shape[0]), P,
                           make_work(P), make_integrator_buffers(tab.b, 2, 0), out,
                           np.empty((n_out, 0)), 1.0, 1.0, np.array([True]))
    assert status == -1
    t = h * np.arange(n_out)
    return t, out[:, 0]


def test_single_dof_free_and_forced_response():
    """Damped oscillator (2 kHz) stepped at 75 kHz: ode3 follows the exact solution."""
    t, x = run_sdof("ode3", 1 / 75_000)
    exact = sdof_exact(t)
    assert np.max(np.abs(x - exact)) < 1e-3 * X0


@pytest.mark.parametrize("scheme", ["heun", "ode3", "rk4"])
def test_observed_order_of_convergence(scheme):
    errors = []
    for h in (2e-5, 1e-5, 5e-6):
        t, x = run_sdof(scheme, h)
        errors.append(abs(x[-1] - sdof_exact(t[-1])))
    rates = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert rates == pytest.approx([SCHEMES[scheme].order] * 2, abs=0.25)


@pytest.fixture
def bearing_rig():
    b = Rig209()
    rig = cmsim.Rig.rotor_on_bearings(b, cmsim.Rotor(mass_kg=5.0, inertia_kg_m2=0.01),
                                      shaft_damping_n_s_per_m=(0.0, 0.0))
    rig = replace(rig, input_coupling=cmsim.Coupling(1e5, 0.0))
    return rig


def Rig209(**changes):
    return replace(cmsim.Rig.paper_2016().bearings[0], damping_n_s_per_m=0.0, **changes)


def _energy(model, states, t):
    n = model.n_dof
    q, v = states[:, :n], states[:, n:]
    kinetic = 0.5 * np.einsum("ij,j,ij->i", v, model.mass, v)
    springs = 0.5 * np.einsum("ij,jk,ik->i", q, model.stiffness, q)
    load = -q @ model.force
    balls = 0.0
    for ib, brg in enumerate(model.rig.bearings):
        ix, iy, it = (int(v) for v in model.kernel_params.b_int[ib, :3])
        b_par = model.kernel_params.b_par
        cage = (b_par[ib, BP_CAGE] * b_par[ib, BP_SENSE] * (model.omega[it] * t + q[:, it])
                + b_par[ib, BP_PHASE])
        balls = balls + bearing_strain_energy(brg, q[:, ix], q[:, iy], cage)
    return kinetic + springs + load + balls


def test_energy_is_conserved_without_damping(bearing_rig):
    """Undamped rotor on two 209 bearings, nearly at rest (cage frozen): the total energy
    (kinetic + shafts + Hertz contacts − load work) is conserved up to the integrator's
    error, which falls at third order with the step (ode3 slowly damps kHz modes)."""
    op = cmsim.OperatingPoint(speed_rpm=1e-3, radial_load_n=2000.0)
    model = build_model(bearing_rig, op)
    q0 = quasi_static_state(model, 0.0)
    q0[model.index("x_1D1")] += 3e-6
    y0 = np.concatenate([q0, np.zeros(model.n_dof)])
    drifts = []
    for fs in (150_000, 300_000, 600_000):
        states, _, _ = integrate(model, y0, 0.0, 1 / fs, int(0.005 * fs))
        e = _energy(model, states, np.arange(len(states)) / fs)
        kinetic = 0.5 * np.einsum("ij,j,ij->i", states[:, model.n_dof:], model.mass,
                                  states[:, model.n_dof:])
        drifts.append(np.max(np.abs(e - e[0])) / kinetic.max())
    rates = [math.log2(drifts[i] / drifts[i + 1]) for i in range(2)]
    assert rates == pytest.approx([3.0, 3.0], abs=0.3)
    assert drifts[-1] < 2e-3


def test_rigid_mesh_static_transmission_error():
    """Constant pair stiffness on near-rigid supports, pair at the pitch point (single
    contact): the quasi-static DTE along the line of action is F/k."""
    rig = cmsim.Rig.paper_2016()
    stiff = replace(rig.bearings[0], clearance_m=0.0, stiffness_n_per_m_p=1e14)
    shafts = tuple(replace(s, bearing_1=replace(stiff, mass_kg=s.bearing_1.mass_kg),
                           bearing_2=replace(stiff, mass_kg=s.bearing_2.mass_kg),
                           flexural_stiffness_n_per_m=(1e12, 1e12)) for s in rig.shafts)
    rig = replace(rig, shafts=shafts)
    k_pair = 2.0e8
    for torque in (10.0, 100.0):
        op = cmsim.OperatingPoint(1000.0, torque)
        model = build_model(rig, op, (MeshStiffnessTable.constant(rig.gears, k_pair), None))
        q = quasi_static_state(model, 0.0)
        rb = rig.gears.driving.base_radius_m
        dte = q[model.index("theta_1G1")] - q[model.index("theta_2G1")]
        # compatibility along the line of action: r_b·DTE + n·(c1 − c2) = F/k, the stiff
        # (but plausible: 1e14 N/m^1.5, 1e12 N/m) supports moving the centres by ~1 %
        g = model.mesh_jacobian()
        centres = g @ q - g[model.index("theta_1G1")] * q[model.index("theta_1G1")] \
            - g[model.index("theta_2G1")] * q[model.index("theta_2G1")]
        assert abs(centres) < 0.02 * torque / rb / k_pair
        assert dte * rb + centres == pytest.approx(torque / rb / k_pair, rel=2e-3)


def test_rotor_on_two_bearings_static_deflection(bearing_rig):
    """Radial load W on a symmetric rotor: each bearing carries W/2 and deflects δ with
    W/2 = k Σ (δ cos θ_i − c)^1.5 cos θ_i (hand sum over the balls at their cage angles)."""
    load = 3000.0
    op = cmsim.OperatingPoint(speed_rpm=600.0, radial_load_n=load)
    model = build_model(bearing_rig, op)
    q = quasi_static_state(model, 0.0)
    b = bearing_rig.bearings[0]
    k = bearing_contact_stiffness(b)
    ix = model.index("x_1b1")
    # the load points down (-y); ball i sits at θ_cage + 2π i/9 with θ_cage = 0 at t = 0
    theta = 2 * math.pi * np.arange(9) / 9 + math.pi / 2  # angles measured from the load line

    def reaction(d):
        ov = d * np.cos(theta - math.pi) - b.clearance_m
        return k * np.sum(np.clip(ov, 0, None) ** 1.5 * np.cos(theta - math.pi))

    d_hand = brentq(lambda d: reaction(d) - load / 2, b.clearance_m, 1e-3)
    assert q[ix] == pytest.approx(0.0, abs=0.02 * d_hand)
    assert -q[ix + 1] == pytest.approx(d_hand, rel=0.02)


def test_mean_bearing_reactions_balance_mesh_force():
    rig = cmsim.Rig.paper_2016()
    run = cmsim.dynamics.simulate(rig, cmsim.OperatingPoint(1000, 60), 0.3, seed=4)
    mesh = run["Fmesh_total"].mean()
    assert mesh == pytest.approx(60 / rig.gears.driving.base_radius_m, rel=0.01)
    for shaft in ("1", "2"):
        loa = run[f"F_{shaft}b1_loa"].mean() + run[f"F_{shaft}b2_loa"].mean()
        oloa = run[f"F_{shaft}b1_oloa"].mean() + run[f"F_{shaft}b2_oloa"].mean()
        assert loa == pytest.approx(mesh, rel=0.01)
        assert abs(oloa) < 0.01 * mesh


def test_check_memory_refuses_a_run_that_does_not_fit():
    """A run whose outputs exceed MAX_OUTPUT_BYTES is refused before any work, naming the
    duration that fits; the paper's 75 kHz second fits."""
    rig = cmsim.Rig.paper_2016()
    check_memory(1.0, 75_000.0, rig)
    with pytest.raises(ParameterError, match=r"duration_s = 600 s .* duration_s <= \d+ s"):
        check_memory(600.0, 1e7, rig)
