"""Ball bearings: Hertz stiffness (Annex B), Fukata ball forces, cage kinematics."""

from cmsim.bearings.forces import (ball_offsets, bearing_force, bearing_strain_energy,
                                   bearing_tangent_stiffness, loaded_balls)
from cmsim.bearings.hertz import bearing_contact_stiffness
from cmsim.bearings.kinematics import (ball_pass_cycles_per_rev, cage_angle, cage_ratios,
                                       slip_jitter)

__all__ = ["ball_offsets", "bearing_force", "bearing_strain_energy", "bearing_tangent_stiffness", "loaded_balls",
           "bearing_contact_stiffness", "ball_pass_cycles_per_rev", "cage_angle", "cage_ratios",
           "slip_jitter"]
