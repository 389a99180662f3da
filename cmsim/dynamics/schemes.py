"""Which scheme integrates a run, and with how many steps per output sample: the one rule.

Each scheme of :data:`~cmsim.dynamics.integrator.SCHEMES` takes the fewest steps per output
sample that meet the step rule of :mod:`cmsim.dynamics.step` with its own stability interval
(:func:`~cmsim.dynamics.step.steps_per_period`: ode3 4.7 steps per period of the highest mode,
rk4 2.88), and an exponential one the split of :func:`cmsim.dynamics.exponential.exponential_split`.

``"auto"`` (the default of :func:`cmsim.dynamics.simulate`) takes, of :data:`AUTO_SCHEMES`, the
one with the fewest right-hand-side evaluations per output sample (stages × steps), ode3 on a
tie. On the paper's rig: at 75 kHz ode3 at one step per sample (3 evaluations; rk4 would take
4); at 25.6 kHz rk4 at 2 steps (8) instead of ode3 at 3 (9), and 7 times nearer the converged
GMF harmonics (``benchmarks/bench_schemes.py``: 0.10 % against 0.70 %).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from cmsim.dynamics.exponential import exponential_split
from cmsim.dynamics.integrator import SCHEMES
from cmsim.dynamics.modal import highest_frequency_hz
from cmsim.dynamics.step import integration_substeps, steps_per_period

__all__ = ["AUTO_SCHEMES", "SchemeChoice", "choose_scheme"]

#: Schemes ``"auto"`` chooses from, in order of preference on a tie.
AUTO_SCHEMES = ("ode3", "rk4")


class SchemeChoice(NamedTuple):
    """The integration of a run.

    Attributes
    ----------
    scheme : str
        Key of :data:`~cmsim.dynamics.integrator.SCHEMES`.
    split : LinearSplit or None
        The chains an exponential scheme integrates in closed form (``None``: a plain one).
    substeps : int
        Steps per output sample.
    highest_mode_hz : float
        The highest mode the scheme's explicit stages meet, Hz.
    """

    scheme: str
    split: object
    substeps: int
    highest_mode_hz: float


def choose_scheme(model, q, fs_hz, excitation, scheme="auto", substeps=None):
    """The scheme, split and steps per output sample of a run.

    Parameters
    ----------
    model : DynamicModel
    q : ndarray
        State the modes are linearised at (the start).
    fs_hz : float
        Output sample rate, Hz.
    excitation : Excitation
        The run's fastest excitation (:func:`cmsim.dynamics.step.fastest_excitation`).
    scheme : str
        ``"auto"`` or a key of :data:`~cmsim.dynamics.integrator.SCHEMES`.
    substeps : int, optional
        Steps per output sample the caller chose (already checked against the excitation):
        ``"auto"`` then takes the first scheme of :data:`AUTO_SCHEMES` whose stability
        interval holds the highest mode at that step (ode3 at the paper's own 75 kHz), or
        the one with the widest interval when none does (the run may then diverge visibly,
        as a named scheme does).

    Returns
    -------
    SchemeChoice
    """
    f_max = highest_frequency_hz(model, q)
    if scheme == "auto":
        if substeps is not None:
            # the caller's step: the first scheme it keeps stable (ω·h within the scheme's
            # interval), else the widest interval
            h_omega = 2.0 * math.pi * f_max / (fs_hz * substeps)
            stable = [n for n in AUTO_SCHEMES if h_omega <= SCHEMES[n].imaginary_limit]
            name = stable[0] if stable else max(AUTO_SCHEMES,
                                                key=lambda n: SCHEMES[n].imaginary_limit)
            return SchemeChoice(name, None, substeps, f_max)
        options = []
        for name in AUTO_SCHEMES:
            tab = SCHEMES[name]
            steps = integration_substeps(fs_hz, excitation, f_max,
                                         mode_steps=steps_per_period(tab))
            options.append((tab.stages * steps, AUTO_SCHEMES.index(name), name, steps))
        _, _, name, steps = min(options)
        return SchemeChoice(name, None, steps, f_max)
    tab = SCHEMES[scheme]
    if tab.exponential:
        split = exponential_split(model, q, fs_hz, excitation, steps_per_period(tab))
        if split is not None:
            need = integration_substeps(fs_hz, excitation, split.highest_mode_hz,
                                        mode_steps=steps_per_period(tab))
            return SchemeChoice(scheme, split, need if substeps is None else substeps,
                                split.highest_mode_hz)
    need = integration_substeps(fs_hz, excitation, f_max, mode_steps=steps_per_period(tab))
    return SchemeChoice(scheme, None, need if substeps is None else substeps, f_max)
