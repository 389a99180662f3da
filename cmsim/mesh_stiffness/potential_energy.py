"""Single tooth-pair stiffness of a spur gear pair by the potential-energy method.

Each tooth is a non-uniform cantilever built in at the root circle, whose half-thickness
h(y) is read from the rack-generated tooth (:class:`~cmsim.mesh_stiffness.geometry.ToothProfile`:
trochoidal fillet, involute, tip rounding), not from the usual idealisation that starts the
involute at the base circle. The compliance of one pair in contact is

    1/k = 1/K_h + Σ_{gear 1, gear 2} (1/K_b + 1/K_s + 1/K_a + 1/K_f)

with bending, shear and axial compression of the tooth (Yang & Lin [1]; eqs. 5-10 of [2]),
the fillet-foundation (gear body) term of Sainsot et al. [3] (eq. 11 of [2]) and the Hertz
term K_h = π E b / (4(1 − ν²)) [1] (eq. 13 of [2]).

Conventions (the same as :mod:`cmsim.mesh_stiffness._kernels`): the contact position ``s`` is
measured along the line of action from the tangent point T1 on the driving gear's base
circle towards T2; with L = a sin α_w = T1T2 the contact radii are sqrt(r_b1² + s²) on gear 1
and sqrt(r_b2² + (L − s)²) on gear 2. Stiffnesses in N/m, compliances in m/N, SI throughout.

Tooth frame (as in :mod:`~cmsim.mesh_stiffness.geometry`): centreline +y, load on the right
flank. For a contact point at radius r with involute pressure angle α_r = acos(r_b / r) and
polar half-angle θ_c = ψ_b − inv α_r, the normal force acts at (x_c, y_c) = r (sin θ_c,
cos θ_c) at the angle α1 = α_r − θ_c to the normal of the centreline; its component F cos α1
bends and shears the tooth, F sin α1 compresses it. The beam is built in on the chord that
joins the two fillet ends on the root circle, at y0 = r_f cos θ_f, and d = y_c − y0.

References
----------
.. [1] D. C. H. Yang, J. Y. Lin, "Hertzian damping, tooth friction and bending elasticity in
   gear impact dynamics", J. Mech. Transm. Autom. Des. 109 (1987) 189-196.
.. [2] G. Cheng et al., "Study on the dynamic characteristics of gears considering surface
   topography in a mixed lubrication state", Lubricants 12 (2024) 7, eqs. 5-13
   (papers/004).
.. [3] P. Sainsot, P. Velex, O. Duverger, "Contribution of gear body to tooth deflections —
   a new bidimensional analytical formula", J. Mech. Des. 126 (2004) 748-752.
.. [4] ISO 6336-1:2006, *Calculation of load capacity of spur and helical gears — Part 1*,
   §9 (tooth stiffness parameters c′ and c_γ, method B).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np

from cmsim.errors import ModelWarning, ParameterError, check_range, check_type
from cmsim.mesh_stiffness._beam_kernels import beam_sums_jit
from cmsim.mesh_stiffness.geometry import ToothProfile, involute_half_angle
from cmsim.rig import GearPair, SpurGear

__all__ = [
    "PairCompliance", "ToothCompliance", "pair_stiffness_potential_energy",
    "pair_compliance_potential_energy", "mesh_stiffness_potential_energy",
    "active_contact_limits_m", "tooth_compliance", "cantilever_compliance",
    "fillet_foundation_compliance", "sainsot_coefficients", "hertz_stiffness",
    "iso6336_stiffness", "SAINSOT_COEFFICIENTS", "SAINSOT_FITTED_RANGES",
]

#: Sainsot et al. (2004) polynomial coefficients (A, B, C, D, E, F) of
#: X* = A/θf² + B hf² + C hf/θf + D/θf + E hf + F, rows L*, M*, P*, Q*.
SAINSOT_COEFFICIENTS = {
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}

#: Ranges of L*, M*, P*, Q* over the gears the fit was made on (as used by ROSS's
#: ``GearElementTVMS``; they correspond to 1.4 <= hf <= 7, 0.01 <= θf <= 0.12 rad).
SAINSOT_FITTED_RANGES = {"L": (6.82, 6.94), "M": (1.08, 3.29), "P": (2.56, 13.47),
                         "Q": (0.141, 0.62)}

#: Timoshenko shear coefficient of a rectangular section used in eq. 6.
_SHEAR_FACTOR = 1.2

#: Load positions integrated at once (bounds the memory of the (rows, n_nodes) arrays).
_ROWS_PER_BLOCK = 256

#: Tolerance on the contact radius range, m.
_RADIUS_TOL_M = 1e-9


# --------------------------------------------------------------------------- results
@dataclass(frozen=True, eq=False)
class ToothCompliance:
    """Compliances of one tooth loaded along the line of action, m/N, shape (n,) each.

    Attributes
    ----------
    bending, shear, axial : ndarray
        1/K_b, 1/K_s, 1/K_a of the tooth cantilever.
    foundation : ndarray
        1/K_f, fillet-foundation (gear body) compliance of Sainsot et al.
    """

    bending: np.ndarray
    shear: np.ndarray
    axial: np.ndarray
    foundation: np.ndarray

    @property
    def total(self):
        """Sum of the four compliances, m/N, shape (n,)."""
        return self.bending + self.shear + self.axial + self.foundation


@dataclass(frozen=True, eq=False)
class PairCompliance:
    """Compliance components of one tooth pair along the contact path.

    Attributes
    ----------
    contact_position_m : ndarray, shape (n,)
        Position s on the line of action from T1, m.
    hertz : float
        1/K_h, m/N (independent of s).
    driving, driven : ToothCompliance
        Tooth compliances of gear 1 and gear 2, m/N, shape (n,) each.
    """

    contact_position_m: np.ndarray
    hertz: float
    driving: ToothCompliance
    driven: ToothCompliance

    @property
    def total(self):
        """Total compliance 1/k of the pair, m/N, shape (n,)."""
        return self.hertz + self.driving.total + self.driven.total

    @property
    def stiffness(self):
        """Single-pair stiffness k, N/m, shape (n,)."""
        return 1.0 / self.total

    def as_dict(self):
        """Components as a flat dict of arrays (m/N), e.g. for plotting or a DataFrame."""
        out = {"contact_position_m": self.contact_position_m,
               "hertz": np.full(self.contact_position_m.shape, self.hertz)}
        for name, tooth in (("driving", self.driving), ("driven", self.driven)):
            for comp in ("bending", "shear", "axial", "foundation"):
                out[f"{comp}_{name}"] = getattr(tooth, comp)
        out["total"] = self.total
        return out


# --------------------------------------------------------------------------- building blocks
def cantilever_compliance(half_thickness_m, length_m, load_offset_m, load_angle_rad,
                          youngs_modulus_pa, poisson_ratio, face_width_m, n_nodes=1001, *,
                          nodes=None):
    """Bending, shear and axial compliance of a non-uniform cantilever (eqs. 5-10 of [2]).

    The beam runs along u from its built-in section (u = 0) and has the rectangular section
    2 h(u) × b. A force F is applied at the section u = d, at the distance e from the beam
    axis, at the angle α1 to the normal of the axis (its axial component compressive). With
    I = (2/3) h³ b, A = 2 h b, G = E / (2(1 + ν)):

        1/K_b = ∫₀ᵈ [cos α1 (d − u) − e sin α1]² / (E I) du
        1/K_s = ∫₀ᵈ 1.2 cos² α1 / (G A) du
        1/K_a = ∫₀ᵈ sin² α1 / (E A) du

    The axial term carries no 1.2 factor: eq. 7 of [2] prints one, but the standard
    Yang-Lin axial compression energy F_a²/(2 E A) has none.

    Parameters
    ----------
    half_thickness_m : callable
        h(u), m, elementwise for an ndarray u (m) of any shape with values in
        [0, max(length_m)]; must return half-thicknesses > 0.
    length_m : array_like, shape (n,)
        d, distance from the built-in section to the loaded section, m (> 0).
    load_offset_m : array_like, shape (n,)
        e, distance of the load point from the beam axis, m.
    load_angle_rad : array_like, shape (n,)
        α1, rad.
    youngs_modulus_pa, poisson_ratio : float
        E (Pa) and ν.
    face_width_m : float
        b, m.
    n_nodes : int
        Nodes of the composite Simpson rule on each [0, d] (made odd); exact for a uniform
        beam.
    nodes : dict, optional
        A store for the nodes and the terms that do not depend on the thickness (moment arm,
        load angle), filled on the first call and read on the next ones: for one beam (the
        same lengths, offsets, angles and ``n_nodes``) integrated with several thicknesses
        (a tooth with cracks of several depths). Without it each block of load sections is
        built and dropped in turn.

    Returns
    -------
    bending, shear, axial : ndarray, shape (n,)
        Compliances, m/N.

    Raises
    ------
    ParameterError
        On non-positive lengths, thicknesses or material constants.
    """
    d = np.atleast_1d(np.asarray(length_m, dtype=float))
    e = np.broadcast_to(np.asarray(load_offset_m, dtype=float), d.shape)
    a1 = np.broadcast_to(np.asarray(load_angle_rad, dtype=float), d.shape)
    if not (np.all(np.isfinite(d)) and np.all(d > 0.0)):
        raise ParameterError("length_m must be finite and > 0")
    if not (np.all(np.isfinite(e)) and np.all(np.isfinite(a1))):
        raise ParameterError("load_offset_m and load_angle_rad must be finite")
    E = check_range("youngs_modulus_pa", youngs_modulus_pa, 0.0, lo_open=True, unit="Pa")
    nu = check_range("poisson_ratio", poisson_ratio, 0.0, 0.5, hi_open=True)
    face_width_m = check_range("face_width_m", face_width_m, 0.0, lo_open=True, unit="m")
    if isinstance(n_nodes, bool) or not isinstance(n_nodes, (int, np.integer)) or n_nodes < 3:
        raise ParameterError(f"n_nodes must be an integer >= 3, got {n_nodes!r}")
    if n_nodes % 2 == 0:
        n_nodes += 1                    # Simpson's rule wants an even number of intervals
    G = E / (2.0 * (1.0 + nu))

    t = np.linspace(0.0, 1.0, int(n_nodes))
    if nodes is None:
        blocks = _beam_blocks(d, e, a1, t)
    else:
        blocks = nodes.get("blocks") or nodes.setdefault("blocks",
                                                         list(_beam_blocks(d, e, a1, t)))
    bending, shear, axial = (np.empty_like(d) for _ in range(3))
    w = _simpson_weights(t.size)
    for sl, u, arm2, c2, s2 in blocks:
        h = np.asarray(half_thickness_m(u), dtype=float)
        if h.shape != u.shape:
            h = h * np.ones_like(u)
        if not (h.min() > 0.0 and np.isfinite(h.max())):            # NaN fails the first
            raise ParameterError("half_thickness_m must return finite values > 0 on the beam")
        sums = np.empty((2, h.shape[0]))
        beam_sums_jit(np.ascontiguousarray(h), arm2, w, float(face_width_m), sums[0], sums[1])
        bending[sl] = sums[0] * d[sl] / E
        ja = sums[1] * d[sl]
        shear[sl] = _SHEAR_FACTOR * c2 * ja / G
        axial[sl] = s2 * ja / E
    return bending, shear, axial


@functools.lru_cache(maxsize=8)
def _simpson_weights(n):
    """Weights of the composite Simpson rule on ``n`` (odd) equally spaced nodes tᵢ of [0, 1]:
    ∫₀ᵈ f(u) du ≈ d · Σ wᵢ f(d tᵢ) (1, 4, 2, 4, …, 4, 1, over 3(n − 1); read-only)."""
    w = np.full(n, 2.0)
    w[1::2] = 4.0
    w[0] = w[-1] = 1.0
    return _read_only(w / (3.0 * (n - 1)))


def _beam_blocks(d, e, a1, t):
    """Blocks of :data:`_ROWS_PER_BLOCK` load sections of :func:`cantilever_compliance`:
    ``(rows, u, arm², cos² α1, sin² α1)`` with the nodes u on [0, d] of every section and
    the bending moment per unit load at them (read-only arrays)."""
    for lo in range(0, d.size, _ROWS_PER_BLOCK):
        sl = slice(lo, lo + _ROWS_PER_BLOCK)
        dd, ee = d[sl, None], e[sl, None]
        c, s = np.cos(a1[sl, None]), np.sin(a1[sl, None])
        u = dd * t                      # nodes on [0, d] for every load position
        arm = c * (dd - u) - ee * s     # bending moment per unit load at section u
        yield sl, *(_read_only(a) for a in (u, arm * arm, c[:, 0] ** 2, s[:, 0] ** 2))


def sainsot_coefficients(root_half_angle_rad, hf):
    """L*, M*, P*, Q* of Sainsot et al. (2004) (eq. 11 of [2]).

    X* = A/θf² + B hf² + C hf/θf + D/θf + E hf + F with the rows of
    :data:`SAINSOT_COEFFICIENTS`. Warns (``UserWarning``) when a value falls outside
    :data:`SAINSOT_FITTED_RANGES`, i.e. the formula is extrapolated.

    Parameters
    ----------
    root_half_angle_rad : float
        θf, half angular tooth thickness at the root circle, rad.
    hf : float
        r_f / r_int, root radius over bore radius.

    Returns
    -------
    dict
        {'L': L*, 'M': M*, 'P': P*, 'Q': Q*}.
    """
    tf = check_range("root_half_angle_rad", root_half_angle_rad, 0.0, math.pi / 2,
                     lo_open=True, unit="rad")
    hf = check_range("hf", hf, 1.0, lo_open=True)
    out = {}
    for key, (A, B, C, D, E, F) in SAINSOT_COEFFICIENTS.items():
        out[key] = A / tf ** 2 + B * hf ** 2 + C * hf / tf + D / tf + E * hf + F
    outside = [f"{k}* = {v:.4g}, fitted {SAINSOT_FITTED_RANGES[k][0]:g}-"
               f"{SAINSOT_FITTED_RANGES[k][1]:g}" for k, v in out.items()
               if not SAINSOT_FITTED_RANGES[k][0] <= v <= SAINSOT_FITTED_RANGES[k][1]]
    if outside:
        warnings.warn("gear mesh stiffness: the tooth foundation's compliance (Sainsot's "
                      "fillet-foundation formula) is extrapolated beyond the tooth shapes it "
                      f"was fitted on (root half-angle θf = {tf:.4f} rad, root over bore "
                      f"radius hf = {hf:.3f}: " + "; ".join(outside) + ")", ModelWarning,
                      stacklevel=2)
    return out


def fillet_foundation_compliance(profile, u_f_m, load_angle_rad):
    """Fillet-foundation compliance 1/K_f of Sainsot et al. (eq. 11 of [2]).

    1/K_f = cos² α1 / (E b) · [L* (u_f/S_f)² + M* (u_f/S_f) + P* (1 + Q* tan² α1)]

    with S_f = 2 r_f sin θf (root chordal thickness) and hf = r_f / r_int (r_int: bore
    radius).

    Parameters
    ----------
    profile : ToothProfile
        The tooth (gives r_f, θf, bore radius, E and b).
    u_f_m : array_like, shape (n,)
        Distance from the root chord (y0 = r_f cos θf) to where the force line crosses the
        tooth centreline, m.
    load_angle_rad : array_like, shape (n,)
        α1, angle between the force line and the normal to the centreline, rad.

    Returns
    -------
    ndarray, shape (n,)
        1/K_f, m/N.
    """
    gear = profile.gear
    coef = sainsot_coefficients(profile.root_half_angle_rad,
                                profile.root_radius_m / gear.bore_radius_m)
    ratio = np.asarray(u_f_m, dtype=float) / profile.root_chord_thickness_m
    a1 = np.asarray(load_angle_rad, dtype=float)
    return (np.cos(a1) ** 2 / (gear.youngs_modulus_pa * gear.face_width_m)
            * (coef["L"] * ratio ** 2 + coef["M"] * ratio
               + coef["P"] * (1.0 + coef["Q"] * np.tan(a1) ** 2)))


def hertz_stiffness(pair):
    """Hertz term K_h of Yang & Lin (eq. 13 of [2]), N/m.

    K_h = π b / (2 [(1 − ν1²)/E1 + (1 − ν2²)/E2]), i.e. π E b / (4(1 − ν²)) for equal
    materials; b is the smaller face width. Independent of the load and of the contact
    position (a linearised line contact).

    Parameters
    ----------
    pair : GearPair

    Returns
    -------
    float
        K_h, N/m.
    """
    _check_pair(pair)
    g1, g2 = pair.driving, pair.driven
    b = min(g1.face_width_m, g2.face_width_m)
    soft = (1 - g1.poisson_ratio ** 2) / g1.youngs_modulus_pa \
        + (1 - g2.poisson_ratio ** 2) / g2.youngs_modulus_pa
    return math.pi * b / (2.0 * soft)


def tooth_compliance(profile, contact_radius_m, n_nodes=1001, thinned=None):
    """Compliance of one tooth loaded on its involute at the given radii.

    Parameters
    ----------
    profile : ToothProfile
        Generated tooth.
    contact_radius_m : array_like, shape (n,)
        Contact radii on the involute, within [form radius, tip-rounding start], m.
    n_nodes : int
        Nodes of the beam integration.
    thinned : callable, optional
        ``thinned(h, y)``: the half-thickness, m, of the section that carries the load, from
        the tooth's own h = ``profile.half_thickness_at(y)`` at the heights
        y = min(y0 + u, r_a) of the beam's nodes (arrays of one shape); default the tooth's
        own. A cracked tooth passes its reduced section
        (:func:`cmsim.faults.crack.cracked_tooth_compliance`); the foundation term stays the
        healthy one. The tooth's own sections at the nodes of a contact grid are then kept
        (:func:`_tooth_sections`) for the next cracked tooth on the same grid.

    Returns
    -------
    ToothCompliance
    """
    check_type("profile", profile, ToothProfile)
    gear = profile.gear
    r = np.atleast_1d(np.asarray(contact_radius_m, dtype=float))
    lo, hi = profile.form_radius_m, profile.tip_round_start_radius_m
    if not np.all(np.isfinite(r)) or np.any(r < lo - _RADIUS_TOL_M) \
            or np.any(r > hi + _RADIUS_TOL_M):
        raise ParameterError(f"contact radii must lie on the involute, in [{lo:g}, {hi:g}] m")
    r = np.clip(r, lo, hi)
    rb = gear.base_radius_m
    alpha_r = np.arccos(rb / r)
    theta_c = involute_half_angle(r, rb, gear.base_half_thickness_angle_rad)
    x_c, y_c = r * np.sin(theta_c), r * np.cos(theta_c)
    a1 = alpha_r - theta_c
    y0 = profile.root_chord_y_m

    def section(u):
        y = np.minimum(y0 + u, profile.tip_radius_m)
        return y, profile.half_thickness_at(y)

    if thinned is None:
        def half_thickness(u):
            return section(u)[1]
    else:
        kept = _tooth_sections(profile, r.tobytes(), int(n_nodes))

        def half_thickness(u):
            # a block of the beam's nodes is known by its rows and its first row's length
            key = (u.shape, float(u[0, -1]))
            if key not in kept:
                kept[key] = tuple(_read_only(a) for a in section(u))
            y, h = kept[key]
            return thinned(h, y)
    bending, shear, axial = cantilever_compliance(
        half_thickness, y_c - y0, x_c, a1, gear.youngs_modulus_pa, gear.poisson_ratio,
        gear.face_width_m, n_nodes=n_nodes, nodes=None if thinned is None else kept)
    u_f = y_c - x_c * np.tan(a1) - y0      # force line meets the centreline below y_c
    foundation = fillet_foundation_compliance(profile, u_f, a1)
    return ToothCompliance(bending=bending, shear=shear, axial=axial, foundation=foundation)


@functools.lru_cache(maxsize=4)
def _tooth_sections(profile, radii_bytes, n_nodes):
    """``{block: (y, h)}``: the heights and the tooth's own half-thicknesses at the beam's
    nodes of :func:`tooth_compliance` for one tooth, contact grid (float64 bytes) and number
    of nodes, filled as blocks are met, and the beam's nodes themselves (``"blocks"``, the
    ``nodes`` of :func:`cantilever_compliance`); read-only arrays, about 8 MB for a grid of
    257 contact points. Every cracked record of a dataset integrates the same tooth on the
    same grid with another crack."""
    return {}


def _read_only(a):
    a.setflags(write=False)
    return a


# --------------------------------------------------------------------------- gear pair
def active_contact_limits_m(pair):
    """Start and end of involute-involute contact on the line of action, m from T1.

    s_start = L − sqrt(r_tr2² − r_b2²), s_end = sqrt(r_tr1² − r_b1²), where r_tr is the
    radius at which each gear's tip rounding begins and L = a sin α_w (= T1T2).

    Parameters
    ----------
    pair : GearPair

    Returns
    -------
    (float, float)
        (s_start, s_end), m.

    Warns
    -----
    UserWarning
        If the contact would start below a gear's form radius (tip-fillet interference).
    """
    _check_pair(pair)
    g1, g2 = pair.driving, pair.driven
    L = _path_length(pair)
    s_start = L - math.sqrt(_tip_round_start(g2) ** 2 - g2.base_radius_m ** 2)
    s_end = math.sqrt(_tip_round_start(g1) ** 2 - g1.base_radius_m ** 2)
    lo, hi = _involute_domain(pair)
    if s_start < lo - _RADIUS_TOL_M or s_end > hi + _RADIUS_TOL_M:
        warnings.warn("the active contact reaches below a form radius: the tips interfere "
                      "with the fillets of the mating gear", stacklevel=2)
    return s_start, s_end


def pair_compliance_potential_energy(pair, contact_position_m, n_nodes=1001):
    """Compliance components of one tooth pair at positions s on the line of action.

    Parameters
    ----------
    pair : GearPair
        The gears (working centre distance from the pair).
    contact_position_m : array_like, shape (n,)
        s from T1, m; both contact points must lie on the involutes (between each gear's
        form radius and tip-rounding start).
    n_nodes : int
        Nodes of each beam integration.

    Returns
    -------
    PairCompliance
    """
    _check_pair(pair)
    s = np.atleast_1d(np.asarray(contact_position_m, dtype=float))
    if s.ndim != 1 or s.size == 0 or not np.all(np.isfinite(s)):
        raise ParameterError("contact_position_m must be a non-empty 1-D array of finite s")
    lo, hi = _involute_domain(pair)
    if np.any(s < lo - _RADIUS_TOL_M) or np.any(s > hi + _RADIUS_TOL_M):
        raise ParameterError(f"contact_position_m must lie in [{lo:g}, {hi:g}] m, where both "
                             "contact points are on the involutes")
    g1, g2 = pair.driving, pair.driven
    L = _path_length(pair)
    p1, p2 = ToothProfile.from_gear(g1), ToothProfile.from_gear(g2)
    r1 = np.sqrt(g1.base_radius_m ** 2 + s ** 2)
    r2 = np.sqrt(g2.base_radius_m ** 2 + (L - s) ** 2)
    return PairCompliance(contact_position_m=s, hertz=1.0 / hertz_stiffness(pair),
                          driving=tooth_compliance(p1, r1, n_nodes),
                          driven=tooth_compliance(p2, r2, n_nodes))


def pair_stiffness_potential_energy(pair, contact_position_m):
    """Single tooth-pair stiffness by the potential-energy method, N/m.

    1/k = 1/K_h + Σ_{gear 1, gear 2} (1/K_b + 1/K_s + 1/K_a + 1/K_f); see the module
    docstring and :func:`pair_compliance_potential_energy` for the components.

    Parameters
    ----------
    pair : GearPair
    contact_position_m : array_like, shape (n,)
        s from T1 along the line of action, m.

    Returns
    -------
    ndarray, shape (n,)
        k, N/m.

    Examples
    --------
    >>> from cmsim.rig import Rig
    >>> pair = Rig.paper_2016().gears
    >>> s0, s1 = active_contact_limits_m(pair)
    >>> k = pair_stiffness_potential_energy(pair, [0.5 * (s0 + s1)])
    >>> bool(5e7 < k[0] < 2e8)
    True
    """
    return pair_compliance_potential_energy(pair, contact_position_m).stiffness


def mesh_stiffness_potential_energy(pair, contact_position_m):
    """Mesh stiffness: sum of the pairs in contact, N/m.

    Pairs are spaced by the base pitch p_b on the line of action; a pair at s + j p_b
    (j integer) contributes when it lies in :func:`active_contact_limits_m`.

    Parameters
    ----------
    pair : GearPair
    contact_position_m : array_like, shape (n,)
        Position s of a reference pair, m (any real value; the result is p_b-periodic).

    Returns
    -------
    ndarray, shape (n,)
        k_mesh, N/m.
    """
    _check_pair(pair)
    s = np.atleast_1d(np.asarray(contact_position_m, dtype=float))
    if s.ndim != 1 or not np.all(np.isfinite(s)):
        raise ParameterError("contact_position_m must be a 1-D array of finite values")
    s0, s1 = active_contact_limits_m(pair)
    pb = pair.driving.base_pitch_m
    base = s0 + np.mod(s - s0, pb)           # the pair nearest the start of contact
    total = np.zeros_like(s)
    for j in range(int(math.ceil((s1 - s0) / pb)) + 1):
        sj = base + j * pb
        on = sj <= s1
        if np.any(on):
            total[on] += pair_stiffness_potential_energy(pair, sj[on])
    return total


# --------------------------------------------------------------------------- ISO 6336
#: ISO 6336-1 method B coefficients C1..C9 of q′ (mm·µm/N).
_ISO_C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529,
          0.00182)


def iso6336_stiffness(pair, c_m=0.8, c_r=1.0):
    """Single-pair and mesh stiffness of ISO 6336-1:2006 method B (§9).

    q′ = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1² + C9 x2²
    (mm·µm/N), c′_th = 1/q′, c′ = c′_th C_M C_R C_B cos β, c_γα = c′ (0.75 ε_α + 0.25), with
    C_B = (1 + 0.5 (1.2 − h_fP/m))·(1 − 0.02 (20° − α)) (h_fP: basic-rack dedendum of the gear,
    i.e. the cutter addendum; averaged over both gears), β = 0 (spur), z_n = z and ε_α the
    transverse contact ratio for sharp tips. Valid for line loads F_t/b >= 100 N/mm (below,
    ISO scales c′ by (F_t/b / 100)^0.25, not applied here).

    Parameters
    ----------
    pair : GearPair
    c_m : float
        Correction C_M (0.8).
    c_r : float
        Gear blank factor C_R (1 for solid gears).

    Returns
    -------
    dict
        ``q_prime_mm_um_per_n``, ``c_prime_th_n_per_mm_um``, ``C_B``,
        ``c_prime_n_per_mm_um``, ``c_gamma_n_per_mm_um`` (per mm of face width), and
        ``c_prime_n_per_m``, ``c_gamma_n_per_m`` (for the face width b), ``contact_ratio``.
    """
    _check_pair(pair)
    c_m = check_range("c_m", c_m, 0.0, 2.0, lo_open=True)
    c_r = check_range("c_r", c_r, 0.0, 1.0, lo_open=True)
    g1, g2 = pair.driving, pair.driven
    C = _ISO_C
    z1, z2, x1, x2 = g1.n_teeth, g2.n_teeth, g1.profile_shift, g2.profile_shift
    q = (C[0] + C[1] / z1 + C[2] / z2 + C[3] * x1 + C[4] * x1 / z1 + C[5] * x2
         + C[6] * x2 / z2 + C[7] * x1 ** 2 + C[8] * x2 ** 2)
    alpha_deg = math.degrees(g1.pressure_angle_rad)
    c_b = 0.5 * sum((1 + 0.5 * (1.2 - g.rack_addendum_coef)) * (1 - 0.02 * (20.0 - alpha_deg))
                    for g in (g1, g2))
    c_th = 1.0 / q
    c_prime = c_th * c_m * c_r * c_b            # cos β = 1
    eps = pair.contact_ratio
    c_gamma = c_prime * (0.75 * eps + 0.25)
    b_mm = 1e3 * min(g1.face_width_m, g2.face_width_m)
    per_m = 1e6 * b_mm                          # N/(mm·µm) × b[mm] = N/µm → N/m
    return {"q_prime_mm_um_per_n": q, "c_prime_th_n_per_mm_um": c_th, "C_B": c_b,
            "c_prime_n_per_mm_um": c_prime, "c_gamma_n_per_mm_um": c_gamma,
            "c_prime_n_per_m": c_prime * per_m, "c_gamma_n_per_m": c_gamma * per_m,
            "contact_ratio": eps}


# --------------------------------------------------------------------------- internals
def _check_pair(pair):
    check_type("pair", pair, GearPair)


def _path_length(pair):
    """T1T2 = a sin α_w, m."""
    return pair.working_centre_distance_m * math.sin(pair.working_pressure_angle_rad)


def _tip_round_start(gear: SpurGear):
    return ToothProfile.from_gear(gear, n_points=16).tip_round_start_radius_m


def _involute_domain(pair):
    """Range of s on which both contact points lie on the involutes, m."""
    g1, g2 = pair.driving, pair.driven
    t1, t2 = ToothProfile.from_gear(g1, n_points=16), ToothProfile.from_gear(g2, n_points=16)
    L = _path_length(pair)
    lo = max(math.sqrt(t1.form_radius_m ** 2 - g1.base_radius_m ** 2),
             L - math.sqrt(t2.tip_round_start_radius_m ** 2 - g2.base_radius_m ** 2))
    hi = min(math.sqrt(t1.tip_round_start_radius_m ** 2 - g1.base_radius_m ** 2),
             L - math.sqrt(t2.form_radius_m ** 2 - g2.base_radius_m ** 2))
    return lo, hi
