"""Three honest baseline diagnostic algorithms: they read signals, fs, operating point and the
rig's characteristic frequencies only, never a label.

Each is a diagnostic function (:mod:`cmsim.diagnostics`) returning a
:class:`~cmsim.diagnostics.harness.Diagnosis` with a label and a score per class. Channels
read: the housing accelerometers (``accel_*``) when the record has them, else every signal
except a tacho and shaft angles (``tacho``, ``theta_*``); a class score is the largest over the
channels (and bearings / shafts).

1. :func:`envelope` — envelope analysis at the bearing defect frequencies, with the
   envelope-families extractor of :mod:`cmsim.features.envelope`. Per channel and bearing,
   the demodulation band is the band rule's (:func:`cmsim.features.lines.demodulation_band`)
   and each line of the families is read as its amplitude (the line rule at
   :data:`~cmsim.features.lines.SLIP_TOLERANCE`: real bearings slip by 1-2 %) over the
   median of the envelope spectrum around it. Class scores are the family scores (geometric
   mean of the ratios over the class's lines):

   * ``outer_race``: h·BPFO, h = 1, 2, 3;
   * ``inner_race``: BPFI, 2·BPFI, BPFI ± fr (fr: the rate of the bearing's shaft);
   * ``ball``: 2·BSF, 4·BSF, 2·BSF ± FTF (a ball defect hits both races, and enters and
     leaves the load zone with the cage);

   label = the class with the largest score when it exceeds :data:`ENVELOPE_THRESHOLD`
   (3: a bin of Gaussian noise reads about 1.5 times its local median), else ``healthy``;
   ``scores["healthy"]`` = − the largest fault score.
2. :func:`tsa` — time-synchronous average over each gear shaft (from the ``tacho`` channel,
   one pulse per input-shaft revolution, when present; else the nominal speed), then the
   *difference signal*: the average with the regular meshing components removed (shaft
   orders 1-2, every multiple of the tooth count Z and its ±1 sidebands, Stewart 1977), and
   FM4 = its kurtosis (3 for Gaussian noise). ``scores["gear"]`` = the largest FM4; label
   ``gear`` above :data:`TSA_THRESHOLD`. Unlike ``tsa_residual_kurtosis`` of
   :mod:`cmsim.features` (the kurtosis of what is *not* synchronous, which a bearing defect
   raises), this reads only what turns with a gear, so a bearing defect leaves it unchanged.
3. :func:`sideband` — sideband energy around the GMF harmonics: from
   :func:`cmsim.features.extract_features` (flat-top amplitude spectrum), the energy of the
   shaft-rate sidebands k·GMF ± n·fr (n = ±1, ±2, each shaft) over the energy of the GMF
   lines k = 1..6, in dB; label ``gear`` above :data:`SIDEBAND_THRESHOLD_DB`.

The gear baselines predict ``"gear"`` for any gear fault; their ``label_map`` attribute maps
the true labels of gear faults (:data:`GEAR_FAULTS`) to it, and the harness applies it. They
raise :class:`~cmsim.errors.ParameterError` on a rig without gears.

References
----------
.. [1] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", MSSP 25
   (2011) 485-520.
.. [2] R. M. Stewart, "Some useful data analysis techniques for gearbox diagnostics", ISVR
   report MHM/R/10/77 (1977) (FM4, difference signal).
.. [3] P. D. Samuel, D. J. Pines, "A review of vibration-based techniques for helicopter
   transmission diagnostics", J. Sound Vib. 282 (2005) 475-508.
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.diagnostics.diagnosis import HEALTHY, Diagnosis
from cmsim.errors import ParameterError
from cmsim.features import extract_features, statistics
from cmsim.features.envelope import (FAULT_FAMILIES, demodulated_spectrum, envelope_lines,
                                     family_scores, line_ratios)
from cmsim.spectra.order import tacho_pulse_times
from cmsim.spectra.tsa import time_synchronous_average

__all__ = ["envelope", "tsa", "sideband", "BASELINES", "GEAR_CLASS", "GEAR_FAULTS",
           "BEARING_CLASSES", "ENVELOPE_THRESHOLD", "TSA_THRESHOLD", "SIDEBAND_THRESHOLD_DB",
           "signal_channels", "envelope_scores"]

#: Classes of the envelope baseline.
BEARING_CLASSES = FAULT_FAMILIES
#: Class predicted by the gear baselines.
GEAR_CLASS = "gear"
#: Fault labels scored as :data:`GEAR_CLASS` by the gear baselines.
GEAR_FAULTS = ("tooth_crack", "tooth_spall", "tooth_breakage", "eccentricity", "profile_error")

#: Envelope line-to-local-median ratio above which a bearing fault is declared.
ENVELOPE_THRESHOLD = 3.0
#: FM4 above which a local gear fault is declared (3 for Gaussian noise; healthy simulated
#: gears read 3-8.5 at 10-30 N m, the measured SpectraQuest ones 3.3-3.6).
TSA_THRESHOLD = 10.0
#: Sideband-to-GMF energy ratio above which a gear fault is declared, dB.
SIDEBAND_THRESHOLD_DB = -20.0
#: Shaft orders removed from the average besides the mesh components (residual signal).
SHAFT_ORDERS_REMOVED = 2


def signal_channels(signals):
    """Names of the channels the baselines read: ``accel_*`` if any, else all but a tacho
    and shaft angles.

    Parameters
    ----------
    signals : dict of str to numpy.ndarray
        Channels of a record.
    """
    names = [k for k in signals if k.startswith("accel_")]
    if not names:
        names = [k for k in signals if k != "tacho" and not k.startswith("theta")]
    if not names:
        raise ParameterError("the record has no vibration channel", param="signals")
    return names


def _x(signals, name):
    x = np.asarray(signals[name], dtype=float)
    return x - x.mean()


# ---------------------------------------------------------------------- envelope
def envelope_scores(x, fs_hz, bf):
    """Per-class line-to-median scores of one channel for one bearing (see the module
    docstring) and the demodulation band.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, any unit.
    fs_hz : float
        Sampling rate, Hz.
    bf : cmsim.frequencies.BearingFrequencies

    Returns
    -------
    scores : dict of str to float
    band_hz : tuple of float
    """
    (freq, amp), band = demodulated_spectrum(x, fs_hz, [bf])
    lines = envelope_lines(bf)
    return family_scores(line_ratios(freq, amp, lines), lines), band


def envelope(signals, fs_hz, operating_point, frequencies):
    """Envelope analysis at the bearing defect frequencies (see the module docstring).

    Parameters
    ----------
    signals : dict of str to numpy.ndarray
        Channels of the record, each shape (n,).
    fs_hz : float
        Sampling rate, Hz.
    operating_point : cmsim.rig.OperatingPoint
        Not used beyond the frequencies (kept for the common signature).
    frequencies : cmsim.frequencies.RigFrequencies
        Characteristic frequencies; needs at least one bearing.

    Returns
    -------
    Diagnosis
        Label in ``healthy``, ``outer_race``, ``inner_race``, ``ball``; a score per class.
    """
    if not frequencies.bearings:
        raise ParameterError("envelope analysis needs the rig's bearing frequencies",
                             param="frequencies")
    best = {c: -math.inf for c in BEARING_CLASSES}
    seen = set()
    for name, bf in frequencies.bearings.items():
        key = (round(bf.bpfo_hz, 3), round(bf.bpfi_hz, 3), round(bf.bsf_hz, 3))
        if key in seen or bf.bpfo_hz <= 0:
            continue
        seen.add(key)
        for ch in signal_channels(signals):
            s, _ = envelope_scores(_x(signals, ch), fs_hz, bf)
            for c, v in s.items():
                if math.isfinite(v):
                    best[c] = max(best[c], v)
    top = max(best, key=best.get)
    worst = best[top]
    label = top if worst > ENVELOPE_THRESHOLD else HEALTHY
    return Diagnosis(label=label, scores={HEALTHY: -worst, **best})


# ---------------------------------------------------------------------- TSA / FM4
def _gear_shafts(frequencies):
    """[(shaft rate Hz, tooth count)] of the gear shafts."""
    if frequencies.gmf_hz is None:
        raise ParameterError("this baseline needs a rig with gears (a GMF)",
                             param="frequencies")
    out = [(frequencies.fr1_hz, int(round(frequencies.gmf_hz / frequencies.fr1_hz)))]
    f2 = frequencies.fr2_hz
    if f2 is not None and abs(f2 - frequencies.fr1_hz) > 1e-6 * frequencies.fr1_hz:
        out.append((f2, int(round(frequencies.gmf_hz / f2))))
    return out


def _speed(signals, fs_hz, shaft_hz, fr1_hz):
    """kwargs for the TSA: a speed trace from the tacho (input shaft, 1 pulse/rev) scaled to
    this shaft, else the nominal speed."""
    if "tacho" in signals:
        try:
            t = tacho_pulse_times(np.asarray(signals["tacho"], dtype=float), fs_hz)
        except ParameterError:
            t = np.empty(0)
        if t.size >= 3:
            rpm = 60.0 / np.diff(t) * (shaft_hz / fr1_hz)
            tm = 0.5 * (t[1:] + t[:-1])
            n = len(signals["tacho"])
            tt = np.concatenate(([0.0], tm, [n / fs_hz]))
            rr = np.concatenate(([rpm[0]], rpm, [rpm[-1]]))
            return {"speed_rpm": rr, "speed_time_s": tt}
    return {"speed_rpm": 60.0 * shaft_hz}


def tsa_difference(average, n_teeth):
    """Residual and difference signals of a synchronous average.

    Parameters
    ----------
    average : numpy.ndarray, shape (m,)
        One averaged revolution, unit of the signal.
    n_teeth : int
        Teeth of the gear on this shaft (the mesh is order ``n_teeth``).

    Returns
    -------
    residual : numpy.ndarray, shape (m,)
        Average without the mean, shaft orders 1-2 and the mesh harmonics.
    difference : numpy.ndarray, shape (m,)
        The residual without the first-order sidebands of the mesh harmonics either.
    """
    a = np.asarray(average, dtype=float)
    spec = np.fft.rfft(a)
    k = np.arange(spec.size)
    regular = (k <= SHAFT_ORDERS_REMOVED) | (k % n_teeth == 0)
    side = regular | (k % n_teeth == 1) | (k % n_teeth == n_teeth - 1)
    return (np.fft.irfft(np.where(regular, 0.0, spec), a.size),
            np.fft.irfft(np.where(side, 0.0, spec), a.size))


def tsa(signals, fs_hz, operating_point, frequencies):
    """TSA difference-signal kurtosis (FM4) for local gear faults (see the module docstring).

    Parameters
    ----------
    signals : dict of str to numpy.ndarray
        Channels of the record, each shape (n,); a ``tacho`` channel (1 pulse per input-shaft
        revolution) is used for the speed when present.
    fs_hz : float
        Sampling rate, Hz.
    operating_point : cmsim.rig.OperatingPoint
        Not used beyond the frequencies (kept for the common signature).
    frequencies : cmsim.frequencies.RigFrequencies
        Needs the GMF and shaft rates.

    Returns
    -------
    Diagnosis
        Label ``healthy`` or ``gear``; scores ``gear`` (FM4) and ``healthy`` (−FM4).
    """
    fm4 = -math.inf
    for shaft_hz, z in _gear_shafts(frequencies):
        speed = _speed(signals, fs_hz, shaft_hz, frequencies.fr1_hz)
        for ch in signal_channels(signals):
            avg = time_synchronous_average(_x(signals, ch), fs_hz, **speed)
            _, diff = tsa_difference(avg.average, z)
            k = statistics(diff)[1]
            if math.isfinite(k):
                fm4 = max(fm4, k)
    return Diagnosis(label=GEAR_CLASS if fm4 > TSA_THRESHOLD else HEALTHY,
                     scores={HEALTHY: -fm4, GEAR_CLASS: fm4})


# ---------------------------------------------------------------------- sidebands
def sideband_ratio_db(x, fs_hz, frequencies):
    """Shaft-rate sideband energy around the GMF harmonics over the GMF lines' energy, dB.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, any unit.
    fs_hz : float
        Sampling rate, Hz.
    frequencies : cmsim.frequencies.RigFrequencies
        With gears.

    Returns
    -------
    float
        10·log10(Σ sideband² / Σ GMF²) over the harmonics below fs/2 (NaN if none).
    """
    row = extract_features(x, fs_hz, frequencies, envelope=False)
    gmf = np.asarray(row.gmf_amp, dtype=float)
    keys = [k for k in row.sidebands if k.startswith("fr1_")]
    if frequencies.fr2_hz is not None and abs(frequencies.fr2_hz - frequencies.fr1_hz) > \
            1e-6 * frequencies.fr1_hz:
        keys += [k for k in row.sidebands if k.startswith("fr2_")]
    sb = np.array([row.sidebands[k] for k in keys], dtype=float)
    ok = np.isfinite(gmf) & np.all(np.isfinite(sb), axis=0)
    if not ok.any():
        return math.nan
    e_gmf = float(np.sum(gmf[ok] ** 2))
    e_sb = float(np.sum(sb[:, ok] ** 2))
    return 10.0 * math.log10(e_sb / e_gmf) if e_gmf > 0 and e_sb > 0 else math.nan


def sideband(signals, fs_hz, operating_point, frequencies):
    """Sideband energy around the GMF harmonics (see the module docstring).

    Parameters
    ----------
    signals : dict of str to numpy.ndarray
        Channels of the record, each shape (n,).
    fs_hz : float
        Sampling rate, Hz.
    operating_point : cmsim.rig.OperatingPoint
        Not used beyond the frequencies (kept for the common signature).
    frequencies : cmsim.frequencies.RigFrequencies
        Needs the GMF and shaft rates.

    Returns
    -------
    Diagnosis
        Label ``healthy`` or ``gear``; scores ``gear`` (dB) and ``healthy`` (− that).
    """
    _gear_shafts(frequencies)
    best = -math.inf
    for ch in signal_channels(signals):
        v = sideband_ratio_db(_x(signals, ch), fs_hz, frequencies)
        if math.isfinite(v):
            best = max(best, v)
    return Diagnosis(label=GEAR_CLASS if best > SIDEBAND_THRESHOLD_DB else HEALTHY,
                     scores={HEALTHY: -best, GEAR_CLASS: best})


_GEAR_MAP = {f: GEAR_CLASS for f in GEAR_FAULTS}
tsa.label_map = dict(_GEAR_MAP)
sideband.label_map = dict(_GEAR_MAP)

#: Built-in algorithms by name (``cmsim evaluate --algorithm envelope``).
BASELINES = {"envelope": envelope, "tsa": tsa, "sideband": sideband}
