"""The tooth contact's oil and dissipation: lubricant properties, friction and damping."""

from __future__ import annotations

from dataclasses import dataclass

from cmsim.errors import check_range
from cmsim.rig.ranges import RANGES

__all__ = ["Lubricant", "MeshContact"]


@dataclass(frozen=True)
class Lubricant:
    """Lubricant between the teeth.

    Attributes
    ----------
    dynamic_viscosity_pa_s : float
        Dynamic viscosity η, Pa·s (Koster squeeze-film damping, paper eq. 5).
    pressure_viscosity_pa_inv : float
        Barus pressure-viscosity coefficient α, 1/Pa (EHL film thickness, :mod:`cmsim.losses`;
        mineral oils 1-3e-8).
    density_kg_m3 : float
        Oil density, kg/m³ (paper 000 Table 5: 970 for its ISO 46).
    surface_roughness_m : float
        Composite RMS roughness σ = sqrt(σ1² + σ2²) of the tooth and race surfaces, m (film
        ratio λ = h/σ of the mixed-lubrication friction).
    """

    dynamic_viscosity_pa_s: float = 0.004
    pressure_viscosity_pa_inv: float = 2.0e-8
    density_kg_m3: float = 870.0
    surface_roughness_m: float = 0.4e-6

    def __post_init__(self):
        check_range("dynamic_viscosity_pa_s", self.dynamic_viscosity_pa_s, 0.0, 10.0, unit="Pa s")
        check_range("pressure_viscosity_pa_inv", self.pressure_viscosity_pa_inv, 0.0, 1e-7,
                    unit="1/Pa")
        check_range("density_kg_m3", self.density_kg_m3, 100.0, 3000.0, unit="kg/m^3")
        check_range("surface_roughness_m", self.surface_roughness_m, 0.0, 50e-6, lo_open=True,
                    unit="m")


@dataclass(frozen=True)
class MeshContact:
    """Dissipative terms of the tooth contact (paper §4).

    The paper does not print ξ, v0 or δ_threshold; the defaults are our choices.

    Attributes
    ----------
    friction_coefficient : float
        Coulomb coefficient f (paper: 0, 0.03, 0.05).
    friction_smoothing_m_s : float
        v0 of the smoothed sign v/sqrt(v² + v0²), m/s. 0.05 m/s spreads the flip at the pitch
        point over about 4 steps at 75 kHz and 1000 rpm.
    damping_ratio : float
        ξ of the hysteretic damping 2ξ·sqrt(K̄·M_eq) in contact.
    squeeze_gap_threshold_m : float
        δ_threshold that bounds the Koster squeeze-film coefficient out of contact, m.
    """

    friction_coefficient: float = 0.0
    friction_smoothing_m_s: float = 0.05
    damping_ratio: float = 0.05
    squeeze_gap_threshold_m: float = 1.0e-6

    def __post_init__(self):
        RANGES["friction"].check("friction_coefficient", self.friction_coefficient)
        check_range("friction_smoothing_m_s", self.friction_smoothing_m_s, 0.0, 10.0,
                    lo_open=True, unit="m/s")
        check_range("damping_ratio", self.damping_ratio, 0.0, 1.0)
        check_range("squeeze_gap_threshold_m", self.squeeze_gap_threshold_m, 0.0, 1e-3,
                    lo_open=True, unit="m")
