"""Characteristic frequencies of a gear rig: shaft rates, GMF, bearing defect and ball-pass rates.

Bearing kinematics with both rings rotating (rolling without slip), with γ = (d/D)·cos α,
inner ring rate f_i and outer ring rate f_o (Hz, signed, same sense positive):

* cage (FTF)          f_c  = f_i·(1 − γ)/2 + f_o·(1 + γ)/2
* outer-race defect   BPFO = N·|f_c − f_o|
* inner-race defect   BPFI = N·|f_i − f_c|
* ball spin           BSF  = (D/2d)·(1 − γ²)·|f_i − f_o|
* ball pass under a load fixed in space (the variable-compliance frequency of the model)
  BPF = N·|f_c|.

With a fixed outer ring BPF = BPFO. The paper rig's ratio BPF/f_shaft = 3.6342 ("bearing
cycles per gear turn", ref. [1] §5) needs a contact angle near 10°: the free contact angle of
its 209 bearing (9.93°, D = 64.9985 mm) gives 3.6339, within 0.01 % (α = 0 gives 3.6207).

References
----------
.. [1] A. Fernandez-del-Rincon et al., "Enhanced model of gear transmission dynamics for
   condition monitoring applications", MSSP 85 (2017) 445-467, eq. 6 and §5.
.. [2] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", MSSP 25
   (2011) 485-520, eq. (1)-(4).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from cmsim.errors import ParameterError, check_range
from cmsim.spectra._checks import positive_int

__all__ = ["BearingFrequencies", "bearing_frequencies", "rig_frequencies", "peak_families"]


@dataclass(frozen=True)
class BearingFrequencies:
    """Kinematic frequencies of one rolling bearing, Hz (all >= 0).

    Attributes
    ----------
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
        Ball pass frequency relative to a load fixed in space N·|f_c|, Hz.
    """

    ftf_hz: float
    bpfo_hz: float
    bpfi_hz: float
    bsf_hz: float
    bpf_hz: float

    def as_dict(self):
        """``{"ftf_hz": ..., "bpfo_hz": ..., "bpfi_hz": ..., "bsf_hz": ..., "bpf_hz": ...}``."""
        return asdict(self)


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
    n = positive_int("n_balls", n_balls, lo=3)
    d = check_range("ball_diameter_m", ball_diameter_m, 0.0, lo_open=True, unit="m")
    dm = check_range("pitch_diameter_m", pitch_diameter_m, d, lo_open=True,
                     unit="m (> ball_diameter_m)")
    alpha = check_range("contact_angle_rad", contact_angle_rad, 0.0, 0.5 * math.pi,
                        hi_open=True, unit="rad")
    fo = check_range("outer_ring_hz", outer_ring_hz, unit="Hz")
    gamma = d / dm * math.cos(alpha)
    fc = fi * (1.0 - gamma) / 2.0 + fo * (1.0 + gamma) / 2.0
    return BearingFrequencies(
        ftf_hz=abs(fc),
        bpfo_hz=n * abs(fc - fo),
        bpfi_hz=n * abs(fi - fc),
        bsf_hz=dm / (2.0 * d) * (1.0 - gamma ** 2) * abs(fi - fo),
        bpf_hz=n * abs(fc),
    )


def rig_frequencies(rig, op):
    """Characteristic frequencies of a rig at an operating point.

    Parameters
    ----------
    rig : cmsim.rig.Rig
        Gear rig or bearing rig.
    op : cmsim.rig.OperatingPoint
        Input shaft speed (``op.speed_rpm``).

    Returns
    -------
    dict
        ``"shaft_hz"`` (input shaft rate, Hz); for gear rigs also ``"output_shaft_hz"``
        (= shaft_hz·Z1/Z2) and ``"gmf_hz"`` (= Z1·shaft_hz). For each name in
        ``rig.bearing_names`` a dict with ``"shaft_hz"`` (rate of the shaft carrying that
        bearing), ``"ftf_hz"``, ``"bpfo_hz"``, ``"bpfi_hz"``, ``"bsf_hz"`` and ``"bpf_hz"``
        (see :class:`BearingFrequencies`), using each bearing's effective contact angle and
        ``outer_ring_speed_ratio``.

    Examples
    --------
    >>> from cmsim.rig import Rig, OperatingPoint
    >>> f = rig_frequencies(Rig.paper_2016(), OperatingPoint(speed_rpm=1000.0))
    >>> round(f["gmf_hz"], 2), round(f["1b1"]["bpf_hz"] / f["shaft_hz"], 4)
    (466.67, 3.6339)
    """
    f1 = float(op.shaft_hz)
    out = {"shaft_hz": f1}
    rates = [f1]
    if rig.has_gears:
        z1, z2 = rig.gears.driving.n_teeth, rig.gears.driven.n_teeth
        out["output_shaft_hz"] = f1 * z1 / z2
        out["gmf_hz"] = z1 * f1
        rates.append(out["output_shaft_hz"])
    per_shaft = [len(s.bearings) for s in rig.shafts]
    shaft_of = [i for i, k in enumerate(per_shaft) for _ in range(k)]
    for name, brg, i_shaft in zip(rig.bearing_names, rig.bearings, shaft_of):
        fs_hz = rates[i_shaft]
        bf = bearing_frequencies(fs_hz, brg.n_balls, brg.ball_diameter_m, brg.pitch_diameter_m,
                                 brg.effective_contact_angle_rad,
                                 outer_ring_hz=brg.outer_ring_speed_ratio * fs_hz)
        out[name] = {"shaft_hz": fs_hz, **bf.as_dict()}
    return out


#: Keys of a families dict (see :func:`peak_families` and :mod:`cmsim.spectra.labels`).
FAMILY_KEYS = ("GMF", "BPF", "fr", "BPFO", "BPFI", "BSF", "FTF")


def peak_families(freqs, bearing=None):
    """Base frequencies for :func:`~cmsim.spectra.labels.label_peaks` from :func:`rig_frequencies`.

    Parameters
    ----------
    freqs : dict
        Output of :func:`rig_frequencies`.
    bearing : str, optional
        Bearing name whose BPF/BPFO/BPFI/BSF/FTF are used; default the first bearing of
        shaft 1 (``"1b1"``).

    Returns
    -------
    dict of str to float
        ``{"GMF", "BPF", "fr", "BPFO", "BPFI", "BSF", "FTF"}`` in Hz (``"GMF"`` only for
        gear rigs); ``"fr"`` is the rate of the shaft carrying ``bearing`` (the input shaft
        for the default). Zero frequencies (e.g. BPFO with a co-rotating outer ring) are
        left out.
    """
    names = [k for k, v in freqs.items() if isinstance(v, dict)]
    if not names:
        raise ParameterError("freqs must be the dict returned by rig_frequencies "
                             "(no bearing entries found)")
    name = names[0] if bearing is None else bearing
    if name not in names:
        raise ParameterError(f"bearing must be one of {names}, got {bearing!r}")
    b = freqs[name]
    fam = {}
    if "gmf_hz" in freqs:
        fam["GMF"] = float(freqs["gmf_hz"])
    fam["fr"] = float(b["shaft_hz"])
    fam.update(BPF=b["bpf_hz"], BPFO=b["bpfo_hz"], BPFI=b["bpfi_hz"], BSF=b["bsf_hz"],
               FTF=b["ftf_hz"])
    return {k: float(v) for k, v in fam.items() if v > 0.0}
