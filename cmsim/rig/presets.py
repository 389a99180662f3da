"""Named rigs: the paper's gear rig and the bearing test rigs of the public datasets.

A dataset spec's ``[rig] builtin = "..."`` and the command line's rig names read
:data:`PRESETS`. The bearing rigs carry the documented bearing geometry of the public
datasets; their rotor (5 kg, 0.01 kg·m²) is a stated assumption (undocumented there), and
they are loaded through :attr:`OperatingPoint.radial_load_n <cmsim.rig.OperatingPoint>`.
"""

from __future__ import annotations

from cmsim.errors import ParameterError
from cmsim.rig.bearing import RollingBearing
from cmsim.rig.rig import Rig
from cmsim.rig.shafts import Rotor

__all__ = ["PRESETS", "preset", "cwru_6205_rig", "mfpt_nice_rig"]


def cwru_6205_rig():
    """A rotor on two SKF 6205 ball bearings (CWRU drive-end geometry: 9 balls,
    d = 7.94 mm, pitch D = 39.04 mm), loaded radially through ``radial_load_n``."""
    brg = RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3)
    return Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01),
                                 name="cwru_6205")


def mfpt_nice_rig():
    """A rotor on two MFPT test bearings (NICE, 8 rollers, d = 5.969 mm (0.235 in), pitch
    D = 31.623 mm (1.245 in), 0 deg), loaded radially through ``radial_load_n``."""
    brg = RollingBearing.from_pitch(8, 5.969e-3, 31.623e-3)
    return Rig.rotor_on_bearings(brg, Rotor(mass_kg=5.0, inertia_kg_m2=0.01),
                                 name="mfpt_nice")


#: Built-in rigs by name → a function that builds one.
PRESETS = {"paper_2016": Rig.paper_2016, "cwru_6205": cwru_6205_rig,
           "mfpt_nice": mfpt_nice_rig}


def preset(name):
    """The built-in rig called ``name`` (a key of :data:`PRESETS`).

    Examples
    --------
    >>> preset("cwru_6205").bearings[0].n_balls
    9
    """
    try:
        return PRESETS[name]()
    except (KeyError, TypeError):
        raise ParameterError(f"builtin rig must be one of {sorted(PRESETS)}, got {name!r}",
                             param="builtin", allowed=", ".join(sorted(PRESETS))) from None
