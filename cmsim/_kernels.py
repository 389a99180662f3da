"""Numba kernels of the top-level modules: the housing path of :mod:`cmsim.sensors`.

:func:`housing_modes_jit` runs the housing modes (one biquad each, added in parallel) over an
interpolated force and keeps every k-th sample of their sum. Each biquad is the direct form
II transposed of :func:`scipy.signal.sosfilt` written with the same operations in the same
order, and the modes are summed in the order ``((0 + y₁) + y₂) + …`` of adding one
``sosfilt`` output after another, so the result is theirs bit for bit; it reads the
interpolated force once for all modes and forms the sum only where it is kept.

The numba rule (as in :mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``,
float64/int64 arrays and scalars only, no Python objects, no random numbers, no allocation in
the hot path.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy", _nrt=False)
def housing_modes_jit(xk, sos, k, state, out):
    """``out[m] = Σ_s y_s[m·k]``: the modes ``sos`` (n_modes, 6) driven by ``xk`` from rest.

    ``state`` (n_modes, 2) is zeroed here and holds the biquads' delays; ``out`` has
    ``ceil(len(xk) / k)`` samples.
    """
    n_modes = sos.shape[0]
    for s in range(n_modes):
        state[s, 0] = 0.0
        state[s, 1] = 0.0
    for n in range(xk.shape[0]):
        x = xk[n]
        keep = n % k == 0
        acc = 0.0
        for s in range(n_modes):
            y = sos[s, 0] * x + state[s, 0]
            state[s, 0] = sos[s, 1] * x - sos[s, 4] * y + state[s, 1]
            state[s, 1] = sos[s, 2] * x - sos[s, 5] * y
            if keep:
                acc = acc + y
        if keep:
            out[n // k] = acc
