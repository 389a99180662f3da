"""Scale-free features: compare a model with a measurement whose absolute scale is unknown.

Every column of :func:`relative_features` is a ratio (dB) or a shape statistic, never an
absolute level, so an unknown sensor gain, unit or transfer-path gain drops out; the
measured-data loop of :mod:`cmsim.discrepancy` compares them segment by segment
(:func:`segment_features`). Lines are read with the one line rule
(:func:`~cmsim.features.lines.line_amplitude`) at
:data:`~cmsim.features.lines.SLIP_TOLERANCE` on both sides of a comparison; the envelope
families are those of :mod:`cmsim.features.envelope`.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache

import numpy as np

from cmsim.errors import ParameterError
from cmsim.features.absolute import gmf_levels, statistics, tsa_residual_kurtosis
from cmsim.features.envelope import (band_bank, band_excess, demodulated_spectrum,
                                     envelope_lines, line_amplitudes)
from cmsim.features.lines import EXACT_TOLERANCE, SLIP_TOLERANCE, line_amplitude
from cmsim.features.sidebands import sideband_energies
from cmsim.spectra._checks import sampling_rate, signal_1d
from cmsim.spectra.amplitude import amplitude_spectrum

__all__ = ["relative_features", "raw_floor", "envelope_columns", "band_family_columns", "band_column",
           "envelope_over_floor",
           "segment_features", "segments", "N_SHAPE_BANDS", "N_ENVELOPE_BANDS",
           "shape_band_edges", "N_RELATIVE_GMF_HARMONICS"]

#: Bands of the spectral-shape columns (3 log-spaced up to 0.05·fs, then linear to fs/2).
N_SHAPE_BANDS = 12

#: GMF harmonics whose levels relative to the largest are read.
N_RELATIVE_GMF_HARMONICS = 4

#: Bands of :func:`band_family_columns` (those of
#: :func:`~cmsim.features.envelope.band_bank`, as many at any sample rate).
N_ENVELOPE_BANDS = len(band_bank(1.0))

#: The lines of :func:`~cmsim.features.envelope.envelope_lines` read band by band: each
#: family's fundamental.
_BAND_LINES = ("bpfo_1", "bpfi_1", "bsf2_1")
_BAND_COLUMN = re.compile(r"_bb\d+_db$")


def _db(a, ref=1.0):
    if not (math.isfinite(a) and ref > 0):
        return math.nan
    return 20.0 * math.log10(max(a, 1e-30 * ref) / ref)


def _mean(*values):
    v = [a for a in values if a == a]
    return float(np.mean(v)) if v else math.nan


def _db_power(p):
    return 10.0 * math.log10(max(p, 1e-6)) if p == p else p


def shape_band_edges(fs, df):
    """Edges of the :data:`N_SHAPE_BANDS` spectral-shape bands, Hz: three log-spaced from
    20 Hz (or two bins) to 0.05·fs, then nine of equal width to fs/2.

    Parameters
    ----------
    fs : float
        Sample rate, Hz.
    df : float
        Frequency resolution of the spectrum, Hz.
    """
    return np.concatenate([np.geomspace(max(20.0, 2 * df), 0.05 * fs, 4)[:-1],
                           np.linspace(0.05 * fs, 0.5 * fs, N_SHAPE_BANDS - 2)])


def _shape_bands(freq, power, fs, df):
    edges = shape_band_edges(fs, df)
    total = power[freq >= edges[0]].sum()
    return {f"shape_b{i}_db": 10.0 * math.log10(max(
        power[(freq >= edges[i]) & (freq < edges[i + 1])].sum() / total, 1e-12))
        for i in range(len(edges) - 1)}


def relative_features(signal, fs_hz, freqs, bearings=None):
    """Scale-free features of a segment (see the module docstring).

    * ``kurtosis_log``, ``crest_log``: natural log of the kurtosis and crest factor;
    * ``shape_b{i}_db``: share of the spectrum's energy in each of :data:`N_SHAPE_BANDS`
      bands (the spectral shape after the transfer path), dB;
    * ``raw_fr_h1_db``, ``raw_fr_h2_db``: shaft lines of the (Hann) amplitude spectrum over
      its median level between half the shaft rate and 20 × the highest BPFI, dB; per
      bearing b, ``raw_bpfo_{b}_db`` (the ball-pass line of a fixed outer ring: varying
      compliance, an outer-race defect) and ``raw_bpfo_{b}_band_db``, the power in its bins
      over the floor's (a line smeared by slip keeps it);
    * envelope spectrum (:func:`~cmsim.features.envelope.demodulated_spectrum`: one band
      for all bearings, the band rule) over its median level between half the shaft rate and
      4 × the highest BPFI, dB: ``env_fr_h1_db``; per bearing b, lines of
      :func:`~cmsim.features.envelope.envelope_lines`: ``env_{bpfo|bpfi|bsf2}_{b}_h{1|2}_db``
      (bsf2 = 2·BSF, a ball defect hitting both races), ``env_ftf_{b}_db``,
      ``env_bpfi_{b}_sb_db`` (BPFI ± the shaft rate), ``env_bpfo_{b}_sb_db`` (BPFO and
      2·BPFO ± the shaft rate: a once-per-rev speed or load modulation) and
      ``env_bpfo_{b}_band_db`` (the power in the BPFO line's bins over the median's);
    * gear rigs: ``gmf{k}_rel_db`` (k = 1..4, relative to the largest) and
      ``tsa_residual_kurtosis_log`` (:func:`~cmsim.features.absolute.gmf_levels`,
      :func:`~cmsim.features.absolute.tsa_residual_kurtosis`),
      and the sideband energies of :func:`~cmsim.features.sidebands.sideband_energies`.

    Parameters
    ----------
    signal : array_like, shape (n,)
        Segment, any unit.
    fs_hz : float
        Sample rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies
        Frequencies of the rig at the record's speed.
    bearings : sequence of str, optional
        Bearings whose families are read (default all of ``freqs``).

    Returns
    -------
    dict of str to float
        NaN where a line lies outside the spectrum.
    """
    x = signal_1d(signal, "signal")
    fs = sampling_rate(fs_hz, "fs_hz")
    x = x - x.mean()
    names = list(freqs.bearing_names) if bearings is None else list(bearings)
    bfs = {b: freqs.bearing(b) for b in names}
    out = {}
    _, kurt, crest = statistics(x)
    out["kurtosis_log"] = math.log(max(kurt, 1e-3))
    out["crest_log"] = math.log(max(crest, 1e-3))
    freq, amp = amplitude_spectrum(x, fs, window="hann")
    df = freq[1]
    out.update(_shape_bands(freq, amp ** 2, fs, df))
    fr = freqs.fr1_hz
    floor = raw_floor(freq, amp, fr, bfs.values())
    tol = SLIP_TOLERANCE
    out["raw_fr_h1_db"] = _db(line_amplitude(freq, amp, fr, tol), floor)
    out["raw_fr_h2_db"] = _db(line_amplitude(freq, amp, 2 * fr, tol), floor)
    for b, bf in bfs.items():
        out[f"raw_bpfo_{b}_db"] = _db(line_amplitude(freq, amp, bf.bpfo_hz, tol), floor)
        out[f"raw_bpfo_{b}_band_db"] = _db_power(band_excess(freq, amp, bf.bpfo_hz, floor,
                                                             tol))
    if bfs:
        out.update(envelope_columns(x, fs, fr, bfs))
    if freqs.gmf_hz is not None:
        n_gmf = N_RELATIVE_GMF_HARMONICS
        g = gmf_levels(amplitude_spectrum(x, fs), freqs.gmf_hz, n_gmf, EXACT_TOLERANCE)
        gmax = np.nanmax(g) if np.any(np.isfinite(g)) else math.nan
        for k in range(1, n_gmf + 1):
            out[f"gmf{k}_rel_db"] = _db(g[k - 1], gmax)
        out.update(sideband_energies(x, fs, freqs))
        tk = tsa_residual_kurtosis(x, fs, freqs.fr1_hz)
        out["tsa_residual_kurtosis_log"] = math.log(tk) if math.isfinite(tk) and tk > 0 \
            else math.nan
    return out


def raw_floor(freq, amp, shaft_hz, bearings):
    """The floor the raw lines of :func:`relative_features` are read over: the amplitude
    spectrum's median between half the shaft rate and 20 × the highest BPFI (at least 4 ×
    the shaft rate), or the Nyquist frequency.

    Parameters
    ----------
    freq, amp : numpy.ndarray
        An amplitude spectrum (0 to the Nyquist frequency) and its frequencies, Hz.
    shaft_hz : float
        The input shaft's rate, Hz.
    bearings : iterable of cmsim.frequencies.BearingFrequencies
        The bearings whose ball-pass lines are read.

    Returns
    -------
    float
        The floor, the spectrum's unit.
    """
    top = max([bf.bpfi_hz for bf in bearings] + [4.0 * shaft_hz])
    sel = (freq >= 0.5 * shaft_hz) & (freq <= min(freq[-1], 20 * top))
    return float(np.median(amp[sel]))


def envelope_columns(x, fs_hz, shaft_hz, bearings):
    """The envelope columns of :func:`relative_features` (``env_*``): the lines of each
    bearing's families over the envelope spectrum's median between half the shaft rate and
    4 × the highest BPFI, dB.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Segment, mean removed.
    fs_hz : float
        Sample rate, Hz.
    shaft_hz : float
        Input shaft rate, Hz.
    bearings : dict of str to cmsim.frequencies.BearingFrequencies
        The bearings read, by name (at least one).

    Returns
    -------
    dict of str to float
    """
    fr, tol, out = shaft_hz, SLIP_TOLERANCE, {}
    (ef, ea), _ = demodulated_spectrum(x, fs_hz, bearings.values())
    efloor = _envelope_floor(ef, ea, fr, bearings)
    out["env_fr_h1_db"] = _db(line_amplitude(ef, ea, fr, tol), efloor)
    for b, bf in bearings.items():
        a = line_amplitudes(ef, ea, envelope_lines(bf), tol)
        for fam in ("bpfo", "bpfi", "bsf2"):
            for h in (1, 2):
                out[f"env_{fam}_{b}_h{h}_db"] = _db(a[f"{fam}_{h}"], efloor)
        out[f"env_ftf_{b}_db"] = _db(a["ftf"], efloor)
        out[f"env_bpfi_{b}_sb_db"] = _db(_mean(a["bpfi_m1"], a["bpfi_p1"]), efloor)
        sb = [line_amplitude(ef, ea, h * bf.bpfo_hz + s * bf.shaft_hz, tol)
              for h in (1, 2) for s in (-1, 1)]
        out[f"env_bpfo_{b}_sb_db"] = _db(_mean(*sb), efloor)
        out[f"env_bpfo_{b}_band_db"] = _db_power(band_excess(ef, ea, bf.bpfo_hz, efloor, tol))
    return out


def envelope_over_floor(x, fs_hz, shaft_hz, bearings, band_hz=None):
    """The envelope spectrum :func:`envelope_columns` reads (its band rule, or a given band)
    over its floor, for lines read at any frequency (a shaft's harmonics).

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, mean removed.
    fs_hz : float
        Sample rate, Hz.
    shaft_hz : float
        Input shaft rate, Hz (the floor's span starts at half of it).
    bearings : dict of str to cmsim.frequencies.BearingFrequencies
        The bearings whose families set the band rule's band and the floor's span.
    band_hz : tuple of float, optional
        The band demodulated (default the band rule's on ``x``).

    Returns
    -------
    freq : numpy.ndarray
        Bin frequencies, Hz.
    ratio : numpy.ndarray
        Amplitude over the floor.
    band_hz : tuple of float
        The band demodulated, Hz.
    """
    (ef, ea), band = demodulated_spectrum(x, fs_hz, bearings.values(), band_hz)
    return ef, ea / _envelope_floor(ef, ea, shaft_hz, bearings), band


def _envelope_floor(ef, ea, shaft_hz, bearings):
    """The envelope spectrum's median between half the shaft rate and 4 × the highest BPFI."""
    top = max(bf.bpfi_hz for bf in bearings.values())
    sel = (ef >= 0.5 * shaft_hz) & (ef <= 4.0 * top)
    return float(np.median(ea[sel])) if np.any(sel) else 1.0


def band_family_columns(x, fs_hz, shaft_hz, bearings):
    """Each bearing's defect families in every band of the fixed bank
    (:func:`~cmsim.features.envelope.band_bank`): ``env_{bpfo|bpfi|bsf2}_{b}_h1_bb{j}_db``,
    the family's fundamental over the envelope spectrum's median in band j, as
    :func:`envelope_columns` reads it in the band rule's one band.

    A spall rings the structure where the structure resonates, which the band rule (chosen on
    the record's own spectral kurtosis) need not pick: on the angle-domain generator's gear
    machines an outer race lifted its BPFO line 5.2 dB in the rule's band and 8.1 dB in the
    fixed band where its impacts ring (``benchmarks/bench_band_families.py``). Read against a
    baseline in the same band, the family stands out where it rings. Only the fundamental is
    read: a harmonic's window is twice as wide, and on a gearbox it holds a shaft order more
    often than not (cmsim's own gear machine: BPFO's second harmonic 4.5 Hz from the 7th
    order, which a tooth fault lifts in every band).

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Segment, mean removed.
    fs_hz : float
        Sample rate, Hz.
    shaft_hz : float
        Input shaft rate, Hz.
    bearings : dict of str to cmsim.frequencies.BearingFrequencies
        The bearings read, by name (at least one).

    Returns
    -------
    dict of str to float
    """
    lines = {b: [ln for ln in envelope_lines(bf) if ln.name in _BAND_LINES]
             for b, bf in bearings.items()}
    out = {}
    for j, band in enumerate(band_bank(fs_hz)):
        (ef, ea), _ = demodulated_spectrum(x, fs_hz, bearings.values(), band)
        floor = _envelope_floor(ef, ea, shaft_hz, bearings)
        for b, bl in lines.items():
            for name, a in line_amplitudes(ef, ea, bl, SLIP_TOLERANCE).items():
                out[f"env_{name[:-2]}_{b}_h1_bb{j}_db"] = _db(a, floor)
    return out


def band_column(name):
    """Whether feature ``name`` is one band's of :func:`band_family_columns`."""
    return bool(_BAND_COLUMN.search(name))


def segment_samples(fs_hz, seg_s):
    """Samples of a segment of about ``seg_s`` seconds: the number nearest ``round(seg_s ·
    fs_hz)`` with no prime factor over 5 (the smaller on a tie; within 3.3 % of it for a
    segment of 500 samples or more). A segment's spectra, envelopes and kurtogram are FFTs
    of its length: SpectraQuest's 0.5 s are 6452 = 4 · 1613 samples, whose transforms ran
    3-5 times slower than those of 6480 (Bluestein's algorithm for the large prime), most of
    a comparison's time. The common rates (10, 12, 20, 25.6, 48, 51.2 kHz) give 0.5 s
    exactly. The rule is fixed here, not asked of the FFT library, so a machine file's
    segments are the same whatever library version reads it.

    Parameters
    ----------
    fs_hz : float
        Sample rate, Hz.
    seg_s : float
        Segment length asked, s.

    Returns
    -------
    int

    Examples
    --------
    >>> segment_samples(12_000.0, 0.5), segment_samples(12_904.56, 0.5)
    (6000, 6480)
    """
    return _regular_near(int(round(seg_s * fs_hz)))


@lru_cache(maxsize=64)
def _regular_near(n):
    """The number nearest ``n`` (the smaller on a tie) whose prime factors are 2, 3 and 5."""
    if n <= 1:
        return n
    best = 1
    p2 = 1
    while p2 <= 2 * n:
        p3 = p2
        while p3 <= 2 * n:
            p5 = p3
            while p5 <= 2 * n:
                if (abs(p5 - n), p5) < (abs(best - n), best):
                    best = p5
                p5 *= 5
            p3 *= 3
        p2 *= 2
    return best


def segments(n_samples, fs_hz, seg_s, max_segments=None):
    """(start, stop) sample indices of consecutive segments of ``seg_s`` seconds
    (:func:`segment_samples` each).

    Parameters
    ----------
    n_samples : int
        Samples in the record.
    fs_hz : float
        Sample rate, Hz.
    seg_s : float
        Segment length, s.
    max_segments : int, optional
        At most this many segments, spread evenly over the record.

    Returns
    -------
    list of (int, int)
    """
    n = segment_samples(fs_hz, seg_s)
    k = n_samples // n
    if max_segments is not None and k > max_segments:
        starts = np.linspace(0, n_samples - n, max_segments).astype(int)
    else:
        starts = np.arange(k) * n
    return [(int(s), int(s) + n) for s in starts]


def segment_features(x, fs_hz, freqs, bearings, seg_s, max_segments=None):
    """:func:`relative_features` of every segment of a record (:func:`segments`).

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Record.
    fs_hz : float
        Sample rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies
        Frequencies at the record's speed.
    bearings : sequence of str
        Bearings whose defect families are read.
    seg_s : float
        Segment length, s.
    max_segments : int, optional
        At most this many segments, spread over the record.

    Returns
    -------
    names : list of str
    values : numpy.ndarray, shape (n_segments, n_features)
    """
    rows = [relative_features(x[a:b], fs_hz, freqs, bearings)
            for a, b in segments(x.size, fs_hz, seg_s, max_segments)]
    if not rows:
        raise ParameterError(f"record shorter than one {seg_s:g}-s segment", param="RECORD")
    names = list(rows[0])
    return names, np.array([[r[k] for k in names] for r in rows], dtype=float)
