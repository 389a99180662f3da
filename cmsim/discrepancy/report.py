"""HTML report of a comparison: the finding in words, measured and simulated spectra and
envelope spectra overlaid before and after, the families marked, the causes ranked."""

from __future__ import annotations

import base64
import html
import io
import json
import textwrap
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_text
from cmsim.discrepancy.compare import feature_label
from cmsim.features.envelope import demodulated_spectrum
from cmsim.spectra.plots import agg_figure

__all__ = ["write_report"]


def _norm_spectrum(x, fs):
    """(freq, level dB re the median level) of a Hann amplitude spectrum (scale-free)."""
    x = np.asarray(x, dtype=float)
    n = min(x.size, int(fs))                      # 1-Hz resolution, averaged
    k = max(1, x.size // n)
    win = np.hanning(n)
    p = np.mean([np.abs(np.fft.rfft((s - s.mean()) * win)) ** 2
                 for s in np.reshape(x[:k * n], (k, n))], axis=0)
    amp = np.sqrt(p)
    return np.fft.rfftfreq(n, 1 / fs), 20 * np.log10(np.maximum(amp, 1e-30) / np.median(amp))


#: Envelope families marked on the report's envelope spectra: (attribute, label, colour).
FAMILIES = (("bpfo_hz", "BPFO", "tab:blue"), ("bpfi_hz", "BPFI", "tab:green"),
            ("bsf_hz", "2×BSF", "tab:purple"))


def _envelope(x, fs, bearing, band):
    spec, band = demodulated_spectrum(np.asarray(x, dtype=float), fs, [bearing], band)
    amp = np.asarray(spec.amplitude)
    return np.asarray(spec.freq_hz), 20 * np.log10(np.maximum(amp, 1e-30) / np.median(amp)), band


def _figure(spectra, title_after):
    fs = spectra["fs_hz"]
    bearing = spectra.get("bearing")
    rows = 2 if bearing is None else 3
    fig = agg_figure((9, 3.2 * rows))
    axes = fig.subplots(rows, 1)
    m = _norm_spectrum(spectra["measured"], fs)
    for ax, key, title in ((axes[0], "nominal", "before: nominal model"),
                           (axes[1], "fitted", title_after)):
        ax.plot(*m, lw=0.6, color="k", label="measured")
        if spectra.get(key) is not None:
            ax.plot(*_norm_spectrum(spectra[key], fs), lw=0.6, color="tab:red", alpha=0.8,
                    label="simulated")
        ax.set_title("\n".join(textwrap.wrap(title, 90)), fontsize=9)
        ax.set_ylabel("dB re median level")
        ax.set_xlabel("frequency, Hz")
        ax.legend(loc="upper right")
    if bearing is not None:
        ax = axes[2]
        f, a, band = _envelope(spectra["measured"], fs, bearing, None)
        top = 4.5 * max(bearing.bpfi_hz, 2 * bearing.bsf_hz)
        sel = f <= top
        ax.plot(f[sel], a[sel], lw=0.7, color="k", label="measured")
        for key, colour in (("nominal", "tab:gray"), ("fitted", "tab:red")):
            if spectra.get(key) is not None:
                fe, ae, _ = _envelope(spectra[key], fs, bearing, band)
                ax.plot(fe[fe <= top], ae[fe <= top], lw=0.7, color=colour, alpha=0.8,
                        label=key)
        for attr, label, colour in FAMILIES:
            f0 = getattr(bearing, attr) * (2.0 if attr == "bsf_hz" else 1.0)
            for k in range(1, 4):
                ax.axvline(k * f0, color=colour, lw=0.8, ls="--",
                           label=label if k == 1 else None)
        ax.set_title(f"envelope spectrum, {spectra.get('bearing_name') or 'sensor'} bearing, "
                     f"band {band[0]:.0f}-{band[1]:.0f} Hz (the measured record's)")
        ax.set_xlabel("frequency, Hz")
        ax.set_ylabel("dB re median level")
        ax.legend(loc="upper right", fontsize=7, ncol=2)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    return base64.b64encode(buf.getvalue()).decode()


def write_report(comparison, out_dir):
    """Write ``compare.html`` (and ``compare.json``) into ``out_dir``; returns the HTML path.

    Parameters
    ----------
    comparison : Comparison
        Result of :func:`cmsim.discrepancy.compare`.
    out_dir : str or Path
        Directory (created if missing).

    Returns
    -------
    Path
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    d = comparison.to_dict()
    after = ("after: extended by " + d["finding"] + _in_words(d["parameters"], " (", ")")
             if d["finding"] not in ("none", "unexplained") else
             "after: no extension (" + ("no significant discrepancy" if d["finding"] == "none"
                                       else "no cause explains the departure") + ")")
    named = (f" on {html.escape(str(d['component']))}" if d["component"] else "") + (
        html.escape(_in_words(d["parameters"], " (", ")")))
    png = _figure(comparison.spectra, after)
    rows = "".join(f"<tr><td>{html.escape(feature_label(x))}</td><td>{x['measured']:.3g}</td>"
                   f"<td>{x['simulated']:.3g}</td><td>{x['z']:.2f}</td></tr>"
                   for x in d["discrepancies"])
    causes = "".join(f"<tr><td>{html.escape(c['name'])}</td>"
                     f"<td>{html.escape(str(c['component'] or '—'))}</td>"
                     f"<td>{c['delta_chi2']:.1f}</td><td>{c['judged_on']}</td>"
                     f"<td>{c['delta_chi2_all']:.1f}</td>"
                     f"<td>{html.escape(_in_words(c['parameters']))}</td></tr>"
                     for c in d["causes"])
    not_judged = ("; spectral shape and levels not judged (no documented path): "
                  + html.escape(", ".join(d["not_judged"])) if d.get("not_judged") else "")
    ties = ("; near tie with " + html.escape(", ".join(
        t["name"] + (f" ({t['component']})" if t.get("component") else "")
        for t in d["near_ties"])) if d.get("near_ties") else "")
    departures = ("; departs from the model in " + html.escape(", ".join(d["departures"]))
                  if d.get("departures") else "")
    g = d["gain"]
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>cmsim compare</title>
<style>body{{font-family:sans-serif;max-width:1000px;margin:auto}}td,th{{padding:2px 8px}}
</style></head><body><h1>cmsim compare</h1>
<p><b>{html.escape(d['words'])}</b></p>
<p>Nominal model: {html.escape(d['mode'])}{not_judged}. Finding <b>{html.escape(d['finding'])}</b>
{named}{ties}{departures}; gain on
held-out segments: χ²/feature {g['before']:.3g} → {g['after']:.3g} (relative
{g['relative']:.2f}; a record like the model's own sits near {g['baseline_level']:g});
{d['simulations']} simulations, {d['wall_s']:.1f} s.</p>
<p>Record: {html.escape(_in_words(d['record']))}<br>Inferred:
{html.escape(_in_words(d['inferred']) or "nothing")}</p>
<img src="data:image/png;base64,{png}" alt="spectra">
<h2>Largest discrepancies (nominal model, fit segments)</h2>
<table><tr><th>feature</th><th>measured</th><th>simulated</th><th>z</th></tr>{rows}</table>
<h2>Causes, ranked</h2>
<table><tr><th>cause</th><th>component</th><th>Δχ² on its signature</th><th>features in it</th>
<th>Δχ² on all</th><th>parameters</th></tr>{causes}</table>
</body></html>"""
    path = out / "compare.html"
    atomic_write_text(path, page)
    atomic_write_text(out / "compare.json", json.dumps(_plain(d), indent=1))
    return path


def _in_words(values, before="", after=""):
    """A mapping as a reader reads it: ``size_m 0.0003, depth_m 0.0002`` (nested mappings
    in parentheses, numbers to 4 significant digits, None as "—"), between ``before`` and
    ``after``; "" for an empty one. The report shows no raw JSON (compare.json holds it)."""
    def one(v):
        if isinstance(v, dict):
            return "(" + _in_words(v) + ")"
        if isinstance(v, (list, tuple)):
            return ", ".join(one(x) for x in v)
        if isinstance(v, (float, np.floating)):
            return f"{float(v):.4g}"
        return "—" if v is None else str(v)
    text = ", ".join(f"{k} {one(v)}" for k, v in (values or {}).items())
    return f"{before}{text}{after}" if text else ""


def _plain(obj):
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    return obj
