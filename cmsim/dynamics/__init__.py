"""Equations of motion, numba kernels, integrator, quasi-static solve, modal analysis."""

from cmsim.dynamics.model import DynamicModel, build_model
from cmsim.dynamics.quasistatic import quasi_static_orbit, quasi_static_state
from cmsim.dynamics.simulation import integrate, simulate

__all__ = ["DynamicModel", "build_model", "quasi_static_state",
           "quasi_static_orbit", "integrate", "simulate"]
