"""Bearing defect families in the envelope spectrum: THE envelope-families extractor.

Used alike by the ``envelope`` baseline (:mod:`cmsim.diagnostics.baselines`), the sim-to-real
features (:mod:`cmsim.diagnostics.syn2real`) and the comparison with a measured record
(:func:`cmsim.features.relative_features`, which reads the same lines of the same
demodulated spectrum over the spectrum's median level instead of the local one, the
reference its χ² was calibrated with).

Lines (:func:`envelope_lines`), each with the spacing of its family:

===========  ============================================================  =======
family       lines (names)                                                 spacing
===========  ============================================================  =======
outer_race   h·BPFO, h = 1, 2, 3 (``bpfo_1 bpfo_2 bpfo_3``)                BPFO
inner_race   BPFI, 2·BPFI, BPFI ∓ f_s (``bpfi_1 bpfi_2 bpfi_m1 bpfi_p1``)  BPFI
ball         2·BSF, 4·BSF, 2·BSF ∓ FTF (``bsf2_1 bsf2_2 bsf2_mftf          2·BSF
             bsf2_pftf``)
cage         FTF (``ftf``)                                                 f_s
shaft        f_s, 2·f_s (``shaft_1 shaft_2``)                              f_s
===========  ============================================================  =======

(f_s: rate of the bearing's shaft. A ball defect hits both races, hence 2·BSF; it enters and
leaves the load zone with the cage, hence the FTF sidebands; an inner-race defect turns with
the shaft through the load zone, hence the f_s sidebands. The FTF line itself is not scored
with the ball family: any loaded bearing whose cage runs unevenly shows it, and counted in
the ball score it lowers the sim-to-real envelope rule's ball recall on CWRU from 13 to 5 %.)

A line's **ratio** is its amplitude (the line rule of :mod:`cmsim.features.lines`, with
:data:`~cmsim.features.lines.SLIP_TOLERANCE`) over the median of the envelope spectrum within
± max(:data:`LOCAL_MEDIAN_MIN_BINS` bins, :data:`LOCAL_MEDIAN_FRACTION` × spacing) around it:
dimensionless, so an unknown sensor unit, gain or transfer path drops out; a bin of Gaussian
noise reads about 1.5. A family's **score** is the geometric mean of its lines' ratios.

The envelope spectrum (:func:`demodulated_spectrum`) is that of the band of the band rule
(:func:`~cmsim.features.lines.demodulation_band`), Hann window. The sim-to-real features read
the same lines in every band of a fixed bank instead (:func:`band_bank_features`).

References
----------
.. [1] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", MSSP 25
   (2011) 485-520.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError
from cmsim.features.lines import (FALLBACK_BAND, SLIP_TOLERANCE, demodulation_band,
                                  highest_fault_hz, line_amplitude, line_amplitudes_at,
                                  line_bins)
from cmsim.frequencies import BearingFrequencies
from cmsim.spectra.envelope import envelope_spectrum

__all__ = ["EnvelopeLine", "envelope_lines", "line_amplitudes", "line_ratios", "local_level",
           "family_scores",
           "demodulated_spectrum", "band_excess", "band_bank", "band_bank_features", "FAULT_FAMILIES",
           "LOCAL_MEDIAN_FRACTION", "LOCAL_MEDIAN_MIN_BINS", "ENVELOPE_LINE_NAMES"]

#: Families of a bearing defect, in the order of the family scores.
FAULT_FAMILIES = ("outer_race", "inner_race", "ball")

#: Half-width of the local-median window around a line, × the family spacing.
LOCAL_MEDIAN_FRACTION = 0.5

#: Least half-width of the local-median window, bins.
LOCAL_MEDIAN_MIN_BINS = 10


@dataclass(frozen=True)
class EnvelopeLine:
    """One line of a defect family in the envelope spectrum.

    Attributes
    ----------
    name : str
        Line name (``"bpfo_1"``, ``"bpfi_m1"``, ``"ftf"``, ...).
    family : str
        ``"outer_race"``, ``"inner_race"``, ``"ball"``, ``"cage"`` or ``"shaft"``.
    frequency_hz : float
        Nominal frequency, Hz.
    spacing_hz : float
        Spacing of the family (sets the local-median window), Hz.
    """

    name: str
    family: str
    frequency_hz: float
    spacing_hz: float


def envelope_lines(bf):
    """The lines of a bearing's defect families (table in the module docstring).

    Parameters
    ----------
    bf : cmsim.frequencies.BearingFrequencies
        The bearing's frequencies (``shaft_hz``, ``bpfo_hz``, ``bpfi_hz``, ``bsf_hz``,
        ``ftf_hz``).

    Returns
    -------
    tuple of EnvelopeLine
    """
    fs_, o, i, b2, c = bf.shaft_hz, bf.bpfo_hz, bf.bpfi_hz, 2.0 * bf.bsf_hz, bf.ftf_hz
    return (EnvelopeLine("bpfo_1", "outer_race", o, o),
            EnvelopeLine("bpfo_2", "outer_race", 2 * o, o),
            EnvelopeLine("bpfo_3", "outer_race", 3 * o, o),
            EnvelopeLine("bpfi_1", "inner_race", i, i),
            EnvelopeLine("bpfi_2", "inner_race", 2 * i, i),
            EnvelopeLine("bpfi_m1", "inner_race", i - fs_, i),
            EnvelopeLine("bpfi_p1", "inner_race", i + fs_, i),
            EnvelopeLine("bsf2_1", "ball", b2, b2),
            EnvelopeLine("bsf2_2", "ball", 2 * b2, b2),
            EnvelopeLine("bsf2_mftf", "ball", b2 - c, b2),
            EnvelopeLine("bsf2_pftf", "ball", b2 + c, b2),
            EnvelopeLine("ftf", "cage", c, fs_),
            EnvelopeLine("shaft_1", "shaft", fs_, fs_),
            EnvelopeLine("shaft_2", "shaft", 2 * fs_, fs_))


#: Names of the lines of :func:`envelope_lines`, in order.
ENVELOPE_LINE_NAMES = tuple(ln.name for ln in envelope_lines(BearingFrequencies(
    shaft_hz=1.0, ftf_hz=1.0, bpfo_hz=1.0, bpfi_hz=1.0, bsf_hz=1.0, bpf_hz=1.0)))


def _local_window(freq, line):
    df = float(freq[1] - freq[0])
    w = max(LOCAL_MEDIAN_MIN_BINS * df, LOCAL_MEDIAN_FRACTION * line.spacing_hz)
    return (freq >= line.frequency_hz - w) & (freq <= line.frequency_hz + w)


def local_level(freq, amp, line):
    """Median of a spectrum in the local window of a line (see the module docstring).

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz.
    amp : numpy.ndarray, shape (..., n_bins)
        Amplitude spectra.
    line : EnvelopeLine

    Returns
    -------
    float or numpy.ndarray of shape amp.shape[:-1]
    """
    return np.median(np.asarray(amp)[..., _local_window(freq, line)], axis=-1)


def line_amplitudes(freq, amp, lines, tolerance=SLIP_TOLERANCE):
    """Each line's amplitude (the line rule), by line name.

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz, uniformly spaced from 0.
    amp : numpy.ndarray, shape (n_bins,)
        Envelope amplitude spectrum.
    lines : sequence of EnvelopeLine
    tolerance : float
        Relative tolerance of the line rule.

    Returns
    -------
    dict of str to float
        NaN for a line outside (0, last bin).
    """
    f = np.array([ln.frequency_hz for ln in lines], dtype=float)
    a = line_amplitudes_at(freq, amp, np.where((f > 0.0) & (f < freq[-1]), f, math.nan),
                           tolerance)
    return {ln.name: float(v) for ln, v in zip(lines, a)}


def line_ratios(freq, amp, lines, tolerance=SLIP_TOLERANCE):
    """Each line's amplitude over its local median (see the module docstring).

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz, uniformly spaced from 0.
    amp : numpy.ndarray, shape (..., n_bins)
        Envelope amplitude spectra (several along the leading axes, e.g. bands).
    lines : sequence of EnvelopeLine
    tolerance : float
        Relative tolerance of the line rule.

    Returns
    -------
    numpy.ndarray, shape amp.shape[:-1] + (len(lines),)
        Linear ratios; NaN for a line outside (0, last bin).
    """
    amp = np.asarray(amp, dtype=float)
    out = np.full(amp.shape[:-1] + (len(lines),), math.nan)
    for j, line in enumerate(lines):
        if not (0.0 < line.frequency_hz < freq[-1]):
            continue
        a = line_amplitude(freq, amp, line.frequency_hz, tolerance)
        med = local_level(freq, amp, line)
        out[..., j] = np.where(med > 0, a / np.where(med > 0, med, 1.0), math.nan)
    return out


def family_scores(ratios, lines):
    """Score of each defect family: the geometric mean of its lines' ratios.

    Parameters
    ----------
    ratios : numpy.ndarray, shape (..., n_lines)
        From :func:`line_ratios` (NaN lines are left out).
    lines : sequence of EnvelopeLine

    Returns
    -------
    dict of str to float or numpy.ndarray
        :data:`FAULT_FAMILIES` → score (NaN when none of its lines was read).
    """
    logr = np.log(np.maximum(np.asarray(ratios, dtype=float), 1e-300))
    out = {}
    for fam in FAULT_FAMILIES:
        cols = [j for j, ln in enumerate(lines) if ln.family == fam]
        v = logr[..., cols]
        ok = np.isfinite(v)
        n = ok.sum(axis=-1)
        s = np.where(ok, v, 0.0).sum(axis=-1)
        score = np.where(n > 0, np.exp(s / np.maximum(n, 1)), math.nan)
        out[fam] = float(score) if np.ndim(score) == 0 else score
    return out


def demodulated_spectrum(x, fs_hz, bearings, band_hz=None):
    """Envelope spectrum (Hann) of the band of the band rule, for some bearings' families.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, any unit.
    fs_hz : float
        Sample rate, Hz.
    bearings : iterable of cmsim.frequencies.BearingFrequencies
        Bearings whose families are read (the band rule reads their highest fundamental).
    band_hz : tuple of float, optional
        A given band (lo, hi), Hz, instead of the band rule's.

    Returns
    -------
    spectrum : cmsim.spectra.Spectrum
        ``kind="envelope"``.
    band_hz : tuple of float
        The band, Hz (the fallback band when the band-pass filter could not be designed).
    """
    fs = float(fs_hz)
    band = band_hz if band_hz is not None else demodulation_band(
        x, fs, highest_fault_hz(list(bearings)))
    try:
        return envelope_spectrum(x, fs, band, window="hann"), tuple(float(b) for b in band)
    except (ParameterError, np.linalg.LinAlgError, ValueError):
        if band_hz is not None:
            raise
        band = (FALLBACK_BAND[0] * fs, FALLBACK_BAND[1] * fs)
        return envelope_spectrum(x, fs, band, window="hann"), band


def band_excess(freq, amp, f_hz, floor, tolerance=SLIP_TOLERANCE):
    """Power in the bins of a line over what a floor puts there (a line smeared by slip or a
    speed wobble keeps its energy; a line that is gone does not).

    Parameters
    ----------
    freq : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz.
    amp : numpy.ndarray, shape (n_bins,)
        Amplitude spectrum.
    f_hz : float
        Nominal frequency of the line, Hz.
    floor : float
        Level of the floor (same unit as ``amp``).
    tolerance : float
        Relative tolerance of the line rule.

    Returns
    -------
    float
        Σ amp² over the line's bins / (bins × floor²); NaN outside the spectrum.
    """
    sel = line_bins(freq, f_hz, tolerance)
    if sel is None or not floor > 0:
        return math.nan
    return float(np.sum(amp[sel] ** 2) / ((sel.stop - sel.start) * floor ** 2))


# ---------------------------------------------------------------------- band bank
def band_bank(fs_hz):
    """The fixed bank of demodulation bands of :func:`band_bank_features`.

    Bands fs/8 wide spaced fs/16 from fs/24 up to 0.48·fs (12 kHz: 500-2000, 1250-2750, ...,
    4250-5750 Hz).

    Parameters
    ----------
    fs_hz : float
        Sample rate, Hz.

    Returns
    -------
    list of (float, float)
    """
    width = fs_hz / 8.0
    lo = fs_hz / 24.0
    out = []
    while lo + width <= 0.48 * fs_hz + 1e-9:
        out.append((lo, lo + width))
        lo += width / 2.0
    return out


#: Share of a window at each end left out of its band envelopes' kurtosis
#: (:func:`band_bank_features`): 128 of 4096 samples; 64-256 read the same medians on
#: CWRU's real and synthetic windows (healthy 2.4-2.5, against 4.4-4.9 with the ends).
ENVELOPE_EDGE_SHARE = 1.0 / 32.0


def _kurtosis(x):
    x = x - x.mean(axis=-1, keepdims=True)
    x2 = x * x                            # (x²)², not x ** 4: numpy's pow is 40 times slower
    m2 = x2.mean(axis=-1)
    return (x2 * x2).mean(axis=-1) / np.maximum(m2 ** 2, 1e-300)


def band_bank_features(windows, fs_hz, bearings, tolerance=SLIP_TOLERANCE):
    """Envelope-family features of windows in every band of :func:`band_bank`.

    Each window is band-passed in each band by zeroing FFT bins; the modulus of the analytic
    signal is the envelope, its Hann amplitude spectrum is read at the lines of
    :func:`envelope_lines` (:func:`line_ratios`). Features: the log ratio of each line, its
    largest and its median over the bands; each fault family's mean log ratio in its best
    band (:func:`family_scores`); the log kurtosis of the window and the largest log kurtosis
    of a band's squared envelope, read inside the window's ends
    (:data:`ENVELOPE_EDGE_SHARE`). Lines outside the spectrum read a log ratio of 0.

    Parameters
    ----------
    windows : numpy.ndarray, shape (n, window)
        Signal windows, any unit.
    fs_hz : float
        Sample rate, Hz.
    bearings : sequence of cmsim.frequencies.BearingFrequencies, length n
        The bearing of each window at its record's speed.
    tolerance : float
        Relative tolerance of the line rule.

    Returns
    -------
    features : numpy.ndarray, shape (n, n_features)
    names : list of str
        ``max_<line>``, ``med_<line>``, ``family_<family>``, ``log_kurtosis``,
        ``log_env_kurtosis``.
    family_ratio : numpy.ndarray, shape (n, 3)
        Score of each of :data:`FAULT_FAMILIES` in the band where it is largest.
    """
    x = np.asarray(windows, dtype=float)
    n, win = x.shape
    fs = float(fs_hz)
    spec = np.fft.rfft(x, axis=1)
    f = np.fft.rfftfreq(win, 1.0 / fs)
    hann = np.hanning(win)
    edge = int(win * ENVELOPE_EDGE_SHARE)
    env_amp, env_kurt = [], []
    for lo, hi in band_bank(fs):
        sel = (f >= lo) & (f <= hi)
        full = np.zeros((n, win), complex)
        full[:, :f.size][:, sel] = 2.0 * spec[:, sel]
        env = np.abs(np.fft.ifft(full, axis=1))
        # the band-pass is circular: the jump between a window's last and first samples
        # rings every band at its two ends (a healthy window's quietest band read a
        # squared-envelope kurtosis in the hundreds there); the kurtosis is read inside
        env_kurt.append(_kurtosis(env[:, edge:win - edge] ** 2))
        e = env - env.mean(axis=1, keepdims=True)
        env_amp.append(np.abs(np.fft.rfft(e * hann, axis=1)))
    env_amp = np.stack(env_amp, axis=1)                    # (n, n_bands, n_freq)
    n_lines = len(ENVELOPE_LINE_NAMES)
    logr = np.zeros((n, env_amp.shape[1], n_lines))
    fam = np.zeros((n, env_amp.shape[1], len(FAULT_FAMILIES)))
    for i in range(n):
        lines = envelope_lines(bearings[i])
        r = line_ratios(f, env_amp[i], lines, tolerance)
        logr[i] = np.nan_to_num(np.log(np.maximum(r, 1e-300)), nan=0.0)
        scores = family_scores(np.exp(logr[i]), lines)
        fam[i] = np.stack([np.log(scores[c]) for c in FAULT_FAMILIES], axis=-1)
    family_ratio = np.exp(fam.max(axis=1))
    kurt_x = np.log(_kurtosis(x))
    kurt_env = np.log(np.stack(env_kurt, axis=1)).max(axis=1)
    feats = np.concatenate([logr.max(axis=1), np.median(logr, axis=1), fam.max(axis=1),
                            kurt_x[:, None], kurt_env[:, None]], axis=1)
    names = ([f"max_{k}" for k in ENVELOPE_LINE_NAMES]
             + [f"med_{k}" for k in ENVELOPE_LINE_NAMES]
             + [f"family_{c}" for c in FAULT_FAMILIES] + ["log_kurtosis", "log_env_kurtosis"])
    return feats, names, family_ratio
