"""Cracked-tooth mesh stiffness (potential energy) against crack depth.

Tier (b) literature, at the tolerance the sources support: Chaari, Fakhfakh & Haddar (Eur. J.
Mech. A/Solids 28 (2009) 461-468) report, for their gear, losses of the total mesh stiffness
in the single-contact zone of the order of 5-10 % for a crack through 25 % of the tooth and
20-40 % for 50-75 % (figures as summarised in issue 16's brief; the paper's own text was not
available to us). We read "x % of the tooth" as the crack having crossed x % of the tooth
thickness at its start, q·sin ν / (2 h_c) — our model stops at the centreline (50 %). Plus
closed-form checks: no crack = healthy, the loss grows monotonically with depth, and the
cracked tooth is weakest where the lever arm is longest (contact near its tip).
"""

import math

import numpy as np
import pytest

from cmsim.faults.crack import (crack_start, crack_stiffness_factor, max_crack_depth_m,
                                mesh_stiffness_loss)
from cmsim.mesh_stiffness.geometry import ToothProfile
from cmsim.mesh_stiffness.potential_energy import _involute_domain
from cmsim.rig import Rig

NU = math.pi / 4


@pytest.fixture(scope="module")
def pair():
    return Rig.paper_2016().gears


@pytest.fixture(scope="module")
def losses(pair):
    qmax = max_crack_depth_m(pair.driving, NU)
    fractions = (0.1, 0.25, 0.5, 0.75, 1.0)      # of the half-thickness h_c
    return {f: mesh_stiffness_loss(pair, 1, f * qmax, NU) for f in fractions}


def test_no_crack_is_healthy(pair):
    s = np.linspace(*_involute_domain(pair), 7)
    np.testing.assert_allclose(crack_stiffness_factor(pair, 1, 0.0, NU, s), 1.0, atol=1e-12)


def test_crack_start_is_in_the_fillet(pair):
    prof = ToothProfile.from_gear(pair.driving)
    y_s, h_c = crack_start(prof)
    assert prof.root_chord_y_m < y_s < prof.form_radius_m
    assert 0.5 * prof.root_chord_thickness_m > h_c > prof.half_thickness_at(
        prof.form_radius_m) - 1e-12


def test_loss_grows_with_depth(losses):
    depth = sorted(losses)
    for key in ("max_loss", "mean_loss", "pair_loss_mean"):
        v = [losses[d][key] for d in depth]
        assert all(b > a for a, b in zip(v, v[1:])), (key, v)
    assert losses[0.1]["max_loss"] > 0.0


def test_loss_in_published_band(losses):
    """25 % of the tooth thickness (tip halfway to the centreline): 5-10 %; 50 % (tip on the
    centreline): 20-40 % (Chaari et al. 2009). Measured: 8.3 % and 31 %."""
    assert 0.05 <= losses[0.5]["max_loss"] <= 0.10
    assert 0.20 <= losses[1.0]["max_loss"] <= 0.40
    # the mean over the cracked tooth's passage is diluted by the double-contact zones
    assert losses[1.0]["mean_loss"] < losses[1.0]["max_loss"]


def test_weakest_near_the_tip(pair):
    s0, s1 = _involute_domain(pair)
    s = np.linspace(s0, s1, 41)
    q = 0.5 * max_crack_depth_m(pair.driving, NU)
    f1 = crack_stiffness_factor(pair, 1, q, NU, s)       # gear-1 tip at the end of the path
    f2 = crack_stiffness_factor(pair, 2, q, NU, s)       # gear-2 tip at the start
    assert np.argmin(f1) > 30 and np.argmin(f2) < 10
    assert np.all(np.diff(f1) < 1e-12)


def test_fe_crack_has_the_pe_geometry(pair):
    """The FE crack (mesh_stiffness.root_crack.RootCrack) starts where the PE crack starts and
    its tip sits at the PE tip offset h_q = h_c - q sin(nu) from the centreline."""
    from cmsim.faults.crack import crack_tip_offset_m
    from cmsim.mesh_stiffness.root_crack import RootCrack

    prof = ToothProfile.from_gear(pair.driving, n_points=800)     # the FE mesh's sampling
    q = 0.6 * max_crack_depth_m(pair.driving, NU)
    mouth, direction, tip = RootCrack(q, NU).path_m(prof)
    y_s, h_c = crack_start(ToothProfile.from_gear(pair.driving))
    np.testing.assert_allclose(mouth, [h_c, y_s], rtol=0, atol=1e-12)
    assert tip[0] == pytest.approx(crack_tip_offset_m(prof, q, NU), abs=1e-12)
    assert direction[1] < 0 < mouth[0] - tip[0]                 # inwards and down
    # the mouth lies on the loaded (right) fillet of the outline
    assert prof.half_thickness_at(np.array([y_s]))[0] == pytest.approx(h_c, rel=1e-3)
