"""HTML report of a sweep directory: waterfalls, orbits, DTE traces and labelled-peak tables.

:func:`build_report` reads the run files of a sweep (``DIR/records/*.npz``, listed by
``DIR/manifest.parquet`` when there is one; a folder of runs saved by
:meth:`Run.save <cmsim.run.Run.save>` under ``DIR/runs/`` too) and writes
``DIR/report.html`` with PNG figures
beside it (relative links, no external assets: the directory can be zipped and sent).
Everything shown is computed from the run files alone — operating point, rig, clearance and
friction are read from each run's metadata — so regenerating the report from the files
reproduces it.

The sweep parameter is the first of torque, speed, friction, clearance that takes more than
one value; runs that differ in the others form separate groups, each with its own figures:

==========================  ===========================================================
figure                      content (paper figure it emulates)
==========================  ===========================================================
``dte*.png``                DTE over a few mesh cycles and over one gear turn (Figs. 9-10)
``waterfall_<signal>*.png`` log-amplitude spectra versus the parameter, k·GMF and m·BPF
                            marked, labelled peaks, dominant GMF harmonic starred
                            (DTE: Fig. 11; 1b1 LOA: Figs. 12, 16, 20; 1b1 OLOA: 17, 24)
``gmf_harmonics*.png``      amplitude of each GMF harmonic of the 1b1 LOA force versus the
                            parameter, dominant one circled (Fig. 13's statement)
``orbits*.png``             centre orbits of bearings 1b1 and 2b1 over one ball-pass cycle,
                            clearance circle dashed (Figs. 7, 14, 18)
==========================  ===========================================================

For a speed sweep the spectra are drawn versus shaft order (so the GMF lines stay put).
"""

from __future__ import annotations

import html
import io
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_bytes, atomic_write_text
from cmsim.datasets.manifest import RECORDS_DIR, read_rows, read_spec
from cmsim.datasets.report_digest import _digest, _dominant, _n_harm, _read_run
from cmsim.datasets.sweep_plots import plot_orbit_family, plot_trace_family
from cmsim.errors import ParameterError, check_range
from cmsim.losses.plots import run_loss_rows, run_losses_figure
from cmsim.spectra._checks import positive_int
from cmsim.spectra.waterfall import plot_family_waterfall, plot_harmonic_trend

__all__ = ["ReportResult", "build_report", "sweep_run_files", "sweep_failures", "DEFAULT_SIGNALS",
           "SWEEP_AXES"]

#: Signals whose spectra are drawn as waterfalls by default.
DEFAULT_SIGNALS = ("dte_um", "F_1b1_loa", "F_1b1_oloa")

#: Candidate sweep parameters, in order of precedence, with their axis labels.
SWEEP_AXES = {"torque_nm": "Torque [N·m]", "speed_rpm": "Speed [rpm]",
              "friction": "Mesh friction coefficient [-]", "clearance_um": "Clearance [µm]"}

_UNITS = {"torque_nm": "N·m", "speed_rpm": "rpm", "friction": "friction", "clearance_um": "µm"}
_SIGNAL_TITLES = {"dte_um": "DTE along the line of action",
                  "dte": "DTE (angle)"}
_DPI = 110
#: Folder of runs saved by hand (``Run.save``) or by cmsim before sweeps wrote ``records/``.
_RUNS_DIR = "runs"


@dataclass(frozen=True)
class ReportResult:
    """What :func:`build_report` wrote.

    Attributes
    ----------
    html : str
        Path of ``report.html``.
    figures : tuple of str
        PNG file names (in the same directory).
    runs : tuple of dict
        Per run: ``name``, ``file``, ``speed_rpm``, ``torque_nm``, ``friction``,
        ``clearance_m``, ``seed``, ``dominant_gmf_harmonic`` (of ``dominant_signal``, None
        for bearing rigs), ``dominant_gmf_amplitude``, ``load_s``, ``spectra_s``.
    sweep_axis : str
        Key of :data:`SWEEP_AXES` used as the parameter.
    dominant_signal : str or None
        Signal whose dominant GMF harmonic is reported.
    timing_s : dict of str to float
        ``load``, ``spectra``, ``plot``, ``write``, ``total`` (report generation, s) and
        ``integration`` (sum of the runs' ``meta["wall_s"]``, the simulation that made them).
    failed : tuple of dict
        The sweep's grid points that have no run (:func:`sweep_failures`): ``name``, their
        settings and ``error``.
    """

    html: str
    figures: tuple
    runs: tuple
    sweep_axis: str
    dominant_signal: str | None
    timing_s: dict
    failed: tuple = ()

    def to_dict(self):
        """JSON-ready dict (timings flattened as ``<key>_s``)."""
        out = {"html": self.html, "figures": list(self.figures), "runs": list(self.runs),
               "n_runs": len(self.runs), "failed": list(self.failed),
               "n_failed": len(self.failed), "sweep_axis": self.sweep_axis,
               "dominant_signal": self.dominant_signal}
        out.update({f"{k}_s": v for k, v in self.timing_s.items()})
        return out


def sweep_run_files(sweep_dir):
    """Run files of a sweep: the manifest's ok records in index order, else
    ``records/*.npz`` (or ``runs/*.npz``: runs saved by hand, or by an older cmsim)."""
    d = Path(sweep_dir)
    if not d.is_dir():
        raise ParameterError(f"sweep directory {d} does not exist (or is not a directory)")
    rows = read_rows(d) if (d / RECORDS_DIR).is_dir() else None
    if rows is not None:
        channels = (read_spec(d) or {}).get("spec", {}).get("channels")
        if channels is not None:
            raise ParameterError(f"{d} is a dataset of sensor channels ({', '.join(channels)}); "
                                 f"the report draws the full runs a sweep keeps (a spec "
                                 f"without channels, e.g. cmsim sweep)")
        rows = rows[rows["status"] == "ok"]
        files = [f for f in (d / p for p in rows["path"]) if f.is_file()]
    else:
        files = sorted((d / RECORDS_DIR).glob("*.npz")) or sorted((d / _RUNS_DIR).glob("*.npz"))
    if not files:
        failed = sweep_failures(d)
        why = (f"; {len(failed)} failed: " + "; ".join(f"{f['name']}: {f['error']}"
                                                         for f in failed)) if failed else ""
        raise ParameterError(f"{d} holds no finished runs (expected {d / RECORDS_DIR}/*.npz)"
                             f"{why}")
    return files


#: Manifest columns of the settings a failed grid point is listed with.
_FAILED_SETTINGS = ("speed_rpm", "torque_nm", "friction", "clearance_m", "radial_load_n")


def sweep_failures(sweep_dir):
    """The grid points of a sweep that failed (their manifest rows with status ``failed``).

    Parameters
    ----------
    sweep_dir : str or path-like
        The sweep directory.

    Returns
    -------
    list of dict
        Per failed point, in index order: ``name`` (record id), the settings of
        :data:`_FAILED_SETTINGS` it has, and ``error`` (one line); empty without a manifest.
    """
    d = Path(sweep_dir)
    rows = read_rows(d) if (d / RECORDS_DIR).is_dir() else None
    if rows is None:
        return []
    out = []
    for row in rows[rows["status"] == "failed"].to_dict("records"):
        point = {"name": str(row["record_id"])}
        point.update({k: float(row[k]) for k in _FAILED_SETTINGS
                      if k in row and row[k] is not None and row[k] == row[k]})
        point["error"] = " ".join(str(row.get("error") or "unknown error").split())
        out.append(point)
    return out


# ---------------------------------------------------------------------- sweep axis and groups
def _sweep_axis(digests):
    for key in SWEEP_AXES:
        if len({d[key] for d in digests}) > 1:
            return key
    return "torque_nm"


def _groups(digests, axis):
    others = [k for k in SWEEP_AXES if k != axis]
    groups = {}
    for d in digests:
        groups.setdefault(tuple(d[k] for k in others), []).append(d)
    out = []
    for key, members in groups.items():
        members.sort(key=lambda m: m[axis])
        out.append((dict(zip(others, key)), members))
    return out


# ---------------------------------------------------------------------- figures
def _save(fig, path):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI, metadata={"Software": None})
    atomic_write_bytes(path, buf.getvalue())


def _common_axis(members, signal, in_orders):
    """Spectra of ``signal`` on one axis (Hz, or shaft orders for a speed sweep)."""
    axes = []
    for m in members:
        f, a = m["spectra"][signal]
        axes.append((f / m["shaft_hz"] if in_orders else f, a))
    ref = min(axes, key=lambda fa: fa[0][1] - fa[0][0])[0]
    hi = min(f[-1] for f, _ in axes)
    ref = ref[ref <= hi]
    amps = [a[: ref.size] if f.size >= ref.size and np.allclose(f[: ref.size], ref)
            else np.interp(ref, f, a) for f, a in axes]
    return ref, amps


def _waterfall(members, signal, axis, in_orders, f_show, dyn_db, title):
    freq, amps = _common_axis(members, signal, in_orders)
    m0 = members[0]
    fam = dict(m0["families"][signal])
    peaks, dominant = [], []
    for m in members:
        p = m["peaks"][signal]
        if in_orders:
            p = p.assign(frequency_hz=p["frequency_hz"] / m["shaft_hz"])
        peaks.append(p)
        h = m["harmonics"].get(signal)
        dominant.append(int(np.nanargmax(h[:_n_harm(m)])) + 1 if h is not None else None)
    if in_orders:
        fam = {k: v / m0["shaft_hz"] for k, v in fam.items()}
    fig = plot_family_waterfall(
        freq, amps, [m[axis] for m in members], families=fam, peaks=peaks,
        dominant=dominant if fam.get("GMF") else None, value_label=SWEEP_AXES[axis],
        amplitude_unit=m0["units"][signal], max_freq=freq[-1], dynamic_range_db=dyn_db,
        title=title, freq_unit="order" if in_orders else "Hz")
    return fig


# ---------------------------------------------------------------------- HTML
_CSS = """
body { font-family: system-ui, sans-serif; max-width: 1250px; margin: 1.5em auto;
       padding: 0 1em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 2em; border-bottom: 1px solid #ccc; }
figure { margin: 1.2em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; margin-top: 0.3em; }
table { border-collapse: collapse; font-size: 0.85em; margin: 0.5em 0; }
th, td { border: 1px solid #ccc; padding: 2px 7px; text-align: right; }
th { background: #f0f0f0; } td.l { text-align: left; }
dl { display: grid; grid-template-columns: max-content auto; gap: 2px 12px; font-size: 0.95em; }
dt { font-weight: 600; } summary { cursor: pointer; font-weight: 600; margin: 0.6em 0; }
"""


def _fmt(v, spec=".4g"):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return format(v, spec) if isinstance(v, (int, float)) else html.escape(str(v))


def _table(header, rows, left=()):
    out = ["<table><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>"]
    for r in rows:
        cells = "".join(f'<td class="l">{c}</td>' if j in left else f"<td>{c}</td>"
                        for j, c in enumerate(r))
        out.append(f"<tr>{cells}</tr>")
    return "\n".join(out) + "</table>"


def _describe_group(fixed, axis):
    parts = []
    for k, v in fixed.items():
        if k == "speed_rpm":
            parts.append(f"{v:g} rpm")
        elif k == "torque_nm":
            parts.append(f"{v:g} N·m")
        elif k == "friction" and v is not None:
            parts.append(f"mesh friction {v:g}")
        elif k == "clearance_um":
            parts.append(f"bearing clearance {v:g} µm" if v >= 0 else f"preload {-v:g} µm")
    return ", ".join(parts)


# ---------------------------------------------------------------------- main entry
def build_report(sweep_dir, signals=DEFAULT_SIGNALS, *, top_n=8, max_freq_hz=None,
                 n_mesh_cycles=5, dynamic_range_db=60.0, progress=False):
    """Write ``report.html`` and its PNG figures into a sweep directory.

    Parameters
    ----------
    sweep_dir : str or path-like
        Directory written by ``cmsim sweep`` (:func:`cmsim.datasets.generate_dataset` of a
        spec without channels), or any directory with ``runs/*.npz`` saved from
        :func:`cmsim.dynamics.simulate`.
    signals : sequence of str
        Signals drawn as waterfalls and tabulated (must exist in every run).
    top_n : int
        Largest labelled peaks listed per run and signal (1-100).
    max_freq_hz : float, optional
        Upper frequency of the waterfalls, Hz; default 6.5·GMF (gear rigs) or 10.5·BPF.
    n_mesh_cycles : int
        Mesh cycles in the short DTE panel (1-100).
    dynamic_range_db : float
        Depth of each waterfall line below the overall maximum, dB (> 0).
    progress : bool
        tqdm bar over the runs on stderr.

    Returns
    -------
    ReportResult
    """
    from tqdm import tqdm

    start = time.perf_counter()
    out_dir = Path(sweep_dir)
    files = sweep_run_files(out_dir)
    if isinstance(signals, str):
        signals = (signals,)
    signals = tuple(signals)
    if not signals:
        raise ParameterError("signals must name at least one signal")
    top_n = positive_int("top_n", top_n, lo=1, hi=100)
    n_mesh_cycles = positive_int("n_mesh_cycles", n_mesh_cycles, lo=1, hi=100)
    dyn = check_range("dynamic_range_db", dynamic_range_db, 0.0, 200.0, lo_open=True, unit="dB")

    if signals == DEFAULT_SIGNALS:
        # the defaults name what the rig has: a bearing rig has no DTE
        present = _read_run(files[0]).signals
        signals = tuple(s for s in DEFAULT_SIGNALS if s in present) or signals
    digests = []
    for path in tqdm(files, disable=not progress, desc="report", unit="run"):
        digests.append(_digest(path, signals, top_n, max_freq_hz, n_mesh_cycles))
    axis = _sweep_axis(digests)
    in_orders = axis == "speed_rpm"
    dom_signal = digests[0]["dominant_signal"]
    f_show = digests[0]["f_show"]
    groups = _groups(digests, axis)
    figures, sections = [], []

    plotting = tqdm(disable=not progress, desc="figures", unit="fig")

    def emit(fig, name):
        _save(fig, out_dir / name)
        figures.append(name)
        plotting.update(1)
        return name

    t_plot0 = time.perf_counter()
    for gi, (fixed, members) in enumerate(groups):
        sfx = f"_g{gi + 1}" if len(groups) > 1 else ""
        sections.append(_group_section(gi, fixed, members, axis, in_orders, signals,
                                       dom_signal, f_show, dyn, n_mesh_cycles, sfx, emit))
    if any(d["losses"] for d in digests):
        sections.append(_losses_section([d for d in digests if d["losses"]], emit))
    plotting.close()
    t_plot1 = time.perf_counter()

    runs = []
    for d in digests:
        k, a = _dominant(d, dom_signal)
        runs.append({"name": d["name"], "file": d["file"], "speed_rpm": d["speed_rpm"],
                     "torque_nm": d["torque_nm"], "friction": d["friction"],
                     "clearance_m": d["clearance_m"], "seed": d["seed"],
                     "dominant_gmf_harmonic": k, "dominant_gmf_amplitude": a,
                     "load_s": d["load_s"], "spectra_s": d["spectra_s"]})
    failed = sweep_failures(out_dir)
    page = _html_page(out_dir, digests, runs, axis, signals, dom_signal, sections, top_n,
                      f_show, in_orders, failed)
    html_path = out_dir / "report.html"
    atomic_write_text(html_path, page)
    end = time.perf_counter()
    timing = {"load": sum(d["load_s"] for d in digests),
              "spectra": sum(d["spectra_s"] for d in digests),
              "plot": t_plot1 - t_plot0, "write": end - t_plot1, "total": end - start,
              "integration": sum(d["integration_s"] for d in digests)}
    return ReportResult(html=str(html_path), figures=tuple(figures), runs=tuple(runs),
                        sweep_axis=axis, dominant_signal=dom_signal, timing_s=timing,
                        failed=tuple(failed))


def _group_section(gi, fixed, members, axis, in_orders, signals, dom_signal, f_show, dyn,
                   n_mesh_cycles, sfx, emit):
    """Figures of one group and their HTML (captions)."""

    values = [m[axis] for m in members]
    vlabel = SWEEP_AXES[axis]
    m0 = members[0]
    parts = [f"<h2>{'Group ' + str(gi + 1) + ': ' if sfx else ''}"
             f"{html.escape(_describe_group(fixed, axis))}</h2>"]
    n_fig = [0]

    def figure(name, caption):
        n_fig[0] += 1
        parts.append(f'<figure><img src="{html.escape(name)}" alt="{html.escape(caption)}">'
                     f"<figcaption><b>Figure {n_fig[0]}.</b> {caption}</figcaption></figure>")

    if "dte_short" in m0:
        panels = [
            {"t": [m["dte_short"][0] for m in members], "y": [m["dte_short"][1] for m in members],
             "ylabel": "DTE [µm]", "period_s": 1.0 / m0["gmf_hz"],
             "title": f"(a) last {n_mesh_cycles} mesh cycles (dotted: mesh period "
                      f"{1e3 / m0['gmf_hz']:.3f} ms)"}] + [
            {"t": [m["dte_turn"][0] for m in members], "y": [m["dte_turn"][1] for m in members],
             "ylabel": "DTE − mean [µm]", "period_s": 1.0 / m0["bpf_hz"]["1b1"]
             if "1b1" in m0.get("bpf_hz", {}) else None, "runs": [i],
             "title": f"({'bc'[j]}) one input-shaft turn at {values[i]:g} "
                      f"{_UNITS[axis]}, mean removed (dotted: ball-pass period of 1b1)"}
            for j, i in enumerate(sorted({0, len(members) - 1}))]
        name = emit(plot_trace_family(panels, values, value_label=vlabel,
                                      title="Dynamic transmission error"), f"dte{sfx}.png")
        figure(name, "Dynamic transmission error r<sub>b1</sub>·(θ<sub>1G1</sub> − "
               "(Z<sub>2</sub>/Z<sub>1</sub>)·θ<sub>2G1</sub>) in µm along the line of action "
               "(paper Figs. 9-10; there the mean rises with torque and the ball-pass "
               "modulation shows at low torque).")
    for s in signals:
        unit = members[0]["units"][s]
        what = _SIGNAL_TITLES.get(s, f"Force of bearing {s.split('_')[1]} on the housing, "
                                     f"{s.split('_')[-1].upper()}" if s.startswith("F_") else s)
        title = f"{what} — amplitude spectra [dB re 1 {unit}]"
        name = emit(_waterfall(members, s, axis, in_orders, f_show, dyn, title),
                    f"waterfall_{s}{sfx}.png")
        figure(name, f"Waterfall of <code>{html.escape(s)}</code> ({html.escape(what)}): "
               f"20·log<sub>10</sub> of the flat-top amplitude spectrum (dB re 1 {unit}), one "
               f"line per {html.escape(vlabel)}, lowest value at the bottom, each line shifted "
               f"up by the stated offset. Blue dashed: k·GMF; red ticks: m·BPF of the bearing; "
               f"markers: labelled peaks (blue ▼ k·GMF, red • k·GMF±m·BPF, orange ▲ m·BPF); "
               f"gold ★: dominant GMF harmonic."
               + (" Frequency axis in shaft orders (speed sweep)." if in_orders else ""))
    if dom_signal and len(members) > 1:
        n_h = _n_harm(m0)
        h = np.array([m["harmonics"][dom_signal][:n_h] for m in members])
        name = emit(plot_harmonic_trend(values, h, value_label=vlabel,
                                        amplitude_unit=members[0]["units"][dom_signal],
                                        title=f"GMF harmonics of {dom_signal}"),
                    f"gmf_harmonics{sfx}.png")
        figure(name, f"Amplitude of the first {n_h} GMF harmonics of "
               f"<code>{dom_signal}</code> versus {html.escape(vlabel)}; circled and numbered: "
               f"the dominant harmonic (paper: 2nd at low torque, 5th at high torque).")
    if m0["orbits"]:
        names = list(m0["orbits"])
        orbits = [[m["orbits"][b] for m in members] for b in names]
        clear = [m0["clearance_m"]] * len(names)
        name = emit(plot_orbit_family(orbits, values, bearing_names=names, clearances_m=clear,
                                      value_label=vlabel,
                                      title="Bearing centre orbits over the last ball-pass cycle"),
                    f"orbits{sfx}.png")
        figure(name, "Centre orbits of bearings " + ", ".join(names) + " over the last "
               "ball-pass cycle of each run (open circle: start), in µm; dashed circle: the "
               "radial clearance (paper Figs. 7, 14, 18). Bottom: the lowest and highest "
               f"{html.escape(vlabel.split(' [')[0].lower())} about their mean "
               "(paper Figs. 8, 15).")
    return "\n".join(parts)


def _losses_section(digests, emit):
    """Loss breakdown of the runs made with every loss on (``simulate(losses=...)``)."""
    digests = sorted(digests, key=lambda d: (d["speed_rpm"], d["torque_nm"]))
    labels = [f"{d['speed_rpm']:g} rpm\n{d['torque_nm']:g} N·m" for d in digests]
    losses = [d["losses"] for d in digests]
    name = emit(run_losses_figure(losses, labels), "losses.png")
    rows = run_loss_rows(losses)
    keys = ["windage", "meshing", "oil_jet", "bearing_viscous", "bearing_load",
            "tooth_friction", "damping"]
    table = _table(["run", "speed [rpm]", "torque [N·m]"] + [f"{k.replace('_', ' ')} [W]"
                                                             for k in keys]
                   + ["total [W]", "efficiency [%]", "balance closure [%]"],
                   [(d["name"], _fmt(d["speed_rpm"], "g"), _fmt(d["torque_nm"], "g"),
                     *(_fmt(r[k], ".3g") for k in keys), _fmt(r["total"], ".4g"),
                     _fmt(100 * r["efficiency"], ".3f"),
                     "—" if r["closure"] is None else _fmt(100 * r["closure"], ".3f"))
                    for d, r in zip(digests, rows)], left=(0,))
    return "\n".join([
        "<h2>Power losses</h2>",
        f'<figure><img src="{html.escape(name)}" alt="loss breakdown"><figcaption>Loss '
        "power by source of each run made with every loss on: windage and meshing (pumping) "
        "torques of paper 000 eq. 25-28, oil jet (eq. 30), the bearings' viscous and load "
        "torques (Harris–Palmgren), the tooth friction with the mixed-lubrication "
        "coefficient along the path (paper 004 eq. 21) and the damping the run dissipates, "
        "both from the run's own power balance (input = output + losses + change of stored "
        "energy; its closure is listed). Right: efficiency of each run.</figcaption>"
        "</figure>", table])


def _failed_section(failed):
    """HTML of the grid points without a run (nothing when every point ran)."""
    if not failed:
        return []
    columns = [k for k in _FAILED_SETTINGS if any(k in f for f in failed)]
    rows = [(html.escape(f["name"]), *(_fmt(f.get(k), "g") for k in columns),
             html.escape(f["error"])) for f in failed]
    return ["<h2>Failed grid points (no run, left out of every figure and table)</h2>",
            _table(["run", *columns, "error"], rows, left=(0, len(columns) + 1))]


def _html_page(out_dir, digests, runs, axis, signals, dom_signal, sections, top_n, f_show,
               in_orders, failed=()):
    d0 = digests[0]
    values = sorted({d[axis] for d in digests})
    speeds = sorted({d["speed_rpm"] for d in digests})
    missing = (f"; {len(failed)} of {len(digests) + len(failed)} grid points failed: "
               + ", ".join(html.escape(f["name"]) for f in failed)) if failed else ""
    head = [("Rig", html.escape(d0["rig_name"])),
            ("Runs", f"{len(digests)} (files in <code>"
                     f"{html.escape(d0['file'].split('/')[0])}/</code>){missing}"),
            ("Sweep parameter", f"{html.escape(SWEEP_AXES[axis])}: "
                                f"{', '.join(f'{v:g}' for v in values)}"),
            ("Speed", ", ".join(f"{s:g} rpm" for s in speeds)),
            ("GMF", f"{d0['gmf_hz']:.2f} Hz at {d0['speed_rpm']:g} rpm" if d0["gmf_hz"]
             else "— (no gears)"),
            ("Record", f"{d0['duration_s']:g} s at {d0['fs_hz']:g} Hz "
                       f"(resolution {1.0 / d0['duration_s']:.3g} Hz, flat-top window)"),
            ("Signals", ", ".join(f"<code>{html.escape(s)}</code>" for s in signals)),
            ("Waterfall span", f"0-{f_show:.0f} Hz" + (" (shown in orders)" if in_orders else ""))]
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             f"<title>cmsim sweep report — {html.escape(out_dir.name)}</title>",
             f"<style>{_CSS}</style></head><body>",
             f"<h1>cmsim sweep report — {html.escape(out_dir.name)}</h1>",
             "<p>Simulated vibration of the spur-gear transmission (19-DOF model of "
             "Fernandez-del-Rincon et al.). Every figure and table below is computed from the "
             "run files alone; regenerate with <code>cmsim report "
             f"{html.escape(out_dir.name)}</code>.</p>",
             "<dl>" + "".join(f"<dt>{k}</dt><dd>{v}</dd>" for k, v in head) + "</dl>",
             *_failed_section(failed)]
    if dom_signal:
        rows = [(r["name"], _fmt(r["speed_rpm"], "g"), _fmt(r["torque_nm"], "g"),
                 _fmt(r["friction"], "g"), _fmt(r["clearance_m"] * 1e6, "g"), r["seed"],
                 f"{r['dominant_gmf_harmonic']}×GMF", _fmt(r["dominant_gmf_amplitude"], ".4g"))
                for r in runs]
        parts += ["<h2>Dominant GMF harmonic per run</h2>",
                  f"<p>Largest of the GMF harmonics below {f_show:.0f} Hz in "
                  f"<code>{dom_signal}</code>.</p>",
                  _table(["run", "speed [rpm]", "torque [N·m]", "friction [-]",
                          "clearance [µm]", "seed", "dominant",
                          f"amplitude [{d0['units'][dom_signal]}]"], rows, left=(0,))]
    parts += sections
    parts.append(f"<h2>Labelled peaks (top {top_n} per run, whole spectrum)</h2>")
    for j, s in enumerate(signals):
        unit = d0["units"][s]
        rows = []
        for d in digests:
            p = d["peaks"][s].sort_values("amplitude", ascending=False).head(top_n)
            for r in p.itertuples():
                rows.append((d["name"], _fmt(d[axis], "g"), _fmt(r.frequency_hz, ".2f"),
                             _fmt(r.amplitude, ".4g"), _fmt(float(r.db_re_carrier), ".1f"),
                             html.escape(r.label)))
        open_ = " open" if j == 0 else ""
        parts.append(f"<details{open_}><summary><code>{html.escape(s)}</code> "
                     f"({len(rows)} rows)</summary>"
                     + _table(["run", SWEEP_AXES[axis], "frequency [Hz]",
                               f"amplitude [{unit}]", "dB re carrier", "label"], rows,
                              left=(0, 5)) + "</details>")
    parts.append("<p style='font-size:0.8em;color:#666'>Labels: k·GMF ± m·BPF ± n·fr "
                 "(GMF gear mesh, BPF ball pass of the bearing, fr shaft rate); “?” = "
                 "significant but unlabelled. dB re carrier: relative to the GMF harmonic "
                 "(k) the peak belongs to.</p></body></html>")
    return "\n".join(parts) + "\n"
