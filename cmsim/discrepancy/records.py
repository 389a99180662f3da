"""Measured records: a dataset folder's ``metadata.json`` + one signal file → a measured Run.

Format (``../shared/datasets/README.md``; users' own records follow the same schema): a folder
holds ``metadata.json`` and one file per recording, ``.npz`` (one 1-D array per channel),
``.csv`` (one column per channel, a header row of channel names) or ``.wav`` (one channel per
WAV channel, named ``ch0``, ``ch1``, … unless ``channels`` lists the names; the WAV rate is
the sample rate). ``metadata.json`` gives ``fs_hz`` (or ``null``), ``sensors`` (channel →
``near``/``direction``/``unit``), ``geometry.bearings`` (bearing key → ``n_balls``,
``ball_diameter_mm``, ``pitch_diameter_mm``, ``contact_angle_deg``, ``shaft``),
``geometry.gears`` (stages with ``input_teeth``/``output_teeth``) and ``recordings[]``
(``file``, ``fs_hz``, ``shaft_speed_rpm``, load fields ``torque_nm``, ``motor_load_hp``,
``radial_load_lbs``, ``load_percent``).

Only the keys listed in :data:`RECORDING_KEYS` are read from a recording entry: the answer key
(``condition``, ``fault``, ``fault_*``, expected defect frequencies) and the file name never
reach the pipeline (the file name only locates the entry).

What the metadata lacks is inferred from the signal and reported in
:attr:`MeasuredRecord.inferred`: the sample rate of a gear record from the mesh comb of the
documented tooth counts at the documented speed, and the shaft speed from the shaft-harmonic
comb (refined within ±3 % of a documented speed).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.io import wavfile

from cmsim.errors import ParameterError
from cmsim.frequencies import rig_frequencies
from cmsim.rig import OperatingPoint, Rig, RollingBearing, Rotor
from cmsim.run import Run

__all__ = ["MeasuredRecord", "read_record", "record_from_run", "RECORDING_KEYS",
           "DEFAULT_ROTOR_MASS_KG", "estimate_shaft_hz", "LBF_N", "unit_scale_of",
           "ACCELERATION_UNITS"]

#: Recording-entry keys the pipeline reads; everything else (the answer key) is ignored.
RECORDING_KEYS = ("file", "n_samples", "fs_hz", "shaft_speed_rpm", "shaft_speed_hz",
                  "torque_nm", "motor_load_hp", "radial_load_lbs", "radial_load_n",
                  "load_percent", "channels", "segment")

#: Rotor mass assumed for a bearing rig whose rotor is not documented, kg.
DEFAULT_ROTOR_MASS_KG = 10.0

#: Newtons per pound-force.
LBF_N = 4.4482216

_G = 9.80665


@dataclass(frozen=True)
class MeasuredRecord:
    """A measured record ready for comparison with the model.

    Attributes
    ----------
    run : Run
        ``source="measured"``; signals named as the dataset's channels (unit as recorded).
    channel : str
        Channel compared.
    rig : Rig
        Model rig built from the metadata geometry (bearing ``1b1`` = the channel's bearing).
    op : OperatingPoint
        Speed (documented or inferred), torque and radial load (N, the rotor weight plus the
        documented radial load).
    model_signal : str
        Model output that corresponds to the channel (``accel_1b1_y``, …).
    components : dict of str to str
        Model component → dataset name (``{"1b1": "drive_end"}``).
    inferred : dict
        Quantity → ``{"value": …, "how": …}`` for what was inferred from the signal.
    path : str
        The signal file.
    unit_scale : float or None
        Factor from the channel's unit to m/s² (``g`` → 9.80665), or None when the unit is
        not an acceleration unit cmsim knows: then only scale-free features are compared.
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

    @property
    def fs_hz(self):
        """Sample rate (documented or inferred), Hz."""
        return self.run.fs_hz

    @property
    def signal(self):
        """The compared channel, float64 with the mean removed."""
        x = np.asarray(self.run[self.channel], dtype=float)
        return x - x.mean()

    def frequencies(self, speed_rpm=None):
        """:class:`~cmsim.frequencies.RigFrequencies` of the model rig at the record's speed."""
        op = self.op if speed_rpm is None else replace(self.op, speed_rpm=speed_rpm)
        return rig_frequencies(self.rig, op)


# ---------------------------------------------------------------------- files
def _resolve(path):
    p = Path(path)
    if p.exists():
        return p
    root = os.environ.get("CMSIM_DATA")
    if root and not p.is_absolute():
        q = Path(root) / p
        if q.exists():
            return q
    where = f" (nor under CMSIM_DATA={root})" if root else " (set CMSIM_DATA to a data root)"
    raise ParameterError(f"record {path} does not exist{where}", param="record",
                         allowed="an existing .npz, .csv or .wav file")


def _read_signals(path, names=None):
    """Channel name → float64 array, and the WAV rate (else None)."""
    suffix = path.suffix.lower()
    if suffix == ".npz":
        with np.load(path, allow_pickle=False) as z:
            data = {k: np.asarray(z[k], dtype=float) for k in z.files
                    if np.ndim(z[k]) == 1 and k not in ("t", "meta", "source")}
        return data, None
    if suffix == ".csv":
        import pandas as pd
        df = pd.read_csv(path)
        return {str(c): df[c].to_numpy(dtype=float) for c in df.columns}, None
    if suffix == ".wav":
        rate, x = wavfile.read(path)
        x = np.asarray(x, dtype=float)
        x = x[:, None] if x.ndim == 1 else x
        names = list(names or []) or [f"ch{i}" for i in range(x.shape[1])]
        if len(names) != x.shape[1]:
            names = [f"ch{i}" for i in range(x.shape[1])]
        return {n: x[:, i] for i, n in enumerate(names)}, float(rate)
    raise ParameterError(f"record {path}: unsupported file type {suffix!r}", param="record",
                         allowed=".npz, .csv or .wav")


def _metadata(path):
    meta_path = path.parent / "metadata.json"
    if not meta_path.exists():
        raise ParameterError(f"no metadata.json next to {path} (the record format is the "
                             f"metadata.json schema of the datasets README)", param="record",
                             allowed="a file in a folder with metadata.json")
    try:
        meta = json.loads(meta_path.read_text())
    except (ValueError, OSError) as exc:
        raise ParameterError(f"{meta_path}: not valid JSON ({exc})", param="record") from None
    entry = {}
    for rec in meta.get("recordings") or []:
        if rec.get("file") == path.name:
            entry = {k: rec[k] for k in RECORDING_KEYS if k in rec}
    clean = {k: meta.get(k) for k in ("fs_hz", "channels", "sensors", "geometry")}
    return clean, entry


# ---------------------------------------------------------------------- model rig
def _bearing(geom):
    try:
        n = int(geom["n_balls"])
        d = float(geom["ball_diameter_mm"]) * 1e-3
        pd_ = float(geom["pitch_diameter_mm"]) * 1e-3
    except (KeyError, TypeError, ValueError):
        raise ParameterError(f"bearing geometry needs n_balls, ball_diameter_mm and "
                             f"pitch_diameter_mm, got {geom!r}", param="geometry.bearings")
    return RollingBearing.from_pitch(n, d, pd_, clearance_m=5e-6)


def _gear_rig(stage):
    """Paper rig with the documented tooth counts (other gear data undocumented)."""
    base = Rig.paper_2016()
    g = base.gears
    z1, z2 = int(stage["input_teeth"]), int(stage["output_teeth"])
    pair = replace(g, driving=replace(g.driving, n_teeth=z1),
                   driven=replace(g.driven, n_teeth=z2))
    return replace(base, gears=pair)


def _model_rig(geometry, near):
    """(rig, components, notes) from metadata geometry; ``near`` = the channel's bearing key."""
    geometry = geometry or {}
    bearings = geometry.get("bearings") or {}
    gears = [s for s in (geometry.get("gears") or [])
             if s.get("input_teeth") and s.get("output_teeth")]
    if gears:
        rig = _gear_rig(gears[0])
        return rig, {"1G1": "input gear", "2G1": "output gear"}, \
            ["gear data beyond tooth counts undocumented: the paper rig's gears and 209 "
             "bearings with the documented tooth counts"]
    if not bearings:
        raise ParameterError("metadata.json has neither bearing geometry nor gear tooth "
                             "counts: give a rig with --rig", param="geometry",
                             allowed="geometry.bearings or geometry.gears")
    keys = list(bearings)
    first = near if near in bearings else keys[0]
    other = next((k for k in keys if k != first), first)
    rig = Rig.rotor_on_bearings(_bearing(bearings[first]),
                                Rotor(mass_kg=DEFAULT_ROTOR_MASS_KG, inertia_kg_m2=0.02),
                                bearing_2=_bearing(bearings[other]))
    return rig, {"1b1": first, "1b2": other}, [
        f"rotor {DEFAULT_ROTOR_MASS_KG:g} kg assumed (undocumented)"]


# ---------------------------------------------------------------------- inference
def _prominence_db(freq, amp, f, floor, tol):
    """Peak within f·(1 ± tol) over the floor, dB, and the peak frequency."""
    sel = (freq >= f * (1 - tol)) & (freq <= f * (1 + tol))
    if not np.any(sel):
        return -np.inf, f
    i = np.argmax(amp[sel])
    return 20 * math.log10(max(amp[sel][i], 1e-300) / floor), float(freq[sel][i])


def _log_spectrum(x, fs):
    n = x.size
    win = np.hanning(n)
    amp = np.abs(np.fft.rfft((x - x.mean()) * win)) * 2 / win.sum()
    freq = np.fft.rfftfreq(n, 1 / fs)
    return freq, amp


def estimate_shaft_hz(x, fs_hz, *, lo_hz, hi_hz, teeth=None, n_harmonics=4):
    """Input-shaft rate that best explains the spectrum's comb of shaft harmonics.

    Parameters
    ----------
    x : ndarray
        Signal.
    fs_hz : float
        Sample rate, Hz.
    lo_hz, hi_hz : float
        Search range of the shaft rate, Hz.
    teeth : tuple of int, optional
        (Z1, Z2): the mesh comb k·Z1·f (k = 1..3) and the output shaft f·Z1/Z2 are added.
    n_harmonics : int
        Shaft harmonics in the comb.

    Returns
    -------
    (float, float)
        Shaft rate, Hz, and the comb score (mean prominence of its lines over the median
        spectrum level, dB).
    """
    freq, amp = _log_spectrum(np.asarray(x, dtype=float), fs_hz)
    df = freq[1]
    logamp = np.log10(np.maximum(amp, 1e-300))
    # local floor: running median in log (robust), evaluated on a coarse grid
    floor = 10 ** np.median(logamp[1:])
    n_grid = int(min(20000, max(200, (hi_hz - lo_hz) / (df / 4))))
    grid = np.geomspace(lo_hz, hi_hz, n_grid)
    best = (-np.inf, grid[0])
    mults = [float(m) for m in range(1, n_harmonics + 1)]
    if teeth is not None:
        z1, z2 = teeth
        mults = [1.0, 2.0, z1 / z2] + [k * z1 for k in (1, 2, 3)]
    for f in grid:
        s, n = 0.0, 0
        for m in mults:
            fm = m * f
            if fm >= fs_hz / 2 or fm < 2 * df:
                continue
            k = int(round(fm / df))
            s += 20 * (np.max(logamp[max(k - 1, 1):k + 2]) - math.log10(floor))
            n += 1
        if n and s / n > best[0]:
            best = (s / n, f)
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


def _infer_fs_gear(x, shaft_hz, teeth):
    """Sample rate of a gear record with undocumented fs: the mesh comb in cycles/sample."""
    nu, score = estimate_shaft_hz(x, 1.0, lo_hz=2e-4, hi_hz=0.45 / (3 * teeth[0]),
                                  teeth=teeth)
    return shaft_hz / nu, nu, score


# ---------------------------------------------------------------------- reader
def read_record(path, *, channel=None, rig=None):
    """Read a measured record (metadata.json schema) into a :class:`MeasuredRecord`.

    Parameters
    ----------
    path : str or Path
        Signal file (.npz, .csv, .wav) in a folder with ``metadata.json``; relative paths
        are also looked up under ``$CMSIM_DATA``.
    channel : str, optional
        Channel to compare; default the first channel whose sensor sits near a documented
        bearing, else the first channel.
    rig : Rig, optional
        Model rig to use instead of the one built from the metadata geometry.

    Returns
    -------
    MeasuredRecord

    Raises
    ------
    ParameterError
        Missing file or metadata, unknown channel, no way to get the sample rate.
    """
    p = _resolve(path)
    meta, entry = _metadata(p)
    sensors = meta.get("sensors") or {}
    signals, wav_rate = _read_signals(p, entry.get("channels"))
    if not signals:
        raise ParameterError(f"record {p} holds no 1-D channel", param="record")
    bearings = ((meta.get("geometry") or {}).get("bearings")) or {}
    if channel is None:
        near_bearing = [c for c in signals if (sensors.get(c) or {}).get("near") in bearings]
        channel = near_bearing[0] if near_bearing else sorted(signals)[0]
    if channel not in signals:
        raise ParameterError(f"channel {channel!r} is not in {p.name}; available: "
                             f"{sorted(signals)}", param="--channel",
                             allowed=", ".join(sorted(signals)))
    x = signals[channel]
    if x.size < 4096 or not np.all(np.isfinite(x)):
        raise ParameterError(f"channel {channel!r} must hold >= 4096 finite samples, got "
                             f"{x.size}", param="--channel")
    near = (sensors.get(channel) or {}).get("near")
    inferred = {}
    notes = []
    if rig is None:
        model_rig, components, notes = _model_rig(meta.get("geometry"), near)
    else:
        model_rig = rig
        components = {b: b for b in rig.bearing_names}
    teeth = None
    if model_rig.gears is not None:
        teeth = (model_rig.gears.driving.n_teeth, model_rig.gears.driven.n_teeth)

    speed_rpm = entry.get("shaft_speed_rpm")
    if speed_rpm is None and entry.get("shaft_speed_hz") is not None:
        speed_rpm = 60.0 * float(entry["shaft_speed_hz"])
    fs = entry.get("fs_hz", meta.get("fs_hz")) or wav_rate
    if fs is None:
        if teeth is None or speed_rpm is None:
            raise ParameterError("fs_hz is undocumented and cannot be inferred (needs gear "
                                 "tooth counts and a shaft speed)", param="fs_hz",
                                 allowed="a number > 0 in metadata.json")
        fs, nu, score = _infer_fs_gear(x, float(speed_rpm) / 60.0, teeth)
        inferred["fs_hz"] = {"value": fs, "how": f"mesh comb of {teeth[0]}:{teeth[1]} teeth at "
                             f"{nu:.6g} cycles/sample (shaft line), {score:.1f} dB over the "
                             f"median level, scaled by the documented speed"}
    fs = float(fs)
    if speed_rpm is None:
        f, score = estimate_shaft_hz(x, fs, lo_hz=5.0, hi_hz=min(100.0, fs / 40), teeth=teeth)
        speed_rpm = 60.0 * f
        inferred["speed_rpm"] = {"value": speed_rpm, "how": f"shaft-harmonic comb, "
                                 f"{score:.1f} dB over the median level"}
    elif "fs_hz" not in inferred:
        f0 = float(speed_rpm) / 60.0
        f, score = estimate_shaft_hz(x, fs, lo_hz=0.97 * f0, hi_hz=1.03 * f0, teeth=teeth)
        if score > 10.0 and abs(f / f0 - 1) > 2e-3:
            inferred["speed_rpm"] = {"value": 60.0 * f, "how": f"refined from the documented "
                                     f"{float(speed_rpm):g} rpm by the shaft-harmonic comb "
                                     f"({score:.1f} dB)"}
            speed_rpm = 60.0 * f
    speed_rpm = float(speed_rpm)

    radial = DEFAULT_ROTOR_MASS_KG * _G if model_rig.gears is None else 0.0
    if entry.get("radial_load_n") is not None:
        radial += float(entry["radial_load_n"])
    elif entry.get("radial_load_lbs") is not None:
        radial += LBF_N * float(entry["radial_load_lbs"])
    torque = 0.0
    if model_rig.gears is not None:
        if entry.get("torque_nm") is not None:
            torque = float(entry["torque_nm"])
        else:
            pct = entry.get("load_percent")
            torque = 20.0 if pct is None else 5.0 + 0.4 * float(pct)
            notes.append(f"output torque {torque:g} N m assumed from load_percent={pct} "
                         "(brake capacity undocumented)")
    op = OperatingPoint(speed_rpm=speed_rpm, torque_nm=torque, radial_load_n=radial,
                        radial_load_angle_rad=-math.pi / 2)
    direction = str((sensors.get(channel) or {}).get("direction", "")).lower()
    axis = "x" if ("horizontal" in direction or "3 o'clock" in direction) else "y"
    bearing = "1b1"
    if model_rig.gears is None:
        bearing = next((b for b, key in components.items() if key == near), "1b1")
    model_signal = f"accel_{bearing}_{axis}"
    n = x.size
    run = Run(np.arange(n) / fs, {c: v for c, v in signals.items() if v.size == n},
              {"fs_hz": fs, "channel": channel,
               "sensor": sensors.get(channel), "operating_point": {
                   "speed_rpm": op.speed_rpm, "torque_nm": op.torque_nm,
                   "radial_load_n": op.radial_load_n,
                   "radial_load_angle_rad": op.radial_load_angle_rad},
               "rig": model_rig.to_dict(), "notes": notes,
               "inferred": inferred}, source="measured")
    return MeasuredRecord(run=run, channel=channel, rig=model_rig, op=op,
                          model_signal=model_signal, components=components,
                          inferred=inferred, path=str(p),
                          unit_scale=unit_scale_of((sensors.get(channel) or {}).get("unit")))


def record_from_run(run, channel, rig, op, model_signal=None, components=None,
                    unit_scale=None):
    """A :class:`MeasuredRecord` from an in-memory measured run (the test generator's way).

    Parameters
    ----------
    run : Run
        The measured signals.
    channel : str
        Channel compared.
    rig : Rig
        Model rig.
    op : OperatingPoint
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


#: Accelerometer units cmsim converts to m/s² (the first word of a metadata ``unit``).
ACCELERATION_UNITS = {"g": _G, "m/s2": 1.0, "m/s^2": 1.0, "m/s²": 1.0, "mm/s2": 1e-3,
                      "mm/s^2": 1e-3}


def unit_scale_of(unit):
    """Factor from an accelerometer unit (``"g"``, ``"g (believed)"``, ``"m/s^2"``) to m/s²,
    or None for anything else (volts, an unknown unit).

    Parameters
    ----------
    unit : str or None

    Returns
    -------
    float or None
    """
    if not isinstance(unit, str) or not unit.strip():
        return None
    return ACCELERATION_UNITS.get(unit.strip().split()[0].lower())
