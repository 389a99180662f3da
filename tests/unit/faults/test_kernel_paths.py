"""The two kernel paths of a faulty bearing give the same forces.

Tier (a) exact equivalence: a bearing with race or ball defects gets the healthy (vectorised)
ball law plus the change of the few balls sitting in a defect; a bearing with an off-size
ball is evaluated ball by ball. Forcing the ball-by-ball path on a bearing with defects only
(an off-size excess of 1e-30 m, which changes no overlap) must reproduce the fast path's
forces and accelerations at arbitrary states and times — for each defect kind, for coinciding
defects on one bearing (their losses combine on the same ball) and for defects on two
bearings.
"""

import math

import numpy as np
import pytest

from cmsim.dynamics._bearing_kernels import BI_FAULTY
from cmsim.dynamics.model import build_model
from cmsim.faults import BallDefect, InnerRaceDefect, OffSizeBall, OuterRaceDefect
from cmsim.rig import OperatingPoint, Rig, RollingBearing, Rotor


def _rig():
    b = RollingBearing.from_pitch(9, 7.94e-3, 39.04e-3, clearance_m=5e-6)
    return Rig.rotor_on_bearings(b, Rotor(mass_kg=10.0, inertia_kg_m2=0.02))


CASES = {
    "outer": (OuterRaceDefect("1b1", 1.0e-3, 1e-4),),
    "inner": (InnerRaceDefect("1b1", 8e-4, 1e-4),),
    "ball": (BallDefect("1b1", 1.0e-3, 1e-4, ball=3),),
    "outer+inner+ball": (OuterRaceDefect("1b1", 1.0e-3, 1e-4),
                         InnerRaceDefect("1b1", 1.2e-3, 5e-5, angle_rad=0.3),
                         BallDefect("1b1", 5e-4, 1e-4, ball=0)),
    "two bearings": (OuterRaceDefect("1b1", 1.0e-3, 1e-4),
                     OuterRaceDefect("1b2", 2.0e-3, 2e-5, angle_rad=1.0)),
}


@pytest.mark.parametrize("case", list(CASES))
def test_defect_correction_equals_ball_by_ball(case):
    rig, op = _rig(), OperatingPoint(1797.0, radial_load_n=2000.0)
    faults = CASES[case]
    fast = build_model(rig, op, faults=faults, seed=1)
    bearings = sorted({f.bearing for f in faults})
    exact = build_model(rig, op, seed=1, faults=faults + tuple(
        OffSizeBall(b, diameter_excess_m=1e-30) for b in bearings))
    modes = [int(fast.kernel_params.b_int[i, BI_FAULTY]) for i in range(len(rig.bearings))]
    assert modes[rig.bearing_names.index("1b1")] == 1
    assert all(int(exact.kernel_params.b_int[rig.bearing_names.index(b), BI_FAULTY]) == 2
               for b in bearings)
    rng = np.random.default_rng(4)
    n = fast.n_dof
    loaded = 0
    for t in rng.uniform(0.0, 0.2, 60):
        y = np.zeros(2 * n)
        for b in bearings:                       # inner ring pushed into the load zone
            i = fast.index(f"x_{b}")
            y[i:i + 2] = rng.normal(0.0, 1.5e-5, 2) + (0.0, -1.5e-5)
        y[n:] = rng.normal(0.0, 1e-3, n)
        a, da = fast.rhs(t, y, want_diag=True)
        b_, db = exact.rhs(t, y, want_diag=True)
        np.testing.assert_allclose(da, db, rtol=1e-9, atol=1e-9 * max(1.0, np.abs(db).max()))
        np.testing.assert_allclose(a, b_, rtol=1e-9, atol=1e-6)
        loaded += bool(np.any(np.abs(db) > 1.0))
    assert loaded > 30
    # and the defect does change the force somewhere (the correction is not a no-op)
    healthy = build_model(rig, op, seed=1)
    diffs = []
    for t in np.linspace(0.0, 0.2, 400):
        y = np.zeros(2 * n)
        for b in bearings:
            i = fast.index(f"x_{b}")
            y[i:i + 2] = (0.0, -2.5e-5)
        diffs.append(np.abs(fast.rhs(t, y, True)[1] - healthy.rhs(t, y, True)[1]).max())
    assert max(diffs) > 10.0 and math.isfinite(max(diffs))
