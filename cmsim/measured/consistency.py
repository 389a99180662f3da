"""A record's stated sample rate and speed checked against its own lines.

A sample rate wrong by a factor k scales every line of the spectrum by k; a speed wrong by k
moves every predicted line by 1/k. Either way the lines the rig makes — shaft harmonics, the
bearing defect families — stand at a ratio ρ ≠ 1 of where the metadata puts them, while at
ρ = 1 they all fit. :func:`check_rate_and_speed` finds ρ from the signal, family by family,
and refuses a record whose clearest family says ρ ≠ 1.

For one family (fundamental u = order × stated shaft rate, harmonics k·u) the ratio is
decided by the lines that only one of two neighbouring fundamentals predicts
(:func:`exclusive_contrast_db`), tested in this order:

* **the stated lines missing** — the stated comb predicts k·u for k not a multiple of m (the
  first two: u and 3u for m = 2) that a comb at m·u does not; if these stand
  :data:`MISSING_MARGIN_DB` below the lines at m·u and one of those stands clear
  (:data:`CLEAR_LINE_DB`), the fundamental is m·u (the stated rate is m times too low);
* **lines between the stated ones** — a comb at u/m also predicts j·u/m for j not a multiple
  of m (the first two: u/2 and 3u/2); if these stand clear and as high as the stated lines
  (within :data:`SUBCOMB_MARGIN_DB`), the fundamental is u/m (the stated rate is m times
  too high). The missing-line test goes first because a lower comb predicts the stated
  lines too: it must not be taken where they are absent.

Steps of 2 (:data:`STEPS`) are taken until neither test moves the fundamental (4 = 2·2),
within [1/:data:`LARGEST_FACTOR`, :data:`LARGEST_FACTOR`]. A family speaks only when its
lines stand :data:`CLEAR_LINE_DB` over the local floor at its ratio, and the one whose lines
stand highest decides (a healthy record's or a gearbox's shaft comb, a faulty bearing's
defect family in the envelope spectrum). A harmonic of the true fundamental always fits a
too-high stated rate too, which is why the lines *between* the stated ones decide, never
the stated lines alone. The mesh comb is not a family of its own (:func:`line_families`).

Known limit: a record whose every family is weak (below :data:`CLEAR_LINE_DB` at any ratio)
is not checked (:func:`check_rate_and_speed` returns None and the reader notes it).

Line prominence: the largest amplitude within ±:data:`LINE_TOLERANCE` of the line (the stated
speed may be nominal, bearings slip) over the median of the surrounding ±10 % (at least 25
bins) of a Hann amplitude spectrum; bearing families are read in the envelope spectrum of the
kurtogram's band.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cmsim.errors import ParameterError
from cmsim.spectra.amplitude import amplitude_spectrum
from cmsim.spectra.envelope import envelope_spectrum
from cmsim.spectra.kurtogram import kurtogram
from cmsim.spectra.lines import line_window

__all__ = ["LineFamily", "FamilyVerdict", "line_families", "line_prominence_db",
           "exclusive_contrast_db", "family_ratio", "lowest_fundamental", "family_verdicts",
           "check_rate_and_speed", "REFUSE_LINE_DB",
           "LINE_TOLERANCE", "SUBCOMB_MARGIN_DB", "MISSING_MARGIN_DB", "CLEAR_LINE_DB",
           "LARGEST_FACTOR", "STEPS"]

#: Half-width of the window a line is looked for in, relative to its frequency (a nominal
#: speed and an induction motor's slip differ by about 1 %; bearings slip 1-2 %).
LINE_TOLERANCE = 0.015

#: Bins beyond that tolerance on each side of the window (the one line rule,
#: :func:`cmsim.spectra.lines.line_window`, at 2 bins: a stated rate four times the true one
#: puts the low lines a few bins from 0, where the rule's 1.5 bins miss the Hann lobe's top).
LINE_WINDOW_BINS = 2.0

#: Lines between the stated ones standing within this of the stated lines, dB, make the
#: lower fundamental the true one.
SUBCOMB_MARGIN_DB = 5.0

#: Stated lines this far below the lines of a fundamental m times higher, dB, make that
#: fundamental the true one.
MISSING_MARGIN_DB = 5.5

#: Least prominence, dB over the local floor, of a family's lines for it to speak (the
#: largest of ~40 bins of pure noise stands about 7 dB over their median).
CLEAR_LINE_DB = 15.0

#: Least prominence, dB, of the deciding family for a record to be refused: between
#: CLEAR_LINE_DB and this a family at another ratio leaves the check undecided. A faulty
#: ball's cage-modulated comb put a simulated 0.4-s ball-fault record's BPFO family at
#: 1/2 × 17 dB over its floor (a valid record refused); the weakest doctored real record
#: that must be refused stands 20.3 dB (MFPT IR_vload4 at fs × 2).
REFUSE_LINE_DB = 20.0

#: Largest factor between the stated and the found fundamental that is tested.
LARGEST_FACTOR = 4

#: Factors a fundamental is moved by, one step at a time (4 = 2·2). A step of 3 is not
#: taken: a gear rig's 3rd shaft harmonic often stands well above the 1st and 2nd, which
#: reads as "the stated lines are missing" at 3×.
STEPS = (2,)


@dataclass(frozen=True)
class LineFamily:
    """A family of lines a rig makes: harmonics of ``order`` × the input-shaft rate.

    Attributes
    ----------
    name : str
        ``"shaft"`` or ``"<bearing> BPFO"`` / ``"<bearing> BPFI"``.
    order : float
        Fundamental as a multiple of the input-shaft rate.
    harmonics : int
        Harmonics read (1..harmonics).
    envelope : bool
        Read in the envelope spectrum (bearing defects) instead of the amplitude spectrum.
    """

    name: str
    order: float
    harmonics: int
    envelope: bool = False


@dataclass(frozen=True)
class FamilyVerdict:
    """Where one family's lines stand relative to the stated ones.

    Attributes
    ----------
    family : LineFamily
    ratio : float
        Found fundamental / stated fundamental (1 when they agree).
    level_db : float
        Mean prominence of the family's lines at the found fundamental, dB over the floor.
    """

    family: LineFamily
    ratio: float
    level_db: float


def line_families(frequencies):
    """The families of a rig's lines, from its characteristic frequencies at 1 Hz.

    Parameters
    ----------
    frequencies : cmsim.frequencies.RigFrequencies
        At an input-shaft rate of 1 Hz (so every frequency is an order).

    Returns
    -------
    list of LineFamily
        The shaft comb (4 harmonics) and BPFO and BPFI (2 each, envelope) of every bearing.
        The mesh comb is not a family of its own: its lines are shaft orders (Z1·k), so the
        lines between them are shaft harmonics too and cannot tell a ratio; a gear rig's
        shaft comb (strong, with the mesh's modulation) decides for it.
    """
    out = [LineFamily("shaft", 1.0, 4)]
    for name, b in (frequencies.bearings or {}).items():
        out.append(LineFamily(f"{name} BPFO", float(b.bpfo_hz) / frequencies.fr1_hz, 2, True))
        out.append(LineFamily(f"{name} BPFI", float(b.bpfi_hz) / frequencies.fr1_hz, 2, True))
    return out


def line_prominence_db(freq, log_amp, f_hz):
    """Prominence of the line nearest ``f_hz``: the largest bin within ±:data:`LINE_TOLERANCE`
    ± :data:`LINE_WINDOW_BINS` (:func:`cmsim.spectra.lines.line_window`) over the median of
    its ±10 % (>= 25 bins), dB; NaN outside the spectrum.

    Parameters
    ----------
    freq : numpy.ndarray, shape (n,)
        Bin frequencies, Hz (uniform from 0).
    log_amp : numpy.ndarray, shape (n,)
        log10 of the amplitude.
    f_hz : float
        Line frequency, Hz.
    """
    df = freq[1]
    sel = line_window(freq, f_hz, LINE_TOLERANCE, LINE_WINDOW_BINS)
    idx = np.flatnonzero(sel) if sel is not None else np.empty(0, int)
    if idx.size == 0 or idx[0] < 2 or idx[-1] >= log_amp.size - 1:
        return float("nan")
    j = int(idx[0] + np.argmax(log_amp[idx]))
    w = max(25, int(round(0.1 * f_hz / df)))
    return float(20.0 * (log_amp[j] - np.median(log_amp[max(j - w, 1):j + w + 1])))


def _mean(values):
    v = [x for x in values if x == x]
    return float(np.mean(v)) if v else float("nan")


def exclusive_contrast_db(freq, log_amp, low_hz, m, harmonics, n_exclusive=2):
    """Lines a comb at ``low_hz`` predicts and one at ``m·low_hz`` does not, against the
    lines of the higher comb.

    Parameters
    ----------
    freq, log_amp : numpy.ndarray, shape (n,)
        Spectrum (:func:`line_prominence_db`).
    low_hz : float
        The lower fundamental, Hz.
    m : int
        Factor to the higher fundamental (2 or 3).
    harmonics : int
        Harmonics of the higher comb read.
    n_exclusive : int
        Exclusive lines read (the first ones).

    Returns
    -------
    exclusive_db : float
        Mean prominence of the first exclusive lines j·low (j not a multiple of m), dB.
    higher_db : float
        Mean prominence of the higher comb's lines k·m·low, dB.
    higher_peak_db : float
        Prominence of the higher comb's strongest line, dB.
    """
    exclusive = [line_prominence_db(freq, log_amp, j * low_hz)
                 for j in range(1, m * harmonics) if j % m][:n_exclusive]
    higher = [line_prominence_db(freq, log_amp, k * m * low_hz)
              for k in range(1, harmonics + 1)]
    peak = max((h for h in higher if h == h), default=float("nan"))
    return _mean(exclusive), _mean(higher), peak


def _lower_fits(exclusive_db, higher_db, higher_peak_db):
    """The lower fundamental's own line stands clear and as high as the higher comb: the
    lower fundamental is the true one."""
    return exclusive_db >= CLEAR_LINE_DB and exclusive_db - higher_db > -SUBCOMB_MARGIN_DB


def _higher_fits(exclusive_db, higher_db, higher_peak_db):
    """The higher comb has a clear line and the lower one's own lines are missing: the
    higher fundamental is the true one."""
    return higher_peak_db >= CLEAR_LINE_DB and exclusive_db - higher_db < -MISSING_MARGIN_DB


def family_ratio(freq, log_amp, stated_hz, harmonics):
    """Found / stated fundamental of one family, and its lines' level there.

    Parameters
    ----------
    freq, log_amp : numpy.ndarray, shape (n,)
        Spectrum (:func:`line_prominence_db`).
    stated_hz : float
        Fundamental the metadata predicts, Hz.
    harmonics : int
        Harmonics read.

    Returns
    -------
    (float, float)
        Ratio (a power of 2 within [1/4, 4], or 1) and mean prominence of the
        lines at the found fundamental, dB.
    """
    ratio = 1.0
    moved = True
    while moved:
        moved = False
        for m in STEPS:            # missing lines first: a lower comb predicts them too
            if ratio >= 1.0 and ratio * m <= LARGEST_FACTOR and _higher_fits(
                    *exclusive_contrast_db(freq, log_amp, stated_hz * ratio, m, harmonics)):
                ratio *= m
                moved = True
            elif ratio <= 1.0 and ratio / m >= 1.0 / LARGEST_FACTOR and _lower_fits(
                    *exclusive_contrast_db(freq, log_amp, stated_hz * ratio / m, m, harmonics)):
                ratio /= m
                moved = True
    level = _mean(line_prominence_db(freq, log_amp, k * stated_hz * ratio)
                  for k in range(1, harmonics + 1))
    return ratio, level


def lowest_fundamental(freq, log_amp, f_hz, harmonics, *, lo_hz):
    """The ratio to the lowest fundamental whose comb explains a comb found at ``f_hz``: the
    best-fitting comb of a spectrum is often at a harmonic of the true fundamental (its
    even or every third line standing highest), never below it.

    Parameters
    ----------
    freq, log_amp : numpy.ndarray, shape (n,)
        Spectrum (:func:`line_prominence_db`).
    f_hz : float
        Fundamental of the comb found, Hz.
    harmonics : int
        Harmonics read.
    lo_hz : float
        Lowest fundamental considered, Hz.

    Returns
    -------
    float
        1, or 1/m for a product m of 2s and 3s (``f_hz`` × ratio >= ``lo_hz``).
    """
    ratio = 1.0
    moved = True
    while moved:
        moved = False
        for m in (2, 3):
            low = f_hz * ratio / m
            if low >= lo_hz and _lower_fits(*exclusive_contrast_db(freq, log_amp, low, m,
                                                                   harmonics)):
                ratio /= m
                moved = True
                break
    return ratio


def _log_spectrum(spectrum):
    freq, amp = spectrum
    return freq, np.log10(np.maximum(amp, 1e-300))


def _envelope_log_spectrum(x, fs_hz, highest_hz):
    """Envelope spectrum of the kurtogram's band (the whole band when none fits)."""
    band = None
    for top in (LARGEST_FACTOR * highest_hz, highest_hz):   # pass the lines at every ratio
        try:
            band = kurtogram(x, fs_hz, max_fault_hz=top).band_hz
            break
        except ParameterError:
            continue
    return _log_spectrum(envelope_spectrum(x, fs_hz, band, window="hann"))


def family_verdicts(x, fs_hz, shaft_hz, frequencies):
    """Every family's ratio and level (see the module docstring).

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        The compared channel, any unit.
    fs_hz : float
        Stated sample rate, Hz.
    shaft_hz : float
        Stated input-shaft rate, Hz.
    frequencies : cmsim.frequencies.RigFrequencies
        The rig's characteristic frequencies at 1 Hz (:func:`line_families`).

    Returns
    -------
    list of FamilyVerdict
    """
    families = line_families(frequencies)
    raw = _log_spectrum(amplitude_spectrum(x, fs_hz, window="hann"))
    env = None
    if any(f.envelope for f in families):
        env = _envelope_log_spectrum(x, fs_hz, max(f.order for f in families if f.envelope)
                                     * shaft_hz)
    out = []
    for f in families:
        freq, log_amp = env if f.envelope else raw
        ratio, level = family_ratio(freq, log_amp, f.order * shaft_hz, f.harmonics)
        out.append(FamilyVerdict(f, ratio, level))
    return out


def check_rate_and_speed(x, fs_hz, speed_rpm, frequencies, *, where, fs_source="fs_hz",
                         speed_source="shaft_speed_rpm"):
    """Refuse a record whose lines stand at a ratio ≠ 1 of where its sample rate and speed
    put them.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        The compared channel.
    fs_hz : float
        Stated (or header) sample rate, Hz.
    speed_rpm : float
        Stated input-shaft speed, rpm.
    frequencies : cmsim.frequencies.RigFrequencies
        The rig's characteristic frequencies at an input-shaft rate of 1 Hz.
    where : str
        The record, for the message.
    fs_source : str
        Where the sample rate came from (``"fs_hz"``, ``"the WAV header"``).
    speed_source : str
        Where the speed came from (``"shaft_speed_rpm"``, ``"speed_rpm"`` of a command
        line, ``"the file"``).

    Returns
    -------
    FamilyVerdict or None
        The deciding family (ratio 1), or None when no family's lines stand clear (nothing
        to check against) or the clearest, at another ratio, stands under
        :data:`REFUSE_LINE_DB` or is a bearing family no other family agrees with
        (undecided): the harmonics of a strong defect family, on a bearing the metadata may
        not even name, can fall on another family's at a ratio 2^k (an outer race's 6th
        BPFO harmonic lies within 1 % of 4 × BPFI on a 6205; the independent angle-domain
        generator's valid records read BPFI at 4 ×), while a wrong rate or speed moves the
        shaft comb too.

    Raises
    ------
    ParameterError
        The deciding family's lines stand at a ratio ρ ≠ 1: the sample rate is ρ times too
        high or the speed ρ times too low (the message gives both corrections).
    """
    verdicts = [v for v in family_verdicts(x, fs_hz, speed_rpm / 60.0, frequencies)
                if v.level_db >= CLEAR_LINE_DB]
    if not verdicts:
        return None
    best = max(verdicts, key=lambda v: v.level_db)
    rho = best.ratio
    if rho == 1.0:
        return best
    if best.level_db < REFUSE_LINE_DB:          # too weak a family to refuse a record on
        return None
    if best.family.envelope and not any(v is not best and v.ratio == rho for v in verdicts):
        return None                # one bearing family alone, no second one agrees: undecided
    ratio = f"{rho:g}" if rho >= 1 else f"1/{1 / rho:g}"
    raise ParameterError(
        f"record {where}: its {best.family.name} lines stand at {ratio} x where {fs_source} "
        f"{fs_hz:g} Hz and {speed_source} {speed_rpm:g} put them ({best.level_db:.0f} dB "
        f"over the floor there, not at the stated lines): the sample rate or the speed "
        f"stated (file, metadata.json or options) is wrong; {fs_source} {fs_hz / rho:g} Hz "
        f"or {speed_source} {speed_rpm * rho:g} would fit", param="record",
        allowed=f"sample rate {fs_hz / rho:g} Hz or speed {speed_rpm * rho:g} rpm")
