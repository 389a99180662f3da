"""Shaft-rate sideband energies of the GMF harmonics, on a segment tracked on its own mesh.

Part of the relative (scale-free) extractor, :func:`cmsim.features.relative_features`:
:func:`mesh_tracked` resamples a segment at uniform mesh phase read from its strongest mesh
line (computed order tracking without a tacho), and :func:`sideband_energies` reads the
energy of the ±1 and of the ±2, ±3 shaft-rate sideband bands of each GMF harmonic over the
carrier's band. Bands, not bins: what the tracking leaves of a slow wobble stays inside them,
and the ratio of two nearby bands drops the transfer path's gain.

References
----------
.. [1] R. B. Randall, *Vibration-based Condition Monitoring*, Wiley 2011, §5.4 (sidebands,
   order tracking).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.ndimage import uniform_filter1d

from cmsim.spectra.amplitude import amplitude_spectrum

__all__ = ["sideband_energies", "mesh_tracked", "N_SIDEBAND_HARMONICS", "SIDEBAND_HALF_WIDTH",
           "MAX_SIDEBAND_ORDER", "TRACK_MAX_ORDER", "TRACK_MIN_DB"]

#: GMF harmonics whose shaft-rate sideband energies are read.
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


def sideband_energies(x, fs, freqs):
    """Shaft-rate sideband energy of each GMF harmonic over its carrier's, dB.

    The segment is first order-tracked on its own mesh (:func:`mesh_tracked`), so a slow
    speed wobble or a slightly wrong nominal speed does not smear the carriers into their
    sidebands. Then, for each gear shaft (rate f_r, Z = GMF/f_r teeth) and GMF harmonic
    k = 1..:data:`N_SIDEBAND_HARMONICS` with k·Z <= :data:`MAX_SIDEBAND_ORDER` and its third
    sideband below 0.45·fs (NaN otherwise): ``sb1_{fr1|fr2}_k{k}_db`` = energy in the bands
    k·GMF ± f_r over the energy in the band at k·GMF, and ``sb23_..._k{k}_db`` the same for
    ± 2 f_r and ± 3 f_r. Each band is k·GMF + n·f_r ± :data:`SIDEBAND_HALF_WIDTH`·f_r: a
    band, not a bin, so what the tracking leaves of a wobble stays in it, and the ratio of
    two nearby bands drops the transfer path's gain. Eccentricity and a slow load modulation
    raise the first sidebands; a local tooth fault spreads energy over many.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Segment, any unit, mean removed.
    fs : float
        Sample rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies
        Frequencies of the rig at the segment's nominal speed (with a GMF).

    Returns
    -------
    dict of str to float
        ``sb1_{fr1|fr2}_k{k}_db`` and ``sb23_{fr1|fr2}_k{k}_db``.
    """
    y, scale = mesh_tracked(x, fs, freqs)
    freq, amp = amplitude_spectrum(y, fs, window="hann")
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
            edges = np.searchsorted(freq, [fk + n * fr + d for n in range(-3, 4)
                                           for d in (-w, w)], side="left")
            e = {n: float(np.sum(power[edges[2 * i]:edges[2 * i + 1]]))   # bins in [lo, hi)
                 for i, n in enumerate(range(-3, 4))}
            c = e[0]
            out[f"sb1_{name}_k{k}_db"] = _db_power(e[-1] + e[1], c)
            out[f"sb23_{name}_k{k}_db"] = _db_power(e[-3] + e[-2] + e[2] + e[3], c)
    return out


def mesh_tracked(x, fs, freqs):
    """``x`` resampled at uniform mesh phase (computed order tracking without a tacho).

    The reference is the strongest GMF harmonic up to shaft order :data:`TRACK_MAX_ORDER`:
    demodulated to zero frequency and averaged over one revolution of each shaft, its phase
    gives the mesh angle; the average nulls the shaft-rate sidebands, so only wobbles slower
    than about f_r/2 are tracked out and the modulations under study stay in the signal.
    Without a line :data:`TRACK_MIN_DB` above its neighbourhood the segment is returned as
    it is. (:mod:`cmsim.spectra.order` resamples from a known speed or a tacho; here the
    angle is read from the signal itself.)

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Segment, any unit.
    fs : float
        Sample rate, Hz.
    freqs : cmsim.frequencies.RigFrequencies
        Frequencies of the rig at the segment's nominal speed (with a GMF).

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
        fk, sk = f, spec
        if fc - 3.0 * fr > f[1]:
            # only the bins around fc take part: cut them (a bin's margin) from the sorted
            # positive half, then the same tests as on the whole spectrum
            lo_hi = [fc - 3.0 * fr - f[1], fc + 3.0 * fr + f[1]]
            i0, i1 = np.searchsorted(f[:(n + 1) // 2], lo_hi)
            fk, sk = f[i0:i1], spec[i0:i1]
        band = np.abs(fk - fc) < 0.5 * fr
        near = (np.abs(fk - fc) < 3.0 * fr) & ~band
        if np.any(band) and np.any(near):
            p = np.abs(sk[band]) ** 2
            snr = 10 * math.log10(max(float(p.max()), 1e-300)
                                  / max(float(np.median(np.abs(sk[near]) ** 2)), 1e-300))
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
