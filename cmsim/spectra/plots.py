"""Matplotlib figures of spectra, waterfalls, orbits and kurtograms.

Every function builds a new :class:`matplotlib.figure.Figure` on the Agg canvas (no pyplot
state, no window, no ``plt.show()``) and returns it; save it with ``fig.savefig(path)``.
Matplotlib is imported inside the functions, so importing :mod:`cmsim.spectra` does not need
it.
"""

from __future__ import annotations

import numpy as np

from cmsim.errors import ParameterError, check_choice, check_range
from cmsim.spectra._checks import signal_1d

__all__ = ["plot_spectrum", "plot_waterfall", "plot_orbit", "plot_kurtogram", "WATERFALL_STYLES"]

#: Styles of :func:`plot_waterfall`.
WATERFALL_STYLES = ("offset", "3d")

#: Line colours of the label families (others grey).
FAMILY_COLOURS = {"GMF": "tab:blue", "BPF": "tab:red", "fr": "tab:green", "BPFO": "tab:orange",
                  "BPFI": "tab:purple", "BSF": "tab:brown", "FTF": "tab:pink",
                  "unlabelled": "0.5"}


def agg_figure(figsize, layout="constrained"):
    """A new figure of ``figsize`` (inches) on its own Agg canvas, with ``layout`` (matplotlib's
    layout engine, ``None`` for none): no pyplot state. Every figure of cmsim starts here."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout=layout)
    FigureCanvasAgg(fig)
    return fig


def _figure(figsize, projection=None):
    fig = agg_figure(figsize)
    ax = fig.add_subplot(projection=projection) if projection else fig.add_subplot()
    return fig, ax


def _amp_label(amplitude_unit, db=False):
    unit = amplitude_unit if amplitude_unit else "signal unit"
    return f"Amplitude [dB re 1 {unit}]" if db else f"Amplitude [{unit}]"


def plot_spectrum(freq, amp, peaks_df=None, families=None, log=True, *, amplitude_unit="",
                  freq_unit="Hz", max_freq=None, max_harmonic=10, title=None):
    """Amplitude spectrum with family markers and peak labels.

    Parameters
    ----------
    freq : array_like, shape (n_bins,)
        Frequencies (Hz, or orders with ``freq_unit="order"``).
    amp : array_like, shape (n_bins,)
        Amplitudes, >= 0.
    peaks_df : pandas.DataFrame, optional
        :func:`~cmsim.spectra.labels.label_peaks` output; labelled peaks get a marker and
        their label, coloured by family.
    families : dict of str to float, optional
        Base frequencies; harmonics of ``"GMF"`` (blue dashed) and ``"BPF"`` (red dotted) up
        to ``max_harmonic`` are drawn as vertical lines.
    log : bool
        Logarithmic amplitude axis.
    amplitude_unit : str
        Unit of the signal for the y label (e.g. "m/s²", "µm").
    freq_unit : str
        Unit of the x axis, ``"Hz"`` or ``"order"``.
    max_freq : float, optional
        Upper x limit.
    max_harmonic : int
        Number of family harmonics to mark.
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    freq = signal_1d(freq, name="freq", min_samples=2)
    amp = signal_1d(amp, name="amp", min_samples=2)
    if freq.shape != amp.shape:
        raise ParameterError("freq and amp must have the same shape")
    fig, ax = _figure((9, 4.5))
    sel = freq > 0 if log else np.ones(freq.size, bool)
    ax.plot(freq[sel], amp[sel], lw=0.8, color="k")
    if log:
        ax.set_yscale("log")
        pos = amp[sel][amp[sel] > 0]
        if pos.size:
            head = 100.0 if peaks_df is not None and len(peaks_df) else 3.0   # room for labels
            ax.set_ylim(max(pos.min(), pos.max() * 1e-6) * 0.5, pos.max() * head)
    f_hi = float(freq[-1]) if max_freq is None else check_range("max_freq", max_freq, 0.0,
                                                                 lo_open=True)
    ax.set_xlim(0.0, f_hi)
    if families:
        for key, style in (("GMF", dict(color="tab:blue", ls="--")),
                           ("BPF", dict(color="tab:red", ls=":"))):
            base = families.get(key)
            if base:
                for k in range(1, max_harmonic + 1):
                    if k * base <= f_hi:
                        ax.axvline(k * base, lw=0.8, alpha=0.6,
                                   label=key if k == 1 else None, **style)
    if peaks_df is not None and len(peaks_df):
        fcol = "frequency_hz" if "frequency_hz" in peaks_df else "order"
        for fam, grp in peaks_df.groupby("family"):
            colour = FAMILY_COLOURS.get(fam, "0.3")
            ax.plot(grp[fcol], grp["amplitude"], "v", ms=5, color=colour, label=f"{fam} peaks")
            for f_pk, a_pk, lab in zip(grp[fcol], grp["amplitude"], grp["label"]):
                if lab != "?" and f_pk <= f_hi:
                    ax.annotate(lab, (f_pk, a_pk), xytext=(0, 6), textcoords="offset points",
                                rotation=90, fontsize=7, ha="center", va="bottom", color=colour)
    ax.set_xlabel("Order [cycles/rev]" if freq_unit == "order" else f"Frequency [{freq_unit}]")
    ax.set_ylabel(_amp_label(amplitude_unit))
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8, loc="upper right")
    ax.grid(True, which="major", alpha=0.3)
    if title:
        ax.set_title(title)
    return fig


def plot_waterfall(freqs, amps_list, values, value_label="Torque [N m]", *, style="offset",
                   amplitude_unit="", max_freq=None, offset_db=None, title=None):
    """Waterfall of log-amplitude spectra versus a parameter (paper Figs 11-12).

    Parameters
    ----------
    freqs : array_like, shape (n_bins,) or sequence of arrays
        Common frequency axis, Hz, or one axis per spectrum.
    amps_list : sequence of array_like
        One amplitude spectrum per parameter value, each matching its frequency axis.
    values : array_like, shape (n_spectra,)
        Parameter value of each spectrum (e.g. torque, N m).
    value_label : str
        Parameter name with unit, for the axis label.
    style : {"offset", "3d"}
        ``"offset"``: dB spectra stacked with a vertical offset, labelled by value;
        ``"3d"``: lines in 3-D (frequency, parameter, dB).
    amplitude_unit : str
        Signal unit for the dB reference.
    max_freq : float, optional
        Upper frequency limit, Hz.
    offset_db : float, optional
        Offset between stacked lines, dB; default 40 % of the overall dB range.
    title : str, optional
        Title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    check_choice("style", style, WATERFALL_STYLES)
    values = np.asarray(values, dtype=float).ravel()
    amps = [signal_1d(a, name="amps_list[i]", min_samples=2) for a in amps_list]
    if len(amps) != values.size or not amps:
        raise ParameterError(f"amps_list has {len(amps)} spectra but values has {values.size}")
    if np.ndim(freqs[0]) == 0:                                # one common axis
        f_list = [signal_1d(freqs, name="freqs", min_samples=2)] * len(amps)
    else:
        f_list = [signal_1d(f, name="freqs[i]", min_samples=2) for f in freqs]
    if len(f_list) != len(amps) or any(f.shape != a.shape for f, a in zip(f_list, amps)):
        raise ParameterError("each spectrum in amps_list must match its frequency axis")
    f_hi = max(float(f[-1]) for f in f_list) if max_freq is None else float(max_freq)
    tiny = np.finfo(float).tiny
    db = [20 * np.log10(np.maximum(a, tiny)) for a in amps]
    top = max(float(d.max()) for d in db)
    db = [np.maximum(d, top - 120.0) for d in db]          # clip numerical-zero bins
    order = np.argsort(values)
    if style == "3d":
        fig, ax = _figure((9, 6), projection="3d")
        for i in order:
            sel = (f_list[i] > 0) & (f_list[i] <= f_hi)
            ax.plot(f_list[i][sel], np.full(sel.sum(), values[i]), db[i][sel], lw=0.6)
        ax.set_xlabel("Frequency [Hz]")
        ax.set_ylabel(value_label)
        ax.set_zlabel(_amp_label(amplitude_unit, db=True))
    else:
        fig, ax = _figure((9, 1.2 + 0.6 * len(amps)))
        span = top - min(float(d.min()) for d in db)
        step = 0.4 * span if offset_db is None else check_range("offset_db", offset_db, 0.0)
        base = min(float(d.min()) for d in db)
        n_sp = len(order)
        for j, i in enumerate(order):
            # front (low parameter) lines hide the ones behind them, as in a 3-D waterfall
            sel = (f_list[i] > 0) & (f_list[i] <= f_hi)
            z = 2 * (n_sp - j)
            line, = ax.plot(f_list[i][sel], db[i][sel] + j * step, lw=0.6, zorder=z + 1)
            ax.fill_between(f_list[i][sel], base + j * step, db[i][sel] + j * step,
                            color="white", zorder=z)
            ax.text(f_hi, float(np.median(db[i][sel])) + j * step, f" {values[i]:g}",
                    color=line.get_color(), va="center", fontsize=8)
        ax.set_xlim(0.0, f_hi)
        ax.set_xlabel("Frequency [Hz]")
        ax.set_ylabel(_amp_label(amplitude_unit, db=True) + " + offset")
        ax.set_title(f"right: {value_label}; lines offset by {step:.0f} dB", fontsize=9)
    if title:
        fig.suptitle(title)
    return fig


def plot_orbit(x_m, y_m, clearance_m=None, *, title=None):
    """Orbit of a bearing or gear centre, in µm, with the radial clearance circle dashed.

    Parameters
    ----------
    x_m, y_m : array_like, shape (n,)
        Displacements, m.
    clearance_m : float, optional
        Radial clearance, m (drawn as a dashed circle if > 0).
    title : str, optional
        Title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    x = signal_1d(x_m, name="x_m", min_samples=2) * 1e6
    y = signal_1d(y_m, name="y_m", min_samples=2) * 1e6
    if x.shape != y.shape:
        raise ParameterError("x_m and y_m must have the same shape")
    fig, ax = _figure((5.5, 5.5))
    ax.plot(x, y, lw=0.7, color="k")
    ax.plot(x[-1], y[-1], "o", ms=4, color="tab:red", label="end")
    if clearance_m is not None:
        c = check_range("clearance_m", clearance_m, unit="m") * 1e6
        if c > 0:
            phi = np.linspace(0.0, 2 * np.pi, 361)
            ax.plot(c * np.cos(phi), c * np.sin(phi), "--", color="tab:blue",
                    label=f"clearance {c:.3g} µm")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [µm]")
    ax.set_ylabel("y [µm]")
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(True, alpha=0.3)
    if title:
        ax.set_title(title)
    return fig


def plot_kurtogram(kgram, *, n_freq=512, title=None):
    """Kurtogram map: spectral kurtosis versus frequency and bandwidth, best band marked.

    Parameters
    ----------
    kgram : cmsim.spectra.kurtogram.Kurtogram
        Result of :func:`~cmsim.spectra.kurtogram.kurtogram`.
    n_freq : int
        Frequency samples of the map.
    title : str, optional
        Title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    grid = np.linspace(0.0, 0.5 * kgram.fs, n_freq)
    rows = []
    for f, sk in zip(kgram.freq_hz, kgram.kurtosis):
        edges = np.concatenate([[f[0]], 0.5 * (f[1:] + f[:-1]), [f[-1]]])
        idx = np.clip(np.searchsorted(edges, grid) - 1, 0, sk.size - 1)
        rows.append(np.nan_to_num(sk[idx], nan=0.0))
    fig, ax = _figure((8, 4))
    levels = np.arange(len(rows))
    mesh = ax.pcolormesh(grid, levels, np.clip(rows, 0.0, None), shading="nearest",
                         cmap="viridis")
    ax.set_yticks(levels)
    ax.set_yticklabels([f"{kgram.bandwidth_of(n):.0f}" for n in kgram.nperseg], fontsize=7)
    best = kgram.nperseg.index(kgram.best_nperseg)
    ax.plot(kgram.band_hz, [best, best], color="tab:red", lw=3, label="best band")
    ax.legend(fontsize=8, loc="upper right")
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel("Bandwidth [Hz]")
    fig.colorbar(mesh, ax=ax, label="Spectral kurtosis [-]")
    ax.set_title(title or f"best band {kgram.band_hz[0]:.0f}-{kgram.band_hz[1]:.0f} Hz, "
                 f"SK = {kgram.kurtosis_max:.2f}", fontsize=9)
    return fig
