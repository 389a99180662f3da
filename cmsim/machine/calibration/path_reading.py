"""Calibration, step 3: the transfer path's shape and gain, and the background it leaves.

One reading of the path (:func:`_reading`): its shape from the background's spectrum (or the
background's over the model's broadband force), its gain pinned by the model lines the
record shows (:func:`_pins`) and beyond them by the modulation of the record's broadband at
the sensor bearing's defect frequencies (:func:`_modulation_pins`), bounded where the record
lacks a model line, and the background — coloured noise and lines — what the path's force
leaves of the record (:mod:`cmsim.machine.calibration`, steps 3-4).
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.dynamics.decimation import AntiAliasFilter
from cmsim.features.envelope import band_bank, envelope_lines
from cmsim.features.lines import SLIP_TOLERANCE, line_window
from cmsim.machine.background import Background, BackgroundLine
from cmsim.machine.calibration.background_lines import _classify, _near, _refined
from cmsim.machine.path import TransferPath, smooth_log
from cmsim.run import signal_info

__all__ = ["PATH_SMOOTHING_OCTAVE", "MODEL_LINE_MIN_DB", "PIN_CONSISTENCY", "BROADBAND_SHARE", "FORCE_MODULATION_MIN_SIGMA", "MAX_SHARE", "MODULATION_MIN_SIGMA", "HOUSING_BAND_LOW"]

#: Smoothing of the path's shape, octave.
PATH_SMOOTHING_OCTAVE = 1.0 / 12.0

#: Least height of a model line over the model force's own floor to pin the path, dB.
MODEL_LINE_MIN_DB = 20.0

#: Most a pinned gain may exceed the lowest bound set by model lines the record does not
#: show (6 dB) before the record's line is taken for another line at that frequency.
PIN_CONSISTENCY = 2.0

#: Most of the record's broadband power the model's own broadband force may account for
#: through the path, at any frequency: the rest is the machine's background.
BROADBAND_SHARE = 0.5

#: Least significance of the model force's modulation at its sensor bearing's defect
#: frequencies in a band (its excess over the noise of the squared-envelope spectrum, in
#: standard deviations of that noise) for the band to read the path's gain
#: (:func:`_modulation_pins`): the share goes as the root of the ratio of the record's excess
#: to the force's, so 10σ leaves it 5 % of scatter from the force's side.
FORCE_MODULATION_MIN_SIGMA = 10.0

#: Most of a band's broadband power the model's force may make through the path: the
#: background keeps at least 10 % of the floor (step 4).
MAX_SHARE = 0.9

#: Least significance of the record's modulation (its excess over the noise of the
#: squared-envelope spectrum, in standard deviations of that noise) to read a share; under
#: it the share is only bounded.
MODULATION_MIN_SIGMA = 3.0

#: Lower edge of a housing's resonant band, as a share of the sample rate: below it the
#: path is taken stiffness-controlled (accelerance ∝ f², the ω²/k of a structure below its
#: first mode); the background there (rocking, the motor, the mains) does not shape it.
HOUSING_BAND_LOW = 0.04


def _model_lines(freqs, bearing):
    """Frequencies of the lines the path is read at: on a gear rig the GMF harmonics (the
    gears' tooth counts are what a gearbox's metadata documents; its bearings often are
    not), on a bearing rig the ball pass of the sensor's bearing and its harmonics."""
    if freqs.gmf_hz:
        return [k * freqs.gmf_hz for k in range(1, 13)]
    if bearing in freqs.bearing_names:
        return [h * freqs.bearing(bearing).bpf_hz for h in range(1, 6)]
    return []


def _path_shape(freq, power, fs, over_force=False):
    """A path's shape from a power spectrum: its root, smoothed over
    :data:`PATH_SMOOTHING_OCTAVE`, falling as f² below :data:`HOUSING_BAND_LOW`·fs; a
    spectrum ``over_force`` (the record's over the model force's) is held above the force's
    anti-alias passband (:class:`~cmsim.dynamics.decimation.AntiAliasFilter`, 0.8 of the
    Nyquist frequency): the force falls there by its filter, and the ratio would read a
    path rising to the Nyquist frequency that lifts what the force has left there (the
    twin's demodulation band then went to the top 500 Hz on a bearing baseline whose own
    band is 1-2 kHz)."""
    df = freq[1] - freq[0]
    shape = np.sqrt(np.exp(smooth_log(np.log(np.maximum(power, 1e-300)), freq,
                                      PATH_SMOOTHING_OCTAVE)))
    i_low = int(np.searchsorted(freq, HOUSING_BAND_LOW * fs))
    shape[:i_low] = shape[i_low] * (np.maximum(freq[:i_low], df) / freq[i_low]) ** 2
    if over_force:
        i_high = min(int(np.searchsorted(freq, AntiAliasFilter.passband * 0.5 * fs)),
                     freq.size - 1)
        shape[i_high:] = shape[i_high]
    return shape


def _pins(shape, strong, lines, floor, pin_at, df, weak_family):
    """(pins, bounds, dropped) of a path shape: the gain corrections [(Hz, factor)] the
    model lines ``strong`` that the record shows at ``pin_at`` ask of it; those that the
    lines it does not show allow (their amplitude 10 dB under the record's floor); and, for a
    ``weak_family`` (a healthy bearing's ball pass, often under the floor), the pins another
    harmonic of the family the record does not show contradicts: some other line at that
    frequency. A gear's mesh harmonics are the strongest periodic lines of a gearbox, and a
    housing resonance can lift one harmonic 20 dB over its neighbours (a 2 %-damped mode
    falls 20 dB at 20 % detuning): a missing neighbour bounds the path there (a cap), it
    does not disown the line."""
    pins, bounds = [], []
    for fm, force_amp in strong:
        j = int(round(fm / df))
        match = [(f, a) for f, a in lines if _near(f, fm, df)]
        if match and any(_near(fm, g, df) for g in pin_at):
            f, a = max(match, key=lambda fa: fa[1])
            pins.append((f, a / force_amp / shape[int(round(f / df))]))
        elif not match:
            floor_amp = math.sqrt(2.0 * float(floor[j]) * df * 5 / 10.0)
            bounds.append((fm, floor_amp / force_amp / shape[j]))
    if not weak_family:
        return pins, bounds, []
    family = [(fb, gb) for fb, gb in bounds if any(_near(fb, g, df) for g in pin_at)]
    dropped = [p for p in pins if any(p[1] > PIN_CONSISTENCY * gb for _, gb in family)]
    return [p for p in pins if p not in dropped], bounds, dropped


def _cyclic_power(segs, fs, band, keep):
    """Squared-envelope spectrum of segments band-passed to ``band`` (Hz): the FFT bins in
    it that ``keep`` holds (the broadband: lines out), the squared modulus of their analytic
    signal, its Hann power spectrum over its squared mean, averaged over the segments. A
    band power modulated as e0·(1 + m cos 2πα t) reads m²/4 at α; a stationary noise adds no
    line. ``(alpha_hz, power)``."""
    n = segs[0].size
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    idx = np.flatnonzero((freq >= band[0]) & (freq < band[1]) & keep)
    w = np.hanning(n)
    out = []
    for x in segs:
        z = np.zeros(n, dtype=complex)
        z[idx] = np.fft.fft(x)[idx]
        e = np.abs(np.fft.ifft(z)) ** 2
        out.append(np.abs(np.fft.rfft((e - e.mean()) * w)) ** 2
                   / max(float(e.mean()) * float(w.sum()), 1e-300) ** 2)
    return freq, np.mean(out, axis=0)


def _modulation(alpha, power, cyclic):
    """Per cyclic frequency of ``cyclic``: (excess, noise, bins) of the squared-envelope
    power ``power`` in the line's bins (the line rule with
    :data:`~cmsim.features.lines.SLIP_TOLERANCE`, a bin counted once) over the mean level
    ``noise`` of the bins around it (± max(6 bins, a quarter of its frequency)) that no line
    holds."""
    windows = [line_window(alpha, a, SLIP_TOLERANCE) for a in cyclic]
    held = np.zeros(alpha.size, dtype=bool)
    for win in windows:
        if win is not None:
            held |= win
    out, counted = [], np.zeros(alpha.size, dtype=bool)
    for a, win in zip(cyclic, windows):
        bins = np.zeros(alpha.size, dtype=bool) if win is None else win & ~counted
        counted |= bins
        near = (np.abs(alpha - a) <= max(6 * alpha[1], 0.25 * a)) & ~held
        noise = float(np.mean(power[near])) if np.any(near) else 0.0
        k = int(np.count_nonzero(bins))
        out.append((float(np.sum(power[bins])) - noise * k, noise, k))
    return out


def _sigma(mods, n_segments):
    """Standard deviation of the summed excess of :func:`_modulation` rows ``mods`` under
    noise alone: a bin of the average of K segments' powers scatters by its level over √K."""
    return math.sqrt(sum(noise ** 2 * k for _, noise, k in mods) / n_segments)


def _modulation_pins(shape, spectra, fs, freqs, bearing, above_hz):
    """(pins, bounds, shares) of the path's gain read from the model force's modulation, in
    the bands of :func:`~cmsim.features.envelope.band_bank` beyond ``above_hz`` (the
    highest model line pinning the path) and below the force's anti-alias passband.

    The background (coloured noise and lines) is stationary; the model's force is not: its
    broadband power is modulated at its bearing's defect frequencies (ball pass through the
    load zone; its shaft's own lines are left out: unbalance, run-out and the motor modulate
    a real machine's broadband at the shaft rate, which the model does not). In a band
    where the record is the force through the path (power P_H) plus a
    background (P_B), the modulation depth of the record's band power is that of the force
    through the path times the share s = P_H / (P_H + P_B): the ratio of the two
    squared-envelope lines is s² — the split between path × force and background, which
    the record's spectrum alone cannot tell. The force's modulation is read through the
    path's ``shape`` (its gain cancels), the record's with its lines out; a band reads only
    where the force's lines stand :data:`FORCE_MODULATION_MIN_SIGMA` over their noise and
    would stand :data:`MODULATION_MIN_SIGMA` over the record's (were the record all force,
    the band could tell a share from none); the share is read where the record's excess is
    :data:`MODULATION_MIN_SIGMA` over its noise, else bounded by that, and is at most
    :data:`MAX_SHARE`. The gain correction of the band is
    then √(s · record's broadband power / (shape² · force's broadband power)) over it.

    The bank's bands (fs/8 wide) hold the sidebands of every defect frequency of a bearing
    several times over and leave the envelope spectrum of a 0.5-s segment enough bins to
    average; the share is read at that resolution (fs/16 between band centres) while the
    path's shape keeps its own (:data:`PATH_SMOOTHING_OCTAVE`).
    """
    if bearing not in freqs.bearing_names:
        return [], [], []
    freq, floor, pf_floor = spectra["freq"], spectra["floor"], spectra["pf_floor"]
    cyclic = sorted({ln.frequency_hz for ln in envelope_lines(freqs.bearing(bearing))
                     if ln.family != "shaft" and ln.frequency_hz > 0})
    source = TransferPath("shape", tuple(freq), tuple(np.maximum(shape, 1e-30)))
    forces = [source.apply(force, fs)[edge:edge + n] for force, edge, n in spectra["forces"]]
    top = AntiAliasFilter.passband * 0.5 * fs
    pins, bounds, shares = [], [], []
    for lo, hi in band_bank(fs):
        centre = math.sqrt(lo * hi)
        if centre <= max(above_hz, HOUSING_BAND_LOW * fs) or centre > top:
            continue
        usable = [a for a in cyclic if a < 0.5 * (hi - lo)]
        alpha, p_force = _cyclic_power(forces, fs, (lo, hi), spectra["force_keep"])
        force_mod = _modulation(alpha, p_force, usable)
        kept = [i for i, (ex, noise, k) in enumerate(force_mod)
                if k and ex >= FORCE_MODULATION_MIN_SIGMA * _sigma([(ex, noise, k)],
                                                                   len(forces))]
        if not kept:
            continue
        _, p_rec = _cyclic_power(spectra["fit"], fs, (lo, hi), spectra["keep"])
        rec_mod = _modulation(alpha, p_rec, usable)
        ex_f = sum(force_mod[i][0] for i in kept)
        ex_r = sum(rec_mod[i][0] for i in kept)
        sigma = _sigma([rec_mod[i] for i in kept], len(spectra["fit"]))
        if ex_f < MODULATION_MIN_SIGMA * sigma:
            continue     # the force's modulation would not stand out of the record's noise
        sel = (freq >= lo) & (freq < hi)
        scale = math.sqrt(float(np.sum(floor[sel])) / float(np.sum(shape[sel] ** 2
                                                                    * pf_floor[sel])))
        if ex_r >= MODULATION_MIN_SIGMA * sigma:
            share = min(math.sqrt(ex_r / ex_f), MAX_SHARE)
            pins.append((centre, math.sqrt(share) * scale))
            shares.append((lo, hi, share))
        else:
            share = math.sqrt(MODULATION_MIN_SIGMA * sigma / ex_f)
            if share < MAX_SHARE:
                bounds.append((centre, math.sqrt(share) * scale))
                shares.append((lo, hi, -share))
    return pins, bounds, shares


def _reading(forced, spectra, fs, freqs, bearing, shaft_hz, ref, longest):
    """(path, background, notes, pins kept) of one reading of the path's shape: the
    background's own (``forced`` False) or the background over the model's broadband
    force.

    Parameters
    ----------
    forced : bool
        Which shape.
    spectra : dict
        ``freq``, ``floor`` (the record's broadband PSD), ``pf_floor`` (the model force's),
        ``lines`` (the record's), ``force_lines`` and ``strong`` (the model force's, and
        those standing :data:`MODEL_LINE_MIN_DB` over its floor).
    fs : float
        Sample rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies
        The rig's frequencies at the record's speed.
    bearing : str
        The sensor's bearing.
    shaft_hz : (float, float)
        Input and output shaft rates, Hz.
    ref : MeasuredRecord
        The first baseline (rig, unit, metadata).
    longest : numpy.ndarray
        The longest baseline signal (the background lines' frequencies are read on it).
    """
    freq, floor, pf_floor = spectra["freq"], spectra["floor"], spectra["pf_floor"]
    lines, force_lines = spectra["lines"], spectra["force_lines"]
    df = freq[1] - freq[0]
    rig = ref.rig
    notes = []
    shape = _path_shape(freq, floor / pf_floor if forced else floor, fs, forced)
    pins, bounds, dropped = _pins(shape, spectra["strong"], lines, floor,
                                  _model_lines(freqs, bearing), df,
                                  weak_family=not freqs.gmf_hz)
    if dropped:
        notes.append(f"{len(dropped)} line(s) of the record at a model line's frequency "
                     f"({', '.join(f'{p[0]:.1f}' for p in dropped[:4])} Hz) not taken as "
                     "the model's: the gain they imply would show another harmonic of that "
                     "family, which the record does not have")
    band = (freq >= 0.05 * fs) & (freq <= 0.45 * fs)
    mod_pins, mod_bounds, shares = _modulation_pins(
        shape, spectra, fs, freqs, bearing, max((p[0] for p in pins), default=0.0))
    bounds = bounds + mod_bounds
    if pins:
        notes.append(f"path gain pinned by {len(pins)} model line(s) the record shows "
                     f"({', '.join(f'{p[0]:.1f}' for p in sorted(pins)[:8])} Hz)")
    if shares:
        notes.append("path gain read from the modulation of the record's broadband at the "
                     "sensor bearing's defect frequencies, over the model force's, in "
                     f"{len(shares)} band(s): share of the broadband the model's force makes "
                     + ", ".join(f"{lo:.0f}-{hi:.0f} Hz {'≤ ' if sh < 0 else ''}{abs(sh):.2f}"
                                 for lo, hi, sh in shares))
    if pins or mod_pins:
        points = sorted(pins + mod_pins)
        lowest = points[0][0]
        if lowest > 2.0 * max(shaft_hz):
            # no model line the record shows pins the shaft orders' band: the model makes no
            # shaft line, and the baseline's own are background
            notes.append(f"path gain under {lowest:.0f} Hz not read from the baseline (its "
                         f"lowest pin): held at that pin's correction on the assumed shape "
                         f"(f² under {HOUSING_BAND_LOW * fs:.0f} Hz); the rotating forces of "
                         "unbalance and misalignment reach the sensor at the shaft orders "
                         "through gains of their own (shaft_gain)")
    else:
        nominal = np.abs(rig.housing.accelerance(freq[band]))
        scale = ref.unit_scale if ref.unit_scale is not None else 1.0
        g = math.exp(float(np.mean(np.log(nominal / scale)) - np.mean(np.log(shape[band]))))
        points = [(float(freq[band][0]), g), (float(freq[band][-1]), g)]
        notes.append("path gain not identifiable on this baseline (no model line stands out "
                     "in it): the rig's nominal housing path averaged over 0.05-0.45·fs; "
                     "fault sizes read through it carry that uncertainty")
        if ref.unit_scale is None:
            notes.append("sensor unit unknown: the path is in sensor unit per N with the "
                         "nominal housing's accelerance taken as 1 unit = 1 m/s²")

    def correction(pts):
        pts = sorted(pts)
        f_, c_ = np.array([p[0] for p in pts]), np.log([p[1] for p in pts])
        return np.exp(np.interp(np.log(np.maximum(freq, df)), np.log(f_), c_))

    corr = correction(points)
    capped = [(fb, gb) for fb, gb in bounds if corr[int(round(fb / df))] > gb]
    if capped:     # model lines, or modulation, the record does not show cap the path there
        corr = correction(points + capped)
        notes.append(f"path gain capped at {len(capped)} frequencies where the record does "
                     f"not show the model's lines or modulation "
                     f"({', '.join(f'{f:.1f}' for f, _ in sorted(capped)[:6])}"
                     f"{', …' if len(capped) > 6 else ''} Hz)")
    gain = shape * corr
    if not (pins or mod_pins):   # a prior gain must keep the model's broadband under the floor
        gain = np.minimum(gain, np.sqrt(BROADBAND_SHARE * floor / pf_floor))
    unit = str((ref.meta.get("sensor") or {}).get("unit") or "")
    path = TransferPath(f"F_{bearing}_{signal_info(ref.model_signal).direction}",
                        tuple(freq), tuple(np.maximum(gain, 1e-30)), unit)

    # the background: the rest of the broadband, and the lines the model does not make
    noise = np.maximum(floor - gain ** 2 * pf_floor, (1.0 - MAX_SHARE) * floor)
    pinned = [p[0] for p in pins]
    own = []              # what the model's own lines put there is not background
    for f, a in lines:
        if any(_near(f, g, df) for g in pinned):
            continue
        made = [fa for fa in force_lines if _near(f, fa[0], df)]
        if made:
            model_amp = float(np.interp(f, freq, gain)) * max(fa[1] for fa in made)
            a = math.sqrt(max(a * a - model_amp * model_amp, 0.0))
        if a > 0.0:
            own.append((f, a))
    fine, fine_df = _refined(own, longest, fs, df)
    bg_lines = [BackgroundLine(*_classify(f, shaft_hz, fine_df, freqs.gmf_hz), a)
                for f, a in fine]
    return path, Background(tuple(freq), tuple(noise), tuple(bg_lines)), notes, len(pins)
