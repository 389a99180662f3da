"""Calibrate a machine on healthy baseline records: what the model cannot know of it.

From one or more healthy records of one machine (same channel and sample rate), every
segment of :data:`SEGMENT_S` alternately goes to the **fit** set (even) and the
**held-out** set (odd). On the fit set:

1. **Spectrum and lines.** The averaged power spectrum (Hann) of the segments; its narrow
   lines are the bins standing :data:`LINE_MIN_DB` over a running median of ±
   :data:`FLOOR_HALF_WIDTH_HZ` (lines have no width there, the broadband has); the running
   mean with the lines' bins masked is the smooth **background spectrum** B(f) (a running
   median alone would sit 0.3-1.6 dB under the mean of a noisy estimate).
2. **Model force.** The nominal (healthy) model at the record's operating point is
   simulated for :data:`N_SEEDS` seeds; its force spectrum gives the lines the model makes
   (GMF harmonics, the ball pass of the sensor's bearing: those standing 20 dB over the
   force's own floor) and its broadband level.
3. **Transfer path.** Its *shape* is that of the background, √B(f) smoothed over
   :data:`PATH_SMOOTHING_OCTAVE` octave: a machine's structure shapes both its broadband
   excitation and the response to the model's forces (the assumption behind choosing a
   demodulation band where the background resonates, Randall & Antoni 2011). A 1/12-octave
   smoothing resolves resonances down to about 3 % damping (half-power width 2ζf ≥ f/16)
   and averages the spectral estimate over enough bins to leave a ±0.5 dB scatter. Below
   :data:`HOUSING_BAND_LOW`·fs the path falls as f² (stiffness-controlled); read over the
   model's force, it is held above the force's anti-alias passband (:func:`_path_shape`).
   Its
   *gain* is pinned where a model line (GMF harmonics on a gear rig, the sensor bearing's
   ball pass on a bearing rig) stands in the record too (the ratio of the measured line to
   the model's, interpolated in log frequency between such lines). Beyond the highest such
   line (a bearing's ball pass pins only the first few hundred hertz, under the housing
   band) the gain is read from the **modulation** of the record's broadband
   (:func:`_modulation_pins`): the background is stationary, the model's force is
   modulated at its bearing's defect frequencies, so the depth of that modulation in the
   record over the force's is the share of the band's power the force makes through the
   path — what splits the record's broadband between path × force and background, which
   its spectrum alone cannot. Where neither reads it
   (a healthy ball bearing's ball pass is usually below the floor) the gain is that of the
   rig's nominal housing path averaged over 0.05-0.45·fs, lowered if that would show a model
   line the record does not, and the machine file says so: fault sizes read through such a
   path carry that uncertainty. Where the background is not the path's (white sensor noise
   under a model's lines) the pins read alike through the background *over the model's
   broadband force* instead. Both shapes are read to the end (path, background): the one
   that keeps more pins is kept, on as many the one whose twin is nearer the *fit*
   segments' features (:data:`MISFIT_CAP`; pins below :data:`HOUSING_BAND_LOW`·fs, all a
   bearing baseline has, cannot tell the shapes apart, both falling as f² there, and the
   scatter of their corrections chose by rounding), and with no pin at all the
   background's own (a twin matches a healthy record's broadband through either).
   A gearbox's mesh harmonics are always the
   model's lines; a healthy bearing's ball-pass line is disowned when the gain it implies
   would show another harmonic the record lacks (:func:`_pins`).
4. **Background.** The coloured noise is B(f) less what the model's broadband force puts
   there through the path (at least 1 − :data:`MAX_SHARE` of B); the lines are the measured
   lines less what the model's own lines put there through the path (powers subtracted, the
   lines matched within :data:`LINE_TOLERANCE` as the pins are), each filed as an order of
   the input or output shaft when it sits on one (so it follows the speed), else at its
   frequency (the mains, other machines). The **rotating forces** of an unbalance or a
   misalignment reach the sensor at the sensor bearing's shaft orders 1-3 through gains of
   their own: the baseline's line at each order over the force of a residual unbalance of
   grade :data:`BALANCE_GRADE_MM_S` (:func:`_shaft_gains`), so that they are sized as a
   trend against the baseline's own lines.
5. **Bearing clearance.** A healthy ball bearing under load makes a comb of ball-pass lines
   (varying compliance) whose level its clearance sets: strong with a clearance (fewer
   balls loaded), weak in line contact or under a preload. A machine's clearance is rarely
   documented, and a model comb the record lacks beside a mesh harmonic cannot be taken out
   by a smooth path (at 20 N m the default rig's sixth ball pass sits 5 Hz from its GMF).
   On a gear rig steps 2-4 are read for the documented clearance and for each of
   :data:`CLEARANCE_CANDIDATES_M`; another is kept only when its twin is nearer the fit
   segments by :data:`CLEARANCE_EVIDENCE` (capped misfit) and no farther uncapped. On a
   bearing rig the ball pass is the family the path is pinned on, and its absent harmonics
   cap the path (step 3); there the documented clearance stays: a preloaded CWRU twin fitted
   its healthy baseline better (held-out χ²/feature 1.27 → 0.74) but named none of the six
   fault records, 4 of which the twin at the documented 5 µm names.
6. **Spread and fit quality.** :func:`cmsim.features.relative_features` of every baseline
   segment give each feature's mean and segment-to-segment spread; the kept twin (model
   force → path + background, :data:`N_TWIN_SEEDS` new seeds, a segment each) is compared
   with the held-out segments feature by feature: z = (twin − baseline) / spread, and,
   since one record is one realisation of the model's random parts (cage phases, slip)
   while the twin averages several, also over √(spread² + the twin's own spread²).

The operating point is the record's (speed read from the signal); the speed wobble is the
relative RMS of the strongest shaft-order line's instantaneous frequency, less what the noise
under the line makes of it, recorded for information — or not identifiable (None) when no
shaft order stands :data:`WOBBLE_MIN_SNR` over its noise.

References
----------
.. [1] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial",
   MSSP 25 (2011) 485-520.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from cmsim.dynamics.decimation import AntiAliasFilter
from cmsim.errors import ParameterError
from cmsim.features import relative_features
from cmsim.features.envelope import band_bank, envelope_lines
from cmsim.features.lines import SLIP_TOLERANCE, line_window
from cmsim.features.relative import segments
from cmsim.frequencies import rig_frequencies
from cmsim.machine.background import Background, BackgroundLine
from cmsim.machine.machine import Machine, model_force, static_load
from cmsim.machine.path import TransferPath, smooth_log
from cmsim.run import signal_info
from cmsim.spectra.floor import segment_psd
from cmsim.spectra.line_detector import (FLOOR_HALF_WIDTH_HZ, LINE_MIN_DB, LINE_TOLERANCE,
                                          MAX_LINES, detect_lines, line_free)

__all__ = ["calibrate", "SEGMENT_S", "N_SEEDS", "LINE_MIN_DB", "FLOOR_HALF_WIDTH_HZ",
           "PATH_SMOOTHING_OCTAVE", "MAX_LINES", "feature_rows"]

#: Segment length, s (the segments compare reads).
SEGMENT_S = 0.5
#: Seeds of the nominal model simulated for the force spectrum.
N_SEEDS = 3
#: Seeds (one segment each) of the twin compared with the held-out baseline segments.
N_TWIN_SEEDS = 6
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
#: Cap on a feature's z (over the baseline's segment-to-segment spread) in the misfit that
#: chooses the path's shape: a feature the twin misses by far counts as 4σ, so one feature
#: does not decide it. The twin's own spread is not in it: a twin made noisy by a wrong
#: shape must not look nearer for it.
MISFIT_CAP = 4.0
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
#: Least power ratio of a shaft-order line over the noise beside it for its instantaneous
#: frequency to tell the speed wobble (20 dB: the noise then adds under 0.5 % of the line's
#: phase wander).
WOBBLE_MIN_SNR = 100.0
#: Shaft-rate sidebands each side of a mesh harmonic whose lines are taken for the mesh's
#: own (:func:`_classify`): those the features read (``sb23``: ±2, ±3).
MESH_FAMILY_SIDEBANDS = 3
#: Lower edge of a housing's resonant band, as a share of the sample rate: below it the
#: path is taken stiffness-controlled (accelerance ∝ f², the ω²/k of a structure below its
#: first mode); the background there (rocking, the motor, the mains) does not shape it.
HOUSING_BAND_LOW = 0.04
#: Balance grade G = e·Ω (mm/s) the baseline's rotor is taken to have, its shaft-rate line
#: being its residual unbalance (:func:`_shaft_gains`): ISO 21940-11 G 6.3, the grade of
#: electric motors, pumps, fans and gear wheels of general machinery.
BALANCE_GRADE_MM_S = 6.3
#: Shaft orders whose baseline lines give a rotating force's gain (:func:`_shaft_gains`):
#: those of unbalance (1×) and misalignment (2×, 3×).
SHAFT_ORDERS = 3
#: Bearing clearances tried besides the documented one, m: line contact and a light preload
#: (:meth:`Rig.with_clearance <cmsim.rig.Rig.with_clearance>`; negative is a preload).
CLEARANCE_CANDIDATES_M = (0.0, -5e-6)
#: Factor by which another clearance's twin must be nearer the fit segments (capped misfit,
#: :data:`MISFIT_CAP`) than the documented clearance's to replace it: the documented value is
#: the prior, and a twin's misfit on ~5 segments scatters by some tens of percent.
CLEARANCE_EVIDENCE = 1.5


def _clearance_words(c):
    """A clearance in words: "15 µm clearance", "line contact", "5 µm preload"."""
    if c == 0.0:
        return "line contact (no clearance)"
    return f"{abs(c) * 1e6:g} µm {'clearance' if c > 0 else 'preload'}"


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


def _shaft_gains(lines, rig, bearing, fr, df, forces):
    """({order: gain}, force N, share of the static load): the gains, sensor unit per N,
    from a rotating force at the orders 1 to :data:`SHAFT_ORDERS` of the sensor bearing's
    shaft (turning at ``fr`` Hz) to the sensor, read from the baseline's lines there (an
    order without a line gets none: the path's own gain there is used).

    The model makes no shaft line, so no model line reads the path there, yet an unbalance
    or a misalignment is judged there: held on the path's assumed f² shape from its lowest
    pin hundreds of hertz up, an unbalance of twice the static load lifted the twin's 1×
    line by at most 0.9 dB (the angle generator's bearing machine of seed 0) where the
    drawn machine's grows 12 dB. A baseline's shaft-rate line is
    its residual unbalance through the machine, so the gain at 1× is that line over the
    force of a residual unbalance of grade :data:`BALANCE_GRADE_MM_S`, e·Ω (ISO 21940-11):
    m·e·Ω² = m·G·Ω on the rotor, half of it on each of its shaft's bearings (both correction
    planes allotted alike), m the shaft's masses in the model (its gear or rotor and its
    bearing nodes). What drives a healthy machine's 2× and 3× lines (residual misalignment,
    run-out, a coupling) has no grade, and is taken as a force of the same magnitude: an
    unbalance or a misalignment is then sized as a trend against the baseline's own lines
    at its orders, which is what practice reads. These gains carry only the rotating
    forces (a sinusoid at a shaft order: a gain is all of its path that a spectrum sees);
    interpolated into the structural path they lifted it over a decade below its lowest
    pin, where the model's own lines then took the mains line for theirs. The static load
    the force is a share of is the model force's, the level an unbalance cause's relative
    amplitude refers to.
    """
    shaft = int(bearing.split("b")[0]) - 1                # node "<shaft>b<k>"
    s = rig.shafts[shaft]
    centre = ((rig.gears.driving if shaft == 0 else rig.gears.driven).mass_kg
              if rig.gears is not None else s.rotor.mass_kg)
    mass = centre + s.bearing_1.mass_kg + s.bearing_2.mass_kg
    force = 0.5 * mass * BALANCE_GRADE_MM_S * 1e-3 * 2.0 * math.pi * fr
    static = float(np.mean([static_load(x[e:e + n]) for x, e, n in forces]))
    gains = {}
    for k in range(1, SHAFT_ORDERS + 1):
        match = [a for f, a in lines if _near(f, k * fr, df)]
        if match and fr > 0.0:
            gains[k] = max(match) / force
    return gains, force, force / static


def _shaft_words(shaft, fr):
    """The machine file's note on the shaft-order gains (:func:`_shaft_gains`)."""
    gains, force, share = shaft
    if not gains:
        return ("no shaft-order line in the baseline: the rotating forces of unbalance and "
                "misalignment reach the sensor through the path's assumed shape there")
    return (f"rotating forces reach the sensor at the shaft orders "
            f"({', '.join(f'{k}× {k * fr:.2f} Hz' for k in sorted(gains))}) through gains "
            f"read from the baseline's lines there, each taken as the response to the force "
            f"of a residual unbalance of grade G {BALANCE_GRADE_MM_S:g} (ISO 21940-11; "
            f"{force:.3g} N on this bearing, {share:.2g} of its static load): an unbalance or "
            "a misalignment is sized as a trend against the baseline's own lines at its "
            f"orders (a rotor balanced to G 2.5 reads {BALANCE_GRADE_MM_S / 2.5:.1f}× too "
            "large)")


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


def feature_rows(segs, fs_hz, freqs, bearings, unit_scale):
    """Features of each segment: :func:`cmsim.features.relative_features`, plus ``level_db``
    (dB re 1 m/s²) when the unit is known; ``(names, array (n_segments, n_features))``.

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
    """
    rows = []
    for x in segs:
        f = relative_features(x, fs_hz, freqs, bearings)
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


def calibrate(records, *, seg_s=SEGMENT_S, n_seeds=N_SEEDS, seed=0, name=None):
    """Calibrate the twin of a machine on its healthy baseline record(s).

    Parameters
    ----------
    records : sequence of MeasuredRecord
        Healthy records of one machine (:func:`cmsim.measured.read_record`, or a part of
        one: :meth:`MeasuredRecord.span <cmsim.measured.MeasuredRecord.span>`), same channel
        and sample rate; the model rig and operating point of the first are the machine's.
    seg_s : float
        Segment length, s (each record needs at least 4 segments).
    n_seeds : int
        Model simulations for the force spectrum.
    seed : int
        Seed of the model simulations and of the twin's background.
    name : str, optional
        Name of the machine (default: the first record's file).

    Returns
    -------
    Machine

    Raises
    ------
    ParameterError
        No record, records of different channels or sample rates, too short a record.
    """
    records = list(records)
    if not records:
        raise ParameterError("calibrate needs at least one baseline record", param="baseline")
    ref = records[0]
    fs = ref.fs_hz
    for r in records[1:]:
        if r.channel != ref.channel or abs(r.fs_hz / fs - 1.0) > 1e-3:
            raise ParameterError(f"baseline records must share a channel and a sample rate: "
                                 f"{ref.channel} at {fs:g} Hz vs {r.channel} at {r.fs_hz:g} Hz",
                                 param="baseline")
    fit, held = [], []
    for r in records:
        x = r.signal
        segs = [x[a:b] for a, b in segments(x.size, fs, seg_s)]
        if len(segs) < 4:
            raise ParameterError(f"baseline {r.record_id or r.path or 'record'} gives "
                                 f"{len(segs)} segments of {seg_s:g} s; needs >= 4",
                                 param="baseline")
        fit += segs[0::2]
        held += segs[1::2]
    rig, op = ref.rig, ref.op
    freqs = rig_frequencies(rig, op)
    bearing = signal_info(ref.model_signal).component
    shaft_hz = (freqs.fr1_hz, freqs.fr2_hz if freqs.fr2_hz is not None else freqs.fr1_hz)
    fr = freqs.bearing(bearing).shaft_hz                       # the sensor bearing's shaft
    notes = [f"operating point: {op.speed_rpm:.2f} rpm from the record; torque "
             f"{op.torque_nm:g} N m and radial load {op.radial_load_n:g} N as the record's "
             "model assumes (the load is not identified from a healthy record)"]

    # 1. the record: spectrum, its lines, the smooth background spectrum
    freq, psd = segment_psd(fit, fs)
    df = freq[1] - freq[0]
    lines, floor = _lines_and_floor(freq, psd)

    # the baseline's spread (step 6; each reading of steps 2-5 below is scored against it)
    bearings = list(rig.bearing_names)
    names, all_rows = feature_rows(fit + held, fs, freqs, bearings, ref.unit_scale)
    # a feature a segment cannot read (a line beyond its resolution) is NaN there; one no
    # two segments read has no spread and is left out
    seen = np.sum(np.isfinite(all_rows), axis=0) >= 2
    spread = {k: (float(np.nanmean(all_rows[:, i])), float(np.nanstd(all_rows[:, i], ddof=1)))
              for i, k in enumerate(names) if seen[i]}
    fit_rows, held_rows = all_rows[:len(fit)], all_rows[len(fit):]

    wobble = _speed_wobble(np.concatenate([r.signal for r in records]), fs, freqs.fr1_hz)
    longest = max(records, key=lambda r: r.signal.size).signal
    baseline = {"freq": freq, "floor": floor, "lines": lines, "fit": fit,
                "keep": line_free(freq, psd)}
    calibrated_on = tuple(f"{r.record_id or r.path or 'record'}"
                          + (f" [{r.meta['span_s'][0]:g}, {r.meta['span_s'][1]:g}] s"
                             if r.meta.get("span_s") else "")
                          + " (even segments fit, odd held out)" for r in records)

    def twin_on(model_rig):
        """Steps 2-4 on one model rig: (capped misfit, chi2 per feature, machine, twin's
        feature rows), the misfits the twin's against the fit segments."""
        # 2. the nominal model's force
        force_runs = [model_force(model_rig, op, ref.model_signal, fs, seg_s, seed + 7777 * s)
                      for s in range(n_seeds)]
        twin_forces = [model_force(model_rig, op, ref.model_signal, fs, seg_s,
                                   seed + 1 + 7777 * (s + n_seeds)) for s in range(N_TWIN_SEEDS)]
        forces = [force[edge:edge + n] for force, edge, n in force_runs]
        _, pf = segment_psd(forces, fs)

        # 3-4. the path and the background, read twice: the path's shape that of the
        # background, or of the background over the model's broadband force; its gain
        # pinned by the model lines the record shows and bounded by those it does not show.
        # Of the two, the one whose twin is nearer the fit segments is kept.
        force_lines, pf_floor = _lines_and_floor(freq, pf)
        strong = [(f, a) for f, a in force_lines
                  if pf[int(round(f / df))] >= 10.0 ** (MODEL_LINE_MIN_DB / 10.0)
                  * pf_floor[int(round(f / df))]]
        spectra = dict(baseline, pf_floor=pf_floor, force_lines=force_lines, strong=strong,
                       forces=force_runs + twin_forces, force_keep=line_free(freq, pf))
        shaft = _shaft_gains(lines, model_rig, bearing, fr, df, force_runs)
        candidates = []
        for forced in (False, True):
            path, background, chain_notes, n_pins = _reading(forced, spectra, fs, freqs,
                                                             bearing, shaft_hz, ref, longest)
            machine = Machine(
                name=name or (ref.record_id or "machine"), rig=model_rig,
                shaft_gain=shaft[0],
                channel=ref.channel, model_signal=ref.model_signal, fs_hz=fs, op=op,
                path=path, background=background, unit=path.unit,
                unit_scale=ref.unit_scale, components=dict(ref.components), segment_s=seg_s,
                speed_wobble=wobble, calibrated_on=calibrated_on,
                notes=tuple(notes + chain_notes + [_shaft_words(shaft, fr)]))
            twin = [machine.sensor_signal(force, edge, n, seed + 31 * s)
                    for s, (force, edge, n) in enumerate(twin_forces)]
            _, twin_rows = feature_rows(twin, fs, freqs, bearings, ref.unit_scale)
            z_fit, _ = _misfit(names, twin_rows, fit_rows, spread)
            score = float(np.mean([min(v * v, MISFIT_CAP ** 2) for v in z_fit.values()])) \
                if z_fit else 0.0
            chi2_fit = float(np.mean([v * v for v in z_fit.values()])) if z_fit else 0.0
            candidates.append((-n_pins, score, forced, machine, twin_rows, chi2_fit))
        if not any(c[0] for c in candidates):
            # no model line pins the path: its gain is a prior, and a twin can match a
            # healthy record's broadband through either shape, so the fit does not tell
            # them apart
            _, score, forced, machine, twin_rows, chi2_fit = candidates[0]
            why = "no model line pins the path"
        else:
            (neg_pins, score, forced, machine, twin_rows, chi2_fit), other = sorted(
                candidates, key=lambda c: c[:3])
            why = (f"it keeps more pins ({-neg_pins} against {-other[0]})"
                   if neg_pins != other[0] else
                   f"its twin's misfit on the fit segments, chi2 per feature with z capped at "
                   f"{MISFIT_CAP:g}, {score:.2f} against {other[1]:.2f} for the other shape")
        shape_words = ("the background over the model's broadband force" if forced
                       else "the background's own")
        machine = replace(machine, notes=machine.notes + (f"path shape: {shape_words} ({why})",))
        return score, chi2_fit, machine, twin_rows

    # 5. the bearings' clearance (gear rigs): a healthy bearing's ball passes under load
    # (varying compliance) make a comb of lines whose level the clearance sets, and a
    # baseline shows it or not; the documented clearance is kept unless another one's twin
    # is nearer the fit segments by CLEARANCE_EVIDENCE (capped) and no farther uncapped
    first = twin_on(rig)
    documented = {b.clearance_m for s in rig.shafts for b in (s.bearing_1, s.bearing_2)}
    tried = [(c, twin_on(rig.with_clearance(c)))
             for c in (CLEARANCE_CANDIDATES_M if rig.gears is not None else ())
             if documented != {c}]
    better = [(c, reading) for c, reading in tried
              if reading[0] * CLEARANCE_EVIDENCE <= first[0] and reading[1] <= first[1]]
    if better:
        c, (score, _, machine, twin_rows) = min(better, key=lambda cr: cr[1][0])
        machine = replace(machine, notes=machine.notes + (
            f"bearing clearance: {_clearance_words(c)} instead of the documented "
            f"{', '.join(_clearance_words(d) for d in sorted(documented))}: its twin's "
            f"misfit on the fit segments (chi2 per feature with z capped at {MISFIT_CAP:g}) "
            f"is {score:.2f} against {first[0]:.2f} (the clearance sets the level of a healthy "
            "bearing's ball-pass comb and how many balls carry the load)",))
    else:
        score, _, machine, twin_rows = first
        why = (f"no other clearance's twin nearer the fit segments by {CLEARANCE_EVIDENCE:g}x"
               if tried else "a bearing rig's clearance is not read")
        machine = replace(machine, notes=machine.notes + (
            f"bearing clearance: the documented "
            f"{', '.join(_clearance_words(d) for d in sorted(documented))} kept ({why})",))

    # 6. the twin on the held-out segments
    z, z_model = _misfit(names, twin_rows, held_rows, spread)
    worst = max(z, key=lambda k: abs(z[k])) if z else None
    worst_m = max(z_model, key=lambda k: abs(z_model[k])) if z_model else None
    quality = {"z": z, "worst_feature": worst,
               "worst_z": float(z[worst]) if worst else float("nan"),
               "chi2_per_feature": float(np.mean([v * v for v in z.values()])) if z else 0.0,
               "z_with_model_spread": z_model, "worst_feature_with_model_spread": worst_m,
               "worst_z_with_model_spread": float(z_model[worst_m]) if worst_m
               else float("nan"),
               "chi2_per_feature_with_model_spread":
                   float(np.mean([v * v for v in z_model.values()])) if z_model else 0.0,
               "n_features": len(z), "held_out_segments": len(held),
               "twin_segments": int(twin_rows.shape[0])}
    return replace(machine, spread=spread, fit_quality=quality)
