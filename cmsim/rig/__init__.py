"""Parameters of a transmission: gears, bearings, shafts, lubricant, housing, operating point.

One concept per module, all frozen dataclasses in SI units:

* :mod:`~cmsim.rig.gears` — :class:`SpurGear`, :class:`GearPair`;
* :mod:`~cmsim.rig.bearing` — :class:`RollingBearing`;
* :mod:`~cmsim.rig.shafts` — :class:`ShaftLine`, :class:`Rotor`, :class:`Coupling`;
* :mod:`~cmsim.rig.contact` — :class:`Lubricant`, :class:`MeshContact`;
* :mod:`~cmsim.rig.housing` — :class:`HousingPath`;
* :mod:`~cmsim.rig.operating` — :class:`OperatingPoint`;
* :mod:`~cmsim.rig.rig` — :class:`Rig`: the components, topology and DOF layout, TOML files;
* :mod:`~cmsim.rig.sampling` — :class:`Sampling`, :data:`SAMPLING`: how a run is sampled, the
  one set of defaults;
* :mod:`~cmsim.rig.ranges` — :data:`RANGES`, the one table of allowed ranges;
* :mod:`~cmsim.rig.presets` — named rigs (:data:`PRESETS`);
* :mod:`~cmsim.rig.codec` — dataclasses to plain dicts and back, every key checked.
"""

from cmsim.rig.bearing import RollingBearing
from cmsim.rig.contact import Lubricant, MeshContact
from cmsim.rig.gears import GearPair, SpurGear
from cmsim.rig.housing import HousingPath
from cmsim.rig.operating import OperatingPoint
from cmsim.rig.presets import PRESETS, preset
from cmsim.rig.ranges import RANGES, Range
from cmsim.rig.rig import RIG_FORMAT_VERSION, Rig
from cmsim.rig.sampling import SAMPLING, Sampling
from cmsim.rig.shafts import Coupling, Rotor, ShaftLine

__all__ = ["SpurGear", "GearPair", "RollingBearing", "Rotor", "ShaftLine", "Coupling",
           "Lubricant", "MeshContact", "OperatingPoint", "HousingPath", "Rig",
           "RIG_FORMAT_VERSION", "RANGES", "Range", "PRESETS", "preset", "Sampling",
           "SAMPLING"]
