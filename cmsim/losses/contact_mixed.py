"""Contact stiffness and damping of the tooth contact under mixed lubrication (paper 004).

Per contact (paper 004 §2.2), with b the Hertz half-width, w the face width, h the film,
η the oil viscosity and λ_a the asperity contact area ratio:

    c_g = 8·η·b³·w / h³                                           (eq. 1, film damping)
    C_l = (1 − λ_a)·c_g                                            (eq. 2)
    K_h = K_s + K_l,    K_l = A_n·(1 − λ_a)·B / h                  (eq. 3)
    C_h = (1/(ξ·sqrt(m·K_s)) + h³/((1 − λ_a)·8·η·b³·w))^−1          (eq. 4)

and for the mesh (eq. 12, 14-16): K_m = (1/K_sys + 1/K_h)^−1 with K_sys the structural pair
stiffness (our mesh table), C_m = C_sys + C_h with C_sys = 2ζ·sqrt(m_eq·K̄_sys) (eq. 15
prints 2ζ·sqrt(m_eq)·K̄_sys, dimensionally a slip: the usual critical-damping form is used).

Simplification of eq. 3's asperity integral: the asperity stiffness at a given load F of a
Greenwood–Williamson surface with an exponential summit-height tail is K_s = F/σ (it does not
depend on the asperity count: the classic "stiffness ∝ load / roughness" of rough contacts);
λ_a is taken equal to the asperity load share 1 − ψ(λ) (GW: real area ∝ asperity load).
B is the oil's bulk modulus, A_n = 2b·w the nominal contact area.

References
----------
.. [1] Paper 004, eq. 1-4, 12, 14-16, Fig. 5 (rougher → lower stiffness and damping).
.. [2] J.A. Greenwood, J.B.P. Williamson, Contact of nominally flat surfaces, Proc. R. Soc.
       A 295 (1966) 300-319.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from cmsim.errors import check_range
from cmsim.losses.mixed_friction import fluid_load_share, mesh_friction_along_path

__all__ = ["OIL_BULK_MODULUS_PA", "ContactStiffnessDamping", "mixed_contact_stiffness_damping",
           "mixed_lubrication_mesh",
           "mesh_mixed_stiffness_damping"]

#: Bulk modulus of a mineral oil, Pa.
OIL_BULK_MODULUS_PA = 1.5e9


@dataclass(frozen=True)
class ContactStiffnessDamping:
    """Stiffness (N/m) and damping (N·s/m) of contacts, arrays of one shape.

    Attributes
    ----------
    asperity_stiffness, film_stiffness, contact_stiffness : ndarray
        K_s, K_l and K_h = K_s + K_l, N/m.
    film_damping, contact_damping : ndarray
        C_l (eq. 2) and C_h (eq. 4), N·s/m.
    asperity_area_ratio : ndarray
        λ_a.
    """

    asperity_stiffness: np.ndarray
    film_stiffness: np.ndarray
    contact_stiffness: np.ndarray
    film_damping: np.ndarray
    contact_damping: np.ndarray
    asperity_area_ratio: np.ndarray


def mixed_contact_stiffness_damping(load_n, half_width_m, face_width_m, film_m, film_ratio,
                                    roughness_m, viscosity_pa_s, *, mass_kg=1.0,
                                    damping_ratio=0.05, bulk_modulus_pa=OIL_BULK_MODULUS_PA):
    """Paper 004 eq. 1-4 for contacts of load ``load_n`` (arrays broadcast).

    Parameters
    ----------
    load_n : ndarray
        Contact load F, N.
    half_width_m : ndarray
        Hertz half-width b, m.
    face_width_m : float
        Face width w, m.
    film_m : ndarray
        Film thickness h (central), m.
    film_ratio : ndarray
        λ = h_min/σ (sets the asperity area ratio).
    roughness_m : float
        Composite RMS roughness σ, m.
    viscosity_pa_s : float
        Oil viscosity η, Pa·s.
    mass_kg : float
        m of eq. 4 (equivalent mass of the pair), kg.
    damping_ratio : float
        ξ of eq. 4.
    bulk_modulus_pa : float
        B of eq. 3, Pa.

    Returns
    -------
    ContactStiffnessDamping
    """
    check_range("roughness_m", roughness_m, 0.0, 50e-6, lo_open=True, unit="m")
    check_range("face_width_m", face_width_m, 0.0, 10.0, lo_open=True, unit="m")
    f = np.maximum(np.asarray(load_n, dtype=float), 0.0)
    b = np.maximum(np.asarray(half_width_m, dtype=float), 1e-9)
    h = np.maximum(np.asarray(film_m, dtype=float), 1e-10)
    lam_a = 1.0 - fluid_load_share(film_ratio)
    k_s = f / roughness_m
    k_l = 2 * b * face_width_m * (1 - lam_a) * bulk_modulus_pa / h
    c_g = 8 * viscosity_pa_s * b ** 3 * face_width_m / h ** 3
    c_l = (1 - lam_a) * c_g
    asp = damping_ratio * np.sqrt(mass_kg * k_s)
    with np.errstate(divide="ignore"):
        c_h = 1.0 / (np.where(asp > 0, 1.0 / np.where(asp > 0, asp, 1.0), np.inf)
                     + np.where(c_l > 0, 1.0 / np.where(c_l > 0, c_l, 1.0), np.inf))
    return ContactStiffnessDamping(k_s, k_l, k_s + k_l, c_l, c_h, lam_a)


def mesh_mixed_stiffness_damping(rig, op, mesh_table, roughness_m, *, viscosity_pa_s=None,
                                 damping_ratio=None):
    """Pair mesh stiffness and damping along the path with mixed-lubrication contacts.

    K_m(s) = (1/k(s) + 1/K_h(s))^−1 and C_m(s) = C_sys + C_h(s) (paper 004 eq. 12, 14-16) on
    the grid of ``mesh_table`` (k(s): the structural pair stiffness of the table).

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    mesh_table : MeshStiffnessTable
    roughness_m : float
        Composite RMS roughness σ, m.
    viscosity_pa_s : float, optional
        Oil viscosity, Pa·s (default: the rig's).
    damping_ratio : float, optional
        ζ of eq. 15 and ξ of eq. 4 (default: the rig's mesh damping ratio).

    Returns
    -------
    dict of ndarray
        ``position_m``, ``stiffness_n_per_m`` (K_m), ``damping_n_s_per_m`` (C_m),
        ``contact`` (:class:`ContactStiffnessDamping`), ``system_damping_n_s_per_m`` (float).
    """
    pair = rig.gears
    s = mesh_table.position_m
    eta = rig.lubricant.dynamic_viscosity_pa_s if viscosity_pa_s is None else viscosity_pa_s
    zeta = rig.mesh_contact.damping_ratio if damping_ratio is None else damping_ratio
    path = mesh_friction_along_path(rig, op, s, mesh_table, roughness_m=roughness_m,
                                    viscosity_pa_s=eta)
    m_eq = pair.mesh_stiffness_mass_kg
    width = min(pair.driving.face_width_m, pair.driven.face_width_m)
    con = mixed_contact_stiffness_damping(path["load_n"], path["half_width_m"], width,
                                          path["h_c_m"], path["lambda"], roughness_m, eta,
                                          mass_kg=m_eq, damping_ratio=zeta)
    loaded = path["load_n"] > 0
    k_sys = np.asarray(mesh_table.stiffness_n_per_m, dtype=float)
    k_mean = float(np.mean(k_sys[loaded])) if np.any(loaded) else float(np.mean(k_sys))
    c_sys = 2 * zeta * math.sqrt(m_eq * k_mean)
    with np.errstate(divide="ignore", invalid="ignore"):
        k_m = np.where(loaded & (k_sys > 0),
                       1.0 / (1.0 / np.where(k_sys > 0, k_sys, 1.0)
                              + 1.0 / np.where(con.contact_stiffness > 0,
                                               con.contact_stiffness, 1e-30)), 0.0)
    c_m = np.where(loaded, c_sys + con.contact_damping, 0.0)
    return {"position_m": s, "stiffness_n_per_m": k_m, "damping_n_s_per_m": c_m,
            "contact": con, "system_damping_n_s_per_m": c_sys}


def mixed_lubrication_mesh(rig, op, mesh_table, roughness_m, *, viscosity_pa_s=None,
                           damping_ratio=None):
    """The mesh under mixed lubrication as the dynamics takes it (``mesh=``, ``damping_table=``).

    Where the quasi-static mesh cycle loads a pair, its stiffness is K_m(s) and its damping
    C_m(s) of :func:`mesh_mixed_stiffness_damping` (paper 004 eq. 12, 14-16); elsewhere (a
    pair the dynamics loads earlier or later than the quasi-static cycle) the structural
    table's stiffness and the default stiffness-proportional damping β·k, β = 2ξ√(M_eq/k̄),
    are kept, so the dynamics never meets a pair without stiffness.

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    mesh_table : MeshStiffnessTable
        The structural (dry) table at the operating torque.
    roughness_m : float
        Composite RMS roughness σ, m.
    viscosity_pa_s, damping_ratio : float, optional
        As in :func:`mesh_mixed_stiffness_damping`.

    Returns
    -------
    (MeshStiffnessTable, ndarray)
        The table with K_m and the pair damping along its grid, N·s/m, for
        ``cmsim.dynamics.simulate(..., mesh=table, damping_table=c)``.
    """
    mixed = mesh_mixed_stiffness_damping(rig, op, mesh_table, roughness_m,
                                         viscosity_pa_s=viscosity_pa_s,
                                         damping_ratio=damping_ratio)
    k_sys = np.asarray(mesh_table.stiffness_n_per_m, dtype=float)
    loaded = mixed["stiffness_n_per_m"] > 0
    zeta = rig.mesh_contact.damping_ratio if damping_ratio is None else damping_ratio
    beta = 2 * zeta * math.sqrt(rig.gears.mesh_stiffness_mass_kg
                                / mesh_table.mean_mesh_stiffness(rig.gears))
    k = np.where(loaded, mixed["stiffness_n_per_m"], k_sys)
    c = np.where(loaded, mixed["damping_n_s_per_m"], beta * k_sys)
    table = replace(mesh_table, stiffness_n_per_m=k,
                    meta=dict(mesh_table.meta, mixed_lubrication_roughness_m=float(roughness_m)))
    return table, c
