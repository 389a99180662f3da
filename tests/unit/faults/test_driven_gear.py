"""Tooth faults on the driven gear sit where its teeth meet the path of contact.

Test tier: closed form (symmetry). A tooth of gear 1 meets the line of action at
s = sqrt(r² − r_b1²) from T1, a tooth of gear 2 at s = L − sqrt(r² − r_b2²): gear 1's tip
closes the path of contact, gear 2's tip opens it. On the paper's 28:28 pair of identical
gears, breaking tooth 0 of gear 2 is therefore the mirror in time, about the instant the
tooth pair 0 passes the pitch point, of breaking tooth 0 of gear 1. Quasi-static
equilibria (no dynamics, so no ringing breaks the symmetry) through one mesh cycle either
side of that instant, one revolution in.
"""

import numpy as np
import pytest

import cmsim
from cmsim.dynamics.model import build_model
from cmsim.dynamics.quasistatic import quasi_static_orbit
from cmsim.dynamics.tooth_contact import resolve_mesh
from cmsim.faults.gear import ToothBreakage

RIG = cmsim.Rig.paper_2016()
OP = cmsim.OperatingPoint(1000.0, 20.0)


def _dte_um(faults, times_s):
    """Quasi-static DTE deviation along the line of action at ``times_s``, µm."""
    model = build_model(RIG, OP, resolve_mesh(RIG, "potential-energy", OP.torque_nm),
                        faults=faults, seed=0)
    q = quasi_static_orbit(model, times_s)
    i1, i2 = model.dof_names.index("theta_1G1"), model.dof_names.index("theta_2G1")
    ratio = RIG.gears.driving.n_teeth / RIG.gears.driven.n_teeth
    return (q[:, i1] - ratio * q[:, i2]) * RIG.gears.driving.base_radius_m * 1e6


def test_broken_tooth_of_the_driven_gear_mirrors_the_driving_gear():
    pair = RIG.gears
    assert pair.driving == pair.driven                      # the symmetry the test rests on
    t_rev = 60.0 / OP.speed_rpm                              # tooth pair 0 at the pitch point
    t_mesh = t_rev / pair.driving.n_teeth
    tau = np.linspace(-1.5, 1.5, 31) * t_mesh                # symmetric about that instant
    healthy = _dte_um((), t_rev + tau)
    broken = {g: _dte_um((ToothBreakage(gear=g, tooth=0, lost_height_m=1e-3),), t_rev + tau)
              - healthy for g in (1, 2)}
    felt = {g: np.abs(d) > 0.1 for g, d in broken.items()}  # µm: lost contact, not noise
    assert felt[1].sum() >= 3 and felt[2].sum() >= 3
    assert np.all(tau[felt[1]] > 0)                          # gear 1's tip: end of the path
    assert np.all(tau[felt[2]] < 0)                          # gear 2's tip: its start
    np.testing.assert_allclose(broken[2][::-1], broken[1], rtol=0.03, atol=0.05)
