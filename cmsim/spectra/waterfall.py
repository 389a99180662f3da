"""Spectra across a sweep: harmonic amplitudes, the dominant harmonic, family-marked waterfalls.

A torque (or speed) sweep is read the way the paper's Figs. 11-12 and 16-17 are read: one
log-amplitude spectrum per parameter value, stacked, with the gear-mesh harmonics k·GMF and
the ball-pass lines m·BPF marked, and the harmonic that dominates at each value picked out.

* :func:`harmonic_amplitudes` — amplitude of k·base (largest bin within ± tolerance);
* :func:`dominant_harmonic` — the k with the largest of those amplitudes;
* :func:`plot_family_waterfall` — stacked dB spectra, one per parameter value, with
  GMF/BPF markers, labelled peaks and the dominant harmonic starred;
* :func:`plot_harmonic_trend` — amplitude of each harmonic versus the parameter.

Figures are built on the Agg canvas without pyplot (see :mod:`cmsim.spectra.plots`).

References
----------
.. [1] A. Fernandez-del-Rincon et al., "Enhanced model of gear transmission dynamics for
   condition monitoring applications", MSSP 85 (2017) 445-467, Figs. 11-13, 16-17.
"""

from __future__ import annotations

import numpy as np

from cmsim.errors import ParameterError, check_choice, check_range
from cmsim.spectra._checks import positive_int, signal_1d, spectrum_arrays
from cmsim.spectra.plots import agg_figure

__all__ = ["harmonic_amplitudes", "dominant_harmonic", "plot_family_waterfall",
           "plot_harmonic_trend", "FAMILY_MARKERS"]

#: Marker style of labelled peaks by family: (marker, colour, legend text).
FAMILY_MARKERS = {"GMF": ("v", "tab:blue", "k·GMF"),
                  "GMF±BPF": (".", "tab:red", "k·GMF ± m·BPF"),
                  "BPF": ("^", "tab:orange", "m·BPF"),
                  "other": ("x", "0.45", "other labelled / unlabelled")}


def harmonic_amplitudes(freq, amp, base_hz, n_harmonics=10, tolerance_hz=None):
    """Amplitude of each harmonic k·base_hz, k = 1..n_harmonics.

    Parameters
    ----------
    freq : array_like, shape (n_bins,)
        Bin frequencies, Hz, increasing and uniformly spaced.
    amp : array_like, shape (n_bins,)
        Amplitude spectrum (window-corrected), unit of the signal.
    base_hz : float
        Fundamental, Hz (> 0), e.g. the GMF.
    n_harmonics : int
        Number of harmonics (1-1000).
    tolerance_hz : float, optional
        Half-width of the search window around k·base_hz, Hz; default 1.5 bins (the flat-top
        main lobe is about ±2 bins wide, so a tone between bins still reads its amplitude).

    Returns
    -------
    numpy.ndarray, shape (n_harmonics,)
        Largest amplitude within ± tolerance of k·base_hz; NaN above the last bin.

    Examples
    --------
    >>> import numpy as np
    >>> f = np.arange(0.0, 1000.0, 1.0)
    >>> a = np.zeros_like(f); a[100] = 1.0; a[300] = 3.0
    >>> harmonic_amplitudes(f, a, 100.0, 4).tolist()
    [1.0, 0.0, 3.0, 0.0]
    """
    freq, amp = spectrum_arrays(freq, amp)
    base = check_range("base_hz", base_hz, 0.0, lo_open=True, unit="Hz")
    n = positive_int("n_harmonics", n_harmonics, lo=1, hi=1000)
    df = float(freq[1] - freq[0])
    tol = 1.5 * df if tolerance_hz is None else check_range("tolerance_hz", tolerance_hz, 0.0,
                                                             lo_open=True, unit="Hz")
    out = np.full(n, np.nan)
    for k in range(1, n + 1):
        fk = k * base
        if fk > freq[-1] + tol:
            break
        lo, hi = np.searchsorted(freq, [fk - tol, fk + tol], side="left")
        hi = max(hi, lo + 1)
        out[k - 1] = float(amp[lo:hi].max())
    return out


def dominant_harmonic(freq, amp, base_hz, n_harmonics=10, tolerance_hz=None):
    """The harmonic k·base_hz of largest amplitude.

    Parameters
    ----------
    freq, amp, base_hz, n_harmonics, tolerance_hz
        See :func:`harmonic_amplitudes`.

    Returns
    -------
    k : int
        Order of the dominant harmonic (1-based).
    amplitude : float
        Its amplitude, unit of the signal.
    """
    h = harmonic_amplitudes(freq, amp, base_hz, n_harmonics, tolerance_hz)
    if not np.any(np.isfinite(h)):
        raise ParameterError(f"no harmonic of base_hz = {base_hz:g} Hz lies in the spectrum "
                             f"(up to {float(np.asarray(freq)[-1]):g} Hz)")
    k = int(np.nanargmax(h)) + 1
    return k, float(h[k - 1])


def _db(a, floor):
    return 20.0 * np.log10(np.maximum(a, floor))


def _marker_group(family, k, m):
    if family == "GMF":
        return "GMF" if m == 0 else "GMF±BPF"
    if family == "BPF" and k == 0:
        return "BPF"
    return "other"


def plot_family_waterfall(freq, amps, values, *, families=None, peaks=None, dominant=None,
                          value_label="Torque [N·m]", amplitude_unit="", max_freq=None,
                          dynamic_range_db=60.0, offset_db=None, n_harmonics=None,
                          freq_unit="Hz", mark_other=False, title=None):
    """Stacked dB spectra, one per parameter value, with GMF/BPF families marked.

    Each spectrum is drawn as 20·log10(amplitude) clipped ``dynamic_range_db`` below the
    largest bin of the whole set and shifted up by ``offset_db`` per parameter step, so the
    lowest value is at the bottom (the front of the paper's 3-D waterfalls). The right axis
    gives the parameter value of each line; the left axis the dB of the lowest line.

    Parameters
    ----------
    freq : array_like, shape (n_bins,)
        Common frequency axis, Hz.
    amps : sequence of array_like, each shape (n_bins,)
        Amplitude spectra (unit ``amplitude_unit``), one per value.
    values : array_like, shape (n_spectra,)
        Parameter value of each spectrum (e.g. torque, N·m); drawn in increasing order.
    families : dict of str to float, optional
        Base frequencies, Hz; ``"GMF"`` harmonics are drawn as dashed lines labelled on top,
        ``"BPF"`` harmonics as ticks at the bottom.
    peaks : sequence of pandas.DataFrame, optional
        :func:`~cmsim.spectra.labels.label_peaks` output per spectrum; labelled peaks that
        stand out of the clipped floor get a marker by family (see :data:`FAMILY_MARKERS`).
    dominant : sequence of int, optional
        Dominant GMF harmonic per spectrum; starred.
    value_label : str
        Name and unit of the parameter, for the right axis.
    amplitude_unit : str
        Unit of the amplitude (dB are re 1 of it).
    max_freq : float, optional
        Upper frequency limit, Hz (default the last bin).
    dynamic_range_db : float
        Depth shown below the overall maximum, dB (> 0).
    offset_db : float, optional
        Shift between successive lines, dB; default 0.45·dynamic_range_db.
    n_harmonics : int, optional
        Number of GMF harmonics marked; default all below ``max_freq``.
    freq_unit : {"Hz", "order"}
        Unit of ``freq``, ``families`` and the peaks' ``frequency_hz`` column (orders: cycles
        per shaft revolution).
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    check_choice("freq_unit", freq_unit, ("Hz", "order"))
    freq = signal_1d(freq, name="freq", min_samples=2)
    values = np.asarray(values, dtype=float).ravel()
    amps = [signal_1d(a, name=f"amps[{i}]", min_samples=2) for i, a in enumerate(amps)]
    if not amps or len(amps) != values.size:
        raise ParameterError(f"amps has {len(amps)} spectra but values has {values.size}")
    if any(a.shape != freq.shape for a in amps):
        raise ParameterError("every spectrum in amps must match freq")
    for name, seq in (("peaks", peaks), ("dominant", dominant)):
        if seq is not None and len(seq) != values.size:
            raise ParameterError(f"{name} must have one entry per value ({values.size}), "
                                 f"got {len(seq)}")
    dr = check_range("dynamic_range_db", dynamic_range_db, 0.0, lo_open=True, unit="dB")
    step = 0.45 * dr if offset_db is None else check_range("offset_db", offset_db, 0.0,
                                                           unit="dB")
    f_hi = float(freq[-1]) if max_freq is None else check_range("max_freq", max_freq, 0.0,
                                                                 lo_open=True, unit="Hz")
    sel = (freq > 0.0) & (freq <= f_hi)
    top = max(float(np.max(a[sel])) for a in amps)
    if not top > 0.0:
        raise ParameterError("all spectra are zero below max_freq")
    ref_db = 20.0 * np.log10(top)
    floor_db = ref_db - dr
    floor = 10.0 ** (floor_db / 20.0)
    order = np.argsort(values, kind="stable")
    n_sp = len(order)

    import matplotlib as mpl
    cmap = mpl.colormaps["viridis"]
    fig = agg_figure((11.0, 3.2 + 0.55 * n_sp))
    ax = fig.add_subplot()
    fam = families or {}
    gmf, bpf = fam.get("GMF"), fam.get("BPF")
    y_top = ref_db + (n_sp - 1) * step + 10.0
    if gmf:
        kmax = int(f_hi // gmf) if n_harmonics is None else int(n_harmonics)
        for k in range(1, kmax + 1):
            ax.axvline(k * gmf, color="tab:blue", ls="--", lw=0.7, alpha=0.45, zorder=0)
            ax.text(k * gmf, 1.005, f"{k}×GMF", color="tab:blue", ha="center", va="bottom",
                    fontsize=8, transform=ax.get_xaxis_transform())
    if bpf:
        for m in range(1, int(f_hi // bpf) + 1):
            ax.plot([m * bpf, m * bpf], [floor_db - 0.10 * step, floor_db - 0.02 * step],
                    color="tab:red", lw=1.2, zorder=1)
        ax.text(bpf, floor_db - 0.12 * step, "m·BPF", color="tab:red", ha="left", va="top",
                fontsize=8)
    used = set()
    for j, i in enumerate(order):
        colour = cmap(0.85 * j / max(n_sp - 1, 1))
        y = _db(amps[i][sel], floor) + j * step
        z = 2 * (n_sp - j)
        ax.fill_between(freq[sel], floor_db + j * step, y, color="white", zorder=z)
        ax.plot(freq[sel], y, lw=0.7, color=colour, zorder=z + 1)
        if peaks is not None and peaks[i] is not None and len(peaks[i]):
            df = peaks[i]
            visible = _db(df["amplitude"].to_numpy(), floor) > floor_db + 0.1 * step
            df = df[(df["frequency_hz"] > 0) & (df["frequency_hz"] <= f_hi) & visible]
            groups = [_marker_group(f, k, m) for f, k, m in zip(df["family"], df["k"], df["m"])]
            for g in FAMILY_MARKERS:
                if g == "other" and not mark_other:
                    continue
                pick = np.array([x == g for x in groups], dtype=bool)
                if not pick.any():
                    continue
                mk, col, text = FAMILY_MARKERS[g]
                ax.plot(df["frequency_hz"].to_numpy()[pick],
                        _db(df["amplitude"].to_numpy()[pick], floor) + j * step + 2.5, mk,
                        color=col, ms=4 if mk != "." else 6, zorder=z + 1,
                        label=text if g not in used else None)
                used.add(g)
        if dominant is not None and gmf and dominant[i]:
            fk = dominant[i] * gmf
            near = np.abs(freq - fk) <= 2.0 * (freq[1] - freq[0])
            a_k = float(np.max(amps[i][near])) if near.any() else top
            ax.plot([fk], [_db(a_k, floor) + j * step + 7.0], "*", color="gold", mec="k",
                    mew=0.6, ms=11, zorder=z + 1,
                    label="dominant GMF harmonic" if "dom" not in used else None)
            used.add("dom")
    ax.set_xlim(0.0, f_hi)
    ax.set_ylim(floor_db - 0.2 * step, y_top)
    ax.set_xlabel("Order [cycles/rev]" if freq_unit == "order" else "Frequency [Hz]")
    unit = amplitude_unit or "signal unit"
    ax.set_ylabel(f"Amplitude [dB re 1 {unit}] (lowest line; +{step:.0f} dB per line)")
    ax2 = ax.twinx()
    ax2.set_ylim(ax.get_ylim())
    ax2.set_yticks([floor_db + j * step + 0.25 * step for j in range(n_sp)])
    ax2.set_yticklabels([f"{values[i]:g}" for i in order], fontsize=8)
    ax2.set_ylabel(value_label)
    ax.grid(True, axis="x", alpha=0.15)
    if used:
        fig.legend(*ax.get_legend_handles_labels(), fontsize=8, loc="outside lower center",
                   ncol=5, frameon=False)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def plot_harmonic_trend(values, harmonic_amps, *, value_label="Torque [N·m]",
                        amplitude_unit="", base_label="GMF", title=None):
    """Amplitude of each harmonic versus the sweep parameter, dominant one circled.

    Parameters
    ----------
    values : array_like, shape (n_values,)
        Parameter value of each run (e.g. torque, N·m).
    harmonic_amps : array_like, shape (n_values, n_harmonics)
        :func:`harmonic_amplitudes` per run.
    value_label : str
        Name and unit of the parameter (x axis).
    amplitude_unit : str
        Unit of the amplitudes (log y axis).
    base_label : str
        Name of the fundamental in the legend ("GMF").
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    values = np.asarray(values, dtype=float).ravel()
    h = np.asarray(harmonic_amps, dtype=float)
    if h.ndim != 2 or h.shape[0] != values.size:
        raise ParameterError(f"harmonic_amps must have shape ({values.size}, n_harmonics), "
                             f"got {h.shape}")
    order = np.argsort(values, kind="stable")
    v, h = values[order], h[order]
    import matplotlib as mpl
    cmap = mpl.colormaps["tab10"]
    fig = agg_figure((8.0, 4.6))
    ax = fig.add_subplot()
    for k in range(h.shape[1]):
        if np.all(~np.isfinite(h[:, k])):
            continue
        ax.plot(v, h[:, k], "-o", ms=3.5, lw=1.2, color=cmap(k % 10),
                label=f"{k + 1}×{base_label}")
    valid = np.where(np.isfinite(h), h, -np.inf)
    dom = np.argmax(valid, axis=1)
    ax.plot(v, h[np.arange(v.size), dom], "o", ms=11, mfc="none", mec="k", mew=1.2,
            label="dominant")
    for x, k, a in zip(v, dom, h[np.arange(v.size), dom]):
        ax.annotate(f"{k + 1}", (x, a), xytext=(0, 8), textcoords="offset points",
                    ha="center", fontsize=8, fontweight="bold")
    ax.set_yscale("log")
    ax.set_xlabel(value_label)
    ax.set_ylabel(f"Amplitude [{amplitude_unit or 'signal unit'}]")
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=8, ncol=2, loc="best")
    if title:
        ax.set_title(title, fontsize=10)
    return fig
