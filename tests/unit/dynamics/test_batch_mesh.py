"""The tooth contacts of a batch of runs (:mod:`cmsim.dynamics._batch_mesh_kernels`) against
the single-run kernel, run by run (issue 49).

Test tier: behaviour contract against the reference kernel
(:func:`cmsim.dynamics._mesh_kernels.mesh_forces_jit`, table mode): for runs of one kernel
layout (healthy; cracked and spalled teeth; eccentric gears) at states drawn about their
start states and at times across several mesh periods — so pairs enter and leave the
zone and rounded-tip (corner) contacts occur — the batched passes give each run's forces,
output forces and involute-origin anchors bit for bit, in any batch and any place.
"""

import numpy as np
import pytest

import cmsim
from cmsim.dynamics._batch_mesh_kernels import BS_SIZE, R_LEN, R_SIZE, mesh_forces_batch_jit
from cmsim.dynamics._mesh_kernels import MI_SLOTS, mesh_forces_jit
from cmsim.dynamics._rhs_kernels import make_work
from cmsim.dynamics.batch import _batch_arrays, _faulty_teeth, kernel_layout
from cmsim.dynamics.simulation import prepare_run
from cmsim.faults import Eccentricity, ToothCrack, ToothSpall

FS = 25_600.0


def _setups(faults_per_run):
    rig = cmsim.Rig.paper_2016()
    ops = [(900.0, 30.0), (1200.0, 80.0), (1000.0, 12.0), (1400.0, 60.0)]
    return [prepare_run(rig, cmsim.OperatingPoint(*ops[i % 4]), 0.01, fs_hz=FS, seed=i,
                        warmup_s=0.0, faults=faults)
            for i, faults in enumerate(faults_per_run)]


CASES = {
    "healthy": [(), (), (), ()],
    "tooth faults": [(ToothCrack(gear=1, depth_m=2e-3),), (ToothCrack(gear=1, depth_m=1e-3),),
                     (ToothCrack(gear=1, depth_m=0.5e-3),), (ToothCrack(gear=1, depth_m=2.4e-3),)],
    "spalls": [(ToothSpall(gear=2, width_m=w, depth_m=20e-6),) for w in (0.5e-3, 1e-3, 1.5e-3,
                                                                         2e-3)],
    "eccentric": [(Eccentricity(gear=g, amplitude_m=a),) for g, a in ((1, 5e-6), (2, 2e-5),
                                                                      (1, 5e-5), (2, 1e-5))],
}


def _single(setups, ys, taus, srs, want_diag):
    """Each run's forces through the single-run kernel (its own scratch, carried on)."""
    out = []
    works = [make_work(s.model.kernel_params) for s in setups]
    n = ys[0][0].size // 2
    n_diag = len(setups[0].model.output_force_names)
    for y, tau, sr in zip(ys, taus, srs):
        step = []
        for l, s in enumerate(setups):
            P = s.model.kernel_params
            g = np.zeros(n)
            d = np.zeros(n_diag)
            mesh_forces_jit(tau[l], sr[l], y[l], n, g, P, works[l], d, want_diag)
            step.append((g, d))
        out.append(step)
    return out, works


def _batched(setups, ys, taus, srs, want_diag):
    S, L, V = _batch_arrays([s.model for s in setups])
    n_runs = len(setups)
    n = ys[0][0].size // 2
    n_diag = len(setups[0].model.output_force_names)
    r = np.zeros((R_SIZE, n_runs))
    sg = np.zeros((int(S.m_int[0, MI_SLOTS]), BS_SIZE, n_runs))
    out = []
    for y, tau, sr in zip(ys, taus, srs):
        g = np.zeros((n, n_runs))
        d = np.zeros((n_diag, n_runs))
        mesh_forces_batch_jit(np.ascontiguousarray(np.stack(y, axis=-1)), n, g, S, L.m_par,
                              L.geo, tau, sr, V.psi, r, sg, _faulty_teeth(S.tk1, S.te1),
                              _faulty_teeth(S.tk2, S.te2), d, want_diag)
        out.append([(g[:, l].copy(), d[:, l].copy()) for l in range(n_runs)])
    return out, V


def _states(setups, n_times=120, seed=0):
    """States about each run's start state and times over about three mesh periods."""
    rng = np.random.default_rng(seed)
    ys, taus, srs = [], [], []
    for k in range(n_times):
        t = k * 2.0e-5 + rng.uniform(0.0, 1e-5)
        y = []
        for s in setups:
            dev = rng.normal(0.0, 1.0, s.y0.size) * np.abs(s.y0) * 0.05
            y.append(s.y0 + dev)
        ys.append(y)
        taus.append(np.full(len(setups), t))
        srs.append(1.0 + rng.uniform(-0.01, 0.01, len(setups)))
    return ys, taus, srs


@pytest.mark.parametrize("case", sorted(CASES))
def test_batched_contacts_are_the_single_run_kernels_run_by_run(case):
    setups = _setups(CASES[case])
    assert len({kernel_layout(s) for s in setups}) == 1
    ys, taus, srs = _states(setups)
    ref, works = _single(setups, ys, taus, srs, True)
    got, V = _batched(setups, ys, taus, srs, True)
    loaded = 0
    for a, b in zip(ref, got):
        for (g_ref, d_ref), (g_got, d_got) in zip(a, b):
            np.testing.assert_array_equal(g_got, g_ref)
            np.testing.assert_array_equal(d_got, d_ref)
            loaded += np.count_nonzero(d_ref)
    assert loaded > 0                                        # pairs carried load
    for l, w in enumerate(works):                            # the same anchors, turned alike
        np.testing.assert_array_equal(V.psi[l], w.psi)


def test_a_run_in_another_batch_place_gets_the_same_contacts():
    setups = _setups(CASES["tooth faults"])
    ys, taus, srs = _states(setups, n_times=60, seed=1)
    got, _ = _batched(setups, ys, taus, srs, True)
    order = [2, 0, 3, 1]
    moved, _ = _batched([setups[i] for i in order], [[y[i] for i in order] for y in ys],
                        [t[order] for t in taus], [s[order] for s in srs], True)
    alone, _ = _batched(setups[1:2], [[y[1]] for y in ys], [t[1:2] for t in taus],
                        [s[1:2] for s in srs], True)
    for k in range(len(ys)):
        for j, i in enumerate(order):
            np.testing.assert_array_equal(moved[k][j][0], got[k][i][0])
        np.testing.assert_array_equal(alone[k][0][0], got[k][1][0])
        np.testing.assert_array_equal(alone[k][0][1], got[k][1][1])


def test_corner_contacts_and_zone_changes_are_exercised():
    """The states of the contract tests reach both kinds of contact (else they prove less)."""
    from cmsim.dynamics._mesh_kernels import SG_ON, SG_S
    setups = _setups(CASES["healthy"])
    S, L, V = _batch_arrays([s.model for s in setups])
    ys, taus, srs = _states(setups)
    geo = setups[0].model.kernel_params.geo
    r = np.zeros((R_SIZE, len(setups)))
    sg = np.zeros((int(S.m_int[0, MI_SLOTS]), BS_SIZE, len(setups)))
    n = ys[0][0].size // 2
    kinds = set()
    for y, tau, sr in zip(ys, taus, srs):
        g = np.zeros((n, len(setups)))
        d = np.zeros((len(setups[0].model.output_force_names), len(setups)))
        mesh_forces_batch_jit(np.ascontiguousarray(np.stack(y, axis=-1)), n, g, S, L.m_par,
                              L.geo, tau, sr, V.psi, r, sg, _faulty_teeth(S.tk1, S.te1),
                              _faulty_teeth(S.tk2, S.te2), d, False)
        for j in range(sg.shape[0]):
            for l in range(len(setups)):
                if sg[j, SG_ON, l]:
                    s = sg[j, SG_S, l]
                    length = r[R_LEN, l]
                    kinds.add("corner" if s < length - geo[3] or s > geo[2] else "involute")
                else:
                    kinds.add("off")
    assert kinds == {"corner", "involute", "off"}
