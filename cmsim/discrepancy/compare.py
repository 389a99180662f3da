"""The loop: simulate a record's operating point, compare, rank causes, fit, re-simulate, gain.

1. The record is cut into segments (:func:`~cmsim.discrepancy.features.segments`); the even
   segments are the **fit** set, the odd ones the **held-out** set. The spread of the features
   over all segments, plus a model-uncertainty floor, is each feature's noise σ.
2. The nominal model (the record's rig, speed and load, the default housing path and a sensor
   noise of :data:`~cmsim.discrepancy.causes.NOMINAL_NOISE_RATIO`) is simulated with one seed
   and its scale-free features compared: χ² = Σ ((measured − simulated)/σ)².
3. Every applicable cause is simulated at its probe values (same seed: common random
   numbers); its score is the share of the nominal χ² it removes on the fit set.
4. No significant discrepancy when the nominal χ² per feature stays within the noise
   (:data:`CHI2_PER_FEATURE_LIMIT`) or no cause removes :data:`MIN_SCORE` of it.
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
from cmsim.discrepancy.features import feature_floor, record_features
from cmsim.dynamics import simulate
from cmsim.errors import IntegrationDiverged, ParameterError
from cmsim.run import signal_info
from cmsim.sensors import add_sensors

__all__ = ["Comparison", "compare", "simulate_setup", "CHI2_PER_FEATURE_LIMIT", "MIN_SCORE",
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

#: Points of the coarse grid of the fit (over the cause's bounds, log scale).
FIT_GRID = 6

#: Simulated time dropped at each end of a model signal (filter edges), s.
EDGE_S = 0.05


def simulate_setup(setup, fs_hz, duration_s, model_signal, seed, noise_ref_rms=None):
    """The model's sensor signal for ``setup``.

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
    info = signal_info(model_signal)
    mesh = "potential-energy" if setup.rig.gears is not None else None
    run = simulate(setup.rig, setup.op, duration_s + 2 * EDGE_S, fs_hz=max(fs_hz, 1e3),
                   seed=seed, faults=setup.faults, mesh=mesh, warmup_s=0.1)
    run = add_sensors(run, path=setup.housing, bearings=[info.component], seed=seed)
    edge = int(round(EDGE_S * run.fs_hz))
    n = int(round(duration_s * run.fs_hz))
    x = np.asarray(run[model_signal], dtype=float)[edge:edge + n]
    x = x - x.mean()
    rng = np.random.default_rng(seed + 7919)
    ref = float(np.std(x)) if noise_ref_rms is None else float(noise_ref_rms)
    return x + setup.noise_ratio * ref * rng.standard_normal(x.size)


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
    """Simulate setups (cached) and score them against measured feature means."""

    def __init__(self, record, seg_s, seed, budget):
        self.record = record
        self.seg_s = seg_s
        self.seed = seed
        self.budget = budget
        self.count = 0
        self.freqs = record.frequencies()
        self.bearing = signal_info(record.model_signal).component
        self.cache = {}
        self.signals = {}
        self.ref_rms = None

    def features(self, setup, seed=None, keep=None):
        seed = self.seed if seed is None else seed
        key = (repr(setup), seed)
        if key in self.cache:
            return self.cache[key]
        if self.count >= self.budget:
            raise _Budget()
        self.count += 1
        try:
            rows, xs = [], []
            for i in range(SIM_SEEDS):          # independent cage phases, one segment each
                x = simulate_setup(setup, self.record.fs_hz, self.seg_s,
                                   self.record.model_signal, seed + 7777 * i,
                                   noise_ref_rms=self.ref_rms)
                if self.ref_rms is None:           # the first (nominal) run sets the noise
                    self.ref_rms = float(np.std(x)) / math.sqrt(1 + setup.noise_ratio ** 2)
                names, f = record_features(x, self.record.fs_hz, self.freqs, self.bearing,
                                           self.seg_s)
                rows.append(f[0])
                xs.append(x)
            out = dict(zip(names, np.nanmean(rows, axis=0)))
            x = np.concatenate(xs)
        except (IntegrationDiverged, ParameterError):
            out, x = None, None
        self.cache[key] = out
        if keep is not None and x is not None:
            self.signals[keep] = x
        return out


class _Budget(Exception):
    pass


def _chi2(meas, sim, sigma, names, nominal=None):
    total, n = 0.0, 0
    for k in names:
        s = sim.get(k, math.nan) if sim is not None else math.nan
        if not math.isfinite(s) and nominal is not None:
            s = nominal.get(k, math.nan)
        if not math.isfinite(s):
            s = meas[k] - 3.0 * sigma[k]          # a feature the model lost: 3σ off
        total += ((meas[k] - s) / sigma[k]) ** 2
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
    f_nom = ev.features(nominal, keep="nominal")
    if f_nom is None:
        raise ParameterError("the nominal model of this record diverged", param="record")
    f_alt = ev.features(nominal, seed=seed + 2) or f_nom   # seed-to-seed spread of the model
    cols = [k for k in names if math.isfinite(meas_fit[k]) and math.isfinite(meas_held[k])
            and math.isfinite(f_nom.get(k, math.nan))]
    sigma = {k: math.sqrt(spread[k] ** 2 * (2.0 / F.shape[0] + 1.0 / SIM_SEEDS)
                          + 0.5 * SIM_SEEDS * (f_nom[k] - f_alt.get(k, f_nom[k])) ** 2
                          + feature_floor(k) ** 2) for k in cols}
    chi_nom = _chi2(meas_fit, f_nom, sigma, cols)
    n = len(cols)

    # rank
    cands = list(causes) if causes is not None else applicable_causes(record.rig)
    ranked = []
    for cause in cands:
        best = (math.inf, None, None)
        for comp in cause.components(record.rig, ev.bearing):
            for v in cause.probes:
                try:
                    f = ev.features(cause.apply(nominal, v, comp))
                except _Budget:
                    f = None
                except ParameterError:
                    continue
                if f is None:
                    continue
                c = _chi2(meas_fit, f, sigma, cols, f_nom)
                if c < best[0]:
                    best = (c, comp, v)
        if best[1] is not None or best[2] is not None:
            ranked.append({"name": cause.name, "cause": cause, "component": best[1],
                           "probe": best[2], "chi2": best[0],
                           "score": max(0.0, 1.0 - best[0] / chi_nom)})
    ranked.sort(key=lambda r: -r["score"])

    discrepancies = sorted(
        ({"feature": k, "measured": meas_fit[k], "simulated": f_nom[k],
          "z": (meas_fit[k] - f_nom[k]) / sigma[k]} for k in cols),
        key=lambda d: -abs(d["z"]))
    significant = (chi_nom / n > CHI2_PER_FEATURE_LIMIT and ranked
                   and ranked[0]["score"] >= MIN_SCORE)
    finding, component, params = "none", None, {}
    fitted = nominal
    if significant:
        top = ranked[0]
        cause, comp = top["cause"], top["component"]
        finding, component = cause.name, _component_name(record, comp)
        lo, hi = cause.bounds
        tr = (math.log, math.exp) if cause.log_scale else (lambda v: v, lambda v: v)

        def objective(u):
            v = clamp(cause, tr[1](u))
            try:
                f = ev.features(cause.apply(nominal, v, comp))
            except (_Budget, ParameterError):
                return chi_nom * 10
            return _chi2(meas_fit, f, sigma, cols, f_nom) if f is not None else chi_nom * 10

        best_v, best_c = top["probe"], top["chi2"]
        # coarse grid over the bounds (the objective may have several minima), then bounded
        # Brent in the bracket around the best grid point
        grid = np.linspace(tr[0](lo), tr[0](hi), FIT_GRID)
        n_left = max(0, ev.budget - ev.count)
        if n_left >= FIT_GRID + 3:
            vals = [objective(u) for u in grid]
            i = int(np.argmin(vals))
            if vals[i] < best_c:
                best_v, best_c = clamp(cause, tr[1](grid[i])), float(vals[i])
            a, b = grid[max(i - 1, 0)], grid[min(i + 1, FIT_GRID - 1)]
            n_fit = max(0, ev.budget - ev.count)
            if n_fit >= 3:
                res = minimize_scalar(objective, bounds=(a, b), method="bounded",
                                      options={"maxiter": n_fit, "xatol": 0.02})
                if res.fun < best_c:
                    best_v, best_c = clamp(cause, tr[1](res.x)), float(res.fun)
        params = {cause.parameter: best_v}
        fitted = cause.apply(nominal, best_v, comp)
        top["fitted"] = params
    # held-out: re-simulate nominal and fitted with a new seed
    ev.budget = budget
    f_nom2 = ev.features(nominal, seed=seed + 1)
    before = _chi2(meas_held, f_nom2, sigma, cols) / n
    if fitted is nominal:
        after = before
    else:
        f_fit2 = ev.features(fitted, seed=seed + 1, keep="fitted")
        after = _chi2(meas_held, f_fit2, sigma, cols, f_nom2) / n
    gain = {"before": before, "after": after,
            "relative": 0.0 if before <= 0 else 1.0 - after / before,
            "on": "held-out segments (odd), re-simulated with a new seed"}
    causes_out = [{"name": r["name"], "component": _component_name(record, r["component"]),
                   "score": r["score"],
                   "parameters": r.get("fitted", {r["cause"].parameter: r["probe"]})}
                  for r in ranked]
    spectra = {"measured": x, "fs_hz": fs, "nominal": ev.signals.get("nominal"),
               "fitted": ev.signals.get("fitted")}
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


def _component_name(record, comp):
    if comp is None:
        return None
    return record.components.get(comp, comp)


def with_setup(record, **changes):
    """The record with its operating point fields replaced (helper for scripts)."""
    return replace(record, op=replace(record.op, **changes))
