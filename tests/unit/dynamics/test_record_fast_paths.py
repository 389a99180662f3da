"""The shortcuts that make a dataset record cheaper give the same numbers, bit for bit.

Tier: same-code regression guard (issue 27). Each shortcut is checked against the general
path it replaces, run side by side on the same model: equality is exact (``array_equal``),
not a tolerance, because each shortcut only skips work whose result is known exactly (a
zero added, a value read back unchanged).
"""

import numpy as np
import pytest

import cmsim
from cmsim.dynamics import build_model, quasi_static_state
from cmsim.dynamics._mesh_kernels import MI_BALL_SLIP
from cmsim.dynamics._rhs_kernels import (integrate_jit, make_integrator_buffers, make_work,
                                         no_propagator)
from cmsim.dynamics.integrator import SCHEMES
from cmsim.dynamics.tooth_contact import resolve_mesh
from cmsim.faults import RollingSlip

H = 1.0 / 76_800.0


def _model(slip):
    rig = cmsim.Rig.paper_2016()
    op = cmsim.OperatingPoint(1000.0, 50.0)
    return build_model(rig, op, resolve_mesh(rig, None, op.torque_nm), slip=slip,
                       duration_s=0.05, seed=3, cage_phases_rad=[0.3, 1.1, 2.0, 4.4])


def _run(model, P, n_out=1500):
    tab = SCHEMES["ode3"]
    y0 = np.concatenate([quasi_static_state(model, 0.0), np.zeros(model.n_dof)])
    out = np.empty((n_out, y0.size))
    diag = np.empty((n_out, len(model.output_force_names)))
    status = integrate_jit(y0, 0.0, H, n_out, 1, 0, tab.a, tab.b, tab.c, no_propagator(3), P,
                           make_work(P),
                           make_integrator_buffers(tab.b, y0.size, diag.shape[1]), out, diag,
                           1e-3, 0.5, model.translational_mask)
    assert status == -1
    return out, diag


@pytest.mark.parametrize("ball_rms", [0.0, 2e-3])
def test_ball_slip_flag_says_whether_balls_move(ball_rms):
    model = _model(RollingSlip(cage_speed_rms=0.005, ball_rms_rad=ball_rms))
    assert model.kernel_params.m_int[MI_BALL_SLIP] == int(ball_rms > 0)


def test_cage_only_slip_skips_the_ball_grid_bit_for_bit():
    """A slip of the cages alone (a dataset's ``slip``) leaves every ball row of the grid at
    zero; skipping those rows must not change a bit of the states or forces."""
    model = _model(RollingSlip(cage_speed_rms=0.005))
    P = model.kernel_params
    m_int = P.m_int.copy()
    m_int[MI_BALL_SLIP] = 1                       # force the general per-ball path
    general = P._replace(m_int=m_int).frozen()      # one array-flag signature
    fast_y, fast_d = _run(model, P)
    ref_y, ref_d = _run(model, general)
    assert np.array_equal(fast_y, ref_y)
    assert np.array_equal(fast_d, ref_d)
    # and the slip is felt: the run differs from one without slip
    no_slip_y, _ = _run(model, _model(None).kernel_params)
    assert not np.array_equal(fast_y, no_slip_y)


@pytest.mark.parametrize("factor, width", [(3, 7), (2, 1), (5, 8), (3, 0), (3, 5), (4, 2),
                                           (2, 9), (3, 6)])
def test_anti_alias_kernel_is_upfirdn_bit_for_bit(factor, width):
    """The numba FIR gives :func:`scipy.signal.upfirdn`'s outputs exactly (the sums in the
    same order), for any width (groups of four columns, then the columns left over one by
    one, any number of outputs), a transposed (non-contiguous) block and a 1-D signal."""
    from scipy.signal import upfirdn

    from cmsim.dynamics.decimation import AntiAliasFilter

    aa = AntiAliasFilter(factor, 25_600.0 * factor)
    rng = np.random.default_rng(factor)
    x = rng.standard_normal((5_003, width)) * np.logspace(-6, 3, width)
    hl = aa.half_length
    n_out = (x.shape[0] - 2 * hl - 1) // factor + 1
    first = 2 * hl // factor
    ref = upfirdn(aa.taps, x, up=1, down=factor, axis=0)[first:first + n_out]
    assert np.array_equal(aa.apply(x), ref)
    assert np.array_equal(aa.apply(np.asfortranarray(x)), ref)
    if width:
        assert np.array_equal(aa.apply(x[:, 0]), ref[:, 0])
    assert aa.apply(x[:2 * hl]).shape == (0, width)


@pytest.mark.parametrize("fs_hz", [25_600.0, 12_000.0, 51_200.0, 200_000.0])
def test_housing_path_at_the_force_rate_is_the_interpolated_sosfilt(fs_hz):
    """The housing path run at the force's own rate (cmsim._kernels) gives the sum of one
    ``sosfilt`` per mode over the force interpolated by ``resample_poly`` and kept every k-th
    sample (the reference written as it was before the kernel) to rounding: within 1e-12 of
    the largest on these forces (measured 3e-14 to 9e-14 on a white force, 2e-13 to 4e-13
    on a wandering one of 20 000 samples; 1e-12 to 3e-12 on one of 10 s, as the modes'
    double zero at DC takes its low frequencies away), the first two samples, which start
    the recursion, to rounding as well (their sums run in another order); forces side by
    side each as alone, bit for bit."""
    import math

    from scipy.signal import resample_poly, sosfilt

    from cmsim.sensors import (STEPS_PER_MODE_PERIOD, housing_acceleration, housing_sos,
                               interpolation_filter)

    path = cmsim.Rig.paper_2016().housing
    rng = np.random.default_rng(7)
    k = max(1, math.ceil(STEPS_PER_MODE_PERIOD * max(path.natural_frequencies_hz) / fs_hz))
    for force in (rng.standard_normal(4_001) * 300.0 + 1e3,
                  np.cumsum(rng.standard_normal(20_000)) * 3.0 + 1e3, np.array([5.0, 7.0])):
        x = force - force[0]
        xk = resample_poly(x, k, 1, window=interpolation_filter(k) / k) if k > 1 else x
        ref = np.zeros_like(xk)
        for section in housing_sos(path, fs_hz * k):
            ref += sosfilt(section[None, :], xk)
        ref = ref[::k]
        got = housing_acceleration(force, fs_hz, path)
        assert np.max(np.abs(got - ref)) <= 1e-12 * np.max(np.abs(ref))
        assert np.allclose(got[:2], ref[:2], rtol=1e-13, atol=1e-16 * np.max(np.abs(ref)))
        both = housing_acceleration(np.column_stack([force[::-1], force]), fs_hz, path)
        assert np.array_equal(both[:, 1], got)
        assert np.array_equal(both[:, 0], housing_acceleration(force[::-1], fs_hz, path))


def test_recorded_signals_are_those_of_the_full_run():
    """A run that keeps a few signals forms only those, with the values the full run has
    (derived ones too: line of action, DTE, total mesh force; a speed profile's rotation)."""
    from cmsim.dynamics import simulate
    from cmsim.faults import SpeedFluctuation

    rig = cmsim.Rig.paper_2016()
    op = cmsim.OperatingPoint(900.0, 40.0)
    keep = ["theta_1b1", "F_1b1_y", "F_2b1_loa", "F_1b1_oloa", "dte_um", "Fmesh_total"]
    kw = dict(fs_hz=25_600.0, seed=5, warmup_s=0.005,
              faults=[SpeedFluctuation(relative_amplitude=0.002, frequency_hz=3.0)])
    full = simulate(rig, op, 0.01, **kw)
    part = simulate(rig, op, 0.01, record=keep, **kw)
    assert sorted(part.signals) == sorted(keep)
    for name in keep:
        assert np.array_equal(part[name], full[name]), name


def test_cracked_factor_with_the_healthy_pair_cached_is_unchanged():
    """The cracked tooth's stiffness factor reads the healthy pair's compliance from a cache
    the second time: the same factor, bit for bit, as the healthy pair computed afresh."""
    import math

    from cmsim.faults import crack
    from cmsim.mesh_stiffness.potential_energy import pair_compliance_potential_energy

    pair = cmsim.Rig.paper_2016().gears
    lo, hi = crack._involute_domain(pair)
    s = np.linspace(lo, hi, 57)
    crack._healthy_pair_compliance.cache_clear()
    first = crack.crack_stiffness_factor(pair, 2, 1.2e-3, math.pi / 4, s)
    again = crack.crack_stiffness_factor(pair, 2, 1.2e-3, math.pi / 4, s)
    assert crack._healthy_pair_compliance.cache_info().hits >= 1
    healthy = pair_compliance_potential_energy(pair, s)
    cracked = crack.cracked_tooth_compliance(
        crack.ToothProfile.from_gear(pair.driven),
        np.sqrt(pair.driven.base_radius_m ** 2 + (crack._path_length(pair) - s) ** 2),
        1.2e-3, math.pi / 4)
    ref = healthy.total / (healthy.hertz + healthy.driving.total + cracked.total)
    assert np.array_equal(first, ref) and np.array_equal(again, ref)


def test_cracked_tooth_reuses_its_sections_bit_for_bit():
    """A cracked tooth on a contact grid met before reads the beam's nodes and the tooth's
    own sections at them from the last crack: the same compliance, bit for bit, as the beam
    integrated afresh with the cracked section (the reference written as it was before the
    store), and another depth still gives another one."""
    import math

    from cmsim.faults import crack
    from cmsim.mesh_stiffness import potential_energy as pe
    from cmsim.mesh_stiffness.geometry import involute_half_angle

    gear = cmsim.Rig.paper_2016().gears.driving
    profile = crack.ToothProfile.from_gear(gear)
    r = np.linspace(profile.form_radius_m, profile.tip_round_start_radius_m, 300)
    nu = math.pi / 4
    y0, y_s = profile.root_chord_y_m, crack.crack_start(profile)[0]
    theta = involute_half_angle(r, gear.base_radius_m, gear.base_half_thickness_angle_rad)
    x_c, y_c = r * np.sin(theta), r * np.cos(theta)
    a1 = np.arccos(gear.base_radius_m / r) - theta
    pe._tooth_sections.cache_clear()
    results = {}
    for depth in (0.8e-3, 1.6e-3, 0.8e-3):
        h_q = crack.crack_tip_offset_m(profile, depth, nu)

        def h_eff(u):
            y = np.minimum(y0 + u, profile.tip_radius_m)
            h = profile.half_thickness_at(y)
            return np.where((y >= y_s) & (h > h_q), 0.5 * (h + h_q), h)

        ref = pe.cantilever_compliance(h_eff, y_c - y0, x_c, a1, gear.youngs_modulus_pa,
                                       gear.poisson_ratio, gear.face_width_m)
        got = crack.cracked_tooth_compliance(profile, r, depth, nu)
        for part, want in zip(("bending", "shear", "axial"), ref):
            assert np.array_equal(getattr(got, part), want), (depth, part)
        results[depth] = got.bending
    assert pe._tooth_sections.cache_info().hits >= 2
    assert not np.array_equal(results[0.8e-3], results[1.6e-3])


def test_mesh_stiffness_of_a_table_is_computed_once():
    """A table's mesh stiffness over the mesh cycle (a run asks for it four times) is summed
    once per pair and kept; the kept arrays are the ones summed afresh, read-only, and a
    table derived from it (another stiffness) sums its own."""
    import dataclasses

    from cmsim.dynamics.tooth_contact import resolve_mesh

    rig = cmsim.Rig.paper_2016()
    table, _ = resolve_mesh(rig, None, 43.2)
    first = table.mesh_stiffness(rig.gears)
    assert table.mesh_stiffness(rig.gears) is first
    fresh = table._mesh_cycle(rig.gears, 400)
    assert all(np.array_equal(a, b) for a, b in zip(first, fresh))
    assert not first[1].flags.writeable
    stiffer = dataclasses.replace(table, stiffness_n_per_m=2.0 * table.stiffness_n_per_m)
    assert stiffer.mean_mesh_stiffness(rig.gears) == pytest.approx(
        2.0 * table.mean_mesh_stiffness(rig.gears), rel=1e-12)
