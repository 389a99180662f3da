"""Load-independent gear losses: windage and meshing (pumping) torques, oil-jet torque.

Paper 000 (§3.7-3.9): for one gear of pitch radius r_p turning at ω,

    M_wind = 0.5 · c_wind · ρ_air · ω² · r_p⁵,   c_wind = 1.0034 · n^−0.017     (eq. 25-26)
    M_mesh = 0.5 · c_mesh · ρ_air · ω² · r_p⁵,   c_mesh = 0.7179 · n^0.0387     (eq. 27-28)
    M_qm   = ṁ_j · ω · r_p²                      (radial oil jet, eq. 30)

with ω in rad/s in the torques and n in rpm in the coefficients (the paper's correlations,
fitted on its 38-tooth, module-4 test-rig gears). Each torque acts on each gear of the pair.

References
----------
.. [1] Paper 000 (bearing-gear power-loss model and test rig), eq. 25-30, Table 4.
"""

from __future__ import annotations

import math

import numpy as np

from cmsim.errors import ParameterError, check_range

__all__ = ["AIR_GAS_CONSTANT", "air_density_kg_m3", "windage_coefficient", "meshing_coefficient",
           "windage_torque_nm", "meshing_torque_nm", "oil_jet_torque_nm"]

#: Specific gas constant of dry air, J/(kg·K).
AIR_GAS_CONSTANT = 287.05


def air_density_kg_m3(pressure_pa=101325.0, temperature_c=20.0):
    """Air density from the perfect-gas law ρ = p/(R·T), kg/m³.

    Parameters
    ----------
    pressure_pa : float
        Absolute pressure, Pa (paper 000 Table 4: 100 688 Pa in test 1).
    temperature_c : float
        Temperature, °C (Table 4: 58.83 °C in test 1).

    Examples
    --------
    >>> round(air_density_kg_m3(101325.0, 20.0), 4)
    1.2041
    """
    check_range("pressure_pa", pressure_pa, 0.0, 1e7, lo_open=True, unit="Pa")
    check_range("temperature_c", temperature_c, -100.0, 500.0, unit="degC")
    return pressure_pa / (AIR_GAS_CONSTANT * (temperature_c + 273.15))


def _rpm(speed_rpm):
    s = np.asarray(speed_rpm, dtype=float)
    if not np.all(np.isfinite(s)) or np.any(s <= 0) or np.any(s > 1e5):
        raise ParameterError(f"speed_rpm must be in (0, 100000] rpm, got {speed_rpm!r}")
    return s


def windage_coefficient(speed_rpm):
    """c_wind = 1.0034 · n^−0.017 (paper 000 eq. 26, n in rpm).

    Parameters
    ----------
    speed_rpm : float or ndarray
        Gear speed n, rpm.
    """
    return 1.0034 * _rpm(speed_rpm) ** -0.017


def meshing_coefficient(speed_rpm):
    """c_mesh = 0.7179 · n^0.0387 (paper 000 eq. 28, n in rpm).

    Parameters
    ----------
    speed_rpm : float or ndarray
        Gear speed n, rpm.
    """
    return 0.7179 * _rpm(speed_rpm) ** 0.0387


def _torque(coef, speed_rpm, pitch_radius_m, air_density):
    check_range("pitch_radius_m", pitch_radius_m, 0.0, 10.0, lo_open=True, unit="m")
    check_range("air_density_kg_m3", air_density, 0.0, 100.0, unit="kg/m^3")
    omega = _rpm(speed_rpm) * math.pi / 30.0
    return 0.5 * coef * air_density * omega ** 2 * pitch_radius_m ** 5


def windage_torque_nm(speed_rpm, pitch_radius_m, air_density_kg_m3=1.2041):
    """Windage resisting torque on one gear, N·m (paper 000 eq. 25).

    Parameters
    ----------
    speed_rpm : float or ndarray
        Gear speed, rpm.
    pitch_radius_m : float
        Pitch radius r_p, m.
    air_density_kg_m3 : float
        Density of the surrounding air, kg/m³ (:func:`air_density_kg_m3`).

    Examples
    --------
    >>> round(float(windage_torque_nm(1000.0, 0.076, 1.2041)), 5)     # paper 000 gears
    0.01494
    """
    return _torque(windage_coefficient(speed_rpm), speed_rpm, pitch_radius_m, air_density_kg_m3)


def meshing_torque_nm(speed_rpm, pitch_radius_m, air_density_kg_m3=1.2041):
    """Meshing (air/oil pumping) resisting torque on one gear, N·m (paper 000 eq. 27).

    Parameters
    ----------
    speed_rpm : float or ndarray
        Gear speed, rpm.
    pitch_radius_m : float
        Pitch radius r_p, m.
    air_density_kg_m3 : float
        Density of the surrounding air, kg/m³.
    """
    return _torque(meshing_coefficient(speed_rpm), speed_rpm, pitch_radius_m, air_density_kg_m3)


def oil_jet_torque_nm(speed_rpm, pitch_radius_m, mass_flow_kg_s=0.0):
    """Radial oil-jet torque ṁ_j·ω·r_p² on one gear, N·m (paper 000 eq. 30).

    Parameters
    ----------
    speed_rpm : float or ndarray
    pitch_radius_m : float
    mass_flow_kg_s : float
        Oil mass flow hitting the gear, kg/s (paper 000: 1-7 L/min shared by the gears).
    """
    check_range("mass_flow_kg_s", mass_flow_kg_s, 0.0, 100.0, unit="kg/s")
    return mass_flow_kg_s * _rpm(speed_rpm) * math.pi / 30.0 * pitch_radius_m ** 2
