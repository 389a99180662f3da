"""What the sweep report needs from each run file, read once and reduced to a digest.

:func:`_digest` loads one run (:func:`_read_run`, an unreadable file named in a
:class:`~cmsim.errors.ParameterError`) and keeps only what :mod:`cmsim.datasets.report` draws
and tabulates: operating point, rig and clearance from the run's metadata, the amplitude
spectra up to the waterfall span with their labelled peaks and GMF harmonic levels, the DTE
over a few mesh cycles and over one input-shaft turn, and the bearing-centre orbits over one
ball-pass cycle; the run itself is then dropped. :func:`_n_harm` and :func:`_dominant` read
the dominant GMF harmonic off a digest.
"""

from __future__ import annotations

import time
import zipfile

import numpy as np

from cmsim.errors import ParameterError, check_range
from cmsim.features import N_GMF_HARMONICS, gmf_levels
from cmsim.frequencies import rig_frequencies
from cmsim.run import Run
from cmsim.spectra.amplitude import amplitude_spectrum
from cmsim.spectra.labels import label_peaks
from cmsim.spectra.run_spectrum import signal_bearing, signal_unit

__all__ = []   # the report's internals: imported by cmsim.datasets.report


def _read_run(path):
    """``Run.load(path)`` with its rig and operating point parsed; an unreadable or corrupted
    file is a :class:`ParameterError` naming it (re-running the sweep recomputes it)."""
    try:
        run = Run.load(path)
        run.rig, run.operating_point  # noqa: B018 - parse the meta here
        return run
    except (OSError, ValueError, KeyError, TypeError, EOFError, zipfile.BadZipFile) as exc:
        if isinstance(exc, ParameterError) and "does not exist" not in str(exc):
            detail = str(exc)
        else:
            detail = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
        raise ParameterError(f"run file {path} is unreadable or corrupted ({detail}); run "
                             f"the sweep command again to recompute it") from None


def _digest(path, signals, top_n, max_freq_hz, n_mesh_cycles):
    """Everything the report needs from one run (the run itself is then dropped)."""
    t0 = time.perf_counter()
    run = _read_run(path)
    t1 = time.perf_counter()
    missing = [s for s in signals if s not in run.signals]
    if missing:
        raise ParameterError(f"signal(s) {missing} not in {path.name}; available: {run.names}",
                             param="signals")
    meta, rig, op = run.meta, run.rig, run.operating_point
    freqs = rig_frequencies(rig, op)
    bearings = rig.bearing_names
    fs = run.fs_hz
    d = {"name": path.stem, "file": f"{path.parent.name}/{path.name}", "rig_name": rig.name,
         "has_gears": rig.has_gears,
         "speed_rpm": op.speed_rpm, "torque_nm": op.torque_nm,
         "friction": rig.mesh_contact.friction_coefficient if rig.has_gears else None,
         "clearance_m": rig.bearings[0].clearance_m, "seed": meta.get("seed"),
         "fs_hz": fs, "duration_s": run.t.size / fs, "shaft_hz": freqs.fr1_hz,
         "gmf_hz": freqs.gmf_hz, "integration_s": float(meta.get("wall_s", 0.0)),
         "losses": meta.get("losses"),
         "spectra": {}, "peaks": {}, "harmonics": {}, "units": {}, "families": {}}
    d["clearance_um"] = d["clearance_m"] * 1e6
    if max_freq_hz is None:
        f_show = 6.5 * freqs.gmf_hz if rig.has_gears else 10.5 * freqs.bearing(bearings[0]).bpf_hz
    else:
        f_show = check_range("max_freq_hz", max_freq_hz, 0.0, 0.5 * fs, lo_open=True,
                             unit="Hz")
    d["f_show"] = f_show
    extra = ("F_1b1_loa",) if (rig.has_gears and "F_1b1_loa" in run.signals
                               and "F_1b1_loa" not in signals) else ()
    d["dominant_signal"] = ("F_1b1_loa" if "F_1b1_loa" in run.signals else signals[0]) \
        if rig.has_gears else None
    for s in signals + extra:
        fam = freqs.families(signal_bearing(s, bearings))
        f, a = amplitude_spectrum(run[s], fs)
        peaks = label_peaks(f, a, fam)
        keep = f <= 1.02 * f_show
        d["spectra"][s] = (f[keep].copy(), a[keep].copy())
        d["peaks"][s] = peaks
        d["units"][s] = signal_unit(s)
        d["families"][s] = fam
        if "GMF" in fam:
            d["harmonics"][s] = gmf_levels((f, a), fam["GMF"])       # 1..6 × GMF
    # DTE: a few mesh cycles, and one turn of the input shaft, both from the end of the record
    if rig.has_gears and "dte_um" in run.signals:
        dte = run["dte_um"]
        n_short = min(dte.size, max(2, int(round(n_mesh_cycles / freqs.gmf_hz * fs))))
        n_turn = min(dte.size, max(2, int(round(fs / freqs.fr1_hz))))
        d["dte_short"] = (np.arange(n_short) / fs, dte[-n_short:].copy())
        seg = dte[-n_turn:]
        d["dte_turn"] = (np.arange(n_turn) / fs, seg - seg.mean())
    # orbits of the first bearing of each shaft over its last ball-pass cycle
    d["orbits"] = {}
    for b in [n for n in bearings if n.endswith("b1")]:
        n_cyc = min(run.t.size, max(2, int(round(fs / freqs.bearing(b).bpf_hz))))
        d["orbits"][b] = (run[f"x_{b}"][-n_cyc:].copy(), run[f"y_{b}"][-n_cyc:].copy())
        d.setdefault("bpf_hz", {})[b] = freqs.bearing(b).bpf_hz
    t2 = time.perf_counter()
    d["load_s"], d["spectra_s"] = t1 - t0, t2 - t1
    d["top_n"] = top_n
    return d


def _n_harm(m):
    """GMF harmonics considered for the dominant one: those below the run's span, at most
    the :data:`~cmsim.features.N_GMF_HARMONICS` (6) read by the feature extractor."""
    if not m["gmf_hz"]:
        return N_GMF_HARMONICS
    return max(1, min(N_GMF_HARMONICS, int(m["f_show"] // m["gmf_hz"])))


def _dominant(m, signal):
    h = m["harmonics"].get(signal) if signal else None
    if h is None:
        return None, None
    n = _n_harm(m)
    k = int(np.nanargmax(h[:n])) + 1
    return k, float(h[k - 1])
