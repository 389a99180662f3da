"""The integration step of a run: the one rule every command's runs go through.

A fixed-step explicit scheme must do two things with its step h = 1/(fs_hz·substeps):

1. stay stable and accurate on the stiffest mode: at least :data:`STEPS_PER_PERIOD` steps per
   period of the highest natural frequency (ode3's stability limit is ω·h = √3 on the
   imaginary axis);
2. resolve what drives the model: the mesh stiffness repeats at the gear mesh frequency and
   the ball contacts at the ball-pass rates, and an excitation sampled by fewer steps than
   its harmonics need is not "filtered" later — it is wrong inside the dynamics (a mesh at
   46.7 kHz integrated at 75 kHz shows its third harmonic aliased at 10 kHz). The step
   therefore resolves the first :data:`RESOLVED_HARMONICS` harmonics of the fastest
   excitation with :data:`STEPS_PER_PERIOD` steps each.

The automatic step (``substeps=None``) follows both; a step the caller sets is refused when it
breaks (2) — a run that diverges shows itself, an under-resolved excitation does not. The
output then passes through the anti-alias filter of :mod:`cmsim.dynamics.decimation`, so the
record holds exactly what an acquisition at ``fs_hz`` would: lines above its Nyquist
frequency are filtered out, not folded back.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from cmsim.errors import ParameterError
from cmsim.frequencies import rig_frequencies
from cmsim.rig import RANGES

__all__ = ["STEPS_PER_PERIOD", "RESOLVED_HARMONICS", "Excitation", "fastest_excitation",
           "integration_substeps", "steps_per_period"]

#: Integration steps per period of the highest natural frequency (and of each resolved
#: excitation harmonic): ω_max·h <= 2π/4.7 = 1.34, 77 % of ode3's stability limit √3 on the
#: imaginary axis (the paper's 75 kHz for its rig's 15.94 kHz mode 19).
STEPS_PER_PERIOD = 4.7

#: ode3's stability interval on the imaginary axis (:data:`STEPS_PER_PERIOD` uses 77 % of it).
ODE3_IMAGINARY_LIMIT = math.sqrt(3.0)

def steps_per_period(tableau):
    """Steps per period of the highest mode that ``tableau`` needs: :data:`STEPS_PER_PERIOD`
    scaled by ode3's imaginary stability interval over the scheme's, so every scheme keeps
    the same 77 % margin (rk4: 2.88). A scheme without a wider interval (heun has none) is
    held to ode3's.

    Examples
    --------
    >>> from cmsim.dynamics.integrator import SCHEMES
    >>> steps_per_period(SCHEMES["ode3"]), round(steps_per_period(SCHEMES["rk4"]), 2)
    (4.7, 2.88)
    """
    limit = float(tableau.imaginary_limit)
    if limit <= ODE3_IMAGINARY_LIMIT:
        return STEPS_PER_PERIOD
    return STEPS_PER_PERIOD * ODE3_IMAGINARY_LIMIT / limit


#: Harmonics of the fastest excitation the step resolves: the GMF harmonics the features
#: measure (:data:`cmsim.features.N_GMF_HARMONICS`; the report's waterfalls reach 6.5·GMF).
RESOLVED_HARMONICS = 6


class Excitation(NamedTuple):
    """The fastest periodic excitation of a run.

    Attributes
    ----------
    name : str
        What it is, as an engineer reads it (``"GMF"``, ``"BPFI of 1b1"``).
    hz : float
        Its fundamental at the fastest speed of the run, Hz.
    speed_rpm : float
        That fastest input speed, rpm.
    """

    name: str
    hz: float
    speed_rpm: float

    def fastest_speed_rpm(self, rate_hz):
        """Fastest input speed whose excitation ``rate_hz`` still resolves, rpm."""
        return self.speed_rpm * rate_hz / self.least_rate_hz

    @property
    def least_rate_hz(self):
        """Smallest integration rate that resolves its first :data:`RESOLVED_HARMONICS`
        harmonics, Hz."""
        return STEPS_PER_PERIOD * RESOLVED_HARMONICS * self.hz


def fastest_excitation(rig, op, speed_ratio=1.0):
    """The fastest periodic excitation of ``rig`` at ``op``: the gear mesh or a ball pass.

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    speed_ratio : float
        Fastest speed of the run over ``op.speed_rpm`` (a run-up, a speed wobble; >= 1).

    Returns
    -------
    Excitation
        The largest of GMF and, per bearing, the ball passes over the outer race (BPFO), the
        inner race (BPFI), a load fixed in space (BPF) and a ball defect on both races
        (2·BSF).

    Examples
    --------
    >>> from cmsim.rig import Rig, OperatingPoint
    >>> e = fastest_excitation(Rig.paper_2016(), OperatingPoint(100000.0))
    >>> e.name, round(e.hz)
    ('GMF', 46667)
    """
    freqs = rig_frequencies(rig, op)
    found = [("GMF", freqs.gmf_hz)] if freqs.gmf_hz else []
    for bearing, bf in freqs.bearings.items():
        found += [(f"BPFO of {bearing}", bf.bpfo_hz), (f"BPFI of {bearing}", bf.bpfi_hz),
                  (f"BPF of {bearing}", bf.bpf_hz), (f"2×BSF of {bearing}", 2.0 * bf.bsf_hz)]
    name, hz = max(found, key=lambda item: item[1])
    ratio = max(float(speed_ratio), 1.0)
    return Excitation(name, float(hz) * ratio, float(op.speed_rpm) * ratio)


def _substeps_for(rate_hz, fs_hz):
    """Fewest whole steps per output sample that reach ``rate_hz`` at ``fs_hz``."""
    return max(1, math.ceil(rate_hz / fs_hz - 1e-9))


def integration_substeps(fs_hz, excitation, highest_mode_hz=0.0, substeps=None,
                         mode_steps=STEPS_PER_PERIOD):
    """Integration steps per output sample at ``fs_hz``: chosen, or checked when given.

    Parameters
    ----------
    fs_hz : float
        Output sample rate, Hz.
    excitation : Excitation
        The fastest excitation of the run (:func:`fastest_excitation`).
    highest_mode_hz : float
        Highest natural frequency of the model, Hz (0: not known yet; only the excitation
        then counts).
    substeps : int, optional
        Steps per sample the caller chose (checked against the excitation only: a step too
        long for the highest mode diverges visibly); ``None`` chooses the fewest that meet
        both rules of the module docstring.
    mode_steps : float
        Steps per period of the highest mode the scheme needs (:func:`steps_per_period`;
        ode3's by default).

    Returns
    -------
    int

    Raises
    ------
    ParameterError
        ``substeps`` too few to resolve the excitation (``param="substeps"``), or more than
        :data:`cmsim.rig.RANGES` allows needed at ``fs_hz`` (``param="fs_hz"``); the message
        states the least value that works and the fastest speed the given one allows.

    Examples
    --------
    >>> integration_substeps(75000.0, Excitation("GMF", 466.67, 1000.0),
    ...                      highest_mode_hz=15935.0)
    1
    >>> integration_substeps(75000.0, Excitation("GMF", 46667.0, 100000.0))
    18
    """
    need = excitation.least_rate_hz
    what = (f"{RESOLVED_HARMONICS} harmonics of {excitation.name} {excitation.hz:.6g} Hz "
            f"(>= {need:.4g} Hz)")
    top = RANGES["substeps"].hi
    if substeps is not None:
        if fs_hz * substeps >= need:
            return int(substeps)
        least = _substeps_for(need, fs_hz)
        allowed = (f"an integer in [{least}, {top}]" if least <= top
                   else f"more than the {top} allowed: raise fs_hz")
        raise ParameterError(
            f"substeps = {substeps} integrates at {fs_hz * substeps:.6g} Hz, "
            f"{fs_hz * substeps / excitation.hz:.2g} steps per period of {excitation.name}; "
            f"resolving {what} needs {STEPS_PER_PERIOD:g} steps per period of each: substeps "
            f"must be {allowed} (or left out: automatic), or speed_rpm at most "
            f"{excitation.fastest_speed_rpm(fs_hz * substeps):.6g} rpm", param="substeps",
            allowed=allowed)
    rate = max(mode_steps * highest_mode_hz, need)
    chosen = _substeps_for(rate, fs_hz)
    if chosen > top:
        if need >= rate:
            slower = f", or speed_rpm at most {excitation.fastest_speed_rpm(fs_hz * top):.6g} rpm"
        else:
            what, slower = f"the highest mode {highest_mode_hz:.6g} Hz (>= {rate:.4g} Hz)", ""
        raise ParameterError(
            f"fs_hz = {fs_hz:g} Hz would need substeps = {chosen} (at most {top}) to resolve "
            f"{what} with {mode_steps:.3g} steps per period: fs_hz must be >= "
            f"{rate / top:.6g} Hz{slower}", param="fs_hz",
            allowed=f"a number >= {rate / top:.6g} Hz")
    return chosen
