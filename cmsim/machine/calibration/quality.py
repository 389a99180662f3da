"""Calibration, step 6 and the operating point: the features of baseline segments, the twin's
misfit against them, and the speed wobble (:mod:`cmsim.machine.calibration`).
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.errors import ParameterError
from cmsim.features import band_family_columns, relative_features

__all__ = ["WOBBLE_MIN_SNR", "feature_rows"]

#: Least power ratio of a shaft-order line over the noise beside it for its instantaneous
#: frequency to tell the speed wobble (20 dB: the noise then adds under 0.5 % of the line's
#: phase wander).
WOBBLE_MIN_SNR = 100.0


def _misfit(names, twin_rows, rows, spread):
    """(z, z_model) of the twin's mean feature against the mean of the baseline ``rows``:
    over the baseline's segment-to-segment spread, and over that and the twin's own spread
    (one record is one realisation of the model's random parts; the twin averages several)."""
    z, z_model = {}, {}
    for i, k in enumerate(names):
        if k in spread and spread[k][1] > 0:
            a, b = np.nanmean(twin_rows[:, i]), np.nanmean(rows[:, i])
            if math.isfinite(a) and math.isfinite(b):
                z[k] = float((a - b) / spread[k][1])
                model = float(np.nanstd(twin_rows[:, i], ddof=1))
                z_model[k] = float((a - b) / math.hypot(spread[k][1], model))
    return z, z_model


def feature_rows(segs, fs_hz, freqs, bearings, unit_scale, bands=False):
    """Features of each segment: :func:`cmsim.features.relative_features`, plus ``level_db``
    (dB re 1 m/s²) when the unit is known, and with ``bands`` each bearing's defect families
    in every band of the fixed bank (:func:`cmsim.features.band_family_columns`: what a
    record is judged on against its machine's baseline); ``(names, array (n_segments,
    n_features))``.

    Parameters
    ----------
    segs : sequence of numpy.ndarray
        Segments of a signal, sensor unit.
    fs_hz : float
        Sample rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies
        Frequencies of the model rig at the record's speed.
    bearings : sequence of str
        Bearings whose families are read.
    unit_scale : float or None
        Sensor unit → m/s² (None: no ``level_db``).
    bands : bool
        Add the band-by-band families.
    """
    rows = []
    bfs = {b: freqs.bearing(b) for b in bearings} if bands else {}
    for x in segs:
        f = relative_features(x, fs_hz, freqs, bearings)
        if bfs:
            f.update(band_family_columns(x - np.mean(x), fs_hz, freqs.fr1_hz, bfs))
        if unit_scale is not None:
            f["level_db"] = 20.0 * math.log10(max(float(np.std(x)) * unit_scale, 1e-30))
        rows.append(f)
    if not rows:
        raise ParameterError("no segment to read features from", param="baseline")
    names = list(rows[0])
    return names, np.array([[r[k] for k in names] for r in rows], dtype=float)


def _speed_wobble(x, fs, shaft_hz):
    """Relative RMS of the slow fluctuation of the input speed, or None where the baseline
    cannot tell it.

    The strongest of the first four shaft orders is demodulated and averaged over two shaft
    periods; its instantaneous frequency fluctuates with the speed and with the noise under
    the line. The noise's share, read the same way half a shaft order beside the line, is
    removed; a line less than :data:`WOBBLE_MIN_SNR` over that noise tells nothing.
    """
    n = x.size
    spec = np.abs(np.fft.rfft(x * np.hanning(n)))
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    orders = [(float(np.max(spec[sel])), k) for k in range(1, 5)
              if np.any(sel := np.abs(freq - k * shaft_hz) <= 0.02 * k * shaft_hz)]
    if not orders:
        return None
    k = max(orders)[1]
    width = max(1, int(round(2.0 * fs / shaft_hz)))
    t = np.arange(n) / fs

    def demodulated(f0):
        b = np.convolve(x * np.exp(-2j * math.pi * f0 * t), np.ones(width) / width, "valid")
        return b[::width]

    line = demodulated(k * shaft_hz)
    noise = 0.5 * sum(float(np.mean(np.abs(demodulated(k * shaft_hz + d)) ** 2))
                      for d in (-0.5 * shaft_hz, 0.5 * shaft_hz))
    power = float(np.abs(np.mean(line)) ** 2)
    if line.size < 10 or power < WOBBLE_MIN_SNR * noise:
        return None
    step = width / fs
    inst = np.diff(np.unwrap(np.angle(line))) / (2.0 * math.pi * step)
    var_noise = noise / power / (2.0 * math.pi * step) ** 2
    return float(math.sqrt(max(float(np.var(inst)) - var_noise, 0.0)) / (k * shaft_hz))
