"""Rolling-bearing faults: localized race and ball defects, wear, an off-size ball, slip.

Localized defects (``outer_race``, ``inner_race``, ``ball``) follow Sawalhi & Randall [1]: as
a ball rolls over a defect of length L along the race it loses part of its overlap (its
deflection) — at most the depth it can fall, which the ball's curvature limits to the sagitta
of the chord L on the ball, R_b − sqrt(R_b² − (L/2)²), and the defect depth limits to
``depth_m`` (:func:`ball_drop_m`). The ball rolls down the entry edge (the loss rises over the
distance the ball needs to reach that depth, sqrt(2 R_b d − d²) ≤ L/2) and is pushed back up
abruptly at the exit edge (over :data:`EXIT_RAMP_FRACTION` of the entry distance, our choice;
[1] describe the exit as a sudden restoration). The kernel applies the trapezoid of
:func:`defect_profile` (columns of :class:`~cmsim.faults.compile.FaultArrays`
``bearing_defects``).

* outer race: fixed in the housing at ``angle_rad`` (x axis = 0, counter-clockwise +); by
  default in the load zone: the direction of the radial load on a bearing rig (the CWRU
  "@6" position for a downward load), the line of action of the mesh force on the bearing's
  shaft on a gear rig;
* inner race: turns with the shaft (``angle_rad`` on the ring from its reference);
* ball: one defect on one ball that strikes the outer race and the inner race once each per
  spin revolution (2 × BSF) — when it lies on the ball's rolling track. A ball rolls on a
  great circle perpendicular to its spin axis; a pit elsewhere on the ball never meets the
  races, and one at the track's edge meets them in part (its overlap with the contact band,
  the Hertz ellipse's width across the track, :func:`track_share`).
  ``axis_offset`` is the sine of the defect's latitude above that circle (0: on the track,
  the Sawalhi-Randall case; a defect at a random place on the ball has it uniform in
  [−1, 1]). The spin axis of a real ball is not fixed: cage-pocket friction, gyroscopic
  moments and misalignment turn it, so the defect drifts on and off the track [4], [5];
  ``wander_s`` > 0 makes the axis a random walk on the sphere (rotational diffusion with
  correlation time ``wander_s``: ⟨n(t)·n(0)⟩ = exp(−t/wander_s)), drawn per run from the
  run's seed, and the defect strikes intermittently and with varying strength.

Sizes are lengths along the race (ball: along the ball's surface) in m; a race defect longer
than the ball spacing on that race, or a ball defect longer than the ball diameter, is refused.
``wear`` is clearance growth (a plain rig change, :func:`~cmsim.faults.compile.rig_with_faults`),
``off_size_ball`` one ball larger (or smaller) by Δd, ``rolling_slip`` the random slip of
paper 001 (§5, §6.2.1) as a catalogue entry.

References
----------
.. [1] N. Sawalhi, R. B. Randall, "Simulating gear and bearing interactions in the presence
   of faults. Part I. The combined gear bearing dynamic model and the simulation of localised
   bearing faults", MSSP 22 (2008) 1924-1951, §3.3 and Figs. 6-8.
.. [2] R. B. Randall, J. Antoni, "Rolling element bearing diagnostics — a tutorial", MSSP 25
   (2011) 485-520, eqs. (1)-(4) (defect frequencies).
.. [3] A. Fernandez-del-Rincon et al., MSSP 2016, §5 (rolling slip).
.. [4] W. A. Smith, R. B. Randall, "Rolling element bearing diagnostics using the Case
   Western Reserve University data: a benchmark study", MSSP 64-65 (2015) 100-131 (ball
   faults: intermittent, often not diagnosable).
.. [5] T. A. Harris, M. N. Kotzalas, *Rolling Bearing Analysis*, 5th ed., Wiley 2006,
   ch. 10 (ball spin-axis orientation set by friction and gyroscopic moments, not fixed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cmsim.bearings.hertz import bearing_raceway_contacts, contact_semi_axes_m
from cmsim.errors import ParameterError, check_range
from cmsim.faults.base import Fault, check_angle, check_bearing, check_int, mm, register

__all__ = ["OuterRaceDefect", "InnerRaceDefect", "BallDefect", "BearingWear", "OffSizeBall",
           "RollingSlip", "NO_SLIP", "ball_drop_m", "defect_profile", "track_share",
           "wandering_offset", "EXIT_RAMP_FRACTION", "KIND_OUTER", "KIND_INNER", "KIND_BALL"]

#: Kind codes of the ``bearing_defects`` rows.
KIND_OUTER, KIND_INNER, KIND_BALL = 1.0, 2.0, 3.0

#: Exit ramp as a fraction of the entry ramp (abrupt exit of [1]); our choice.
EXIT_RAMP_FRACTION = 0.2


def ball_drop_m(ball_radius_m, length_m, depth_m):
    """Largest loss of ball overlap in a defect of length L and depth d, m.

    min(d, R_b − sqrt(R_b² − (L/2)²)) (Sawalhi & Randall [1]); the ball reaches the defect
    bottom when L/2 >= R_b.

    Examples
    --------
    >>> round(ball_drop_m(3.97e-3, 1.0e-3, 1e-3) * 1e6, 3)     # 6205 ball, 1 mm defect
    31.612
    """
    half = 0.5 * length_m
    sag = ball_radius_m - math.sqrt(max(ball_radius_m ** 2 - half * half, 0.0))
    return min(depth_m, sag)


def _entry_distance_m(ball_radius_m, length_m, drop_m):
    """Distance the ball rolls over the entry edge to fall by ``drop_m``, <= L/2, m."""
    x = math.sqrt(max(2.0 * ball_radius_m * drop_m - drop_m * drop_m, 0.0))
    return min(x, 0.5 * length_m)


def defect_profile(angle_rad, centre_rad, half_width_rad, entry_rad, exit_rad):
    """Trapezoid of a defect row: 0 outside, linear entry and exit ramps, 1 in between.

    The ball enters at ``centre − half_width`` (moving towards increasing angle) and leaves
    at ``centre + half_width``. Reference implementation of what the kernel evaluates.

    Parameters
    ----------
    angle_rad : ndarray
        Angle of the ball relative to the defect frame, rad (wrapped to (−π, π] about the
        centre).
    centre_rad, half_width_rad, entry_rad, exit_rad : float
        Columns 2, 3, 5, 6 of a ``bearing_defects`` row, rad.

    Returns
    -------
    ndarray
        Profile in [0, 1], same shape as ``angle_rad``.
    """
    a = np.mod(np.asarray(angle_rad, dtype=float) - centre_rad + math.pi, 2 * math.pi) - math.pi
    x = a + half_width_rad                      # distance since the entry edge
    y = half_width_rad - a                      # distance to the exit edge
    up = np.clip(x / entry_rad, 0.0, 1.0) if entry_rad > 0 else (x >= 0).astype(float)
    down = np.clip(y / exit_rad, 0.0, 1.0) if exit_rad > 0 else (y >= 0).astype(float)
    return np.where((x >= 0) & (y >= 0), np.minimum(up, down), 0.0)


def track_share(axis_offset, track_rad, half_width_rad):
    """Share of a ball defect's depth the races meet, by where it sits on the ball (0..1).

    The pit spans [s − h, s + h] across the rolling track (s = R_b·|axis_offset|, h = L/2),
    the contact band [−a, a]; the share is their overlap over the smaller of the two widths:
    1 while the pit is inside the band or covers it (the Sawalhi-Randall case, whatever its
    size), falling linearly to 0 as it slides out, 0 once it misses the band. In ball radii:
    ``track_rad`` = (a + h)/R_b, ``half_width_rad`` = h/R_b.

    Parameters
    ----------
    axis_offset : float or numpy.ndarray
        Sine of the defect's latitude above the rolling track.
    track_rad, half_width_rad : float
        See above.
    """
    s = np.abs(np.asarray(axis_offset, dtype=float))
    h = float(half_width_rad)
    a = float(track_rad) - h
    overlap = np.clip(np.minimum(s + h, a) - np.maximum(s - h, -a), 0.0, None)
    return np.minimum(overlap / (2.0 * min(h, a)), 1.0)


def wandering_offset(axis_offset, wander_s, n_samples, dt_s, rng):
    """Sine of a ball defect's latitude over time with a wandering spin axis.

    The spin axis n is a random walk on the unit sphere (isotropic rotational diffusion,
    coefficient D = 1/(2 τ), so ⟨n(t)·n(0)⟩ = exp(−t/τ)); the defect sits at p = e_z in the
    ball, and the offset is n·p. Each step adds a Gaussian kick sqrt(2 D dt)·ξ perpendicular
    to n and renormalises.

    Parameters
    ----------
    axis_offset : float
        Offset at t = 0, in [−1, 1].
    wander_s : float
        Correlation time τ of the axis, s (> 0).
    n_samples : int
        Samples of the result (t = 0, dt_s, ...).
    dt_s : float
        Spacing, s (well below τ).
    rng : numpy.random.Generator

    Returns
    -------
    numpy.ndarray, shape (n_samples,)
    """
    z = float(axis_offset)
    n = np.array([math.sqrt(max(1.0 - z * z, 0.0)), 0.0, z])
    kicks = rng.standard_normal((int(n_samples), 3)) * math.sqrt(dt_s / wander_s)
    out = np.empty(int(n_samples))
    for i in range(int(n_samples)):
        out[i] = n[2]
        k = kicks[i] - n * (kicks[i] @ n)
        n = n + k
        n /= math.sqrt(n @ n)
    return out


def _check_size(name, value, unit="m"):
    return check_range(name, value, 0.0, 0.1, lo_open=True, unit=unit)


@dataclass(frozen=True)
class _LocalizedDefect(Fault):
    """Common part of the race and ball defects: a pit of ``size_m`` × ``depth_m`` in one
    bearing that a ball rolls over (Sawalhi & Randall [1]).

    Subclasses also hold ``exit_ramp_fraction`` (after their own defaulted fields, so the
    order of the constructor's arguments stays that of each entry).
    """

    bearing: str
    size_m: float
    depth_m: float

    def __post_init__(self):
        if not isinstance(self.bearing, str):
            raise ParameterError(f"bearing must be a bearing name such as '1b1', got "
                                 f"{self.bearing!r}", param="bearing")
        _check_size("size_m", self.size_m)
        check_range("depth_m", self.depth_m, 0.0, 0.01, lo_open=True, unit="m")
        check_range("exit_ramp_fraction", self.exit_ramp_fraction, 0.0, 1.0, unit="")

    def _check_depth_fits(self, brg):
        """Refuse a pit deeper than the ball radius of ``brg``."""
        check_range("depth_m", self.depth_m, 0.0, 0.5 * brg.ball_diameter_m, lo_open=True,
                    unit=f"m (up to the ball radius of {self.bearing})")

    def _drop_and_entry_m(self, ball_radius_m):
        """(largest loss of overlap, entry distance over which it builds up), m."""
        drop = ball_drop_m(ball_radius_m, self.size_m, self.depth_m)
        return drop, _entry_distance_m(ball_radius_m, self.size_m, drop)


@dataclass(frozen=True)
class _RaceDefect(_LocalizedDefect):
    """Common part of the outer- and inner-race defects."""

    angle_rad: float | None = None
    exit_ramp_fraction: float = EXIT_RAMP_FRACTION

    def __post_init__(self):
        super().__post_init__()
        if self.angle_rad is not None:
            check_angle("angle_rad", self.angle_rad)

    @property
    def label(self):
        return f"{self.name}@{self.bearing} size={mm(self.size_m)} depth={mm(self.depth_m)}"

    @property
    def site(self):
        where = "the load zone" if self.angle_rad is None else f"{self.angle_rad:g} rad"
        return f"{self.name} defect at {where} of bearing {self.bearing}"

    def race_radius_m(self, brg):
        raise NotImplementedError

    def validate(self, rig):
        brg = rig.bearings[check_bearing(rig, self.bearing)]
        r = self.race_radius_m(brg)
        spacing = 2 * math.pi * r / brg.n_balls
        check_range("size_m", self.size_m, 0.0, spacing, lo_open=True,
                    unit=f"m (up to the ball spacing on the {self.race} race of "
                         f"{self.bearing}, 2*pi*{r * 1e3:.4g} mm / {brg.n_balls})")
        self._check_depth_fits(brg)
        return self

    def defect_row(self, rig, default_angle_rad):
        """Row of ``FaultArrays.bearing_defects`` for this defect on ``rig``, validated
        against it first (with ``default_angle_rad`` the position of a pit given none)."""
        return self.validate(rig)._row(rig, default_angle_rad)

    def _row(self, rig, default_angle_rad):
        """:meth:`defect_row` of a defect already checked against ``rig``."""
        ib = check_bearing(rig, self.bearing)
        brg = rig.bearings[ib]
        rb, r = 0.5 * brg.ball_diameter_m, self.race_radius_m(brg)
        drop, entry = self._drop_and_entry_m(rb)
        centre = default_angle_rad if self.angle_rad is None else self.angle_rad
        return [float(ib), self.kind, float(centre), 0.5 * self.size_m / r, drop, entry / r,
                self.exit_ramp_fraction * entry / r, -1.0, 0.0, 0.0, 0.0]


@register
@dataclass(frozen=True)
class OuterRaceDefect(_RaceDefect):
    """Localized defect on the outer race, fixed in the housing.

    Attributes
    ----------
    bearing : str
        Bearing name (``rig.bearing_names``, e.g. ``"1b1"``).
    size_m : float
        Defect length along the race, m (> 0, at most the ball spacing on the race).
    depth_m : float
        Defect depth, m (> 0, at most the ball radius).
    angle_rad : float or None
        Position in the housing, rad (x axis = 0, counter-clockwise +); ``None`` = the centre
        of the load zone (:mod:`cmsim.faults.bearing`).
    exit_ramp_fraction : float
        Exit ramp as a fraction of the entry ramp, in [0, 1] (0: an abrupt exit; default
        :data:`EXIT_RAMP_FRACTION`): the defect's edge profile.
    """

    name = "outer_race"
    kind = KIND_OUTER
    race = "outer"

    def race_radius_m(self, brg):
        """Outer raceway radius, m."""
        return 0.5 * brg.outer_raceway_diameter_m


@register
@dataclass(frozen=True)
class InnerRaceDefect(_RaceDefect):
    """Localized defect on the inner race, turning with the shaft.

    Attributes
    ----------
    bearing : str
        Bearing name.
    size_m : float
        Defect length along the race, m (> 0, at most the ball spacing on the race).
    depth_m : float
        Defect depth, m (> 0, at most the ball radius).
    angle_rad : float or None
        Position on the ring from its reference (turning with it), rad; ``None`` = 0.
    exit_ramp_fraction : float
        Exit ramp as a fraction of the entry ramp, in [0, 1] (0: an abrupt exit; default
        :data:`EXIT_RAMP_FRACTION`): the defect's edge profile.
    """

    name = "inner_race"
    kind = KIND_INNER
    race = "inner"

    def race_radius_m(self, brg):
        """Inner raceway radius, m."""
        return 0.5 * brg.inner_raceway_diameter_m


@register
@dataclass(frozen=True)
class BallDefect(_LocalizedDefect):
    """Localized defect (a spall) on one ball, striking both races (2 × BSF).

    Attributes
    ----------
    bearing : str
        Bearing name.
    size_m : float
        Defect length along the ball's surface, m (> 0, below the ball diameter).
    depth_m : float
        Defect depth, m (> 0, at most the ball radius).
    ball : int
        Index of the faulty ball in the cage (0 .. n_balls − 1).
    phase_rad : float
        Phase of the defect on the ball's spin, rad (0 = facing the outer race at t = 0).
    exit_ramp_fraction : float
        Exit ramp as a fraction of the entry ramp, in [0, 1] (0: an abrupt exit; default
        :data:`EXIT_RAMP_FRACTION`): the defect's edge profile.
    axis_offset : float
        Sine of the defect's latitude above the ball's rolling track at t = 0, in [−1, 1]
        (0: on the track; module docstring).
    wander_s : float
        Correlation time of the spin axis' random walk, s (0: a fixed axis, the defect stays
        at ``axis_offset``).
    """

    name = "ball"

    ball: int = 0
    phase_rad: float = 0.0
    exit_ramp_fraction: float = EXIT_RAMP_FRACTION
    axis_offset: float = 0.0
    wander_s: float = 0.0

    def __post_init__(self):
        super().__post_init__()
        check_int("ball", self.ball, 0)
        check_angle("phase_rad", self.phase_rad)
        check_range("axis_offset", self.axis_offset, -1.0, 1.0, unit="")
        check_range("wander_s", self.wander_s, 0.0, 1e3, unit="s")

    @property
    def label(self):
        return (f"ball@{self.bearing}#{self.ball} size={mm(self.size_m)} "
                f"depth={mm(self.depth_m)}")

    @property
    def site(self):
        return f"ball defect on ball {self.ball} of bearing {self.bearing}"

    def validate(self, rig):
        brg = rig.bearings[check_bearing(rig, self.bearing)]
        check_range("size_m", self.size_m, 0.0, brg.ball_diameter_m, lo_open=True,
                    hi_open=True, unit=f"m (below the ball diameter of {self.bearing})")
        self._check_depth_fits(brg)
        check_int("ball", self.ball, 0, brg.n_balls - 1)
        return self

    def defect_row(self, rig, ball_load_n):
        """Row of ``FaultArrays.bearing_defects`` (angles on the ball, radius R_b).

        Parameters
        ----------
        rig : Rig
        ball_load_n : float
            Load of a ball in the load zone, N: sets the contact band's half-width (the
            wider of the outer and inner race contacts, :func:`track_share`).
        """
        return self.validate(rig)._row(rig, ball_load_n)

    def _row(self, rig, ball_load_n):
        """:meth:`defect_row` of a defect already checked against ``rig``."""
        ib = check_bearing(rig, self.bearing)
        brg = rig.bearings[ib]
        rb = 0.5 * brg.ball_diameter_m
        drop, entry = self._drop_and_entry_m(rb)
        band = max(contact_semi_axes_m(c, ball_load_n)[1] for c in bearing_raceway_contacts(brg))
        return [float(ib), KIND_BALL, float(self.phase_rad), 0.5 * self.size_m / rb, drop,
                entry / rb, self.exit_ramp_fraction * entry / rb, float(self.ball),
                float(self.axis_offset), float(self.wander_s),
                (band + 0.5 * self.size_m) / rb]


@register
@dataclass(frozen=True)
class BearingWear(Fault):
    """Distributed wear of a bearing: its radial clearance grows.

    Attributes
    ----------
    bearing : str
        Bearing name.
    clearance_growth_m : float
        Increase of ``clearance_m``, m (> 0; the worn clearance must stay within the
        bearing's allowed range, 5 % of the ball diameter).
    """

    name = "wear"

    bearing: str
    clearance_growth_m: float

    def __post_init__(self):
        check_range("clearance_growth_m", self.clearance_growth_m, 0.0, 1e-3, lo_open=True,
                    unit="m")

    @property
    def label(self):
        return f"wear@{self.bearing} +{1e6 * self.clearance_growth_m:.3g}um"

    @property
    def site(self):
        return f"wear of bearing {self.bearing}"

    def validate(self, rig):
        brg = rig.bearings[check_bearing(rig, self.bearing)]
        check_range("clearance_growth_m", self.clearance_growth_m, 0.0,
                    0.05 * brg.ball_diameter_m - brg.clearance_m, lo_open=True,
                    unit=f"m (worn clearance of {self.bearing} at most 5 % of its ball "
                         "diameter)")
        return self


@register
@dataclass(frozen=True)
class OffSizeBall(Fault):
    """One ball larger (or smaller) than the others by Δd: a extra overlap of Δd.

    Attributes
    ----------
    bearing : str
        Bearing name.
    ball : int
        Index of the ball in the cage.
    diameter_excess_m : float
        Δd, m, signed (+: larger ball), |Δd| at most 1 % of the ball diameter.
    """

    name = "off_size_ball"

    bearing: str
    diameter_excess_m: float
    ball: int = 0

    def __post_init__(self):
        check_range("diameter_excess_m", self.diameter_excess_m, -1e-3, 1e-3, unit="m")
        check_int("ball", self.ball, 0)

    @property
    def label(self):
        return f"off_size_ball@{self.bearing}#{self.ball} {1e6 * self.diameter_excess_m:+.3g}um"

    @property
    def site(self):
        return f"off_size_ball on ball {self.ball} of bearing {self.bearing}"

    def validate(self, rig):
        brg = rig.bearings[check_bearing(rig, self.bearing)]
        lim = 0.01 * brg.ball_diameter_m
        check_range("diameter_excess_m", self.diameter_excess_m, -lim, lim,
                    unit=f"m (1 % of the ball diameter of {self.bearing})")
        check_int("ball", self.ball, 0, brg.n_balls - 1)
        return self


@register
@dataclass(frozen=True)
class RollingSlip(Fault):
    """Random rolling slip of all bearings (paper 001 §5, last assumption, and §6.2.1).

    The one slip value: a catalogue entry (``rolling_slip``) and the ``slip`` argument of
    :func:`cmsim.dynamics.simulate` alike. Two independent effects, both Ornstein-Uhlenbeck
    processes with correlation time ``correlation_s``, drawn from the run's seed:

    * the cage speed fluctuates by a fraction ``cage_speed_rms`` of its nominal value, so the
      cage angle wanders like a random walk and the ball-pass lines spread over a band;
    * each ball leads or lags its nominal place in the cage by a small angle of standard
      deviation ``ball_rms_rad`` (cage-pocket play).

    Attributes
    ----------
    cage_speed_rms : float
        Standard deviation of the relative cage-speed fluctuation (0.01 = 1 %), in [0, 0.2].
    ball_rms_rad : float
        Standard deviation of each ball's angular deviation, rad, in [0, 0.05].
    correlation_s : float
        Correlation time of both processes, s, in [1e-5, 10].
    """

    name = "rolling_slip"

    cage_speed_rms: float = 0.01
    ball_rms_rad: float = 0.0
    correlation_s: float = 5e-3

    def __post_init__(self):
        check_range("cage_speed_rms", self.cage_speed_rms, 0.0, 0.2)
        check_range("ball_rms_rad", self.ball_rms_rad, 0.0, 0.05, unit="rad")
        check_range("correlation_s", self.correlation_s, 1e-5, 10.0, unit="s")

    @property
    def active(self):
        """True when any slip is requested."""
        return self.cage_speed_rms > 0.0 or self.ball_rms_rad > 0.0

    @property
    def label(self):
        return (f"rolling_slip cage={100 * self.cage_speed_rms:.3g}% "
                f"ball={1e3 * self.ball_rms_rad:.3g}mrad")

    @property
    def site(self):
        return "rolling_slip (one per run)"


#: Rolling without slip (the paper's runs but §6.2.1): what a run without ``slip`` uses.
NO_SLIP = RollingSlip(cage_speed_rms=0.0)
