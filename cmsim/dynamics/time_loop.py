"""The time loop of a run: the fixed-step numba kernel driven in chunks, and the anti-alias
decimation fed from them. :func:`integrate` runs the kernel over a span of output samples in
blocks of :data:`CHUNK_STEPS` (one scratch state, bit-identical to a single call) and raises
:class:`~cmsim.errors.IntegrationDiverged` when a displacement, a rotation deviation beyond
:data:`MAX_ROTATION_DEVIATION_RAD` or a non-finite value appears; with more than one step per
output sample the recorded columns of the blocks pass through the run's
:class:`~cmsim.dynamics.decimation.AntiAliasFilter`, as an acquisition system does. What to
integrate, and how the recorded states become a :class:`~cmsim.run.Run`, stay in
:mod:`cmsim.dynamics.simulation`, which re-exports this module's public names.
"""

from __future__ import annotations

import functools
import math
import time

import numpy as np

from cmsim.dynamics._decimation_kernels import gather_columns_jit
from cmsim.dynamics._rhs_kernels import (integrate_jit, make_integrator_buffers, make_work,
                                         no_propagator)
from cmsim.dynamics.decimation import AntiAliasFilter
from cmsim.dynamics.integrator import SCHEMES
from cmsim.errors import IntegrationDiverged, check_choice

__all__ = ["integrate", "MAX_ROTATION_DEVIATION_RAD", "CHUNK_STEPS", "DECIMATION_CHUNK_STEPS"]

#: Integration steps per chunk (bounds the memory of the fast-rate states).
CHUNK_STEPS = 2 ** 16

#: Integration steps per chunk when decimating: a block small enough to be read back from
#: the cache by the anti-alias filter (chunks do not change the result).
DECIMATION_CHUNK_STEPS = 2 ** 13

#: A dynamic twist beyond this (rad) means the run has diverged; it also bounds the Taylor
#: rotation of the cage angle in the bearing kernel (error < 1e-10 below it).
MAX_ROTATION_DEVIATION_RAD = 0.5


def max_displacement_m(model):
    """The largest displacement of a translational DOF a run of ``model`` may reach before it
    counts as diverged, m (100 × the largest bearing clearance, at least 1 mm)."""
    return max(1e-3, 100 * max(abs(b.clearance_m) for b in model.rig.bearings))


def diverged_at(t, max_disp, substeps):
    """The :class:`IntegrationDiverged` of a run that diverged at time ``t`` (s)."""
    return IntegrationDiverged(
        f"the integration diverged at t = {t:.6g} s (a displacement exceeded {max_disp:g} m, "
        f"a rotation deviation {MAX_ROTATION_DEVIATION_RAD:g} rad, or a value became "
        f"non-finite); use a smaller step (substeps > {substeps} or a higher fs_hz) or check "
        f"the rig parameters")


class _Integrator:
    """The fixed-step kernel run in chunks with one scratch state (bit-identical to one call).

    ``chunks(y0, t0, h, n_out, substeps)`` yields ``(m0, states, diag)`` blocks of at most
    ``chunk_steps`` (default :data:`CHUNK_STEPS`) output samples; sample ``m0 + i`` is the
    state at ``t0 + (m0 + i)·substeps·h``. The last state of a block is the first of the next
    one. The blocks are views of one pair of buffers, valid until the next block is asked
    for (a consumer copies what it keeps): fresh arrays for every block would cost the page
    faults of tens of megabytes per run.
    """

    def __init__(self, model, scheme, progress=None, split=None):
        check_choice("scheme", scheme, tuple(SCHEMES))
        self.model = model
        self.tab = SCHEMES[scheme]
        # an exponential scheme integrates the split's chains in closed form and the rest
        # (its kernel arrays) with the tableau; a plain one everything with the tableau
        self.split = split if self.tab.exponential else None
        self.params = model.kernel_params if self.split is None else self.split.kernel_params
        self.progress = progress
        self.wall = 0.0
        self.max_disp = max_displacement_m(model)
        self.mask = model.translational_mask

    def chunks(self, y0, t0, h, n_out, substeps, chunk_steps=CHUNK_STEPS):
        model, tab = self.model, self.tab
        n_diag = len(model.output_force_names)
        buffers = make_integrator_buffers(tab.b, y0.size, n_diag)
        prop = (no_propagator(tab.b.shape[0]) if self.split is None
                else self.split.propagator(tab, h))
        # compile (or load from cache) outside the timed region, then start from fresh scratch
        integrate_jit(y0, t0, h, 1, 1, 0, tab.a, tab.b, tab.c, prop, self.params,
                      make_work(self.params), buffers, np.empty((1, y0.size)),
                      np.empty((1, n_diag)), self.max_disp, MAX_ROTATION_DEVIATION_RAD,
                      self.mask)
        self.work = make_work(self.params)
        y, m0 = y0, 0
        rows = min(chunk_steps + 1, n_out)
        states_buf = np.empty((rows, y0.size))
        diag_buf = np.empty((rows, n_diag))
        while m0 < n_out:
            # one sample of overlap: a block's last state starts the next block
            count = min(chunk_steps + 1, n_out - m0 + (1 if m0 else 0))
            states = states_buf[:count]
            diag = diag_buf[:count]
            first = m0 - 1 if m0 else 0
            start = time.perf_counter()
            status = integrate_jit(y, t0, h, count, substeps, first, tab.a, tab.b, tab.c, prop,
                                   self.params, self.work, buffers, states, diag,
                                   self.max_disp, MAX_ROTATION_DEVIATION_RAD, self.mask)
            self.wall += time.perf_counter() - start
            if status >= 0:
                raise diverged_at(t0 + (first + status) * substeps * h, self.max_disp, substeps)
            skip = 1 if m0 else 0
            yield m0, states[skip:], diag[skip:]
            y = states[-1].copy()
            m0 = first + count
            if self.progress is not None:
                self.progress(m0, n_out)

    def stats(self):
        """On-line contact solves of model A: ``hybrid_solves``, ``hybrid_unconverged``."""
        return {"hybrid_solves": int(self.work.hstat[0]),
                "hybrid_unconverged": int(self.work.hstat[1])}


def integrate(model, y0, t0, dt_out, n_out, substeps=1, scheme="ode3", stats=None,
              progress=None, split=None):
    """Run the fixed-step kernel; returns ``(states, diag, wall_s)``.

    Parameters
    ----------
    model : DynamicModel
    y0 : ndarray, shape (2n,)
        Initial ``[q, v]``.
    t0 : float
        Initial time, s.
    dt_out : float
        Output sample spacing, s.
    n_out : int
        Number of output samples (the first is ``y0``).
    substeps : int
        Integration steps per output sample.
    scheme : str
        Key of :data:`cmsim.dynamics.integrator.SCHEMES`.
    stats : dict, optional
        Receives ``hybrid_solves`` and ``hybrid_unconverged`` (on-line contact solves of
        model A, and those that hit the iteration limit and used their last iterate).
    progress : callable, optional
        Called as ``progress(done, total)`` (output samples) after each chunk of
        :data:`CHUNK_STEPS` samples; chunks do not change the result.
    split : LinearSplit, optional
        The chains an exponential ``scheme`` integrates in closed form
        (:func:`cmsim.dynamics.exponential.choose_scheme`; without it, an exponential
        scheme runs as its plain tableau).

    Returns
    -------
    states : ndarray, shape (n_out, 2n)
    diag : ndarray, shape (n_out, n_diag)
    wall_s : float
        Wall time of the integration proper (compilation excluded), s.
    """
    runner = _Integrator(model, scheme, progress, split)
    states = np.empty((n_out, y0.size))
    diag = np.empty((n_out, len(model.output_force_names)))
    for m0, st, dg in runner.chunks(np.asarray(y0, dtype=float), t0, dt_out / substeps, n_out,
                                    substeps):
        states[m0:m0 + len(st)] = st
        diag[m0:m0 + len(dg)] = dg
    if stats is not None:
        stats.update(runner.stats())
    return states, diag, runner.wall


class RecordedColumns:
    """A table of ``n_rows`` samples by ``n_cols`` columns of which only ``cols`` are held
    (the rest were never filtered): ``x[rows, j]`` reads column j, NaN where it is not
    held. A record keeps its recorded columns only (3 of the gear rig's 19 displacements
    for an accelerometer and the DTE), not a full-width array."""

    def __init__(self, n_rows, n_cols, cols):
        self.shape = (int(n_rows), int(n_cols))
        self._where = {int(c): k for k, c in enumerate(cols)}
        self.data = np.full((self.shape[0], len(self._where)), np.nan, order="F")

    def __getitem__(self, key):
        rows, j = key
        k = self._where.get(int(j))
        col = self.data[:, k] if k is not None else np.full(self.shape[0], np.nan)
        return col[rows]


class _Decimator:
    """One run's anti-alias decimation, fed the integrator's blocks in order.

    ``feed(i0, states, diag)`` takes a block of fast samples (sample ``i0`` first, as
    :meth:`_Integrator.chunks` yields them) and filters the recorded columns into the output
    instants ``n_warm .. n_warm + n_rec − 1``; :attr:`q_out` and :attr:`d_out` hold them
    (:class:`RecordedColumns`: NaN in the columns not recorded). A batch of runs
    (:mod:`cmsim.dynamics.batch`) feeds one per run from its lane of the batch's blocks,
    which hold only the recorded columns:
    ``block_q``, ``block_d`` say where in a block's states and forces the recorded ones
    are (default: the blocks hold every column).
    """

    def __init__(self, model, n_warm, n_rec, aa, q_cols=None, d_cols=None, block_q=None,
                 block_d=None):
        k, hl = aa.factor, aa.half_length
        n = model.n_dof
        self.aa, self.k, self.n_rec = aa, k, n_rec
        self.first = n_warm * k - hl                  # first fast sample the filter reads
        self.last = (n_warm + n_rec - 1) * k + hl     # last one
        n_forces = len(model.output_force_names)
        self.qc = np.arange(n) if q_cols is None else np.asarray(q_cols, dtype=int)
        self.dc = np.arange(n_forces) if d_cols is None else np.asarray(d_cols, dtype=int)
        self.q_out = RecordedColumns(n_rec, n, self.qc)
        self.d_out = RecordedColumns(n_rec, n_forces, self.dc)
        self.bq = self.qc if block_q is None else np.asarray(block_q, dtype=int)
        self.bd = self.dc if block_d is None else np.asarray(block_d, dtype=int)
        self.m0 = 0                                   # next output sample to fill
        self.n_tail = 0                               # fast samples not yet consumed
        # the filtered columns side by side, in one buffer for the run: the tail a block
        # leaves, then the next block
        self.width = self.qc.size + self.dc.size
        self.buf = np.zeros((2 * hl + k + DECIMATION_CHUNK_STEPS + 1, self.width))

    def feed(self, i0, st, dg):
        """Filter the block ``st``, ``dg`` (fast samples ``i0 ..``) into the outputs."""
        if i0 + len(st) <= self.first:                # warm-up the filter never reads
            return
        lo = max(self.first - i0, 0)
        n_tail, k, width = self.n_tail, self.k, self.width
        n_rows = n_tail + len(st) - lo
        if n_rows > self.buf.shape[0]:
            self.buf = np.vstack([self.buf[:n_tail], np.zeros((n_rows - n_tail, width))])
        buf, qc, dc = self.buf, self.qc, self.dc
        gather_columns_jit(st, dg, lo, self.bq, self.bd, buf, n_tail)
        # output m sits at fast index (n_warm + m)·k; its window starts at that − hl
        out = self.aa.apply(buf[:n_rows])
        take = min(len(out), self.n_rec - self.m0)
        if take > 0:
            m0 = self.m0
            self.q_out.data[m0:m0 + take] = out[:take, :qc.size]
            self.d_out.data[m0:m0 + take] = out[:take, qc.size:qc.size + dc.size]
            self.m0 += take
        self.n_tail = n_rows - take * k
        buf[:self.n_tail] = buf[take * k:n_rows].copy()


def _integrate_decimated(model, y0, dt_out, n_warm, n_rec, aa, scheme, stats, progress=None,
                         q_cols=None, d_cols=None, split=None):
    """Integrate at ``aa.factor`` steps per output sample in chunks and decimate through
    ``aa``; returns the recorded ``(q, forces, wall_s)`` at the output instants
    ``n_warm .. n_warm + n_rec − 1``. With ``q_cols``/``d_cols`` only those state and force
    columns are filtered (the others are NaN)."""
    dec = _Decimator(model, n_warm, n_rec, aa, q_cols, d_cols)
    runner = _Integrator(model, scheme, progress, split)
    for i0, st, dg in runner.chunks(y0, 0.0, dt_out / aa.factor, dec.last + 1, 1,
                                    DECIMATION_CHUNK_STEPS):
        dec.feed(i0, st, dg)
    stats.update(runner.stats())
    return dec.q_out, dec.d_out, runner.wall


@functools.lru_cache(maxsize=16)
def decimation(substeps, fs_hz, warmup_s):
    """``(anti-alias filter, warm-up samples)`` of a run recorded at ``fs_hz`` (Hz) after
    ``warmup_s`` (s) and integrated at ``substeps`` > 1 steps per sample: the centred filter
    needs half its length of integration before the first sample (designed once per rate)."""
    aa = AntiAliasFilter(int(substeps), fs_hz * substeps)
    return aa, max(int(round(warmup_s * fs_hz)), math.ceil(aa.half_length / substeps))


def _integrate_run(model, y0, dt, warmup_s, fs_hz, n_rec, substeps, scheme, stats, progress,
                   q_cols, d_cols, split=None):
    """The run's integration: ``(states, diag, wall_s, n_warm, anti_alias)`` of the recorded
    samples, directly at ``fs_hz`` (one step per sample) or through the anti-alias filter."""
    if substeps == 1:
        n_warm = int(round(warmup_s * fs_hz))
        report = None if progress is None else (lambda done, total: progress(done * dt,
                                                                             total * dt))
        states, diag, wall = integrate(model, y0, 0.0, dt, n_warm + n_rec, 1, scheme, stats,
                                       report, split)
        return states[n_warm:, :model.n_dof], diag[n_warm:], wall, n_warm, None
    aa, n_warm = decimation(substeps, fs_hz, warmup_s)
    report = None if progress is None else (lambda done, total: progress(
        done * dt / substeps, total * dt / substeps))
    states, diag, wall = _integrate_decimated(model, y0, dt, n_warm, n_rec, aa, scheme, stats,
                                              report, q_cols, d_cols, split)
    return states, diag, wall, n_warm, aa
