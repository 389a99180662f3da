"""Peak finding above a robust noise floor, and naming peaks as k·GMF ± m·BPF ± n·fr.

Noise floor
    running median (:func:`scipy.ndimage.median_filter`) of the amplitude in dB over
    ``floor_bins`` bins, raised to at least (largest peak − ``dynamic_range_db``) so that
    window side lobes of clean synthetic signals (flat-top: −93 dB) are not taken as peaks.
    A peak is significant if it stands ``threshold_db`` (default 15 dB) above that floor
    (:func:`scipy.signal.find_peaks` on the dB excess); a bin of Gaussian noise exceeds its
    median by 15 dB with probability ≈ 3e-10 (by 10 dB: ≈ 1e-3, i.e. about ten false peaks
    in a 10 000-bin spectrum). Its frequency is refined by the
    power-weighted centroid of ±2 bins (error < 0.11 bin for flat-top, < 0.01 for Hann);
    its amplitude is the spectrum value at the peak bin.

Families
    ``families`` maps base names (:data:`FAMILY_KEYS`) to base frequencies (Hz, or orders).
    Each template of :data:`TEMPLATES` spans a lattice k·carrier + m·(m-base) + n·(n-base):

    ==========  =========  =========  =========  ===================================
    template    k counts   m counts   n counts   k range (default max_harmonic)
    ==========  =========  =========  =========  ===================================
    gear        GMF        BPF        fr         0..50 (k = 0: "1BPF", "2fr", ...)
    BPFO        BPFO       —          fr         1..10
    BPFI        BPFI       —          fr         1..10
    BSF         BSF        —          FTF        1..10
    FTF         FTF        —          —          1..3
    shaft       fr         —          —          1..10 (beyond the gear template's ±n)
    other gear  GMF        —          fr1, fr2   1..50 (the other gear shaft's sidebands)
    its shaft   fr1, fr2   —          —          1..10
    ==========  =========  =========  =========  ===================================

    ``fr`` is the rate of the shaft carrying the bearing, ``fr1`` or ``fr2`` the other gear
    shaft's (given on a rig whose gears are not 1:1).

    |m|, |n| <= ``max_sideband``; a template is used when its carrier is in ``families``
    (the gear template also without GMF, with k = 0). The *family* of a label is the base of
    its leading term (``"GMF"``, ``"BPF"``, ``"fr"``, ``"BPFO"``, ...).

Speed and slip
    A measured record's speed is known to a relative ``relative_tolerance`` and its balls
    slip by up to ``slip_tolerance``. One speed moves every line by one factor: it is read
    first, from the peaks on the shaft and mesh lines (:func:`_speed_scale`), and each
    slipping family's own factor from its fundamental and harmonics; the lattice is built on
    the bases so read. A base not read keeps its uncertainty as a window proportional to
    the frequency of its terms.

Labelling rule
    A peak takes the candidate within ``tolerance_hz`` (default: one bin) of its frequency
    (or within the window of its bases not read) with the smallest |k| + |m| + |n|, a
    candidate within the bin before one only a window reaches; ties go to fewer terms
    (non-zero indices: "3BPFO" before "2BPFO+1fr" if both fit), then to the smaller
    frequency error, then to the template order above (so a line at BPF = BPFO reads
    "1BPF"). Labels write every term with its integer,
    positive terms first: "1GMF", "2GMF+1BPF", "3GMF-1BPF-2fr", "1BPF", "1BPFO+1fr",
    "4fr-1BPF". Significant peaks without a candidate are kept as label "?" and family
    "unlabelled".

dB references
    ``db_re_max`` is 20·log10(amplitude / largest peak amplitude). ``db_re_carrier`` is
    relative to the spectrum's amplitude at the carrier harmonic k·carrier of the same label
    (largest bin within the tolerance, at least ±1.5 bins): sidebands of an AM carrier with
    modulation index μ read 20·log10(μ/2); carriers read 0 dB. Labels with k = 0 and
    unlabelled peaks use the largest peak (``db_re_carrier = db_re_max``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.ndimage
import scipy.signal

from cmsim.errors import ParameterError, check_choice, check_range
from cmsim.frequencies import (BEARING_FAMILY_KEYS, FAMILY_KEYS, RigFrequencies,
                               peak_families)
from cmsim.spectra._checks import (WINDOWS, band, positive_int, sampling_rate, signal_1d,
                                   spectrum_arrays)
from cmsim.spectra.amplitude import amplitude_spectrum
from cmsim.spectra.envelope import envelope_spectrum
from cmsim.spectra.kurtogram import residual_kurtogram
from cmsim.spectra.order import order_spectrum

__all__ = ["FamilyTemplate", "TEMPLATES", "FAMILY_KEYS", "PEAK_KINDS", "find_peaks",
           "label_peaks", "labelled_peaks"]

#: Spectrum kinds accepted by :func:`labelled_peaks`.
PEAK_KINDS = ("amplitude", "envelope", "order")

_COLUMNS = ["frequency_hz", "amplitude", "db_re_carrier", "db_re_max", "snr_db", "label",
            "family", "k", "m", "n", "expected_hz", "error_hz"]


@dataclass(frozen=True)
class FamilyTemplate:
    """A lattice of labels k·carrier + m·m_base + n·n_base.

    Attributes
    ----------
    carrier : str
        Base counted by k (a key of :data:`FAMILY_KEYS`).
    m_base, n_base : str or None
        Bases counted by m and n; ``None`` keeps that index at 0.
    k_min : int
        Smallest k (0 lets the modulators appear alone, e.g. "1BPF").
    max_harmonic : int
        Default largest k.
    """

    carrier: str
    m_base: str | None = None
    n_base: str | None = None
    k_min: int = 1
    max_harmonic: int = 10


#: Default templates, in tie-break order.
TEMPLATES = (
    FamilyTemplate("GMF", "BPF", "fr", k_min=0, max_harmonic=50),
    FamilyTemplate("BPFO", None, "fr"),
    FamilyTemplate("BPFI", None, "fr"),
    FamilyTemplate("BSF", None, "FTF"),
    FamilyTemplate("FTF", max_harmonic=3),
    FamilyTemplate("fr"),
    FamilyTemplate("GMF", None, "fr1"),
    FamilyTemplate("GMF", None, "fr2"),
    FamilyTemplate("fr1"),
    FamilyTemplate("fr2"),
)


# ---------------------------------------------------------------------- peak finding
def find_peaks(freq, amp, *, threshold_db=15.0, floor_bins=None, dynamic_range_db=80.0,
               min_freq=0.0, max_peaks=None):
    """Significant peaks of an amplitude spectrum above a running-median noise floor.

    Parameters
    ----------
    freq : array_like, shape (n_bins,)
        Bin frequencies (Hz or orders), increasing, uniformly spaced.
    amp : array_like, shape (n_bins,)
        Amplitudes, >= 0.
    threshold_db : float
        Least height above the noise floor, dB (> 0).
    floor_bins : int, optional
        Width of the running median, bins (odd, >= 3); default max(21, n_bins/50).
    dynamic_range_db : float
        Peaks more than this below the largest bin are ignored, dB (> 0).
    min_freq : float
        Peaks below this frequency are ignored (the DC bin always is), same unit as ``freq``.
    max_peaks : int, optional
        Keep only the ``max_peaks`` highest above the floor.

    Returns
    -------
    pandas.DataFrame
        One row per peak, increasing frequency; columns ``frequency_hz`` (refined),
        ``amplitude``, ``floor`` (noise floor amplitude at the peak), ``snr_db`` (height above
        the floor, dB) and ``bin`` (index into ``freq``).
    """
    freq, amp = spectrum_arrays(freq, amp, min_samples=4)
    thr = check_range("threshold_db", threshold_db, 0.0, lo_open=True, unit="dB")
    dr = check_range("dynamic_range_db", dynamic_range_db, 0.0, lo_open=True, unit="dB")
    fmin = check_range("min_freq", min_freq, 0.0)
    nb = freq.size
    if floor_bins is None:
        width = max(21, nb // 50) | 1
    else:
        width = positive_int("floor_bins", floor_bins, lo=3)
    tiny = np.finfo(float).tiny
    db = 20.0 * np.log10(np.maximum(amp, tiny))
    top = float(db[freq > 0].max()) if np.any(freq > 0) else float(db.max())
    floor_db = np.maximum(scipy.ndimage.median_filter(db, size=width, mode="nearest"),
                          top - dr)
    excess = db - floor_db
    idx, _ = scipy.signal.find_peaks(excess, height=thr, prominence=min(thr, 3.0))
    # the floor varies a little across a main lobe: move to the largest bin within ±2 bins
    idx = np.unique(np.array([max(i - 2, 0) + int(np.argmax(amp[max(i - 2, 0): i + 3]))
                              for i in idx], dtype=int))
    idx = idx[(freq[idx] > 0.0) & (freq[idx] >= fmin)]
    if max_peaks is not None:
        keep = positive_int("max_peaks", max_peaks, lo=1)
        idx = np.sort(idx[np.argsort(excess[idx])[::-1][:keep]])
    f_ref = np.empty(idx.size)
    for j, i in enumerate(idx):
        s = slice(max(i - 2, 0), min(i + 3, nb))
        p = amp[s] ** 2
        f_ref[j] = float(np.sum(freq[s] * p) / np.sum(p)) if np.sum(p) > 0 else freq[i]
    # pandas only here: a comparison imports this module but builds no peak table, and
    # importing pandas is 0.4 s of `cmsim compare`'s start
    import pandas as pd

    return pd.DataFrame({"frequency_hz": f_ref, "amplitude": amp[idx],
                         "floor": 10.0 ** (floor_db[idx] / 20.0), "snr_db": excess[idx],
                         "bin": idx.astype(int)})


# ---------------------------------------------------------------------- candidates
def _check_families(families):
    if not isinstance(families, dict) or not families:
        raise ParameterError(f"families must be a non-empty dict of base frequencies keyed by "
                             f"{FAMILY_KEYS}, got {families!r}")
    out = {}
    for key, value in families.items():
        if key not in FAMILY_KEYS:
            raise ParameterError(f"families key {key!r} is not one of {FAMILY_KEYS}")
        out[key] = check_range(f"families[{key!r}]", value, 0.0, lo_open=True)
    return out


def _candidates(families, f_max, max_harmonic, max_sideband, templates):
    """Arrays (freq, k, m, n, template index) of all lattice points in (0, f_max]."""
    rows = []
    for it, tpl in enumerate(templates):
        c = families.get(tpl.carrier)
        b = families.get(tpl.m_base) if tpl.m_base else None
        r = families.get(tpl.n_base) if tpl.n_base else None
        if c is None and not (tpl.k_min == 0 and (b or r)):
            continue
        if tpl.n_base and r is None and not b:     # its modulator is not in the families
            continue
        kmax = tpl.max_harmonic if max_harmonic is None else max_harmonic
        ks = np.arange(tpl.k_min, kmax + 1) if c else np.array([0])
        ms = np.arange(-max_sideband, max_sideband + 1) if b else np.array([0])
        ns = np.arange(-max_sideband, max_sideband + 1) if r else np.array([0])
        k, m, n = (a.ravel() for a in np.meshgrid(ks, ms, ns, indexing="ij"))
        f = k * (c or 0.0) + m * (b or 0.0) + n * (r or 0.0)
        ok = (f > 0.0) & (f <= f_max) & ((k != 0) | (m != 0) | (n != 0))
        rows.append(np.column_stack([f[ok], k[ok], m[ok], n[ok], np.full(ok.sum(), it)]))
    if not rows:
        raise ParameterError(f"no template of {[t.carrier for t in templates]} can be built "
                             f"from families {sorted(families)}")
    return np.vstack(rows)


def _label(k, m, n, tpl):
    terms = [(int(v), name) for v, name in ((k, tpl.carrier), (m, tpl.m_base), (n, tpl.n_base))
             if v != 0]
    terms.sort(key=lambda t: t[0] < 0)          # positive terms first, order kept otherwise
    text = ""
    for i, (v, name) in enumerate(terms):
        sign = "-" if v < 0 else ("+" if i else "")
        text += f"{sign}{abs(v)}{name}"
    return text, terms[0][1]


def label_peaks(freq, amp, families, *, tolerance_hz=None, max_harmonic=None, max_sideband=3,
                threshold_db=15.0, floor_bins=None, dynamic_range_db=80.0, min_freq=0.0,
                max_peaks=None, templates=TEMPLATES, relative_tolerance=0.0,
                slip_tolerance=0.0):
    """Find the significant peaks of a spectrum and name them (see the module docstring).

    Parameters
    ----------
    freq : array_like, shape (n_bins,)
        Bin frequencies, Hz (or orders, with ``families`` in orders), uniformly spaced.
    amp : array_like, shape (n_bins,)
        Amplitude spectrum (window-corrected, e.g. from
        :func:`~cmsim.spectra.amplitude.amplitude_spectrum`).
    families : dict of str to float
        Base frequencies by name, keys from :data:`FAMILY_KEYS`, e.g.
        ``{"GMF": 466.67, "BPF": 60.57, "fr": 16.67}`` or
        :meth:`~cmsim.frequencies.RigFrequencies.families` output.
    tolerance_hz : float, optional
        Largest |peak − candidate| for a match, same unit as ``freq``; default one bin.
    max_harmonic : int, optional
        Largest k for every template; default each template's own (GMF 50, FTF 3, others 10).
    max_sideband : int
        Largest |m| and |n| (0-20).
    threshold_db, floor_bins, dynamic_range_db, min_freq, max_peaks
        Peak detection, see :func:`find_peaks`.
    templates : tuple of FamilyTemplate
        Lattices to try, in tie-break order.
    relative_tolerance : float
        Uncertainty of the speed every family scales with (0-0.5; a nominal speed's 3 %
        moves a line at f by up to 0.03·f). One speed moves every line by the same factor:
        the labeller first finds the factor within it that puts the most peaks on the
        lattice (:func:`_speed_scale`), then names each peak on the lattice scaled by it
        within ``tolerance_hz`` (a window of 0.03·f at every line would let a high mesh
        harmonic's sideband take its neighbour's label).
    slip_tolerance : float
        Relative tolerance of the bearing terms of a label (BPF, BPFO, BPFI, BSF, FTF: their
        balls slip, the shafts' lines do not), >= 0.

    Returns
    -------
    pandas.DataFrame
        One row per significant peak, increasing frequency, columns ``frequency_hz``,
        ``amplitude``, ``db_re_carrier``, ``db_re_max``, ``snr_db``, ``label``, ``family``,
        ``k``, ``m``, ``n`` (ints; 0 when unlabelled), ``expected_hz`` (on the scaled
        lattice) and ``error_hz`` (NaN when unlabelled). ``df.attrs`` holds ``families``,
        ``tolerance_hz``, the tolerances and ``speed_scale`` (the factor found, 1 without a
        relative tolerance).
    """
    freq, amp = spectrum_arrays(freq, amp, min_samples=4)
    fam = _check_families(families)
    df_bin = float(freq[1] - freq[0])
    tol = df_bin if tolerance_hz is None else check_range("tolerance_hz", tolerance_hz, 0.0,
                                                           lo_open=True)
    if max_harmonic is not None:
        max_harmonic = positive_int("max_harmonic", max_harmonic, lo=1, hi=1000)
    msb = positive_int("max_sideband", max_sideband, lo=0, hi=20)
    rel = check_range("relative_tolerance", relative_tolerance, 0.0, 0.5)
    slip = check_range("slip_tolerance", slip_tolerance, 0.0, 0.5)
    peaks = find_peaks(freq, amp, threshold_db=threshold_db, floor_bins=floor_bins,
                       dynamic_range_db=dynamic_range_db, min_freq=min_freq,
                       max_peaks=max_peaks)
    f_pk, a_pk = peaks["frequency_hz"].to_numpy(), peaks["amplitude"].to_numpy()
    f_top = (float(freq[-1]) + tol) * (1.0 + rel + slip)
    scale, spread, pinned = 1.0, 0.0, set()
    if rel > 0.0:
        cand = _candidates(fam, f_top, max_harmonic, msb, templates)
        slips = tol + slip * _part(cand, fam, templates, BEARING_FAMILY_KEYS)
        scale = _speed_scale(f_pk, a_pk, cand[:, 0], slips, rel)
        if scale is None:             # too few shaft or mesh lines to read the speed from:
            scale, spread = 1.0, rel  # each line keeps the whole uncertainty
    fam = {b: scale * v for b, v in fam.items()}
    for b in sorted(BEARING_FAMILY_KEYS & fam.keys()) if slip + spread > 0.0 else ():
        # a slipping family's own factor, read from its fundamental and its harmonics
        ks = np.arange(1.0, FAMILY_HARMONICS + 1.0)
        own = _speed_scale(f_pk, a_pk, fam[b] * ks, np.full(ks.size, tol), slip + spread,
                           proposers=ks == 1.0, min_held=FAMILY_MIN_LINES)
        if own is not None:
            fam[b] *= own
            pinned.add(b)
    cand = _candidates(fam, f_top, max_harmonic, msb, templates)
    cf, ck, cm, cn, ct = cand.T
    complexity = np.abs(ck) + np.abs(cm) + np.abs(cn)
    n_terms = (ck != 0).astype(int) + (cm != 0).astype(int) + (cn != 0).astype(int)
    loose = {b: slip * (b in BEARING_FAMILY_KEYS) + spread for b in fam if b not in pinned}
    window = tol + _part(cand, fam, templates, loose)
    a_max = float(peaks["amplitude"].max()) if len(peaks) else 1.0
    carrier_window = max(tol, 1.5 * df_bin)

    rows = []
    for f_p, a_p in zip(f_pk, a_pk):
        err = np.abs(cf - f_p)
        hit = np.flatnonzero(err <= window)
        db_max = 20.0 * math.log10(a_p / a_max) if a_p > 0 else -math.inf
        if hit.size == 0:
            rows.append(("?", "unlabelled", 0, 0, 0, math.nan, math.nan, db_max))
            continue
        # a line on its point within the bin beats one a slip or speed window reaches
        order = np.lexsort((ct[hit], err[hit], n_terms[hit], complexity[hit],
                            err[hit] > tol))
        j = hit[order[0]]
        tpl = templates[int(ct[j])]
        k, m, n = int(ck[j]), int(cm[j]), int(cn[j])
        text, family = _label(k, m, n, tpl)
        db_car = db_max
        if k != 0:
            fc = k * fam[tpl.carrier]
            near = np.abs(freq - fc) <= carrier_window + loose.get(tpl.carrier, 0.0) * fc
            a_car = float(amp[near].max()) if np.any(near) else 0.0
            db_car = 20.0 * math.log10(a_p / a_car) if a_car > 0 and a_p > 0 else math.nan
        rows.append((text, family, k, m, n, float(cf[j]), float(f_p - cf[j]), db_car))

    out = peaks[["frequency_hz", "amplitude", "snr_db"]].copy()
    out["label"] = [r[0] for r in rows]
    out["family"] = [r[1] for r in rows]
    for i, col in enumerate(("k", "m", "n"), start=2):
        out[col] = np.array([r[i] for r in rows], dtype=int)
    out["expected_hz"] = np.array([r[5] for r in rows], dtype=float)
    out["error_hz"] = np.array([r[6] for r in rows], dtype=float)
    out["db_re_carrier"] = np.array([r[7] for r in rows], dtype=float)
    with np.errstate(divide="ignore"):
        out["db_re_max"] = 20.0 * np.log10(out["amplitude"].to_numpy() / a_max)
    out = out[_COLUMNS].reset_index(drop=True)
    out.attrs = {"families": dict(fam), "tolerance_hz": tol, "relative_tolerance": rel,
                 "slip_tolerance": slip, "speed_scale": scale,
                 "families_read": sorted(pinned)}
    return out


#: Strongest peaks whose candidates propose a speed factor to :func:`_speed_scale`.
SCALE_TRIAL_PEAKS = 8

#: Least number of peaks on shaft and mesh lines a speed factor is read from.
MIN_SCALE_LINES = 2

#: Harmonics of a slipping family its own factor is read on (the fundamental proposes).
FAMILY_HARMONICS = 10

#: Least number of a slipping family's lines its own factor is read from (its fundamental
#: and two harmonics: a dense spectrum puts a second line within a bin of a harmonic of
#: about one proposal in twenty by chance).
FAMILY_MIN_LINES = 3


def _part(cand, families, templates, weights):
    """Σ weight × |frequency| of each candidate's terms whose base has a weight (a dict, or
    a set: weight 1), Hz."""
    weights = dict.fromkeys(weights, 1.0) if not isinstance(weights, dict) else weights
    _, k, m, n, t = cand.T
    out = np.zeros(k.size)
    for it, tpl in enumerate(templates):
        sel = t == it
        for count, base in ((k, tpl.carrier), (m, tpl.m_base), (n, tpl.n_base)):
            if base in weights and base in families:
                out[sel] += weights[base] * np.abs(count[sel]) * families[base]
    return out


def _speed_scale(f_pk, a_pk, cf, window, rel, proposers=None, min_held=MIN_SCALE_LINES):
    """The factor within 1 ± ``rel`` that puts the most peaks on the shaft and mesh lines of
    the lattice ``cf`` (windows ``window``), refined on them; None if fewer than
    ``min_held`` peaks sit on them at any factor. With ``proposers`` (a mask of ``cf``)
    only those candidates propose (a family's fundamental, for its own factor).

    Only the candidates with no slipping term (the narrowest windows) take part: a bearing
    line's slip blurs the factor, and the bearing lattices are dense enough that a window of
    their slip holds most peaks at any factor. Each of the :data:`SCALE_TRIAL_PEAKS`
    strongest peaks near a shaft or mesh line proposes the factor that puts it exactly on
    it; the proposal holding the most peaks (then the most amplitude, then nearest 1) wins.
    A wrong factor that shifts a high harmonic's sideband onto its neighbour moves every
    lower line off its candidate, so the count separates them. The winner is refined by
    least squares over the pairs it holds (a proposal from a low line carries its
    centroid's error up the lattice).
    """
    if f_pk.size == 0:
        return None
    exact = window <= np.min(window) * (1.0 + 1e-9)    # candidates with no slipping term
    propose = exact if proposers is None else exact & proposers
    near_any = (np.abs(f_pk[:, None] - cf[None, :]) <= (window + rel * cf)[None, :]) & propose
    cf, window = cf[exact], window[exact]
    near_any = near_any[:, exact]
    strong = [p for p in np.argsort(a_pk)[::-1] if near_any[p].any()][:SCALE_TRIAL_PEAKS]
    best, best_key = None, None
    for p in strong:
        for j in np.flatnonzero(near_any[p]):
            s = f_pk[p] / cf[j]
            if abs(s - 1.0) > rel:
                continue
            held, _ = _held(f_pk, cf * s, window)
            key = (int(held.sum()), float(a_pk[held].sum()), -abs(s - 1.0))
            if best_key is None or key > best_key:
                best, best_key = s, key
    if best is None or best_key[0] < min_held:
        return None
    held, j = _held(f_pk, cf * best, window)
    return float(np.sum(f_pk[held] * cf[j[held]]) / np.sum(cf[j[held]] ** 2))


def _held(f_pk, cf, window):
    """Which peaks lie within a candidate's window, and each peak's nearest candidate."""
    err = np.abs(f_pk[:, None] - cf[None, :])
    j = np.argmin(err, axis=1)
    return np.any(err <= window[None, :], axis=1), j


def labelled_peaks(x, fs, freqs, kind="amplitude", *, band_hz=None, speed_rpm=None,
                   bearing=None, window="flattop", tolerance_hz=None, max_sideband=3,
                   threshold_db=15.0, max_peaks=None):
    """Spectrum of a signal plus :func:`label_peaks` in one call.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, any unit.
    fs : float
        Sampling rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies or dict
        Characteristic frequencies (:func:`~cmsim.frequencies.rig_frequencies`), or a
        families dict (keys from :data:`FAMILY_KEYS`, Hz).
    kind : {"amplitude", "envelope", "order"}
        ``"amplitude"``: :func:`~cmsim.spectra.amplitude.amplitude_spectrum`;
        ``"envelope"``: :func:`~cmsim.spectra.envelope.envelope_spectrum` in ``band_hz``
        (default: the best band of the kurtogram of the signal's linear-prediction residual,
        as the band rule reads it); ``"order"``:
        :func:`~cmsim.spectra.order.order_spectrum`, with families divided by ``fr``.
    band_hz : tuple of float, optional
        Demodulation band for ``kind="envelope"``, Hz.
    speed_rpm : float or array_like, optional
        Shaft speed for ``kind="order"``; default constant 60·fr.
    bearing : str, optional
        Bearing whose frequencies are used when ``freqs`` is a ``RigFrequencies``.
    window : {"flattop", "hann", "boxcar"}
        Spectrum window.
    tolerance_hz : float, optional
        Match tolerance, Hz (orders for ``kind="order"``); default one bin.
    max_sideband : int
        Largest |m|, |n|.
    threshold_db : float
        Least height above the noise floor, dB.
    max_peaks : int, optional
        Keep only the highest peaks.

    Returns
    -------
    pandas.DataFrame
        As :func:`label_peaks`; for ``kind="order"`` the columns ``frequency_hz``,
        ``expected_hz``, ``error_hz`` are named ``order``, ``expected_order``, ``error_order``.
    """
    check_choice("kind", kind, PEAK_KINDS)
    check_choice("window", window, WINDOWS)
    fs = sampling_rate(fs)
    if isinstance(freqs, RigFrequencies):
        fam = freqs.families(bearing)
    elif isinstance(freqs, dict):
        fam = peak_families(freqs, bearing) if "shaft_hz" in freqs else _check_families(freqs)
    else:
        raise ParameterError(f"freqs must be a RigFrequencies or a families dict, got "
                             f"{type(freqs).__name__}")
    if kind == "amplitude":
        f, a = amplitude_spectrum(x, fs, window=window)
    elif kind == "envelope":
        x = signal_1d(x)
        if band_hz is None:
            bnd = residual_kurtogram(x, fs).band_hz
        else:
            bnd = band("band_hz", band_hz, fs)
        f, a = envelope_spectrum(x, fs, bnd, window=window)
    else:
        if "fr" not in fam:
            raise ParameterError("kind='order' needs the shaft rate 'fr' in freqs")
        spd = 60.0 * fam["fr"] if speed_rpm is None else speed_rpm
        f, a = order_spectrum(x, fs, speed_rpm=spd, window=window)
        fam = {k: v / fam["fr"] for k, v in fam.items()}
    out = label_peaks(f, a, fam, tolerance_hz=tolerance_hz, max_sideband=max_sideband,
                      threshold_db=threshold_db, max_peaks=max_peaks)
    if kind == "order":
        out = out.rename(columns={"frequency_hz": "order", "expected_hz": "expected_order",
                                  "error_hz": "error_order"})
    return out
