"""Hybrid contact solve of paper 001 eq. 2 (mesh_stiffness.hybrid, _hybrid_kernels).

Tier (a), exact properties of the solution: the numba kernel agrees to 1e-9 with an
independent Python solve that enumerates every active set and solves each with
``scipy.optimize.root``; its forces are non-negative, the loaded contacts satisfy
compatibility to round-off, the unloaded ones have non-negative gaps (complementarity); a
single contact solves the scalar equation; the kernel can be called from numba code and is
fast enough for the time integrator (measured, with a generous bound).

Uses the paper gear's influence tables from the session's FE cache (built once, ≈ 10 s).
"""

import math
import time

import numpy as np
import pytest
from numba import njit

from cmsim.errors import ParameterError
from cmsim.mesh_stiffness._hybrid_kernels import hybrid_forces_jit
from cmsim.mesh_stiffness.hybrid import HybridMeshModel, work_size
from cmsim.rig import Rig


@pytest.fixture(scope="module")
def model():
    return HybridMeshModel.from_pair(Rig.paper_2016().gears)


def _case(model, rng, n, equal):
    pair = model.pair
    length = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)
    pb = pair.driving.base_pitch_m
    lo = 2e-3
    s = rng.uniform(lo, max(lo, 29e-3 - (n - 1) * pb)) + pb * np.arange(n)
    r1, r2 = s, length - s
    delta = np.full(n, rng.uniform(0.0, 3e-5)) if equal else rng.uniform(-2e-5, 4e-5, n)
    chi1, chi2 = np.maximum(r1, 2e-4), np.maximum(r2, 2e-4)
    if rng.uniform() < 0.2:                    # a corner contact: tip rounding radius
        chi2[0] = 1.6e-4
    return delta, r1, r2, chi1, chi2


def _check_solution(model, f, delta, r1, r2, chi1, chi2):
    cm = model.coupling_matrix(r1, r2)
    scale = np.max(delta)
    assert np.all(f >= 0.0)
    gap = cm @ f - delta
    for i in range(f.size):
        if f[i] > 0:
            resid = model.local_approach(f[i], chi1[i], chi2[i]) + gap[i]
            assert abs(resid) <= 1e-11 * scale
        else:
            assert gap[i] >= -1e-12 * scale


@pytest.mark.parametrize("seed", range(4))
def test_kernel_matches_enumeration(model, seed):
    rng = np.random.default_rng(seed)
    worst = 0.0
    for trial in range(40):
        n = int(rng.integers(1, 5))
        delta, r1, r2, chi1, chi2 = _case(model, rng, n, equal=trial % 3 == 0)
        f = model.forces(delta, r1, r2, chi1, chi2)
        ref = model.forces_reference(delta, r1, r2, chi1, chi2)
        if np.max(ref) > 0:
            worst = max(worst, float(np.max(np.abs(f - ref)) / np.max(ref)))
        else:
            assert np.all(f == 0.0)
        if np.max(delta) > 0:
            _check_solution(model, f, delta, r1, r2, chi1, chi2)
    assert worst < 1e-9


def test_single_contact_solves_the_scalar_equation(model):
    delta, r1, r2 = np.array([2e-5]), np.array([0.0152]), np.array([0.0152])
    f = model.forces(delta, r1, r2, r1, r2)[0]
    c = model.coupling_matrix(r1, r2)[0, 0]
    assert math.isclose(model.local_approach(f, r1[0], r2[0]) + c * f, delta[0], rel_tol=1e-12)
    # stiffer than the bodies alone would be without the local term is impossible
    assert f < delta[0] / c


def test_a_neighbour_load_can_unload_a_contact(model):
    """Slot 1 is pressed 20 µm, slot 0 only 1 µm: the neighbour's load twists the web and
    the 1 µm contact opens (F = 0, positive gap)."""
    pair = model.pair
    length = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)
    s = 0.008 + pair.driving.base_pitch_m * np.arange(2)
    delta = np.array([1e-6, 2e-5])
    f = model.forces(delta, s, length - s, s, length - s)
    assert f[0] == 0.0 and f[1] > 0
    _check_solution(model, f, delta, s, length - s, s, length - s)


def test_no_interference_no_force(model):
    f = model.forces(np.array([-1e-6, 0.0, -3e-6]), np.full(3, 0.01), np.full(3, 0.02),
                     np.full(3, 0.01), np.full(3, 0.02))
    assert np.all(f == 0.0)


def test_forces_rejects_bad_input(model):
    with pytest.raises(ParameterError, match="same length"):
        model.forces([1e-6, 1e-6], [0.01], [0.02], [0.01], [0.02])
    with pytest.raises(ParameterError, match="radii"):
        model.forces([1e-6], [0.01], [0.02], [0.0], [0.02])
    with pytest.raises(ParameterError, match="finite"):
        model.forces([np.nan], [0.01], [0.02], [0.01], [0.02])


def test_kernel_from_numba_and_its_speed(model):
    """Callable inside njit code with preallocated work/out; time per call is printed."""
    pair = model.pair
    length = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)
    s = 0.009 + pair.driving.base_pitch_m * np.arange(3)
    r1, r2 = s.copy(), length - s
    delta = np.array([2.5e-5, 2.5e-5, -5e-6])
    hp, d1, c1, d2, c2 = model.kernel_args()
    work, out, extra = np.empty(work_size(3)), np.empty(3), np.zeros(3)

    @njit
    def many(n_calls, delta, r1, r2, hp, d1, c1, d2, c2, extra, work, out):
        acc = 0.0
        for k in range(n_calls):
            delta[0] = 2.5e-5 + 1e-9 * (k % 11)
            if hybrid_forces_jit(delta, r1, r2, r1, r2, hp, d1, c1, d2, c2, extra, work,
                                 out) < 0:
                return -1.0
            acc += out[0]
        return acc

    assert many(10, delta, r1, r2, hp, d1, c1, d2, c2, extra, work, out) > 0
    n_calls = 50_000
    t0 = time.perf_counter()
    assert many(n_calls, delta, r1, r2, hp, d1, c1, d2, c2, extra, work, out) > 0
    per_call = (time.perf_counter() - t0) / n_calls
    # printed, not asserted: wall times depend on the machine's load
    print(f"hybrid_forces_jit, 3 contacts (2 loaded): {per_call * 1e6:.2f} µs per call")
    delta[0] = 2.5e-5
    ref = model.forces_reference(delta, r1, r2, r1, r2)
    hybrid_forces_jit(delta, r1, r2, r1, r2, hp, d1, c1, d2, c2, extra, work, out)
    assert np.allclose(out, ref, rtol=1e-9, atol=0)


def test_extra_compliance_of_a_weakened_tooth_is_in_series_with_its_own_contact(model):
    """A compliance e added to contact i (a cracked tooth, :mod:`cmsim.faults`) acts in
    series with that contact only: the forces F' solved with it are the healthy solution of
    the interferences δ − e·F', and the weakened pair carries less of the load."""
    pair = model.pair
    length = pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)
    s = 0.004 + pair.driving.base_pitch_m * np.arange(2)      # double contact
    r1, r2 = s.copy(), length - s
    delta = np.array([2.0e-5, 2.0e-5])
    hp, d1, c1, d2, c2 = model.kernel_args()
    work, healthy, weak = np.empty(work_size(2)), np.empty(2), np.empty(2)
    assert hybrid_forces_jit(delta, r1, r2, r1, r2, hp, d1, c1, d2, c2, np.zeros(2), work,
                             healthy) >= 0
    k0 = healthy[0] / delta[0]
    extra = np.array([1.0 / k0, 0.0])                   # tooth 0 about half as stiff
    assert hybrid_forces_jit(delta, r1, r2, r1, r2, hp, d1, c1, d2, c2, extra, work,
                             weak) >= 0
    assert weak[0] < 0.75 * healthy[0] and weak[1] > healthy[1]
    again = np.empty(2)
    hybrid_forces_jit(delta - extra * weak, r1, r2, r1, r2, hp, d1, c1, d2, c2, np.zeros(2),
                      work, again)
    np.testing.assert_allclose(again, weak, rtol=1e-6)
