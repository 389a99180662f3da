"""Time-domain figures across a sweep: bearing-centre orbits and DTE traces, one line per run.

Companions of :mod:`cmsim.spectra.waterfall` for the paper's Figs. 7/14 (orbits of bearings
1b1 and 2b1 at several torques, clearance circle dashed) and 9-10 (DTE over a few mesh cycles
and over one gear turn). Lines are coloured by the sweep parameter (viridis, low = dark).
Figures are built on the Agg canvas without pyplot.
"""

from __future__ import annotations

import numpy as np

from cmsim.errors import ParameterError
from cmsim.spectra._checks import signal_1d
from cmsim.spectra.plots import agg_figure

__all__ = ["plot_orbit_family", "plot_trace_family"]


def _colour_by_value(values):
    """The sweep ``values`` as floats, the runs in increasing value (stable), and the colour
    of each run, ``{run: colour}``: viridis by rank, the lowest value darkest."""
    import matplotlib as mpl
    cmap = mpl.colormaps["viridis"]
    values = np.asarray(values, dtype=float).ravel()
    order = np.argsort(values, kind="stable")
    n = values.size
    return values, order, {int(i): cmap(0.85 * j / max(n - 1, 1)) for j, i in enumerate(order)}


def plot_orbit_family(orbits, values, *, bearing_names, clearances_m=None,
                      value_label="Torque [N·m]", detail_runs=None, title=None):
    """Centre orbits of several bearings, one column per bearing, one line per run.

    Top row: absolute position with the clearance circle (the orbits of different runs sit
    where the load pushes them); bottom row: the orbits of ``detail_runs`` (default the
    lowest and highest value) about their own means, so shapes and sizes can be compared
    (paper Figs. 8, 15).

    Parameters
    ----------
    orbits : sequence of sequence of (array_like, array_like)
        ``orbits[b][i] = (x_m, y_m)``: displacements of bearing ``b`` in run ``i``, m.
    values : array_like, shape (n_runs,)
        Sweep parameter of each run (colour and legend).
    bearing_names : sequence of str
        Panel titles, one per bearing.
    clearances_m : sequence of float, optional
        Radial clearance of each bearing, m; a dashed circle is drawn if > 0 (negative
        values are preloads and are written in the title instead).
    value_label : str
        Name and unit of the parameter, for the legend title.
    detail_runs : sequence of int, optional
        Runs drawn about their mean in the bottom row (default: lowest and highest value).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    values, order, colour_of = _colour_by_value(values)
    if len(orbits) != len(bearing_names) or not orbits:
        raise ParameterError(f"orbits has {len(orbits)} bearings but bearing_names has "
                             f"{len(bearing_names)}")
    if clearances_m is not None and len(clearances_m) != len(orbits):
        raise ParameterError("clearances_m needs one value per bearing")
    detail = {int(order[0]), int(order[-1])} if detail_runs is None else set(detail_runs)
    n_b = len(orbits)
    fig = agg_figure((4.6 * n_b + 1.8, 9.4))
    grid = fig.subplots(2, n_b, squeeze=False)
    for b, name in enumerate(bearing_names):
        ax, axc = grid[0, b], grid[1, b]
        if len(orbits[b]) != values.size:
            raise ParameterError(f"orbits[{b}] has {len(orbits[b])} runs, values has "
                                 f"{values.size}")
        for i in order:
            x = signal_1d(orbits[b][i][0], name="x_m", min_samples=2) * 1e6
            y = signal_1d(orbits[b][i][1], name="y_m", min_samples=2) * 1e6
            ax.plot(x, y, lw=0.9, color=colour_of[i], label=f"{values[i]:g}")
            ax.plot(x[0], y[0], "o", ms=3, color=colour_of[i], mfc="white")
            if i in detail:
                axc.plot(x - x.mean(), y - y.mean(), lw=0.9, color=colour_of[i],
                         label=f"{values[i]:g}")
        extra = ""
        if clearances_m is not None:
            c = float(clearances_m[b]) * 1e6
            if c > 0:
                phi = np.linspace(0.0, 2 * np.pi, 361)
                ax.plot(c * np.cos(phi), c * np.sin(phi), "--", color="0.3", lw=1.0,
                        label=f"clearance {c:.3g} µm")
            elif c < 0:
                extra = f" (preload {-c:.3g} µm)"
        ax.plot([0], [0], "+", color="0.3", ms=8)
        for a in (ax, axc):
            a.set_aspect("equal", adjustable="datalim")
            a.grid(True, alpha=0.3)
        ax.set_xlabel("x, normal to the line of centres [µm]")
        ax.set_ylabel("y, along the line of centres [µm]")
        ax.set_title(f"bearing {name}{extra}: position", fontsize=10)
        axc.set_xlabel("x − mean [µm]")
        axc.set_ylabel("y − mean [µm]")
        axc.set_title(f"bearing {name}: orbit about its mean (detail)", fontsize=10)
    grid[1, -1].legend(title=value_label, fontsize=8, title_fontsize=8, loc="upper left",
                       bbox_to_anchor=(1.02, 1.0))
    grid[0, -1].legend(title=value_label, fontsize=8, title_fontsize=8, loc="upper left",
                       bbox_to_anchor=(1.02, 1.0))
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def plot_trace_family(panels, values, *, value_label="Torque [N·m]", title=None):
    """Time traces of several runs, one or more panels, one line per run.

    Parameters
    ----------
    panels : sequence of dict
        One dict per panel with ``"t"`` (sequence of time arrays per run, s, plotted in
        ms), ``"y"`` (sequence of value arrays per run), ``"ylabel"`` (with unit),
        ``"title"``, and optionally ``"period_s"`` (vertical grid every period, e.g. the
        mesh period) and ``"runs"`` (indices of the runs drawn; default all).
    values : array_like, shape (n_runs,)
        Sweep parameter of each run (colour and legend).
    value_label : str
        Name and unit of the parameter, for the legend title.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    values, _, colour_of = _colour_by_value(values)
    fig = agg_figure((11.0, 3.4 * len(panels) + 0.6))
    axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
    for ax, p in zip(axes, panels):
        runs = p.get("runs", range(values.size))
        if len(p["t"]) != values.size or len(p["y"]) != values.size:
            raise ParameterError("each panel needs one time and one value array per run")
        t_hi = 0.0
        for i in sorted(runs, key=lambda k: values[k]):
            t = signal_1d(p["t"][i], name="t", min_samples=2)
            y = signal_1d(p["y"][i], name="y", min_samples=2)
            ax.plot(1e3 * t, y, lw=1.0, color=colour_of[i], label=f"{values[i]:g}")
            t_hi = max(t_hi, float(t[-1]))
        period = p.get("period_s")
        if period:
            for k in range(1, int(t_hi / period) + 1):
                ax.axvline(1e3 * k * period, color="0.6", lw=0.6, ls=":", zorder=0)
        ax.set_xlim(0.0, 1e3 * t_hi)
        ax.set_xlabel("Time [ms]")
        ax.set_ylabel(p["ylabel"])
        ax.set_title(p.get("title", ""), fontsize=10)
        ax.grid(True, axis="y", alpha=0.3)
        ax.legend(title=value_label, fontsize=8, title_fontsize=8, loc="center left",
                  bbox_to_anchor=(1.01, 0.5))
    if title:
        fig.suptitle(title, fontsize=11)
    return fig
