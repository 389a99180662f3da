"""The one measured record: a measured :class:`~cmsim.run.Run` with what a diagnosis and a
comparison with the model need.

:func:`read_record` turns a signal file (in a folder with ``metadata.json``, or with what
the caller states in its place) into a :class:`MeasuredRecord`: it reads the schema's
readable keys (:mod:`cmsim.measured.schema`), the channels and what the file states
(:mod:`cmsim.measured.readers`), agrees the rate, speed, unit and calibration of every
source (:mod:`cmsim.measured.stated`), fills in what they all lack from the signal
(:mod:`cmsim.measured.inference`: sample rate, speed), checks a stated sample rate and
speed against the record's own lines (:mod:`cmsim.measured.consistency`) before anything
is computed on them, and builds the model of the record
(:mod:`cmsim.measured.model_rig`). The same record serves the diagnostics harness (signals,
sample rate, documented operating point and characteristic frequencies) and
:func:`cmsim.discrepancy.compare` (the compared channel, the model rig and operating point).
The answer key never enters it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from cmsim.errors import ParameterError, RecordWarning
from cmsim.frequencies import RigFrequencies, rig_frequencies
from cmsim.measured.consistency import BEARING_SLIP, check_rate_and_speed
from cmsim.measured.inference import (NOTE_AGREEMENT, infer_sample_rate, note_disagreement,
                                      refine_speed, sample_rate_from_note, speed_comb_doubt)
from cmsim.measured.model_rig import (NO_GEOMETRY, documented_frequencies,
                                      documented_operating_point, model_operating_point,
                                      model_rig)
from cmsim.measured.readers import is_cmsim_run, npz_names, read_file, resolve_path
from cmsim.measured.samples import (MIN_SAMPLES, checked_samples, clipping_doubt,
                                    count_doubt)
from cmsim.measured.schema import (FOLDER_KEYS, checked_unit, documented_speed,
                                   read_metadata, recording_entry, unit_kind, unit_scale_of)
from cmsim.measured.stated import (CALIBRATION_TOLERANCE, HEADER_RATE_TOLERANCE,
                                   MEASURED_SPEED_UNCERTAINTY, SPEED_TOLERANCE, agreed,
                                   agreed_unit, speed_uncertainty)
from cmsim.rig import OperatingPoint, Rig
from cmsim.run import Run
from cmsim.sensors import decimate

__all__ = ["MeasuredRecord", "read_record", "read_run", "record_from_run", "MIN_SAMPLES"]


@dataclass(frozen=True, eq=False)
class MeasuredRecord:
    """A measured record (one recording of a folder, or an in-memory measured run).

    Attributes
    ----------
    run : cmsim.run.Run
        ``source="measured"``: every channel of the file (unit as recorded, float64) sampled
        at :attr:`fs_hz`; its meta holds the readable metadata, each channel's unit where
        stated (``units``), the notes on what was assumed and what was inferred — never the
        answer key or the file name.
    channel : str
        Channel compared with the model (default: the first sensor near a documented
        bearing, else the first channel).
    rig : cmsim.rig.Rig or None
        Model rig (:func:`~cmsim.measured.model_rig.model_rig`, or the user's); None for a
        recording without geometry read with ``model=False`` (a spectrum's).
    op : cmsim.rig.OperatingPoint
        Operating point of the model: speed (documented or inferred), torque and radial load
        with the model's assumptions (:func:`~cmsim.measured.model_rig.model_operating_point`).
    model_signal : str
        Model output that corresponds to :attr:`channel` (``accel_1b1_y``, ...).
    components : dict of str to str
        Model component → dataset name (``{"1b1": "drive_end"}``).
    inferred : dict
        Quantity → ``{"value": ..., "how": ...}`` for what was inferred from the signal.
    path : str
        The signal file ("" for an in-memory record).
    unit_scale : float or None
        Factor from the channel's unit to m/s² (``g`` → 9.80665), or None when the unit is
        not an acceleration unit cmsim knows (then only scale-free features are compared).
    record_id : str
        File stem ("" for an in-memory record); names the record in reports, never read by a
        diagnosis.
    frequencies : cmsim.frequencies.RigFrequencies or None
        Characteristic frequencies of the documented geometry at the record's speed (bearing
        keys as in the metadata): what a diagnosis is given. None for an in-memory record.
    operating_point : cmsim.rig.OperatingPoint or None
        Documented operating point at the record's speed (no model assumption): what a
        diagnosis is given. None for an in-memory record.
    path_documented : bool
        Whether the model rig's housing path is the machine's (a rig the user gave, an
        in-memory record made through that rig); a rig built from metadata geometry carries
        the generic path, and only path-free evidence is then judged without a calibrated
        machine (:func:`cmsim.discrepancy.compare`).
    """

    run: Run
    channel: str
    rig: Rig
    op: OperatingPoint
    model_signal: str
    components: dict = field(default_factory=dict)
    inferred: dict = field(default_factory=dict)
    path: str = ""
    unit_scale: float | None = None
    record_id: str = ""
    frequencies: RigFrequencies | None = None
    operating_point: OperatingPoint | None = None
    path_documented: bool = True

    @property
    def fs_hz(self):
        """Sample rate (documented or inferred), Hz."""
        return self.run.fs_hz

    @property
    def signal(self):
        """The compared channel, float64 with the mean removed."""
        x = np.asarray(self.run[self.channel], dtype=float)
        return x - x.mean()

    @property
    def signals(self):
        """Channel name → samples (every channel of the record)."""
        return dict(self.run.signals)

    @property
    def meta(self):
        """The run's metadata (readable keys, notes, inferred values; no answer key)."""
        return self.run.meta

    def span(self, start_s, stop_s=None):
        """The same record cut to the time span [``start_s``, ``stop_s``) (s from its first
        sample; ``stop_s`` None: to the end) — e.g. to calibrate a machine on one half of a
        baseline and compare the other half with it.

        Parameters
        ----------
        start_s : float
            Start, s (>= 0).
        stop_s : float, optional
            End, s (> start_s, at most the record's duration).

        Returns
        -------
        MeasuredRecord
        """
        n = self.run.t.size
        duration = n / self.fs_hz
        stop = duration if stop_s is None else float(stop_s)
        if not (0.0 <= float(start_s) < stop <= duration * (1 + 1e-9)):
            raise ParameterError(f"span must satisfy 0 <= start < stop <= {duration:g} s, got "
                                 f"[{start_s:g}, {stop:g}]", param="span",
                                 allowed=f"0 <= start < stop <= {duration:g} s")
        a, b = int(round(float(start_s) * self.fs_hz)), min(int(round(stop * self.fs_hz)), n)
        if b - a < MIN_SAMPLES:
            raise ParameterError(f"span [{start_s:g}, {stop:g}] s holds {b - a} samples; needs "
                                 f">= {MIN_SAMPLES}", param="span")
        run = Run(self.run.t[a:b] - self.run.t[a],
                  {k: np.asarray(v)[a:b] for k, v in self.run.signals.items()},
                  dict(self.run.meta, span_s=[float(start_s), stop]), source="measured")
        return replace(self, run=run)

    def resampled(self, fs_out_hz):
        """The same record at a lower sample rate: every channel low-passed and resampled
        (:func:`cmsim.sensors.decimate`, the one resampler of cmsim) — e.g. a record made at
        twice the rate of the baseline its machine was calibrated on.

        Parameters
        ----------
        fs_out_hz : float
            Sample rate, Hz: at most the record's, ``fs·up/down`` (down <= 1000).

        Returns
        -------
        MeasuredRecord
            Its first sample at the filter's half length into the record; the meta says
            from which rate it was resampled (``resampled_from_hz``).
        """
        names = list(self.run.signals)
        y, _, info = decimate(np.column_stack([np.asarray(self.run[k], dtype=float)
                                               for k in names]), self.fs_hz, fs_out_hz)
        fs = float(fs_out_hz)
        run = Run(np.arange(y.shape[0]) / fs, {k: y[:, i] for i, k in enumerate(names)},
                  dict(self.run.meta, fs_hz=fs, resampled_from_hz=self.fs_hz,
                       resampling=info), source="measured")
        return replace(self, run=run)

    def model_frequencies(self, speed_rpm=None):
        """Characteristic frequencies of the model rig (bearings ``1b1``, ...).

        Parameters
        ----------
        speed_rpm : float, optional
            Input-shaft speed, rpm; default the record's.

        Returns
        -------
        cmsim.frequencies.RigFrequencies
        """
        op = self.op if speed_rpm is None else replace(self.op, speed_rpm=speed_rpm)
        return rig_frequencies(self.rig, op)


def _channel(signals, sensors, bearings, channel, name):
    if channel is None:
        # the first near a documented bearing, else the first by name; never a time base
        # (a LabVIEW "X_Value", a "Time" channel, a matrix's time column): samples that
        # never fall and end higher are a clock, not a vibration
        near_bearing = [c for c in signals if (sensors.get(c) or {}).get("near") in bearings]
        candidates = near_bearing or sorted(signals)
        channel = next((c for c in candidates if not _rises_throughout(signals[c])),
                       candidates[0])
    if channel not in signals:
        raise ParameterError(f"channel {channel!r} is not in {name}; available: "
                             f"{sorted(signals)}", param="--channel",
                             allowed=", ".join(sorted(signals)))
    return channel, checked_samples(signals[channel], channel, name)


def _rises_throughout(x):
    """Whether no sample of ``x`` is below the one before and the last is above the first (a
    time base, one printed coarser than its step included, or a sample index)."""
    return x.size > 2 and x[-1] > x[0] and bool(np.all(np.diff(x) >= 0))


def _sample_rate(fs, x, speed_rpm, teeth, inferred, notes, meta):
    """The sample rate: stated (file, metadata.json, caller), else inferred from the
    signal."""
    if fs is not None:
        return float(fs)
    note_hz = sample_rate_from_note(meta.get("fs_note"))
    if teeth is not None and speed_rpm is not None:
        fs, nu, score = infer_sample_rate(x, speed_rpm / 60.0, teeth)
        how = (f"mesh comb of {teeth[0]}:{teeth[1]} teeth at {nu:.6g} cycles/sample (shaft "
               f"line), {score:.1f} dB over the median level, scaled by the documented speed")
        gap = note_disagreement(fs, note_hz)
        if gap == gap:
            how += f"; the metadata note says {note_hz:g} Hz ({100 * gap:.1f} % apart)"
            if gap > NOTE_AGREEMENT:
                notes.append(f"inferred fs {fs:.6g} Hz disagrees with fs_note {note_hz:g} Hz "
                             f"by {100 * gap:.1f} %")
        inferred["fs_hz"] = {"value": fs, "how": how}
        return float(fs)
    if note_hz is not None:
        inferred["fs_hz"] = {"value": note_hz, "how": "fs_note of metadata.json (not verified "
                             "against the signal: no gear tooth counts or speed)"}
        return note_hz
    raise ParameterError("fs_hz is undocumented (the file states no rate, metadata.json no "
                         "\"fs_hz\") and cannot be inferred (needs gear tooth counts and a "
                         "shaft speed)", param="fs_hz",
                         allowed="a number > 0: fs_hz, or \"fs_hz\" in metadata.json")


def _check_against_lines(x, fs, speed_rpm, frequencies, notes, doubts, path, fs_source,
                         speed_source, speed_tolerance, trust):
    """The stated sample rate and speed checked against the record's own lines
    (:func:`~cmsim.measured.consistency.check_rate_and_speed`): a strong contradiction
    refuses the record, a weaker one goes to ``doubts`` and is warned
    (:class:`~cmsim.errors.RecordWarning`), what was checked (or that nothing could be) to
    the notes; the check's outcome."""
    check = check_rate_and_speed(x, fs, speed_rpm, frequencies, where=path,
                                 fs_source=fs_source, speed_source=speed_source,
                                 speed_tolerance=speed_tolerance, trust=trust)
    if check.verdict == "contradicted":
        doubts.append(check.message)
        warnings.warn(check.message, RecordWarning, stacklevel=3)
    else:
        notes.append(check.message)
    return check


#: Quantity of a channel's unit → how often it is differentiated to an acceleration.
DIFFERENTIATIONS = {"velocity": "once", "displacement": "twice"}


def _to_acceleration(x, fs_hz, quantity, factor):
    """A velocity (``factor`` to m/s) or displacement (to m) channel as an acceleration in
    m/s²: differentiated in the frequency domain (× j2πf per time), exact up to the Nyquist
    frequency; the record is mirrored first, so its two ends meet without a jump."""
    y = (np.asarray(x, dtype=float) - np.mean(x)) * factor
    n = y.size
    z = np.concatenate([y, y[::-1]])
    jw = 2j * np.pi * np.fft.rfftfreq(z.size, 1.0 / fs_hz)
    order = 1 if quantity == "velocity" else 2
    return np.fft.irfft(np.fft.rfft(z) * jw ** order, z.size)[:n]


def _refined_speed(x, fs, speed, teeth, check, uncertainty, inferred):
    """``(speed, its uncertainty)``: refined by the shaft comb where it stands clear
    (:func:`~cmsim.measured.inference.refine_speed`; kept where the clear comb confirms it),
    else, for a nominal speed, moved to where the check found the rig's lines standing
    highest within its uncertainty, in steps of 1 %
    (:attr:`~cmsim.measured.consistency.RateCheck.speed_scale`); what was refined goes to
    ``inferred``."""
    refined, how, confirmed = refine_speed(x, fs, speed, teeth)
    if confirmed and how is None:
        # a nominal 965 rpm that the comb reads at 964.5 was moved 1 % to where the
        # families' lines stood highest, and the findings with it
        return speed, min(uncertainty, MEASURED_SPEED_UNCERTAINTY)
    if how is None and check is not None and check.verdict == "agrees" \
            and check.speed_scale != 1.0:
        refined = speed * check.speed_scale
        how = (f"the nominal {speed:g} rpm searched within its {100 * uncertainty:g} %: the "
               f"rig's lines ({check.family.family.name} and the others) stand highest "
               f"{100 * (check.speed_scale - 1):+.0f} % from it")
    if how is None:
        return speed, uncertainty
    inferred["speed_rpm"] = {"value": refined, "how": how}
    return refined, min(uncertainty, MEASURED_SPEED_UNCERTAINTY)


def _say(text, notes, doubts, stacklevel=2):
    """What the user should hear of a record: noted, kept among its doubts (the meta's
    ``warnings``) and warned (:class:`~cmsim.errors.RecordWarning`), at ``stacklevel`` as
    the function saying it counts (2: its caller)."""
    notes.append(text)
    doubts.append(text)
    warnings.warn(text, RecordWarning, stacklevel=stacklevel + 1)


def _stated_speed(path, file_rpm, entry, speed_rpm, notes, doubts):
    """``(speed, where from)``: the caller's ``speed_rpm`` when given — it replaces what the
    file and metadata.json state, and a value it replaces is warned of
    (:class:`~cmsim.errors.RecordWarning`) and noted — else the file's and the metadata's,
    which must agree (:func:`~cmsim.measured.stated.agreed`)."""
    rpm_doc, rpm_key = documented_speed(entry)
    if speed_rpm is None:
        return agreed(path, "speed", [("the file", "record", file_rpm),
                                      (rpm_key, "record", rpm_doc)], SPEED_TOLERANCE, " rpm")
    for what, value in (("the file", file_rpm), (rpm_key, rpm_doc)):
        if value is not None and abs(float(value) / float(speed_rpm) - 1.0) > 1e-9:
            gap = 100 * (float(speed_rpm) / float(value) - 1)
            text = (f"record {path}: speed_rpm {float(speed_rpm):g} replaces {float(value):g} "
                    f"rpm, the speed {what} states ({gap:+.2g} %)")
            _say(text, notes, doubts, stacklevel=3)
    return float(speed_rpm), "speed_rpm"


def _model_of(path, rig, full, geometry, near, notes, model):
    """``(rig, components)``: the rig given, else the model of the documented geometry
    (:func:`~cmsim.measured.model_rig.model_rig`, its notes first in ``notes``); without
    geometry, refused — or, when no ``model`` is asked for, ``(None, {})`` and a note."""
    if rig is not None:
        return rig, {b: b for b in rig.bearing_names}
    try:
        if full is None:
            raise ParameterError(f"record {path}: {NO_GEOMETRY}", param="rig",
                                 allowed="a rig TOML, or metadata.json with geometry")
        rig, components, rig_notes = model_rig(geometry, near)
    except ParameterError as exc:
        if model or exc.param not in ("rig", "geometry"):
            raise
        notes.append("no geometry documented: read without a model (spectra name the shaft "
                     "harmonics only)")
        return None, {}
    notes[:0] = rig_notes
    return rig, components


def read_record(path, *, channel=None, rig=None, fs_hz=None, speed_rpm=None, unit=None,
                calibration=None, trust_metadata=False, model=True):
    """Read a measured recording into a :class:`MeasuredRecord`.

    Channel names, sample rate, unit, shaft speed and calibration come from the file where
    it states them (:mod:`~cmsim.measured.readers`), else from ``metadata.json`` beside it,
    else from the arguments here (a command line's ``--fs-hz``, ``--speed-rpm``, ``--unit``,
    ``--calibration``); every source that states a value must agree with the others, or
    the record is refused with both values named. Without ``metadata.json`` the file and
    the arguments must give the sample rate, and ``rig`` the model (no geometry is
    documented).

    Parameters
    ----------
    path : str or pathlib.Path
        Signal file (:data:`~cmsim.measured.readers.READERS`: ``.npz``, ``.csv``, ``.wav``,
        ``.mat``, ``.uff``/``.unv``, ``.tdms``), usually in a folder with ``metadata.json``;
        a relative path is also looked up under ``$CMSIM_DATA``.
    channel : str, optional
        Channel to compare; default the first channel whose sensor sits near a documented
        bearing, else the first channel (sorted).
    rig : cmsim.rig.Rig, optional
        Model rig to use instead of the one built from the metadata geometry.
    fs_hz : float, optional
        Sample rate, Hz, when neither the file nor ``metadata.json`` states it.
    speed_rpm : float, optional
        Input-shaft speed, rpm: replaces what the file and ``metadata.json`` state (a value
        it replaces is warned of), and is used as given (not refined from the signal).
    unit : str, optional
        Unit of every channel whose file and ``metadata.json`` state none (``g``,
        ``m/s^2``, ``V``; :func:`~cmsim.measured.schema.checked_unit`), as ``calibration``
        applies to every channel; one they state must agree.
    calibration : float, optional
        Physical units per stored sample value (a WAV in counts or volts), applied to every
        channel, when neither the file nor ``metadata.json`` states it.
    trust_metadata : bool
        Read the stated sample rate and speed as they are, without checking them against
        the record's lines (the user knows them to be right).
    model : bool
        Build the model rig; False reads a recording without geometry all the same (its
        :attr:`MeasuredRecord.rig` is then None: a spectrum, not a comparison).

    Returns
    -------
    MeasuredRecord
        Its meta holds ``rate_check`` (the check's outcome,
        :class:`~cmsim.measured.consistency.RateCheck`), ``speed_uncertainty`` (relative:
        the stated speed's, smaller once refined from the signal), ``bearing_slip`` (how far
        the rolling elements' lines may stand from where the speed puts them besides; a
        spectrum's labels read both) and ``warnings``: what the user
        should hear (a contradiction too weak to refuse the record, a value replaced).

    Raises
    ------
    ParameterError
        Missing file, or no ``metadata.json`` and no sample rate from the file or
        ``fs_hz``; unknown channel (the message lists the file's); a value two sources
        state differently; no way to get the sample rate; a damaged file or channel
        (:mod:`~cmsim.measured.readers`, too few, non-finite or constant samples); a sample
        rate or speed its own lines contradict strongly
        (:func:`~cmsim.measured.consistency.check_rate_and_speed`).
    """
    p = resolve_path(path)
    unit = checked_unit(unit)
    full = read_metadata(p.parent, missing_ok=True)
    meta = {k: (full or {}).get(k) for k in FOLDER_KEYS}
    entry = recording_entry(full or {}, p.name, p.parent / "metadata.json")
    sensors = meta.get("sensors") or {}
    geometry = meta.get("geometry") or {}
    f = read_file(p, entry.get("channels"))
    if full is None and f.rate_hz is None and fs_hz is None:
        why = "".join(f" ({text.removeprefix(f'record {p}: ')})" for text in f.said)
        raise ParameterError(f"record {p}: no metadata.json in {p.parent} and the file states "
                             f"no sample rate{why}: give fs_hz (and speed_rpm, rig), or write "
                             f"the metadata with cmsim import (the record format is the "
                             f"metadata.json schema of the datasets README)", param="record",
                             allowed="a file in a folder with metadata.json, or fs_hz")
    signals = dict(f.signals)
    if not signals:
        raise ParameterError(f"record {p} holds no 1-D channel", param="record")
    scale, _ = agreed(p, "units per stored value", [
        ("the file", "record", f.calibration),
        ('metadata.json "calibration"', "record", entry.get("calibration")),
        ("calibration", "calibration", calibration)], CALIBRATION_TOLERANCE)
    if scale is not None and f.calibration is None:      # the reader applied the file's
        signals = {k: scale * v for k, v in signals.items()}
    channel, x = _channel(signals, sensors, geometry.get("bearings") or {}, channel, str(p))
    sensor = dict(sensors.get(channel) or {})
    stated_units = [("the file", "record", f.units.get(channel)),
                    ('metadata.json "sensors"', "record", sensor.get("unit")),
                    ("unit", "unit", unit)]
    sensor_unit = agreed_unit(p, channel, stated_units)
    quantity, unit_factor = unit_kind(sensor_unit, f"record {p}: channel {channel!r} ("
                                      + next((w for w, _, u in stated_units if u), "") + ")")
    if sensor_unit is not None:
        sensor["unit"] = sensor_unit
    inferred, notes, doubts = {}, list(f.said), list(f.said)   # read_file warned them
    for text in (clipping_doubt(x, channel, p), count_doubt(x, entry.get("n_samples"),
                                                            channel, p)):
        if text is not None:
            _say(text, notes, doubts)
    if scale is None and channel in f.counts and sensor_unit is not None:
        text = (f"record {p}: channel {channel!r} holds integer counts of a converter and no "
                f"calibration states their units: each count is read as 1 {sensor_unit} "
                f"(state the {sensor_unit} per count, in metadata.json \"calibration\" or "
                f"as the command's calibration, where it is not 1)")
        _say(text, notes, doubts)
    speed, speed_from = _stated_speed(p, f.speed_rpm, entry, speed_rpm, notes, doubts)
    fs, fs_from = agreed(p, "sample rate", [
        (f.rate_from, "record", f.rate_hz),
        ('metadata.json "fs_hz"', "record", entry.get("fs_hz") or meta.get("fs_hz")),
        ("fs_hz", "fs_hz", fs_hz)], HEADER_RATE_TOLERANCE, " Hz")
    near = sensor.get("near")
    rig_given = rig is not None
    rig, components = _model_of(p, rig, full, geometry, near, notes, model)
    teeth = None
    if rig is not None and rig.gears is not None:
        teeth = (rig.gears.driving.n_teeth, rig.gears.driven.n_teeth)

    fs = _sample_rate(fs, x, speed, teeth, inferred, notes, meta)
    if quantity in DIFFERENTIATIONS:          # the model's quantity is an acceleration
        x = signals[channel] = _to_acceleration(x, fs, quantity, unit_factor)
        text = (f"record {p}: channel {channel!r} is a {quantity} in {sensor_unit!r}; the "
                f"model's sensors measure acceleration, so it is differentiated "
                f"{DIFFERENTIATIONS[quantity]} (x j2\u03c0f) to m/s^2")
        sensor_unit = sensor["unit"] = "m/s^2"
        _say(text, notes, doubts)
    lines = documented_frequencies(geometry, 1.0)
    if rig_given and not lines.bearings and lines.gmf_hz is None:
        lines = rig_frequencies(rig, OperatingPoint(speed_rpm=60.0))
    uncertainty = speed_uncertainty(entry, speed_from)
    check = None
    if speed is not None:             # before anything is computed on them
        check = _check_against_lines(x, fs, speed, lines, notes, doubts, p,
                                     fs_from or "the inferred rate", speed_from, uncertainty,
                                     trust_metadata)
    if "fs_hz" not in inferred and speed_rpm is None:   # the caller's speed is the speed;
                                                        # an inferred rate is scaled by it
        speed, uncertainty = _refined_speed(x, fs, speed, teeth, check, uncertainty, inferred)
    if speed is not None and not trust_metadata:
        doubt = speed_comb_doubt(x, fs, speed, uncertainty=uncertainty, teeth=teeth, where=p,
                                 fs_source=fs_from or "the inferred rate",
                                 speed_source=speed_from)
        if doubt is not None:
            _say(doubt, notes, doubts)
    op = (model_operating_point(entry, rig, speed, notes) if rig is not None
          else documented_operating_point(entry, speed))

    direction = str(sensor.get("direction", "")).lower()
    axis = "x" if ("horizontal" in direction or "3 o'clock" in direction) else "y"
    bearing = next((b for b in (rig.bearing_names if rig is not None else ())
                    if components.get(b) == near), "1b1")
    n = x.size
    run = Run(np.arange(n) / fs, {c: v for c, v in signals.items() if v.size == n},
              {"fs_hz": fs, "channel": channel, "sensor": sensor or None,
               "units": _channel_units(p, signals, f.units, sensors, channel, sensor_unit,
                                       unit),
               "recording": entry, "operating_point": {
                   "speed_rpm": op.speed_rpm, "torque_nm": op.torque_nm,
                   "radial_load_n": op.radial_load_n,
                   "radial_load_angle_rad": op.radial_load_angle_rad},
               "rig": rig.to_dict() if rig is not None else None, "notes": notes,
               "inferred": inferred,
               "warnings": doubts, "speed_uncertainty": uncertainty,
               "bearing_slip": BEARING_SLIP,
               "rate_check": check.to_dict() if check is not None else None},
              source="measured")
    return MeasuredRecord(
        run=run, channel=channel, rig=rig, op=op, model_signal=f"accel_{bearing}_{axis}",
        components=components, inferred=inferred, path=str(p),
        unit_scale=unit_scale_of(sensor.get("unit")),
        record_id=p.stem, frequencies=documented_frequencies(geometry, speed / 60.0),
        operating_point=documented_operating_point(entry, speed),
        path_documented=rig_given)


def _channel_units(path, signals, file_units, sensors, channel, channel_unit, unit):
    """Channel → unit: the compared channel's ``channel_unit`` (as agreed), every other
    channel's from the file, metadata.json or ``unit`` by the same rule
    (:func:`~cmsim.measured.stated.agreed_unit`), as ``cmsim import`` documents them."""
    out = {c: agreed_unit(path, c, [("the file", "record", file_units.get(c)),
                                    ('metadata.json "sensors"', "record",
                                     (sensors.get(c) or {}).get("unit")),
                                    ("unit", "unit", unit)])
           for c in signals if c != channel}
    out[channel] = channel_unit
    return {c: u for c, u in out.items() if u}


def read_run(path, *, channel=None, rig=None, fs_hz=None, speed_rpm=None, unit=None,
             calibration=None, trust_metadata=False):
    """Any record cmsim writes or reads, as a :class:`~cmsim.run.Run` with its rig and
    operating point: a run (``cmsim simulate``, ``cmsim sweep``), a dataset record
    (``cmsim dataset``) or a measured recording (:func:`read_record`, with every check it
    makes).

    Parameters
    ----------
    path : str or pathlib.Path
        The file. An ``.npz`` holding a ``meta`` array is one cmsim wrote; any other file is
        a measured recording.
    channel : str, optional
        Compared channel of a measured recording (default as :func:`read_record`).
    rig : cmsim.rig.Rig, optional
        Model rig of a measured recording (:func:`read_record`).
    fs_hz : float, optional
        Sample rate of a measured recording, Hz (:func:`read_record`).
    speed_rpm : float, optional
        Input-shaft speed of a measured recording, rpm (:func:`read_record`).
    unit : str, optional
        Unit of a measured recording's channels that state none (:func:`read_record`).
    calibration : float, optional
        Physical units per stored sample value of a measured recording
        (:func:`read_record`).
    trust_metadata : bool
        Read a measured recording's stated rate and speed unchecked (:func:`read_record`).

    Returns
    -------
    run : cmsim.run.Run
    signal : str or None
        The signal to look at by default: a measured recording's compared channel, a dataset
        record's first channel, None for a simulated run (its caller's default).

    Raises
    ------
    ParameterError
        What :func:`read_record` raises; a value given for a file cmsim wrote (its rate,
        speed and rig are its own).
    """
    p = resolve_path(path)
    stated = {"rig": rig, "fs_hz": fs_hz, "speed_rpm": speed_rpm, "unit": unit,
              "calibration": calibration}
    if is_cmsim_run(p):
        given = [k for k, v in stated.items() if v is not None]
        if given:
            raise ParameterError(f"{given[0]}: record {p} is one cmsim wrote (a run or a "
                                 f"dataset record); its rate, speed and rig are its own: "
                                 f"leave out {given[0]}", param=given[0],
                                 allowed="a measured recording")
        run = Run.load(p)
        run.rig, run.operating_point  # noqa: B018 - parse the meta now: a bad one is bad input
        return run, (None if "t" in npz_names(p) else sorted(run.signals)[0])
    rec = read_record(p, channel=channel, trust_metadata=trust_metadata, model=False, **stated)
    if rec.rig is not None and rec.frequencies is not None and not rec.frequencies.bearings:
        # the model rig's bearings are an assumption (the paper rig's): nothing to name by
        rec.run.meta["bearings_documented"] = False
    return rec.run, rec.channel


def record_from_run(run, channel, rig, op, model_signal=None, components=None,
                    unit_scale=None):
    """A :class:`MeasuredRecord` from an in-memory measured run (the test generator's way).

    Parameters
    ----------
    run : cmsim.run.Run
        The measured signals.
    channel : str
        Channel compared.
    rig : cmsim.rig.Rig
        Model rig.
    op : cmsim.rig.OperatingPoint
        Operating point.
    model_signal : str, optional
        Model output of the channel (default: ``channel``).
    components : dict, optional
        Model component → dataset name (default: the rig's bearings by their own names).
    unit_scale : float, optional
        Factor from the channel's unit to m/s² (None: unknown unit).

    Returns
    -------
    MeasuredRecord
    """
    return MeasuredRecord(run=run, channel=channel, rig=rig, op=op,
                          model_signal=model_signal or channel,
                          components=components or {b: b for b in rig.bearing_names},
                          unit_scale=unit_scale)
