"""Characteristic frequencies of a rig: shaft rates, GMF, bearing defect and ball-pass rates.

These are rig kinematics (no signal processing): :class:`RigFrequencies` holds the shaft
rates, the gear mesh frequency and, per bearing, a :class:`BearingFrequencies`. The cage
formula is written once, here, in :func:`cage_speed_ratios` (the model's ball angles in
:mod:`cmsim.bearings.kinematics` take it from here too)
(f_c = K_in·f_i + K_out·f_o, K_in = (1 − γ)/2, K_out = (1 + γ)/2, γ = (d/D)·cos α); with the
inner ring rate f_i and outer ring rate f_o (Hz, signed, same sense positive):

* cage (FTF)          f_c
* outer-race defect   BPFO = N·|f_c − f_o|
* inner-race defect   BPFI = N·|f_i − f_c|
* ball spin           BSF  = (D/2d)·(1 − γ²)·|f_i − f_o|
* ball pass under a load fixed in space (the variable-compliance frequency of the model)
  BPF = N·|f_c|.

With a fixed outer ring BPF = BPFO. The paper rig's ratio BPF/f_shaft = 3.6342 ("bearing
cycles per gear turn", ref. [1] §5) needs a contact angle near 10°: the free contact angle of
its 209 bearing (9.93°, D = 64.9985 mm) gives 3.6339, within 0.01 % (α = 0 gives 3.6207).

Layering: this module imports only :mod:`cmsim.errors` (it sits below
:mod:`cmsim.bearings`); the bearings, faults, spectra, features and datasets layers import it.

References
----------
.. [1] A. Fernandez-del-Rincon et al., "Enhanced model of gear transmission dynamics for
   condition monitoring applications", MSSP 85 (2017) 445-467, eq. 6 and §5.
.. [2] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", MSSP 25
   (2011) 485-520, eq. (1)-(4).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from cmsim.errors import ParameterError, check_range, check_type

__all__ = ["BearingFrequencies", "RigFrequencies", "bearing_frequencies", "rig_frequencies",
           "peak_families", "cage_speed_ratios", "FAMILY_KEYS", "BEARING_FAMILY_KEYS",
           "lines_above_nyquist"]

#: Keys of a families dict (see :meth:`RigFrequencies.families` and :mod:`cmsim.spectra.labels`).
FAMILY_KEYS = ("GMF", "BPF", "fr", "BPFO", "BPFI", "BSF", "FTF", "fr1", "fr2")

#: The keys of :data:`FAMILY_KEYS` a bearing makes: its lines slip with the balls, and a
#: record that documents no bearing has none to name by (the rest are shaft and mesh lines).
BEARING_FAMILY_KEYS = frozenset(("BPF", "BPFO", "BPFI", "BSF", "FTF"))


def cage_speed_ratios(ball_diameter_m, pitch_diameter_m, contact_angle_rad=0.0):
    """(K_in, K_out) = ((1 − γ)/2, (1 + γ)/2), γ = (d/D)·cos α: the one cage formula.

    The cage turns at f_c = K_in·f_in + K_out·f_out (rolling without slip); every cage,
    defect and ball-pass rate in cmsim (this module's, the model's ball angles through
    :func:`cmsim.bearings.kinematics.cage_ratios`) derives from these two ratios.

    Parameters
    ----------
    ball_diameter_m : float
        Ball diameter d, m.
    pitch_diameter_m : float
        Pitch diameter D, m.
    contact_angle_rad : float
        Contact angle α, rad.

    Examples
    --------
    >>> k_in, k_out = cage_speed_ratios(7.94e-3, 39.04e-3)      # CWRU 6205
    >>> round(k_in, 6), round(k_out, 6)
    (0.398309, 0.601691)
    """
    gamma = ball_diameter_m / pitch_diameter_m * math.cos(contact_angle_rad)
    return 0.5 * (1.0 - gamma), 0.5 * (1.0 + gamma)


@dataclass(frozen=True)
class BearingFrequencies:
    """Kinematic frequencies of one rolling bearing, Hz (all >= 0).

    Attributes
    ----------
    shaft_hz : float
        Rate of the shaft carrying the bearing (inner ring) f_i, Hz.
    ftf_hz : float
        Fundamental train (cage) frequency |f_c|, Hz.
    bpfo_hz : float
        Ball pass frequency, outer race N·|f_c − f_o|, Hz.
    bpfi_hz : float
        Ball pass frequency, inner race N·|f_i − f_c|, Hz.
    bsf_hz : float
        Ball spin frequency (D/2d)(1 − γ²)|f_i − f_o|, Hz (one defect hit per spin on one
        race; a ball defect hitting both races shows at 2·BSF).
    bpf_hz : float
        Ball pass frequency relative to a load fixed in space N·|f_c|, Hz (the model's
        variable-compliance rate).
    """

    shaft_hz: float
    ftf_hz: float
    bpfo_hz: float
    bpfi_hz: float
    bsf_hz: float
    bpf_hz: float

    def to_dict(self):
        """``{"shaft_hz", "ftf_hz", "bpfo_hz", "bpfi_hz", "bsf_hz", "bpf_hz"}``, Hz."""
        return asdict(self)

    def __getitem__(self, key):
        """Mapping access ``bf["bpf_hz"]`` (kept for JSON-style callers; prefer attributes)."""
        try:
            return self.to_dict()[key]
        except KeyError:
            raise KeyError(f"no bearing frequency {key!r}; have {list(self.to_dict())}") from None


def bearing_frequencies(shaft_hz, n_balls, ball_diameter_m, pitch_diameter_m,
                        contact_angle_rad=0.0, outer_ring_hz=0.0):
    """Cage, defect and ball-pass frequencies of a bearing whose rings may both rotate.

    Parameters
    ----------
    shaft_hz : float
        Inner ring (shaft) rotation rate f_i, Hz, >= 0.
    n_balls : int
        Number of rolling elements N, >= 3.
    ball_diameter_m : float
        Ball diameter d, m (> 0).
    pitch_diameter_m : float
        Pitch diameter D, m (> d).
    contact_angle_rad : float
        Contact angle α, rad, in [0, π/2).
    outer_ring_hz : float
        Outer ring rotation rate f_o, Hz, signed (+: same sense as the shaft).

    Returns
    -------
    BearingFrequencies

    References
    ----------
    .. [1] R. B. Randall, J. Antoni, MSSP 25 (2011) 485-520, eq. (1)-(4).

    Examples
    --------
    >>> fr = bearing_frequencies(1797 / 60, 9, 7.94e-3, 39.04e-3)   # CWRU 6205-2RS
    >>> round(fr.bpfo_hz, 2), round(fr.bpfi_hz, 2), round(fr.bsf_hz, 2)
    (107.36, 162.19, 70.58)
    """
    fi = check_range("shaft_hz", shaft_hz, 0.0, unit="Hz")
    if isinstance(n_balls, bool) or not isinstance(n_balls, (int, np.integer)) or n_balls < 3:
        raise ParameterError(f"n_balls must be an integer >= 3, got {n_balls!r}")
    n = int(n_balls)
    d = check_range("ball_diameter_m", ball_diameter_m, 0.0, lo_open=True, unit="m")
    dm = check_range("pitch_diameter_m", pitch_diameter_m, d, lo_open=True,
                     unit="m (> ball_diameter_m)")
    alpha = check_range("contact_angle_rad", contact_angle_rad, 0.0, 0.5 * math.pi,
                        hi_open=True, unit="rad")
    fo = check_range("outer_ring_hz", outer_ring_hz, unit="Hz")
    k_in, k_out = cage_speed_ratios(d, dm, alpha)
    gamma = k_out - k_in
    fc = k_in * fi + k_out * fo
    return BearingFrequencies(
        shaft_hz=float(fi),
        ftf_hz=abs(fc),
        bpfo_hz=n * abs(fc - fo),
        bpfi_hz=n * abs(fi - fc),
        bsf_hz=dm / (2.0 * d) * (1.0 - gamma ** 2) * abs(fi - fo),
        bpf_hz=n * abs(fc),
    )


@dataclass(frozen=True)
class RigFrequencies:
    """Characteristic frequencies of a rig at one operating point, Hz.

    Build it with :func:`rig_frequencies` from a rig and an operating point, or directly for a measured
    record (e.g. ``RigFrequencies(fr1_hz=29.95, bearings={"DE": bearing_frequencies(...)})``).

    Attributes
    ----------
    fr1_hz : float
        Input shaft rate, Hz.
    fr2_hz : float or None
        Output shaft rate fr1·Z1/Z2, Hz (``None`` without gears).
    gmf_hz : float or None
        Gear mesh frequency Z1·fr1, Hz (``None`` without gears).
    bearings : dict of str to BearingFrequencies
        Per bearing name, in the rig's bearing order.
    """

    fr1_hz: float
    fr2_hz: float | None = None
    gmf_hz: float | None = None
    bearings: dict = field(default_factory=dict)

    def __post_init__(self):
        check_range("fr1_hz", self.fr1_hz, 0.0, unit="Hz")
        for name, bf in self.bearings.items():
            if not isinstance(bf, BearingFrequencies):
                raise ParameterError(f"bearings[{name!r}] must be a BearingFrequencies, got "
                                     f"{type(bf).__name__}")

    @property
    def has_gears(self):
        """True when a GMF is defined."""
        return self.gmf_hz is not None

    @property
    def bearing_names(self):
        """Bearing names, in order."""
        return tuple(self.bearings)

    @property
    def shaft_rates_hz(self):
        """``{"fr1": fr1_hz, "fr2": fr2_hz}`` (``fr2`` only with gears), Hz."""
        out = {"fr1": self.fr1_hz}
        if self.fr2_hz is not None:
            out["fr2"] = self.fr2_hz
        return out

    def bearing(self, name=None):
        """:class:`BearingFrequencies` of bearing ``name`` (default: the first)."""
        if not self.bearings:
            raise ParameterError("these frequencies hold no bearing")
        if name is None:
            return next(iter(self.bearings.values()))
        try:
            return self.bearings[name]
        except KeyError:
            raise ParameterError(f"bearing must be one of {list(self.bearings)}, "
                                 f"got {name!r}") from None

    def families(self, bearing=None):
        """Base frequencies for :func:`~cmsim.spectra.labels.label_peaks`, Hz.

        Parameters
        ----------
        bearing : str, optional
            Bearing whose BPF/BPFO/BPFI/BSF/FTF are used; default the first.

        Returns
        -------
        dict of str to float
            Keys from :data:`FAMILY_KEYS` (``"GMF"`` only with gears); ``"fr"`` is the rate
            of the shaft carrying ``bearing``, and with gears of another ratio than 1:1 the
            other gear shaft's rate is ``"fr2"`` (the output shaft) or ``"fr1"`` (the input
            shaft): a gear modulates the mesh at its own shaft's rate. Zero frequencies
            (e.g. BPFO with a co-rotating outer ring) are left out.
        """
        b = self.bearing(bearing)
        fam = {}
        if self.gmf_hz is not None:
            fam["GMF"] = float(self.gmf_hz)
        fam.update(fr=b.shaft_hz, BPF=b.bpf_hz, BPFO=b.bpfo_hz, BPFI=b.bpfi_hz, BSF=b.bsf_hz,
                   FTF=b.ftf_hz)
        for key, rate in self.shaft_rates_hz.items():
            if not math.isclose(rate, b.shaft_hz, rel_tol=1e-9):
                fam[key] = rate
        return {k: float(v) for k, v in fam.items() if v > 0.0}

    def to_dict(self):
        """JSON-ready dict: ``"shaft_hz"`` (= fr1), ``"output_shaft_hz"`` and ``"gmf_hz"``
        (gear rigs), and per bearing name the :meth:`BearingFrequencies.to_dict`."""
        out = {"shaft_hz": self.fr1_hz}
        if self.fr2_hz is not None:
            out["output_shaft_hz"] = self.fr2_hz
        if self.gmf_hz is not None:
            out["gmf_hz"] = self.gmf_hz
        for name, bf in self.bearings.items():
            out[name] = bf.to_dict()
        return out

    @classmethod
    def from_dict(cls, d):
        """Inverse of :meth:`to_dict`."""
        if not isinstance(d, dict) or "shaft_hz" not in d:
            raise ParameterError("expected a dict written by RigFrequencies.to_dict "
                                 "(with 'shaft_hz')")
        bearings = {k: BearingFrequencies(**v) for k, v in d.items() if isinstance(v, dict)}
        return cls(fr1_hz=float(d["shaft_hz"]), fr2_hz=d.get("output_shaft_hz"),
                   gmf_hz=d.get("gmf_hz"), bearings=bearings)

    def __getitem__(self, key):
        """Mapping access to :meth:`to_dict` (``f["gmf_hz"]``, ``f["1b1"]["bpf_hz"]``).

        Kept for JSON-style callers; prefer the attributes (``f.gmf_hz``,
        ``f.bearing("1b1").bpf_hz``).
        """
        d = self.to_dict()
        try:
            return d[key]
        except KeyError:
            raise KeyError(f"no frequency {key!r}; have {list(d)}") from None

    def __contains__(self, key):
        return key in self.to_dict()

    def __iter__(self):
        return iter(self.to_dict())

    def get(self, key, default=None):
        """``to_dict().get(key, default)`` (see :meth:`__getitem__`)."""
        return self.to_dict().get(key, default)


def rig_frequencies(rig, op):
    """Characteristic frequencies of ``rig`` at ``op`` (each bearing's effective contact angle
    and ``outer_ring_speed_ratio``).

    Parameters
    ----------
    rig : cmsim.rig.Rig
        Gear rig or bearing rig.
    op : cmsim.rig.OperatingPoint
        Input shaft speed (``op.speed_rpm``).

    Returns
    -------
    RigFrequencies

    Examples
    --------
    >>> from cmsim.rig import Rig, OperatingPoint
    >>> f = rig_frequencies(Rig.paper_2016(), OperatingPoint(speed_rpm=1000.0))
    >>> round(f.gmf_hz, 2), round(f.bearing("1b1").bpf_hz / f.fr1_hz, 4)
    (466.67, 3.6339)
    """
    f1 = float(op.shaft_hz)
    rates = [f1]
    f2 = gmf = None
    if rig.has_gears:
        z1, z2 = rig.gears.driving.n_teeth, rig.gears.driven.n_teeth
        f2 = f1 * z1 / z2
        gmf = z1 * f1
        rates.append(f2)
    shaft_of = [i for i, s in enumerate(rig.shafts) for _ in s.bearings]
    bearings = {}
    for name, brg, i_shaft in zip(rig.bearing_names, rig.bearings, shaft_of):
        fs_hz = rates[i_shaft]
        bearings[name] = bearing_frequencies(
            fs_hz, brg.n_balls, brg.ball_diameter_m, brg.pitch_diameter_m,
            brg.effective_contact_angle_rad,
            outer_ring_hz=brg.outer_ring_speed_ratio * fs_hz)
    return RigFrequencies(fr1_hz=f1, fr2_hz=f2, gmf_hz=gmf, bearings=bearings)


def peak_families(freqs, bearing=None):
    """:meth:`RigFrequencies.families` of ``freqs`` (a :class:`RigFrequencies` or its
    :meth:`~RigFrequencies.to_dict`)."""
    if isinstance(freqs, dict):
        if not any(isinstance(v, dict) for v in freqs.values()):
            raise ParameterError("freqs must be a RigFrequencies or its to_dict() "
                                 "(no bearing entries found)")
        freqs = RigFrequencies.from_dict(freqs)
    check_type("freqs", freqs, RigFrequencies)
    return freqs.families(bearing)


def lines_above_nyquist(freqs, fs_hz, *, rate="fs_hz", speed="speed_rpm"):
    """One line per characteristic frequency of ``freqs`` above the Nyquist frequency of a
    record sampled at ``fs_hz``: the gear mesh, the ball passes over each race. A record
    that misses them holds none of what condition monitoring reads there (an anti-alias
    filtered record has nothing there; one that is not, aliases).

    Parameters
    ----------
    freqs : RigFrequencies
        At the fastest speed of the record.
    fs_hz : float
        Sample rate of the record, Hz.
    rate, speed : str
        Names of the rate and the speed, for the message (a command line's options).

    Returns
    -------
    list of str
        Empty when every line lies under the Nyquist frequency.

    Examples
    --------
    >>> from cmsim.rig import OperatingPoint, Rig
    >>> lines_above_nyquist(rig_frequencies(Rig.paper_2016(), OperatingPoint(1000.0)), 75e3)
    []
    >>> print(lines_above_nyquist(rig_frequencies(Rig.paper_2016(), OperatingPoint(1e5)),
    ...                           75e3)[0])  # doctest: +ELLIPSIS
    the gear mesh (GMF 46667 Hz) lies above the Nyquist frequency 37500 Hz of fs_hz 75000: ...
    """
    nyquist = 0.5 * float(fs_hz)
    lines = []
    if freqs.gmf_hz is not None:
        lines.append(("the gear mesh", "GMF", freqs.gmf_hz))
    for name, b in freqs.bearings.items():
        lines += [(f"bearing {name}'s outer-race ball pass", "BPFO", b.bpfo_hz),
                  (f"bearing {name}'s inner-race ball pass", "BPFI", b.bpfi_hz)]
    return [f"{what} ({short} {f:.0f} Hz) lies above the Nyquist frequency {nyquist:.0f} Hz of "
            f"{rate} {float(fs_hz):g}: the record holds none of its lines; raise {rate} above "
            f"{2 * f:.0f} Hz or lower {speed}" for what, short, f in lines if f >= nyquist]
