"""Speed of the time integration, measured side by side in one run (issue 2).

Prints
1. the realtime factor (simulated s / wall s) at 75 kHz on the default rig, 100 N m;
2. the per-step cost of our ode3 relative to a bare numba ode3 loop over only the linear
   19-DOF part, written the plain way (dense M⁻¹(f − K q − C v)); also relative to the same
   loop using our spring-element linear part;
3. our speed relative to the same model written the way a user would otherwise write it:
   ``scipy.integrate.solve_ivp`` (RK23, the same step) with a NumPy right-hand side
   (vectorised over balls, pure-Python pair geometry). The NumPy RHS is checked against the
   kernel first, so both integrate the same equations.

Run: ``python benchmarks/bench_simulate.py`` (about a minute). The three loops of 1-2 are
timed in turns, in CPU time, several rounds; a ratio is the median of the rounds' ratios
(with their range), so a machine that drifts between rounds moves both sides of each ratio;
the absolute times are the best round. Compare ratios, not absolute times.
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit
from scipy.integrate import solve_ivp

import cmsim
from cmsim.dynamics import build_model, quasi_static_state
from cmsim.dynamics._bearing_kernels import BI_SIZE, BP_C, BP_CAGE, BP_K, BP_P, BP_PHASE, BP_SENSE
from cmsim.dynamics._mesh_kernels import (MI_SIZE, MP_A0, MP_BETA, MP_DTHR, MP_KOSTER, MP_MU,
                                          MP_OM1, MP_OM2, MP_PB, MP_PSI10, MP_PSI20, MP_SLO,
                                          MP_TAB0, MP_TABD, MP_V0, MP_ZAFTER, MP_ZBEFORE)
from cmsim.dynamics._rhs_kernels import (integrate_jit, make_integrator_buffers, make_work,
                                         no_propagator)
from cmsim.dynamics.integrator import SCHEMES
from cmsim.dynamics.simulation import integrate
from cmsim.dynamics.tooth_contact import resolve_mesh
from cmsim.mesh_stiffness._kernels import mesh_frame_jit, pair_contact_jit
from bench_dataset import cpu_info  # the one CPU description of the benchmarks

FS = 75_000.0
REPEATS = 5


@njit(cache=True)
def dense_linear_ode3(y0, h, n_steps, minv, kmat, cmat, fext, out):
    """Bare ode3 over M q'' + C q' + K q = f with dense matrices (the baseline)."""
    n = minv.shape[0]
    y = y0.copy()
    k1 = np.empty(2 * n)
    k2 = np.empty(2 * n)
    k3 = np.empty(2 * n)
    yi = np.empty(2 * n)
    for step in range(n_steps):
        for stage in range(3):
            if stage == 0:
                src, dst, c = y, k1, 0.0
            elif stage == 1:
                for i in range(2 * n):
                    yi[i] = y[i] + 0.5 * h * k1[i]
                src, dst = yi, k2
            else:
                for i in range(2 * n):
                    yi[i] = y[i] + 0.75 * h * k2[i]
                src, dst = yi, k3
            for i in range(n):
                acc = fext[i]
                for j in range(n):
                    acc -= kmat[i, j] * src[j] + cmat[i, j] * src[n + j]
                dst[i] = src[n + i]
                dst[n + i] = minv[i] * acc
        for i in range(2 * n):
            y[i] += h * (2.0 / 9.0 * k1[i] + 1.0 / 3.0 * k2[i] + 4.0 / 9.0 * k3[i])
        for i in range(2 * n):
            out[step, i] = y[i]
    return y


def numpy_rhs_factory(model):
    """The same equations as the kernel, written with NumPy (what a user would write)."""
    P = model.kernel_params
    n = model.n_dof
    minv, fext, omega = P.minv, P.fext, P.omega
    kmat, cmat = model.stiffness, model.damping
    b_int, b_par, b_cos, b_sin = P.b_int, P.b_par, P.b_cos, P.b_sin
    m_int, mp, geo, tab_k, tab_e = P.m_int, P.m_par, P.geo, P.tab_k, P.tab_e
    i1, i2, n_slots = int(m_int[0]), int(m_int[1]), int(m_int[2])
    rb1, rb2 = geo[0], geo[1]
    offsets = np.arctan2(b_sin, b_cos)
    z1, z2 = P.teeth1.shape[0], P.teeth2.shape[0]
    s_tab = mp[MP_TAB0] + mp[MP_TABD] * np.arange(tab_k.size)

    def rhs(t, y):
        q, v = y[:n], y[n:]
        g = fext.copy()
        # bearings, vectorised over balls
        rate = b_par[:, BP_CAGE] * b_par[:, BP_SENSE]
        cage = rate * (omega[b_int[:, 2]] * t + q[b_int[:, 2]]) + b_par[:, BP_PHASE]
        theta = cage[:, None] + offsets
        x, yy = q[b_int[:, 0]], q[b_int[:, 1]]
        d = x[:, None] * np.cos(theta) + yy[:, None] * np.sin(theta) - b_par[:, BP_C][:, None]
        f = b_par[:, BP_K][:, None] * np.clip(d, 0.0, None) ** b_par[:, BP_P][:, None]
        np.subtract.at(g, b_int[:, 0], np.sum(f * np.cos(theta), axis=1))
        np.subtract.at(g, b_int[:, 1], np.sum(f * np.sin(theta), axis=1))
        # mesh: exact pair geometry per potential pair
        c1x, c1y, c2x, c2y = q[i1], q[i1 + 1], q[i2], mp[MP_A0] + q[i2 + 1]
        phi_t1, length, cos_t1, sin_t1 = mesh_frame_jit.py_func(c1x, c1y, c2x, c2y, rb1, rb2)
        psi1 = mp[MP_OM1] * t + q[i1 + 2] + mp[MP_PSI10]
        psi2 = mp[MP_PSI20] - (mp[MP_OM2] * t + q[i2 + 2])
        delta_inv = (rb1 * (q[i1 + 2] + mp[MP_PSI10] - phi_t1)
                     + rb2 * (mp[MP_PSI20] - q[i2 + 2] - phi_t1 - math.pi) - length)
        s_ref = rb1 * (psi1 - phi_t1)
        m0 = math.floor((s_ref - mp[MP_SLO]) / mp[MP_PB])
        w1, w2 = mp[MP_OM1] + v[i1 + 2], -(mp[MP_OM2] + v[i2 + 2])
        for j in range(n_slots):
            pair = m0 - j
            s = s_ref - pair * mp[MP_PB]
            if s < length - geo[3] - mp[MP_ZBEFORE] or s > geo[2] + mp[MP_ZAFTER]:
                continue
            p1 = psi1 - 2 * math.pi * (pair % z1) / z1
            p2 = psi2 + 2 * math.pi * (pair % z2) / z2
            delta, nx, ny, px, py, s_eq, chi1, chi2 = pair_contact_jit.py_func(
                s, delta_inv, math.cos(p1), math.sin(p1), math.cos(p2), math.sin(p2),
                c1x, c1y, c2x, c2y, cos_t1, sin_t1, length, geo)
            dvx = (v[i1] - w1 * (py - c1y)) - (v[i2] - w2 * (py - c2y))
            dvy = (v[i1 + 1] + w1 * (px - c1x)) - (v[i2 + 1] + w2 * (px - c2x))
            approach = dvx * nx + dvy * ny
            overlap = delta - np.interp(s, s_tab, tab_e)
            if overlap > 0:
                k_pair = np.interp(s, s_tab, tab_k)
                fn = max(k_pair * (overlap + mp[MP_BETA] * approach), 0.0)
            elif approach > 0:
                gap = max(-overlap, mp[MP_DTHR])
                req = chi1 * chi2 / (chi1 + chi2) if chi1 > 0 and chi2 > 0 else 0.0
                fn = mp[MP_KOSTER] * (req / (2 * gap)) ** 1.5 * approach
            else:
                continue
            slide = dvx * ny - dvy * nx
            ff = mp[MP_MU] * fn * slide / math.sqrt(slide ** 2 + mp[MP_V0] ** 2)
            f2 = np.array([fn * nx + ff * ny, fn * ny - ff * nx])
            g[i2:i2 + 2] += f2
            g[i1:i1 + 2] -= f2
            g[i1 + 2] -= (px - c1x) * f2[1] - (py - c1y) * f2[0]
            g[i2 + 2] -= (px - c2x) * f2[1] - (py - c2y) * f2[0]
        return np.concatenate([v, minv * (g - kmat @ q - cmat @ v)])

    return rhs


def main():
    rig = cmsim.Rig.paper_2016()
    op = cmsim.OperatingPoint(1000.0, 100.0)
    model = build_model(rig, op, resolve_mesh(rig, None, op.torque_nm),
                        cage_phases_rad=[0.3, 1.1, 2.0, 4.4])
    name, cores, load = cpu_info()
    print(f"CPU: {name}, {cores} cores usable, load average {load[0]:.1f} (figures are ratios "
          "measured side by side in this run; absolute times depend on the machine and its "
          "load)")
    print(f"mesh: {model.mesh_table.method} table at {model.mesh_table.torque_nm} N m")
    n = model.n_dof
    y0 = np.concatenate([quasi_static_state(model, 0.0), np.zeros(n)])
    h = 1.0 / FS
    n_steps = int(0.5 * FS)

    # the three loops, timed in turns (our integration, a bare dense linear ode3, our kernel on
    # the linear part only), CPU time, so each ratio pairs runs that met the same machine
    out = np.empty((n_steps, 2 * n))
    args = (model.kernel_params.minv, model.stiffness, model.damping, model.force, out)
    P = model.kernel_params._replace(b_int=np.zeros((0, BI_SIZE), dtype=np.int64),
                                     m_int=np.zeros(MI_SIZE, dtype=np.int64))
    tab = SCHEMES["ode3"]
    diag = np.empty((n_steps, len(model.output_force_names)))

    def linear_only():
        # without the mesh, the load torque spins shaft 2 up: lift the divergence limits
        status = integrate_jit(y0, 0.0, h, n_steps, 1, 0, tab.a, tab.b, tab.c,
                               no_propagator(tab.b.shape[0]), P,
                               make_work(P), make_integrator_buffers(tab.b, 2 * n, diag.shape[1]),
                               out, diag, math.inf, math.inf, model.translational_mask)
        assert status == -1

    loops = {"ours": lambda: integrate(model, y0, 0.0, h, n_steps),
             "dense": lambda: dense_linear_ode3(y0, h, n_steps, *args),
             "linear": linear_only}
    integrate(model, y0, 0.0, h, 10)  # compile
    dense_linear_ode3(y0, h, 10, *args)
    linear_only()
    rounds = {k: [] for k in loops}
    for _ in range(REPEATS):
        for key, fn in loops.items():
            start = time.process_time()
            fn()
            rounds[key].append((time.process_time() - start) / n_steps)
    ours_per_step = min(rounds["ours"])
    ours = ours_per_step * n_steps

    def ratio(key):
        r = sorted(a / b for a, b in zip(rounds["ours"], rounds[key]))
        return f"{np.median(r):.2f} (rounds {r[0]:.2f}-{r[-1]:.2f})"

    print(f"realtime factor at 75 kHz (default rig, 100 N m): {h / ours_per_step:.2f} "
          f"({ours_per_step * 1e9:.0f} ns per ode3 step, CPU, best of {REPEATS})   "
          "[target >= 10]")
    print(f"per-step cost / bare dense-linear numba ode3: {ratio('dense')} "
          f"(baseline {min(rounds['dense']) * 1e9:.0f} ns per step)   [target <= 3]")
    print(f"per-step cost / our kernel on the linear part only: {ratio('linear')} "
          f"(baseline {min(rounds['linear']) * 1e9:.0f} ns per step)")

    # 3. solve_ivp with a NumPy right-hand side of the same model
    rhs = numpy_rhs_factory(model)
    rng = np.random.default_rng(0)
    for _ in range(20):
        t = rng.uniform(0, 0.1)
        y = y0 + np.concatenate([rng.normal(0, 2e-6, n), rng.normal(0, 1e-3, n)])
        ref = model.rhs(t, y)
        assert np.allclose(rhs(t, y), ref, rtol=1e-7, atol=1e-9 * np.abs(ref).max()), \
            "NumPy RHS differs from the kernel"
    span = 0.01
    start = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, span), y0, method="RK23", max_step=h, first_step=h,
                    t_eval=np.arange(0.0, span, h))
    ivp = time.perf_counter() - start
    assert sol.success
    ivp_per_sim_s = ivp / span
    ours_per_sim_s = ours / (n_steps * h)
    print(f"speed vs solve_ivp(RK23, NumPy RHS, same step): {ivp_per_sim_s / ours_per_sim_s:.0f}x "
          f"({sol.nfev} RHS calls for {span} s, {ivp:.1f} s wall)   [target >= 100]")


if __name__ == "__main__":
    main()
