"""A straight root crack in the loaded fillet of tooth 0 (the FE body's crack).

Where it starts — the loaded fillet's point whose tangent makes :data:`CRITICAL_TANGENT_RAD`
(30°) with the tooth centreline (ISO 6336-3 critical section, :func:`crack_start_point`, the
same start as the potential-energy crack of :mod:`cmsim.faults.crack`) — its path and the
nodes :func:`cmsim.mesh_stiffness.fe_mesh.gear_mesh` cuts into the mesh. All lengths in m, in
the frame of tooth 0 (gear centre at the origin, tooth 0 on +y).

References
----------
.. [1] F. Chaari, T. Fakhfakh, M. Haddar, Eur. J. Mech. A/Solids 28 (2009) 461-468.
.. [2] ISO 6336-3:2006, §6 (critical section at the 30° tangent).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.errors import check_range
from cmsim.mesh_stiffness.geometry import ToothProfile

__all__ = ["RootCrack", "crack_start_point", "CRITICAL_TANGENT_RAD"]

#: Tangent angle to the centreline at the critical section (ISO 6336-3), rad: a root
#: crack starts where the loaded fillet's tangent makes this angle with the centreline.
CRITICAL_TANGENT_RAD = math.radians(30.0)

_START_CACHE = {}


def crack_start_point(profile):
    """(y_s, h_c): height from the gear centre and half-thickness of a root crack's start, m.

    The point of the loaded-side (right) fillet where the tangent makes
    :data:`CRITICAL_TANGENT_RAD` (30°) with the tooth centreline (ISO 6336-3 critical
    section), found by finite differences on the outline of the default resolution (so
    the answer does not depend on how finely ``profile`` was sampled).

    Parameters
    ----------
    profile : ToothProfile

    Returns
    -------
    (float, float)
    """
    key = profile.gear
    if key not in _START_CACHE:
        profile = ToothProfile.from_gear(key)
        y = np.linspace(profile.root_chord_y_m, profile.tip_radius_m, 4001)
        h = profile.half_thickness_at(y)
        slope = np.abs(np.gradient(h, y))
        below = np.nonzero(slope <= math.tan(CRITICAL_TANGENT_RAD))[0]
        i = int(below[0]) if below.size else 0
        _START_CACHE[key] = (float(y[i]), float(h[i]))
    return _START_CACHE[key]


@dataclass(frozen=True)
class RootCrack:
    """A straight root crack in the loaded fillet of tooth 0, cut into the mesh.

    The crack starts (its *mouth*) at the 30° tangent point of the right (loaded, tension
    side) fillet, (h_c, y_s) of :func:`crack_start_point`, and runs a length q towards the
    centreline and the gear centre at the angle ν to the centreline, direction
    (−sin ν, −cos ν); its tip is at h_c − q sin ν from the centreline (Chaari et al. 2009,
    as :mod:`cmsim.faults.crack`). Its faces are traction-free: contact of the faces when
    the crack closes (under compression, e.g. load on the other flank) is not modelled.

    Attributes
    ----------
    depth_m : float
        Crack length q, m (> 0, tip at most on the centreline: q sin ν <= h_c).
    angle_rad : float
        ν, rad, in (0, π/2].
    h_crack : float
        Element size along the crack faces, in modules (0.03); the tip gets half of it.
    """

    depth_m: float
    angle_rad: float = math.pi / 4
    h_crack: float = 0.03

    def __post_init__(self):
        check_range("depth_m", self.depth_m, 0.0, 0.05, lo_open=True, unit="m")
        check_range("angle_rad", self.angle_rad, 0.0, 0.5 * math.pi, lo_open=True, unit="rad")
        check_range("h_crack", self.h_crack, 1e-3, 0.5, unit="modules")

    def as_dict(self):
        """Plain dict of the fields (for cache keys and provenance)."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    def path_m(self, profile):
        """Mouth, direction (unit) and tip of the crack in the frame of tooth 0, m.

        Parameters
        ----------
        profile : ToothProfile
            The tooth (its gear sets the crack start, :func:`crack_start_point`).

        Returns
        -------
        (ndarray, ndarray, ndarray)
            Mouth (2,), m; unit direction (2,); tip (2,), m.

        Raises
        ------
        ParameterError
            If the tip would pass the tooth centreline (q sin ν > h_c).
        """
        y_s, h_c = crack_start_point(profile)
        qmax = h_c / math.sin(self.angle_rad)
        check_range("depth_m", self.depth_m, 0.0, qmax, lo_open=True,
                    unit=f"m (crack tip at most on the tooth centreline: {qmax * 1e3:.4g} mm)")
        mouth = np.array([h_c, y_s])
        direction = np.array([-math.sin(self.angle_rad), -math.cos(self.angle_rad)])
        return mouth, direction, mouth + self.depth_m * direction

    def nodes_m(self, profile):
        """Points along the crack from the mouth to the tip, spaced <= h_crack, m.

        Parameters
        ----------
        profile : ToothProfile

        Returns
        -------
        ndarray, shape (n + 1, 2)
            Mouth first, tip last (n >= 2 segments).
        """
        mouth, direction, _ = self.path_m(profile)
        h = self.h_crack * profile.gear.module_m
        n = max(2, int(math.ceil(self.depth_m / h)))
        t = self.depth_m * np.arange(n + 1) / n
        return mouth + t[:, None] * direction
