"""HTML page of an :class:`~cmsim.diagnostics.harness.Evaluation`: scores, confusion matrix,
detection against severity, per-record answers and errors.

The figures (matplotlib, Agg canvas) are embedded as base64 PNG, so the page is one file,
written atomically (:func:`cmsim._io.atomic_write_text`).
"""

from __future__ import annotations

import base64
import html
import io
import math
from pathlib import Path

import numpy as np

from cmsim._io import atomic_write_text
from cmsim.spectra.plots import agg_figure

__all__ = ["write_report", "confusion_figure", "detection_figure"]


def _png(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    return base64.b64encode(buf.getvalue()).decode("ascii")


def confusion_figure(evaluation):
    """Confusion matrix (rows true, columns predicted) as a matplotlib Figure.

    Parameters
    ----------
    evaluation : cmsim.diagnostics.harness.Evaluation
    """
    conf = evaluation.metrics["confusion"]
    classes, m = conf["classes"], np.asarray(conf["matrix"], dtype=float)
    fig = agg_figure((1.2 + 0.7 * max(len(classes), 2), 1.0 + 0.6 * max(len(classes), 2)),
                     layout=None)
    ax = fig.add_subplot()
    if m.size:
        ax.imshow(m, cmap="Blues")
        for i in range(m.shape[0]):
            for j in range(m.shape[1]):
                ax.text(j, i, f"{int(m[i, j])}", ha="center", va="center",
                        color="white" if m[i, j] > 0.6 * m.max() else "black")
    ax.set_xticks(range(len(classes)), classes, rotation=45, ha="right")
    ax.set_yticks(range(len(classes)), classes)
    ax.set_xlabel("predicted")
    ax.set_ylabel("true")
    ax.set_title(f"{evaluation.algorithm}: accuracy {evaluation.metrics['accuracy']:.2f}")
    return fig


def detection_figure(evaluation):
    """Fault score against severity per fault class, with the 5 % false-alarm threshold
    (left), and the detection rate against severity (right).

    Parameters
    ----------
    evaluation : cmsim.diagnostics.harness.Evaluation
    """
    det = evaluation.metrics["detection"]
    fig = agg_figure((10, 3.8), layout=None)
    ax1, ax2 = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    healthy = [r.fault_score for r in evaluation.records if r.error is None
               and r.true_label == "healthy"]
    for cls in det["classes"]:
        pts = [(r.severity, r.fault_score) for r in evaluation.records
               if r.error is None and r.true_label == cls and math.isfinite(r.severity)]
        if pts:
            s, v = np.array(pts).T
            ax1.semilogx(s, v, "o", label=cls)
        c = det["classes"][cls]
        if c["severity"]:
            ax2.semilogx(c["severity"], c["detection_rate"], "o-", label=cls)
    thr = det["threshold"]
    if math.isfinite(thr):
        ax1.axhline(thr, color="k", ls="--", lw=1, label="threshold (5 % FA)")
    if healthy:
        ax1.plot([], [], " ", label=f"{len(healthy)} healthy records")
    ax1.set_xlabel("severity (main fault size), m")
    ax1.set_ylabel("fault score")
    ax2.set_xlabel("severity (main fault size), m")
    ax2.set_ylabel("detection rate")
    ax2.set_ylim(-0.05, 1.05)
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
    fig.suptitle(f"{evaluation.algorithm}: detection against severity")
    return fig


def _fmt(v):
    if isinstance(v, float):
        return "–" if not math.isfinite(v) else f"{v:.3g}"
    return html.escape(str(v))


def _error_cell(result):
    """A record's error, its traceback folded under it."""
    if not result.error:
        return ""
    cell = html.escape(result.error)
    tb = result.traceback
    if tb:
        cell += f"<details><summary>traceback</summary><pre>{html.escape(tb)}</pre></details>"
    return cell


def write_report(evaluation, path):
    """Write the HTML page of ``evaluation`` to ``path`` (atomically); return the path.

    Parameters
    ----------
    evaluation : cmsim.diagnostics.harness.Evaluation
    path : str or pathlib.Path
        The ``.html`` file.
    """
    m = evaluation.metrics
    e = html.escape
    rows = "".join(
        f"<tr><td>{e(r.record_id)}</td><td>{e(r.true_label)}</td><td>{_fmt(r.severity)}</td>"
        f"<td>{e(str(r.label))}</td><td>{_fmt(r.fault_score)}</td>"
        f"<td>{e(', '.join(f'{k}={_fmt(v)}' for k, v in r.scores.items()))}</td>"
        f"<td>{_error_cell(r)}</td></tr>" for r in evaluation.records)
    unreadable = "".join(f"<tr><td>{e(rid)}</td><td>{e(why)}</td></tr>"
                         for rid, why in evaluation.unreadable)
    if unreadable:
        unreadable = ("<h2>Records not read (skipped)</h2><table><tr><th>record</th>"
                      f"<th>why</th></tr>{unreadable}</table>")
    auc = "".join(f"<tr><td>{e(k)}</td><td>{_fmt(v)}</td><td>{_fmt(m['f1'].get(k, math.nan))}"
                  f"</td></tr>" for k, v in m["auc"].items())
    det = m["detection"]
    det_rows = "".join(
        f"<tr><td>{e(k)}</td><td>{_fmt(v['min_detected_severity'])}</td>"
        f"<td>{_fmt(v['min_reliable_severity'])}</td><td>{_fmt(v['detection_rate_all'])}</td>"
        f"</tr>" for k, v in det["classes"].items())
    figs = ""
    if m["n_scored"]:
        figs = (f'<img alt="confusion matrix" src="data:image/png;base64,'
                f'{_png(confusion_figure(evaluation))}">'
                f'<img alt="detection against severity" src="data:image/png;base64,'
                f'{_png(detection_figure(evaluation))}">')
    page = f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>cmsim evaluate: {e(evaluation.algorithm)}</title>
<style>body{{font-family:sans-serif;margin:2em}}table{{border-collapse:collapse}}
td,th{{border:1px solid #ccc;padding:2px 6px;font-size:90%}}</style></head><body>
<h1>{e(evaluation.algorithm)} on {e(evaluation.dataset)}</h1>
<p>{m['n_records']} records, {m['n_scored']} answered, {m['n_failed']} raised (left out of
the scores), {m['records_skipped']} failed in the dataset,
{m['records_unreadable']} could not be read. Accuracy {_fmt(m['accuracy'])}
(chance: {_fmt(m['chance_accuracy'])}), macro-F1 {_fmt(m['macro_f1'])}. Detection threshold
{_fmt(det['threshold'])} (95th percentile of the healthy records' fault scores; false-alarm
rate reached {_fmt(det['false_alarm_rate'])}).</p>
{figs}
<h2>Per class</h2><table><tr><th>class</th><th>ROC AUC (one-vs-rest)</th><th>F1</th></tr>
{auc}</table>
<h2>Detection against severity (5 % false alarms)</h2>
<table><tr><th>fault</th><th>smallest severity detected</th>
<th>smallest severity from which all are detected</th><th>detection rate</th></tr>
{det_rows}</table>
<h2>Records</h2><table><tr><th>record</th><th>true</th><th>severity</th><th>predicted</th>
<th>fault score</th><th>scores</th><th>error</th></tr>{rows}</table>
{unreadable}
</body></html>
"""
    return atomic_write_text(Path(path), page)
