"""Shaft lines that rose only because their floor fell: a cause named on them is not named
(a step of :func:`cmsim.discrepancy.judge.judge` between the decision and step 5).

The judge's features are scale-free: the shaft lines ``raw_fr_h1_db`` and ``raw_fr_h2_db``
are read over the spectrum's median (:func:`~cmsim.features.relative.raw_floor`), so a record
whose broadband fell reads its shaft lines as risen by as much. Against its own machine the
record and the baseline share the sensor (where neither unit is known, its unstated unit):
a line's rise in absolute level is its rise over the floor plus the floor's own change (each
read at its own speed). A cause whose evidence on its own signature comes mostly
(:data:`FLOOR_BORNE_SHARE`) from shaft lines it reads risen, none of which rose
:data:`LINE_RISE_DB` in absolute level, is named on a floor that fell, not on its lines: the
record is decided again without it (another cause, or ``unexplained`` with where the record
departs). A cause that reads the lines fallen (added noise: the floor rose) is not asked.

SpectraQuest's broken-tooth records (``b30hz0``, ``b30hz50``) against the healthy ones of
their gearbox (channel a1, eight segments each): the floor 8.8 and 6.8 dB under the healthy
records', the 1× and 2× input-shaft lines within 1.8 dB of theirs (their spread over the
segments 0.9-2.2 dB), read 8.5 and 10.2 dB up over the floor — misalignment, unbalance and
the input gear's eccentricity each drew half their evidence or more from them, and
misalignment was named.
"""

from __future__ import annotations

import numpy as np

from cmsim.features.relative import raw_floor, segments
from cmsim.spectra.amplitude import amplitude_spectrum

__all__ = ["FLOOR_BORNE_SHARE", "LINE_RISE_DB", "SHAFT_LINES", "floor_borne",
           "floor_change_db", "held_lines", "line_fell"]

#: The raw shaft lines, read over :func:`~cmsim.features.relative.raw_floor`, and their
#: orders in words.
SHAFT_LINES = {"raw_fr_h1_db": "1×", "raw_fr_h2_db": "2×"}

#: Share of a cause's evidence on its own signature (the features it raises nearer the
#: record) the shaft lines carry for the check to apply.
FLOOR_BORNE_SHARE = 0.5

#: Least rise of a shaft line in absolute level over the baseline's for a cause named on
#: it, dB: about 3 times the spread of a 0.5-s segment's line (0.9-1.1 dB on SpectraQuest's
#: healthy input shaft at no load), and half the judge's
#: :data:`~cmsim.discrepancy.stand_out.FAMILY_RISE_DB`.
LINE_RISE_DB = 3.0

#: Segments of a record or a baseline the floor is averaged over.
FLOOR_SEGMENTS = 16


def _floor_db(signals, fs_hz, freqs, scale, seg_s):
    """Mean over segments of :func:`raw_floor`, dB re 1 m/s²."""
    bearings = [freqs.bearing(b) for b in freqs.bearing_names]
    out = []
    for x in signals:
        for a, b in segments(x.size, fs_hz, seg_s, FLOOR_SEGMENTS):
            y = np.asarray(x[a:b], dtype=float) * scale
            spec = amplitude_spectrum(y - y.mean(), fs_hz, window="hann")
            out.append(20.0 * np.log10(max(raw_floor(spec.freq_hz, spec.amplitude,
                                                     freqs.fr1_hz, bearings), 1e-300)))
    return float(np.mean(out)) if out else None


def floor_change_db(record, machine, seg_s):
    """The record's raw floor over its baseline's, dB (each at its own speed, over segments
    of ``seg_s``), or None where one unit is known and the other not, or the machine keeps
    no baseline. Where neither unit is known, both are taken as the one sensor's unstated
    unit (the machine's channel, as ``compare --machine`` asks).

    Parameters
    ----------
    record : MeasuredRecord
        The record.
    machine : cmsim.machine.Machine
        Its machine.
    seg_s : float
        Segment length, s (the library's).

    Returns
    -------
    float or None
    """
    base = machine.baseline
    if (record.unit_scale is None) != (machine.unit_scale is None) or base is None \
            or not base.records:
        return None
    rec = _floor_db([record.signal], record.fs_hz, record.model_frequencies(),
                    record.unit_scale or 1.0, seg_s)
    ref = _floor_db(base.records, record.fs_hz,
                    record.model_frequencies(speed_rpm=machine.op.speed_rpm),
                    machine.unit_scale or 1.0, seg_s)
    return None if rec is None or ref is None else rec - ref


def floor_borne(row, names, meas, base, floor_db):
    """The absolute rises of the shaft lines ``row`` reads risen over their floor (dB), where
    the row draws :data:`FLOOR_BORNE_SHARE` of its evidence from them and none rose
    :data:`LINE_RISE_DB` in absolute level; None otherwise.

    Parameters
    ----------
    row : dict
        A cause's row of :func:`~cmsim.discrepancy.judge.decide_record` (``per_feature``:
        each feature's evidence, ``judged_on``).
    names : sequence of str
        The compared features.
    meas, base : numpy.ndarray
        The record's features and the baseline's.
    floor_db : float
        :func:`floor_change_db`.

    Returns
    -------
    dict or None
        Line → its rise in absolute level, dB.
    """
    gain = {k: max(v, 0.0) for k, v in row["per_feature"].items() if k in row["judged_on"]}
    # the lines the cause reads risen over their floor (a cause that reads them fallen,
    # as added noise does, is named on the floor's rise: nothing here asks it)
    over = {k: float(meas[i] - base[i]) for k in SHAFT_LINES if k in names
            for i in [names.index(k)] if gain.get(k, 0.0) > 0.0 and meas[i] > base[i]}
    if not over or sum(gain[k] for k in over) < FLOOR_BORNE_SHARE * sum(gain.values()):
        return None
    rises = {k: v + floor_db for k, v in over.items()}
    return None if max(rises.values()) >= LINE_RISE_DB else rises


def line_fell(name, meas, base, floor_db):
    """Whether a feature read fallen over the baseline fell in absolute level too: a shaft
    line (:data:`SHAFT_LINES`) only where it fell :data:`LINE_RISE_DB` with its floor's
    change added (an unknown ``floor_db``, None, leaves it as read); any other feature as
    read.

    Parameters
    ----------
    name : str
        The feature.
    meas, base : float
        Its value on the record and on the baseline.
    floor_db : float or None
        :func:`floor_change_db`.

    Returns
    -------
    bool
    """
    if name not in SHAFT_LINES or floor_db is None:
        return True
    return meas - base + floor_db <= -LINE_RISE_DB


def held_lines(decision, names, meas, base, floor_db, redecide):
    """The decision taken again without the causes named on a floor that fell (module
    docstring), and the notes saying why (none where the named cause is not one of them).

    Parameters
    ----------
    decision : dict
        :func:`~cmsim.discrepancy.judge.decide_record`'s result.
    names : sequence of str
        The compared features.
    meas, base : numpy.ndarray
        The record's features and the baseline's.
    floor_db : float or None
        :func:`floor_change_db` (None: unknown, the decision stands).
    redecide : callable
        ``redecide(excluded)``: the decision without the causes named in ``excluded``.

    Returns
    -------
    (dict, list of str)
    """
    top = decision["top"]
    if top is None or not any(k in top["judged_on"] for k in SHAFT_LINES):
        return decision, []
    lines = None if floor_db is None else floor_borne(top, names, meas, base, floor_db)
    if lines is None:
        return decision, []
    # the named cause is one of the rows: every cause any of whose readings the floor
    # carries is held with it
    held = {r["name"] for r in list(decision["ranked"]) + list(decision["by_signature"])
            if floor_borne(r, names, meas, base, floor_db) is not None}
    new = redecide(held)
    return new, [
        f"{', '.join(sorted(n.replace('_', ' ') for n in held))} not named: their evidence "
        f"is the shaft lines over the spectrum's floor, which lies {floor_db:+.1f} dB from "
        f"the baseline's, while the lines themselves moved "
        + " and ".join(f"{v:+.1f} dB ({SHAFT_LINES[k]})" for k, v in lines.items())
        + f" (a line's rise asked: {LINE_RISE_DB:g} dB)"]
