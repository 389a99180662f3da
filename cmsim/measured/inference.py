"""What a record's metadata lacks, inferred from its signal (and reported as inferred).

* **Shaft speed** — :func:`estimate_shaft_hz`: the input-shaft rate whose comb of lines
  (shaft harmonics; with gears also the output shaft and the first mesh harmonics) stands
  highest over the spectrum's median level. A documented speed is refined within
  ±:data:`SPEED_SEARCH_FRACTION` when the comb is clear (:data:`MIN_COMB_DB`) and its
  interpolated rate lies in that range, more than :data:`MIN_SPEED_CHANGE` away
  (:func:`refine_speed`); an undocumented one is searched
  between 5 Hz and min(100 Hz, fs/40), and the comb found is moved to its true fundamental
  by the lines between its own (:func:`cmsim.measured.consistency.family_ratio`: the best
  comb of a record whose 2nd shaft harmonic and mains lines stand high is at 2×).
* **Sample rate** (``fs_hz: null``, e.g. the SpectraQuest gearbox) — one rule,
  :func:`infer_sample_rate`: the mesh comb of the documented tooth counts is found in
  cycles per sample, and the documented input-shaft speed turns it into Hz. A prose
  ``fs_note`` in the metadata is only a cross-check (:func:`sample_rate_from_note`): a
  disagreement of more than :data:`NOTE_AGREEMENT` is reported; the note is used only when
  the signal cannot say (no tooth counts or no speed), and then reported as unverified.

Spectra come from :func:`cmsim.measured.comb_ratio.log_spectrum` (Hann window).
"""

from __future__ import annotations

import math
import re

import numpy as np

from cmsim.measured.comb_ratio import (COMB_HARMONICS, COMB_TOLERANCE, log_spectrum,
                                      shaft_comb_db)
from cmsim.measured.consistency import lowest_fundamental
from cmsim.measured.stated import NOMINAL_SPEED_UNCERTAINTY

__all__ = ["estimate_shaft_hz", "refine_speed", "infer_sample_rate", "sample_rate_from_note",
           "speed_comb_doubt", "SPEED_SEARCH_FRACTION", "MIN_COMB_DB", "MIN_SPEED_CHANGE",
           "NOTE_AGREEMENT", "DOUBT_RATIOS", "DOUBT_COMB_DB", "DOUBT_MARGIN_DB"]

#: Half-width of the search around a documented speed, relative (a stored nominal speed and
#: an induction motor's slip under load differ by a few per cent at most: the uncertainty of
#: a nominal speed, :data:`cmsim.measured.stated.NOMINAL_SPEED_UNCERTAINTY`).
SPEED_SEARCH_FRACTION = NOMINAL_SPEED_UNCERTAINTY

#: Least comb prominence (mean line level over the spectrum's median), dB, for a refined
#: speed to replace the documented one.
MIN_COMB_DB = 10.0

#: Most points of the shaft-rate grid :func:`estimate_shaft_hz` scores (vectorised).
MAX_GRID_POINTS = 2_000_000

#: Least relative change for a refined speed to replace the documented one.
MIN_SPEED_CHANGE = 2e-3

#: Largest relative disagreement between an inferred sample rate and a metadata note's value
#: that passes without a warning.
NOTE_AGREEMENT = 0.02


#: Ratios to a stated shaft rate over which :func:`speed_comb_doubt` looks for the shaft's
#: comb (a factor 2ᵏ is :mod:`cmsim.measured.consistency`'s, the speed's own uncertainty
#: :func:`refine_speed`'s), and the grid's relative step.
DOUBT_RATIOS = (0.5, 2.0)
DOUBT_STEP = COMB_TOLERANCE

#: Combs within this of the highest found are as good: the lowest is named (a comb at twice
#: the shaft's rate holds its even harmonics, and an outer race's comb at 1.8 × CWRU's
#: shaft, its 2 × BPFO, stands 2 dB over the shaft's own; a comb at half has its odd lines
#: missing, 15-20 dB down).
DOUBT_TIE_DB = 3.0

#: A comb found elsewhere doubts the stated speed when it stands this high over its floor
#: (:func:`~cmsim.measured.comb_ratio.shaft_comb_db`) and this much over the stated speed's
#: comb. Measured on the shared records and on copies with a wrong speed or rate: honest,
#: the best comb of the range stands at most 4.5 dB over the stated one (MFPT, whose shaft
#: comb is weak: 8-17 dB); stated 5-78 % off or at a wrong rate (12.8, 10.24, 8 kHz for 12
#: kHz), 22-35 dB (CWRU's comb: 29-40 dB).
DOUBT_COMB_DB = 25.0
DOUBT_MARGIN_DB = 15.0


def speed_comb_doubt(x, fs_hz, speed_rpm, *, uncertainty=0.0, teeth=None, where="",
                     fs_source="fs_hz", speed_source="the speed"):
    """The warning that a record's shaft comb stands at another speed than the stated one,
    or None.

    A speed (or a sample rate) stated a few per cent to a factor of two off, not a factor
    2ᵏ, puts every line the rig makes off its window: the families' verdicts
    (:func:`~cmsim.measured.consistency.check_rate_and_speed`) then find one of the many
    families by chance, and the record was compared at the wrong speed in silence. The
    shaft's own comb, read on narrow windows, is searched over :data:`DOUBT_RATIOS` of the
    stated rate (the speed's uncertainty, the factors 2ᵏ and a gear rig's other shaft left
    out); a comb standing :data:`DOUBT_COMB_DB` high and :data:`DOUBT_MARGIN_DB` over the
    stated one's is warned (not refused: another shaft, a belt's, may turn there).

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        The compared channel.
    fs_hz : float
        Sample rate, Hz.
    speed_rpm : float
        The speed the record is compared at, rpm.
    uncertainty : float
        Its relative uncertainty.
    teeth : tuple of int, optional
        (Z1, Z2) of a gear rig.
    where, fs_source, speed_source : str
        The record and where its rate and speed came from, for the message.

    Returns
    -------
    str or None
    """
    freq, log_amp = log_spectrum(x, fs_hz)
    f0 = float(speed_rpm) / 60.0
    stated = shaft_comb_db(freq, log_amp, f0, max(uncertainty, COMB_TOLERANCE))
    if stated >= DOUBT_COMB_DB:
        return None
    lo, hi = DOUBT_RATIOS
    ratios = np.exp(np.arange(math.log(lo), math.log(hi), DOUBT_STEP))
    near = [1.0, 0.5, 2.0] + ([teeth[0] / teeth[1], teeth[1] / teeth[0]] if teeth else [])
    keep = np.ones(ratios.size, dtype=bool)
    for r in near:
        keep &= np.abs(ratios / r - 1.0) > max(uncertainty, COMB_TOLERANCE) + 0.01
    ratios = ratios[keep]
    combs = np.array([shaft_comb_db(freq, log_amp, r * f0) for r in ratios])
    if not np.any(combs == combs):
        return None
    best = float(np.nanmax(combs))
    if not (best >= DOUBT_COMB_DB and best - (stated if stated == stated else 0.0)
            >= DOUBT_MARGIN_DB):
        return None
    good = np.flatnonzero(combs >= best - DOUBT_TIE_DB)
    i = int(good[0])                              # ratios rise: the lowest
    best, rho = float(combs[i]), float(ratios[i])
    return (f"record {where}: the shaft's comb stands at {rho * speed_rpm:.0f} rpm ({best:.0f} "
            f"dB over its floor, its first {COMB_HARMONICS} harmonics), not at {speed_source} "
            f"{speed_rpm:g} rpm ({stated:.0f} dB): the speed or the sample rate stated may be "
            f"wrong ({rho * speed_rpm:.0f} rpm, or {fs_source} {fs_hz / rho:.6g} Hz, would "
            f"put it there); if another shaft turns at that speed, they stand")


def estimate_shaft_hz(x, fs_hz, *, lo_hz, hi_hz, teeth=None, n_harmonics=4):
    """Input-shaft rate that best explains the spectrum's comb of shaft harmonics.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, any unit.
    fs_hz : float
        Sample rate, Hz (1.0 gives the rate in cycles per sample).
    lo_hz, hi_hz : float
        Search range of the shaft rate, Hz.
    teeth : tuple of int, optional
        (Z1, Z2): the mesh comb k·Z1·f (k = 1..3) and the output shaft f·Z1/Z2 are added.
    n_harmonics : int
        Shaft harmonics in the comb (without ``teeth``).

    Returns
    -------
    (float, float)
        Shaft rate, Hz, and the comb score (mean prominence of its lines over the median
        spectrum level, dB).
    """
    freq, logamp = log_spectrum(x, fs_hz)
    df = freq[1]
    floor = np.median(logamp[1:])
    mults = [float(m) for m in range(1, n_harmonics + 1)]
    if teeth is not None:
        z1, z2 = teeth
        mults = [1.0, 2.0, z1 / z2] + [k * z1 for k in (1, 2, 3)]
    # a grid fine enough that its highest line (the third mesh harmonic, 90 times the shaft
    # rate of a 30-tooth pinion) moves a quarter bin from one point to the next: coarser,
    # the mesh lines fell between the points and the comb was read 0.2 % off
    n_grid = int(min(MAX_GRID_POINTS, max(200, math.log(hi_hz / lo_hz)
                                         * 4.0 * max(mults) * hi_hz / df)))
    grid = np.geomspace(lo_hz, hi_hz, n_grid)
    # each line's level: the highest of the three bins around it
    near = logamp.copy()
    near[1:-1] = np.maximum(np.maximum(logamp[:-2], logamp[1:-1]), logamp[2:])
    total = np.zeros(grid.size)
    count = np.zeros(grid.size)
    for m in mults:
        fm = m * grid
        ok = (fm < fs_hz / 2) & (fm >= 2 * df)
        k = np.minimum(np.rint(fm / df).astype(np.int64), near.size - 2)
        total += np.where(ok, 20 * (near[np.maximum(k, 1)] - floor), 0.0)
        count += ok
    score = np.where(count > 0, total / np.maximum(count, 1), -np.inf)
    i = int(np.argmax(score))
    best = (float(score[i]), float(grid[i]))
    return _refine(freq, logamp, best[1], mults, fs_hz), float(best[0])


def _refine(freq, logamp, f, mults, fs_hz):
    """Shaft rate from the interpolated peaks of its comb lines (amplitude-weighted)."""
    df = freq[1]
    num = den = 0.0
    for m in mults:
        k = int(round(m * f / df))
        if m * f >= fs_hz / 2 or k < 2 or k + 3 >= logamp.size:
            continue
        j = k - 2 + int(np.argmax(logamp[k - 2:k + 3]))
        a, b, c = logamp[j - 1], logamp[j], logamp[j + 1]
        d = 0.5 * (a - c) / (a - 2 * b + c) if (a - 2 * b + c) < 0 else 0.0
        w = 10 ** b
        num += w * (j + d) * df / m
        den += w
    return float(num / den) if den > 0 else float(f)


def refine_speed(x, fs_hz, speed_rpm, teeth=None):
    """A documented speed, or the comb's within ±:data:`SPEED_SEARCH_FRACTION` when clear.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, any unit.
    fs_hz : float
        Sample rate, Hz.
    speed_rpm : float or None
        Documented input-shaft speed, rpm (None: searched between 5 Hz and
        min(100 Hz, fs/40)).
    teeth : tuple of int, optional
        (Z1, Z2) of a gear rig.

    Returns
    -------
    speed_rpm : float
        The speed to use, rpm.
    how : str or None
        How it was inferred, or None when the documented speed is kept.
    confirmed : bool
        Whether the shaft comb stands clear (:data:`MIN_COMB_DB`) at the speed returned: a
        documented speed it confirms within :data:`MIN_SPEED_CHANGE` is kept as the comb
        read it, and no coarser search moves it.
    """
    if speed_rpm is None:
        f, score = estimate_shaft_hz(x, fs_hz, lo_hz=5.0, hi_hz=min(100.0, fs_hz / 40),
                                     teeth=teeth)
        ratio = lowest_fundamental(*log_spectrum(x, fs_hz), f, 4, lo_hz=5.0)
        how = f"shaft-harmonic comb, {score:.1f} dB over the median level"
        if ratio != 1.0:       # the best comb was a harmonic of the shaft's
            f *= ratio
            how += (f"; its fundamental is 1/{1 / ratio:g} of the comb's best fit (its lines "
                    f"between stand as high)")
        return 60.0 * f, how, score > MIN_COMB_DB
    f0 = float(speed_rpm) / 60.0
    f, score = estimate_shaft_hz(x, fs_hz, lo_hz=(1 - SPEED_SEARCH_FRACTION) * f0,
                                 hi_hz=(1 + SPEED_SEARCH_FRACTION) * f0, teeth=teeth)
    clear = score > MIN_COMB_DB and abs(f / f0 - 1) <= SPEED_SEARCH_FRACTION
    if clear and abs(f / f0 - 1) > MIN_SPEED_CHANGE:
        return 60.0 * f, (f"refined from the documented {float(speed_rpm):g} rpm by the "
                          f"shaft-harmonic comb ({score:.1f} dB)"), True
    return float(speed_rpm), None, clear


def infer_sample_rate(x, shaft_hz, teeth):
    """Sample rate of a gear record with an undocumented rate: its mesh comb in cycles per
    sample, scaled by the documented input-shaft rate. The comb found is moved to its true
    fundamental by the lines between its own, as an undocumented speed is
    (:func:`~cmsim.measured.consistency.lowest_fundamental`): on a 5-s cut of a gearbox
    record the comb at twice the shaft rate (the 2nd mesh harmonic, the even shaft lines)
    can fit best, and the rate would come out half the true one.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal, any unit.
    shaft_hz : float
        Documented input-shaft rate, Hz.
    teeth : tuple of int
        (Z1, Z2).

    Returns
    -------
    fs_hz : float
        Sample rate, Hz.
    cycles_per_sample : float
        Input-shaft rate found in the signal, cycles per sample.
    score : float
        Comb prominence, dB over the median level.
    """
    lo = 2e-4
    nu, score = estimate_shaft_hz(x, 1.0, lo_hz=lo, hi_hz=0.45 / (3 * teeth[0]), teeth=teeth)
    nu *= lowest_fundamental(*log_spectrum(x, 1.0), nu, 4, lo_hz=lo)
    return shaft_hz / nu, nu, score


def sample_rate_from_note(note):
    """The ``fs ~= 12.97 kHz`` of a prose metadata note, Hz, or None.

    Parameters
    ----------
    note : str or None

    Returns
    -------
    float or None
    """
    m = re.search(r"fs\s*~?=\s*([0-9.]+)\s*kHz", str(note or ""))
    return 1e3 * float(m.group(1)) if m else None


def note_disagreement(fs_hz, note_hz):
    """Relative disagreement |fs/note − 1| (NaN without a note value).

    Parameters
    ----------
    fs_hz : float
        Inferred sample rate, Hz.
    note_hz : float or None
        The note's value, Hz.
    """
    return abs(fs_hz / note_hz - 1.0) if note_hz else math.nan
