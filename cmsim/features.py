"""The one feature extractor: labelled lines, sidebands, envelope families and statistics.

One record (simulated or measured) and its :class:`~cmsim.frequencies.RigFrequencies` give a
:class:`FeatureRow` of fixed, named scalar columns (:meth:`FeatureRow.to_dict`):

* **GMF harmonics** k = 1..:data:`N_GMF_HARMONICS` (6: the paper's Figs. 5-6 and the report
  show up to the 6th; the dominant harmonic moves from the 2nd to the 5th with torque):
  ``gmf{k}_amp``, the flat-top amplitude spectrum at k·GMF (signal unit);
* **sidebands** around each GMF harmonic at ±1, ±2 (:data:`SIDEBAND_ORDERS`) times each shaft
  rate and the bearing's ball-pass rate: ``gmf{k}_sb_fr1_m1`` (k·GMF − fr1),
  ``gmf{k}_sb_fr2_p2`` (k·GMF + 2·fr2), ``gmf{k}_sb_bpf_{bearing}_m1`` …; NaN when the
  offset is below :data:`MIN_SIDEBAND_BINS` bins (the carrier's flat-top lobe would be read);
* **bearing defect families** in the envelope spectrum, harmonics h = 1..
  :data:`N_ENVELOPE_HARMONICS` (3) of BPFO, BPFI, BSF and FTF (:data:`ENVELOPE_FAMILIES`;
  ``bsf_h2`` is 2·BSF, the rate of a ball defect hitting both races):
  ``env_{family}_{bearing}_h{h}``. The demodulation band is the kurtogram's best band at
  least :data:`~cmsim.spectra.kurtogram.FAULT_BANDWIDTH_FACTOR` × the highest fundamental
  wide (``env_band_lo_hz``, ``env_band_hi_hz``), or ``band_hz``;
* **statistics** of the mean-removed signal: ``rms``, ``kurtosis`` (m4/m2², 3 for Gaussian
  noise, 1.5 for a sine), ``crest`` (max|x − x̄|/rms, √2 for a sine) and
  ``tsa_residual_kurtosis``, the kurtosis of the residual of the time-synchronous average over
  the input shaft (gear rigs only: a gear shaft rate is known);
* optionally the ``top_n`` largest labelled peaks: ``peak{i}_hz``, ``peak{i}_amp``,
  ``peak{i}_label``, ``peak{i}_db_re_carrier``.

Without gears (a bearing rig, a measured bearing record) the GMF columns are present and NaN,
so rows of different records share their columns. Lines are read by
:func:`cmsim.spectra.waterfall.harmonic_amplitudes` (largest bin within ±1.5 bins, so a tone
between bins still reads its amplitude); spectra come from :mod:`cmsim.spectra`.

References
----------
.. [1] R. B. Randall, *Vibration-based Condition Monitoring*, Wiley 2011, ch. 5-6
   (GMF sidebands, envelope analysis, TSA residual).
.. [2] P. D. McFadden, MSSP 1 (1987) 83-95 (time-synchronous averaging).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.ndimage import uniform_filter1d

from cmsim.errors import ParameterError
from cmsim.frequencies import RigFrequencies
from cmsim.spectra._checks import band as check_band
from cmsim.spectra._checks import positive_int, sampling_rate, signal_1d
from cmsim.spectra.amplitude import amplitude_spectrum
from cmsim.spectra.envelope import envelope_spectrum
from cmsim.spectra.kurtogram import FAULT_BANDWIDTH_FACTOR, kurtogram
from cmsim.spectra.labels import label_peaks
from cmsim.spectra.run_spectrum import run_families, signal_bearing
from cmsim.spectra.tsa import time_synchronous_average
from cmsim.spectra.waterfall import harmonic_amplitudes

__all__ = ["FeatureRow", "LabelledLine", "extract_features", "run_features", "gmf_levels",
           "statistics", "relative_features", "N_GMF_HARMONICS", "SIDEBAND_ORDERS",
           "N_ENVELOPE_HARMONICS", "ENVELOPE_FAMILIES", "MIN_SIDEBAND_BINS", "N_SHAPE_BANDS",
           "LINE_TOLERANCE", "N_SIDEBAND_HARMONICS", "SIDEBAND_HALF_WIDTH",
           "MAX_SIDEBAND_ORDER"]

#: GMF harmonics measured (1..6).
N_GMF_HARMONICS = 6

#: Sideband orders n of k·GMF + n·f_rate.
SIDEBAND_ORDERS = (-2, -1, 1, 2)

#: Harmonics of each bearing defect family read in the envelope spectrum (1..3).
N_ENVELOPE_HARMONICS = 3

#: Bearing defect families of the envelope spectrum (attribute prefixes of
#: :class:`~cmsim.frequencies.BearingFrequencies`).
ENVELOPE_FAMILIES = ("bpfo", "bpfi", "bsf", "ftf")

#: Least sideband offset, in spectrum bins, for a sideband to be read (a flat-top main lobe
#: spans about ±2.5 bins and the reading window ±1.5 bins).
MIN_SIDEBAND_BINS = 5.0

#: Bands of the spectral-shape columns of :func:`relative_features` (3 log-spaced up to
#: 0.05·fs, then linear to fs/2).
N_SHAPE_BANDS = 12

#: Relative tolerance on a line's frequency in :func:`relative_features` (a bearing's 1-2 %
#: slip, a slightly wrong speed); the line is the largest bin within ±(tolerance + 1.5 bins).
LINE_TOLERANCE = 0.02

#: GMF harmonics whose shaft-rate sideband energies :func:`relative_features` reads.
N_SIDEBAND_HARMONICS = 8

#: Half width of a sideband energy band, in shaft rates (the bands of a carrier and its
#: sidebands tile the spectrum around it).
SIDEBAND_HALF_WIDTH = 0.5

#: Highest shaft order k·Z at which sideband energies are read.
MAX_SIDEBAND_ORDER = 150

#: Highest shaft order of the line the mesh is tracked on (a wobble ε moves a line at order
#: q by q·ε shaft rates; it must stay within the ±f_r/2 band: 0.2 % up to order 250).
TRACK_MAX_ORDER = 200

#: Least level of the tracked line over its neighbourhood's median bin, dB.
TRACK_MIN_DB = 20.0


@dataclass(frozen=True)
class LabelledLine:
    """One labelled spectral peak.

    Attributes
    ----------
    frequency_hz : float
        Peak frequency, Hz.
    amplitude : float
        Amplitude, signal unit.
    label : str
        Label from :func:`~cmsim.spectra.labels.label_peaks` (``""`` if unlabelled).
    db_re_carrier : float
        Level relative to its carrier, dB (NaN when the label has no carrier).
    """

    frequency_hz: float
    amplitude: float
    label: str
    db_re_carrier: float


@dataclass(frozen=True)
class FeatureRow:
    """Features of one signal (see the module docstring for the column names).

    Attributes
    ----------
    bearing : str or None
        Bearing whose ball-pass and defect rates are used (``None``: the frequencies hold no
        bearing; then there are no envelope columns).
    rms : float
        RMS of the mean-removed signal, signal unit.
    kurtosis : float
        m4/m2² of the mean-removed signal (3: Gaussian, 1.5: sine).
    crest : float
        max|x − x̄| / rms.
    tsa_residual_kurtosis : float
        Kurtosis of the TSA residual over the input shaft; NaN without gears or with fewer
        than 2 whole revolutions.
    gmf_amp : tuple of float, shape (n_gmf,)
        Amplitude at k·GMF, k = 1..n_gmf, signal unit; NaN without gears or above fs/2.
    sidebands : dict of str to tuple of float
        ``"{rate}_{m|p}{n}"`` (rate ``fr1``, ``fr2`` or ``bpf_<bearing>``) → amplitude at
        k·GMF ± n·rate for k = 1..n_gmf, signal unit (NaN where unresolved or absent).
    envelope : dict of str to tuple of float
        Family (``"bpfo"``, ``"bpfi"``, ``"bsf"``, ``"ftf"``) → envelope-spectrum amplitude at
        h·f_family, h = 1..3, signal unit.
    envelope_band_hz : tuple of float
        Demodulation band (lo, hi), Hz; (NaN, NaN) when no band could be chosen.
    peaks : tuple of LabelledLine
        The ``top_n`` largest labelled peaks of the amplitude spectrum, largest first, padded
        with NaN/``""`` lines when fewer peaks stand out (empty when ``top_n`` = 0).
    """

    bearing: str | None
    rms: float
    kurtosis: float
    crest: float
    tsa_residual_kurtosis: float
    gmf_amp: tuple
    sidebands: dict = field(default_factory=dict)
    envelope: dict = field(default_factory=dict)
    envelope_band_hz: tuple = (math.nan, math.nan)
    peaks: tuple = ()

    def to_dict(self):
        """Flat dict of scalar columns with stable names (floats, NaN where absent; peak
        labels are str)."""
        out = {"rms": self.rms, "kurtosis": self.kurtosis, "crest": self.crest,
               "tsa_residual_kurtosis": self.tsa_residual_kurtosis}
        for k, a in enumerate(self.gmf_amp, start=1):
            out[f"gmf{k}_amp"] = a
            for key, amps in self.sidebands.items():
                out[f"gmf{k}_sb_{key}"] = amps[k - 1]
        for fam, amps in self.envelope.items():
            for h, a in enumerate(amps, start=1):
                out[f"env_{fam}_{self.bearing}_h{h}"] = a
        if self.envelope:
            out["env_band_lo_hz"], out["env_band_hi_hz"] = self.envelope_band_hz
        for i, p in enumerate(self.peaks, start=1):
            out[f"peak{i}_hz"] = p.frequency_hz
            out[f"peak{i}_amp"] = p.amplitude
            out[f"peak{i}_label"] = p.label
            out[f"peak{i}_db_re_carrier"] = p.db_re_carrier
        return out

    def to_summary(self):
        """JSON-ready summary (NaN → ``None``), the per-signal record of a sweep manifest.

        Returns
        -------
        dict
            ``gmf_harmonics`` (list of the GMF harmonic amplitudes, or ``None`` without
            gears), ``dominant_gmf_harmonic`` (int or ``None``), ``top_peaks`` (list of
            {frequency_hz, amplitude, label, db_re_carrier}, the padding left out) and
            ``features`` (:meth:`to_dict`).
        """
        def js(v):
            return None if isinstance(v, float) and not math.isfinite(v) else v

        has_gmf = any(math.isfinite(a) for a in self.gmf_amp)
        return {
            "top_peaks": [{"frequency_hz": p.frequency_hz, "amplitude": p.amplitude,
                           "label": p.label, "db_re_carrier": js(p.db_re_carrier)}
                          for p in self.peaks if math.isfinite(p.frequency_hz)],
            "gmf_harmonics": [js(float(a)) for a in self.gmf_amp] if has_gmf else None,
            "dominant_gmf_harmonic": self.dominant_gmf_harmonic,
            "features": {k: js(v) for k, v in self.to_dict().items()}}

    @property
    def dominant_gmf_harmonic(self):
        """k of the largest GMF harmonic (1-based), or ``None`` without a finite one."""
        a = np.asarray(self.gmf_amp, dtype=float)
        if not np.any(np.isfinite(a)):
            return None
        return int(np.nanargmax(a)) + 1


# ---------------------------------------------------------------------- building blocks
def gmf_levels(spectrum, gmf_hz, n_harmonics=N_GMF_HARMONICS):
    """Amplitudes of k·GMF, k = 1..n_harmonics, in an amplitude spectrum.

    Parameters
    ----------
    spectrum : cmsim.spectra.Spectrum or (freq_hz, amplitude)
        Amplitude spectrum, Hz and signal unit.
    gmf_hz : float
        Gear mesh frequency, Hz (> 0).
    n_harmonics : int
        Number of harmonics.

    Returns
    -------
    numpy.ndarray, shape (n_harmonics,)
        Amplitudes, signal unit; NaN above the last bin.
    """
    freq, amp = spectrum
    return harmonic_amplitudes(freq, amp, gmf_hz, n_harmonics)


def _line(freq, amp, f_hz):
    """Amplitude of the line at ``f_hz`` (NaN outside (0, last bin])."""
    if not (math.isfinite(f_hz) and 0.0 < f_hz):
        return math.nan
    return float(harmonic_amplitudes(freq, amp, f_hz, 1)[0])


def statistics(x):
    """``(rms, kurtosis, crest)`` of the mean-removed signal ``x``.

    Examples
    --------
    >>> t = np.arange(4000) / 4000.0
    >>> [round(v, 4) for v in statistics(np.sin(2 * np.pi * 10 * t))]
    [0.7071, 1.5, 1.4142]
    """
    x = np.asarray(x, dtype=float)
    d = x - x.mean()
    m2 = float(np.mean(d * d))
    if m2 <= 0.0:
        return 0.0, math.nan, math.nan
    rms = math.sqrt(m2)
    return rms, float(np.mean(d ** 4)) / m2 ** 2, float(np.max(np.abs(d))) / rms


def _tsa_residual_kurtosis(x, fs, shaft_hz):
    try:
        avg = time_synchronous_average(x, fs, speed_rpm=60.0 * shaft_hz)
    except ParameterError:
        return math.nan
    return statistics(avg.residual)[1]


def _envelope(x, fs, bf, band_hz):
    """(band, {family: (n,) amplitudes}) of the envelope spectrum."""
    rates = {fam: getattr(bf, f"{fam}_hz") for fam in ENVELOPE_FAMILIES}
    nan_fams = {fam: (math.nan,) * N_ENVELOPE_HARMONICS for fam in ENVELOPE_FAMILIES}
    if band_hz is None:
        f_max = max(bf.bpfo_hz, bf.bpfi_hz, 2.0 * bf.bsf_hz, bf.ftf_hz)
        try:
            band = kurtogram(x, fs, max_fault_hz=f_max if f_max > 0 else None).band_hz
        except ParameterError:
            return (math.nan, math.nan), nan_fams
    else:
        band = check_band("band_hz", band_hz, fs)
    freq, amp = envelope_spectrum(x, fs, band)
    out = {fam: tuple(_line(freq, amp, h * r) for h in range(1, N_ENVELOPE_HARMONICS + 1))
           for fam, r in rates.items()}
    return tuple(float(b) for b in band), out


# ---------------------------------------------------------------------- extractor
def extract_features(signal, fs_hz, freqs, *, bearing=None, band_hz=None,
                     n_gmf_harmonics=N_GMF_HARMONICS, top_n=0, envelope=True):
    """Features of one signal: GMF harmonics, sidebands, envelope families, statistics.

    Parameters
    ----------
    signal : array_like, shape (n,)
        Signal, any unit (acceleration, force, DTE ...); finite, n >= 64.
    fs_hz : float
        Sampling rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies
        Characteristic frequencies (:func:`cmsim.frequencies.rig_frequencies`, or built
        directly for a measured record).
    bearing : str, optional
        Bearing whose ball-pass and defect rates are used; default the first of ``freqs``.
    band_hz : tuple of float, optional
        Envelope demodulation band (lo, hi), Hz; default the kurtogram's best band of width
        >= 3 × the highest defect fundamental (max of BPFO, BPFI, 2·BSF, FTF).
    n_gmf_harmonics : int
        GMF harmonics read (default :data:`N_GMF_HARMONICS` = 6).
    top_n : int
        Largest labelled peaks kept (0: no peak labelling).
    envelope : bool
        Compute the envelope families (False skips the kurtogram and envelope spectrum).

    Returns
    -------
    FeatureRow

    Examples
    --------
    >>> from cmsim.frequencies import RigFrequencies
    >>> fs = 4096.0
    >>> t = np.arange(8192) / fs
    >>> f = RigFrequencies(fr1_hz=10.0, fr2_hz=10.0, gmf_hz=200.0)
    >>> row = extract_features(2.0 * np.sin(2 * np.pi * 400.0 * t), fs, f)
    >>> round(row.to_dict()["gmf2_amp"], 3), row.dominant_gmf_harmonic
    (2.0, 2)
    """
    x = signal_1d(signal, "signal")
    fs = sampling_rate(fs_hz, "fs_hz")
    if not isinstance(freqs, RigFrequencies):
        raise ParameterError(f"freqs must be a RigFrequencies, got {type(freqs).__name__}")
    n_gmf = positive_int("n_gmf_harmonics", n_gmf_harmonics, lo=1, hi=100)
    top_n = positive_int("top_n", top_n, lo=0)
    bf = freqs.bearing(bearing) if freqs.bearings else None
    name = (bearing if bearing is not None else freqs.bearing_names[0]) if bf else None

    rms, kurt, crest = statistics(x)
    spec = amplitude_spectrum(x, fs)
    freq, amp = spec
    df = spec.resolution_hz
    rates = dict(freqs.shaft_rates_hz)
    if "fr2" not in rates:
        rates["fr2"] = math.nan
    if bf is not None:
        rates[f"bpf_{name}"] = bf.bpf_hz
    nan_h = (math.nan,) * n_gmf
    if freqs.gmf_hz is not None:
        gmf = float(freqs.gmf_hz)
        gmf_amp = tuple(float(v) for v in gmf_levels(spec, gmf, n_gmf))
        sidebands = {}
        for key, r in rates.items():
            for n in SIDEBAND_ORDERS:
                off = n * r
                ok = math.isfinite(off) and abs(off) >= MIN_SIDEBAND_BINS * df
                sidebands[f"{key}_{'m' if n < 0 else 'p'}{abs(n)}"] = tuple(
                    _line(freq, amp, k * gmf + off) if ok else math.nan
                    for k in range(1, n_gmf + 1))
        tsa_k = _tsa_residual_kurtosis(x, fs, freqs.fr1_hz)
    else:
        gmf_amp, tsa_k = nan_h, math.nan
        sidebands = {f"{key}_{'m' if n < 0 else 'p'}{abs(n)}": nan_h
                     for key in rates for n in SIDEBAND_ORDERS}

    env_band, env = (math.nan, math.nan), {}
    if bf is not None and envelope:
        env_band, env = _envelope(x, fs, bf, band_hz)

    peaks = ()
    if top_n:
        fam = freqs.families(name) if bf is not None else (
            {"GMF": freqs.gmf_hz} if freqs.gmf_hz else {"fr": freqs.fr1_hz})
        df_peaks = label_peaks(freq, amp, fam).sort_values("amplitude", ascending=False)
        peaks = tuple(LabelledLine(float(r.frequency_hz), float(r.amplitude), str(r.label),
                                   float(r.db_re_carrier))
                      for r in df_peaks.head(top_n).itertuples())
        peaks += (LabelledLine(math.nan, math.nan, "", math.nan),) * (top_n - len(peaks))
    return FeatureRow(bearing=name, rms=rms, kurtosis=kurt, crest=crest,
                      tsa_residual_kurtosis=tsa_k, gmf_amp=gmf_amp, sidebands=sidebands,
                      envelope=env, envelope_band_hz=env_band, peaks=peaks)


def run_features(run, channel, *, freqs=None, bearing=None, **kwargs):
    """:func:`extract_features` of one signal of a :class:`~cmsim.run.Run`.

    Parameters
    ----------
    run : cmsim.run.Run
        Simulated run (its meta holds the rig and operating point) or measured record.
    channel : str
        Signal name, e.g. ``"F_1b1_loa"``.
    freqs : cmsim.frequencies.RigFrequencies, optional
        Default: from the run's rig and operating point.
    bearing : str, optional
        Default: the bearing named in ``channel`` (``F_2b1_loa`` → ``2b1``), else the first.
    **kwargs
        Passed to :func:`extract_features` (``band_hz``, ``n_gmf_harmonics``, ``top_n``,
        ``envelope``).

    Returns
    -------
    FeatureRow
    """
    if freqs is None:
        freqs, _ = run_families(run)
    if bearing is None and freqs.bearings:
        bearing = signal_bearing(channel, freqs.bearing_names)
    return extract_features(run[channel], run.fs_hz, freqs, bearing=bearing, **kwargs)


# ---------------------------------------------------------------------- scale-free features
def _hann_spectrum(x, fs):
    win = np.hanning(x.size)
    amp = np.abs(np.fft.rfft((x - x.mean()) * win)) * 2.0 / win.sum()
    return np.fft.rfftfreq(x.size, 1.0 / fs), amp


def _line_bins(freq, f, df):
    """Mask of the bins within f·(1 ± LINE_TOLERANCE) ± 1.5 bins (None if there are none)."""
    half = LINE_TOLERANCE * f + 1.5 * df
    sel = (freq >= f - half) & (freq <= f + half)
    return sel if f > 0 and np.any(sel) else None


def _peak(freq, amp, f, df):
    """Largest bin of the line at ``f`` (:func:`_line_bins`; NaN outside the spectrum)."""
    sel = _line_bins(freq, f, df)
    return math.nan if sel is None else float(np.max(amp[sel]))


def _band_excess(freq, amp, f, df, floor):
    """Power in the bins of the line at ``f`` (:func:`_line_bins`) over what the local floor
    puts there: a line smeared by slip or a speed fluctuation keeps its energy (unlike a
    line that is gone, or drowned in noise)."""
    sel = _line_bins(freq, f, df)
    if sel is None or not floor > 0:
        return math.nan
    return float(np.sum(amp[sel] ** 2) / (np.count_nonzero(sel) * floor ** 2))


def _db(a, ref):
    if not (math.isfinite(a) and ref > 0):
        return math.nan
    return 20.0 * math.log10(max(a, 1e-30 * ref) / ref)


def _sideband_energies(x, fs, freqs):
    """Shaft-rate sideband energy of each GMF harmonic over its carrier's, dB.

    The segment is first order-tracked on its own mesh (:func:`_mesh_tracked`), so a slow
    speed wobble or a slightly wrong nominal speed does not smear the carriers into their
    sidebands. Then, for each gear shaft (rate f_r, Z = GMF/f_r teeth) and GMF harmonic
    k = 1..:data:`N_SIDEBAND_HARMONICS` with k·Z <= :data:`MAX_SIDEBAND_ORDER` and its third
    sideband below 0.45·fs (NaN otherwise): ``sb1_{fr1|fr2}_k{k}_db`` = energy in the bands
    k·GMF ± f_r over the energy in the band at k·GMF, and ``sb23_..._k{k}_db`` the same for
    ± 2 f_r and ± 3 f_r. Each band is k·GMF + n·f_r ± :data:`SIDEBAND_HALF_WIDTH`·f_r: a
    band, not a bin, so what the tracking leaves of a wobble stays in it, and the ratio of
    two nearby bands drops the transfer path's gain. Eccentricity and a slow load modulation
    raise the first sidebands; a local tooth fault spreads energy over many."""
    y, scale = _mesh_tracked(x, fs, freqs)
    freq, amp = _hann_spectrum(y, fs)
    power = amp ** 2
    gmf = freqs.gmf_hz * scale
    out = {}
    rates = [("fr1", freqs.fr1_hz * scale)]
    if freqs.fr2_hz is not None:
        rates.append(("fr2", freqs.fr2_hz * scale))
    for name, fr in rates:
        w = SIDEBAND_HALF_WIDTH * fr
        for k in range(1, N_SIDEBAND_HARMONICS + 1):
            fk = k * gmf
            if fk / fr > MAX_SIDEBAND_ORDER + 0.5 or fk + 3.5 * fr > 0.45 * fs:
                out[f"sb1_{name}_k{k}_db"] = out[f"sb23_{name}_k{k}_db"] = math.nan
                continue
            e = {n: float(np.sum(power[(freq >= fk + n * fr - w) & (freq < fk + n * fr + w)]))
                 for n in (-3, -2, -1, 0, 1, 2, 3)}
            c = e[0]
            out[f"sb1_{name}_k{k}_db"] = _db_power(e[-1] + e[1], c)
            out[f"sb23_{name}_k{k}_db"] = _db_power(e[-3] + e[-2] + e[2] + e[3], c)
    return out


def _mesh_tracked(x, fs, freqs):
    """``x`` resampled at uniform mesh phase (computed order tracking without a tacho).

    The reference is the strongest GMF harmonic up to shaft order :data:`TRACK_MAX_ORDER`:
    demodulated to zero frequency and averaged over one revolution of each shaft, its phase
    gives the mesh angle; the average nulls the shaft-rate sidebands, so only wobbles slower
    than about f_r/2 are tracked out and the modulations under study stay in the signal.
    Without a line :data:`TRACK_MIN_DB` above its neighbourhood the segment is returned as
    it is. (:mod:`cmsim.spectra.order` resamples from a known speed or a tacho; here the
    angle is read from the signal itself.)

    Returns
    -------
    (ndarray, float)
        The resampled segment (same length and rate) and the measured mean speed over the
        nominal one.
    """
    n = x.size
    fr = min(f for f in (freqs.fr1_hz, freqs.fr2_hz) if f is not None)
    spec = np.fft.fft(x)
    f = np.fft.fftfreq(n, 1.0 / fs)
    best = None                                   # (energy, snr dB, k) of the strongest line
    k = 1
    while k * freqs.gmf_hz / freqs.fr1_hz <= TRACK_MAX_ORDER + 0.5 \
            and k * freqs.gmf_hz + 3 * fr < 0.45 * fs:
        fc = k * freqs.gmf_hz
        band = np.abs(f - fc) < 0.5 * fr
        near = (np.abs(f - fc) < 3.0 * fr) & ~band
        if np.any(band) and np.any(near):
            p = np.abs(spec[band]) ** 2
            snr = 10 * math.log10(max(float(p.max()), 1e-300)
                                  / max(float(np.median(np.abs(spec[near]) ** 2)), 1e-300))
            if best is None or float(p.sum()) > best[0]:
                best = (float(p.sum()), snr, k)
        k += 1
    if best is None or best[1] < TRACK_MIN_DB:
        return x, 1.0
    k = best[2]
    fc = k * freqs.gmf_hz
    t = np.arange(n) / fs
    # complex demodulation, then a moving average over one revolution of each shaft: its
    # zeros sit on every multiple of the shaft rates (the sidebands under study and the
    # other mesh harmonics), while a wobble slower than f_r/2 passes
    base = x * np.exp(-2j * math.pi * fc * t)
    for rate in {freqs.fr1_hz, freqs.fr2_hz or freqs.fr1_hz}:
        width = max(1, int(round(fs / rate)))
        base = (uniform_filter1d(base.real, width, mode="nearest")
                + 1j * uniform_filter1d(base.imag, width, mode="nearest"))
    phase = np.unwrap(np.angle(base)) + 2 * math.pi * fc * t
    if np.any(np.diff(phase) <= 0.0):             # noise, not a line: leave the segment
        return x, 1.0
    # a cubic spline, as cmsim.spectra.order: linear interpolation at ~8 samples per period
    # of a mesh harmonic would modulate it by ~6 % as the resampling delay slides by
    y = CubicSpline(phase, x)(np.linspace(phase[0], phase[-1], n))
    scale = (phase[-1] - phase[0]) / (2 * math.pi * k * freqs.gmf_hz * (n - 1) / fs)
    return y, scale


def _db_power(p, ref):
    if not (math.isfinite(p) and ref > 0):
        return math.nan
    return 10.0 * math.log10(max(p, 1e-30 * ref) / ref)


def _shape_bands(freq, power, fs, df):
    edges = np.concatenate([np.geomspace(max(20.0, 2 * df), 0.05 * fs, 4)[:-1],
                            np.linspace(0.05 * fs, 0.5 * fs, N_SHAPE_BANDS - 2)])
    total = power[freq >= edges[0]].sum()
    return {f"shape_b{i}_db": 10.0 * math.log10(max(
        power[(freq >= edges[i]) & (freq < edges[i + 1])].sum() / total, 1e-12))
        for i in range(len(edges) - 1)}


def relative_features(signal, fs_hz, freqs, bearings=None):
    """Features that compare a model with a measurement whose absolute scale is unknown.

    Every column is a ratio (dB) or a shape statistic, never an absolute level, so an
    unknown sensor gain, unit or transfer-path gain drops out (the measured-data loop of
    :mod:`cmsim.discrepancy` compares these):

    * ``kurtosis_log``, ``crest_log``: natural log of the kurtosis and crest factor;
    * ``shape_b{i}_db``: share of the spectrum's energy in each of :data:`N_SHAPE_BANDS`
      bands (the spectral shape after the transfer path), dB;
    * ``raw_fr_h1_db``, ``raw_fr_h2_db``: shaft lines of the amplitude spectrum over its
      median level, dB; per bearing b, ``raw_bpfo_{b}_db`` (the ball-pass line of a fixed
      outer ring: varying compliance, an outer-race defect) and ``raw_bpfo_{b}_band_db``,
      the power around it over the floor's (a line smeared by slip keeps it);
    * envelope spectrum (band: the kurtogram's best, wide enough for the highest defect
      fundamental of the bearings) over its median level, dB: ``env_fr_h1_db``; per bearing
      b, ``env_{bpfo|bpfi|bsf2}_{b}_h{1|2}_db`` (bsf2 = 2·BSF, a ball defect hitting both
      races), ``env_ftf_{b}_db``, ``env_bpfi_{b}_sb_db`` (BPFI ± shaft rate), ``env_bpfo_{b}_sb_db``
      (BPFO and 2·BPFO ± shaft rate: a once-per-rev speed or load modulation) and
      ``env_bpfo_{b}_band_db``;
    * gear rigs: ``gmf{k}_rel_db`` (k = 1..4, relative to the largest) and
      ``tsa_residual_kurtosis_log`` from :func:`extract_features`; per gear shaft and GMF
      harmonic k = 1..:data:`N_SIDEBAND_HARMONICS` (up to shaft order
      :data:`MAX_SIDEBAND_ORDER`), ``sb1_{fr1|fr2}_k{k}_db`` and
      ``sb23_{fr1|fr2}_k{k}_db``: energy of the ±1 and of the ±2, ±3 shaft-rate sidebands
      over the carrier's (bands, robust to a small speed wobble; each harmonic its own
      column, since the transfer path favours some and the noise floor hides others).

    Lines are the largest bin within ±(:data:`LINE_TOLERANCE` relative + 1.5 bins) of the
    nominal frequency (Hann window).

    Parameters
    ----------
    signal : array_like, shape (n,)
        Segment, any unit.
    fs_hz : float
        Sample rate, Hz.
    freqs : RigFrequencies
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
    freq, amp = _hann_spectrum(x, fs)
    df = freq[1]
    out.update(_shape_bands(freq, amp ** 2, fs, df))
    fr = freqs.fr1_hz
    top = max([bf.bpfi_hz for bf in bfs.values()] + [4.0 * fr])
    sel = (freq >= 0.5 * fr) & (freq <= min(fs / 2, 20 * top))
    floor = float(np.median(amp[sel]))
    out["raw_fr_h1_db"] = _db(_peak(freq, amp, fr, df), floor)
    out["raw_fr_h2_db"] = _db(_peak(freq, amp, 2 * fr, df), floor)
    for b, bf in bfs.items():
        out[f"raw_bpfo_{b}_db"] = _db(_peak(freq, amp, bf.bpfo_hz, df), floor)
        e = _band_excess(freq, amp, bf.bpfo_hz, df, floor)
        out[f"raw_bpfo_{b}_band_db"] = 10.0 * math.log10(max(e, 1e-6)) if e == e else e
    if bfs:
        f_max = max(max(bf.bpfo_hz, bf.bpfi_hz, 2 * bf.bsf_hz) for bf in bfs.values())
        try:
            lo_b, hi_b = kurtogram(x, fs, max_fault_hz=f_max).band_hz
        except ParameterError:
            lo_b, hi_b = 0.05 * fs, 0.45 * fs
        if hi_b - lo_b < 0.02 * fs:             # a very narrow band: ill-conditioned filter
            mid = 0.5 * (lo_b + hi_b)
            lo_b, hi_b = max(mid - 0.01 * fs, 1.0), min(mid + 0.01 * fs, 0.49 * fs)
        try:
            ef, ea = envelope_spectrum(x, fs, (lo_b, hi_b), window="hann")
        except (ParameterError, np.linalg.LinAlgError, ValueError):
            ef, ea = envelope_spectrum(x, fs, (0.05 * fs, 0.45 * fs), window="hann")
        edf = ef[1]
        top_e = max(bf.bpfi_hz for bf in bfs.values())
        esel = (ef >= 0.5 * fr) & (ef <= 4.0 * top_e)
        efloor = float(np.median(ea[esel])) if np.any(esel) else 1.0
        out["env_fr_h1_db"] = _db(_peak(ef, ea, fr, edf), efloor)
        for b, bf in bfs.items():
            for fam, f in (("bpfo", bf.bpfo_hz), ("bpfi", bf.bpfi_hz), ("bsf2", 2 * bf.bsf_hz)):
                for h in (1, 2):
                    out[f"env_{fam}_{b}_h{h}_db"] = _db(_peak(ef, ea, h * f, edf), efloor)
            out[f"env_ftf_{b}_db"] = _db(_peak(ef, ea, bf.ftf_hz, edf), efloor)
            sb = [_peak(ef, ea, bf.bpfi_hz + s * fr, edf) for s in (-1, 1)]
            out[f"env_bpfi_{b}_sb_db"] = _db(float(np.nanmean(sb)), efloor)
            sb = [_peak(ef, ea, h * bf.bpfo_hz + s * fr, edf) for h in (1, 2) for s in (-1, 1)]
            out[f"env_bpfo_{b}_sb_db"] = _db(float(np.nanmean(sb)), efloor)
            e = _band_excess(ef, ea, bf.bpfo_hz, edf, efloor)
            out[f"env_bpfo_{b}_band_db"] = 10.0 * math.log10(max(e, 1e-6)) if e == e else e
    if freqs.gmf_hz is not None:
        row = extract_features(x, fs, freqs, bearing=names[0] if names else None,
                               envelope=False, n_gmf_harmonics=4)
        d = row.to_dict()
        g = np.array([d[f"gmf{k}_amp"] for k in range(1, 5)], dtype=float)
        gmax = np.nanmax(g) if np.any(np.isfinite(g)) else math.nan
        for k in range(1, 5):
            out[f"gmf{k}_rel_db"] = _db(g[k - 1], gmax)
        out.update(_sideband_energies(x, fs, freqs))
        tk = row.tsa_residual_kurtosis
        out["tsa_residual_kurtosis_log"] = math.log(tk) if math.isfinite(tk) and tk > 0 \
            else math.nan
    return out
