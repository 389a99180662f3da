"""HTML report of a comparison: measured and simulated spectra overlaid before and after."""

from __future__ import annotations

import base64
import html
import io
import json
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_text

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


def _figure(spectra, title_after):
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    fs = spectra["fs_hz"]
    fig, axes = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    m = _norm_spectrum(spectra["measured"], fs)
    for ax, key, title in ((axes[0], "nominal", "before: nominal model"),
                           (axes[1], "fitted", title_after)):
        ax.plot(*m, lw=0.6, color="k", label="measured")
        if spectra.get(key) is not None:
            ax.plot(*_norm_spectrum(spectra[key], fs), lw=0.6, color="tab:red", alpha=0.8,
                    label="simulated")
        ax.set_title(title)
        ax.set_ylabel("dB re median level")
        ax.legend(loc="upper right")
    axes[1].set_xlabel("frequency, Hz")
    buf = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
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
    after = ("after: extended by " + d["finding"] + " " + json.dumps(d["parameters"])
             if d["finding"] != "none" else "after: no extension (no significant discrepancy)")
    png = _figure(comparison.spectra, after)
    rows = "".join(f"<tr><td>{html.escape(x['feature'])}</td><td>{x['measured']:.3g}</td>"
                   f"<td>{x['simulated']:.3g}</td><td>{x['z']:.2f}</td></tr>"
                   for x in d["discrepancies"])
    causes = "".join(f"<tr><td>{html.escape(c['name'])}</td><td>{c['component']}</td>"
                     f"<td>{c['score']:.3f}</td><td>{html.escape(json.dumps(c['parameters']))}"
                     f"</td></tr>" for c in d["causes"])
    g = d["gain"]
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>cmsim compare</title>
<style>body{{font-family:sans-serif;max-width:1000px;margin:auto}}td,th{{padding:2px 8px}}
</style></head><body><h1>cmsim compare</h1>
<p>Finding: <b>{html.escape(d['finding'])}</b> on {d['component']}
{html.escape(json.dumps(d['parameters']))}; gain on held-out segments: χ²/feature
{g['before']:.3g} → {g['after']:.3g} (relative {g['relative']:.2f});
{d['simulations']} simulations, {d['wall_s']:.1f} s.</p>
<p>Record: {html.escape(json.dumps(d['record']))}<br>Inferred: {html.escape(json.dumps(d['inferred']))}</p>
<img src="data:image/png;base64,{png}" alt="spectra">
<h2>Largest discrepancies (nominal model, fit segments)</h2>
<table><tr><th>feature</th><th>measured</th><th>simulated</th><th>z</th></tr>{rows}</table>
<h2>Causes, ranked</h2>
<table><tr><th>cause</th><th>component</th><th>score</th><th>parameters</th></tr>{causes}</table>
</body></html>"""
    path = out / "compare.html"
    atomic_write_text(path, page)
    atomic_write_text(out / "compare.json", json.dumps(_plain(d), indent=1))
    return path


def _plain(obj):
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    return obj
