"""A second generator of "measured" records, independent of cmsim's model: angle-domain
synthesis of a machine, written to a folder in the ``metadata.json`` schema of real records.

The hidden-effect benchmark's first generator (:mod:`cmsim.discrepancy.synthetic`) makes its
records with cmsim's own dynamics, so a comparison that knows that model sees them through
its own eyes. This one shares no code with cmsim's model (numpy and scipy, its own kinematic
formulas; of cmsim only the ``g`` of the schema's unit,
:data:`cmsim.measured.schema.STANDARD_GRAVITY_M_S2`, which the reader converts back with)
and builds a signal the way condition-monitoring textbooks describe a machine's
vibration (Randall 2011, ch. 2-3; McFadden & Smith 1984; Antoni & Randall 2002):

* each machine is drawn: shaft speed, gear tooth counts (gear machines) or none, bearing
  geometry, 2-4 housing resonances (frequency, damping, gain), mesh harmonic levels and
  their shaft-rate amplitude and phase modulation (manufacturing errors, run-out: the
  SpectraQuest rig shows sidebands as strong as the carriers), shaft-order lines, the mains
  line and its harmonics, coloured background noise, a slow speed wobble and sensor noise;
* the signal is synthesised in the angle domain of the input shaft, θ(t) = 2π ∫ f_r(t) dt:
  mesh harmonics k·Z1·θ modulated by the shaft phases, shaft orders m·θ, and bearing
  impacts placed at their angles (with 1-2 % random slip) that ring the housing resonances;
  broadband background through the same resonances (a machine's structure shapes both);
* one healthy **baseline** record per machine, and records with one **effect**: outer-race,
  inner-race (load-zone modulated at the shaft rate) or ball (modulated at the cage rate)
  defect, a local tooth fault (once-per-revolution amplitude/phase dip and impact), shaft
  eccentricity (once-per-revolution modulation of the mesh), unbalance (the 1× line and a
  once-per-revolution load modulation), misalignment (the 2× line and a twice-per-revolution
  modulation), speed fluctuation, a changed transfer path, more sensor noise — or none.

:func:`write_machine` writes a machine's records (``.npz``, one channel, in g) and its
``metadata.json`` (documented speed, geometry, sample rate, the sensor's bearing, and the
answer key per recording, which a diagnosis must never read).

References
----------
.. [1] R. B. Randall, *Vibration-based Condition Monitoring*, Wiley 2011.
.. [2] P. D. McFadden, J. D. Smith, J. Sound Vib. 96 (1984) 69-82.
.. [3] J. Antoni, R. B. Randall, "Differential diagnosis of gear and bearing faults",
   J. Vib. Acoust. 124 (2002) 165-171.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from scipy import signal as sps

from cmsim.measured.schema import STANDARD_GRAVITY_M_S2

__all__ = ["Machine", "draw_machine", "synthesise", "write_machine", "EFFECTS",
           "GEAR_ONLY", "BEARING_ONLY"]

#: Effects this generator makes, named as cmsim's cause catalogue names them.
EFFECTS = ("bearing_outer_race", "bearing_inner_race", "bearing_ball", "tooth_fault",
           "eccentricity", "unbalance", "misalignment", "speed_fluctuation", "transfer_path",
           "noise")

#: Effects only a gear machine has; only a bearing machine has.
GEAR_ONLY = ("tooth_fault", "eccentricity")
BEARING_ONLY = ()

@dataclass(frozen=True)
class Machine:
    """One drawn machine (every field in SI units unless the name says otherwise).

    Attributes
    ----------
    kind : str
        ``"gear"`` or ``"bearing"``.
    fs_hz : float
        Sample rate, Hz.
    speed_rpm : float
        Input shaft speed, rpm.
    teeth : tuple of int or None
        (Z1, Z2) of the one gear stage.
    bearings : dict
        Bearing name → {n_balls, ball_diameter_mm, pitch_diameter_mm, shaft}; the sensor
        sits on the first.
    modes_hz, damping, mode_gain : tuple of float
        Housing resonances: frequency, damping ratio, relative gain.
    mesh_amp : tuple of float
        Mesh harmonic amplitudes, m/s² (gear machines).
    mesh_am : tuple of float
        Amplitude-modulation indices of the mesh at f_r1 and f_r2.
    mesh_pm_rad : tuple of float
        Phase-modulation amplitudes of the mesh at f_r1 and f_r2, rad.
    shaft_lines : tuple of float
        Amplitudes of shaft orders 1-4, m/s².
    mains_hz : float
        Mains frequency (50 or 60 Hz).
    mains_amp : tuple of float
        Amplitudes of the mains line's 1st-3rd harmonics, m/s².
    background_rms : float
        RMS of the broadband background, m/s².
    sensor_noise_rms : float
        RMS of the white sensor noise, m/s².
    wobble : tuple of float
        Slow speed wobble: relative amplitude and frequency, Hz.
    impact_gain : float
        Size of a bearing or tooth impact relative to the background, per unit severity.
    """

    kind: str
    fs_hz: float
    speed_rpm: float
    teeth: tuple | None
    bearings: dict
    modes_hz: tuple
    damping: tuple
    mode_gain: tuple
    mesh_amp: tuple = ()
    mesh_am: tuple = (0.0, 0.0)
    mesh_pm_rad: tuple = (0.0, 0.0)
    shaft_lines: tuple = (0.0, 0.0, 0.0, 0.0)
    mains_hz: float = 50.0
    mains_amp: tuple = (0.0, 0.0, 0.0)
    background_rms: float = 0.1
    sensor_noise_rms: float = 0.01
    wobble: tuple = (0.0, 1.0)
    impact_gain: float = 1.0
    seed: int = 0
    notes: list = field(default_factory=list)


def _loguniform(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def draw_machine(seed, kind="bearing"):
    """A machine of ``kind`` (``"gear"`` or ``"bearing"``) drawn from ``seed``.

    Parameters
    ----------
    seed : int
        Seed of every drawn property.
    kind : str
        ``"gear"`` (one spur stage on two shafts, sensor on an input-shaft bearing) or
        ``"bearing"`` (a rotor on two ball bearings, sensor on the drive end).

    Returns
    -------
    Machine
    """
    rng = np.random.default_rng([int(seed), 7])
    fs = float(rng.choice([12_000.0, 20_000.0, 25_600.0]))
    if kind == "gear":
        speed = rng.uniform(900.0, 1800.0)
        z1 = int(rng.integers(18, 36))
        z2 = int(rng.integers(z1 + 5, 3 * z1))
        teeth = (z1, z2)
        gmf = speed / 60.0 * z1
        n_h = max(1, min(6, int(0.4 * fs / gmf)))
        mesh_amp = tuple(_loguniform(rng, 0.3, 3.0) * 0.7 ** k for k in range(n_h))
        mesh_am = (_loguniform(rng, 0.02, 0.5), _loguniform(rng, 0.02, 0.3))
        mesh_pm = (_loguniform(rng, 0.01, 0.3), _loguniform(rng, 0.01, 0.2))
    else:
        speed = rng.uniform(1200.0, 3600.0)
        teeth, mesh_amp, mesh_am, mesh_pm = None, (), (0.0, 0.0), (0.0, 0.0)
    d_ball = rng.uniform(5.0, 14.0)
    pitch = d_ball * rng.uniform(3.8, 5.5)
    bearings = {"drive_end": {"n_balls": int(rng.integers(7, 13)), "ball_diameter_mm": d_ball,
                              "pitch_diameter_mm": pitch, "shaft": "input"},
                "fan_end": {"n_balls": int(rng.integers(7, 13)),
                            "ball_diameter_mm": 0.85 * d_ball,
                            "pitch_diameter_mm": 0.8 * pitch, "shaft": "input"}}
    n_modes = int(rng.integers(2, 5))
    modes = tuple(sorted(rng.uniform(800.0, 0.42 * fs, n_modes)))
    background = _loguniform(rng, 0.05, 0.5)
    return Machine(
        kind=kind, fs_hz=fs, speed_rpm=float(speed), teeth=teeth, bearings=bearings,
        modes_hz=modes, damping=tuple(rng.uniform(0.01, 0.08, n_modes)),
        mode_gain=tuple(_loguniform(rng, 0.3, 3.0) for _ in range(n_modes)),
        mesh_amp=mesh_amp, mesh_am=mesh_am, mesh_pm_rad=mesh_pm,
        shaft_lines=tuple(background * _loguniform(rng, 0.05, 1.0) * 0.6 ** m
                          for m in range(4)),
        mains_hz=float(rng.choice([50.0, 60.0])),
        mains_amp=tuple(background * _loguniform(rng, 0.01, 0.3) * 0.5 ** m for m in range(3)),
        background_rms=background, sensor_noise_rms=background * rng.uniform(0.05, 0.2),
        wobble=(rng.uniform(0.0005, 0.003), rng.uniform(0.2, 2.0)),
        impact_gain=_loguniform(rng, 0.5, 2.0), seed=int(seed))


# ---------------------------------------------------------------------- kinematics (own)
def _defect_orders(b):
    """Defect frequencies of a bearing in orders of its shaft (fixed outer ring, 0°)."""
    n, d, dp = b["n_balls"], b["ball_diameter_mm"], b["pitch_diameter_mm"]
    r = d / dp
    return {"ftf": 0.5 * (1 - r), "bpfo": 0.5 * n * (1 - r), "bpfi": 0.5 * n * (1 + r),
            "bsf": 0.5 * dp / d * (1 - r * r)}


def _housing_sos(m, modes_hz, damping, gain):
    """Second-order sections of the housing: a sum of resonances (band-pass sections)."""
    out = []
    for f, z, g in zip(modes_hz, damping, gain):
        w = 2 * math.pi * f
        b, a = sps.bilinear([g * 2 * z * w, 0.0], [1.0, 2 * z * w, w * w], fs=m.fs_hz)
        out.append(sps.tf2sos(b, a))
    return out


def _through(sos_list, x):
    return sum(sps.sosfilt(sos, x) for sos in sos_list)


def _ringing(m, housing, t_hits, peaks, n):
    """Impacts at times ``t_hits`` (s) ringing the housing, each with the peak ``peaks``."""
    delta = np.zeros(int(0.05 * m.fs_hz))
    delta[0] = 1.0
    unit_peak = float(np.max(np.abs(_through(housing, delta))))
    x = np.zeros(n)
    idx = np.round(np.asarray(t_hits) * m.fs_hz).astype(int)
    keep = (idx >= 0) & (idx < n)
    np.add.at(x, idx[keep], np.asarray(peaks, dtype=float)[keep] / unit_peak)
    return _through(housing, x)


def synthesise(m, effect=None, severity=1.0, *, duration_s=3.0, seed=0):
    """One record of machine ``m`` with ``effect`` (None: healthy) at ``severity``.

    Parameters
    ----------
    m : Machine
        The machine.
    effect : str or None
        One of :data:`EFFECTS`, or None.
    severity : float
        Size of the effect, 1 = clearly visible to a trained eye (0.5-2 sensible).
    duration_s : float
        Length, s.
    seed : int
        Seed of this record's random parts (noise, slip, phases).

    Returns
    -------
    numpy.ndarray
        Acceleration, m/s².
    """
    if effect is not None and effect not in EFFECTS:
        raise ValueError(f"effect must be one of {EFFECTS} or None, got {effect!r}")
    rng = np.random.default_rng([int(m.seed), int(seed), 11])
    fs = m.fs_hz
    n = int(round(duration_s * fs))
    t = np.arange(n) / fs
    fr0 = m.speed_rpm / 60.0
    w_amp, w_hz = m.wobble
    speed = 1.0 + w_amp * np.sin(2 * math.pi * w_hz * t + rng.uniform(0, 2 * math.pi))
    if effect == "speed_fluctuation":            # once-per-rev fluctuation, 1-4 %
        speed = speed + 0.02 * severity * np.sin(2 * math.pi * fr0 * t)
    theta = 2 * math.pi * fr0 * np.cumsum(speed) / fs            # input shaft angle
    modes = np.array(m.modes_hz)
    if effect == "transfer_path":
        modes = modes * (1.0 + 0.25 * severity * rng.choice([-1.0, 1.0]))
        modes = np.clip(modes, 300.0, 0.45 * fs)
    housing = _housing_sos(m, modes, m.damping, m.mode_gain)

    # background: white through the housing plus a pink floor, scaled to its rms
    white = rng.standard_normal(n)
    bg = _through(housing, white)
    pink = np.cumsum(rng.standard_normal(n))
    pink = sps.sosfilt(sps.butter(1, 5.0, "highpass", fs=fs, output="sos"), pink)
    bg = bg / np.std(bg) + 0.3 * pink / np.std(pink)
    x = m.background_rms * bg / np.std(bg)

    load_mod = np.ones(n)                         # once/twice-per-rev load modulation
    lines = list(m.shaft_lines)
    if effect == "unbalance":
        lines[0] += m.background_rms * 1.5 * severity
        load_mod = load_mod + 0.15 * severity * np.cos(theta)
    if effect == "misalignment":
        lines[1] += m.background_rms * 1.5 * severity
        lines[0] += m.background_rms * 0.4 * severity
        load_mod = load_mod + 0.15 * severity * np.cos(2 * theta)
    for order, a in enumerate(lines, start=1):
        x += a * np.cos(order * theta + rng.uniform(0, 2 * math.pi))
    for h, a in enumerate(m.mains_amp, start=1):
        x += a * np.cos(2 * math.pi * h * m.mains_hz * t + rng.uniform(0, 2 * math.pi))

    if m.teeth is not None:
        z1, z2 = m.teeth
        theta2 = theta * z1 / z2
        am1, am2 = m.mesh_am
        pm1, pm2 = m.mesh_pm_rad
        env = (1 + am1 * np.cos(theta + 0.3) + am2 * np.cos(theta2 + 1.1)) * load_mod
        pm = pm1 * np.sin(theta + 0.7) + pm2 * np.sin(theta2 + 0.2)
        if effect == "eccentricity":               # once-per-rev of the input gear
            env = env + 0.4 * severity * np.cos(theta + 2.0)
            pm = pm + 0.3 * severity * np.sin(theta + 2.0)
            x += m.background_rms * 0.5 * severity * np.cos(theta + 2.0)
        if effect == "tooth_fault":                # a local dip once per input revolution
            pitch = 2 * math.pi / z1
            phase = np.mod(theta, 2 * math.pi) - math.pi
            dip = np.exp(-0.5 * (phase / (0.8 * pitch)) ** 2)
            env = env * (1 - 0.6 * min(severity, 1.5) * dip)
            pm = pm + 0.8 * severity * dip
            hits = _crossings(theta, 2 * math.pi, math.pi, t)
            x += _ringing(m, housing, hits, np.full(len(hits), 0.8 * severity * m.impact_gain
                                                    * m.mesh_amp[0]), n)
        mesh = np.zeros(n)
        for k, a in enumerate(m.mesh_amp, start=1):
            mesh += a * np.cos(k * z1 * theta + k * pm + 0.4 * k)
        # the drawn harmonic levels stand for the mesh force through the path at each one
        x += env * mesh

    if effect in ("bearing_outer_race", "bearing_inner_race", "bearing_ball"):
        b = m.bearings["drive_end"]
        orders = _defect_orders(b)
        slip = 1.0 - rng.uniform(0.005, 0.02)
        key = {"bearing_outer_race": "bpfo", "bearing_inner_race": "bpfi",
               "bearing_ball": "bsf"}[effect]
        rate = orders[key] * (2.0 if key == "bsf" else 1.0) * slip
        period = 2 * math.pi / rate                 # input-shaft angle between impacts
        jitter = rng.normal(0.0, 0.01 * period, int(theta[-1] / period) + 2)
        angles = period * (np.arange(jitter.size) + rng.uniform()) + jitter
        hits = np.interp(angles, theta, t)
        amps = np.full(hits.size, 6.0 * severity * m.impact_gain * m.background_rms)
        if key == "bpfi":                           # the defect passes the load zone
            amps *= 0.5 * (1 + np.cos(angles))
        elif key == "bsf":                          # the ball carried by the cage
            amps *= 0.5 * (1 + np.cos(angles * orders["ftf"]))
        x += _ringing(m, housing, hits, amps, n)

    noise = m.sensor_noise_rms + (m.background_rms * severity if effect == "noise" else 0.0)
    return x + noise * rng.standard_normal(n)


def _crossings(theta, period, offset, t):
    """Times at which ``theta`` passes ``offset + k·period``."""
    k = np.arange(math.ceil((theta[0] - offset) / period), int((theta[-1] - offset) / period)
                  + 1)
    return np.interp(offset + k * period, theta, t)


def write_machine(folder, m, records, *, duration_s=3.0):
    """Write ``records`` of machine ``m`` to ``folder`` (one ``.npz`` each, key ``acc`` in g)
    with a ``metadata.json`` in the schema of the shared measured datasets.

    Parameters
    ----------
    folder : str or Path
        Created if needed; files are written atomically.
    m : Machine
        The machine.
    records : sequence of (str, str or None, float, int)
        (name, effect, severity, seed) per record; name ``baseline`` is the healthy record.
    duration_s : float
        Length of each record, s.

    Returns
    -------
    pathlib.Path
        ``folder``.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    entries = []
    for name, effect, severity, seed in records:
        x = synthesise(m, effect, severity, duration_s=duration_s,
                       seed=seed) / STANDARD_GRAVITY_M_S2
        _atomic_npz(folder / f"{name}.npz", acc=x.astype(np.float32))
        entries.append({"file": f"{name}.npz", "n_samples": int(x.size), "fs_hz": m.fs_hz,
                        "shaft_speed_rpm": round(m.speed_rpm, 3),
                        "condition": "healthy" if effect is None else "faulty",
                        "fault": effect or "none", "fault_severity": severity})
    geometry = {"gears": None if m.teeth is None else [
        {"stage": 1, "input_teeth": m.teeth[0], "output_teeth": m.teeth[1],
         "module_mm": None, "pressure_angle_deg": None, "face_width_mm": None,
         "documented": True}],
        "bearings": {k: dict(v, model=None, contact_angle_deg=0.0, location=k,
                             outer_ring_fixed=True) for k, v in m.bearings.items()}}
    meta = {"dataset": f"angle-domain machine {m.seed} ({m.kind})",
            "source": "cmsim.discrepancy.angle_domain (synthetic, independent of the model)",
            "citation": None, "license": "CC0", "rig": f"synthetic {m.kind} machine",
            "fs_hz": m.fs_hz, "channels": {"acc": "housing accelerometer on the drive end"},
            "sensors": {"acc": {"near": "drive_end", "direction": "radial", "unit": "g"}},
            "geometry": geometry, "recordings": entries,
            "generator": {k: v for k, v in asdict(m).items() if k != "notes"}}
    _atomic_text(folder / "metadata.json", json.dumps(meta, indent=1, default=float))
    return folder


def _atomic_text(path, text):
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


def _atomic_npz(path, **arrays):
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".npz")
    with os.fdopen(fd, "wb") as fh:
        np.savez_compressed(fh, **arrays)
    os.replace(tmp, path)
