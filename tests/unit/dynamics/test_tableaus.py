"""Butcher tableaus of every fixed-step scheme: consistency and order conditions.

Tier (a) closed form. For an explicit Runge-Kutta method of order p the weights b, nodes c
and matrix a satisfy (Butcher, "Numerical methods for ODEs", §31):

* row sums c = a·1 (each stage evaluates the right-hand side at its own time);
* a strictly lower triangular (explicit);
* order 1: Σ b = 1; order 2: b·c = 1/2; order 3: b·c² = 1/3, b·a·c = 1/6;
  order 4: b·c³ = 1/4, b·(c∘a·c) = 1/8, b·a·c² = 1/12, b·a·a·c = 1/24;

and the conditions of order p + 1 fail (the method is not of a higher order than declared).
"""

import numpy as np
import pytest

from cmsim.dynamics.integrator import SCHEMES


def _conditions(tab):
    a, b, c = tab.a, tab.b, tab.c
    return {
        1: [(b.sum(), 1.0)],
        2: [(b @ c, 1 / 2)],
        3: [(b @ c ** 2, 1 / 3), (b @ a @ c, 1 / 6)],
        4: [(b @ c ** 3, 1 / 4), (b @ (c * (a @ c)), 1 / 8), (b @ a @ c ** 2, 1 / 12),
            (b @ a @ a @ c, 1 / 24)],
        5: [(b @ c ** 4, 1 / 5), (b @ a @ a @ a @ c, 1 / 120)],
    }


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_nodes_are_the_row_sums(name):
    tab = SCHEMES[name]
    np.testing.assert_allclose(tab.c, tab.a.sum(axis=1), rtol=0, atol=1e-15)
    assert tab.c[0] == pytest.approx(0.0, abs=0)
    s = tab.b.size
    assert tab.a.shape == (s, s) and tab.c.shape == (s,)
    assert np.all(np.triu(tab.a) == 0.0)


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_order_conditions(name):
    tab = SCHEMES[name]
    cond = _conditions(tab)
    for order in range(1, tab.order + 1):
        for got, want in cond[order]:
            assert got == pytest.approx(want, rel=1e-14), (name, order)
    higher = cond[tab.order + 1]
    assert any(abs(got - want) > 1e-3 for got, want in higher), name


def test_declared_orders():
    assert {k: v.order for k, v in SCHEMES.items()} == {"ode3": 3, "lawson-ode3": 3, "rk4": 4,
                                                        "lawson-rk4": 4, "heun": 2}
    assert [k for k, v in SCHEMES.items() if v.exponential] == ["lawson-ode3", "lawson-rk4"]


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_imaginary_stability_interval(name):
    """The declared interval is where |R(iθ)| <= 1 ends, R(z) = 1 + z bᵀ(I − zA)⁻¹1 the
    stability function (0 when an undamped mode grows from the start: heun)."""
    tab = SCHEMES[name]

    def growth(theta):
        z = 1j * theta
        s = tab.b.size
        return abs(1 + z * tab.b @ np.linalg.solve(np.eye(s) - z * tab.a, np.ones(s)))

    limit = tab.imaginary_limit
    inside = np.linspace(1e-3, limit, 200)[:-1] if limit > 0 else np.array([1e-3, 0.1])
    if limit > 0:
        assert max(growth(t) for t in inside) <= 1.0 + 1e-12
        assert growth(limit * 1.01) > 1.0
    else:
        assert all(growth(t) > 1.0 for t in inside)
