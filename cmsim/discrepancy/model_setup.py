"""Everything the model of a record is built from: :class:`ModelSetup`, which each cause of
the catalogue (:mod:`cmsim.discrepancy.causes`) extends.

Layering: imports :mod:`cmsim.rig` only.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

from cmsim.rig import HousingPath, OperatingPoint, Rig

__all__ = ["ModelSetup", "NOMINAL_NOISE_RATIO", "CHAIN_FIELDS"]

#: Sensor noise of the nominal model, as a fraction of the healthy model signal's RMS.
NOMINAL_NOISE_RATIO = 0.1


@dataclass(frozen=True)
class ModelSetup:
    """Everything the model of a record is built from.

    Attributes
    ----------
    rig : Rig
    op : OperatingPoint
    faults : tuple of Fault
        Catalogue faults added to the model.
    housing : HousingPath
        Transfer path from bearing forces to the sensor.
    noise_ratio : float
        Sensor noise RMS relative to the healthy nominal model signal's RMS.
    mixed_friction : bool
        Tooth friction from the mixed-lubrication film of the rig's lubricant (roughness,
        viscosity; ``simulate(losses=...)``) instead of the rig's constant coefficient.
    machine : cmsim.machine.Machine or None
        The calibrated machine whose path and background replace ``housing`` and the
        sensor noise (:mod:`cmsim.machine`).
    frequency_factor : float
        Scale of the machine path's frequencies (1: as calibrated).
    structure : str
        Where the machine's structural response that ``frequency_factor`` moves is read:
        ``"path"``, its calibrated path; ``"floor"``, its baseline's broadband floor
        (:class:`cmsim.machine.change.Change`).
    lines_follow_path : bool
        Whether the baseline's lines move with the machine's path when its frequencies
        scale (``frequency_factor``): True, they reach the sensor through the structure;
        False, by another way (the mains picked up by the cable, a line drawn at the sensor).
    background_gain : float
        Factor on the machine's background (1: as calibrated).
    white_noise : float
        White noise at the machine's sensor, RMS relative to its background noise's
        (:meth:`Machine.sensor_signal <cmsim.machine.Machine.sensor_signal>`).
    background_level : float
        Factor on the machine's whole background (coloured noise and lines) beyond what
        ``background_gain`` refits within its spread: the ``background`` cause (1: none).
    shaft_forces : tuple of (float, float)
        (shaft order, relative amplitude): a rotating force laid on the bearing force after
        the dynamics, ``F̄ + (F − F̄)·(1 + m·a·cos(kθ)) + a·L·cos(kθ)`` (``m`` the
        ``shaft_modulation``, ``L`` :func:`~cmsim.machine.static_load`; unbalance: order 1,
        misalignment: order 2); quasi-static, the shaft rate being far below the modes.
    shaft_modulation : float
        Depth of the load modulation the shaft forces swing, relative to their amplitude
        (1: the ``a`` above): how far a rotating force swings the mesh and the bearings'
        dynamic load against the line it makes depends on the machine's stiffnesses and on
        its gain at the shaft orders, which a healthy baseline does not pin (a nuisance,
        :data:`~cmsim.discrepancy.signatures.SHAFT_MODULATIONS`).
    """

    rig: Rig
    op: OperatingPoint
    faults: tuple = ()
    housing: HousingPath = HousingPath()
    noise_ratio: float = NOMINAL_NOISE_RATIO
    mixed_friction: bool = False
    machine: object = None
    frequency_factor: float = 1.0
    background_gain: float = 1.0
    white_noise: float = 0.0
    shaft_forces: tuple = ()
    background_level: float = 1.0
    structure: str = "path"
    lines_follow_path: bool = True
    shaft_modulation: float = 1.0

    def with_faults(self, *faults):
        """Same setup with ``faults`` added."""
        return replace(self, faults=self.faults + tuple(faults))

    def dynamics_key(self):
        """What the simulated forces depend on (not the machine, the measurement chain nor
        the shaft forces laid on the force after the dynamics: :data:`CHAIN_FIELDS` at their
        defaults); kept on the setup (its repr is read thousands of times a comparison)."""
        key = self.__dict__.get("_dynamics_key")
        if key is None:
            key = repr(replace(self, machine=None, **{f.name: f.default for f in fields(self)
                                                      if f.name in CHAIN_FIELDS}))
            object.__setattr__(self, "_dynamics_key", key)
        return key

    def chain_key(self):
        """What the sensor signal depends on besides the dynamics (:data:`CHAIN_FIELDS`)."""
        return tuple(getattr(self, name) for name in CHAIN_FIELDS)

    def path_key(self):
        """What the signal before its sensor noise depends on besides the dynamics: the
        chain less the noise ratio, which only scales the noise."""
        return tuple(getattr(self, name) for name in CHAIN_FIELDS if name != "noise_ratio")


#: Fields of :class:`ModelSetup` that shape the sensor signal after the dynamics (the
#: measurement chain, the machine's background and path, the shaft forces laid on the force):
#: its :meth:`~ModelSetup.chain_key`, and at their defaults in its
#: :meth:`~ModelSetup.dynamics_key`.
CHAIN_FIELDS = ("housing", "noise_ratio", "frequency_factor", "background_gain", "white_noise",
                "shaft_forces", "background_level", "structure", "lines_follow_path",
                "shaft_modulation")
