"""The loop: simulate a record's operating point, compare, rank causes, fit, re-simulate, gain.

1. The record is cut into segments (:func:`~cmsim.discrepancy.features.segments`); the even
   segments are the **fit** set, the odd ones the **held-out** set. The spread of the features
   over all segments, plus a model-uncertainty floor, is each feature's noise σ.
2. The nominal model (the record's rig, speed and load, the default housing path and a sensor
   noise of :data:`~cmsim.discrepancy.causes.NOMINAL_NOISE_RATIO`) is simulated with one seed
   and its scale-free features compared: χ² = Σ ((measured − simulated)/σ)².
3. The transfer path (housing frequency factor) and the sensor noise act after the dynamics:
   they are refitted for every simulated setup on a small grid without a new simulation
   (the ``transfer_path`` and ``noise`` causes are these fits on the nominal model alone).
   Every other applicable cause is simulated at its probe values (same seed: common random
   numbers) with the nuisances refitted; its score is the share of the nominal χ² it
   removes on the fit set. Each feature adds at most :data:`Z_CAP`² (a robust χ²).
4. No significant discrepancy when the nominal χ² per feature stays within the noise
   (:data:`CHI2_PER_FEATURE_LIMIT`). Otherwise the finding is the best physical cause if it
   removes :data:`MIN_SCORE` of what the nuisances alone leave, else the best nuisance if it
   removes :data:`MIN_SCORE` of the nominal χ², else none.
5. Otherwise the best cause's parameter is fitted (``scipy.optimize.minimize_scalar``, bounded,
   in log scale) within the simulation budget; the nominal and the fitted model are then
   re-simulated with a new seed and compared on the held-out segments: ``gain.before`` and
   ``gain.after`` are χ² per feature there, ``gain.relative`` = 1 − after/before.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import minimize_scalar

from cmsim.discrepancy.causes import (ModelSetup, applicable_causes, clamp)
from cmsim.discrepancy.features import N_SHAPE_BANDS, feature_floor, record_features
from cmsim.dynamics import simulate
from cmsim.errors import IntegrationDiverged, ParameterError
from cmsim.run import signal_info
from cmsim.sensors import housing_acceleration

__all__ = ["Comparison", "compare", "simulate_setup", "simulate_forces", "sensor_signal", "CHI2_PER_FEATURE_LIMIT", "MIN_SCORE",
           "DEFAULT_BUDGET"]

#: Nominal χ² per feature below which the record agrees with the model.
CHI2_PER_FEATURE_LIMIT = 2.0

#: Least share of the nominal χ² the best cause must remove to be named.
MIN_SCORE = 0.3

#: Default number of simulations (ranking + fit + re-simulation).
DEFAULT_BUDGET = 48

#: Simulations (seeds: cage phases) averaged per model evaluation, one segment each; the
#: model's features depend on the relative cage phases of its bearings.
SIM_SEEDS = 2

#: A feature adds at most Z_CAP² to the χ² (robust: a misfit the catalogue cannot mend, such
#: as an unknown transfer path next to a fault, does not hide what another cause explains).
Z_CAP = 4.0

#: Causes fitted for every setup after the dynamics (no simulation of their own).
NUISANCES = ("noise", "transfer_path")

#: Noise ratios and housing frequency factors tried for every setup (nuisances).
NOISE_GRID = (0.03, 0.1, 0.3, 1.0, 3.0)
PATH_GRID = (0.7, 0.85, 1.18, 1.4)

#: Points of the coarse grid of the fit (over the cause's bounds, log scale).
FIT_GRID = 6

#: Simulated time dropped at each end of a model signal (filter edges), s.
EDGE_S = 0.05


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
    ndarray
    """
    info = signal_info(model_signal)
    mesh = "potential-energy" if setup.rig.gears is not None else None
    run = simulate(setup.rig, setup.op, duration_s + 2 * EDGE_S, fs_hz=max(fs_hz, 1e3),
                   seed=seed, faults=setup.faults, mesh=mesh, warmup_s=0.1)
    edge = int(round(EDGE_S * run.fs_hz))
    n = int(round(duration_s * run.fs_hz))
    f = np.asarray(run[f"F_{info.component}_{info.direction}"], dtype=float)
    return f[: n + 2 * edge], edge, n


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


class _Evaluator:
    """Simulate setups (cached forces) and score them; the transfer path and the noise are
    applied after the dynamics, so they are refitted for every setup without simulating."""

    def __init__(self, record, seg_s, seed, budget):
        self.record = record
        self.seg_s = seg_s
        self.seed = seed
        self.budget = budget
        self.count = 0
        self.freqs = record.frequencies()
        self.bearing = signal_info(record.model_signal).component
        self.forces = {}
        self.ref_rms = None
        self.fs = max(record.fs_hz, 1e3)

    def _forces(self, setup, seed):
        key = (repr(replace(setup, housing=None, noise_ratio=0.0)), seed)
        if key not in self.forces:
            if self.count >= self.budget:
                raise _Budget()
            self.count += 1
            try:
                self.forces[key] = [simulate_forces(setup, self.fs, self.seg_s,
                                                    self.record.model_signal, seed + 7777 * i)
                                    for i in range(SIM_SEEDS)]
            except (IntegrationDiverged, ParameterError):
                self.forces[key] = None
        return self.forces[key]

    def signal(self, setup, seed=None):
        """Concatenated sensor signals of the setup's runs (None if it diverged)."""
        seed = self.seed if seed is None else seed
        runs = self._forces(setup, seed)
        if runs is None:
            return None
        if self.ref_rms is None:                   # the nominal healthy level fixes the noise
            x = sensor_signal(*runs[0], self.fs, setup.housing, 0.0, None, seed)
            self.ref_rms = float(np.std(x))
        return [sensor_signal(f, e, n, self.fs, setup.housing, setup.noise_ratio,
                              self.ref_rms, seed + 7777 * i)
                for i, (f, e, n) in enumerate(runs)]

    def features(self, setup, seed=None):
        xs = self.signal(setup, seed)
        if xs is None:
            return None
        rows = []
        for x in xs:
            names, f = record_features(x, self.record.fs_hz, self.freqs, self.bearing,
                                       self.seg_s)
            rows.append(f[0])
        return dict(zip(names, np.nanmean(rows, axis=0)))

    def best_nuisance(self, setup, score, seed=None, fixed=()):
        """(χ², setup) with the noise ratio and the housing frequency factor refitted by a
        coordinate search on the cached runs (no new simulation); ``fixed`` names the
        nuisance(s) left alone."""
        base = setup.housing
        best = (score(self.features(setup, seed)), setup)
        if best[0] is None:
            return math.inf, setup
        for _ in range(2):
            if "noise" not in fixed:
                for r in NOISE_GRID:
                    cand = replace(best[1], noise_ratio=r)
                    c = score(self.features(cand, seed))
                    if c < best[0]:
                        best = (c, cand)
            if "transfer_path" not in fixed:
                for fac in PATH_GRID:
                    cand = replace(best[1], housing=replace(base, natural_frequencies_hz=tuple(
                        fac * f for f in base.natural_frequencies_hz)))
                    c = score(self.features(cand, seed))
                    if c < best[0]:
                        best = (c, cand)
        return best


class _Budget(Exception):
    pass


def _weight(name):
    """Weight of a feature: the spectral-shape bands share one family's weight of 4."""
    return 4.0 / N_SHAPE_BANDS if name.startswith("shape_") else 1.0


def _chi2(meas, sim, sigma, names, nominal=None):
    total, n = 0.0, 0
    for k in names:
        s = sim.get(k, math.nan) if sim is not None else math.nan
        if not math.isfinite(s) and nominal is not None:
            s = nominal.get(k, math.nan)
        if not math.isfinite(s):
            s = meas[k] - 3.0 * sigma[k]          # a feature the model lost: 3σ off
        total += _weight(k) * min(((meas[k] - s) / sigma[k]) ** 2, Z_CAP ** 2)
        n += 1
    return total


def compare(record, *, budget=DEFAULT_BUDGET, seed=0, seg_s=None, max_segments=8,
            causes=None):
    """Compare a measured record with the model, name a cause, fit it, measure the gain.

    Parameters
    ----------
    record : MeasuredRecord
        From :func:`~cmsim.discrepancy.records.read_record` (or a test generator).
    budget : int
        Most simulations used (ranking, fit and the two held-out re-simulations), >= 4.
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
    if not (isinstance(budget, int) and budget >= 4):
        raise ParameterError(f"budget must be an integer >= 4, got {budget!r}", param="budget",
                             allowed=">= 4")
    x = record.signal
    fs = record.fs_hz
    duration = x.size / fs
    seg_s = float(seg_s) if seg_s is not None else min(0.5, duration / 4.0)
    ev = _Evaluator(record, seg_s, seed, budget - 2)     # 2 kept for the held-out runs
    names, F = record_features(x, fs, ev.freqs, ev.bearing, seg_s, max_segments)
    if F.shape[0] < 4:
        raise ParameterError(f"record of {duration:.3g} s gives {F.shape[0]} segments of "
                             f"{seg_s:g} s; needs >= 4", param="record")
    fit_rows, held_rows = F[0::2], F[1::2]
    meas_fit = dict(zip(names, np.nanmean(fit_rows, axis=0)))
    meas_held = dict(zip(names, np.nanmean(held_rows, axis=0)))
    spread = dict(zip(names, np.nanstd(F, axis=0, ddof=1)))
    nominal = ModelSetup(rig=record.rig, op=record.op, housing=record.rig.housing)
    f_nom = ev.features(nominal)
    if f_nom is None:
        raise ParameterError("the nominal model of this record diverged", param="record")
    f_alt = ev.features(nominal, seed=seed + 2) or f_nom   # seed-to-seed spread of the model
    cols = [k for k in names if math.isfinite(meas_fit[k]) and math.isfinite(meas_held[k])
            and math.isfinite(f_nom.get(k, math.nan))]
    sigma = {k: math.sqrt(spread[k] ** 2 * (2.0 / F.shape[0] + 1.0 / SIM_SEEDS)
                          + 0.5 * SIM_SEEDS * (f_nom[k] - f_alt.get(k, f_nom[k])) ** 2
                          + feature_floor(k) ** 2) for k in cols}
    n = len(cols)

    def fit_score(f):
        return None if f is None else _chi2(meas_fit, f, sigma, cols, f_nom)

    chi_nom = fit_score(f_nom)
    # nuisances alone: noise, transfer path, both (no new simulation)
    cands = list(causes) if causes is not None else applicable_causes(record.rig)
    nuisance = {c.name: c for c in cands if c.name in NUISANCES}
    chi_both, setup_both = ev.best_nuisance(nominal, fit_score)
    ranked = []
    for name, cause in nuisance.items():
        other = tuple(k for k in NUISANCES if k != name)
        c, st = ev.best_nuisance(nominal, fit_score, fixed=other)
        value = (st.noise_ratio if name == "noise" else
                 st.housing.natural_frequencies_hz[0] / nominal.housing.natural_frequencies_hz[0])
        ranked.append({"name": name, "cause": cause, "component": None, "probe": value,
                       "chi2": c, "setup": st, "score": max(0.0, 1.0 - c / chi_nom)})
    # physical causes, each with the nuisances refitted
    for cause in cands:
        if cause.name in NUISANCES:
            continue
        best = (math.inf, None, None, None)
        for comp in cause.components(record.rig, ev.bearing):
            for v in cause.probes:
                try:
                    c, st = ev.best_nuisance(cause.apply(nominal, v, comp), fit_score)
                except _Budget:
                    continue
                except ParameterError:
                    continue
                if c < best[0]:
                    best = (c, comp, v, st)
        if best[3] is not None:
            ranked.append({"name": cause.name, "cause": cause, "component": best[1],
                           "probe": best[2], "chi2": best[0], "setup": best[3],
                           "score": max(0.0, 1.0 - best[0] / chi_nom),
                           "beyond_nuisance": max(0.0, 1.0 - best[0] / chi_both)})
    physical = sorted((r for r in ranked if r["name"] not in NUISANCES),
                      key=lambda r: -r["score"])
    nuis = sorted((r for r in ranked if r["name"] in NUISANCES), key=lambda r: -r["score"])

    discrepancies = sorted(
        ({"feature": k, "measured": meas_fit[k], "simulated": f_nom[k],
          "z": (meas_fit[k] - f_nom[k]) / sigma[k]} for k in cols),
        key=lambda d: -abs(d["z"]))
    finding, component, params = "none", None, {}
    fitted = nominal
    top = None
    if chi_nom / n > CHI2_PER_FEATURE_LIMIT:
        if physical and physical[0]["beyond_nuisance"] >= MIN_SCORE:
            top = physical[0]
        elif nuis and nuis[0]["score"] >= MIN_SCORE:
            top = nuis[0]
    ordered = ([top] if top else []) + [r for r in physical + nuis if r is not top]
    ordered = ordered[:1] + sorted(ordered[1:], key=lambda r: -r["score"])
    if top is not None and top["name"] in NUISANCES:
        finding = top["name"]
        fitted = top["setup"]
        params = _nuisance_params(fitted, nominal)
        top["fitted"] = params
    elif top is not None:
        cause, comp = top["cause"], top["component"]
        finding, component = cause.name, _component_name(record, comp)
        lo, hi = cause.bounds
        tr = (math.log, math.exp) if cause.log_scale else (lambda v: v, lambda v: v)
        states = {}

        def objective(u):
            v = clamp(cause, tr[1](u))
            try:
                c, st = ev.best_nuisance(cause.apply(nominal, v, comp), fit_score)
            except (_Budget, ParameterError):
                return chi_nom * 10
            states[float(u)] = st
            return c

        best_v, best_c, best_st = top["probe"], top["chi2"], top["setup"]
        # coarse grid over the bounds (the objective may have several minima), then bounded
        # Brent in the bracket around the best grid point
        grid = np.linspace(tr[0](lo), tr[0](hi), FIT_GRID)
        if ev.budget - ev.count >= FIT_GRID + 3:
            vals = [objective(u) for u in grid]
            i = int(np.argmin(vals))
            if vals[i] < best_c:
                best_v, best_c = clamp(cause, tr[1](grid[i])), float(vals[i])
                best_st = states.get(float(grid[i]), best_st)
            a, b = grid[max(i - 1, 0)], grid[min(i + 1, FIT_GRID - 1)]
            n_fit = ev.budget - ev.count
            if n_fit >= 3:
                res = minimize_scalar(objective, bounds=(a, b), method="bounded",
                                      options={"maxiter": n_fit, "xatol": 0.02})
                if res.fun < best_c and float(res.x) in states:
                    best_v, best_c = clamp(cause, tr[1](res.x)), float(res.fun)
                    best_st = states[float(res.x)]
        params = {cause.parameter: best_v, **_nuisance_params(best_st, nominal)}
        fitted = best_st
        top["fitted"] = params
    # held-out: re-simulate nominal and fitted with a new seed
    ev.budget = budget
    f_nom2 = ev.features(nominal, seed=seed + 1)
    before = _chi2(meas_held, f_nom2, sigma, cols) / n
    if fitted is nominal:
        after = before
    else:
        f_fit2 = ev.features(fitted, seed=seed + 1)
        after = _chi2(meas_held, f_fit2, sigma, cols, f_nom2) / n
    gain = {"before": before, "after": after,
            "relative": 0.0 if before <= 0 else 1.0 - after / before,
            "on": "held-out segments (odd), re-simulated with a new seed"}
    causes_out = [{"name": r["name"], "component": _component_name(record, r["component"]),
                   "score": r["score"],
                   **({"beyond_nuisance": r["beyond_nuisance"]} if "beyond_nuisance" in r
                      else {}),
                   "parameters": r.get("fitted", {r["cause"].parameter: r["probe"]})}
                  for r in ordered]
    sig_nom = ev.signal(nominal, seed + 1)
    sig_fit = ev.signal(fitted, seed + 1) if fitted is not nominal else None
    spectra = {"measured": x, "fs_hz": fs,
               "nominal": None if sig_nom is None else np.concatenate(sig_nom),
               "fitted": None if sig_fit is None else np.concatenate(sig_fit)}
    return Comparison(
        discrepancies=[{k: (float(v) if k != "feature" else v) for k, v in d.items()}
                       for d in discrepancies[:12]],
        causes=causes_out, finding=finding, component=component, parameters=params,
        gain=gain, simulations=ev.count, wall_s=time.perf_counter() - start,
        chi2_per_feature=chi_nom / n, n_features=n, inferred=dict(record.inferred),
        record={"channel": record.channel, "model_signal": record.model_signal,
                "fs_hz": fs, "duration_s": duration, "speed_rpm": record.op.speed_rpm,
                "torque_nm": record.op.torque_nm, "radial_load_n": record.op.radial_load_n,
                "segment_s": seg_s, "segments": int(F.shape[0])},
        spectra=spectra)


def _nuisance_params(setup, nominal):
    """The fitted nuisances of a setup: noise ratio and housing frequency factor."""
    return {"noise_ratio": setup.noise_ratio,
            "frequency_factor": setup.housing.natural_frequencies_hz[0]
            / nominal.housing.natural_frequencies_hz[0]}


def _component_name(record, comp):
    if comp is None:
        return None
    return record.components.get(comp, comp)


def with_setup(record, **changes):
    """The record with its operating point fields replaced (helper for scripts)."""
    return replace(record, op=replace(record.op, **changes))
