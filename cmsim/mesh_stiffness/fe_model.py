"""Two-dimensional linear-elastic finite-element model of a gear body (scikit-fem).

The gear is a plate of thickness ``b`` (the face width) in the transverse plane. Assembly uses
scikit-fem's quadratic triangle (``ElementTriP2``) and its linear-elasticity form; the
stiffness matrix is factorised once (:func:`scipy.sparse.linalg.splu`) and reused for every
load case.

Plane strain or plane stress
----------------------------
The default is **plane strain** (``plane="strain"``), for two reasons:

* the hybrid split at depth h (:mod:`cmsim.mesh_stiffness.influence`) is only consistent
  if the FE body and the analytical local term (Weber-Banaschek, plane strain, as in paper
  001) see the same material law near the contact: the FE displacement at depth h then
  contains the same ln h that the local term removes (with a plane-stress body the two
  logarithms differ by the factor 1 − ν², and the total compliance drifts twice as much
  with h: ≈ 2 % instead of ≈ 1 % for h from 0.1 m to 0.4 m);
* it reproduces the paper's model: the mean mesh stiffness of the paper pair comes out at
  1.08e8 / 1.16e8 / 1.20e8 N/m at 10 / 50 / 100 N·m, against 1.08e8 / 1.16e8 / 1.19e8 N/m
  inferred from the paper's Tables 5/6 (papers/NOTES.md).

Physically, b = 2 m = 6.35 mm is narrow (about the tooth thickness), so the far field of the
tooth bending is closer to plane stress; ``plane="stress"`` is available and gives a mesh
about 5 % softer. The contact zone itself (a ≪ b) is plane strain either way.

Boundary condition
------------------
Every node on the bore circle is fixed (u = 0): the gear is shrunk or keyed onto a shaft that
is rigid compared with the web; the shaft's own torsion and bending are degrees of freedom of
the dynamic model, not of the mesh stiffness.

Units: SI (m, N, Pa). Forces are totals over the face width (N), so displacements per unit
force are the compliances of the b-wide gear.

References
----------
.. [1] T. Gustafsson, G. D. McBain, "scikit-fem: A Python package for finite element
   assembly", JOSS 5 (2020) 2369.
.. [2] S. P. Timoshenko, J. N. Goodier, *Theory of Elasticity*, 3rd ed. (1970), §§ 7-8
   (plane stress, plane strain).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse.linalg import splu

from cmsim.errors import ParameterError, check_choice, check_range, check_type
from cmsim.mesh_stiffness.fe_mesh import GearMesh, MeshSpec, gear_mesh
from cmsim.rig import SpurGear

__all__ = ["PLANE_MODES", "ElasticModel2D", "GearBodyModel", "lame_parameters"]

#: Allowed two-dimensional idealisations.
PLANE_MODES = ("stress", "strain")


def lame_parameters(youngs_modulus_pa, poisson_ratio, plane):
    """Lamé constants (λ, μ) of the 2-D idealisation, Pa.

    Parameters
    ----------
    youngs_modulus_pa : float
        E, Pa.
    poisson_ratio : float
        ν.
    plane : {'stress', 'strain'}
        Plane stress uses λ* = 2λμ/(λ + 2μ) = Eν/(1 − ν²); plane strain the 3-D λ.

    Returns
    -------
    (float, float)
        λ and μ, Pa.

    Examples
    --------
    >>> lam, mu = lame_parameters(210e9, 0.3, "stress")
    >>> round(lam / 1e9, 3), round(mu / 1e9, 3)
    (69.231, 80.769)
    """
    check_choice("plane", plane, PLANE_MODES)
    e, nu = float(youngs_modulus_pa), float(poisson_ratio)
    mu = e / (2.0 * (1.0 + nu))
    lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)) if plane == "strain" else e * nu / (1 - nu ** 2)
    return lam, mu


@dataclass(frozen=True, eq=False)
class ElasticModel2D:
    """A factorised 2-D linear-elastic model on a scikit-fem triangle mesh.

    Build it with :meth:`from_mesh`.

    Attributes
    ----------
    mesh : skfem.MeshTri
        The mesh (coordinates in m).
    basis : skfem.CellBasis
        Vector P2 basis.
    youngs_modulus_pa, poisson_ratio : float
        Material.
    thickness_m : float
        Out-of-plane thickness b, m.
    plane : str
        One of :data:`PLANE_MODES`.
    fixed_dofs : ndarray of int
        Clamped degrees of freedom.
    factor_seconds : float
        Wall time of assembly and factorisation, s.
    """

    mesh: object = field(repr=False)
    basis: object = field(repr=False)
    youngs_modulus_pa: float
    poisson_ratio: float
    thickness_m: float
    plane: str
    fixed_dofs: np.ndarray = field(repr=False)
    factor_seconds: float
    _free: np.ndarray = field(repr=False)
    _lu: object = field(repr=False)

    @classmethod
    def from_mesh(cls, mesh, youngs_modulus_pa, poisson_ratio, thickness_m, plane,
                  fixed_boundary):
        """Assemble and factorise.

        Parameters
        ----------
        mesh : skfem.MeshTri
            Triangle mesh, m, with the boundary ``fixed_boundary`` tagged.
        youngs_modulus_pa : float
            E, Pa.
        poisson_ratio : float
            ν in [0, 0.5).
        thickness_m : float
            b, m.
        plane : {'stress', 'strain'}
        fixed_boundary : str
            Name of the clamped boundary (all displacement components zero).

        Returns
        -------
        ElasticModel2D
        """
        from skfem import Basis, ElementTriP2, ElementVector, asm
        from skfem.models.elasticity import linear_elasticity

        e = check_range("youngs_modulus_pa", youngs_modulus_pa, 1e6, 1e13, unit="Pa")
        nu = check_range("poisson_ratio", poisson_ratio, 0.0, 0.5, hi_open=True)
        b = check_range("thickness_m", thickness_m, 0.0, lo_open=True, unit="m")
        if fixed_boundary not in (mesh.boundaries or {}):
            raise ParameterError(f"fixed_boundary {fixed_boundary!r} is not a boundary of the "
                                 "mesh")
        t0 = time.perf_counter()
        basis = Basis(mesh, ElementVector(ElementTriP2()), intorder=4)
        lam, mu = lame_parameters(e, nu, plane)
        stiffness = b * asm(linear_elasticity(lam, mu), basis)
        fixed = basis.get_dofs(fixed_boundary).all()
        free = np.setdiff1d(np.arange(basis.N), fixed)
        lu = splu(stiffness[free][:, free].tocsc())
        return cls(mesh=mesh, basis=basis, youngs_modulus_pa=e, poisson_ratio=nu,
                   thickness_m=b, plane=plane, fixed_dofs=fixed,
                   factor_seconds=time.perf_counter() - t0, _free=free, _lu=lu)

    @property
    def n_dofs(self):
        """Number of degrees of freedom (including the clamped ones)."""
        return int(self.basis.N)

    def probe(self, points_m):
        """Sparse matrix that maps a displacement vector to displacements at points.

        Parameters
        ----------
        points_m : ndarray, shape (n, 2)
            Points inside the mesh, m.

        Returns
        -------
        scipy.sparse matrix, shape (2 n, n_dofs)
            Rows ``k`` give u_x at point k, rows ``n + k`` give u_y.
        """
        pts = np.asarray(points_m, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise ParameterError("points_m must have shape (n, 2)")
        try:
            return self.basis.probes(np.ascontiguousarray(pts.T)).tocsr()
        except ValueError as exc:            # skfem: a point outside every element
            raise ParameterError(f"a probe point lies outside the mesh: {exc}") from None

    def point_load_vectors(self, points_m, directions):
        """Consistent nodal forces of unit point loads (one column per load).

        Parameters
        ----------
        points_m : ndarray, shape (n, 2)
            Load points inside (or within round-off of) the mesh, m.
        directions : ndarray, shape (n, 2)
            Force directions (unit vectors); each load is 1 N in total.

        Returns
        -------
        ndarray, shape (n_dofs, n)
        """
        d = np.asarray(directions, dtype=float)
        n = d.shape[0]
        probe = self.probe(points_m)                      # (2n, N)
        weights = np.zeros((2 * n, n))
        weights[np.arange(n), np.arange(n)] = d[:, 0]
        weights[n + np.arange(n), np.arange(n)] = d[:, 1]
        return np.asarray(probe.T @ weights)

    def solve(self, loads):
        """Displacements for one or several load vectors.

        Parameters
        ----------
        loads : ndarray, shape (n_dofs,) or (n_dofs, k)
            Nodal forces, N.

        Returns
        -------
        ndarray, same shape as ``loads``
            Nodal displacements, m (zero on the clamped dofs).
        """
        f = np.asarray(loads, dtype=float)
        if f.shape[0] != self.n_dofs:
            raise ParameterError(f"loads must have {self.n_dofs} rows, got {f.shape[0]}")
        u = np.zeros_like(f)
        u[self._free] = self._lu.solve(np.ascontiguousarray(f[self._free]))
        return u


@dataclass(frozen=True, eq=False)
class GearBodyModel:
    """FE model of a whole gear body clamped at its bore.

    Attributes
    ----------
    gear : SpurGear
    gear_mesh : GearMesh
        The triangulation (frame of :mod:`cmsim.mesh_stiffness.fe_mesh`: tooth 0 on +y).
    model : ElasticModel2D
        Assembled and factorised model.
    mesh_seconds : float
        Wall time of the mesh generation, s.
    """

    gear: SpurGear
    gear_mesh: GearMesh = field(repr=False)
    model: ElasticModel2D = field(repr=False)
    mesh_seconds: float

    @classmethod
    def from_gear(cls, gear, spec=MeshSpec(), plane="strain", crack=None):
        """Mesh, assemble and factorise the body of ``gear``.

        Parameters
        ----------
        gear : SpurGear
            Geometry, bore radius and material (E, ν, face width).
        spec : MeshSpec
            Mesh sizes.
        plane : {'stress', 'strain'}
            2-D idealisation (module docstring).
        crack : RootCrack, optional
            Root crack cut into tooth 0 (:func:`~cmsim.mesh_stiffness.fe_mesh.gear_mesh`);
            its faces are traction-free.

        Returns
        -------
        GearBodyModel
        """
        check_type("gear", gear, SpurGear)
        check_choice("plane", plane, PLANE_MODES)
        t0 = time.perf_counter()
        gm = gear_mesh(gear, spec, crack)
        t_mesh = time.perf_counter() - t0
        model = ElasticModel2D.from_mesh(gm.to_skfem(), gear.youngs_modulus_pa,
                                         gear.poisson_ratio, gear.face_width_m, plane, "bore")
        return cls(gear=gear, gear_mesh=gm, model=model, mesh_seconds=t_mesh)
