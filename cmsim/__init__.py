"""cmsim: vibration of a spur-gear transmission on ball bearings, for condition monitoring."""

from cmsim.errors import IntegrationDiverged, ParameterError
from cmsim.rig import (Coupling, GearPair, Lubricant, MeshContact, OperatingPoint, Rig,
                       RollingBearing, Rotor, ShaftLine, SpurGear)

__version__ = "0.1.0"

__all__ = [
    "Coupling", "GearPair", "Lubricant", "MeshContact", "OperatingPoint", "Rig",
    "RollingBearing", "Rotor", "ShaftLine", "SpurGear", "ParameterError", "IntegrationDiverged",
    "__version__",
]
