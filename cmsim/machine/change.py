"""What a cause changes on a machine's sensor signal, as the model says, laid on the machine's
own healthy baseline: the record a cause would make is ``baseline ⊕ change``.

The twin of a machine does not predict its healthy record (the baseline is that prediction,
:class:`~cmsim.machine.baseline.Baseline`); the model supplies only what a cause changes,
relative to the model's own healthy run with the same seeds (same cage phases, same slip):

* **lines the healthy model makes** (ball-pass combs, mesh harmonics and their sidebands:
  :func:`~cmsim.spectra.line_detector.detect_lines` on the healthy force's spectrum) are
  changed on the baseline's own bins there. What the model *adds* to a line is added through
  the calibrated path's gain, in power, to the baseline's level there (a defect's comb on a
  ball-pass line); what it *takes away* is taken from the baseline's own line in proportion
  (the ratio of the model's line with the cause to without it: the path cancels) where the
  baseline shows that line, as far as the model's line makes it (its power through the
  path over the baseline line's), and nothing where it does not show it (a preload cannot
  remove a comb the machine never showed). Adding the difference of two forces instead would add a second
  comb of another phase where one should shrink: power adds, it never cancels;
* **everything else the cause makes** (impacts ringing the structure, new sidebands, a new
  family) is the difference of the two forces with those line bins notched out, through the
  machine's path (:class:`~cmsim.machine.path.TransferPath`, minimum phase: an impact stays an
  impact), added to the baseline's samples;
* a **rotating force** at a shaft order (unbalance, misalignment) adds its power to the
  baseline's line at that order through the machine's gain there
  (:meth:`Machine.rotating_gain <cmsim.machine.Machine.rotating_gain>`), and so does a line
  the force itself makes at a shaft order (an eccentric gear's once-per-revolution force);
* a **speed fluctuation** modulates every order-locked line the baseline has: the baseline is
  read on a warped time, τ(t) = t + a/(2π f)·sin(2π f t + φ), so its instantaneous speed is
  (1 + a·cos(2π f t + φ)) times its own (a ratio: the path cancels);
* a **transfer path** whose frequencies moved by a factor refilters the baseline by the ratio
  of the structure's responses, |H(f/a)| / |H(f)| (the structure shapes all the sensor sees),
  H the calibrated path or, read another way, the root of the baseline's own broadband floor
  (its resonances are where the baseline's broadband peaks); its lines moved with it or held
  where they reach the sensor another way;
* **more noise**: white noise, RMS relative to the background's coloured noise; a **louder
  background**: the background's noise and lines (random phases) added so that its power
  grows by the factor squared.

All of it is deterministic given the forces and ``rng``; a change with nothing in it returns
the baseline's segments unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import map_coordinates

from cmsim.errors import ParameterError
from cmsim.machine.path import smooth_log
from cmsim.spectra.floor import segment_psd
from cmsim.spectra.line_detector import detect_lines, span_sums
from cmsim.spectra.lines import line_bins

__all__ = ["Change", "apply_change", "pinned_correction", "path_ratio", "SHARED_LINE_DB",
           "BROADBAND_DEAD_ZONE", "warp_speed", "STRUCTURES", "PATH_RATIO_OCTAVE",
           "FLOOR_RATIO_OCTAVE", "PATH_RATIO_MAX", "MESH_REGION_ORDERS", "shaft_locked"]

#: The model's broadband must fall under this share of its healthy power for the baseline's
#: broadband to fall with it: the running floors of 8 half-second segments scatter by ~7 %,
#: and a ratio within that scatter is no change (3 of the scatter's σ).
BROADBAND_DEAD_ZONE = 0.8

#: A healthy model line the baseline shows standing this high over its floor (dB) is the
#: baseline's line: a cause that weakens the model's line weakens the baseline's in
#: proportion. Lower, the baseline's bins there are its noise, which no cause removes.
SHARED_LINE_DB = 6.0


@dataclass(frozen=True, eq=False)
class Change:
    """A cause's change on a machine's sensor signal (module docstring).

    Attributes
    ----------
    force, healthy : numpy.ndarray or None
        The model's bearing force behind the machine's channel with the cause and without it
        (same seed, same length), N, at the machine's rate, with ``edge`` spare samples at
        each end; None: the cause does not change the dynamics.
    edge : int
        Spare samples at each end of the forces.
    rotating : tuple of (int, float, float)
        Rotating forces at orders of the sensor bearing's shaft: (order, amplitude N, phase).
    shaft_hz : float
        Rate of the sensor bearing's shaft, Hz (the rotating forces' orders).
    input_hz : float
        Rate of the input shaft, Hz (a speed fluctuation's frequency).
    frequency_factor : float
        Scale of the path's frequencies (1: as calibrated).
    structure : str
        Where the structure's response that ``frequency_factor`` moves is read (one of
        :data:`STRUCTURES`): ``"path"``, the calibrated transfer path; ``"floor"``, the
        baseline's broadband floor (what a broadband excitation makes through the structure:
        its resonances are where the floor peaks; the path's gain is pinned to the model's
        lines and divided by the model force's own shape, which a record not made by the
        model does not share).
    lines_follow_path : bool
        Whether the baseline's lines move with the path (:func:`path_ratio`); False, they
        reach the sensor another way and keep their level.
    white_noise : float
        White noise added, RMS relative to the background's coloured noise RMS.
    background_gain : float
        Factor (>= 1) on the background's power root: louder background noise and lines.
    speed_fluctuation : float
        Relative amplitude of a once-per-revolution fluctuation of the input speed.
    pin_hz : tuple of float
        Lines the healthy model and the baseline always share (a gear's mesh harmonics), Hz:
        where the baseline shows them they pin the path (:func:`pinned_correction`).
    path_gain : float
        Factor on what the change adds through the path (1: the calibrated gain): the
        path's gain where a change rings the structure is a nuisance of its own.
    """

    force: np.ndarray | None = None
    healthy: np.ndarray | None = None
    edge: int = 0
    rotating: tuple = ()
    shaft_hz: float = 0.0
    input_hz: float = 0.0
    frequency_factor: float = 1.0
    white_noise: float = 0.0
    background_gain: float = 1.0
    speed_fluctuation: float = 0.0
    pin_hz: tuple = ()
    path_gain: float = 1.0
    structure: str = "path"
    lines_follow_path: bool = True

    def __post_init__(self):
        if (self.force is None) != (self.healthy is None):
            raise ParameterError("a change needs both forces or neither", param="change")
        if self.force is not None and np.shape(self.force) != np.shape(self.healthy):
            raise ParameterError("the forces of a change must have the same length",
                                 param="change")
        if not (self.frequency_factor > 0 and self.white_noise >= 0 and self.path_gain > 0
                and self.background_gain >= 1.0 and self.speed_fluctuation >= 0):
            raise ParameterError("a change's frequency factor must be > 0, its noise and "
                                 "speed fluctuation >= 0 and its background gain >= 1",
                                 param="change")
        if self.structure not in STRUCTURES:
            raise ParameterError(f"a change's structure must be one of {STRUCTURES}, got "
                                 f"{self.structure!r}", param="structure")


def warp_speed(x, fs_hz, amplitude, frequency_hz, phase_rad):
    """``x`` read on a warped time: its instantaneous speed times (1 + a·cos(2π f t + φ)).

    The signal is doubled in rate (FFT) and read by cubic B-spline interpolation at
    τ(t)·2fs, τ(t) = t + a/(2π f)·sin(2π f t + φ) − a/(2π f)·sin φ (τ(0) = 0), held at its
    last sample beyond its end.

    Parameters
    ----------
    x : numpy.ndarray, shape (n,)
        Signal.
    fs_hz : float
        Sample rate, Hz.
    amplitude : float
        Relative amplitude a of the speed's fluctuation (< 1).
    frequency_hz : float
        Its frequency f, Hz.
    phase_rad : float
        Its phase φ, rad.

    Returns
    -------
    numpy.ndarray, shape (n,)

    Examples
    --------
    >>> x = np.sin(2 * np.pi * 50 * np.arange(1000) / 1000.0)
    >>> bool(np.allclose(warp_speed(x, 1000.0, 0.0, 5.0, 0.0), x))
    True
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    if amplitude == 0.0:
        return x.copy()
    up = np.fft.irfft(np.fft.rfft(x), 2 * n) * 2.0          # band-limited, twice the rate
    t = np.arange(n) / fs_hz
    w = 2.0 * math.pi * frequency_hz
    tau = t + amplitude / w * (np.sin(w * t + phase_rad) - math.sin(phase_rad))
    pos = np.clip(tau * 2.0 * fs_hz, 0.0, 2 * n - 1)
    return map_coordinates(up, [pos], order=3, mode="nearest")


def pinned_correction(freq, lines, psd_h, psd_b, floor_b, gain2, pin_hz):
    """Factor on the path's magnitude that pins it where the baseline and the healthy model
    share a line of a family both always make (a gear's mesh harmonics, ``pin_hz``): at each
    healthy model line there that the baseline shows :data:`SHARED_LINE_DB` over its floor,
    √(the baseline line's power over the path² × the model line's), interpolated between
    those lines in log frequency (held beyond them); 1 without such a line. A line the two
    share by chance (a model's ball-pass harmonic on a baseline's mains harmonic) pins
    nothing: only the families in ``pin_hz`` do.

    A change that modulates such a line (a gear's eccentricity lifting the shaft-rate
    sidebands of the mesh harmonics the baseline has) is then carried relative to the
    baseline's own line, whatever the calibrated path's gain there: the path cancels.

    Parameters
    ----------
    freq : numpy.ndarray, shape (m,)
        Segment frequency grid, Hz.
    lines : sequence of DetectedLine
        The healthy model's lines (:func:`~cmsim.spectra.line_detector.detect_lines`).
    psd_h, psd_b, floor_b : numpy.ndarray, shape (m,)
        PSD of the healthy model force, of the baseline, and the baseline's floor.
    gain2 : numpy.ndarray, shape (m,)
        The path's power gain.
    pin_hz : sequence of float
        Frequencies of the lines that may pin (within their line window), Hz.

    Returns
    -------
    numpy.ndarray, shape (m,)
    """
    pins = []
    for ln in lines:
        b = ln.bins
        if not any(freq[b.start] <= f <= freq[b.stop - 1] for f in pin_hz):
            continue
        p_h, p_b, f_b = float(psd_h[b].sum()), float(psd_b[b].sum()), float(floor_b[b].sum())
        g2 = float(np.mean(gain2[b]))
        if p_h > 0.0 and g2 > 0.0 and p_b - f_b >= (10.0 ** (SHARED_LINE_DB / 10.0) - 1.0) * f_b:
            pins.append((ln.frequency_hz, math.sqrt((p_b - f_b) / (g2 * p_h))))
    if not pins:
        return np.ones(freq.size)
    pins.sort()
    f_pin = np.log([max(f, freq[1]) for f, _ in pins])
    c_pin = np.log([c for _, c in pins])
    return np.exp(np.interp(np.log(np.maximum(freq, freq[1])), f_pin, c_pin))


#: Smoothing of the calibrated path's magnitude before its frequencies are scaled, octave:
#: the structure's resonances, not the pins' and caps' narrow corrections (a ratio of two
#: scaled copies of a narrow correction read +16 dB in one band where the modes moved by 8 %).
PATH_RATIO_OCTAVE = 1.0 / 3.0

#: Smoothing of the baseline's floor before its frequencies are scaled, octave: the
#: calibration's own smoothing of a path's shape
#: (:data:`~cmsim.machine.calibration.path_reading.PATH_SMOOTHING_OCTAVE`; the floor is a
#: running median already, with no pins). The angle-domain generator's moved housing modes
#: (±17-37 %) are read within 1-2 dB in every band from 150 Hz to 3.5 kHz at 1/12 octave; at
#: 1/3 they lose up to 8 dB at the modes' peaks.
FLOOR_RATIO_OCTAVE = 1.0 / 12.0

#: Most a moved path may change the baseline at any frequency, either way (±20 dB: a mode
#: moving onto a frequency where the structure had an antiresonance).
PATH_RATIO_MAX = 10.0

#: Where the structure's response that moves is read (:attr:`Change.structure`).
STRUCTURES = ("path", "floor")


def path_ratio(freq, grid, power, factor, octave):
    """|H(f/a)| / |H(f)| of a structure whose frequencies moved by ``factor`` = a, |H|² being
    ``power`` on ``grid`` (smoothed over ``octave`` where the grid is uniform), the ratio
    held within 1/:data:`PATH_RATIO_MAX` and :data:`PATH_RATIO_MAX`.

    Parameters
    ----------
    freq : numpy.ndarray
        Frequencies the ratio is read at, Hz.
    grid, power : numpy.ndarray
        The structure's power response |H|² and its frequencies, Hz (increasing).
    factor : float
        The factor a (> 0).
    octave : float
        Smoothing, octave.

    Returns
    -------
    numpy.ndarray

    Examples
    --------
    >>> f = np.arange(0.0, 5000.0, 2.0)
    >>> mode = 1.0 / ((1 - (f / 1000.0) ** 2) ** 2 + (0.1 * f / 1000.0) ** 2)
    >>> r = path_ratio(f, f, mode, 1.2, FLOOR_RATIO_OCTAVE)
    >>> bool(r[600] > 3.0 and r[500] < 0.5)     # the peak moved from 1000 Hz to 1200 Hz
    True
    """
    grid = np.asarray(grid, dtype=float)
    log_p = np.log(np.maximum(np.asarray(power, dtype=float), 1e-300))
    if grid.size > 4 and np.allclose(np.diff(grid), grid[1] - grid[0]):
        log_p = smooth_log(log_p, grid, octave)
    ratio = np.exp(0.5 * (np.interp(freq / factor, grid, log_p) - np.interp(freq, grid, log_p)))
    return np.clip(ratio, 1.0 / PATH_RATIO_MAX, PATH_RATIO_MAX)


#: Orders of the faster shaft on each side of a mesh harmonic that a gear's modulation
#: (its sidebands) and the speed's wobble (their smear) fill: on the angle-domain generator's
#: gear machines the floor stands 20-45 dB over its level an octave away within ±3 orders.
MESH_REGION_ORDERS = 4.0


def shaft_locked(freq, lines, change):
    """The bins of a baseline's spectrum that are locked to the shafts, not its broadband
    (a moved path keeps their locked power and moves only the broadband under them): its
    ``lines`` and, on a gear rig, each mesh harmonic (``change.pin_hz``) with
    :data:`MESH_REGION_ORDERS` orders of the faster shaft on each side (its sidebands,
    smeared by the speed's wobble, which the floor's running median reads as broadband).

    Parameters
    ----------
    freq : numpy.ndarray
        The baseline's PSD frequencies, Hz.
    lines : sequence of DetectedLine
        Its lines (:func:`~cmsim.spectra.line_detector.detect_lines`).
    change : Change
        Its mesh harmonics and shaft rates.

    Returns
    -------
    numpy.ndarray of bool
    """
    out = np.zeros(freq.size, dtype=bool)
    for ln in lines:
        out[ln.bins] = True
    reach = MESH_REGION_ORDERS * max(change.shaft_hz, change.input_hz)
    for f in change.pin_hz:
        out |= np.abs(freq - f) <= reach
    return out


def _positions(lo, hi):
    """(bins, span of each) of the spans ``lo[j]:hi[j]`` laid end to end (empty ones
    dropped)."""
    width = np.maximum(hi - lo, 0)
    owner = np.repeat(np.arange(lo.size), width)
    return np.arange(width.sum()) + np.repeat(lo - (np.cumsum(width) - width), width), owner


def _scale_lines(scale, spans, psd_h, psd_c, psd_b, floor_b, gain2):
    """Scale the baseline's spectrum on the bins of each line the healthy model makes (module
    docstring): what the model adds to the line, added through the path (``gain2``, |H|²);
    what it takes away, taken from the baseline's own line in proportion, as far as the
    model's line makes it; a line the baseline never showed, left. The lines' bins are
    disjoint."""
    if not spans:
        return
    p_h, p_c, p_b, f_b, g2 = (span_sums(v, spans) for v in (psd_h, psd_c, psd_b, floor_b,
                                                               gain2))
    lo = np.array([b.start for b in spans])
    hi = np.array([b.stop for b in spans])
    g2 = g2 / (hi - lo)                                  # the path's mean |H|² over the line
    with np.errstate(divide="ignore", invalid="ignore"):
        kept = ~((p_b <= 0.0) | (p_h <= 0.0))
        adds = kept & (p_c >= p_h)                      # added through the path
        # the baseline's line, in proportion — as far as the model makes it (a baseline's
        # shaft line is its unbalance, not a weak model line there)
        shared = kept & ~adds & (p_b - f_b >= (10.0 ** (SHARED_LINE_DB / 10.0) - 1.0) * f_b)
        reach = g2 * p_h / (p_b - f_b)
        share = np.where(reach < 1.0, reach, 1.0)
        target = np.where(adds, p_b + g2 * (p_c - p_h),
                          f_b + (p_b - f_b) * (1.0 - share * (1.0 - p_c / p_h)))
        factor = np.sqrt(target / p_b)
    sel = np.flatnonzero(adds | shared)
    bins, owner = _positions(lo[sel], hi[sel])
    scale[bins] *= factor[sel][owner]


def _notch_lines(notch, f_long, df_long, freq, df, spans):
    """Notch ``spans`` (bins of the segments' grid ``freq``, spacing ``df``) out of a long
    spectrum (grid ``f_long``, spacing ``df_long``) with raised-cosine edges a segment bin
    wide, each reaching a bin beyond its line; overlapping notches keep the deeper."""
    if not spans:
        return
    lo = freq[[b.start for b in spans]] - 0.5 * df
    hi = freq[[b.stop - 1 for b in spans]] + 0.5 * df
    first = np.maximum(((lo - df) / df_long).astype(np.int64), 0)
    stop = np.minimum(((hi + df) / df_long).astype(np.int64) + 2, f_long.size)
    bins, owner = _positions(first, stop)
    f = f_long[bins]
    edge_w = np.clip(np.maximum(lo[owner] - f, f - hi[owner]) / df, 0.0, 1.0)
    np.minimum.at(notch, bins, 0.5 - 0.5 * np.cos(np.pi * edge_w))


def _add_power(scale, bins, p_base, p_add):
    """Scale the spectrum's ``bins``, holding ``p_base`` of power, so that ``p_add`` adds to
    it: a line at an unknown phase against the baseline's own adds its power."""
    scale[bins] *= math.sqrt((p_base + p_add) / p_base)


def apply_change(machine, segments, change, rng):
    """The baseline's segments with a cause's change laid on them (module docstring).

    Parameters
    ----------
    machine : cmsim.machine.Machine
        The calibrated machine (its path, rotating gains and background).
    segments : numpy.ndarray, shape (k, n)
        Baseline segments, sensor unit, at the machine's rate.
    change : Change
        The change; its forces, if any, cover k·n samples (plus the edges): segment i takes
        samples i·n to (i + 1)·n.
    rng : numpy.random.Generator
        Source of the speed fluctuation's phase, the noise and the background.

    Returns
    -------
    numpy.ndarray, shape (k, n)
        Sensor unit.
    """
    x = np.array(segments, dtype=float, ndmin=2)
    k, n = x.shape
    fs = machine.fs_hz
    if change.speed_fluctuation > 0.0:
        x = np.array([warp_speed(s, fs, change.speed_fluctuation, change.input_hz,
                                 rng.uniform(0.0, 2.0 * math.pi)) for s in x])
    freq = np.fft.rfftfreq(n, 1.0 / fs)
    df = freq[1] - freq[0]
    scale = np.ones(freq.size)
    a = change.frequency_factor
    added = np.zeros((k, n))
    fill = None                 # PSD of the background that fills what the model loses
    psd_b = floor_b = None
    if change.force is not None or change.rotating or a != 1.0:
        _, psd_b = segment_psd(list(x), fs)
        found, floor_b = detect_lines(freq, psd_b)
        base_lines = np.zeros(freq.size, dtype=bool)
        for ln in found:
            base_lines[ln.bins] = True
    if a != 1.0:
        locked = shaft_locked(freq, found, change)
        broadband = floor_b
        if change.structure == "floor":     # the structure read where the floor is broadband
            broadband = np.exp(np.interp(freq, freq[~locked], np.log(floor_b[~locked])))
            moved = path_ratio(freq, freq, broadband, a, FLOOR_RATIO_OCTAVE)
        else:
            moved = path_ratio(freq, machine.path.freq_hz, np.asarray(machine.path.gain) ** 2,
                               a, PATH_RATIO_OCTAVE)
        if not change.lines_follow_path:    # what is locked stays, the broadband under it moves
            under = np.minimum(broadband, psd_b)
            held = np.sqrt((psd_b - under + under * moved ** 2) / np.maximum(psd_b, 1e-300))
            moved[locked] = held[locked]
        scale *= moved
    if change.force is not None:
        e = int(change.edge)
        span = slice(e, e + k * n)
        force = np.asarray(change.force, dtype=float)
        healthy = np.asarray(change.healthy, dtype=float)
        if force.size < k * n + 2 * e:
            raise ParameterError(f"a change's forces hold {force.size} samples; {k} segments "
                                 f"of {n} need {k * n + 2 * e}", param="change")
        _, psd_h = segment_psd(list(healthy[span].reshape(k, n)), fs)
        _, psd_c = segment_psd(list(force[span].reshape(k, n)), fs)
        lines, floor_h = detect_lines(freq, psd_h)
        floor_c = detect_lines(freq, psd_c)[1]
        gain2 = machine.path.magnitude(freq, a) ** 2 * pinned_correction(
            freq, lines, psd_h, psd_b, floor_b, machine.path.magnitude(freq, a) ** 2,
            change.pin_hz) ** 2
        gain2 = gain2 * change.path_gain ** 2
        _scale_lines(scale, [ln.bins for ln in lines], psd_h, psd_c, psd_b, floor_b, gain2)
        # the broadband the model loses: the baseline scaled by the model's ratio there (its
        # modulation, what an envelope reads, shrinks with it) and the machine's background
        # filling in what it scaled away (the background is stationary and stays): a band
        # whose model share is s keeps 1 − s·(1 − ratio) of its power
        ratio = np.minimum(floor_c / floor_h, 1.0)
        ratio[ratio > BROADBAND_DEAD_ZONE] = 1.0         # within the floors' own scatter
        ratio[base_lines] = 1.0              # the baseline's lines are not its broadband
        share = np.clip(1.0 - np.interp(freq, machine.background.freq_hz,
                                         machine.background.psd) / floor_b, 0.0, 1.0)
        scale *= np.sqrt(ratio)
        fill = floor_b * (1.0 - share) * (1.0 - ratio)
        # a shaft-order line the cause makes (an eccentric gear's rotating mass) adds its
        # power to the baseline's line there through the machine's gain at that order, as a
        # rotating force does: its phase against the machine's own residual unbalance is
        # unknown (added in time, a fixed phase took 5 dB off the 1× line it lifts)
        made = []
        for order, g in machine.shaft_gain.items():
            b = line_bins(freq, order * change.shaft_hz)
            if b is None or not g > 0 or any(
                    ln.bins.start < b.stop and b.start < ln.bins.stop for ln in lines):
                continue                       # (a line the healthy model has: above)
            p_add = float(psd_c[b].sum()) - float(psd_h[b].sum())
            p_b = float(psd_b[b].sum())
            if p_add >= 9.0 * float(psd_h[b].sum()) and p_b > 0.0:
                _add_power(scale, b, p_b, (g * change.path_gain) ** 2 * p_add)
                made.append(b)
        # the rest of the change: the forces' difference without those lines, through the
        # path: the lines the cause makes whole, its broadband with as much power as the
        # model's broadband grew (a change that only moves the phase of what was there adds
        # nothing)
        d = force - healthy
        if e > 1:                   # tapered over the spare samples (they are dropped): a
            ramp = 0.5 - 0.5 * np.cos(np.pi * np.arange(e) / e)   # line cut by the record's
            d[:e] *= ramp                                        # ends would leak past its
            d[-e:] *= ramp[::-1]                                 # notch
        spec = np.fft.rfft(d)
        f_long = np.fft.rfftfreq(d.size, 1.0 / fs)
        notch = np.ones(f_long.size)        # raised-cosine edges a bin wide: a brick-wall
        df_long = f_long[1] - f_long[0]     # notch rings in time, and a segment reads its
        _notch_lines(notch, f_long, df_long, freq, df,                    # edge ringing
                     [ln.bins for ln in lines] + made)
        spec = spec * notch
        d = np.fft.irfft(spec, d.size)
        _, psd_d = segment_psd(list(d[span].reshape(k, n)), fs)
        new_lines, floor_d = detect_lines(freq, psd_d)
        grow = np.sqrt(np.minimum(np.maximum(floor_c - floor_h, 0.0) / floor_d, 1.0))
        for ln in new_lines:                # a line the cause makes is added whole
            grow[ln.bins] = 1.0
        pin = np.sqrt(gain2) / machine.path.magnitude(freq, a)
        d = np.fft.irfft(spec * np.interp(f_long, freq, grow * pin), d.size)
        added += machine.path.apply(d, fs, a)[span].reshape(k, n)
    for order, amp, _ in change.rotating:
        b = line_bins(freq, order * change.shaft_hz)
        if b is None:
            continue
        p_b = float(psd_b[b].sum())
        if p_b > 0.0:
            _add_power(scale, b, p_b,
                       (machine.rotating_gain(order, change.shaft_hz) * amp) ** 2 / 2.0 / df)
    y = np.fft.irfft(np.fft.rfft(x, axis=1) * scale, n, axis=1) + added
    if fill is not None and np.any(fill > 0.0):
        white = np.fft.rfft(rng.standard_normal((k, n)), axis=1)
        y += np.fft.irfft(white * np.sqrt(fill * fs / 2.0), n, axis=1)
    if change.white_noise > 0.0:
        y += change.white_noise * machine.background.noise_rms(fs) * rng.standard_normal((k, n))
    if change.background_gain > 1.0:
        g = math.sqrt(change.background_gain ** 2 - 1.0)
        y += np.array([g * machine.background.synthesize(n, fs, machine.shaft_hz, rng)
                       for _ in range(k)])
    return y
