"""Labelled spectrum of one signal of a saved run (what ``cmsim spectrum`` prints).

The base frequencies used to name the peaks (GMF, BPF, fr, BPFO, …) come from the run's own
metadata — its rig and operating point — through
:func:`~cmsim.frequencies.rig_frequencies`, with the bearing taken from the signal
name (``F_2b1_loa`` → bearing ``2b1`` and the output shaft rate as ``fr``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from cmsim.errors import ParameterError, check_choice, check_range
from cmsim.frequencies import BEARING_FAMILY_KEYS, rig_frequencies
from cmsim.run import signal_info
from cmsim.spectra._checks import band as check_band
from cmsim.spectra._checks import positive_int
from cmsim.spectra.amplitude import amplitude_spectrum
from cmsim.spectra.envelope import envelope_spectrum
from cmsim.spectra.kurtogram import residual_kurtogram
from cmsim.spectra.labels import PEAK_KINDS, label_peaks
from cmsim.spectra.order import order_spectrum

__all__ = ["RunSpectrum", "run_spectrum", "signal_unit", "signal_bearing", "run_families"]


def signal_unit(name):
    """Unit of a run signal (:func:`cmsim.run.signal_info`), ``""`` for a name not in the schema.

    Examples
    --------
    >>> signal_unit("F_1b1_loa"), signal_unit("dte_um"), signal_unit("x_1G1")
    ('N', 'µm', 'm')
    """
    try:
        return signal_info(name).unit
    except ParameterError:
        return ""


def signal_bearing(name, bearing_names):
    """Bearing a signal belongs to (``F_2b1_loa`` → ``"2b1"``), else the first bearing."""
    for part in name.split("_"):
        if part in bearing_names:
            return part
    return bearing_names[0]


def run_families(run, bearing=None):
    """``(RigFrequencies, families dict)`` of a run from its metadata.

    Parameters
    ----------
    run : cmsim.run.Run
        A run written by :func:`cmsim.dynamics.simulate` (meta holds ``rig`` and
        ``operating_point``).
    bearing : str, optional
        Bearing whose BPF/BPFO/… and shaft rate are used (default the first).

    Returns
    -------
    freqs : cmsim.frequencies.RigFrequencies
        Characteristic frequencies of the run's rig, Hz.
    families : dict of str to float
        :meth:`~cmsim.frequencies.RigFrequencies.families` of ``bearing``, Hz.
    """
    rig, op = run.rig, run.operating_point
    if rig is None or op is None:
        raise ParameterError("the run's meta lacks 'rig' or 'operating_point' (not written by "
                             "cmsim.dynamics.simulate?)")
    freqs = rig_frequencies(rig, op)
    return freqs, freqs.families(bearing)


@dataclass(frozen=True, eq=False)
class RunSpectrum:
    """Spectrum of one run signal and its labelled peaks.

    Attributes
    ----------
    signal : str
        Signal name.
    kind : str
        ``"amplitude"``, ``"envelope"`` or ``"order"``.
    freq_hz : numpy.ndarray, shape (n_bins,)
        Bin frequencies, Hz (for ``kind="order"``: orders × nominal shaft rate).
    amplitude : numpy.ndarray, shape (n_bins,)
        Amplitude per bin, unit :attr:`unit`.
    resolution_hz : float
        Bin spacing, Hz.
    unit : str
        Unit of the signal.
    families : dict of str to float
        Base frequencies used for the labels, Hz.
    bearing : str or None
        Bearing whose frequencies were used (None: a record without geometry).
    peaks : pandas.DataFrame
        :func:`~cmsim.spectra.labels.label_peaks` rows below ``max_hz``, largest first;
        ``frequency_hz`` always in Hz (plus ``order`` for ``kind="order"``).
    band_hz : tuple of float or None
        Demodulation band of an envelope spectrum, Hz.
    max_hz : float
        Upper frequency of the listed peaks, Hz.
    """

    signal: str
    kind: str
    freq_hz: np.ndarray
    amplitude: np.ndarray
    resolution_hz: float
    unit: str
    families: dict
    bearing: str
    peaks: object
    band_hz: tuple | None = None
    max_hz: float = math.inf
    extra: dict = field(default_factory=dict)

    def peak_records(self):
        """Peaks as a list of dicts (JSON-ready: ``frequency_hz``, ``amplitude``, ``label``,
        ``family``, ``db_re_carrier``, ``k``, ``m``, ``n``, ``snr_db``)."""
        cols = ["frequency_hz", "amplitude", "label", "family", "db_re_carrier", "k", "m", "n",
                "snr_db"] + (["order"] if "order" in self.peaks else [])
        out = []
        for row in self.peaks[cols].itertuples(index=False):
            rec = {}
            for c, v in zip(cols, row):
                if c in ("k", "m", "n"):
                    rec[c] = int(v)
                elif c in ("label", "family"):
                    rec[c] = str(v)
                else:
                    v = float(v)
                    rec[c] = v if math.isfinite(v) else None
            out.append(rec)
        return out


def run_spectrum(run, signal, kind="amplitude", *, band_hz=None, max_hz=None,
                 resolution_hz=None, bearing=None, max_peaks=20, threshold_db=15.0,
                 max_sideband=3, relative_tolerance=None):
    """Spectrum of ``run[signal]`` with its peaks named k·GMF ± m·BPF ± n·fr.

    Parameters
    ----------
    run : cmsim.run.Run
        Simulated run (meta must hold ``rig`` and ``operating_point``).
    signal : str
        Signal name, one of ``run.names``.
    kind : {"amplitude", "envelope", "order"}
        Amplitude spectrum of the record, envelope spectrum (band ``band_hz``, default the
        best of :func:`~cmsim.spectra.kurtogram.residual_kurtogram`, as the band rule reads
        it), or order spectrum (the shaft angle from the run's ``tacho`` when it has one, so
        a run-up's lines stay at their orders; else from the nominal shaft speed).
    band_hz : tuple of float, optional
        Demodulation band (lo, hi) in Hz, 0 <= lo < hi <= fs/2; only for ``kind="envelope"``.
    max_hz : float, optional
        Peaks above this frequency are not listed, Hz (> 0); default fs/2.
    resolution_hz : float, optional
        Largest acceptable bin spacing, Hz (> 0); a shorter record raises
        :class:`~cmsim.errors.ParameterError` saying the length it needs.
    bearing : str, optional
        Bearing for the BPF family; default the bearing named in ``signal`` or the first.
    max_peaks : int
        Number of largest peaks listed (1-10000).
    threshold_db : float
        Least height of a peak above the noise floor, dB.
    max_sideband : int
        Largest |m|, |n| of a label (0-20).
    relative_tolerance : float, optional
        Uncertainty of the speed the labels scale with
        (:func:`~cmsim.spectra.labels.label_peaks`); default the run's
        ``speed_uncertainty`` (a measured record's), else 0 (a simulated run's lines stand
        where its speed puts them). The bearing terms of a label also take the run's
        ``bearing_slip``.

    Returns
    -------
    RunSpectrum
        Of a measured record without geometry (no ``rig`` in its meta), the peaks are named
        by the shaft rate alone (``bearing`` None).
    """
    if not isinstance(signal, str) or signal not in run.signals:
        raise ParameterError(f"signal must be one of the run's signals {run.names}, "
                             f"got {signal!r}")
    check_choice("kind", kind, PEAK_KINDS)
    max_peaks = positive_int("max_peaks", max_peaks, lo=1, hi=10000)
    fs = run.fs_hz
    if band_hz is not None and kind != "envelope":
        raise ParameterError(f"band_hz applies to kind='envelope' only (kind={kind!r})")
    f_max = 0.5 * fs if max_hz is None else check_range("max_hz", max_hz, 0.0, 0.5 * fs,
                                                        lo_open=True, unit="Hz")
    if run.rig is None and run.operating_point is not None:   # no geometry: the shaft only
        brg, fam = None, {"fr": run.operating_point.shaft_hz}
    else:
        freqs, _ = run_families(run)
        bearing_names = freqs.bearing_names
        brg = signal_bearing(signal, bearing_names) if bearing is None else bearing
        if brg not in bearing_names:
            raise ParameterError(f"bearing must be one of {list(bearing_names)}, got "
                                 f"{bearing!r}")
        fam = freqs.families(brg)
        if run.meta.get("bearings_documented") is False:     # an assumed bearing names nothing
            brg, fam = None, {k: v for k, v in fam.items() if k not in BEARING_FAMILY_KEYS}
    rel = (float(run.meta.get("speed_uncertainty") or 0.0) if relative_tolerance is None
           else relative_tolerance)
    slip = float(run.meta.get("bearing_slip") or 0.0)
    x = np.asarray(run[signal], dtype=float)
    res = None if resolution_hz is None else check_range("resolution_hz", resolution_hz, 0.0,
                                                         lo_open=True, unit="Hz")
    detrend = "linear" if signal.startswith("theta") else "constant"
    band_used, extra = None, {}
    if kind == "amplitude":
        spec = amplitude_spectrum(x, fs, detrend=detrend, resolution_hz=res)
        f, a, df_hz = spec.freq_hz, spec.amplitude, spec.resolution_hz
        lab_f, lab_fam, scale = f, fam, 1.0
    elif kind == "envelope":
        if band_hz is None:
            kg = residual_kurtogram(x, fs)
            band_used = tuple(float(b) for b in kg.band_hz)
            extra["kurtosis"] = float(kg.kurtosis_max)
        else:
            band_used = check_band("band_hz", band_hz, fs)
        spec = envelope_spectrum(x, fs, band_used, resolution_hz=res)
        f, a, df_hz = spec.freq_hz, spec.amplitude, spec.resolution_hz
        lab_f, lab_fam, scale = f, fam, 1.0
    else:
        fr = fam["fr"]
        # the shaft angle from the run's own tacho where it has one (a run-up's lines stay at
        # their orders), else from the nominal speed
        tacho = run.signals.get("tacho")
        if tacho is not None:
            osp = order_spectrum(x, fs, tacho=np.asarray(tacho, dtype=float))
            extra["angle_from"] = "tacho"
        else:
            osp = order_spectrum(x, fs, speed_rpm=60.0 * fr)
            extra["angle_from"] = "nominal speed"
        df_hz = osp.resolution_order * fr
        if res is not None and df_hz > res * (1.0 + 1e-12):
            need = math.ceil(fr / res)
            raise ParameterError(
                f"record too short for resolution_hz={res:g} Hz: an order spectrum at "
                f"{fr:g} Hz shaft rate needs at least {need} whole revolutions "
                f"({need / fr:g} s), got {osp.n_revolutions} ({len(x) / fs:g} s)")
        lab_f, a = osp.order, osp.amplitude
        f = lab_f * fr
        lab_fam = {k: v / fr for k, v in fam.items()}
        scale = fr
        extra["n_revolutions"] = int(osp.n_revolutions)
    peaks = label_peaks(lab_f, a, lab_fam, threshold_db=threshold_db, max_sideband=max_sideband,
                        relative_tolerance=rel, slip_tolerance=slip)
    if kind == "order":
        peaks.insert(1, "order", peaks["frequency_hz"].to_numpy())
        peaks["frequency_hz"] = peaks["order"] * scale
    peaks = peaks[peaks["frequency_hz"] <= f_max]
    peaks = peaks.sort_values("amplitude", ascending=False, kind="stable").head(max_peaks)
    return RunSpectrum(signal=signal, kind=kind, freq_hz=np.asarray(f), amplitude=np.asarray(a),
                       resolution_hz=float(df_hz),
                       unit=signal_unit(signal) or (run.meta.get("units") or {}).get(signal, ""),
                       families=dict(fam),
                       bearing=brg, peaks=peaks.reset_index(drop=True), band_hz=band_used,
                       max_hz=float(f_max), extra=extra)

