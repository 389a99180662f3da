"""Power losses and lubrication (papers 000, 002 and 004).

Sits below :mod:`cmsim.dynamics`: it turns a rig and an operating point into the resisting
torques (``loads``) and the mesh friction coefficient along the path (``friction_table``) that
the caller hands to :func:`cmsim.dynamics.simulate`, and reads a finished
:class:`~cmsim.run.Run` back into a power balance.

* :mod:`~cmsim.losses.gear_losses` — windage and meshing (pumping) torques, paper 000 eq. 25-28,
  oil-jet torque eq. 30;
* :mod:`~cmsim.losses.bearing_friction` — Harris–Palmgren load and viscous torques, cage/ball
  speeds with both rings rotating (paper 002 Table 1);
* :mod:`~cmsim.losses.ehl` — Hamrock–Dowson (point) and Dowson–Higginson/Toyoda (line) films;
* :mod:`~cmsim.losses.mixed_friction` — λ ratio, mixed-lubrication friction coefficient,
  :func:`friction_table_for`;
* :mod:`~cmsim.losses.contact_mixed` — contact stiffness and damping under mixed lubrication
  (paper 004 eq. 1-4, 14-16);
* :mod:`~cmsim.losses.breakdown` — every source at one operating point (:class:`LossBreakdown`);
* :mod:`~cmsim.losses.power_balance` — input = output + losses + stored-energy change of a run.
"""

from cmsim.losses.bearing_friction import (BearingFriction, bearing_friction_torque,
                                           ring_kinematics)
from cmsim.losses.breakdown import (LossBreakdown, LossSettings, RunLosses, operating_losses,
                                    run_losses)
from cmsim.losses.contact_mixed import mixed_contact_stiffness_damping
from cmsim.losses.ehl import (film_thickness_line, film_thickness_point, mesh_film_along_path,
                              reduced_modulus_pa)
from cmsim.losses.gear_losses import (air_density_kg_m3, meshing_torque_nm, oil_jet_torque_nm,
                                      windage_torque_nm)
from cmsim.losses.mixed_friction import (friction_table_for, lambda_ratio,
                                         mixed_friction_coefficient)
from cmsim.losses.power_balance import PowerBalance, power_balance

__all__ = ["BearingFriction", "bearing_friction_torque", "ring_kinematics", "LossBreakdown",
           "LossSettings", "RunLosses", "operating_losses", "run_losses",
           "mixed_contact_stiffness_damping", "film_thickness_line", "film_thickness_point", "mesh_film_along_path",
           "reduced_modulus_pa", "air_density_kg_m3", "meshing_torque_nm", "oil_jet_torque_nm",
           "windage_torque_nm", "friction_table_for", "lambda_ratio",
           "mixed_friction_coefficient", "PowerBalance", "power_balance"]
