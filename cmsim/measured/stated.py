"""What a measured recording states, from where: one rule for every source.

A sample rate, a shaft speed, a channel's unit or a calibration factor can be stated by the
signal file (:mod:`~cmsim.measured.readers`), by ``metadata.json`` and by the caller (a
command line's ``--fs-hz``). The first source in that order gives the value; every other
source that states it must agree, or the record is refused with one line naming both
values and where each comes from. :func:`~cmsim.measured.record.read_record` and
:func:`~cmsim.measured.importing.folder_metadata` both read through it, so a folder that
``cmsim import`` documented reads back with the values the options gave.
"""

from __future__ import annotations

from cmsim.errors import ParameterError
from cmsim.measured.schema import unit_scale_of

__all__ = ["agreed", "agreed_unit", "speed_uncertainty", "HEADER_RATE_TOLERANCE",
           "SPEED_TOLERANCE", "CALIBRATION_TOLERANCE", "MEASURED_SPEED_UNCERTAINTY",
           "NOMINAL_SPEED_UNCERTAINTY"]

#: Largest relative difference between two statements of a record's sample rate (file
#: header, metadata.json, the caller) that still agree.
HEADER_RATE_TOLERANCE = 1e-3

#: Largest relative difference between two statements of a record's shaft speed (a file's
#: measured mean against a metadata nominal); the speed is then refined from the signal.
SPEED_TOLERANCE = 1e-2

#: Largest relative difference between two statements of a calibration factor.
CALIBRATION_TOLERANCE = 1e-6

#: Relative uncertainty of a measured speed (a file's tachometer value, a metadata speed
#: that is not a nominal one, a caller's): a stored mean differs from the actual speed by a
#: few rpm (CWRU's "a few rpm", Smith & Randall 2015).
MEASURED_SPEED_UNCERTAINTY = 0.005

#: Relative uncertainty of a nominal speed (``shaft_speed_*_nominal``: a set-point or
#: nameplate value): an induction motor's slip under load moves it by a few per cent.
NOMINAL_SPEED_UNCERTAINTY = 0.03


def agreed(path, quantity, statements, tolerance, unit=""):
    """The first of ``statements`` that states a value, and where it comes from, after
    checking that every other statement agrees with it; the first that does not is one
    error naming both values.

    Parameters
    ----------
    path : str or pathlib.Path
        The record, for the message.
    quantity : str
        What is stated (``"sample rate"``), for the message.
    statements : sequence of (str, str, float or None)
        ``(phrase, param, value)`` in order of precedence: ``phrase`` names the source in a
        message (``the WAV header``, ``metadata.json "fs_hz"``, ``fs_hz`` for the caller's
        argument), ``param`` is what an error is about (the caller's argument, else
        ``record``); a None value states nothing.
    tolerance : float
        Largest relative difference that still agrees.
    unit : str
        Unit of the values in the message (``" Hz"``).

    Returns
    -------
    value : float or None
    phrase : str or None
        Where the value comes from.

    Raises
    ------
    ParameterError
        Two statements that differ by more than ``tolerance``.
    """
    given = [(what, param, v) for what, param, v in statements if v is not None]
    if not given:
        return None, None
    (what0, param0, v0), rest = given[0], given[1:]
    for what, param, v in rest:
        if abs(float(v) / float(v0) - 1.0) > tolerance:
            hint = (" (the file is what the recorder wrote)" if param0 == "record"
                    and what0.startswith(("the", "its")) else "")
            raise ParameterError(
                f"record {path}: {what0} says {quantity} {float(v0):g}{unit} but {what} says "
                f"{float(v):g}{unit}; correct the one that is wrong{hint}",
                param=param if param != "record" else param0,
                allowed=f"{quantity} = {float(v0):g}{unit}")
    return float(v0), what0


def speed_uncertainty(entry, source):
    """Relative uncertainty of a record's stated speed: :data:`NOMINAL_SPEED_UNCERTAINTY`
    when the metadata states it as a nominal value (read from a ``*_nominal`` key, or equal
    to the entry's nominal speed), else :data:`MEASURED_SPEED_UNCERTAINTY`.

    Parameters
    ----------
    entry : dict
        Readable keys of the recording entry.
    source : str or None
        Where the speed came from (``metadata.json "shaft_speed_rpm"``, ``the file``,
        ``speed_rpm`` of the caller).

    Returns
    -------
    float

    Examples
    --------
    >>> speed_uncertainty({"shaft_speed_rpm": 1500.0, "shaft_speed_rpm_nominal": 1500.0},
    ...                   'metadata.json "shaft_speed_rpm"')
    0.03
    >>> speed_uncertainty({"shaft_speed_rpm": 1797.0}, 'metadata.json "shaft_speed_rpm"')
    0.005
    """
    if source and source.startswith("metadata.json"):
        if "_nominal" in source:
            return NOMINAL_SPEED_UNCERTAINTY
        nominal = [factor * float(entry[k]) for k, factor in
                   (("shaft_speed_rpm_nominal", 1.0), ("shaft_speed_hz_nominal", 60.0))
                   if entry.get(k) is not None]
        stated = [factor * float(entry[k]) for k, factor in
                  (("shaft_speed_rpm", 1.0), ("shaft_speed_hz", 60.0))
                  if entry.get(k) is not None]
        if nominal and stated and abs(stated[0] / nominal[0] - 1.0) < 1e-9:
            return NOMINAL_SPEED_UNCERTAINTY
    return MEASURED_SPEED_UNCERTAINTY


def agreed_unit(path, channel, statements):
    """The channel's unit from the first of ``statements`` that states one; two units of
    different scale (``g`` and ``m/s^2``, or two unknown units of different names) are
    refused.

    Parameters
    ----------
    path : str or pathlib.Path
        The record, for the message.
    channel : str
        The channel, for the message.
    statements : sequence of (str, str, str or None)
        ``(phrase, param, unit)`` in order of precedence, as :func:`agreed`.

    Returns
    -------
    str or None
    """
    given = [(what, param, str(u)) for what, param, u in statements if u]
    if not given:
        return None
    what0, param0, u0 = given[0]
    for what, param, u in given[1:]:
        a, b = unit_scale_of(u0), unit_scale_of(u)
        same = (a == b) if (a is not None and b is not None) \
            else u0.split()[0].lower() == u.split()[0].lower()
        if not same:
            raise ParameterError(f"record {path}: {what0} says channel {channel!r} is in "
                                 f"{u0!r} but {what} says {u!r}; correct the one that is "
                                 f"wrong", param=param if param != "record" else param0,
                                 allowed=f"unit = {u0}")
    return u0
