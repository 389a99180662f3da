"""Fixed-step explicit Runge-Kutta schemes as data (one numba kernel runs them all).

References
----------
.. [1] P. Bogacki, L. F. Shampine, "A 3(2) pair of Runge-Kutta formulas", Appl. Math. Lett.
   2 (1989) 321-325 (MATLAB/Simulink ``ode3``).
.. [2] J. D. Lawson, "Generalized Runge-Kutta processes for stable systems with large
   Lipschitz constants", SIAM J. Numer. Anal. 4 (1967) 372-380 (``lawson-ode3``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

__all__ = ["ButcherTableau", "SCHEMES"]


@dataclass(frozen=True)
class ButcherTableau:
    """Explicit Runge-Kutta coefficients.

    Attributes
    ----------
    a : ndarray, shape (s, s)
        Strictly lower-triangular stage matrix.
    b : ndarray, shape (s,)
        Weights.
    c : ndarray, shape (s,)
        Nodes.
    order : int
        Order of accuracy.
    imaginary_limit : float
        Stability interval on the imaginary axis: the largest ω·h up to which an undamped
        mode does not grow (√3 for ode3, 2√2 for rk4, 0 for heun, which grows any undamped
        mode); it sets the step (:func:`cmsim.dynamics.step.steps_per_period`).
    exponential : bool
        Run in Lawson form: the stiff linear chains in closed form
        (:mod:`cmsim.dynamics.exponential`), the rest with these coefficients.
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    order: int
    imaginary_limit: float
    exponential: bool = False

    @property
    def stages(self):
        """Right-hand-side evaluations per step."""
        return self.b.shape[0]


# Bogacki-Shampine 3rd order (Simulink ode3), without the FSAL error stage
_ODE3 = ButcherTableau(np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 0.75, 0.0]]),
                       np.array([2.0 / 9.0, 1.0 / 3.0, 4.0 / 9.0]), np.array([0.0, 0.5, 0.75]), 3,
                       math.sqrt(3.0))

# classical 4th-order Runge-Kutta
_RK4 = ButcherTableau(np.array([[0.0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1.0, 0]]),
                      np.array([1.0, 2.0, 2.0, 1.0]) / 6.0, np.array([0.0, 0.5, 0.5, 1.0]), 4,
                      2.0 * math.sqrt(2.0))

SCHEMES = {
    "ode3": _ODE3,
    # ode3 in Lawson form: the stiff linear chains in closed form (cmsim.dynamics.exponential)
    "lawson-ode3": replace(_ODE3, exponential=True),
    # classical 4th-order Runge-Kutta: a wider stability interval than ode3's (2√2 against
    # √3), so fewer steps where the highest mode sets them
    "rk4": _RK4,
    # rk4 in Lawson form: with every linear chain in closed form the contacts alone set its
    # step (one per sample at 25.6 kHz), measured and not adopted (bench_schemes.py)
    "lawson-rk4": replace(_RK4, exponential=True),
    # Heun's 2nd-order method, for convergence checks
    "heun": ButcherTableau(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([0.5, 0.5]),
                           np.array([0.0, 1.0]), 2, 0.0),
}
