"""Hybrid FE/analytical contact solve of a spur-gear pair (paper 001 §3, eq. 2).

Following Vedmar & Andersson [2] as applied in paper 001 [1], the compliance of each tooth
pair is split into

* the displacement of the points at depth h below the contacts, linear in all the contact
  forces through the FE influence coefficients of both gear bodies
  (:mod:`cmsim.mesh_stiffness.influence`: λ^p for the driving gear, λ^w for the driven gear),
* the local approach between each contact point and its depth-h point, non-linear in its own
  force (Hertz + Weber-Banaschek, :mod:`cmsim.mesh_stiffness.local_deflection`),

and the forces follow from compatibility with the rigid-body interferences δ_i
(:func:`cmsim.mesh_stiffness.contact.pair_contacts`) and F_i >= 0 with complementarity:

    δ_i = u^p_L,i(F_i) + u^w_L,i(F_i) + Σ_k (λ^p_ik + λ^w_ik) F_k   for F_i > 0,
    δ_i <= Σ_k (λ^p_ik + λ^w_ik) F_k                                for F_i = 0.

:class:`HybridMeshModel` holds the tables and the parameter vector of the numba kernel
:func:`~cmsim.mesh_stiffness._hybrid_kernels.hybrid_forces_jit`; the lead's time integrator
calls that kernel directly with :meth:`HybridMeshModel.kernel_args` ("model A" of paper 001
§6.1). :meth:`HybridMeshModel.forces` is its checked Python wrapper and
:meth:`HybridMeshModel.forces_reference` an independent, slow enumeration used by the tests.

Conventions: contacts are given in slot order (the pair in slot i + 1 is one base pitch
further along the line of action); roll lengths ρ1 = s_eq and ρ2 = L − s_eq of the contact
points (clamped to the tables' range, which covers the involute flanks; corner contacts use
the table value at the tip-rounding start); χ1, χ2 the surfaces' radii of curvature from
:func:`~cmsim.mesh_stiffness._kernels.pair_contact_jit`. SI units.

References
----------
.. [1] A. Fernandez-del-Rincon et al., MSSP 2016 (paper 001), §3, eq. 2.
.. [2] L. Vedmar, A. Andersson, "A method to determine dynamic loads on spur gear teeth and
   on bearings", J. Sound Vib. 267 (2003) 1065-1084.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import root

from cmsim.errors import ParameterError, check_type
from cmsim.mesh_stiffness._hybrid_kernels import (HP_SIZE, WORK_PER_N, WORK_PER_N2,
                                                  coupling_matrix_jit, hybrid_forces_jit)
from cmsim.mesh_stiffness.fe_mesh import MeshSpec
from cmsim.mesh_stiffness.influence import InfluenceTable, influence_table
from cmsim.mesh_stiffness.local_deflection import (contact_modulus, hertz_half_width,
                                                   local_approach)
from cmsim.rig import GearPair

__all__ = ["HybridMeshModel", "work_size", "SOLVER_TOLERANCE", "SOLVER_MAX_ITERATIONS"]

#: Relative tolerance of the Newton step (and of the gaps, relative to max δ).
SOLVER_TOLERANCE = 1e-13
#: Newton iterations at most.
SOLVER_MAX_ITERATIONS = 60


def work_size(n_contacts):
    """Length of the ``work`` array the kernel needs for ``n_contacts`` contacts."""
    return WORK_PER_N2 * n_contacts ** 2 + WORK_PER_N * n_contacts


@dataclass(frozen=True, eq=False)
class HybridMeshModel:
    """Influence tables of a gear pair and the kernel's parameter vector.

    Build it with :meth:`from_pair` (FE tables from the cache or computed once) or
    :meth:`from_tables`.

    Attributes
    ----------
    pair : GearPair
    driving, driven : InfluenceTable
        λ^p (gear 1) and λ^w (gear 2).
    params : ndarray, shape (HP_SIZE,)
        Kernel parameter vector (:mod:`cmsim.mesh_stiffness._hybrid_kernels`).

    Notes
    -----
    Inside numba code, with ``hp, d1, c1, d2, c2 = model.kernel_args()`` and, per potential
    pair j in slot order, ``delta, nx, ny, px, py, s_eq, chi1, chi2 = pair_contact_jit(...)``
    and ``length`` from ``mesh_frame_jit``::

        rho1[j] = s_eq; rho2[j] = length - s_eq
        it = hybrid_forces_jit(delta, rho1, rho2, chi1, chi2, hp, d1, c1, d2, c2, extra, work,
                               out)

    with ``extra`` the compliance a weakened tooth adds to its pair's own λ (zeros for healthy
    teeth), ``work`` of :func:`work_size` (n) floats; ``out`` receives the normal forces (N)
    of gear 1 on gear 2 along each pair's normal.
    """

    pair: GearPair
    driving: InfluenceTable = field(repr=False)
    driven: InfluenceTable = field(repr=False)
    params: np.ndarray = field(repr=False)

    @classmethod
    def from_pair(cls, pair, depth_m=None, spec=MeshSpec(), plane="strain", use_cache=True):
        """Model of ``pair`` with FE influence tables (cached per gear design).

        Parameters
        ----------
        pair : GearPair
        depth_m : float, optional
            Depth h of the influence points, m (default 0.15 modules).
        spec : MeshSpec
            FE mesh sizes.
        plane : {'stress', 'strain'}
            2-D idealisation of the gear bodies.
        use_cache : bool
            Use the on-disk cache (:mod:`cmsim.mesh_stiffness.cache`).

        Returns
        -------
        HybridMeshModel
        """
        check_type("pair", pair, GearPair)
        kw = dict(depth_m=depth_m, spec=spec, plane=plane, use_cache=use_cache)
        t1 = influence_table(pair.driving, **kw)
        t2 = t1 if pair.driven == pair.driving else influence_table(pair.driven, **kw)
        return cls.from_tables(pair, t1, t2)

    def check_pair(self, pair):
        """Refuse a gear ``pair`` other than the one this model was built for.

        Parameters
        ----------
        pair : GearPair
            The rig's gears.

        Raises
        ------
        ParameterError
            Naming ``mesh`` (the argument that carries a model into a run).
        """
        if self.pair != pair:
            raise ParameterError("mesh: the hybrid model was built for a different gear pair "
                                 "than the rig's")

    @classmethod
    def from_tables(cls, pair, driving, driven):
        """Model from given influence tables (no FE)."""
        check_type("pair", pair, GearPair)
        for name, t in (("driving", driving), ("driven", driven)):
            if not isinstance(t, InfluenceTable):
                raise ParameterError(f"{name} must be an InfluenceTable")
        g1, g2 = pair.driving, pair.driven
        hp = np.zeros(HP_SIZE)
        for off, t in ((0, driving), (4, driven)):
            hp[off:off + 4] = (t.roll_m[0], t.roll_m[1] - t.roll_m[0], t.roll_m.size,
                               t.max_offset)
        hp[8], hp[9] = driving.depth_m, driven.depth_m
        hp[10:14] = (g1.youngs_modulus_pa, g1.poisson_ratio, g2.youngs_modulus_pa,
                     g2.poisson_ratio)
        hp[14] = min(g1.face_width_m, g2.face_width_m)
        hp[15] = contact_modulus(g1.youngs_modulus_pa, g1.poisson_ratio,
                                 g2.youngs_modulus_pa, g2.poisson_ratio)
        hp[16] = SOLVER_TOLERANCE
        hp[17] = SOLVER_MAX_ITERATIONS
        hp.setflags(write=False)
        return cls(pair=pair, driving=driving, driven=driven, params=hp)

    # ------------------------------------------------------------------ kernel interface
    def kernel_args(self):
        """``(hp, diag1, cpl1, diag2, cpl2)`` for :func:`hybrid_forces_jit` (float64, C order)."""
        return (self.params, self.driving.diagonal_m_per_n,
                self.driving.coefficients_m_per_n, self.driven.diagonal_m_per_n,
                self.driven.coefficients_m_per_n)

    def _check(self, delta_m, roll1_m, roll2_m, chi1_m, chi2_m):
        arrs = [np.ascontiguousarray(a, dtype=float).reshape(-1)
                for a in (delta_m, roll1_m, roll2_m, chi1_m, chi2_m)]
        n = arrs[0].size
        if n < 1 or any(a.size != n for a in arrs):
            raise ParameterError("delta_m, roll1_m, roll2_m, chi1_m, chi2_m must have the same "
                                 "length >= 1")
        if not all(np.all(np.isfinite(a)) for a in arrs):
            raise ParameterError("contact inputs must be finite")
        if np.any(arrs[3] <= 0) or np.any(arrs[4] <= 0):
            raise ParameterError("chi1_m and chi2_m (radii of curvature) must be > 0")
        return arrs

    def forces(self, delta_m, roll1_m, roll2_m, chi1_m, chi2_m):
        """Contact forces by the numba kernel.

        Parameters
        ----------
        delta_m : array_like, shape (n,)
            Rigid interferences δ_i in slot order, m.
        roll1_m, roll2_m : array_like, shape (n,)
            Roll lengths of the contact points on gear 1 and gear 2, m.
        chi1_m, chi2_m : array_like, shape (n,)
            Radii of curvature at the contacts, m.

        Returns
        -------
        ndarray, shape (n,)
            F_i >= 0, N.

        Raises
        ------
        RuntimeError
            If the solver does not converge.
        """
        d, r1, r2, c1, c2 = self._check(delta_m, roll1_m, roll2_m, chi1_m, chi2_m)
        out = np.empty(d.size)
        work = np.empty(work_size(d.size))
        it = hybrid_forces_jit(d, r1, r2, c1, c2, *self.kernel_args(), np.zeros(d.size), work,
                               out)
        if it < 0:
            raise RuntimeError("hybrid contact solve did not converge")
        return out

    def coupling_matrix(self, roll1_m, roll2_m):
        """C = λ^p + λ^w for contacts in slot order, m/N, shape (n, n)."""
        r1 = np.ascontiguousarray(roll1_m, dtype=float)
        r2 = np.ascontiguousarray(roll2_m, dtype=float)
        c = np.empty(r1.size ** 2)
        hp, d1, c1, d2, c2 = self.kernel_args()
        coupling_matrix_jit(r1, r2, hp, d1, c1, d2, c2, c)
        return c.reshape(r1.size, r1.size)

    def local_approach(self, force_n, chi1_m, chi2_m):
        """u^p_L + u^w_L for one contact, m (vectorised over forces)."""
        hp = self.params
        f = np.asarray(force_n, dtype=float)
        a = hertz_half_width(np.maximum(f, 0.0), chi1_m, chi2_m, hp[14], hp[15])
        return (local_approach(f, a, hp[8], hp[10], hp[11], hp[14])
                + local_approach(f, a, hp[9], hp[12], hp[13], hp[14]))

    def forces_reference(self, delta_m, roll1_m, roll2_m, chi1_m, chi2_m):
        """Contact forces by enumerating active sets (slow, independent of the kernel).

        Every subset A of the contacts is tried: the compatibility equations on A are solved
        with :func:`scipy.optimize.root` (the coupling matrix from the tables, Python local
        terms), and the subset whose forces are all positive and whose other contacts have
        non-negative gaps is returned.

        Returns
        -------
        ndarray, shape (n,)
            F_i >= 0, N.
        """
        d, r1, r2, x1, x2 = self._check(delta_m, roll1_m, roll2_m, chi1_m, chi2_m)
        n = d.size
        if np.max(d) <= 0:
            return np.zeros(n)
        cm = _python_coupling(self, r1, r2)
        best = None
        for m in range(1, n + 1):
            for sub in itertools.combinations(range(n), m):
                idx = np.array(sub)
                f = self._solve_subset(cm, d, x1, x2, idx)
                if f is None or np.any(f[idx] <= 0):
                    continue
                gaps = cm @ f - d
                others = np.setdiff1d(np.arange(n), idx)
                if np.all(gaps[others] >= -1e-12 * np.max(d)):
                    if best is not None:
                        raise RuntimeError("two active sets satisfy complementarity")
                    best = f
        if best is None:
            raise RuntimeError("no active set satisfies complementarity")
        return best

    def _solve_subset(self, cm, d, x1, x2, idx):
        sub = cm[np.ix_(idx, idx)]
        guess = np.linalg.solve(sub + np.diag(np.full(idx.size, 2e-9)), d[idx])
        if np.any(guess <= 0):
            guess = np.maximum(guess, 1e-3 * np.max(np.abs(guess)) + 1e-12)

        def fun(fa):
            fa = np.abs(fa)
            ul = np.array([self.local_approach(fa[j], x1[i], x2[i]) for j, i in enumerate(idx)])
            return (ul + sub @ fa - d[idx]) / np.max(d)

        sol = root(fun, guess, method="hybr", options={"xtol": 1e-13})
        if np.max(np.abs(fun(sol.x))) > 1e-11:      # success flags are too strict at 1e-13
            return None
        f = np.zeros(d.size)
        f[idx] = sol.x
        return f


def _python_coupling(model, r1, r2):
    """C from the InfluenceTable.coefficient methods (independent of the kernel lookup)."""
    n = r1.size
    c = np.empty((n, n))
    for i in range(n):
        for k in range(n):
            c[i, k] = (model.driving.coefficient(i - k, r1[i], r1[k])
                       + model.driven.coefficient(k - i, r2[i], r2[k]))
    return c
