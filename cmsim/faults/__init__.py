"""The fault catalogue (issue 16): frozen values applied to the model before it is built.

See :mod:`cmsim.faults.base` (registry, parsing), :mod:`~cmsim.faults.bearing`,
:mod:`~cmsim.faults.gear`, :mod:`~cmsim.faults.operating` (the entries),
:mod:`~cmsim.faults.crack` (cracked-tooth stiffness) and :mod:`~cmsim.faults.compile`
(what the dynamics consumes).

Examples
--------
>>> from cmsim.faults import parse_fault, FAULT_TYPES
>>> sorted(FAULT_TYPES)[:3]
['ball', 'eccentricity', 'inner_race']
"""

from cmsim.faults.base import (FAULT_TYPES, Fault, fault_from_dict, faults_to_toml_list,
                               first_clash, load_faults, parse_fault)
from cmsim.faults.bearing import (NO_SLIP, BallDefect, BearingWear, InnerRaceDefect,
                                  OffSizeBall, OuterRaceDefect, RollingSlip)
from cmsim.faults.compile import (FaultArrays, check_faults, compile_faults, fault_frequencies,
                                  operating_modulation, rig_with_faults, slip_from_faults)
from cmsim.faults.gear import (Eccentricity, ProfileError, ToothBreakage, ToothCrack,
                               ToothSpall)
from cmsim.faults.operating import SpeedFluctuation, TorqueRipple

__all__ = [
    "FAULT_TYPES", "Fault", "fault_from_dict", "faults_to_toml_list", "first_clash", "load_faults",
    "parse_fault", "BallDefect", "BearingWear", "InnerRaceDefect", "OffSizeBall",
    "OuterRaceDefect", "RollingSlip", "NO_SLIP", "FaultArrays", "check_faults", "compile_faults",
    "fault_frequencies", "operating_modulation", "rig_with_faults", "slip_from_faults",
    "Eccentricity", "ProfileError", "ToothBreakage", "ToothCrack", "ToothSpall",
    "SpeedFluctuation", "TorqueRipple",
]
