"""Local contact deflection of the hybrid method (mesh_stiffness.local_deflection).

Tier (a), closed form: the exact plane-strain approach between the surface and depth h under
a Hertz pressure is checked against a numerical integration of Johnson's on-axis stresses
(Contact Mechanics eq. 4.47), its h ≫ a limit against the Weber-Banaschek formula, and the
numba kernel's value and derivative against the Python function and finite differences.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from cmsim.mesh_stiffness._hybrid_kernels import HP_SIZE, local_approach_jit
from cmsim.mesh_stiffness.local_deflection import (contact_modulus, hertz_half_width,
                                                   local_approach,
                                                   local_approach_weber_banaschek)

E, NU, B = 210e9, 0.3, 6.35e-3


def test_hertz_half_width_closed_form():
    e_star = contact_modulus(E, NU, E, NU)
    assert math.isclose(e_star, E / (2 * (1 - NU ** 2)), rel_tol=1e-14)
    f, r1, r2 = 1000.0, 0.0152, 0.0152
    r = r1 * r2 / (r1 + r2)
    a = hertz_half_width(f, r1, r2, B, e_star)
    assert math.isclose(a, math.sqrt(8 * f * r * (1 - NU ** 2) / (math.pi * E * B)),
                        rel_tol=1e-13)
    # the peak pressure of the ellipse integrates back to the load
    p0 = 2 * f / (math.pi * a * B)
    assert math.isclose(p0 * math.pi * a / 2 * B, f, rel_tol=1e-13)


@pytest.mark.parametrize("h_over_a", [0.5, 3.0, 30.0])
def test_exact_form_matches_integrated_axis_stresses(h_over_a):
    f, a = 800.0, 1e-4
    h = h_over_a * a
    p0 = 2 * f / (math.pi * a * B)

    def strain(z):                          # plane strain, compressive positive
        sz = -p0 * a / math.sqrt(a * a + z * z)
        sx = -p0 / a * ((a * a + 2 * z * z) / math.sqrt(a * a + z * z) - 2 * z)
        return -((1 - NU ** 2) * sz - NU * (1 + NU) * sx) / E

    approach = quad(strain, 0.0, h, epsabs=0, epsrel=1e-13)[0]
    assert math.isclose(local_approach(f, a, h, E, NU, B), approach, rel_tol=1e-9)


def test_weber_banaschek_is_the_deep_limit():
    f, a = 500.0, 5e-5
    for h_over_a, tol in ((10.0, 5e-3), (1000.0, 1e-6)):
        exact = local_approach(f, a, h_over_a * a, E, NU, B)
        wb = local_approach_weber_banaschek(f, a, h_over_a * a, E, NU, B)
        assert abs(exact / wb - 1) < tol
    # zero force, zero approach; arrays work
    assert local_approach(0.0, a, 1e-3, E, NU, B) == 0.0
    u = local_approach(np.array([0.0, 10.0, 100.0]), np.array([1e-6, 1e-5, 3e-5]), 1e-3, E, NU,
                       B)
    assert u[0] == 0.0 and 0 < u[1] < u[2]


def _hp(depth1, depth2):
    hp = np.zeros(HP_SIZE)
    hp[8], hp[9] = depth1, depth2
    hp[10:14] = (E, NU, 1.9e11, 0.29)
    hp[14] = B
    hp[15] = contact_modulus(E, NU, 1.9e11, 0.29)
    return hp


def test_kernel_local_term_and_derivative():
    hp = _hp(4.8e-4, 3.0e-4)
    chi1, chi2 = 0.012, 0.018
    for f in (1e-3, 1.0, 100.0, 3000.0, 5e4):
        u, du = local_approach_jit(f, chi1, chi2, hp)
        a = hertz_half_width(f, chi1, chi2, B, hp[15])
        expect = (local_approach(f, a, hp[8], hp[10], hp[11], B)
                  + local_approach(f, a, hp[9], hp[12], hp[13], B))
        assert math.isclose(u, expect, rel_tol=1e-13)
        eps = 1e-6 * f
        up = local_approach_jit(f + eps, chi1, chi2, hp)[0]
        um = local_approach_jit(f - eps, chi1, chi2, hp)[0]
        assert math.isclose(du, (up - um) / (2 * eps), rel_tol=1e-6)
        assert du > 0                          # monotone: one contact solution


def test_local_compliance_softens_with_load_logarithmically():
    """u/F = 2(1 − ν²)/(π E b)[ln(2h/a) − …] falls by (1 − ν²)/(π E b)·ln 10 per decade of F."""
    hp = _hp(5e-4, 5e-4)
    hp[12:14] = (E, NU)
    hp[15] = contact_modulus(E, NU, E, NU)
    c = [local_approach_jit(f, 0.01, 0.01, hp)[0] / f for f in (100.0, 1000.0)]
    per_decade = 2 * 2 * (1 - NU ** 2) / (math.pi * E * B) * 0.5 * math.log(10.0)
    assert math.isclose(c[0] - c[1], per_decade, rel_tol=0.02)
