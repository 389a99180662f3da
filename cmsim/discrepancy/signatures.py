"""A machine's signature library: each cause of the catalogue, over a grid of its sizes, laid on
the machine's own healthy baseline as the model says it changes it.

For every cause that applies to the machine's rig, on every component it may sit on, the
cause extends the machine's nominal setup (:class:`~cmsim.discrepancy.causes.ModelSetup`) at
:data:`N_SIZES` values log-spaced over its bounds (:func:`value_grid`); the model is run with
the cause and without it on the same seed (:func:`cmsim.machine.model_force`), and the
difference is laid on :data:`LIBRARY_SEGMENTS` of the baseline's segments
(:func:`cmsim.machine.change.apply_change`: lines the healthy model makes changed on the
baseline's own lines, the rest of the change through the calibrated path; a speed fluctuation
warps the baseline; a transfer path refilters it; noise and background add to it). The
features of those segments (:func:`cmsim.features.relative_features`, plus ``level_db``
when the machine's unit is known) are averaged: one row of the library per value.

**Nuisances profiled with each cause** (:data:`BEARING_VARIANTS`). How a bearing defect shows
depends on how many rollers carry the load: with a clearance, the load zone is narrow and
an inner-race or ball defect hits hard once per revolution (kurtosis high, strong shaft-rate
sidebands); in line contact or under a preload every roller is loaded and the defect hits at
every pass (a family, little kurtosis). A machine's clearance is rarely documented, so a
bearing defect's entries are computed for the documented clearance and for each variant,
each change relative to the healthy model *of that variant*: a comparison takes the variant
that fits the record best (a profile likelihood), so a family that stands out over the
baseline is not vetoed by a statistic the model makes differently under another load zone.
Where a change rings the structure, the path's gain there is profiled too
(:data:`PATH_GAINS`); for a rotating force (unbalance, misalignment), the depth of the load
modulation it swings against the line it makes (:data:`SHAFT_MODULATIONS`: the line reaches
the sensor through a gain at the shaft orders no healthy baseline pins; these variants are
computed after every other entry, which keeps its noise draws).
A moved transfer path (:attr:`~cmsim.discrepancy.causes.Cause.moves_path`) is profiled the
same way over where the structure's response is read: the calibrated path, the baseline's
lines moving with it; or the baseline's broadband floor, its lines held (the floor tells
nothing of how the lines reach the sensor) — :class:`~cmsim.machine.change.Change`.

**The realisation spread.** A record of a healthy machine differs from its baseline by more
than the segment-to-segment spread within one record: the cages' phases and the slip of a
run are the same over its segments and differ from run to run. The library measures it as
the model's own, twice, and keeps the larger: the healthy model with :data:`REALISATIONS`
other seeds laid on the baseline as a change, and those runs through the machine's twin
(path and background, :meth:`~cmsim.machine.Machine.sensor_signal`) — the change operator
keeps a baseline's envelope lines where two healthy runs differ only by their cages'
phases, which on a gear rig's four bearings move them by 2-5 dB from run to run. The twin's
runs are read twice: with their background drawn afresh (the **realisation** spread, which
the χ² reads: a fresh draw of the background lines' phases swings an envelope's shaft-rate
line by up to 20 dB — the sidebands' phases decide whether the mesh is amplitude- or
phase-modulated — and so does any change the library predicts less well than the phases
it was made with), and with the machine's own lines, their noise afresh (the **run
spread**, which the gate of a family that stands out reads: the baseline's segments hold
such a line within 0.4-0.5 dB on the angle-domain generator's gear machines, where the
realisation spread put 10-13 dB under it).

Layering: builds on :mod:`cmsim.machine` (the change operator, the library's container) and
the cause catalogue (:mod:`cmsim.discrepancy.causes`).
"""

from __future__ import annotations

import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numpy as np

from cmsim.datasets.pool import check_workers, process_pool
from cmsim.discrepancy.causes import ModelSetup, applicable_causes
from cmsim.discrepancy.evaluator import _shaft_forces
from cmsim.errors import IntegrationDiverged, ParameterError
from cmsim.faults import SpeedFluctuation
from cmsim.frequencies import rig_frequencies
from cmsim.machine import model_force
from cmsim.machine.calibration import feature_rows
from cmsim.machine.change import Change, apply_change
from cmsim.machine.library import SignatureEntry, SignatureLibrary
from cmsim.run import signal_info

__all__ = ["BAND_FAMILIES", "build_library", "value_grid", "predicted_rows", "change_of",
           "parse_variant",
           "simulate_entry", "operating_shift",
           "N_SIZES", "LIBRARY_SEGMENTS", "REALISATIONS", "BEARING_VARIANTS", "GRIDS", "DENSER",
           "PATH_GAINS", "SHAFT_MODULATIONS"]

#: Values of each cause's parameter in the library (log-spaced over its bounds).
N_SIZES = 8

#: A machine's library and the records judged against it read each bearing's defect
#: families in every band of the fixed bank too (:func:`cmsim.features.band_family_columns`).
BAND_FAMILIES = True

#: Baseline segments each prediction is averaged over (spread over the baseline).
LIBRARY_SEGMENTS = 8

#: Other healthy runs of the model that measure the realisation spread.
REALISATIONS = 4

#: Factors on the calibrated path's gain for a cause whose change is impacts ringing the
#: structure (:attr:`~cmsim.discrepancy.causes.Cause.rings_structure`): where its impacts
#: ring, a healthy baseline rarely pins the path (a bearing rig's path gain is a prior
#: there), and the gain and the defect's size trade off — the model's outer-race spall on
#: CWRU's drive end lifted its BPFO envelope line 24 dB over the baseline's at the smallest
#: size of the grid (0.03 mm) where the 0.18-mm record lifts it 22 dB.
PATH_GAINS = (0.1, 0.3, 1.0, 3.0)

#: Depths of the load modulation a cause's rotating forces swing, relative to their share,
#: of the variants besides the documented 1 (:attr:`~cmsim.discrepancy.causes.Cause.rotates`,
#: ``shaft_modulation`` of :class:`~cmsim.discrepancy.model_setup.ModelSetup`): the line a
#: rotating force makes reaches the sensor through a gain at the shaft orders that a healthy
#: baseline does not pin, while the load it swings modulates the baseline's own lines (a
#: ratio), so the two trade off; the value of every variant sizes the force on its line. The
#: angle-domain generator's unbalance of severity 1.16 lifts its 1× line as far as the model's
#: unbalance of share 0.046 does, with mesh sidebands of 8.7 % where that share swings 2.3 %.
SHAFT_MODULATIONS = (0.3, 3.0)

#: Clearances of the bearing-defect variants besides the documented one, m: line contact
#: (every roller under a load within its contact stiffness) and a light preload (every
#: roller loaded): the load zone's extent and the number of rollers loaded.
BEARING_VARIANTS = (0.0, -5e-6)

#: Parameter ranges of the library where they differ from a cause's fitted bounds: the
#: noise and background causes scale the machine's own background (below 1.3 times it, the
#: baseline's spread covers it). A two-sided cause (the transfer path's factor) takes as many
#: values on each side of 1 and 1 itself, the baseline, which the interpolation between the
#: grid's points then passes through.
GRIDS = {"noise": (0.13, 10.0), "transfer_path": (0.3, 3.0)}

#: Causes whose grid is denser than the others' (a factor on the values): a structure's
#: resonance that moves by 15 % crosses a band of the spectrum's shape, and the features
#: interpolated between the grid's points (log-linear) miss it between steps of 30 %. At 9
#: values over 0.3-3 the angle-domain generator's moved paths (±17-37 %) were named 1 of 8
#: times; at 17, 2 of 8 (2026-11-30). A moved path needs no simulation: each value costs the
#: features of the baseline's segments refiltered (about 0.3 s).
DENSER = {"transfer_path": 2}


def value_grid(cause, n=N_SIZES):
    """(parameter name, values) of a cause's entries: ``n`` values log-spaced over the bounds
    of its first parameter (or :data:`GRIDS`; a two-sided range split in two halves).

    Parameters
    ----------
    cause : Cause
    n : int
        Values.

    Returns
    -------
    (str, tuple of float)

    Examples
    --------
    >>> from cmsim.discrepancy.causes import CAUSES
    >>> name, v = value_grid(CAUSES["bearing_inner_race"](), 3)
    >>> name, [round(x * 1e3, 2) for x in v]
    ('size_m', [0.03, 0.3, 3.0])
    """
    p = cause.params[0]
    span = GRIDS.get(cause.name, p.bounds)
    if p.log_scale and span[0] < 1.0 < span[1] and cause.name in GRIDS:
        half = n // 2 + 1                                          # 1 itself, once
        values = np.concatenate([np.geomspace(span[0], 1.0, half),
                                 np.geomspace(1.0, span[1], half)[1:]])
    elif p.log_scale:
        values = np.geomspace(span[0], span[1], n)
    else:
        values = np.linspace(span[0], span[1], n)
    return p.name, tuple(float(v) for v in values)


def _nanmean(rows):
    with warnings.catch_warnings():               # a column NaN in every row stays NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(rows, axis=0)


def change_of(setup, healthy, force_of, fs_hz, seed, *, threads=1):
    """The :class:`~cmsim.machine.change.Change` a setup makes relative to a healthy one.

    Parameters
    ----------
    setup, healthy : ModelSetup
        The setup with the cause and the healthy setup it extends.
    force_of : callable
        ``force_of(setup)`` → (force with edges, edge, n) of the machine's sensor bearing
        (:func:`cmsim.machine.model_force`), or None if it diverged.
    fs_hz : float
        Sample rate, Hz.
    seed : int
        Seed of the shaft forces' phase.
    threads : int
        Threads the healthy and the changed run go side by side on (the integrator releases
        the GIL): 2 where nothing else uses the other core (a comparison's refining run), 1
        in a pool's worker.

    Returns
    -------
    Change or None
        None when a run diverged.
    """
    machine = healthy.machine
    freqs = rig_frequencies(setup.rig, setup.op)
    fr = freqs.bearing(signal_info(machine.model_signal).component).shaft_hz
    fluct = sum(f.relative_amplitude for f in setup.faults if isinstance(f, SpeedFluctuation))
    dyn = replace(setup, faults=tuple(f for f in setup.faults
                                      if not isinstance(f, SpeedFluctuation)))
    force = base = None
    edge, rotating = 0, ()
    moved = dyn.dynamics_key() != healthy.dynamics_key()
    if moved or setup.shaft_forces:
        runs = _side_by_side(force_of, (healthy, dyn) if moved else (healthy,), threads)
        h, c = runs[0], runs[-1]
        if h is None or c is None:
            return None
        base, edge = h[0], h[1]
        force = c[0]
        if setup.shaft_forces:
            force, rotating = _shaft_forces(force, fs_hz, fr, setup.shaft_forces, seed,
                                            setup.shaft_modulation)
    return Change(force=force, healthy=base, edge=edge, rotating=tuple(rotating), shaft_hz=fr,
                  input_hz=setup.op.speed_rpm / 60.0, frequency_factor=setup.frequency_factor,
                  structure=setup.structure, lines_follow_path=setup.lines_follow_path,
                  white_noise=setup.white_noise,
                  background_gain=max(1.0, setup.background_gain * setup.background_level),
                  speed_fluctuation=fluct, pin_hz=_mesh_harmonics(freqs, fs_hz))


def _side_by_side(force_of, setups, threads):
    """``force_of`` of each setup, on up to ``threads`` threads."""
    if threads < 2 or len(setups) < 2:
        return [force_of(s) for s in setups]
    with ThreadPoolExecutor(min(threads, len(setups))) as pool:
        return list(pool.map(force_of, setups))


def _mesh_harmonics(freqs, fs_hz):
    """The mesh harmonics below the Nyquist frequency (none on a bearing rig), Hz."""
    if not freqs.gmf_hz:
        return ()
    return tuple(k * freqs.gmf_hz for k in range(1, int(0.5 * fs_hz / freqs.gmf_hz) + 1))


class _Library:
    """Forces and predicted features of one machine (in this process or a worker)."""

    def __init__(self, machine, segs, seed):
        self.machine = machine
        self.segs = segs
        self.seed = seed
        self.fs = machine.fs_hz
        self.freqs = rig_frequencies(machine.rig, machine.op)
        self.bearings = list(machine.rig.bearing_names)
        self.forces = {}

    def force(self, setup, seed=None):
        seed = self.seed if seed is None else seed
        key = (setup.dynamics_key(), seed)
        if key not in self.forces:
            k, n = self.segs.shape
            try:
                self.forces[key] = model_force(setup.rig, setup.op, self.machine.model_signal,
                                               self.fs, k * n / self.fs, seed,
                                               faults=setup.faults,
                                               mixed_friction=setup.mixed_friction)
            except (IntegrationDiverged, ParameterError):
                self.forces[key] = None
        return self.forces[key]

    def features(self, change, rng_key, signals=False):
        """Mean features of the baseline's segments with ``change`` laid on them (and the
        segments, with ``signals``)."""
        y = apply_change(self.machine, self.segs, change, np.random.default_rng(rng_key))
        names, rows = feature_rows(y, self.fs, self.freqs, self.bearings,
                                   self.machine.unit_scale, bands=BAND_FAMILIES)
        return (names, _nanmean(rows), y) if signals else (names, _nanmean(rows))

    def entry(self, job):
        """(names, {path gain: rows}) of one library entry: per path gain, the mean features
        at each value (None where a run diverged)."""
        cause, comp, healthy, values, gains, index = job
        names, out = None, {g: [] for g in gains}
        for j, v in enumerate(values):
            try:
                setup = cause.extend(healthy, {**cause.start(healthy.rig),
                                               cause.params[0].name: v}, comp)
                change = change_of(setup, healthy, self.force, self.fs, self.seed)
            except ParameterError:
                change = None
            for i, g in enumerate(gains):
                if change is None:
                    out[g].append(None)
                    continue
                names, mean = self.features(replace(change, path_gain=g),
                                            [self.seed, index, j, i])
                out[g].append(mean)
        return names, out

    def realisation(self, job):
        """(names, mean features of the baseline with another healthy run of the model laid
        on it, mean features of that run through the twin — its background drawn afresh,
        and with the machine's own lines)."""
        healthy, seed, index = job
        h, c = self.force(healthy), self.force(healthy, seed)
        if h is None or c is None:
            return None, None, None, None
        names, laid = self.features(Change(force=c[0], healthy=h[0], edge=h[1],
                                           pin_hz=_mesh_harmonics(self.freqs, self.fs)),
                                    [self.seed, 999_983, index])
        k, n = self.segs.shape
        twins = []
        for line_seed in (None, self.seed):
            twin = self.machine.sensor_signal(c[0], c[1], k * n, seed, line_seed=line_seed)
            got, rows = feature_rows(twin.reshape(k, n), self.fs, self.freqs, self.bearings,
                                     self.machine.unit_scale, bands=BAND_FAMILIES)
            twins.append(_nanmean(rows) if got == names else None)
        return names, laid, *twins


#: The library of a worker process (:func:`_adopt`).
_WORKER = None


def _adopt(lib):
    global _WORKER
    _WORKER = lib


def _work(kind, job):
    return getattr(_WORKER, kind)(job)


def _variant_label(label, gain):
    """A variant's label with its path gain: ``"line contact"``, ``"documented; path x0.3"``."""
    return label if gain == 1.0 else f"{label}; path x{gain:g}"


def parse_variant(label):
    """(variant label, path gain) of a library entry's variant (:func:`_variant_label`'s
    output): ``"documented; path x0.3"`` → ``("documented", 0.3)``."""
    if "; path x" in label:
        base, g = label.split("; path x")
        return base, float(g)
    return label, 1.0


def _variants(cause, nominal):
    """(label, healthy setup) of each nuisance variant a cause's entries are computed for."""
    out = [("documented", nominal)]
    if cause.moves_path:
        out.append(("broadband's structure", replace(nominal, structure="floor",
                                                     lines_follow_path=False)))
    if cause.kind == "bearing":
        documented = {b.clearance_m for s in nominal.rig.shafts
                      for b in (s.bearing_1, s.bearing_2)}
        for c in BEARING_VARIANTS:
            if documented != {c}:
                label = ("line contact" if c == 0 else
                         f"{abs(c) * 1e6:g} um {'clearance' if c > 0 else 'preload'}")
                out.append((label, replace(nominal, rig=nominal.rig.with_clearance(c))))
    if cause.rotates:
        out += [(f"modulation x{m:g}", replace(nominal, shaft_modulation=m))
                for m in SHAFT_MODULATIONS]
    return out


def _entry_jobs(causes, rig, sensor_component, nominal, n_sizes):
    """The library's entry jobs (``("entry", (cause, component, healthy setup, values, gains,
    index))``) and what each is (cause name, component, variant label, parameter, values),
    in the order their noise draws are keyed by (``index``): every cause on every component
    under each of its variants, the load modulation variants of the rotating causes last,
    so the other entries keep the draws they had before those variants were computed (a
    library computed earlier holds them as they are)."""
    jobs, meta, modulated = [], [], []
    for cause in causes:
        pname, values = value_grid(cause, n_sizes * DENSER.get(cause.name, 1))
        for comp in cause.components(rig, sensor_component):
            gains = PATH_GAINS if cause.rings_structure else (1.0,)
            for label, healthy in _variants(cause, nominal):
                job = (cause, comp, healthy, values, gains)
                if healthy.shaft_modulation != 1.0:
                    modulated.append((job, (cause.name, comp, label, pname, values)))
                    continue
                jobs.append(("entry", (*job, len(jobs))))
                meta.append((cause.name, comp, label, pname, values))
    for job, m in modulated:
        jobs.append(("entry", (*job, len(jobs))))
        meta.append(m)
    return jobs, meta


def build_library(machine, *, causes=None, n_sizes=N_SIZES, n_segments=LIBRARY_SEGMENTS,
                  seed=0, workers=1, progress=None):
    """The signature library of a calibrated machine (module docstring).

    Parameters
    ----------
    machine : cmsim.machine.Machine
        Calibrated, with its baseline.
    causes : sequence of Cause, optional
        Default: every registered cause that applies to the machine's rig.
    n_sizes : int
        Values per cause.
    n_segments : int
        Baseline segments each prediction is averaged over.
    seed : int
        Seed of the model runs.
    workers : int
        Processes (the entries dealt out among them; the library is the same with one).
    progress : callable, optional
        ``progress(done, total)`` after each entry.

    Returns
    -------
    SignatureLibrary
    """
    if machine.baseline is None:
        raise ParameterError("the machine holds no baseline samples (a version-1 machine "
                             "file): run cmsim calibrate again", param="machine")
    segs = machine.baseline.segments(machine.segment_s, n_segments)
    lib = _Library(machine, segs, int(seed))
    nominal = ModelSetup(rig=machine.rig, op=machine.op, machine=machine)
    names, base_rows = feature_rows(segs, machine.fs_hz, lib.freqs, lib.bearings,
                                    machine.unit_scale, bands=BAND_FAMILIES)
    all_rows = machine.baseline.segments(machine.segment_s)
    _, spread_rows = feature_rows(all_rows, machine.fs_hz, lib.freqs, lib.bearings,
                                  machine.unit_scale, bands=BAND_FAMILIES)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        spread = np.nanstd(spread_rows, axis=0, ddof=1)
    causes = list(causes) if causes is not None else applicable_causes(machine.rig)
    jobs, meta = _entry_jobs(causes, machine.rig, signal_info(machine.model_signal).component,
                             nominal, n_sizes)
    real_jobs = [("realisation", (nominal, int(seed) + 7777 * j, j))
                 for j in range(REALISATIONS + 1)]
    results = _run(lib, real_jobs + jobs, workers, progress)
    base_mean = _nanmean(base_rows)
    laid = [r[1] for r in results[:len(real_jobs)][1:] if r[1] is not None]
    realisation, run_spread = (
        _run_to_run(laid + [base_mean], [r[k] for r in results[:len(real_jobs)]
                                         if r[k] is not None], len(names)) for k in (2, 3))
    entries = []
    for (cause, comp, label, pname, values), (got, by_gain) in zip(meta,
                                                                   results[len(real_jobs):]):
        for g, rows in by_gain.items():
            table = np.array([r if r is not None and got == names
                              else np.full(len(names), np.nan) for r in rows], dtype=float)
            entries.append(SignatureEntry(cause, comp, _variant_label(label, g), pname,
                                          values, table))
    return SignatureLibrary(names=tuple(names), mean=base_mean, spread=spread,
                            realisation=realisation, run_spread=run_spread,
                            entries=tuple(entries),
                            segment_s=machine.segment_s, segments=int(segs.shape[0]),
                            speed_rpm=machine.op.speed_rpm, torque_nm=machine.op.torque_nm,
                            radial_load_n=machine.op.radial_load_n, seed=int(seed),
                            n_sizes=int(n_sizes))


def _run_to_run(laid, twin, n):
    """The larger of the two run-to-run spreads (module docstring) of each feature: over the
    rows of the runs laid on the baseline (the baseline's own mean with them) and over the
    rows of the runs through the twin; zeros where neither has two rows."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        spreads = [np.nanstd(np.vstack(rows), axis=0, ddof=1)
                   for rows in (laid, twin) if len(rows) >= 2]
        return np.nanmax(np.vstack(spreads), axis=0) if spreads else np.zeros(n)


def _run(lib, jobs, workers, progress):
    """Every job's result, in order, on ``workers`` processes (this one alone with 1)."""
    workers = check_workers(workers)
    out = [None] * len(jobs)
    t0 = time.perf_counter()
    if workers == 1:
        for i, (kind, job) in enumerate(jobs):
            out[i] = getattr(lib, kind)(job)
            if progress is not None:
                progress(i + 1, len(jobs), time.perf_counter() - t0)
        return out
    with process_pool(workers, initializer=_adopt, initargs=(lib,)) as pool:
        futures = [pool.submit(_work, kind, job) for kind, job in jobs]
        for i, fut in enumerate(futures):
            out[i] = fut.result()
            if progress is not None:
                progress(i + 1, len(jobs), time.perf_counter() - t0)
    return out


def simulate_entry(machine, library, cause, component, variant, value, *, threads=1):
    """One prediction of the library's kind, simulated anew: the machine's baseline segments
    (those the library was computed on) with ``cause`` at ``value`` on ``component`` under the
    nuisance ``variant`` — what refines a leading cause's size between the grid's points.

    Parameters
    ----------
    machine : cmsim.machine.Machine
        The machine (with its baseline).
    library : SignatureLibrary
        Its library (segments, seed).
    cause : Cause
        The cause.
    component : str or None
        Where it sits.
    variant : str
        A nuisance variant's label (of the library's entries).
    value : float
        The cause's first parameter.
    threads : int
        Threads of its healthy and changed runs (:func:`change_of`).

    Returns
    -------
    (list of str, numpy.ndarray, numpy.ndarray) or None
        Feature names, their means, the predicted segments (k, n); None if a run diverged
        or the variant is unknown.
    """
    segs = machine.baseline.segments(library.segment_s, library.segments)
    lib = _Library(machine, segs, library.seed)
    nominal = ModelSetup(rig=machine.rig, op=machine.op, machine=machine)
    label, gain = parse_variant(variant)
    healthy = dict(_variants(cause, nominal)).get(label)
    if healthy is None:
        return None
    try:
        setup = cause.extend(healthy, {**cause.start(healthy.rig), cause.params[0].name: value},
                             component)
    except ParameterError:
        return None
    change = change_of(setup, healthy, lib.force, lib.fs, lib.seed, threads=threads)
    if change is None:
        return None
    return lib.features(replace(change, path_gain=gain), [library.seed, 424_242],
                        signals=True)


def operating_shift(machine, library, op, *, threads=1):
    """What the model says another operating point changes on the baseline's features: the
    healthy model at ``op`` against the healthy model at the machine's (the same seed) laid
    on the library's segments, less the library's reference — the shift of every feature a
    record at ``op`` is read with (its speed stays the baseline's: the record's lines are
    read at its own speed).

    Parameters
    ----------
    machine : cmsim.machine.Machine
    library : SignatureLibrary
    op : OperatingPoint
        The record's documented operating point.
    threads : int
        Threads of its two runs (:func:`change_of`).

    Returns
    -------
    numpy.ndarray, shape (n_features,) or None
        None when a run diverged.
    """
    segs = machine.baseline.segments(library.segment_s, library.segments)
    lib = _Library(machine, segs, library.seed)
    nominal = ModelSetup(rig=machine.rig, op=machine.op, machine=machine)
    moved = replace(nominal, op=replace(op, speed_rpm=machine.op.speed_rpm))
    change = change_of(moved, nominal, lib.force, lib.fs, lib.seed, threads=threads)
    if change is None:
        return None
    names, mean = lib.features(change, [library.seed, 31_337])
    if list(names) != list(library.names):
        return None
    return mean - library.mean


def predicted_rows(library, cause, component=None):
    """The entries of ``cause`` (on ``component``, any when None) of a library.

    Parameters
    ----------
    library : SignatureLibrary
    cause : str
    component : str, optional

    Returns
    -------
    list of SignatureEntry
    """
    return [e for e in library.entries if e.cause == cause
            and (component is None or e.component == component)]
