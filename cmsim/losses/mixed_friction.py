"""Mixed-lubrication friction coefficient of the tooth contact, and its table along the path.

The film ratio λ = h_min/σ (σ: composite RMS roughness) splits the load between the fluid
film and the asperities. The fluid share is our smooth, monotone choice

    ψ(λ) = 1 − exp(−0.9·λ^1.5)

placed on the classic regime bounds (ψ(1) ≈ 0.6: mixed; ψ(3) ≈ 0.99: full film; ψ → 0 in
boundary lubrication), and the friction coefficient mixes the two regimes as
in Castro et al. and paper 004 (App. A.2: "in the asperity contact area the friction
coefficient is a constant depending on the materials, typically 0.08 to 0.15"):

    μ = (1 − ψ)·μ_b + ψ·μ_f

μ_b is the boundary coefficient (default 0.10, inside paper 000 Table 2's 0.07-0.16 for
steel/steel in limit lubrication). μ_f is the film's traction coefficient from an Eyring
fluid at the mean Hertz pressure p̄ (Barus viscosity η = η0·e^(α·p̄), exponent capped at
25), capped by a limiting shear stress τ_L = γ_L·p̄:

    μ_f = min( (τ0/p̄)·asinh(η·|v_s| / (h_c·τ0)), γ_L )

with τ0 = 5 MPa (Eyring stress) and γ_L = 0.06. It depends on the load (p̄), the sliding
speed v_s (zero at the pitch point) and the film (h_c), so it follows the operating point.

References
----------
.. [1] Paper 004, eq. 20-21 and App. A.2; paper 000 Table 2.
.. [2] J. Castro, J. Seabra, Coefficient of friction in mixed film lubrication: gears versus
       twin-discs, Proc. IMechE J 221 (2007) 399-411 (the λ-weighted mixture).
.. [3] S. Bair, W.O. Winer, limiting shear stress of lubricants (γ_L 0.05-0.1).
"""

from __future__ import annotations

import numpy as np

from cmsim.errors import ParameterError, check_range
from cmsim.losses.ehl import mesh_film_along_path

__all__ = ["BOUNDARY_FRICTION", "EYRING_STRESS_PA", "LIMITING_SHEAR_COEFFICIENT",
           "lambda_ratio", "fluid_load_share", "film_friction_coefficient",
           "mixed_friction_coefficient", "mesh_friction_along_path", "friction_table_for"]

#: Boundary (asperity) friction coefficient of steel on steel, limit lubrication.
BOUNDARY_FRICTION = 0.10
#: Eyring stress τ0 of a mineral oil, Pa.
EYRING_STRESS_PA = 5.0e6
#: Limiting shear stress over pressure γ_L.
LIMITING_SHEAR_COEFFICIENT = 0.06


def lambda_ratio(film_m, roughness_m):
    """λ = h/σ (film over composite RMS roughness), same shape as ``film_m``.

    Parameters
    ----------
    film_m : float or ndarray
        Film thickness, m.
    roughness_m : float
        Composite RMS roughness σ, m.
    """
    check_range("roughness_m", roughness_m, 0.0, 50e-6, lo_open=True, unit="m")
    return np.asarray(film_m, dtype=float) / roughness_m


def fluid_load_share(lam):
    """ψ(λ) = 1 − exp(−0.9·λ^1.5) in [0, 1) (module docstring).

    Parameters
    ----------
    lam : float or ndarray
        Film ratio λ.
    """
    lam = np.maximum(np.asarray(lam, dtype=float), 0.0)
    return 1.0 - np.exp(-0.9 * lam ** 1.5)


def film_friction_coefficient(mean_pressure_pa, sliding_m_s, film_m, viscosity_pa_s,
                              pressure_viscosity_pa_inv, *, eyring_stress_pa=EYRING_STRESS_PA,
                              limiting_shear=LIMITING_SHEAR_COEFFICIENT):
    """Traction coefficient of a full EHL film (Eyring, capped by the limiting shear), ≥ 0.

    Parameters
    ----------
    mean_pressure_pa : ndarray
        Mean Hertz pressure p̄, Pa.
    sliding_m_s : ndarray
        Sliding speed v_s, m/s.
    film_m : ndarray
        Central film h_c, m.
    viscosity_pa_s : float
        η0, Pa·s.
    pressure_viscosity_pa_inv : float
        α, 1/Pa.
    eyring_stress_pa : float
        τ0, Pa.
    limiting_shear : float
        γ_L.
    """
    p = np.maximum(np.asarray(mean_pressure_pa, dtype=float), 1.0)
    h = np.maximum(np.asarray(film_m, dtype=float), 1e-10)
    eta = viscosity_pa_s * np.exp(np.minimum(pressure_viscosity_pa_inv * p, 25.0))
    tau = eyring_stress_pa * np.arcsinh(eta * np.abs(sliding_m_s) / (h * eyring_stress_pa))
    return np.minimum(tau / p, limiting_shear)


def mixed_friction_coefficient(lam, film_friction, boundary_friction=BOUNDARY_FRICTION):
    """μ = (1 − ψ(λ))·μ_b + ψ(λ)·μ_f (module docstring).

    Parameters
    ----------
    lam : ndarray
        Film ratio λ.
    film_friction : ndarray
        μ_f of the fluid film.
    boundary_friction : float
        μ_b of the asperities.
    """
    check_range("boundary_friction", boundary_friction, 0.0, 1.0)
    psi = fluid_load_share(lam)
    return (1.0 - psi) * boundary_friction + psi * np.asarray(film_friction, dtype=float)


def mesh_friction_along_path(rig, op, positions_m, mesh_table=None, *, roughness_m=None,
                             viscosity_pa_s=None, boundary_friction=BOUNDARY_FRICTION):
    """Film, λ and mixed friction coefficient of the tooth contact at positions s.

    Returns the dict of :func:`cmsim.losses.ehl.mesh_film_along_path` plus ``lambda``,
    ``film_friction`` and ``friction`` (arrays like ``positions_m``).

    Parameters
    ----------
    rig : Rig
    op : OperatingPoint
    positions_m : ndarray
        Positions s on the line of action, m.
    mesh_table : MeshStiffnessTable, optional
        Load sharing between pairs.
    roughness_m, viscosity_pa_s : float, optional
        Overrides of the rig lubricant's σ and η0.
    boundary_friction : float
        μ_b.
    """
    sigma = rig.lubricant.surface_roughness_m if roughness_m is None else roughness_m
    out = mesh_film_along_path(rig, op, positions_m, mesh_table, viscosity_pa_s=viscosity_pa_s)
    eta = rig.lubricant.dynamic_viscosity_pa_s if viscosity_pa_s is None else viscosity_pa_s
    lam = lambda_ratio(out["h_min_m"], sigma)
    mu_f = film_friction_coefficient(out["mean_pressure_pa"], out["sliding_m_s"], out["h_c_m"],
                                     eta, rig.lubricant.pressure_viscosity_pa_inv)
    out["lambda"] = lam
    out["film_friction"] = mu_f
    out["friction"] = mixed_friction_coefficient(lam, mu_f, boundary_friction)
    return out


def friction_table_for(rig, op, mesh_table, roughness_m, viscosity_pa_s, *,
                       boundary_friction=BOUNDARY_FRICTION):
    """Mesh friction coefficient on ``mesh_table``'s grid, for ``simulate(friction_table=...)``.

    The parameterised cause the measured-data loop fits: a surface roughness and an oil
    viscosity instead of a bare coefficient.

    Parameters
    ----------
    rig : Rig
        A gear rig (its gears, lubricant's α).
    op : OperatingPoint
        Speed and torque (the film and the pressure follow them).
    mesh_table : MeshStiffnessTable
        The run's table (``resolve_mesh(rig, mesh, op.torque_nm)[0]``): its grid and load
        sharing.
    roughness_m : float
        Composite RMS roughness σ, m (0 < σ <= 50 µm).
    viscosity_pa_s : float
        Oil dynamic viscosity η0, Pa·s (0 < η0 <= 10).
    boundary_friction : float
        μ_b of the asperity contacts.

    Returns
    -------
    ndarray, shape (len(mesh_table.position_m),)
        μ(s) in [0, 1].

    Examples
    --------
    >>> from cmsim.rig import Rig, OperatingPoint
    >>> from cmsim.mesh_stiffness.table import MeshStiffnessTable
    >>> rig = Rig.paper_2016()
    >>> tab = MeshStiffnessTable.constant(rig.gears, 1e8)
    >>> mu = friction_table_for(rig, OperatingPoint(1000.0, 50.0), tab, 0.4e-6, 0.004)
    >>> bool(0.0 <= mu.min() and mu.max() <= 0.16)
    True
    """
    if rig.gears is None:
        raise ParameterError("friction_table_for needs a rig with gears")
    check_range("viscosity_pa_s", viscosity_pa_s, 0.0, 10.0, lo_open=True, unit="Pa s")
    out = mesh_friction_along_path(rig, op, mesh_table.position_m, mesh_table,
                                   roughness_m=roughness_m, viscosity_pa_s=viscosity_pa_s,
                                   boundary_friction=boundary_friction)
    return np.clip(np.ascontiguousarray(out["friction"], dtype=float), 0.0, 1.0)
