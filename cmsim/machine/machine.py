"""A machine: the model of a rig seen through one real machine's sensor (its twin).

The rig says what the physics is; a :class:`Machine` says what this particular housing,
sensor and background do to it, as calibrated on a record of the machine when it was known
to be healthy (:func:`cmsim.machine.calibration.calibrate`). A sensor signal of the machine is

    y(t) = h ∗ F(t) + b(t),

the model's bearing force ``F`` (:func:`model_force`) through the machine's transfer path
``h`` (:class:`~cmsim.machine.path.TransferPath`, minimum phase, in the time domain) plus its
background ``b`` (:class:`~cmsim.machine.background.Background`: coloured noise and the lines
the model does not make). The machine file (TOML, :meth:`Machine.save`) holds the rig, the
identified operating point, the path and background, the baseline's own segment-to-segment
spread of every feature and the fit quality on baseline segments the fit did not use.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import tomli_w

from cmsim._io import atomic_write_text
from cmsim.dynamics import simulate
from cmsim.errors import ParameterError, check_range
from cmsim.features import segment_samples
from cmsim.losses import LossSettings
from cmsim.machine.background import Background, BackgroundLine
from cmsim.frequencies import rig_frequencies
from cmsim.machine.baseline import Baseline
from cmsim.machine.change import Change, apply_change
from cmsim.machine.library import SignatureLibrary
from cmsim.machine.path import TransferPath
from cmsim.rig import RANGES, OperatingPoint, Rig
from cmsim.rig.codec import drop_none
from cmsim.run import signal_info

__all__ = ["Machine", "model_force", "static_load", "rotating_force",
           "MACHINE_FORMAT_VERSION", "EDGE_S"]

#: Version written in a machine file; :meth:`Machine.load` reads it, version 2 (whose
#: segments were ``round(segment_s · fs_hz)`` samples long: read where that is the length
#: :func:`cmsim.features.segment_samples` gives now, refused with a request for a new
#: calibration where it is not, as at SpectraQuest's rate) and version 1 (a twin without its
#: baseline's samples nor a signature library, which compare cannot judge a record with: it
#: asks for a new calibration), and refuses any other.
MACHINE_FORMAT_VERSION = 3

#: Tables a machine file of :data:`MACHINE_FORMAT_VERSION` must hold (a file cut short
#: lacks one and is refused, naming it: the baseline's samples are written last). Its
#: ``library`` is optional (:func:`cmsim.machine.calibrate` does not build it; ``cmsim
#: calibrate`` does).
REQUIRED_TABLES = ("machine", "operating", "rig", "path", "background", "spread",
                   "fit_quality", "baseline")

#: Simulated time dropped at each end of a model force (filter edges), s.
EDGE_S = 0.05


def twin_mesh(rig):
    """The tooth contact a machine's twin is made with: the potential-energy table on a gear
    rig (load-independent, built in about a second for any tooth count, where the hybrid FE
    tables take minutes for a rig other than the paper's), None on a bearing rig. The
    calibration, the comparison and every record made through a machine use it, so that
    the path calibrated on its force is the path its records go through."""
    return "potential-energy" if rig.gears is not None else None


def model_force(rig, op, model_signal, fs_hz, duration_s, seed, *, faults=(),
                mixed_friction=False):
    """The bearing force behind a sensor signal of the model, with spare samples at each end.

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    model_signal : str
        ``accel_<bearing>_<x|y>``: the force is ``F_<bearing>_<x|y>``.
    fs_hz : float
        Sample rate, Hz (at least 1 kHz).
    duration_s : float
        Duration kept, s.
    seed : int
        Seed of the simulation.
    faults : sequence of Fault
        Faults of the model.
    mixed_friction : bool
        Tooth friction from the mixed-lubrication film (``simulate(losses=...)``).

    Returns
    -------
    (numpy.ndarray, int, int)
        The force (N) with ``edge`` extra samples at each end, ``edge``, and the samples
        kept ``n``.
    """
    info = signal_info(model_signal)
    name = f"F_{info.component}_{info.direction}"
    run = simulate(rig, op, duration_s + 2 * EDGE_S, fs_hz=max(fs_hz, 1e3), seed=seed,
                   faults=faults, mesh=twin_mesh(rig), warmup_s=0.1, record=(name,),
                   losses=LossSettings() if mixed_friction else None)
    edge = int(round(EDGE_S * run.fs_hz))
    n = int(round(duration_s * run.fs_hz))
    return np.asarray(run[name], dtype=float)[: n + 2 * edge], edge, n


def _same_segments(data):
    """Refuse a version-2 machine file (parsed) whose segments are not the length cmsim reads
    now (:func:`cmsim.features.segment_samples`): its baseline's spread and its signature
    library were read on segments of another length."""
    try:
        fs_hz = float(data["machine"]["fs_hz"])
        segment_s = float(data["machine"].get("segment_s", 0.5))
    except (KeyError, TypeError, ValueError, AttributeError):
        return                                 # from_dict names what is missing or malformed
    old, now = int(round(segment_s * fs_hz)), segment_samples(fs_hz, segment_s)
    if old != now:
        raise ParameterError(f"this machine file was calibrated on segments of {old} samples; "
                             f"cmsim now reads {segment_s:g}-s segments at {fs_hz:g} Hz as "
                             f"{now} (a length whose FFT is fast): run cmsim calibrate again",
                             param="machine")


def static_load(force):
    """The load a shaft force's relative amplitude refers to: max(|mean|, std) of a bearing
    force, N (its static part, or its swing where that is larger)."""
    force = np.asarray(force, dtype=float)
    return max(abs(float(force.mean())), float(np.std(force)))


def rotating_force(n, fs_hz, shaft_hz, terms, start=0):
    """Rotating forces at shaft orders as a signal: Σ A·cos(2π·k·fr·t + φ) over ``terms``
    ((order k, amplitude A, phase φ) …), on ``n`` samples from sample ``start`` (t = 0 at
    sample 0).

    Parameters
    ----------
    n : int
        Samples.
    fs_hz, shaft_hz : float
        Sample rate and the shaft's rate, Hz.
    terms : sequence of (int, float, float)
        Order, amplitude (any unit), phase (rad).
    start : int
        Index of the first sample.

    Returns
    -------
    numpy.ndarray, shape (n,)
    """
    t = (start + np.arange(n)) / fs_hz
    out = np.zeros(n)
    for k, amp, phase in terms:
        out += amp * np.cos(2.0 * np.pi * k * shaft_hz * t + phase)
    return out


@dataclass(frozen=True, eq=False)
class Machine:
    """One real machine: a rig, its sensor's transfer path and background, calibrated.

    Attributes
    ----------
    name : str
        Free text (the baseline it was calibrated on).
    rig : Rig
        The model rig.
    channel : str
        The measured channel the machine reproduces.
    model_signal : str
        Model output behind the channel (``accel_1b1_y``: the path is applied to
        ``F_1b1_y``).
    fs_hz : float
        Sample rate of the channel, Hz.
    op : OperatingPoint
        Operating point identified on the baseline (speed from the signal).
    path : TransferPath
        Model force → sensor, sensor unit per N.
    background : Background
        Coloured noise and lines, sensor unit.
    unit : str
        Sensor unit as the metadata gives it (``"g"``; ``""`` unknown).
    unit_scale : float or None
        Factor from the sensor unit to m/s² (None: unknown unit).
    components : dict
        Model component → the machine's name for it (``{"1b1": "drive_end"}``).
    segment_s : float
        Segment length the features and their spread are computed on, s.
    speed_wobble : float or None
        Relative RMS of the input speed's slow fluctuation seen on the baseline (None: not
        identifiable on it, no shaft order standing out of its noise).
    shaft_gain : dict
        Order of the sensor bearing's shaft → gain from a rotating force at that order (an
        unbalance, a misalignment) to the sensor, sensor unit per N, read from the
        baseline's line there (:func:`~cmsim.machine.calibration.calibrate`); an order not
        listed takes the path's gain.
    spread : dict
        Feature name → (mean, std) over the baseline's segments.
    fit_quality : dict
        On baseline segments the fit did not use: ``z`` (feature → (twin − baseline) /
        spread), ``worst_feature``, ``worst_z``, ``chi2_per_feature``.
    calibrated_on : tuple of str
        The baseline records and the segments used.
    notes : tuple of str
        What was assumed (an unidentified path gain, an undocumented load ...).
    assumed_load : tuple of str
        The loads of :attr:`op` (``torque_nm``, ``radial_load_n``) its baseline did not
        document: the model's assumption, no measurement a record's documented load can be
        compared with (:func:`cmsim.discrepancy.operating_point.record_load`).
    baseline : Baseline or None
        The healthy record(s) it was calibrated on: the healthy prediction of every
        comparison and the healthy stretches of its dataset records (None: a version-1
        machine file).
    library : SignatureLibrary or None
        What each cause does to the baseline's features (None: not built yet).
    """

    name: str
    rig: Rig
    channel: str
    model_signal: str
    fs_hz: float
    op: OperatingPoint
    path: TransferPath
    background: Background
    unit: str = ""
    unit_scale: float | None = None
    components: dict = field(default_factory=dict)
    segment_s: float = 0.5
    speed_wobble: float | None = None
    shaft_gain: dict = field(default_factory=dict)
    spread: dict = field(default_factory=dict)
    fit_quality: dict = field(default_factory=dict)
    calibrated_on: tuple = ()
    notes: tuple = ()
    assumed_load: tuple = ()
    baseline: Baseline | None = None
    library: SignatureLibrary | None = None

    @property
    def shaft_hz(self):
        """(input, output) shaft rates at the machine's operating point, Hz."""
        fr1 = self.op.speed_rpm / 60.0
        return (fr1, fr1 / self.rig.gears.ratio if self.rig.gears is not None else fr1)

    def sensor_signal(self, force, edge, n, seed, *, speed_rpm=None, frequency_factor=1.0,
                      noise_gain=1.0, line_gain=1.0, rotating=None, white_noise=0.0,
                      line_seed=None):
        """The machine's sensor signal of a model force (:func:`model_force`'s output).

        Parameters
        ----------
        force : numpy.ndarray
            Model force, N, at :attr:`fs_hz`, with ``edge`` spare samples at each end.
        edge, n : int
            Spare samples at each end, samples kept.
        seed : int
            Seed of the background (noise and line phases).
        speed_rpm : float, optional
            Input speed the shaft-order lines follow (default the machine's).
        frequency_factor : float
            Scale of the path's frequencies (1 as calibrated).
        noise_gain, line_gain : float
            Factors on the background noise and lines (1 as calibrated).
        rotating : (float, sequence of (int, float, float)), optional
            Rotating forces at shaft orders, not in ``force``: the shaft's rate (Hz) and
            (order, amplitude N, phase rad) of each, ``A·cos(2π·k·fr·t + φ)`` with t = 0 at
            the force's first sample; each reaches the sensor through :attr:`shaft_gain`.
        white_noise : float
            White noise added at the sensor, RMS relative to the calibrated background
            noise's (a noise the machine's baseline did not have: a sensor, a cable, a
            loose mount).
        line_seed : int, optional
            Seed of the background lines' phases alone (default: drawn with the noise from
            ``seed``): records of one machine share their lines' phases (whether its mesh is
            amplitude- or phase-modulated is the machine's) and differ in their noise.

        Returns
        -------
        numpy.ndarray, shape (n,)
            Sensor unit.
        """
        y = self.path.apply(force, self.fs_hz, frequency_factor)[edge:edge + n]
        if rotating is not None:
            fr, terms = rotating
            y = y + rotating_force(n, self.fs_hz, fr, [(k, self.rotating_gain(k, fr) * amp, ph)
                                                       for k, amp, ph in terms], start=edge)
        fr1 = (self.op.speed_rpm if speed_rpm is None else speed_rpm) / 60.0
        fr2 = fr1 / self.rig.gears.ratio if self.rig.gears is not None else fr1
        rng = np.random.default_rng([int(seed), 104729])
        y = y + self.background.synthesize(
            n, self.fs_hz, (fr1, fr2), rng, noise_gain, line_gain,
            line_rng=None if line_seed is None else np.random.default_rng([int(line_seed),
                                                                           104729]))
        if white_noise > 0.0:
            y = y + white_noise * self.background.noise_rms(self.fs_hz) \
                * rng.standard_normal(n)
        return y - y.mean()

    def rotating_gain(self, order, shaft_hz):
        """Gain from a rotating force at ``order`` of a shaft turning at ``shaft_hz`` to the
        sensor, sensor unit per N: :attr:`shaft_gain`'s; at an order the baseline pins no
        gain at, the path's at that frequency times the ratio of the nearest pinned order's
        gain to the path's there (the lower of two as near); the path's alone where no order
        is pinned. The structural path is read hundreds of hertz up and its shape carried
        down; where shaft orders are pinned they read the shaft lines 30 to 27 500 times
        over it on the angle-domain generator's gear machines and 170-210 times on
        SpectraQuest's gearbox, so the path alone took an unbalance's 1× line 60 dB under
        the 2× and 3× lines of the same shaft's pinned gains (angle gear machine 7: the
        unbalance made no 1× line and was read as an eccentric gear)."""
        gain = self.shaft_gain.get(int(order))
        if gain:
            return float(gain)
        path = float(self.path.magnitude(order * shaft_hz))
        if not self.shaft_gain:
            return path
        near = min(self.shaft_gain, key=lambda k: (abs(k - order), k))
        return path * float(self.shaft_gain[near]) / float(self.path.magnitude(near * shaft_hz))

    @property
    def force_signals(self):
        """The simulated force components the machine's channel is made from."""
        info = signal_info(self.model_signal)
        return (f"F_{info.component}_x", f"F_{info.component}_y")

    def sensor_channel(self, run, seed, healthy=None):
        """``run`` with the machine's sensor channel added (``run`` made at :attr:`fs_hz` on
        :attr:`rig`).

        With the machine's baseline (every machine :func:`~cmsim.machine.calibrate` makes):
        a stretch of the baseline, drawn from ``seed``, with the change from ``healthy`` to
        ``run`` laid on it (:func:`cmsim.machine.change.apply_change`) — the machine's own
        healthy signal and what the model says the run's faults and operating point change
        on it. ``healthy`` is the same model run (the same seed, duration and warm-up) on the
        machine's rig at its operating point without the run's faults; None when ``run`` is that
        run itself (the stretch alone). Without a baseline (a version-1 machine file): the
        model force through the machine's path plus its background (its shaft-order lines
        follow the run's speed).

        Parameters
        ----------
        run : cmsim.run.Run
            A simulated run holding the force of :attr:`model_signal`'s bearing.
        seed : int
            Seed of the baseline stretch (or of the background).
        healthy : cmsim.run.Run, optional
            The healthy reference run (see above).

        Returns
        -------
        cmsim.run.Run
        """
        if abs(run.fs_hz / self.fs_hz - 1.0) > 1e-6:
            raise ParameterError(f"a run at {run.fs_hz:g} Hz cannot go through machine "
                                 f"{self.name!r}, calibrated at {self.fs_hz:g} Hz",
                                 param="machine")
        info = signal_info(self.model_signal)
        name = f"F_{info.component}_{info.direction}"
        force = np.asarray(run[name], dtype=float)
        meta = {"name": self.name, "channel": self.channel, "unit": self.unit,
                "model_signal": self.model_signal}
        if self.baseline is None:
            y = self.sensor_signal(force, 0, force.size, seed,
                                   speed_rpm=run.operating_point.speed_rpm)
            return run.with_signals(**{self.channel: y}).with_meta(
                machine={**meta, "made_as": "model force through the path + background"})
        rng = np.random.default_rng([int(seed), 104729])
        piece = self.baseline.piece(force.size, rng)[None, :]
        if healthy is not None:
            base = np.asarray(healthy[name], dtype=float)
            freqs = rig_frequencies(self.rig, self.op)
            gmf = freqs.gmf_hz
            change = Change(force=force, healthy=base,
                            shaft_hz=freqs.bearing(info.component).shaft_hz,
                            input_hz=freqs.fr1_hz,
                            pin_hz=() if not gmf else tuple(
                                k * gmf for k in range(1, int(0.5 * self.fs_hz / gmf) + 1)))
            piece = apply_change(self, piece, change, rng)
        y = piece[0] - piece[0].mean()
        return run.with_signals(**{self.channel: y}).with_meta(
            machine={**meta, "made_as": "baseline stretch + the model's change"
                     + ("" if healthy is not None else " (none: the machine's healthy state)")})

    def needs_reference(self, op, faults=(), profile=None, rig=None):
        """Whether a run at ``op`` with ``faults`` (a speed ``profile``, on ``rig``) needs a
        healthy reference run for :meth:`sensor_channel`: the machine has a baseline and the
        run is not the machine's healthy state (a fault, another operating point, a run-up,
        another rig — a clearance the dataset varies).

        Parameters
        ----------
        op : OperatingPoint
        faults : sequence of Fault
        profile : SpeedProfile, optional
        rig : Rig, optional
            The run's rig (default the machine's).
        """
        if self.baseline is None:
            return False
        return bool(faults) or profile is not None or (rig is not None and rig != self.rig) \
            or not (
            math.isclose(op.speed_rpm, self.op.speed_rpm, rel_tol=1e-9)
            and math.isclose(op.torque_nm, self.op.torque_nm, rel_tol=1e-9, abs_tol=1e-12)
            and math.isclose(op.radial_load_n, self.op.radial_load_n, rel_tol=1e-9,
                             abs_tol=1e-12))

    def with_rig(self, rig):
        """The same machine on another model rig (a fault, another clearance)."""
        return replace(self, rig=rig)

    def with_library(self, library):
        """The same machine with its signature library."""
        return replace(self, library=library)

    # ------------------------------------------------------------------ file
    def to_dict(self):
        """Plain nested dict (TOML-ready) with a format version."""
        return {
            # a machine without its baseline's samples (made in Python, or read from a
            # version-1 file) is what version 1 holds
            "format_version": MACHINE_FORMAT_VERSION if self.baseline is not None else 1,
            "machine": {"name": self.name, "channel": self.channel,
                        "model_signal": self.model_signal, "fs_hz": self.fs_hz,
                        "unit": self.unit,
                        "unit_scale": -1.0 if self.unit_scale is None else self.unit_scale,
                        "segment_s": self.segment_s,
                        "speed_wobble": -1.0 if self.speed_wobble is None else self.speed_wobble,
                        "components": dict(self.components),
                        "shaft_gain": {str(k): float(v) for k, v in self.shaft_gain.items()},
                        "calibrated_on": list(self.calibrated_on), "notes": list(self.notes),
                        "assumed_load": list(self.assumed_load)},
            "operating": {"speed_rpm": self.op.speed_rpm, "torque_nm": self.op.torque_nm,
                          "radial_load_n": self.op.radial_load_n,
                          "radial_load_angle_rad": self.op.radial_load_angle_rad},
            "rig": drop_none(self.rig.to_dict()),
            "path": self.path.to_dict(),
            "background": self.background.to_dict(),
            "spread": {k: [float(m), float(s)] for k, (m, s) in self.spread.items()},
            "fit_quality": _finite(self.fit_quality),
            **({"library": self.library.to_dict()} if self.library is not None else {}),
            **({"baseline": self.baseline.to_dict()} if self.baseline is not None else {}),
        }

    @classmethod
    def from_dict(cls, data):
        """Machine from :meth:`to_dict` output (every table checked).

        Parameters
        ----------
        data : dict
            The parsed machine file.
        """
        version = data.get("format_version")
        if version is None and "machine" not in data:
            raise ParameterError("not a machine file (no format_version nor [machine] table; "
                                 "cmsim calibrate --out writes one)", param="machine")
        if version not in (1, 2, MACHINE_FORMAT_VERSION):
            raise ParameterError(f"machine format_version {version!r} is not supported (this "
                                 f"cmsim reads versions 1 to {MACHINE_FORMAT_VERSION})",
                                 param="machine")
        if version in (2, 3):
            missing = [t for t in REQUIRED_TABLES if t not in data]
            if missing:
                raise ParameterError(f"not a whole machine file (it lacks "
                                     f"{', '.join(repr(t) for t in missing)}: cut short? cmsim "
                                     "calibrate --out writes one)", param="machine")
        if version == 2:
            _same_segments(data)
        try:
            m, o, p, b = data["machine"], data["operating"], data["path"], data["background"]
            if "fs_hz" in m:                        # values edited by hand: checked
                RANGES["fs_hz"].check('[machine] "fs_hz"', m["fs_hz"])
            if "segment_s" in m:
                check_range('[machine] "segment_s"', m["segment_s"], 0.0, 60.0, lo_open=True)
            scale = float(m["unit_scale"])
            wobble = float(m.get("speed_wobble", -1.0))
            return cls(
                name=str(m["name"]), rig=Rig.from_dict(data["rig"]), channel=str(m["channel"]),
                model_signal=str(m["model_signal"]), fs_hz=float(m["fs_hz"]),
                op=OperatingPoint(**{k: float(v) for k, v in o.items()}),
                path=TransferPath(str(p["source"]), tuple(p["freq_hz"]), tuple(p["gain"]),
                                  str(p.get("unit", ""))),
                background=Background(tuple(b["freq_hz"]), tuple(b["psd"]), tuple(
                    BackgroundLine(str(ln["reference"]), float(ln["value"]),
                                   float(ln["amplitude"])) for ln in b.get("lines", ()))),
                unit=str(m.get("unit", "")), unit_scale=None if scale < 0 else scale,
                components=dict(m.get("components", {})),
                segment_s=float(m.get("segment_s", 0.5)),
                speed_wobble=None if wobble < 0 else wobble,
                shaft_gain={int(k): float(v) for k, v in m.get("shaft_gain", {}).items()},
                spread={k: (float(v[0]), float(v[1])) for k, v in data.get("spread", {}).items()},
                fit_quality=dict(data.get("fit_quality", {})),
                calibrated_on=tuple(m.get("calibrated_on", ())), notes=tuple(m.get("notes", ())),
                assumed_load=tuple(str(k) for k in m.get("assumed_load", ())
                                   if k in ("torque_nm", "radial_load_n")),
                baseline=Baseline.from_dict(data["baseline"]) if "baseline" in data else None,
                library=(SignatureLibrary.from_dict(data["library"]) if "library" in data
                         else None))
        except KeyError as exc:
            raise ParameterError(f"not a machine file (it lacks {exc.args[0]!r})",
                                 param="machine") from None
        except (TypeError, ValueError, IndexError) as exc:
            raise ParameterError(f"not a machine file (a malformed value: {exc})",
                                 param="machine") from None

    def save(self, path):
        """Write the machine file (TOML, atomically).

        Parameters
        ----------
        path : str or pathlib.Path
            The file.
        """
        text = ("# cmsim machine: a rig calibrated on a healthy baseline of one machine "
                "(cmsim calibrate); auto-generated.\n" + tomli_w.dumps(self.to_dict()))
        atomic_write_text(Path(path), text)

    @classmethod
    def load(cls, path):
        """Read a machine file written by :meth:`save`.

        Parameters
        ----------
        path : str or pathlib.Path
            The file.

        Raises
        ------
        ParameterError
            Missing, unreadable or not a machine file (the message names the file).
        """
        path = Path(path)
        try:
            with path.open("rb") as fh:
                data = tomllib.load(fh)
        except FileNotFoundError:
            raise ParameterError(f"machine file {path} does not exist", param="machine") \
                from None
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise ParameterError(f"machine file {path} cannot be read as TOML ({exc})",
                                 param="machine") from None
        try:
            return cls.from_dict(data)
        except ParameterError as exc:
            raise ParameterError(f"machine file {path}: {exc}", param="machine") from None


def _finite(d):
    """``d`` with non-finite floats dropped (TOML has no NaN a reader would expect)."""
    if isinstance(d, dict):
        return {k: _finite(v) for k, v in d.items()
                if not (isinstance(v, float) and not math.isfinite(v))}
    if isinstance(d, (list, tuple)):
        return [_finite(x) for x in d]
    return d
