"""HTML page of a calibration: the baseline against its twin, the path, the fit quality."""

from __future__ import annotations

import base64
import html
import io
from pathlib import Path

import numpy as np
from scipy.signal import welch

from cmsim._io import atomic_write_text
from cmsim.machine.machine import model_force

__all__ = ["write_calibration_report", "detectability_rows"]


def _psd_db(x, fs, nperseg):
    f, p = welch(x, fs, nperseg=min(nperseg, x.size))
    return f, 10.0 * np.log10(np.maximum(p, 1e-30))


def _figure(machine, records, seed):
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fs = machine.fs_hz
    x = np.concatenate([r.signal for r in records])
    force, edge, n = model_force(machine.rig, machine.op, machine.model_signal, fs,
                                 min(4.0, x.size / fs), seed)
    y = machine.sensor_signal(force, edge, n, seed)
    nper = int(fs)                                  # 1-Hz bins
    fig, axes = plt.subplots(2, 1, figsize=(9, 7))
    axes[0].plot(*_psd_db(x, fs, nper), lw=0.6, color="k", label="baseline")
    axes[0].plot(*_psd_db(y, fs, nper), lw=0.6, color="tab:red", alpha=0.8, label="twin")
    unit = _unit_symbol(machine.unit)
    axes[0].set_ylabel(f"PSD, dB re 1 {unit}²/Hz")
    axes[0].set_title("baseline and its twin (new seeds)")
    axes[0].legend(loc="upper right")
    f = np.asarray(machine.path.freq_hz)
    axes[1].semilogy(f, machine.path.gain, color="tab:blue")
    axes[1].set_ylabel(f"|H|, {unit}/N")
    axes[1].set_xlabel("frequency, Hz")
    axes[1].set_title(f"transfer path {machine.path.source} → {machine.channel}")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode()


def _unit_symbol(unit):
    """The unit's symbol for an axis label: its first word (``"g (believed)"`` → ``g``, so
    a label reads ``g²/Hz``, not ``g (believed)²/Hz``), ``unit`` when none is known."""
    words = str(unit or "").split()
    return words[0] if words and words[0].lower() != "unknown" else "unit"


def detectability_rows(detectable, components=None):
    """The detectability table in words: ``(fault, where, seen from)`` per row of
    :func:`cmsim.discrepancy.judge.detectability` (sizes in mm, amplitudes as they are).

    Parameters
    ----------
    detectable : sequence of dict
        Its rows.
    components : dict, optional
        Model component → the machine's name for it.

    Returns
    -------
    list of (str, str, str)
    """
    out = []
    for d in detectable:
        where = (components or {}).get(d["component"], d["component"]) or "-"
        unit, k = ("mm", 1e3) if d["parameter"].endswith("_m") else ("", 1.0)
        label = d["parameter"].rsplit("_", 1)[0] if unit else d["parameter"]
        seen = ("not named at any size up to "
                f"{k * d['largest_tried']:.3g}{' ' + unit if unit else ''}"
                if d["smallest"] is None else
                f"{label.replace('_', ' ')} about {k * d['smallest']:.2g}"
                f"{' ' + unit if unit else ''}")
        out.append((d["cause"].replace("_", " "), str(where).replace("_", "-"), seen))
    return out


def write_calibration_report(machine, records, out_dir, seed=0, detectable=(),
                             consistency=None):
    """Write ``calibration.html`` into ``out_dir``; returns its path.

    Parameters
    ----------
    machine : Machine
        The calibrated machine.
    records : sequence of MeasuredRecord
        The baseline records it was calibrated on.
    out_dir : str or Path
        Directory (created if missing).
    seed : int
        Seed of the twin drawn in the figure.
    detectable : sequence of dict
        :func:`cmsim.discrepancy.judge.detectability` of the machine.
    consistency : dict, optional
        :func:`cmsim.discrepancy.judge.baseline_consistency` of the machine.

    Returns
    -------
    Path
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    png = _figure(machine, records, seed)
    q = machine.fit_quality
    rows = "".join(
        f"<tr><td>{html.escape(k)}</td><td>{machine.spread.get(k, (np.nan,))[0]:.3g}</td>"
        f"<td>{machine.spread.get(k, (0, np.nan))[1]:.3g}</td><td>{z:+.2f}</td></tr>"
        for k, z in sorted((q.get("z") or {}).items(), key=lambda kv: -abs(kv[1])))
    notes = "".join(f"<li>{html.escape(n)}</li>" for n in machine.notes)
    on = "".join(f"<li>{html.escape(c)}</li>" for c in machine.calibrated_on)
    det = "".join(f"<tr><td>{html.escape(a)}</td><td>{html.escape(b)}</td>"
                  f"<td>{html.escape(c)}</td></tr>"
                  for a, b, c in detectability_rows(detectable, machine.components))
    cons = ""
    if consistency is not None:
        moved = (" — not stationary: healthy records may read as departures"
                 if consistency["departs"] else "")
        cons = (f"<p>The baseline judged against itself (its odd segments against its even "
                f"ones, as compare judges a record): χ² per feature "
                f"{consistency['chi2_per_feature']:.2f}, worst "
                f"{html.escape(str(consistency['worst_feature']))} z "
                f"{consistency['worst_z']:+.1f}{moved}.</p>")
    wobble = ("not identifiable" if machine.speed_wobble is None
              else f"{100 * machine.speed_wobble:.2f} % rms")
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>cmsim calibrate</title>
<style>body{{font-family:sans-serif;max-width:1000px;margin:auto}}td,th{{padding:2px 8px}}
</style></head><body><h1>Machine {html.escape(machine.name)}</h1>
<p>Channel {html.escape(machine.channel)} at {machine.fs_hz:g} Hz, model signal
{html.escape(machine.model_signal)}, {machine.op.speed_rpm:.2f} rpm, speed wobble
{wobble}; {len(machine.background.lines)} background lines.</p>
<ul>{on}</ul><ul>{notes}</ul>
<img src="data:image/png;base64,{png}" alt="baseline and twin">
<h2>What this sensor can see</h2>
<p>The smallest size of each fault that a comparison against this machine names, read on
its signature library (the baseline with the fault's change at the calibrated path's gain,
a 10-s record's fit segments; a noiseless estimate).</p>
<table><tr><th>fault</th><th>where</th><th>seen from</th></tr>{det}</table>
{cons}
<h2>Twin against held-out baseline segments</h2>
<p>Worst z {q.get('worst_z', float('nan')):.2f} ({html.escape(str(q.get('worst_feature')))}),
χ² per feature {q.get('chi2_per_feature', float('nan')):.2f}; z = (twin − baseline) / the
baseline's own segment-to-segment spread.</p>
<table><tr><th>feature</th><th>baseline mean</th><th>spread</th><th>z</th></tr>{rows}</table>
</body></html>"""
    path = out / "calibration.html"
    atomic_write_text(path, page)
    return path
