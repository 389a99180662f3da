"""Exponential (Lawson) form of the fixed-step schemes: the stiff linear chains in closed form.

The step of an explicit scheme is bounded by the model's highest natural frequency
(:mod:`cmsim.dynamics.step`). On the paper's rig the modes above 14 kHz are torsional modes
of the shafts' linear springs (98 % of their strain energy), between the small inertias of
the bearing nodes; the contacts alone (bearings, mesh) reach about 6 kHz. The linear springs
fall apart into *chains* — the connected sets of DOFs they join (each shaft's x, y and θ
lines) — and a chain's linear spring-damper part ``L`` has an exact propagator ``e^{tL}``, a
small matrix. The Lawson form of a Runge-Kutta scheme [1] integrates ``w = e^{−(t−t_n)L} y``
with the scheme's tableau: ``L`` then sets no step limit, and everything else (contacts, the
other chains, external loads) is treated as before. A step of the exponential scheme costs
the plain one plus a few small matrix products, and it may take fewer steps per output
sample (:func:`exponential_split`). Whether that wins is measured, not assumed:
``benchmarks/bench_schemes.py`` draws accuracy against cost. On the paper's rig it does not:
at 25.6 kHz lawson-ode3 at 2 steps per sample misses the harmonics by 1.5 times what ode3 at
its own 3 steps does, and rk4 (a wider stability interval, 4 stages) at 2 steps is both
cheaper and 7 times more accurate; the exponential form pays where a linear chain is much
stiffer than everything else (the step of rk4 still follows that chain). ``lawson-rk4``
with every chain in closed form takes one step per sample at 25.6 kHz (half rk4's
evaluations) but misses the harmonics by 3.4-3.9 % (15 % in a run-up): the contacts it leaves
explicit are then stepped at ω·h up to 1.5.

References
----------
.. [1] J. D. Lawson, "Generalized Runge-Kutta processes for stable systems with large
   Lipschitz constants", SIAM J. Numer. Anal. 4 (1967) 372-380.
.. [2] M. Hochbruck, A. Ostermann, "Exponential integrators", Acta Numerica 19 (2010)
   209-286 (§2.5, integrating-factor methods).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from cmsim.dynamics._rhs_kernels import CHAIN_STATES, LinearPropagator
from cmsim.dynamics.modal import highest_frequency_hz
from cmsim.dynamics.step import integration_substeps

__all__ = ["LinearSplit", "linear_chains", "linear_split", "exponential_split"]


@dataclass(frozen=True)
class LinearSplit:
    """The linear chains an exponential scheme integrates exactly, and what is left.

    Attributes
    ----------
    chains : tuple of tuple of int
        The DOF indices of each chain in closed form.
    kernel_params : KernelParams
        The model's kernel arrays without those chains' springs (the part ``N``).
    highest_mode_hz : float
        Highest natural frequency of the rest of the model (contacts and the other chains,
        linearised as :func:`~cmsim.dynamics.modal.highest_frequency_hz`), Hz: it bounds the
        step.
    generators : tuple of ndarray
        Each chain's ``L = [[0, I], [−M⁻¹K, −M⁻¹C]]`` on its positions then velocities.
    """

    chains: tuple
    kernel_params: object
    highest_mode_hz: float
    generators: tuple

    @property
    def dofs(self):
        """All DOFs in closed form, ascending."""
        return tuple(sorted(d for chain in self.chains for d in chain))

    def propagator(self, tableau, h):
        """The :class:`~cmsim.dynamics._rhs_kernels.LinearPropagator` of ``tableau`` at step
        ``h`` (s)."""
        n = self.kernel_params.minv.shape[0]
        nb, size = len(self.chains), CHAIN_STATES
        idx = np.zeros((nb, size), dtype=np.int64)
        sizes = np.array([2 * len(chain) for chain in self.chains], dtype=np.int64)
        factors = list(tableau.c) + [1.0]
        ahead = np.zeros((len(factors), nb, size, size))
        back = np.zeros((len(tableau.c), nb, size, size))
        for b, (chain, lin) in enumerate(zip(self.chains, self.generators)):
            m = 2 * len(chain)
            idx[b, :m] = list(chain) + [n + d for d in chain]
            for i, c in enumerate(factors):
                ahead[i, b, :m, :m] = scipy.linalg.expm(c * h * lin)
            for i, c in enumerate(tableau.c):
                back[i, b, :m, :m] = scipy.linalg.expm(-c * h * lin)
        return LinearPropagator(idx, sizes, ahead, back, np.zeros(size))


def linear_chains(model):
    """The DOF sets the linear springs join (connected components), each with the highest
    natural frequency of its springs alone, Hz, stiffest first (chains of more than
    ``CHAIN_STATES / 2`` DOFs are left out: they stay explicit).

    Parameters
    ----------
    model : DynamicModel

    Returns
    -------
    list of (tuple of int, float)
    """
    n = model.n_dof
    parent = list(range(n))

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b, _ in model.kernel_params.spring_ends:
        parent[root(int(a))] = root(int(b))
    groups = {}
    for i in range(n):
        groups.setdefault(root(i), []).append(i)
    chains = []
    for dofs in groups.values():
        k = model.stiffness[np.ix_(dofs, dofs)]
        if not np.any(k):
            continue                      # DOFs no spring holds (e.g. a free rotation)
        if 2 * len(dofs) > CHAIN_STATES:
            continue                      # too long for a propagator block: stays explicit
        eig = scipy.linalg.eigvalsh(0.5 * (k + k.T), np.diag(model.mass[dofs]))
        chains.append((tuple(dofs), math.sqrt(max(eig[-1], 0.0)) / (2.0 * math.pi)))
    return sorted(chains, key=lambda c: -c[1])


def linear_split(model, q, chains):
    """:class:`LinearSplit` of ``model`` with the springs of ``chains`` (DOF index tuples of
    :func:`linear_chains`) in closed form, linearised at state ``q`` for its highest
    remaining mode."""
    chains = tuple(tuple(int(d) for d in chain) for chain in chains)
    inside = np.zeros(model.n_dof, dtype=bool)
    inside[[d for chain in chains for d in chain]] = True
    P = model.kernel_params
    ends, springs = P.spring_ends, P.springs
    n_ground = int(ends[0, 2])
    ground = np.arange(len(ends)) >= len(ends) - n_ground
    keep = ~inside[ends[:, 0]]            # a chain is closed: both ends inside or outside
    new_ends = np.ascontiguousarray(ends[keep]).copy()
    new_springs = np.ascontiguousarray(springs[keep])
    if len(new_ends) == 0:                # the kernel reads ends[0, 2]: one null spring
        new_ends, new_springs = np.zeros((1, 3), dtype=np.int64), np.zeros((1, 2))
        new_ends[0, 2] = 1
    else:
        new_ends[0, 2] = int(np.sum(keep & ground))
    rest = P._replace(springs=new_springs, spring_ends=new_ends).frozen()
    k_rest = model.stiffness.copy()
    generators = []
    for chain in chains:
        sel = list(chain)
        k_rest[np.ix_(sel, sel)] = 0.0
        minv = 1.0 / model.mass[sel]
        m = len(sel)
        lin = np.zeros((2 * m, 2 * m))
        lin[:m, m:] = np.eye(m)
        lin[m:, :m] = -minv[:, None] * model.stiffness[np.ix_(sel, sel)]
        lin[m:, m:] = -minv[:, None] * model.damping[np.ix_(sel, sel)]
        generators.append(lin)
    return LinearSplit(chains, rest, highest_frequency_hz(model, q, linear_stiffness=k_rest),
                       tuple(generators))


def exponential_split(model, q, fs_hz, excitation, mode_steps):
    """The split of an exponential scheme: the fewest of the stiffest chains
    (:func:`linear_chains`) that reach the fewest steps per output sample any choice of
    chains reaches.

    Parameters
    ----------
    model : DynamicModel
    q : ndarray
        State the modes are linearised at.
    fs_hz : float
        Output sample rate, Hz.
    excitation : Excitation
        The run's fastest excitation.
    mode_steps : float
        Steps per period of the remaining highest mode the scheme needs.

    Returns
    -------
    LinearSplit or None
        ``None`` for a model without chains.
    """
    chains = [dofs for dofs, _ in linear_chains(model)]
    if not chains:
        return None
    whole = linear_split(model, q, chains)
    fewest = integration_substeps(fs_hz, excitation, whole.highest_mode_hz, mode_steps=mode_steps)
    for count in range(1, len(chains)):
        part = linear_split(model, q, chains[:count])
        if integration_substeps(fs_hz, excitation, part.highest_mode_hz,
                                mode_steps=mode_steps) <= fewest:
            return part
    return whole
