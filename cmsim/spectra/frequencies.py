"""Re-export of :mod:`cmsim.frequencies` (characteristic frequencies are rig kinematics).

Kept so that ``from cmsim.spectra.frequencies import rig_frequencies`` and
``from cmsim.spectra import rig_frequencies`` keep working; new code imports
:mod:`cmsim.frequencies`.
"""

from cmsim.frequencies import (FAMILY_KEYS, BearingFrequencies, RigFrequencies,
                               bearing_frequencies, peak_families, rig_frequencies)

__all__ = ["BearingFrequencies", "RigFrequencies", "bearing_frequencies", "rig_frequencies",
           "peak_families", "FAMILY_KEYS"]
