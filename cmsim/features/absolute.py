"""The absolute extractor: labelled lines, sidebands, envelope families and statistics.

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
  ``env_{family}_{bearing}_h{h}``. The demodulation band is that of the band rule
  (``env_band_lo_hz``, ``env_band_hi_hz``), or ``band_hz``;
* **statistics** of the mean-removed signal: ``rms``, ``kurtosis`` (m4/m2², 3 for Gaussian
  noise, 1.5 for a sine), ``crest`` (max|x − x̄|/rms, √2 for a sine) and
  ``tsa_residual_kurtosis``, the kurtosis of the residual of the time-synchronous average over
  the input shaft (gear rigs only: a gear shaft rate is known);
* optionally the ``top_n`` largest labelled peaks: ``peak{i}_hz``, ``peak{i}_amp``,
  ``peak{i}_label``, ``peak{i}_db_re_carrier``.

Without gears (a bearing rig, a measured bearing record) the GMF columns are present and NaN,
so rows of different records share their columns. Lines are read with the one line rule
(:func:`cmsim.features.lines.line_amplitude`: the largest bin within
f·(1 ± ``tolerance``) ± 1.5 bins, so a tone between bins still reads its amplitude; the
default :data:`~cmsim.features.lines.EXACT_TOLERANCE` suits a simulation at constant speed),
the demodulation band with the one band rule (:func:`cmsim.features.lines.demodulation_band`);
spectra come from :mod:`cmsim.spectra` (flat-top: amplitudes are read, not ratios).

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

from cmsim.errors import ParameterError, check_type
from cmsim.features.lines import (EXACT_TOLERANCE, demodulation_band, highest_fault_hz,
                                  line_amplitude)
from cmsim.frequencies import RigFrequencies
from cmsim.spectra._checks import band as check_band
from cmsim.spectra._checks import positive_int, sampling_rate, signal_1d
from cmsim.spectra.amplitude import amplitude_spectrum
from cmsim.spectra.envelope import envelope_spectrum
from cmsim.spectra.labels import label_peaks
from cmsim.spectra.run_spectrum import run_families, signal_bearing
from cmsim.spectra.tsa import time_synchronous_average

__all__ = ["FeatureRow", "LabelledLine", "extract_features", "run_features", "gmf_levels",
           "tsa_residual_kurtosis",
           "statistics", "N_GMF_HARMONICS", "SIDEBAND_ORDERS", "N_ENVELOPE_HARMONICS",
           "ENVELOPE_FAMILIES", "MIN_SIDEBAND_BINS"]

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
def gmf_levels(spectrum, gmf_hz, n_harmonics=N_GMF_HARMONICS, tolerance=EXACT_TOLERANCE):
    """Amplitudes of k·GMF, k = 1..n_harmonics, in an amplitude spectrum (the line rule).

    Parameters
    ----------
    spectrum : cmsim.spectra.Spectrum or (freq_hz, amplitude)
        Amplitude spectrum, Hz and signal unit.
    gmf_hz : float
        Gear mesh frequency, Hz (> 0).
    n_harmonics : int
        Number of harmonics.
    tolerance : float
        Relative tolerance of the line rule (:mod:`cmsim.features.lines`).

    Returns
    -------
    numpy.ndarray, shape (n_harmonics,)
        Amplitudes, signal unit; NaN above the last bin.
    """
    freq, amp = spectrum
    freq, amp = np.asarray(freq, dtype=float), np.asarray(amp, dtype=float)
    gmf = float(gmf_hz)
    if not (math.isfinite(gmf) and gmf > 0.0):
        raise ParameterError(f"gmf_hz must be > 0 Hz, got {gmf_hz!r}", param="gmf_hz")
    return np.array([line_amplitude(freq, amp, k * gmf, tolerance)
                     for k in range(1, positive_int("n_harmonics", n_harmonics) + 1)])


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
    d2 = d * d                            # (d²)², not d ** 4: numpy's pow is 40 times slower
    m2 = float(np.mean(d2))
    if m2 <= 0.0:
        return 0.0, math.nan, math.nan
    rms = math.sqrt(m2)
    return rms, float(np.mean(d2 * d2)) / m2 ** 2, float(np.max(np.abs(d))) / rms


def tsa_residual_kurtosis(x, fs, shaft_hz):
    """Kurtosis of the residual of the time-synchronous average of a signal on one shaft:
    what is not periodic with the shaft, a local tooth fault's impulse among it (Randall,
    *Vibration-based condition monitoring*, 2011, §5.4).

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, any unit.
    fs : float
        Sample rate, Hz.
    shaft_hz : float
        Rate of the shaft, Hz.

    Returns
    -------
    float
        NaN when the signal is too short for an average.
    """
    try:
        avg = time_synchronous_average(x, fs, speed_rpm=60.0 * shaft_hz)
    except ParameterError:
        return math.nan
    return statistics(avg.residual)[1]


def _envelope(x, fs, bf, band_hz, tolerance):
    """(band, {family: (n,) amplitudes}) of the (flat-top) envelope spectrum."""
    rates = {fam: getattr(bf, f"{fam}_hz") for fam in ENVELOPE_FAMILIES}
    if band_hz is None:
        band = demodulation_band(x, fs, highest_fault_hz([bf]))
    else:
        band = check_band("band_hz", band_hz, fs)
    freq, amp = envelope_spectrum(x, fs, band)
    out = {fam: tuple(line_amplitude(freq, amp, h * r, tolerance)
                      for h in range(1, N_ENVELOPE_HARMONICS + 1))
           for fam, r in rates.items()}
    return tuple(float(b) for b in band), out


# ---------------------------------------------------------------------- extractor
def extract_features(signal, fs_hz, freqs, *, bearing=None, band_hz=None,
                     n_gmf_harmonics=N_GMF_HARMONICS, top_n=0, envelope=True,
                     tolerance=EXACT_TOLERANCE):
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
        Envelope demodulation band (lo, hi), Hz; default the band rule's
        (:func:`~cmsim.features.lines.demodulation_band`: the kurtogram's best band of width
        >= 3 × the highest defect fundamental, max of BPFO, BPFI, 2·BSF, FTF).
    n_gmf_harmonics : int
        GMF harmonics read (default :data:`N_GMF_HARMONICS` = 6).
    top_n : int
        Largest labelled peaks kept (0: no peak labelling).
    envelope : bool
        Compute the envelope families (False skips the kurtogram and envelope spectrum).
    tolerance : float
        Relative tolerance of the line rule (:data:`~cmsim.features.lines.EXACT_TOLERANCE`
        for a simulation at constant speed, :data:`~cmsim.features.lines.SLIP_TOLERANCE` for
        lines read at a nominal speed).

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
    check_type("freqs", freqs, RigFrequencies)
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
        gmf_amp = tuple(float(v) for v in gmf_levels(spec, gmf, n_gmf, tolerance))
        sidebands = {}
        for key, r in rates.items():
            for n in SIDEBAND_ORDERS:
                off = n * r
                ok = math.isfinite(off) and abs(off) >= MIN_SIDEBAND_BINS * df
                sidebands[f"{key}_{'m' if n < 0 else 'p'}{abs(n)}"] = tuple(
                    line_amplitude(freq, amp, k * gmf + off, tolerance) if ok else math.nan
                    for k in range(1, n_gmf + 1))
        tsa_k = tsa_residual_kurtosis(x, fs, freqs.fr1_hz)
    else:
        gmf_amp, tsa_k = nan_h, math.nan
        sidebands = {f"{key}_{'m' if n < 0 else 'p'}{abs(n)}": nan_h
                     for key in rates for n in SIDEBAND_ORDERS}

    env_band, env = (math.nan, math.nan), {}
    if bf is not None and envelope:
        env_band, env = _envelope(x, fs, bf, band_hz, tolerance)

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
