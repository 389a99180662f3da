"""The loop: simulate a record's operating point, compare, rank causes, fit, re-simulate, gain.

1. The record is cut into segments (:func:`cmsim.features.segments`); the even
   segments are the **fit** set, the odd ones the **held-out** set. Features are the
   scale-free ones of :func:`cmsim.features.relative_features`, plus the absolute level
   ``level_db`` when the record's unit is known (its σ carries the housing path's unknown
   gain, :data:`LEVEL_SIGMA_DB`).
2. The model of a setup is simulated with :data:`SIM_SEEDS` seeds (cage phases, slip), one
   segment each, and its features averaged; every setup uses the same seeds (common random
   numbers), so causes are compared on the same realisations. The model's own spread from one
   realisation to another is measured on :data:`VAR_SEEDS` runs of the nominal model; with
   the record's segment-to-segment spread and a floor it is each feature's σ, and
   χ² = Σ w·min(((measured − simulated)/σ)², :data:`Z_CAP`²) (robust; the spectral-shape
   bands share one family's weight).
3. The measurement chain — the housing modes' frequency factor and the sensor noise
   (:data:`~cmsim.discrepancy.causes.NUISANCES`) — acts after the dynamics and is refitted
   for every setup without a new simulation, within its prior range. Each cause is simulated
   at its probe values on each component it may sit on; the :data:`REFINE_TOP` best are
   re-ranked at their best over a coarse grid of their bounds (a probe may sit far from the
   truth). A cause's evidence is Δχ² = χ²(nominal) − χ²(cause) on the fit segments, its
   ``score`` the share Δχ²/χ²(nominal). ``transfer_path`` and ``noise`` are the nuisances
   released beyond their prior range (no simulation).
4. The finding is the cause with the largest Δχ² if it reaches :data:`MIN_DELTA_CHI2` (a
   likelihood-ratio test: on records without a hidden effect the best cause's Δχ² stays
   below it, see benchmarks/bench_compare.py) and :data:`MIN_SCORE` (a large misfit that no
   cause mends is not pinned on one); otherwise "no significant discrepancy" (``none``).
5. The finding's parameters are fitted (a coarse grid over the bounds, then bounded Brent in
   log scale, one parameter after the other) within the simulation budget; the nominal and
   the fitted model are then re-simulated with new seeds and compared on the held-out
   segments: ``gain.before`` and ``gain.after`` are χ² per feature there, ``gain.relative``
   = 1 − after/before.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize_scalar

from cmsim.discrepancy.causes import CAUSES, NUISANCES, ModelSetup, applicable_causes
from cmsim.dynamics import simulate
from cmsim.errors import IntegrationDiverged, ParameterError
from cmsim.features import N_SHAPE_BANDS, relative_features, segment_features, segments
from cmsim.losses import LossSettings
from cmsim.run import signal_info
from cmsim.sensors import housing_acceleration

__all__ = ["Comparison", "compare", "simulate_setup", "simulate_forces", "sensor_signal",
           "MIN_DELTA_CHI2", "MIN_SCORE", "DEFAULT_BUDGET",
           "SIM_SEEDS", "VAR_SEEDS", "LEVEL_SIGMA_DB", "Z_CAP", "DB_FLOOR", "LOG_FLOOR",
           "feature_floor"]

#: Least Δχ² (fit segments) for a cause to be named.
MIN_DELTA_CHI2 = 30.0

#: Least share of the nominal χ² the named cause must remove.
MIN_SCORE = 0.25

#: Default budget of simulations (model runs: ranking, fit and the held-out re-simulations).
DEFAULT_BUDGET = 140

#: Simulations (seeds: cage phases, slip) averaged per evaluation of a setup, one segment
#: each.
SIM_SEEDS = 2

#: Runs of the nominal model that measure its realisation-to-realisation spread.
VAR_SEEDS = 6

#: A feature adds at most Z_CAP² to the χ² (robust: a misfit the catalogue cannot mend, such
#: as an unknown transfer path next to a fault, does not hide what another cause explains).
Z_CAP = 4.0

#: Uncertainty of the model's absolute level (the housing path's gain is not known better),
#: dB; only used when the record's unit is known.
LEVEL_SIGMA_DB = 6.0

#: Simulated time dropped at each end of a model signal (filter edges), s.
EDGE_S = 0.05

#: Points of the coarse grid of the fit (over the parameter's bounds, log scale).
FIT_GRID = 6

#: Leading causes (by their probes) re-ranked at their best over the coarse grid.
REFINE_TOP = 3

#: Reference of ``level_db``, m/s².
_LEVEL_REF = 1.0

#: Least model uncertainty of a dB column (a line's level, a band's share), dB.
DB_FLOOR = 1.5

#: Least model uncertainty of a log column (kurtosis, crest), natural-log units.
LOG_FLOOR = 0.1


def feature_floor(name):
    """Model-uncertainty floor of a feature column, in its own unit.

    Parameters
    ----------
    name : str
        Column name (``*_log`` columns are natural logs, the others dB).

    Returns
    -------
    float
    """
    return LOG_FLOOR if name.endswith("_log") else DB_FLOOR


def simulate_forces(setup, fs_hz, duration_s, model_signal, seed):
    """The bearing force behind ``model_signal`` (N), before the transfer path and noise.

    Parameters
    ----------
    setup : ModelSetup
    fs_hz : float
        Sample rate, Hz.
    duration_s : float
        Duration, s.
    model_signal : str
        ``accel_<bearing>_<x|y>``.
    seed : int
        Seed of the simulation.

    Returns
    -------
    (ndarray, int, int)
        The force with ``edge`` extra samples at each end, ``edge`` and the samples kept.
    """
    info = signal_info(model_signal)
    name = f"F_{info.component}_{info.direction}"
    mesh = "potential-energy" if setup.rig.gears is not None else None
    run = simulate(setup.rig, setup.op, duration_s + 2 * EDGE_S, fs_hz=max(fs_hz, 1e3),
                   seed=seed, faults=setup.faults, mesh=mesh, warmup_s=0.1, record=(name,),
                   losses=LossSettings() if setup.mixed_friction else None)
    edge = int(round(EDGE_S * run.fs_hz))
    n = int(round(duration_s * run.fs_hz))
    return np.asarray(run[name], dtype=float)[: n + 2 * edge], edge, n


def sensor_signal(force, edge, n, fs_hz, housing, noise_ratio, noise_ref_rms, seed):
    """Housing acceleration of a simulated force plus sensor noise (edges trimmed).

    Parameters
    ----------
    force : ndarray
        Bearing force with ``edge`` extra samples at each end, N.
    edge, n : int
        Samples trimmed at each end, samples kept.
    fs_hz : float
        Sample rate, Hz.
    housing : HousingPath
        Transfer path.
    noise_ratio : float
        Noise RMS relative to ``noise_ref_rms``.
    noise_ref_rms : float or None
        Reference RMS (None: the signal's own).
    seed : int
        Seed of the noise.

    Returns
    -------
    ndarray
    """
    x = housing_acceleration(force - force.mean(), fs_hz, housing)[edge:edge + n]
    x = x - x.mean()
    ref = float(np.std(x)) if noise_ref_rms is None else float(noise_ref_rms)
    rng = np.random.default_rng(seed + 7919)
    return x + noise_ratio * ref * rng.standard_normal(x.size)


def simulate_setup(setup, fs_hz, duration_s, model_signal, seed, noise_ref_rms=None):
    """The model's sensor signal for ``setup`` (simulation, transfer path, noise).

    Parameters
    ----------
    setup : ModelSetup
    fs_hz : float
        Sample rate, Hz.
    duration_s : float
        Duration, s.
    model_signal : str
        ``accel_<bearing>_<x|y>``.
    seed : int
        Seed of the simulation and of the sensor noise.
    noise_ref_rms : float, optional
        RMS the noise ratio refers to (the healthy model's signal, so that a fault raises
        the signal above a fixed sensor noise); default the signal's own RMS.

    Returns
    -------
    ndarray
    """
    force, edge, n = simulate_forces(setup, fs_hz, duration_s, model_signal, seed)
    return sensor_signal(force, edge, n, max(fs_hz, 1e3), setup.housing, setup.noise_ratio,
                         noise_ref_rms, seed)


@dataclass
class Comparison:
    """Result of :func:`compare` (``to_dict`` is the JSON of ``cmsim compare``)."""

    discrepancies: list
    causes: list
    finding: str
    component: str | None
    parameters: dict
    gain: dict
    simulations: int
    wall_s: float
    chi2_per_feature: float
    n_features: int
    inferred: dict
    record: dict
    spectra: dict = field(default_factory=dict, repr=False)

    def to_dict(self):
        """JSON-ready dict (keys of issue 12)."""
        return {"finding": self.finding, "component": self.component,
                "parameters": self.parameters, "gain": self.gain,
                "discrepancies": self.discrepancies, "causes": self.causes,
                "simulations": self.simulations, "wall_s": self.wall_s,
                "chi2_per_feature": self.chi2_per_feature, "n_features": self.n_features,
                "inferred": self.inferred, "record": self.record}


class _Budget(Exception):
    """The simulation budget is spent."""


class _Evaluator:
    """Simulated forces of setups (cached by their dynamics), the measurement chain applied
    after them, and the features; counts the simulations against the budget."""

    def __init__(self, record, seg_s, seed, budget):
        self.record = record
        self.seg_s = seg_s
        self.seed = seed
        self.budget = budget
        self.count = 0
        self.freqs = record.model_frequencies()
        self.sensor_bearing = signal_info(record.model_signal).component
        self.bearings = list(record.rig.bearing_names)
        self.fs = max(record.fs_hz, 1e3)
        self.forces = {}
        self.cache = {}
        self.ref_rms = None
        self.scale = record.unit_scale

    def _forces(self, setup, seed):
        key = (setup.dynamics_key(), seed)
        if key not in self.forces:
            if self.count >= self.budget:
                raise _Budget()
            self.count += 1
            try:
                self.forces[key] = simulate_forces(setup, self.fs, self.seg_s,
                                                   self.record.model_signal, seed)
            except (IntegrationDiverged, ParameterError):
                self.forces[key] = None
        return self.forces[key]

    def seeds(self, n, base=None):
        """The first ``n`` simulation seeds of a base seed."""
        base = self.seed if base is None else base
        return [base + 7777 * i for i in range(n)]

    def signal(self, setup, seed):
        """The sensor signal of one run of ``setup`` (None if it diverged)."""
        run = self._forces(setup, seed)
        if run is None:
            return None
        if self.ref_rms is None:           # the nominal healthy level fixes the noise
            self.ref_rms = float(np.std(sensor_signal(*run, self.fs, setup.housing, 0.0,
                                                      None, seed)))
        return sensor_signal(*run, self.fs, setup.housing, setup.noise_ratio, self.ref_rms,
                             seed)

    def row(self, setup, seed):
        """Features of one run of ``setup`` (None if it diverged)."""
        key = (setup.dynamics_key(), setup.housing, setup.noise_ratio, seed)
        if key not in self.cache:
            x = self.signal(setup, seed)
            if x is None:
                self.cache[key] = None
            else:
                f = relative_features(x, self.record.fs_hz, self.freqs, self.bearings)
                if self.scale is not None:
                    f["level_db"] = 20.0 * math.log10(max(float(np.std(x)), 1e-30)
                                                      / _LEVEL_REF)
                self.cache[key] = f
        return self.cache[key]

    def features(self, setup, seeds):
        """Features of ``setup`` averaged over ``seeds`` (None if a run diverged)."""
        rows = [self.row(setup, s) for s in seeds]
        if any(r is None for r in rows):
            return None
        with warnings.catch_warnings():          # a column NaN in every run stays NaN
            warnings.simplefilter("ignore", RuntimeWarning)
            return {k: float(np.nanmean([r[k] for r in rows])) for k in rows[0]}


def _weight(name):
    """Weight of a feature: the spectral-shape bands share one family's weight of 4."""
    return 4.0 / N_SHAPE_BANDS if name.startswith("shape_") else 1.0


def _chi2(meas, sim, sigma, names):
    if sim is None:
        return math.inf
    total = 0.0
    for k in names:
        s = sim.get(k, math.nan)
        if not math.isfinite(s):
            s = meas[k] - 3.0 * sigma[k]          # a feature the model lost: 3σ off
        total += _weight(k) * min(((meas[k] - s) / sigma[k]) ** 2, Z_CAP ** 2)
    return total


class _Nuisances:
    """Refit of the measurement chain for a setup: a coordinate search over the housing
    frequency factor and the noise ratio, each within its prior range or released."""

    def __init__(self, ev, score, seeds):
        self.ev, self.score, self.seeds = ev, score, seeds

    def grid(self, nuisance, released):
        if released:
            return nuisance.grid
        lo, hi = nuisance.prior
        return tuple(v for v in nuisance.grid if lo <= v <= hi)

    @staticmethod
    def set(setup, name, value):
        """The setup with nuisance ``name`` at ``value`` (its catalogue cause applied)."""
        return CAUSES[name]().apply(setup, value, None)

    def fit(self, setup, release=None):
        """(χ², setup) with both nuisances refitted; ``release`` names the one searched
        beyond its prior."""
        best = (self.score(self.ev.features(setup, self.seeds)), setup)
        for _ in range(2):
            start = best[0]
            for nu in NUISANCES:
                for v in self.grid(nu, nu.name == release):
                    cand = self.set(best[1], nu.name, v)
                    c = self.score(self.ev.features(cand, self.seeds))
                    if c < best[0]:
                        best = (c, cand)
            if best[0] >= start:
                break
        return best


def _prepare(record, seg_s, max_segments):
    x = record.signal
    fs = record.fs_hz
    duration = x.size / fs
    seg_s = float(seg_s) if seg_s is not None else min(0.5, duration / 4.0)
    freqs = record.model_frequencies()
    names, F = segment_features(x, fs, freqs, list(record.rig.bearing_names), seg_s,
                               max_segments)
    if F.shape[0] < 4:
        raise ParameterError(f"record of {duration:.3g} s gives {F.shape[0]} segments of "
                             f"{seg_s:g} s; needs >= 4", param="record")
    # one column per distinct feature (the two shafts of a 1:1 gear rig read alike), none
    # that the record never reads (a sideband beyond the spectrum)
    keep = [i for i in range(F.shape[1]) if np.isfinite(F[:, i]).any()
            and not any(np.array_equal(F[:, i], F[:, j], equal_nan=True) for j in range(i))]
    names, F = [names[i] for i in keep], F[:, keep]
    if record.unit_scale is not None:
        lv = [20.0 * math.log10(max(float(np.std(x[a:b])) * record.unit_scale, 1e-30)
                                / _LEVEL_REF)
              for a, b in segments(x.size, fs, seg_s, max_segments)]
        names = names + ["level_db"]
        F = np.column_stack([F, lv])
    return seg_s, duration, names, F


def compare(record, *, budget=DEFAULT_BUDGET, seed=0, seg_s=None, max_segments=8,
            causes=None):
    """Compare a measured record with the model, name a cause, fit it, measure the gain.

    Parameters
    ----------
    record : MeasuredRecord
        From :func:`~cmsim.measured.read_record` (or a test generator).
    budget : int
        Most simulations (model runs) used: ranking, fit and the held-out re-simulations
        (>= 2·VAR_SEEDS + 2·SIM_SEEDS).
    seed : int
        Seed of the model simulations.
    seg_s : float, optional
        Segment length, s; default 0.5 s (a quarter of shorter records).
    max_segments : int
        Segments read from the record (spread over it), >= 4.
    causes : sequence of Cause, optional
        Default: every registered cause that applies to the rig.

    Returns
    -------
    Comparison
    """
    start = time.perf_counter()
    least = VAR_SEEDS + 2 * SIM_SEEDS
    if not (isinstance(budget, int) and not isinstance(budget, bool) and budget >= least):
        raise ParameterError(f"budget must be an integer >= {least}, got {budget!r}",
                             param="budget", allowed=f">= {least}")
    seg_s, duration, names, F = _prepare(record, seg_s, max_segments)
    ev = _Evaluator(record, seg_s, seed, budget - 2 * SIM_SEEDS)   # held-out runs kept
    fit_rows, held_rows = F[0::2], F[1::2]
    meas_fit = dict(zip(names, np.nanmean(fit_rows, axis=0)))
    meas_held = dict(zip(names, np.nanmean(held_rows, axis=0)))
    spread = dict(zip(names, np.nanstd(F, axis=0, ddof=1)))
    nominal = ModelSetup(rig=record.rig, op=record.op, housing=record.rig.housing)
    seeds = ev.seeds(SIM_SEEDS)
    var_rows = [ev.row(nominal, s) for s in ev.seeds(VAR_SEEDS)]
    if any(r is None for r in var_rows):
        raise ParameterError("the nominal model of this record diverged", param="record")
    f_nom = ev.features(nominal, seeds)
    cols = [k for k in names if math.isfinite(meas_fit[k]) and math.isfinite(meas_held[k])
            and math.isfinite(f_nom.get(k, math.nan))]
    sigma = {}
    for k in cols:
        v_seed = float(np.nanvar([r[k] for r in var_rows], ddof=1))
        floor = LEVEL_SIGMA_DB if k == "level_db" else feature_floor(k)
        sigma[k] = math.sqrt(v_seed * (1.0 + 1.0 / SIM_SEEDS)
                             + spread[k] ** 2 * 2.0 / F.shape[0] + floor ** 2)
    n_eff = sum(_weight(k) for k in cols)

    def fit_score(f):
        return _chi2(meas_fit, f, sigma, cols)

    nuis = _Nuisances(ev, fit_score, seeds)
    chi_nom, setup_nom = nuis.fit(nominal)
    cands = list(causes) if causes is not None else applicable_causes(record.rig)
    ranked = []
    for cause in cands:
        try:
            ranked.append(_rank(cause, nominal, nuis, ev))
        except _Budget:
            break
    ranked = [r for r in ranked if r is not None]
    ranked.sort(key=lambda r: r["chi2"])
    for r in [r for r in ranked if not r["cause"].post_dynamics][:REFINE_TOP]:
        try:
            _refine(r, nominal, nuis, ev)
        except _Budget:
            break
    for r in ranked:
        r["delta_chi2"] = chi_nom - r["chi2"]
        r["score"] = max(0.0, r["delta_chi2"] / chi_nom) if chi_nom > 0 else 0.0
    ranked.sort(key=lambda r: -r["delta_chi2"])

    discrepancies = sorted(
        ({"feature": k, "measured": meas_fit[k], "simulated": f_nom[k],
          "z": (meas_fit[k] - f_nom[k]) / sigma[k]} for k in cols),
        key=lambda d: -abs(d["z"]))
    finding, component, params = "none", None, {}
    fitted = setup_nom
    top = ranked[0] if ranked else None
    significant = (top is not None and top["delta_chi2"] >= MIN_DELTA_CHI2
                   and top["score"] >= MIN_SCORE)
    if significant:
        finding = top["name"]
        component = _component_name(record, top["component"])
        params, fitted = _fit(top, nominal, nuis, ev)
        top["fitted"] = params
    # held-out: re-simulate nominal and fitted with new seeds
    ev.budget = budget
    held_seeds = ev.seeds(SIM_SEEDS, seed + 1)

    def held(setup):
        return _chi2(meas_held, ev.features(setup, held_seeds), sigma, cols) / n_eff

    before = held(setup_nom)
    after = before if fitted is setup_nom else held(fitted)
    gain = {"before": float(before), "after": float(after),
            "relative": 0.0 if before <= 0 else float(1.0 - after / before),
            "on": "held-out segments (odd), re-simulated with new seeds"}
    causes_out = [{"name": r["name"], "component": _component_name(record, r["component"]),
                   "score": r["score"], "delta_chi2": r["delta_chi2"],
                   "parameters": r.get("fitted", r["probe"])} for r in ranked]
    spectra = {"measured": record.signal, "fs_hz": record.fs_hz,
               "nominal": _concat([ev.signal(setup_nom, s) for s in held_seeds]),
               "fitted": None if fitted is setup_nom else _concat(
                   [ev.signal(fitted, s) for s in held_seeds])}
    return Comparison(
        discrepancies=[{k: (float(v) if k != "feature" else v) for k, v in d.items()}
                       for d in discrepancies[:12]],
        causes=causes_out, finding=finding, component=component, parameters=params,
        gain=gain, simulations=ev.count, wall_s=time.perf_counter() - start,
        chi2_per_feature=chi_nom / n_eff, n_features=len(cols),
        inferred=dict(record.inferred),
        record={"channel": record.channel, "model_signal": record.model_signal,
                "fs_hz": record.fs_hz, "duration_s": duration,
                "speed_rpm": record.op.speed_rpm, "torque_nm": record.op.torque_nm,
                "radial_load_n": record.op.radial_load_n, "segment_s": seg_s,
                "segments": int(F.shape[0]), "unit_scale_to_m_s2": record.unit_scale},
        spectra=spectra)


def _concat(xs):
    return None if any(x is None for x in xs) else np.concatenate(xs)


def _rank(cause, nominal, nuis, ev):
    """The cause's best probe: ``{name, cause, component, probe, chi2, setup}`` or None."""
    if cause.post_dynamics:                       # a nuisance released beyond its prior
        chi, st = nuis.fit(nominal, release=cause.name)
        name = cause.params[0].name
        return {"name": cause.name, "cause": cause, "component": None,
                "probe": {name: _nuisance_params(st, nominal)[name]}, "chi2": chi,
                "setup": st}
    best = None
    for comp in cause.components(nominal.rig, ev.sensor_bearing):
        for values in _probes(cause, nominal.rig):
            try:
                chi, st = nuis.fit(cause.extend(nominal, values, comp))
            except ParameterError:
                continue
            if best is None or chi < best["chi2"]:
                best = {"name": cause.name, "cause": cause, "component": comp,
                        "probe": values, "chi2": chi, "setup": st}
    return best


def _refine(r, nominal, nuis, ev):
    """Re-rank a leading cause at its best over a coarse grid of each parameter's bounds
    (the probes may miss a severity far from them); the fit starts from there."""
    cause, comp = r["cause"], r["component"]
    for p in cause.params:
        fwd, back = (math.log, math.exp) if p.log_scale else (float, float)
        for u in np.linspace(fwd(p.bounds[0]), fwd(p.bounds[1]), FIT_GRID):
            values = {**r["probe"], p.name: p.clamp(back(u))}
            try:
                chi, st = nuis.fit(cause.extend(nominal, values, comp))
            except ParameterError:
                continue
            if chi < r["chi2"]:
                r.update(chi2=chi, setup=st, probe=values)


def _probes(cause, rig):
    """Probe value sets: each parameter's probes with the others at their start
    (:meth:`~cmsim.discrepancy.causes.Cause.start`)."""
    start = cause.start(rig)
    return [{**start, p.name: v} for p in cause.params for v in p.probes]


def _fit(top, nominal, nuis, ev):
    """Fit the named cause's parameters, one after the other (coarse grid over the bounds,
    then bounded Brent), within the budget; returns (parameters, fitted setup)."""
    cause, comp = top["cause"], top["component"]
    if cause.post_dynamics:                       # its value is one of the nuisances
        return _nuisance_params(top["setup"], nominal), top["setup"]
    values = dict(top["probe"])
    best_c, best_st = top["chi2"], top["setup"]
    for p in cause.params:
        lo, hi = p.bounds
        fwd, back = (math.log, math.exp) if p.log_scale else (float, float)
        states = {}

        def objective(u, p=p, states=states):
            v = p.clamp(back(u))
            try:
                c, st = nuis.fit(cause.extend(nominal, {**values, p.name: v}, comp))
            except (_Budget, ParameterError):
                return math.inf
            states[float(u)] = (c, st, v)
            return c

        grid = np.linspace(fwd(lo), fwd(hi), FIT_GRID)
        left = ev.budget - ev.count
        if left < SIM_SEEDS * (FIT_GRID + 3):
            break
        vals = [objective(u) for u in grid]
        i = int(np.argmin(vals))
        a, b = grid[max(i - 1, 0)], grid[min(i + 1, FIT_GRID - 1)]
        n_fit = (ev.budget - ev.count) // SIM_SEEDS
        if n_fit >= 3:
            minimize_scalar(objective, bounds=(a, b), method="bounded",
                            options={"maxiter": n_fit, "xatol": 0.02})
        if states:
            c, st, v = min(states.values(), key=lambda s: s[0])
            if c < best_c:
                best_c, best_st = c, st
                values[p.name] = v
    return {**values, **_nuisance_params(best_st, nominal)}, best_st


def _nuisance_params(setup, nominal):
    """The fitted nuisances of a setup: noise ratio and housing frequency factor (the
    parameters of the ``noise`` and ``transfer_path`` causes)."""
    return {"noise_ratio": setup.noise_ratio,
            "frequency_factor": setup.housing.natural_frequencies_hz[0]
            / nominal.rig.housing.natural_frequencies_hz[0]}


def _component_name(record, comp):
    if comp is None:
        return None
    return record.components.get(comp, comp)
