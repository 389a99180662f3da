"""Calibration, step 4: the baseline's lines the model does not make, filed as background.

Each of the record's narrow lines (the one line detector,
:func:`cmsim.spectra.line_detector.detect_lines`) less what the model's own lines put there
through the path is the background's; its frequency is read on the whole record's fine
bins and filed as an order of the input or output shaft when it sits on one (so it follows
the speed), else at its frequency (the mains, other machines)
(:mod:`cmsim.machine.calibration`).
"""

from __future__ import annotations


import numpy as np

from cmsim.spectra.line_detector import LINE_TOLERANCE, detect_lines

__all__ = ["MESH_FAMILY_SIDEBANDS"]

#: Shaft-rate sidebands each side of a mesh harmonic whose lines are taken for the mesh's
#: own (:func:`_classify`): those the features read (``sb23``: ±2, ±3).
MESH_FAMILY_SIDEBANDS = 3


def _lines_and_floor(freq, psd):
    """(lines [(frequency, amplitude)] strongest first, floor) of a PSD: the one line
    detector (:func:`cmsim.spectra.line_detector.detect_lines`)."""
    lines, floor = detect_lines(freq, psd)
    return [(ln.frequency_hz, ln.amplitude) for ln in lines], floor


def _refined(lines, x, fs, df):
    """The lines' frequencies read on the spectrum of the whole record ``x`` (its bins far
    finer than a segment's), within ± 1.5 segment bins of each."""
    n = x.size
    amp = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(n)))
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    out = []
    for f, a in lines:
        sel = np.abs(freq - f) <= 1.5 * df
        out.append((float(freq[sel][np.argmax(amp[sel])]) if np.any(sel) else f, a))
    return out, freq[1]


def _near(f, g, df):
    return abs(f - g) <= max(1.5 * df, LINE_TOLERANCE * g)


def _classify(f, shaft_hz, fine_df, gmf_hz=None):
    """(reference, value) of a background line read at the whole record's resolution
    ``fine_df``: an order of a shaft when it sits on one within a bin (or 0.1 %), else a
    fixed frequency (the mains and its sub-harmonics sit within a few tenths of a hertz of
    a 4-pole motor's shaft orders, and only the fine bins tell them apart). On a gear rig
    (mesh frequency ``gmf_hz``), a line among a mesh harmonic's shaft-rate sidebands
    (:data:`MESH_FAMILY_SIDEBANDS` of the slower shaft each side) is the nearest order
    within :data:`LINE_TOLERANCE`: those are the mesh's own lines, order-locked, and a speed
    wobble moves them k·Z times a shaft order's excursion (a 588-Hz mesh line under a 0.3 %
    wobble of the baseline read 586.7 Hz at the fine resolution, was taken for a fixed
    line, and the twin's mesh tracking locked on it instead of the model's harmonics)."""
    for ref, rate in zip(("input", "output"), shaft_hz):
        k = round(f / rate)
        if k >= 1 and abs(f - k * rate) <= max(fine_df, 1e-3 * f):
            return ref, float(k)
    if gmf_hz:
        slow = min(shaft_hz)
        h = round(f / gmf_hz)
        if h >= 1 and abs(f - h * gmf_hz) <= (MESH_FAMILY_SIDEBANDS + 0.5) * slow:
            ref, rate = min(zip(("input", "output"), shaft_hz),
                            key=lambda rr: abs(f - round(f / rr[1]) * rr[1]))
            k = round(f / rate)
            if abs(f - k * rate) <= LINE_TOLERANCE * f:
                return ref, float(k)
    return "fixed", f
