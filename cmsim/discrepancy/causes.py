"""The cause catalogue: model extensions that may explain a discrepancy.

A cause is one small class: a catalogue ``name``, the ``parameter`` it fits with its
``bounds`` (SI), the ``probes`` tried when ranking, the components it may sit on, and
:meth:`Cause.apply`, which returns the extended :class:`ModelSetup`. Register it with
:func:`register_cause`::

    @register_cause
    class Misalignment(Cause):
        name = "misalignment"
        parameter = "relative_amplitude"
        bounds = (0.002, 0.1)
        probes = (0.01, 0.04)

        def apply(self, setup, value, component):
            return setup.with_faults(TorqueRipple(relative_amplitude=value, order=2.0))

Layering: imports :mod:`cmsim.faults` and :mod:`cmsim.rig` only.
"""

from __future__ import annotations

import math
import typing
from dataclasses import dataclass, replace

from cmsim.faults import (BallDefect, Eccentricity, InnerRaceDefect, OuterRaceDefect,
                          RollingSlip, SpeedFluctuation, ToothBreakage)
from cmsim.rig import HousingPath, OperatingPoint, Rig

__all__ = ["ModelSetup", "Cause", "CAUSES", "register_cause", "applicable_causes",
           "NOMINAL_NOISE_RATIO"]

#: Sensor noise of the nominal model, as a fraction of the simulated signal's RMS.
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
        Sensor noise RMS relative to the simulated signal's RMS.
    """

    rig: Rig
    op: OperatingPoint
    faults: tuple = ()
    housing: HousingPath = HousingPath()
    noise_ratio: float = NOMINAL_NOISE_RATIO

    def with_faults(self, *faults):
        """Same setup with ``faults`` added."""
        return replace(self, faults=self.faults + tuple(faults))


class Cause:
    """Base of a catalogue cause (subclass, set the class attributes, implement apply)."""

    #: Catalogue name.
    name: typing.ClassVar[str] = ""
    #: Fitted parameter (SI unit in its name).
    parameter: typing.ClassVar[str] = ""
    #: (lo, hi) of the parameter.
    bounds: typing.ClassVar[tuple] = (0.0, 1.0)
    #: Values simulated when ranking.
    probes: typing.ClassVar[tuple] = ()
    #: Fit in log(parameter).
    log_scale: typing.ClassVar[bool] = True
    #: "bearing", "gear" or None: what ``component`` names.
    kind: typing.ClassVar[str | None] = None
    #: Needs gears.
    needs_gears: typing.ClassVar[bool] = False

    def components(self, rig, sensor_bearing):
        """Components this cause may sit on (``[None]`` for a rig-wide cause)."""
        if self.kind == "bearing":
            return [sensor_bearing]
        if self.kind == "gear":
            return ["1G1", "2G1"]
        return [None]

    def applies(self, rig):
        """Whether the cause makes sense on ``rig``."""
        return rig.gears is not None or not self.needs_gears

    def apply(self, setup, value, component):
        """The setup extended by this cause at ``value`` on ``component``."""
        raise NotImplementedError


#: Registered causes, name → class.
CAUSES: dict = {}


def register_cause(cls):
    """Class decorator: add a cause to :data:`CAUSES`."""
    if not cls.name or cls.name in CAUSES:
        raise ValueError(f"cause name {cls.name!r} empty or already registered")
    CAUSES[cls.name] = cls
    return cls


def applicable_causes(rig):
    """Instances of the registered causes that apply to ``rig``."""
    return [c() for c in CAUSES.values() if c().applies(rig)]


def _gear_index(component):
    return 1 if component in (None, "1G1") else 2


# ---------------------------------------------------------------------- gear causes
@register_cause
class EccentricityCause(Cause):
    """Gear eccentricity (once-per-rev modulation of the mesh)."""
    name = "eccentricity"
    parameter = "amplitude_m"
    bounds = (2e-6, 1.5e-4)
    probes = (1e-5, 5e-5)
    kind = "gear"
    needs_gears = True

    def apply(self, setup, value, component):
        return setup.with_faults(Eccentricity(gear=_gear_index(component), amplitude_m=value))


@register_cause
class ToothFaultCause(Cause):
    """A broken (shortened) tooth."""
    name = "tooth_fault"
    parameter = "lost_height_m"
    bounds = (1e-4, 3e-3)
    probes = (5e-4, 2e-3)
    kind = "gear"
    needs_gears = True

    def apply(self, setup, value, component):
        g = setup.rig.gears.driving if _gear_index(component) == 1 else setup.rig.gears.driven
        value = min(value, 0.9 * (g.tip_radius_m - g.root_radius_m))
        return setup.with_faults(ToothBreakage(gear=_gear_index(component),
                                               lost_height_m=value))


@register_cause
class FrictionCause(Cause):
    """Tooth friction (coefficient)."""
    name = "friction"
    parameter = "friction_coefficient"
    bounds = (0.005, 0.2)
    probes = (0.03, 0.08)
    needs_gears = True

    def apply(self, setup, value, component):
        return replace(setup, rig=setup.rig.with_friction(value))


# ---------------------------------------------------------------------- bearing defects
class _Defect(Cause):
    parameter = "size_m"
    bounds = (3e-5, 3e-3)
    probes = (1e-4, 3e-4, 1.2e-3)
    kind = "bearing"
    fault = None

    def apply(self, setup, value, component):
        return setup.with_faults(self.fault(bearing=component, size_m=value,
                                            depth_m=min(1e-4, 0.5 * value)))


@register_cause
class OuterRaceCause(_Defect):
    """Outer-race spall (in the load zone)."""
    name = "bearing_outer_race"
    fault = OuterRaceDefect


@register_cause
class InnerRaceCause(_Defect):
    """Inner-race spall."""
    name = "bearing_inner_race"
    fault = InnerRaceDefect


@register_cause
class BallCause(_Defect):
    """Ball spall."""
    name = "bearing_ball"
    fault = BallDefect


# ---------------------------------------------------------------------- uncertain parameters
@register_cause
class RollingSlipCause(Cause):
    """Random rolling slip of the cage (smears the defect lines)."""
    name = "rolling_slip"
    parameter = "cage_speed_rms"
    bounds = (2e-3, 0.15)
    probes = (0.01, 0.05)

    def apply(self, setup, value, component):
        return setup.with_faults(RollingSlip(cage_speed_rms=value))


def _with_clearance(rig, clearance_m):
    return rig.with_clearance(clearance_m)


@register_cause
class ClearanceCause(Cause):
    """Larger radial clearance of every bearing."""
    name = "clearance"
    parameter = "clearance_m"
    bounds = (1e-6, 1e-4)
    probes = (2e-5, 5e-5)

    def apply(self, setup, value, component):
        return replace(setup, rig=_with_clearance(setup.rig, value))


@register_cause
class PreloadCause(Cause):
    """Preloaded bearings (negative clearance)."""
    name = "preload"
    parameter = "preload_m"
    bounds = (2e-7, 2e-5)
    probes = (2e-6, 8e-6)

    def apply(self, setup, value, component):
        return replace(setup, rig=_with_clearance(setup.rig, -value))


@register_cause
class TorqueMismatchCause(Cause):
    """Load differs from the documented one (output torque; radial load on a bearing rig)."""
    name = "torque_mismatch"
    parameter = "load_factor"
    bounds = (0.15, 6.0)
    probes = (0.4, 2.5)

    def apply(self, setup, value, component):
        op = setup.op
        if setup.rig.gears is not None:
            return replace(setup, op=replace(op, torque_nm=max(op.torque_nm, 1.0) * value))
        return replace(setup, op=replace(op, radial_load_n=max(op.radial_load_n, 10.0) * value))


@register_cause
class SpeedFluctuationCause(Cause):
    """Once-per-revolution fluctuation of the input speed."""
    name = "speed_fluctuation"
    parameter = "relative_amplitude"
    bounds = (1e-3, 0.1)
    probes = (0.01, 0.04)

    def apply(self, setup, value, component):
        return setup.with_faults(SpeedFluctuation(relative_amplitude=value,
                                                  frequency_hz=setup.op.shaft_hz))


@register_cause
class TransferPathCause(Cause):
    """Housing modes at other frequencies than the model's (frequency scale factor)."""
    name = "transfer_path"
    parameter = "frequency_factor"
    bounds = (0.3, 3.0)
    probes = (0.6, 1.6)

    def apply(self, setup, value, component):
        h = setup.housing
        return replace(setup, housing=replace(
            h, natural_frequencies_hz=tuple(f * value for f in h.natural_frequencies_hz)))


@register_cause
class NoiseCause(Cause):
    """Sensor/background noise other than the model's (RMS relative to the signal)."""
    name = "noise"
    parameter = "noise_ratio"
    bounds = (0.005, 10.0)
    probes = (0.02, 1.0)

    def apply(self, setup, value, component):
        return replace(setup, noise_ratio=value)


def clamp(cause, value):
    """``value`` clipped into the cause's bounds."""
    lo, hi = cause.bounds
    return float(min(max(value, lo), hi))


def midpoint(cause):
    """Geometric (log-scale causes) or arithmetic middle of the bounds."""
    lo, hi = cause.bounds
    return math.sqrt(lo * hi) if cause.log_scale else 0.5 * (lo + hi)
