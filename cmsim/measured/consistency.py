"""A record's stated sample rate and speed checked against its own lines.

A sample rate wrong by a factor k scales every line of the spectrum by k; a speed wrong by k
moves every line the rig makes by 1/k. Either way the lines — the shaft combs, the mesh
harmonics, each documented bearing's defect families — stand at a ratio ρ ≠ 1 of where the
metadata puts them, while at ρ = 1 they fit. The rule (:func:`check_rate_and_speed`):

**The stated values stand unless they explain none of the record's structure and another
ratio explains it strongly.** Every family whose lines stand clear of the floor
(:data:`CLEAR_LINE_DB`, at least two of its lines in the spectrum) gives a verdict
(:func:`family_verdict`): the ratio its lines stand at, how high, and whether the
contradiction is strong. Then

* a family at ρ = 1 whose lines stand within :data:`CONFIRM_MARGIN_DB` of the highest
  contradicting family's confirms the stated values: they stand (a contradiction is noted);
* otherwise, with no family at a different ratio as high, the record is **refused** when
  the contradiction is strong and corroborated — a strong verdict of an amplitude-spectrum
  comb (shaft, output shaft, mesh: a wrong rate or speed moves them all, and nothing else
  puts a comb exactly 2ᵏ times off), or a strong verdict that another source of lines
  agrees with (the two shafts, the mesh and each bearing family are sources; a shaft's comb
  in the amplitude and in the envelope spectrum are one);
* any other contradiction is a **warning** naming the evidence: a lone bearing family (its
  harmonics can fall on another family's at a ratio 2ᵏ — an outer race's 6th BPFO harmonic
  lies within 1 % of 4 × BPFI on a 6205 — and the bearing making them may be undocumented),
  or lines between the stated ones that stand under the stated lines (a machine's own
  sub-harmonics: half orders of a loose or rubbing rotor, a healthy CWRU record's 0.5× and
  1.5×).

One family's ratio (:func:`family_ratio`) is decided by the lines that only one of two
neighbouring fundamentals predicts (:func:`exclusive_contrast_db`), in steps of 2 within
[1/:data:`LARGEST_FACTOR`, :data:`LARGEST_FACTOR`]:

* **the stated lines missing** — the stated comb predicts k·u for odd k (the first two: u,
  3u) that a comb at 2u does not; if these stand :data:`MISSING_MARGIN_DB` below the lines
  at 2u and one of those stands clear, the fundamental is 2u. The contradiction is *strong*
  when the stated odd lines are absent (under :data:`ABSENT_LINE_DB`, the level of the
  largest of a few noise bins) and the lines at 2u stand :data:`REFUSE_LINE_DB` high;
* **lines between the stated ones** — a comb at u/2 also predicts u/2, 3u/2; if these stand
  clear and within :data:`SUBCOMB_MARGIN_DB` of the stated lines, the fundamental is u/2.
  The contradiction is *strong* when they stand at least :data:`SUBCOMB_STRONG_DB` above
  the stated lines: the stated comb is the weaker half of the structure.

The missing-line test goes first because a lower comb predicts the stated lines too. A step
of 3 is not taken: a gear rig's 3rd shaft harmonic often stands well above the 1st and 2nd.

Line prominence: the largest amplitude within the line's tolerance ±
:data:`~cmsim.measured.comb_ratio.LINE_WINDOW_BINS`
bins over the median of the surrounding ±10 % (at least 25 bins) of a Hann amplitude
spectrum. The tolerance is the stated speed's own uncertainty (a measured speed is known to
a fraction of a per cent, a nominal one to a motor's slip,
:func:`cmsim.measured.stated.speed_uncertainty`), at least :data:`LINE_TOLERANCE`, plus the
rolling elements' slip (:data:`BEARING_SLIP`) for a bearing family. Bearing families are read
in the envelope spectrum of the kurtogram's band, and each shaft's comb there too (an
inner-race or a tooth fault modulates the band at its shaft's rate).

One comb's reading — line prominence, the exclusive lines' contrast, the ratio found step by
step and its thresholds — lives in :mod:`cmsim.measured.comb_ratio` (re-exported here); this
module holds the families, their verdicts and the decision.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from cmsim.errors import ParameterError
from cmsim.measured.comb_ratio import (CLEAR_LINE_DB, COMB_HARMONICS, COMB_TOLERANCE,
                                      LARGEST_FACTOR, LINE_TOLERANCE, log_spectrum,
                                      shaft_comb_db,
                                      MISSING_MARGIN_DB, REFUSE_LINE_DB, STEPS, SUBCOMB_MARGIN_DB, _mean, _steps,
                                      exclusive_contrast_db, family_ratio,
                                      line_prominence_db, lowest_fundamental)
from cmsim.spectra.envelope import envelope_spectrum
from cmsim.spectra.kurtogram import kurtogram

__all__ = ["LineFamily", "FamilyVerdict", "RateCheck", "line_families", "line_prominence_db",
           "exclusive_contrast_db", "family_ratio", "family_verdict", "lowest_fundamental",
           "family_verdicts", "check_rate_and_speed", "REFUSE_LINE_DB", "LINE_TOLERANCE",
           "BEARING_SLIP", "SUBCOMB_MARGIN_DB", "SUBCOMB_STRONG_DB", "MISSING_MARGIN_DB",
           "ABSENT_LINE_DB", "CLEAR_LINE_DB", "CONFIRM_MARGIN_DB", "LARGEST_FACTOR", "STEPS"]

#: Slip of the rolling elements added to a bearing family's tolerance (1-2 %, Randall &
#: Antoni 2011; the shared records' race lines sit −1.4 % to +0.35 % of their nominal values).
BEARING_SLIP = 0.01

#: Lines between the stated ones standing this much above the stated lines, dB, make the
#: lower fundamental a strong contradiction (honest records' own half orders stand 4-7 dB
#: under the stated lines; a stated speed twice the true one puts the true 1× and 3× there).
SUBCOMB_STRONG_DB = 0.0

#: Stated lines under this prominence, dB, are absent (the largest of ~40 bins of pure noise
#: stands about 7 dB over their median): a strong contradiction of the higher fundamental.
ABSENT_LINE_DB = 10.0

#: A family whose lines at the stated values speak against a contradiction
#: (:meth:`FamilyVerdict.backs`) and stand within this of the contradicting lines, dB,
#: confirms the stated values (at a wrong rate or speed, a family's lines that fall on
#: other lines by chance stand 9 dB or more under the family that moved).
CONFIRM_MARGIN_DB = 6.0


@dataclass(frozen=True)
class LineFamily:
    """A family of lines a rig makes: harmonics of ``order`` × the input-shaft rate.

    Attributes
    ----------
    name : str
        ``"shaft"``, ``"output shaft"``, ``"mesh"``, ``"<bearing> BPFO"`` /
        ``"<bearing> BPFI"``; ``" (envelope)"`` appended when read in the envelope.
    order : float
        Fundamental as a multiple of the input-shaft rate.
    harmonics : int
        Harmonics read (1..harmonics).
    envelope : bool
        Read in the envelope spectrum instead of the amplitude spectrum.
    source : str
        What makes the lines (``"input shaft"``, ``"mesh"``, ``"drive_end BPFO"``): two
        families of one source do not corroborate each other.
    slip : bool
        The lines slip with the rolling elements (:data:`BEARING_SLIP` added).
    """

    name: str
    order: float
    harmonics: int
    envelope: bool = False
    source: str = ""
    slip: bool = False

    def on_shaft_orders(self, m):
        """Whether the family's fundamental over ``m`` is a whole shaft order (a mesh of an
        even tooth count at ``m`` = 2): the lines a ratio of ``m`` (or 1/``m``) moves it
        between are then shaft harmonics, which a gear record holds whatever its rate, and
        the family cannot tell that ratio.

        Parameters
        ----------
        m : float
            The ratio (> 1).
        """
        q = self.order / m
        return not self.slip and q >= 1.0 - 1e-9 and abs(q - round(q)) < 1e-6


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
    strong : bool
        A ratio ≠ 1 of strong evidence (module docstring).
    stated_db : float
        Mean prominence of the lines at the stated fundamental, dB.
    between_db : float
        Mean prominence of the lines that decided the first step, dB: the stated odd lines
        for a higher fundamental, the lines between the stated ones for a lower one (NaN at
        ratio 1).
    n_lines : int
        Lines of the family at ratio 1 that fall in the spectrum.
    odd_db : float
        Mean prominence of the stated fundamental's own lines (k = 1, 3: those no comb at
        twice the fundamental makes), dB.
    """

    family: LineFamily
    ratio: float
    level_db: float
    strong: bool = False
    stated_db: float = float("nan")
    between_db: float = float("nan")
    n_lines: int = 0
    odd_db: float = float("nan")

    def backs(self, rho, against_db):
        """Whether the family's lines at the stated values speak strongly against a ratio
        ``rho`` whose lines stand ``against_db`` high: against a higher one, the stated
        fundamental's own lines stand :data:`REFUSE_LINE_DB` high (a comb at ``rho`` times
        it cannot make them); against a lower one, the family stands that high at ratio 1,
        the lines between its own lower; either way within :data:`CONFIRM_MARGIN_DB` of
        the contradicting lines. Where the lines told apart would be shaft harmonics at
        ``rho`` (:meth:`LineFamily.on_shaft_orders`: a mesh of an even tooth count), they
        must stand as high as the contradicting lines: a mesh's lines are a gear record's
        strongest, its shaft harmonics there are not.

        Parameters
        ----------
        rho : float
            The ratio a contradiction puts the lines at.
        against_db : float
            Prominence of the contradicting lines, dB.
        """
        own = self.odd_db if rho > 1.0 else (self.stated_db if self.ratio == 1.0
                                             else float("nan"))
        if self.family.on_shaft_orders(max(rho, 1.0 / rho)):
            return own >= max(against_db, REFUSE_LINE_DB)
        return own >= REFUSE_LINE_DB and self.stated_db >= against_db - CONFIRM_MARGIN_DB

    def describe(self):
        """The verdict in words (``shaft lines at 1/2 x: ...``), for notes and messages."""
        r = _ratio_text(self.ratio)
        if self.ratio == 1.0:
            return f"{self.family.name} lines where stated ({self.level_db:.0f} dB)"
        if self.ratio > 1.0:
            why = (f"the stated odd lines {self.between_db:.0f} dB, i.e. absent"
                   if self.between_db < ABSENT_LINE_DB
                   else f"the stated odd lines only {self.between_db:.0f} dB")
        else:
            why = (f"lines between the stated ones {self.between_db:.0f} dB against the "
                   f"stated lines' {self.stated_db:.0f} dB")
        return f"{self.family.name} lines at {r} x ({self.level_db:.0f} dB over the floor; {why})"


@dataclass(frozen=True)
class RateCheck:
    """The outcome of :func:`check_rate_and_speed` for a record that is not refused.

    Attributes
    ----------
    verdict : str
        ``"agrees"`` (a family confirms the stated values), ``"unchecked"`` (no family's
        lines stand clear), ``"contradicted"`` (a contradiction too weak or too lone to
        refuse the record: warn), ``"trusted"`` (the caller trusts the stated values).
    family : FamilyVerdict or None
        The confirming family (``agrees``) or the strongest contradicting one.
    ratio : float
        The ratio the contradicting lines stand at (1 when none).
    evidence : tuple of str
        Each speaking family's verdict in words.
    message : str
        One line for the notes (``agrees``, ``unchecked``, ``trusted``) or a warning
        (``contradicted``).
    speed_scale : float
        Factor on the stated speed at which the lines stand highest (1 unless the speed's
        uncertainty exceeds :data:`LINE_TOLERANCE`: a nominal speed is searched).
    """

    verdict: str
    family: FamilyVerdict | None = None
    ratio: float = 1.0
    evidence: tuple = field(default_factory=tuple)
    message: str = ""
    speed_scale: float = 1.0

    @property
    def level_db(self):
        """Prominence of the deciding family's lines, dB (NaN without one)."""
        return self.family.level_db if self.family is not None else float("nan")

    def to_dict(self):
        """JSON-ready: verdict, family, ratio, level_db, evidence, message."""
        return {"verdict": self.verdict,
                "family": self.family.family.name if self.family is not None else None,
                "ratio": self.ratio, "level_db": self.level_db,
                "evidence": list(self.evidence), "message": self.message,
                "speed_scale": self.speed_scale}


def _ratio_text(rho):
    return f"{rho:g}" if rho >= 1 else f"1/{1 / rho:g}"


def line_families(frequencies):
    """The families of a rig's lines, from its characteristic frequencies at 1 Hz.

    Parameters
    ----------
    frequencies : cmsim.frequencies.RigFrequencies
        At an input-shaft rate of 1 Hz (so every frequency is an order).

    Returns
    -------
    list of LineFamily
        The input shaft's comb (4 harmonics) in the amplitude and the envelope spectrum; with
        gears, the output shaft's (its bearings turn at its rate) likewise and the mesh
        harmonics (3); each documented bearing's BPFO and BPFI (3 each, envelope, at the
        rate of the shaft that carries it, which the frequencies already hold; bearings of
        one geometry on one shaft are one family, and a bearing's two families one source:
        the ratio of its BPFI to its BPFO is often near a small fraction — 3/2 on a 6205 —
        so each can fall on the other's harmonics).
    """
    fr = frequencies.fr1_hz
    out = [LineFamily("shaft", 1.0, 4, source="input shaft"),
           LineFamily("shaft (envelope)", 1.0, 4, True, source="input shaft")]
    if frequencies.fr2_hz is not None:
        o = frequencies.fr2_hz / fr
        out += [LineFamily("output shaft", o, 4, source="output shaft"),
                LineFamily("output shaft (envelope)", o, 4, True, source="output shaft")]
    if frequencies.gmf_hz is not None:
        out.append(LineFamily("mesh", frequencies.gmf_hz / fr, 3, source="mesh"))
    seen = {}                       # bearings of one geometry make one set of lines
    for name, b in (frequencies.bearings or {}).items():
        key = (round(b.bpfo_hz / fr, 9), round(b.bpfi_hz / fr, 9))
        seen.setdefault(key, []).append(name)
    for (bpfo, bpfi), names in seen.items():
        name = "/".join(names)
        for what, order in (("BPFO", bpfo), ("BPFI", bpfi)):
            out.append(LineFamily(f"{name} {what}", order, 3, True,
                                  source=f"bearing {name}", slip=True))
    return out


def family_verdict(freq, log_amp, family, stated_hz, tolerance=LINE_TOLERANCE):
    """One family's :class:`FamilyVerdict` (module docstring).

    Parameters
    ----------
    freq, log_amp : numpy.ndarray, shape (n,)
        Spectrum (:func:`line_prominence_db`).
    family : LineFamily
    stated_hz : float
        Fundamental the metadata predicts, Hz.
    tolerance : float
        Relative half-width of each line's window.

    Returns
    -------
    FamilyVerdict
    """
    h = family.harmonics

    def at(f_hz):
        return line_prominence_db(freq, log_amp, f_hz, tolerance)

    ratio, first = _steps(freq, log_amp, stated_hz, h, tolerance,
                          not family.on_shaft_orders(2))
    stated = [at(k * stated_hz) for k in range(1, h + 1)]
    level = _mean(at(k * stated_hz * ratio) for k in range(1, h + 1))
    strong, between = False, float("nan")
    if ratio > 1.0:                 # the stated odd lines absent, the higher comb high
        exclusive, _, peak = first
        between = exclusive
        strong = exclusive < ABSENT_LINE_DB and peak >= REFUSE_LINE_DB
    elif ratio < 1.0:               # the final comb's own lowest lines over the stated ones
        m = int(round(1.0 / ratio))
        between = _mean([at(j * stated_hz * ratio) for j in range(1, 2 * m) if j % m][:2])
        strong = between - _mean(stated) >= SUBCOMB_STRONG_DB and between >= REFUSE_LINE_DB
    return FamilyVerdict(family, ratio, level, strong, _mean(stated), between,
                         sum(s == s for s in stated), _mean(stated[0:3:2]))


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


def _speed_scale(spectra, families, shaft_hz, uncertainty):
    """The factor within ±``uncertainty`` of the stated speed, in steps of
    :data:`LINE_TOLERANCE`, at which the families' lines stand highest on average: a
    nominal speed is searched, not read with windows as wide as its uncertainty (wide
    windows let every family find some line)."""
    n = int(np.floor(uncertainty / LINE_TOLERANCE + 1e-9))
    if n < 1:
        return 1.0
    best, scale = -np.inf, 1.0
    for c in 1.0 + LINE_TOLERANCE * np.arange(-n, n + 1):
        levels = [line_prominence_db(*spectra[f.envelope], k * f.order * shaft_hz * c,
                                     LINE_TOLERANCE + (BEARING_SLIP if f.slip else 0.0))
                  for f in families for k in range(1, f.harmonics + 1)]
        score = _mean(levels)
        if score > best:
            best, scale = score, float(c)
    return scale


def family_verdicts(x, fs_hz, shaft_hz, frequencies, speed_tolerance=0.0):
    """Every family's verdict (see the module docstring).

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
    speed_tolerance : float
        Relative uncertainty of the stated speed: beyond :data:`LINE_TOLERANCE`, the
        speed is searched within it first (the lines read at the speed where they stand
        highest); a bearing family's window adds :data:`BEARING_SLIP`.

    Returns
    -------
    list of FamilyVerdict
    """
    return _verdicts_and_scale(x, fs_hz, shaft_hz, frequencies, speed_tolerance)[0]


def _verdicts_and_scale(x, fs_hz, shaft_hz, frequencies, speed_tolerance):
    """:func:`family_verdicts` and the factor on the stated speed they were read at."""
    families = line_families(frequencies)
    spectra = {False: log_spectrum(x, fs_hz),
               True: _envelope_log_spectrum(x, fs_hz, max(f.order for f in families)
                                            * shaft_hz)}
    scale = _speed_scale(spectra, families, shaft_hz, float(speed_tolerance))
    return [family_verdict(*spectra[f.envelope], f, f.order * shaft_hz * scale,
                           LINE_TOLERANCE + (BEARING_SLIP if f.slip else 0.0))
            for f in families], scale


def _echoes(v, w):
    """Whether ``v``'s lines at its ratio are harmonics (1-4) of a sibling ``w``'s at the
    stated values, within two bearing lines' windows: one bearing's BPFI and BPFO stand
    near a small ratio (2 × BPFI = 3.02 × BPFO on a 6205, 2.93 × on MFPT's), so one
    family's comb can read the other's."""
    q = v.ratio * v.family.order / w.family.order
    return any(abs(q / n - 1.0) <= 2 * (LINE_TOLERANCE + BEARING_SLIP) for n in (1, 2, 3, 4))


def _speaking(verdicts):
    """The verdicts that speak: lines clear of the floor, at least two in the spectrum;
    a bearing family that stands at another ratio on the harmonics of a sibling family
    standing clear where the metadata puts it is left out (:func:`_echoes`)."""
    clear = [v for v in verdicts if v.level_db >= CLEAR_LINE_DB and v.n_lines >= 2]
    return [v for v in clear if v.ratio == 1.0 or not v.family.slip or not any(
        w is not v and w.family.source == v.family.source and w.stated_db >= CLEAR_LINE_DB
        and _echoes(v, w) for w in clear)]


def _decide(verdicts):
    """``(verdict, family, ratio, refuse)`` of the speaking families (module docstring)."""
    clear = _speaking(verdicts)
    if not clear:
        return "unchecked", None, 1.0, False
    against = [v for v in clear if v.ratio != 1.0]
    if not against:
        return "agrees", max(clear, key=lambda v: v.level_db), 1.0, False
    strong = [v for v in against if v.strong]
    top = max(strong or against, key=lambda v: v.level_db)
    rho = top.ratio
    same = [v for v in against if v.ratio == rho]
    backing = [v for v in clear if v.backs(rho, top.level_db) and (   # a sibling backs only
        v.family.source != top.family.source or v.stated_db >= top.level_db)]  # over its echo
    if backing:
        return "agrees", max(backing, key=lambda v: v.stated_db), 1.0, False
    rival = any(v.ratio != rho and v.level_db >= top.level_db - CONFIRM_MARGIN_DB
                for v in strong)
    sources = {v.family.source for v in same}
    refuse = top.strong and not rival and (not top.family.envelope or len(sources) >= 2)
    return "contradicted", top, rho, refuse


def check_rate_and_speed(x, fs_hz, speed_rpm, frequencies, *, where, fs_source="fs_hz",
                         speed_source="shaft_speed_rpm", speed_tolerance=0.0,
                         trust=False):
    """Refuse a record whose lines stand strongly at a ratio ≠ 1 of where its sample rate
    and speed put them and nowhere where they do; say what is weaker.

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
    speed_tolerance : float
        Relative uncertainty of the stated speed
        (:func:`cmsim.measured.stated.speed_uncertainty`).
    trust : bool
        Trust the stated values: nothing is checked (``trust_metadata`` of
        :func:`cmsim.measured.read_record`, ``--trust-metadata``).

    Returns
    -------
    RateCheck
        ``agrees``, ``unchecked``, ``contradicted`` (its message a warning naming the
        evidence) or ``trusted``.

    Raises
    ------
    ParameterError
        The stated values explain none of the record's lines and another ratio ρ explains
        them strongly (module docstring): the message names the evidence and both
        corrections (the sample rate ρ times too high, or the speed ρ times too low).
    """
    if trust:
        return RateCheck("trusted", message="sample rate and speed trusted as stated "
                                            "(trust_metadata): not checked against the signal")
    verdicts, scale = _verdicts_and_scale(x, fs_hz, speed_rpm / 60.0, frequencies,
                                          speed_tolerance)
    verdict, fam, rho, refuse = _decide(verdicts)
    evidence = tuple(v.describe() for v in _speaking(verdicts))
    if verdict == "unchecked":
        return RateCheck(verdict, message="sample rate and speed not checked against the "
                                          "signal: no shaft, mesh or bearing lines stand "
                                          "clear of the floor")
    if verdict == "agrees":
        others = [e for e in evidence if " at " in e]
        note = (f"sample rate and speed agree with the signal's {fam.family.name} lines "
                f"({fam.stated_db:.0f} dB over the floor)")
        if others:
            note += "; not with " + "; ".join(others)
        return RateCheck(verdict, fam, 1.0, evidence, note, scale)
    r = _ratio_text(rho)
    what = (f"record {where}: its {fam.describe()}, where {fs_source} {fs_hz:g} Hz and "
            f"{speed_source} {speed_rpm:g} put them")
    fits = f"{fs_source} {fs_hz / rho:g} Hz or {speed_source} {speed_rpm * rho:g} would fit"
    comb = shaft_comb_db(*log_spectrum(x, fs_hz), rho * speed_rpm / 60.0,
                         max(speed_tolerance, COMB_TOLERANCE))
    if not comb >= CLEAR_LINE_DB:    # the correction put the shaft's own comb nowhere either
        fits += (f" by these lines, but the shaft's own comb does not stand there either "
                 f"({comb:.0f} dB over the floor, its first {COMB_HARMONICS} harmonics): "
                 f"the speed or the rate may be off by another factor than {r}; check both")
    if refuse:
        raise ParameterError(
            f"{what}, and no family of lines stands where they are stated"
            + "".join(f"; {e}" for e in evidence if e != fam.describe()) + f": the sample rate or the speed stated (file, "
            f"metadata.json or options) is wrong; {fits} (if they are right, trust_metadata "
            f"reads the record as stated)", param="record",
            allowed=f"sample rate {fs_hz / rho:g} Hz or speed {speed_rpm * rho:g} rpm")
    others = [e for e in evidence if e != fam.describe()]
    also = f" (also: {'; '.join(others)})" if others else ""
    return RateCheck(verdict, fam, rho, evidence,
                     f"{what}{also}: the sample rate or the speed may be wrong by {r} "
                     f"({fits}); not refused, the evidence is not strong enough", scale)
