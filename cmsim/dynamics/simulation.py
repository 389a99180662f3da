"""Time simulation of a rig: quasi-static start, numba ode3, named output signals (the
chunked time loop and its anti-alias decimation: :mod:`cmsim.dynamics.time_loop`)."""

from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

import cmsim
from cmsim.dynamics._rhs_kernels import (PR_OMEGA, PR_THETA, integrate_jit,
                                         make_integrator_buffers, make_work, no_propagator)
from cmsim.dynamics.integrator import SCHEMES
from cmsim.dynamics.schemes import choose_scheme
from cmsim.dynamics.model import build_model
from cmsim.dynamics.profiles import SpeedProfile, kernel_profile
from cmsim.dynamics.quasistatic import initial_state
from cmsim.dynamics.step import (STEPS_PER_PERIOD, fastest_excitation,
                                 integration_substeps)
from cmsim.dynamics.time_loop import MAX_ROTATION_DEVIATION_RAD, _integrate_run, integrate
from cmsim.dynamics.time_loop import (  # noqa: F401  (moved there, re-exported here)
    CHUNK_STEPS, DECIMATION_CHUNK_STEPS, decimation, diverged_at, max_displacement_m)
from cmsim.dynamics.tooth_contact import resolve_mesh
from cmsim.errors import IntegrationDiverged, ParameterError, check_choice, check_range, check_type
from cmsim.faults import (NO_SLIP, RollingSlip, check_faults, fault_frequencies,
                          operating_modulation, rig_with_faults, slip_from_faults)
from cmsim.losses import LossSettings, power_balance, run_losses
from cmsim.mesh_stiffness.table import MeshStiffnessTable
from cmsim.progress import stage
from cmsim.rig import RANGES, SAMPLING
from cmsim.rig.plausibility import load_warnings
from cmsim.run import Run

__all__ = ["simulate", "integrate", "check_memory", "kernels_cached", "compile_kernels",
           "MAX_ROTATION_DEVIATION_RAD",           "STEPS_PER_PERIOD", "MAX_OUTPUT_BYTES"]

#: Largest output a run may hold in memory, bytes (signals as float64); longer runs are
#: refused with the duration that fits.
MAX_OUTPUT_BYTES = 8 * 2 ** 30

#: Grid spacing of a speed profile's kernel table, s (Θ interpolated linearly: error
#: ≈ (dΩ/dt)·Δt²/8, below 1e-7 rad for a 0-3000 rpm run-up in 1 s).
PROFILE_STEP_S = 1e-4


def check_memory(duration_s, fs_hz, rig):
    """Refuse a run whose outputs would not fit in :data:`MAX_OUTPUT_BYTES`, before any work.

    Parameters
    ----------
    duration_s : float
        Recorded duration, s.
    fs_hz : float
        Output sample rate, Hz.
    rig : Rig
        The rig (its DOFs and bearings set the number of signals).

    Raises
    ------
    ParameterError
        Naming ``duration_s`` and the longest duration that fits at ``fs_hz``.
    """
    n_dof = rig.n_dof
    n_diag = 4 * len(rig.bearings) + 8      # bounds the bearing and pair forces
    # states (2n), forces, then the named signals (DOFs, forces, LOA/OLOA pairs, DTE)
    per_second = 8.0 * fs_hz * (2 * n_dof + 3 * n_diag + n_dof + 8)
    if duration_s * per_second > MAX_OUTPUT_BYTES:
        raise ParameterError(
            f"duration_s = {duration_s:g} s at fs_hz = {fs_hz:g} would need "
            f"{duration_s * per_second / 2 ** 30:.1f} GiB of memory; allowed: duration_s <= "
            f"{MAX_OUTPUT_BYTES / per_second:.0f} s at this fs_hz (split longer records)")


def _recorded(model, record):
    """``(names, state columns, force columns)`` a ``record`` list needs (all: None)."""
    if record is None:
        return None, None, None
    if isinstance(record, str):
        record = (record,)
    dofs = {name: i for i, name in enumerate(model.dof_names)}
    diag = {name: j for j, name in enumerate(model.output_force_names)}
    q_cols, d_cols = set(), set()
    for name in record:
        if name in dofs:
            q_cols.add(dofs[name])
        elif name in diag:
            d_cols.add(diag[name])
        elif name.endswith(("_loa", "_oloa")) and name.startswith("F_") \
                and f"F_{name.split('_')[1]}_x" in diag:
            b = name.split("_")[1]
            d_cols |= {diag[f"F_{b}_x"], diag[f"F_{b}_y"]}
        elif name in ("dte", "dte_um") and "theta_2G1" in dofs:
            q_cols |= {dofs["theta_1G1"], dofs["theta_2G1"]}
        elif name == "Fmesh_total" and any(k.startswith("Fmesh_") for k in diag):
            d_cols |= {j for k, j in diag.items() if k.startswith("Fmesh_")}
        else:
            raise ParameterError(f"record names an unknown signal {name!r}; this model has "
                                 f"{list(dofs) + list(diag)} and the derived F_<b>_loa, "
                                 f"F_<b>_oloa, dte, dte_um, Fmesh_total", param="record")
    return set(record), sorted(q_cols), sorted(d_cols)


def kernels_cached():
    """True when the integration kernel has an up-to-date numba cache (the first run of a
    fresh install compiles it, 1-3 min on 2 cores); False when it will compile or cannot tell."""
    source = Path(sys.modules[integrate_jit.__module__].__file__)
    # numba writes its cache to $NUMBA_CACHE_DIR when set, else beside the source
    places = [Path(os.environ["NUMBA_CACHE_DIR"]) if os.environ.get("NUMBA_CACHE_DIR")
              else source.parent / "__pycache__"]
    try:
        mtime = source.stat().st_mtime
        pattern = f"{source.stem}.{integrate_jit.__name__}*.nbi"
        return any(index.stat().st_mtime >= mtime for place in places if place.is_dir()
                   for index in place.rglob(pattern))
    except OSError:
        return False


def _compile_seconds():
    """Time to compile or load the kernels (measured once per process)."""
    if not hasattr(_compile_seconds, "value"):
        start = time.perf_counter()
        rig = cmsim.Rig.paper_2016()
        model = build_model(rig, cmsim.OperatingPoint(1000.0, 10.0),
                            (MeshStiffnessTable.constant(rig.gears, 1e8), None))
        y0 = np.zeros(2 * model.n_dof)
        tab = SCHEMES["ode3"]
        integrate_jit(y0, 0.0, 1e-5, 2, 1, 0, tab.a, tab.b, tab.c,
                      no_propagator(tab.b.shape[0]), model.kernel_params,
                      make_work(model.kernel_params),
                      make_integrator_buffers(tab.b, y0.size, len(model.output_force_names)),
                      np.empty((2, y0.size)),
                      np.empty((2, len(model.output_force_names))), 1.0, 1.0,
                      model.translational_mask)
        _compile_seconds.value = time.perf_counter() - start
    return _compile_seconds.value


#: What :func:`compile_kernels` announces on stderr while numba compiles on a cold cache.
COMPILE_STAGE = ("compiling numba kernels (first run only: 1-3 min on 2 cores; later runs "
                 "load them from the cache)")


def compile_kernels():
    """Compile the integration kernels now, or load them from numba's cache.

    On a cold cache (:func:`kernels_cached` is False) the compile runs inside a
    :func:`cmsim.progress.stage`: a start line, a heartbeat and the time taken, on stderr.
    Once per process; :func:`simulate` calls it before integrating.

    Returns
    -------
    float
        Seconds the compile (or the cache load) took.
    """
    if hasattr(_compile_seconds, "value") or kernels_cached():
        return _compile_seconds()
    with stage(COMPILE_STAGE):
        return _compile_seconds()


def simulate(rig, op, duration_s=SAMPLING.duration_s, *, mesh=None, fs_hz=SAMPLING.fs_hz,
             substeps=SAMPLING.substeps, scheme="auto", slip=None, seed=SAMPLING.seed,
             warmup_s=SAMPLING.warmup_s, cage_phases_rad="random",
             profile=None, faults=(), progress=None, loads=None, friction_table=None,
             damping_table=None, losses=None, record=None, on_start=None):
    """Simulate ``rig`` at ``op`` and return a :class:`~cmsim.run.Run`.

    The run starts from the quasi-static equilibrium at t = 0 (velocities at the nominal
    rotation), integrates ``warmup_s`` to let the start transient decay, then records
    ``duration_s`` at ``fs_hz``.

    The integration step is ``1/(fs_hz·substeps)`` (the rule: :mod:`cmsim.dynamics.step`). By
    default ``substeps`` is the smallest integer that gives the scheme enough steps per
    period of the model's highest natural frequency (linearised at the start; 15.9 kHz for
    the paper's rig; ode3 :data:`STEPS_PER_PERIOD`, so 75 kHz as in the paper) and
    :data:`STEPS_PER_PERIOD` per period of each of the first
    :data:`~cmsim.dynamics.step.RESOLVED_HARMONICS` harmonics of the fastest excitation (the
    gear mesh or a ball pass, at the fastest speed of the run); a ``substeps`` given that
    does not resolve the excitation is refused. The scheme is chosen with the step
    (:mod:`cmsim.dynamics.schemes`): ode3 at 75 kHz, rk4 at 2 steps per sample at 25.6 kHz. With ``substeps > 1`` the states and forces
    pass through an anti-alias FIR (:class:`~cmsim.dynamics.decimation.AntiAliasFilter`:
    flat to 0.8 × Nyquist, ≥ 80 dB down from Nyquist on) before every ``substeps``-th
    sample is kept, as an acquisition system does: nothing above the output Nyquist
    frequency aliases (a mesh faster than it is filtered out, not folded back).

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    duration_s : float
        Recorded duration, s (0 < duration_s <= 600). The sampling defaults are
        :data:`cmsim.rig.SAMPLING`, shared with the command line and dataset specs.
    fs_hz : float
        Output sample rate, Hz (the paper: 75 kHz).
    substeps : int, optional
        Integration steps per output sample (default: chosen from the highest mode and the
        fastest excitation, see above; 1 = the paper's fixed step 1/fs, no filter).
    scheme : str
        ``"auto"`` (default: ode3 or rk4, whichever takes fewer right-hand-side evaluations
        per sample, :mod:`cmsim.dynamics.schemes`), ``"ode3"`` (Bogacki-Shampine),
        ``"rk4"``, ``"heun"``, or ``"lawson-ode3"`` / ``"lawson-rk4"``: ode3 / rk4 with the
        stiff linear chains of the shafts in closed form (:mod:`cmsim.dynamics.exponential`;
        the step is set by the rest of the model, and the run's meta lists the DOFs
        integrated exactly, ``exact_linear_dofs``). The run's meta records the scheme and
        steps taken.
    mesh : None, str, MeshStiffnessTable, MeshTableSet or HybridMeshModel
        Tooth contact model: ``None`` (default) = the rig's hybrid FE + Weber–Banaschek
        tables at the run's torque (paper 001 §6.1, model B); ``"potential-energy"`` (paper
        004's load-independent table); ``"hybrid"`` = solved on-line from the FE influence
        coefficients (model A, about 3-4 times slower); or an explicit table, a table set
        (read at the run's torque) or a ``HybridMeshModel``.
    slip : RollingSlip, optional
        Random rolling slip (:class:`cmsim.faults.RollingSlip`: cage-speed fluctuation and
        ball jitter); uses ``seed``. A ``rolling_slip`` among ``faults`` takes its place.
    seed : int or None
        Seed of the cage phases and slip (default 0: a run is reproducible); ``None`` draws
        one at random. The run's meta records it.
    warmup_s : float
        Simulated time discarded before recording, s.
    profile : SpeedProfile, optional
        Input speed (and output torque) against time from the start of the warm-up
        (:class:`~cmsim.dynamics.profiles.SpeedProfile`: a run-up, coast-down or measured
        trace); ``op`` then gives only the torque when the profile has none. The cage
        kinematics, the mesh angle and the imposed input rotation follow it.
    faults : sequence of Fault
        Faults of the catalogue (:mod:`cmsim.faults`), felt only through the model: race and
        ball defects, tooth cracks, spalls, breakage, profile errors, eccentricity, wear,
        off-size balls, rolling slip (overrides ``slip``), speed fluctuation and torque
        ripple (laid on the speed/torque, with or without ``profile``). The run's meta lists
        them with their characteristic frequencies (the answer key).
    loads, friction_table, damping_table : optional
        Extra constant generalised forces by DOF name, a mesh friction coefficient and a pair
        damping along the path (as in :func:`~cmsim.dynamics.model.build_model`; e.g. from
        :mod:`cmsim.losses`).
    losses : LossSettings or True, optional
        Every loss source in the run (:func:`cmsim.losses.run_losses`; ``True`` = default
        settings): windage, pumping, oil-jet and bearing torques resist the rotations and the
        tooth friction follows the mixed-lubrication film along the path of contact. The
        run's ``meta["losses"]`` then holds the quasi-static breakdown by source and, at
        constant speed, the run's own power balance (:func:`cmsim.losses.power_balance`).
        Not with ``loads`` or ``friction_table``.
    record : sequence of str, optional
        The signals the run keeps (default: all of them): DOFs (``x_1b1``, ``theta_1G1``,
        …), forces (``F_1b1_x``, ``F_1b1_loa``, ``Fmesh_0``, ``Fmesh_total``), ``dte``,
        ``dte_um``. Only the columns they need are anti-alias filtered, so a dataset that
        keeps a few channels does not pay for filtering all of them; the dynamics are the
        same. A run with ``losses`` then has no power balance (it needs every DOF).
    progress : callable, optional
        Called as ``progress(done_s, total_s)`` (simulated seconds, warm-up included) as the
        integration advances, in chunks that do not change the result.
    on_start : callable, optional
        Called once as ``on_start(total_s)`` when every input is checked and the model is
        built, just before the integration starts (a front end shows its progress bar then,
        never before a bad-input error).
    cage_phases_rad : "random", sequence of float or None
        Initial cage angle of each bearing: drawn uniformly from ``seed`` (default — the
        relative phase of independent cages is arbitrary, and equal phases can cancel the
        ball-pass line in the DTE by symmetry), given explicitly, or ``None`` for all zero.

    Returns
    -------
    Run
    """
    setup = prepare_run(rig, op, duration_s, mesh=mesh, fs_hz=fs_hz, substeps=substeps,
                        scheme=scheme, slip=slip, seed=seed, warmup_s=warmup_s,
                        cage_phases_rad=cage_phases_rad, profile=profile, faults=faults,
                        loads=loads, friction_table=friction_table,
                        damping_table=damping_table, losses=losses, record=record)
    if on_start is not None:
        on_start(setup.warmup_s + setup.duration_s)
    compile_s = compile_kernels()       # after on_start: a front end announces the compile
    return integrate_prepared(setup, progress, compile_s)


def integrate_prepared(setup, progress=None, compile_s=0.0):
    """Integrate a :class:`RunSetup` alone and return its :class:`~cmsim.run.Run`
    (:func:`simulate`'s time loop; ``progress`` as there, ``compile_s`` for the meta)."""
    stats = {}
    try:
        states, diag, wall, n_warm, aa = _integrate_run(
            setup.model, setup.y0, setup.dt, setup.warmup_s, setup.fs_hz, setup.n_rec,
            setup.substeps, setup.scheme, stats, progress, setup.q_cols, setup.d_cols,
            setup.split)
    except IntegrationDiverged as exc:
        raise setup.diverged(exc) from None
    return finish_run(setup, states, diag, wall, n_warm, aa, stats, compile_s)


@dataclass(frozen=True)
class RunSetup:
    """A run checked and built, ready to integrate (:func:`prepare_run`): what
    :func:`simulate` decides before its time loop, and what :func:`finish_run` needs after.

    Attributes
    ----------
    rig, op : Rig, OperatingPoint
        The rig and the operating point (the profile's start speed and torque).
    model : DynamicModel
        The run's equations of motion.
    y0 : ndarray, shape (2n,)
        Start state ``[q0, 0]``: the quasi-static equilibrium, m and rad.
    start_method : str
        How ``q0`` was found (:func:`cmsim.dynamics.quasistatic.initial_state`).
    fs_hz, dt, warmup_s, duration_s : float
        Output sample rate (Hz), its interval (s), warm-up and recorded duration (s).
    n_rec : int
        Recorded samples.
    scheme, split, substeps, f_max
        The integration (:func:`cmsim.dynamics.schemes.choose_scheme`): scheme name, the
        exponential split or None, steps per output sample, highest mode (Hz).
    excitation : Excitation
        The run's fastest excitation.
    wanted, q_cols, d_cols
        The recorded signals' names and the state and force columns they need (None: all).
    kprof, profile
        The kernel's speed/torque table and the user's speed profile (None at constant
        speed).
    seed : int
        The run's seed.
    slip : RollingSlip
        The run's rolling slip.
    faults : tuple of Fault
        The run's faults.
    loss_inputs, loads, friction_table, model_mesh
        The losses' inputs (or None), the loads and friction table the model was built with.
    """

    rig: object
    op: object
    model: object
    y0: np.ndarray
    start_method: str
    fs_hz: float
    dt: float
    warmup_s: float
    duration_s: float
    n_rec: int
    scheme: str
    split: object
    substeps: int
    f_max: float
    excitation: object
    wanted: object
    q_cols: object
    d_cols: object
    kprof: object
    profile: object
    seed: int
    slip: object
    faults: tuple
    loss_inputs: object
    loads: object
    friction_table: object

    def diverged(self, exc):
        """The :class:`IntegrationDiverged` to raise for ``exc``: as it is, or saying that
        no static equilibrium was found when the run started from the nominal geometry."""
        if not self.start_method.endswith("(no equilibrium found)"):
            return exc
        op = self.op
        loads = (f"torque_nm = {op.torque_nm:g} N m" if self.rig.gears is not None
                 else f"radial_load_n = {op.radial_load_n:g} N")
        beyond = load_warnings(self.rig, op)
        if beyond:                                 # a smaller step would not help
            return IntegrationDiverged(f"no static equilibrium at {loads}, and the run from "
                                       f"the nominal geometry diverged: the rig cannot carry "
                                       f"it ({beyond[0]})")
        return IntegrationDiverged(f"no static equilibrium at {loads} (the rig may not carry "
                                   f"it), and the run from the nominal geometry diverged: "
                                   f"{exc}")


def prepare_run(rig, op, duration_s=SAMPLING.duration_s, *, mesh=None, fs_hz=SAMPLING.fs_hz,
                substeps=SAMPLING.substeps, scheme="auto", slip=None, seed=SAMPLING.seed,
                warmup_s=SAMPLING.warmup_s, cage_phases_rad="random", profile=None,
                faults=(), loads=None, friction_table=None, damping_table=None, losses=None,
                record=None):
    """Check a run's inputs and build it, up to its time loop (:func:`simulate`'s
    parameters, which it documents); returns a :class:`RunSetup`."""
    check_choice("scheme", scheme, ("auto",) + tuple(SCHEMES))
    duration_s = RANGES["duration_s"].check("duration_s", duration_s)
    fs_hz = RANGES["fs_hz"].check("fs_hz", fs_hz)
    warmup_s = RANGES["warmup_s"].check("warmup_s", warmup_s)
    if substeps is not None:
        substeps = RANGES["substeps"].check("substeps", substeps)
    if seed is not None:
        seed = RANGES["seed"].check("seed", seed)
    else:
        seed = int(np.random.SeedSequence().entropy % (2 ** 31))
    slip = NO_SLIP if slip is None else slip
    if not isinstance(slip, RollingSlip):
        raise ParameterError(f"slip must be a RollingSlip (cmsim.faults), got "
                             f"{type(slip).__name__}", param="slip")
    rng = np.random.default_rng(seed)
    if isinstance(cage_phases_rad, str):
        if cage_phases_rad != "random":
            raise ParameterError(f"cage_phases_rad must be 'random', None or one angle per "
                                 f"bearing, got {cage_phases_rad!r}")
        cage_phases_rad = rng.uniform(0.0, 2.0 * math.pi, len(rig.bearings))
    check_memory(duration_s, fs_hz, rig)
    faults = check_faults(rig, faults)
    slip = slip_from_faults(faults) or slip
    speed_factor, torque_factor = operating_modulation(faults, op, rig)
    kprof = None
    if profile is not None or speed_factor is not None or torque_factor is not None:
        if profile is None:
            profile = SpeedProfile((0.0,), (op.speed_rpm,))
        check_type("profile", profile, SpeedProfile)
        op = replace(op, speed_rpm=profile.initial_rpm,
                     torque_nm=op.torque_nm if profile.torques_nm is None
                     else profile.torques_nm[0])
        kprof = kernel_profile(profile, op.torque_nm, warmup_s + duration_s + 0.1,
                               PROFILE_STEP_S, speed_factor=speed_factor,
                               torque_factor=torque_factor)
    excitation = fastest_excitation(rig, op, 1.0 if kprof is None else
                                    float(np.max(kprof.table[:, PR_OMEGA])) / op.omega_rad_s)
    if substeps is not None:
        substeps = integration_substeps(fs_hz, excitation, substeps=substeps)
    loss_inputs = None
    if losses is not None and losses is not False:
        if loads is not None or friction_table is not None:
            raise ParameterError("losses sets the run's loads and friction table; give either "
                                 "losses or loads/friction_table", param="losses")
        # the losses read the tables of the rig as given (not worn by faults)
        contact = resolve_mesh(rig, mesh, op.torque_nm)
        loss_inputs = run_losses(rig, op, contact[0],
                                 LossSettings() if losses is True else losses)
        loads, friction_table = loss_inputs.loads, loss_inputs.friction_table
    else:
        contact = resolve_mesh(rig_with_faults(rig, faults), mesh, op.torque_nm)
    model = build_model(rig, op, contact, slip=slip, duration_s=warmup_s + duration_s,
                        seed=int(rng.integers(2 ** 31)), cage_phases_rad=cage_phases_rad,
                        profile=kprof, faults=faults, loads=loads,
                        friction_table=friction_table, damping_table=damping_table)
    n = model.n_dof
    wanted, q_cols, d_cols = _recorded(model, record)
    q0, start_method = initial_state(model, 0.0)
    y0 = np.concatenate([q0, np.zeros(n)])
    dt = 1.0 / fs_hz
    n_rec = int(round(duration_s * fs_hz))
    if n_rec < 2:
        raise ParameterError(f"duration_s = {duration_s:g} s gives fewer than 2 samples at "
                             f"fs_hz = {fs_hz:g}")
    scheme, split, substeps, f_max = choose_scheme(model, q0, fs_hz, excitation, scheme,
                                                   substeps)
    return RunSetup(rig, op, model, y0, start_method, fs_hz, dt, warmup_s, duration_s, n_rec,
                    scheme, split, int(substeps), f_max, excitation, wanted, q_cols, d_cols,
                    kprof, profile, int(seed), slip, faults, loss_inputs, loads, friction_table)


def finish_run(setup, states, diag, wall, n_warm, aa, stats, compile_s=0.0):
    """The :class:`~cmsim.run.Run` of an integrated :class:`RunSetup`: its named signals
    and meta from the recorded ``states`` (n_rec, n) and forces ``diag`` (n_rec, n_diag),
    the integration's wall time ``wall`` (s), warm-up samples ``n_warm``, anti-alias filter
    ``aa`` (or None), the hybrid solver's ``stats`` and the kernels' ``compile_s``."""
    rig, op, model, fs_hz, dt, n_rec = (setup.rig, setup.op, setup.model, setup.fs_hz,
                                        setup.dt, setup.n_rec)
    scheme, split, substeps, f_max = setup.scheme, setup.split, setup.substeps, setup.f_max
    excitation, wanted, kprof, profile = (setup.excitation, setup.wanted, setup.kprof,
                                          setup.profile)
    seed, slip, faults, loss_inputs = setup.seed, setup.slip, setup.faults, setup.loss_inputs
    loads, friction_table = setup.loads, setup.friction_table
    q0 = setup.y0[:model.n_dof]
    start_method = setup.start_method
    t = (n_warm + np.arange(n_rec)) * dt
    signals = _signals(model, t, states, diag, kprof, wanted)
    if wanted is not None:
        signals = {k: v for k, v in signals.items() if k in wanted}
    meta = {
        "cmsim_version": cmsim.__version__,
        "rig": rig.to_dict(),
        "operating_point": {"speed_rpm": op.speed_rpm, "torque_nm": op.torque_nm,
                            "radial_load_n": op.radial_load_n,
                            "radial_load_angle_rad": op.radial_load_angle_rad},
        "fs_hz": fs_hz, "substeps": int(substeps), "scheme": scheme,
        "integration_fs_hz": fs_hz * substeps, "highest_mode_hz": f_max,
        "exact_linear_dofs": [] if split is None else [model.dof_names[d] for d in split.dofs],
        "fastest_excitation": {"name": excitation.name, "hz": excitation.hz},
        "anti_alias": None if aa is None else aa.to_dict(), "warmup_s": n_warm / fs_hz,
        "duration_s": n_rec / fs_hz, "seed": int(seed),
        "cage_phases_rad": [float(x) for x in model.cage_phases_rad],
        "slip": {"cage_speed_rms": slip.cage_speed_rms, "ball_rms_rad": slip.ball_rms_rad,
                 "correlation_s": slip.correlation_s},
        "mesh": None if rig.gears is None else ("hybrid" if model.mesh_model is not None
                                                 else "table"),
        "mesh_table": None if model.mesh_table is None else {
            "method": model.mesh_table.method, "torque_nm": model.mesh_table.torque_nm,
            "mean_mesh_stiffness_n_per_m": model.mesh_table.mean_mesh_stiffness(rig.gears)},
        **({"hybrid_solves": stats["hybrid_solves"],
            "hybrid_unconverged": stats["hybrid_unconverged"]} if model.mesh_model is not None
           else {}),
        "speed_profile": None if profile is None else profile.to_dict(),
        "faults": [dict(f.to_dict(), label=f.label) for f in faults],
        "fault_frequencies": fault_frequencies(rig, op, faults) if faults else {},
        "sim_s": (n_warm + n_rec) / fs_hz, "wall_s": wall, "compile_s": compile_s,
        "realtime_factor": (n_warm + n_rec) / fs_hz / wall if wall > 0 else math.inf,
        "dof_names": list(model.dof_names),
        "initial_state": q0.tolist(), "initial_state_method": start_method,
    }
    run = Run(t, signals, meta)
    if wanted is not None:
        run = run.with_meta(recorded=sorted(wanted))
    if loss_inputs is not None:
        info = loss_inputs.to_dict()
        info["balance"] = None if kprof is not None or wanted is not None else power_balance(
            run, loads, friction_table, model.mesh_table).to_dict()
        run = run.with_meta(losses=info)
    return run


def _signals(model, t, states, diag, kprof=None, wanted=None):
    """The run's named signals from its states and output forces; with ``wanted`` (a set of
    names) only those are formed (a dataset record keeps a few)."""
    rig = model.rig

    def keep(name):
        return wanted is None or name in wanted

    sig = {}
    tau = t
    if kprof is not None and any(keep(name) for name in model.dof_names
                                 if name.startswith("theta")):
        # equivalent time of the nominal rotation, Θ(t)/Ω_ref (as the kernels use it)
        grid = kprof.t0_s + kprof.dt_s * np.arange(kprof.table.shape[0])
        tau = np.interp(t, grid, kprof.table[:, PR_THETA]) / model.op.omega_rad_s
    for i, name in enumerate(model.dof_names):
        if not keep(name):
            continue
        value = states[:, i]
        if name.startswith("theta"):
            value = value + model.omega[i] * tau
        sig[name] = value
    force_col = {name: j for j, name in enumerate(model.output_force_names)}
    for name, j in force_col.items():
        if keep(name):
            sig[name] = diag[:, j].copy()
    for bname in rig.bearing_names:
        loa, oloa = f"F_{bname}_loa", f"F_{bname}_oloa"
        if not (keep(loa) or keep(oloa)):
            continue
        e = model.loa_direction(0 if bname.startswith("1") else 1)
        fx, fy = diag[:, force_col[f"F_{bname}_x"]], diag[:, force_col[f"F_{bname}_y"]]
        if keep(loa):
            sig[loa] = fx * e[0] + fy * e[1]
        if keep(oloa):
            sig[oloa] = -fx * e[1] + fy * e[0]
    if rig.gears is not None:
        if keep("dte") or keep("dte_um"):
            ratio = rig.gears.driven.n_teeth / rig.gears.driving.n_teeth
            dte = (states[:, model.index("theta_1G1")]
                   - ratio * states[:, model.index("theta_2G1")])
            if keep("dte"):
                sig["dte"] = dte
            if keep("dte_um"):
                sig["dte_um"] = dte * rig.gears.driving.base_radius_m * 1e6
        if keep("Fmesh_total"):
            slots = [j for k, j in force_col.items() if k.startswith("Fmesh_")]
            sig["Fmesh_total"] = np.sum([diag[:, j] for j in slots], axis=0)
    return sig
