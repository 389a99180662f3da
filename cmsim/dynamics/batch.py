"""Many runs of one rig in one time loop: :func:`simulate_batch`.

A dataset's records share their rig and differ in operating point, faults and nuisances:
their right-hand sides are the same arithmetic on different numbers. :func:`simulate_batch`
integrates the runs that share a kernel layout (:func:`kernel_layout`) together, the run the
innermost array axis (:mod:`cmsim.dynamics._batch_kernels`), so numba vectorises across them
and the per-step work outside the arithmetic is paid once per batch.

A run's samples do not depend on its batch: it is bit-identical alone (a batch of one) or
among any others, in any place, and agrees with :func:`cmsim.dynamics.simulate` (the
single-run kernel, the reference) to rounding — a relative difference of order 1e-12 on a
1-s record, from the order of the Hertz ball sum. A run that diverges is reported as
:func:`simulate` reports it, and the others finish. Runs the batch kernel does not take (a
step of one sample, an exponential scheme) run alone through :func:`simulate`'s own path.
"""

from __future__ import annotations

import time

import numpy as np

from cmsim.dynamics._batch_kernels import BatchBuffers, LaneParams, integrate_batch_jit
from cmsim.dynamics._batch_mesh_kernels import BS_SIZE, R_SIZE
from cmsim.dynamics._mesh_kernels import MI_SLOTS
from cmsim.dynamics._rhs_kernels import KernelParams, Work, make_work
from cmsim.dynamics.integrator import SCHEMES
from cmsim.dynamics.model import teeth_with_own_tables
from cmsim.dynamics.simulation import compile_kernels, finish_run, integrate_prepared
from cmsim.dynamics.time_loop import (MAX_ROTATION_DEVIATION_RAD, _Decimator, decimation,
                                      diverged_at, max_displacement_m)
from cmsim.errors import IntegrationDiverged

__all__ = ["simulate_batch", "kernel_layout", "BATCH_CHUNK_STEPS"]

#: Integration steps per chunk of a batch: the states of B runs over a chunk stay within the
#: second-level cache for the anti-alias filter (B = 16: 10 MB), chunks do not change results.
BATCH_CHUNK_STEPS = 2 ** 11

#: KernelParams fields whose bytes (not only shapes) runs of one batch share: the switches
#: and indices the kernels branch on.
_SHARED_BYTES = ("m_int", "b_int", "spring_ends")


def kernel_layout(setup):
    """What the batch kernel needs runs to share, as a hashable key; None for a run it does
    not take (one step per sample, or an exponential scheme).

    Runs with the same key have the same DOFs, bearings, mesh slots, switches (faults,
    profile, slip, mesh mode) and table sizes, and the same steps, scheme and record length:
    they differ only in numbers.

    Parameters
    ----------
    setup : RunSetup
        A run from :func:`cmsim.dynamics.simulation.prepare_run`.

    Returns
    -------
    tuple or None
    """
    if setup.substeps < 2 or setup.split is not None or SCHEMES[setup.scheme].exponential:
        return None
    P = setup.model.kernel_params
    arrays = tuple((name, a.shape, a.dtype.str) for name, a in zip(P._fields, P))
    shared = tuple(getattr(P, name).tobytes() for name in _SHARED_BYTES)
    return (setup.scheme, setup.substeps, setup.n_rec, setup.fs_hz, setup.warmup_s,
            len(setup.model.output_force_names), setup.model.translational_mask.tobytes(),
            arrays, shared)


def _stack(arrays, axis=0):
    """The runs' arrays stacked along a new ``axis`` (C-contiguous)."""
    return np.ascontiguousarray(np.stack(arrays, axis=axis))


def _batch_arrays(models):
    """``(S, L, V)`` of :func:`~cmsim.dynamics._batch_kernels.integrate_batch_jit` for the runs'
    models: their KernelParams stacked run first (read-only, as every model's), the vectorised
    loops' values run last, their scratch stacked."""
    params = [m.kernel_params for m in models]
    S = KernelParams(*(_stack(field) for field in zip(*params))).frozen()
    L = LaneParams(*(_stack([getattr(P, f) for P in params], axis=-1)
                     for f in LaneParams._fields))
    works = [make_work(P) for P in params]
    last = ("g", "cage", "slip_cos", "slip_sin", "cage_slip")   # read across runs: run last
    V = Work(*(_stack(field, axis=-1 if name in last else 0)
               for name, field in zip(Work._fields, zip(*works))))
    return S, L, V


def _faulty_teeth(tk, te):
    """1.0 where a run's tooth has tables of its own
    (:func:`~cmsim.dynamics.model.teeth_with_own_tables`), else 0.0; ``tk``, ``te``
    (B, Z, m) the stacked per-tooth tables, the flags flat (B·Z,) as the batch kernel's slot
    loads read them (a tooth flagged 0 reads no table)."""
    return np.ascontiguousarray(teeth_with_own_tables(tk, te).astype(np.float64).reshape(-1))


def _block_columns(size, cols):
    """The columns (int64, sorted) the runs' filters read, of ``size``: each run's ``cols``
    (None: all of them)."""
    if any(c is None for c in cols):
        return np.arange(size, dtype=np.int64)
    return np.unique(np.concatenate([np.asarray(c, dtype=np.int64) for c in cols]
                                    + [np.zeros(0, dtype=np.int64)]))


def _integrate_batch(setups, chunk_steps=BATCH_CHUNK_STEPS):
    """Integrate runs of one kernel layout together; per run ``(q, forces, wall share, n_warm,
    anti-alias filter, stats)`` or the :class:`IntegrationDiverged` it raises."""
    first = setups[0]
    models = [s.model for s in setups]
    aa, n_warm = decimation(first.substeps, first.fs_hz, first.warmup_s)
    n_runs, dim = len(setups), first.y0.size
    n_diag = len(first.model.output_force_names)
    # the blocks hold the columns the runs' filters read (all runs', in order)
    y_cols = _block_columns(dim // 2, [s.q_cols for s in setups])
    d_cols = _block_columns(n_diag, [s.d_cols for s in setups])
    decs = [_Decimator(s.model, n_warm, s.n_rec, aa, s.q_cols, s.d_cols,
                       *(None if c is None else np.searchsorted(cols, c)
                         for c, cols in ((s.q_cols, y_cols), (s.d_cols, d_cols))))
            for s in setups]
    tab = SCHEMES[first.scheme]
    S, L, V = _batch_arrays(models)
    y0 = _stack([s.y0 for s in setups], axis=-1)
    B = BatchBuffers(np.zeros((tab.b.shape[0], dim, n_runs)), y0.copy(), np.empty_like(y0),
                     y0, np.zeros((n_diag, n_runs)),
                     *(np.zeros(n_runs) for _ in range(11)), np.zeros(dim),
                     np.zeros(dim // 2), np.zeros(n_diag), np.zeros((R_SIZE, n_runs)),
                     np.zeros((max(int(S.m_int[0, MI_SLOTS]), 1), BS_SIZE, n_runs)),
                     np.zeros(n_runs), np.zeros(n_runs, dtype=np.int64), np.zeros(n_runs),
                     _faulty_teeth(S.tk1, S.te1), _faulty_teeth(S.tk2, S.te2))
    max_disp = np.array([max_displacement_m(m) for m in models])
    status = np.full(n_runs, -1, dtype=np.int64)
    h = 1.0 / (first.fs_hz * first.substeps)
    n_out = decs[0].last + 1
    rows = min(chunk_steps + 1, n_out)
    out_y = np.empty((n_runs, rows, y_cols.size))
    out_d = np.empty((n_runs, rows, d_cols.size))
    mask = first.model.translational_mask
    m0, wall = 0, 0.0
    while m0 < n_out:
        # one sample of overlap: a block's last state starts the next block
        count = min(chunk_steps + 1, n_out - m0 + (1 if m0 else 0))
        start_at = m0 - 1 if m0 else 0
        t = time.perf_counter()
        integrate_batch_jit(0.0, h, count, 1, start_at, tab.a, tab.b, tab.c, S, L, V, B,
                            out_y, out_d, y_cols, d_cols, max_disp, MAX_ROTATION_DEVIATION_RAD,
                            mask, status)
        wall += time.perf_counter() - t
        skip = 1 if m0 else 0
        for l, dec in enumerate(decs):
            if status[l] < 0:
                dec.feed(m0, out_y[l, skip:count], out_d[l, skip:count])
        m0 = start_at + count
    out = []
    for l, (setup, dec) in enumerate(zip(setups, decs)):
        if status[l] >= 0:
            # (as the single-run path reports it: its kernel steps once per fast sample)
            out.append(setup.diverged(diverged_at(status[l] * h, max_disp[l], 1)))
            continue
        stats = {}
        if setup.model.mesh_model is not None:
            stats = {"hybrid_solves": int(V.hstat[l, 0]),
                     "hybrid_unconverged": int(V.hstat[l, 1])}
        out.append((dec.q_out, dec.d_out, wall / n_runs, n_warm, aa, stats))
    return out


def simulate_batch(setups, batch_size=None):
    """Integrate prepared runs, those of one kernel layout together; returns, per run in
    order, its :class:`~cmsim.run.Run` or the exception it raised
    (:class:`~cmsim.errors.IntegrationDiverged`).

    Parameters
    ----------
    setups : sequence of RunSetup
        Runs from :func:`cmsim.dynamics.simulation.prepare_run`.
    batch_size : int, optional
        Most runs integrated together (default: all of one layout).

    Returns
    -------
    list of Run or Exception
    """
    compile_s = compile_kernels()
    results = [None] * len(setups)
    groups = {}
    for i, setup in enumerate(setups):
        key = kernel_layout(setup)
        if key is None:
            results[i] = _alone(setup, compile_s)
        else:
            groups.setdefault(key, []).append(i)
    size = batch_size or max([len(g) for g in groups.values()] + [1])
    for members in groups.values():
        for j in range(0, len(members), size):
            part = members[j:j + size]
            done = _integrate_batch([setups[i] for i in part])
            for i, res in zip(part, done):
                results[i] = res if isinstance(res, Exception) else finish_run(
                    setups[i], *res[:5], res[5], compile_s)
    return results


def _alone(setup, compile_s):
    """A run the batch kernel does not take, through :func:`simulate`'s own path."""
    try:
        return integrate_prepared(setup, None, compile_s)
    except IntegrationDiverged as exc:
        return exc
