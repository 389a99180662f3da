"""Features that compare a model with a measurement whose absolute scale is unknown.

Every column is a ratio (dB) or a shape statistic, never an absolute level, so an unknown
sensor gain, unit or transfer-path gain drops out:

* ``kurtosis_log``, ``crest_log``: natural log of the kurtosis and crest factor;
* ``shape_b{i}_db``: share of the spectrum's energy in each of :data:`N_SHAPE_BANDS`
  log-spaced bands (the spectral shape after the transfer path), dB;
* ``raw_{line}_db``: prominence of a line of the amplitude spectrum over the median level
  (shaft harmonics ``fr_h1``, ``fr_h2``; the ball-pass rate ``bpfo``), dB;
* ``env_{family}_h{h}_db``: prominence of the envelope-spectrum lines of the bearing defect
  families (``bpfo``, ``bpfi``, ``bsf2`` = 2·BSF, ``ftf``, the shaft ``fr``) and the BPFI ±
  shaft sidebands over the envelope spectrum's median level, dB; the demodulation band is the
  kurtogram's best band (:func:`cmsim.spectra.kurtogram.kurtogram`);
* gear rigs: ``gmf{k}_rel_db`` (each GMF harmonic relative to the largest), ``sb_fr1_db`` and
  ``sb_fr2_db`` (mean level of the ±1 shaft-rate sidebands of GMF harmonics 1-3 relative to
  their carriers) and ``tsa_residual_kurtosis_log``, read by the one feature extractor
  :func:`cmsim.features.extract_features`.

Lines are read as the largest bin within ±(:data:`LINE_TOLERANCE` relative + 1.5 bins) of the
nominal frequency, so a bearing's 1-2 % slip and a slightly wrong speed do not lose them.
Records are cut into segments of equal length; the spread over segments is the feature noise.
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.errors import ParameterError
from cmsim.features import extract_features, statistics
from cmsim.spectra.envelope import envelope_spectrum
from cmsim.spectra.kurtogram import kurtogram

__all__ = ["segment_features", "record_features", "feature_floor", "N_SHAPE_BANDS",
           "LINE_TOLERANCE", "segments"]

#: Relative tolerance on a line's frequency (bearing slip, speed error).
LINE_TOLERANCE = 0.02

#: Bands of the spectral-shape columns (3 log-spaced up to 0.05·fs, then linear to fs/2).
N_SHAPE_BANDS = 12

#: Least model-uncertainty of a column in its own unit (dB columns 1.5 dB, logs 0.1).
DB_FLOOR = 1.5
LOG_FLOOR = 0.1


def feature_floor(name):
    """Model-uncertainty floor of a feature column (its unit)."""
    return LOG_FLOOR if name.endswith("_log") else DB_FLOOR


def _spectrum(x, fs):
    win = np.hanning(x.size)
    amp = np.abs(np.fft.rfft((x - x.mean()) * win)) * 2.0 / win.sum()
    return np.fft.rfftfreq(x.size, 1.0 / fs), amp


def _peak(freq, amp, f, df):
    half = LINE_TOLERANCE * f + 1.5 * df
    sel = (freq >= f - half) & (freq <= f + half)
    if f <= 0 or not np.any(sel):
        return math.nan
    return float(np.max(amp[sel]))


def _db(a, ref):
    if not (math.isfinite(a) and ref > 0):
        return math.nan
    return 20.0 * math.log10(max(a, 1e-30 * ref) / ref)


def segment_features(x, fs_hz, freqs, bearing):
    """Scale-free features of one segment (see the module docstring).

    Parameters
    ----------
    x : ndarray, shape (n,)
        Segment, any unit.
    fs_hz : float
        Sample rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies
        Frequencies of the rig at the record's speed.
    bearing : str
        Bearing whose defect families are read.

    Returns
    -------
    dict of str to float
    """
    x = np.asarray(x, dtype=float)
    x = x - x.mean()
    out = {}
    _, kurt, crest = statistics(x)
    out["kurtosis_log"] = math.log(max(kurt, 1e-3))
    out["crest_log"] = math.log(max(crest, 1e-3))
    freq, amp = _spectrum(x, fs_hz)
    df = freq[1]
    power = amp ** 2
    # log-spaced up to 5 % of fs, then linear (the housing modes and noise live up there)
    edges = np.concatenate([np.geomspace(max(20.0, 2 * df), 0.05 * fs_hz, 4)[:-1],
                            np.linspace(0.05 * fs_hz, 0.5 * fs_hz, N_SHAPE_BANDS - 2)])
    total = power[(freq >= edges[0])].sum()
    for i in range(len(edges) - 1):
        e = power[(freq >= edges[i]) & (freq < edges[i + 1])].sum()
        out[f"shape_b{i}_db"] = 10.0 * math.log10(max(e / total, 1e-12))
    fr = freqs.fr1_hz
    bf = freqs.bearing(bearing)
    lo = freq >= 0.5 * fr
    floor = float(np.median(amp[lo & (freq <= min(fs_hz / 2, 20 * bf.bpfi_hz))]))
    out["raw_fr_h1_db"] = _db(_peak(freq, amp, fr, df), floor)
    out["raw_fr_h2_db"] = _db(_peak(freq, amp, 2 * fr, df), floor)
    out["raw_bpfo_db"] = _db(_peak(freq, amp, bf.bpfo_hz, df), floor)
    # envelope
    f_max = max(bf.bpfo_hz, bf.bpfi_hz, 2 * bf.bsf_hz)
    try:
        band = kurtogram(x, fs_hz, max_fault_hz=f_max).band_hz
    except ParameterError:
        band = (0.05 * fs_hz, 0.45 * fs_hz)
    lo_b, hi_b = band
    if hi_b - lo_b < 0.02 * fs_hz:                # a very narrow band: filter ill-conditioned
        mid = 0.5 * (lo_b + hi_b)
        lo_b, hi_b = max(mid - 0.01 * fs_hz, 1.0), min(mid + 0.01 * fs_hz, 0.49 * fs_hz)
    try:
        ef, ea = envelope_spectrum(x, fs_hz, (lo_b, hi_b), window="hann")
    except (ParameterError, np.linalg.LinAlgError, ValueError):
        ef, ea = envelope_spectrum(x, fs_hz, (0.05 * fs_hz, 0.45 * fs_hz), window="hann")
    edf = ef[1]
    esel = (ef >= 0.5 * fr) & (ef <= 4.0 * bf.bpfi_hz)
    efloor = float(np.median(ea[esel])) if np.any(esel) else 1.0
    fams = {"bpfo": bf.bpfo_hz, "bpfi": bf.bpfi_hz, "bsf2": 2 * bf.bsf_hz}
    for fam, f in fams.items():
        for h in (1, 2, 3):
            out[f"env_{fam}_h{h}_db"] = _db(_peak(ef, ea, h * f, edf), efloor)
    out["env_ftf_h1_db"] = _db(_peak(ef, ea, bf.ftf_hz, edf), efloor)
    out["env_fr_h1_db"] = _db(_peak(ef, ea, fr, edf), efloor)
    sb = [_peak(ef, ea, bf.bpfi_hz + s * fr, edf) for s in (-1, 1)]
    out["env_bpfi_sb_db"] = _db(float(np.nanmean(sb)), efloor)
    if freqs.gmf_hz is not None:
        row = extract_features(x, fs_hz, freqs, bearing=bearing, envelope=False,
                               n_gmf_harmonics=4)
        d = row.to_dict()
        g = np.array([d[f"gmf{k}_amp"] for k in range(1, 5)], dtype=float)
        gmax = np.nanmax(g) if np.any(np.isfinite(g)) else math.nan
        for k in range(1, 5):
            out[f"gmf{k}_rel_db"] = _db(g[k - 1], gmax)
        for rate in ("fr1", "fr2"):
            vals = []
            for k in range(1, 4):
                c = d[f"gmf{k}_amp"]
                for s in ("m1", "p1"):
                    v = d.get(f"gmf{k}_sb_{rate}_{s}", math.nan)
                    if math.isfinite(v) and math.isfinite(c) and c > 0:
                        vals.append(20 * math.log10(max(v, 1e-30) / c))
            out[f"sb_{rate}_db"] = float(np.mean(vals)) if vals else math.nan
        tk = row.tsa_residual_kurtosis
        out["tsa_residual_kurtosis_log"] = math.log(tk) if math.isfinite(tk) and tk > 0 \
            else math.nan
    return out


def segments(n_samples, fs_hz, seg_s, max_segments=None):
    """(start, stop) sample indices of consecutive segments of ``seg_s`` seconds."""
    n = int(round(seg_s * fs_hz))
    k = n_samples // n
    if max_segments is not None and k > max_segments:
        starts = np.linspace(0, n_samples - n, max_segments).astype(int)
    else:
        starts = np.arange(k) * n
    return [(int(s), int(s) + n) for s in starts]


def record_features(x, fs_hz, freqs, bearing, seg_s, max_segments=None):
    """Features of every segment of a record.

    Parameters
    ----------
    x : ndarray
        Record.
    fs_hz : float
        Sample rate, Hz.
    freqs : RigFrequencies
        Frequencies at the record's speed.
    bearing : str
        Bearing whose families are read.
    seg_s : float
        Segment length, s.
    max_segments : int, optional
        At most this many segments, spread over the record.

    Returns
    -------
    (list of str, ndarray of shape (n_segments, n_features))
    """
    rows = [segment_features(x[a:b], fs_hz, freqs, bearing)
            for a, b in segments(x.size, fs_hz, seg_s, max_segments)]
    if not rows:
        raise ParameterError(f"record shorter than one {seg_s:g}-s segment", param="RECORD")
    names = list(rows[0])
    return names, np.array([[r[k] for k in names] for r in rows], dtype=float)
