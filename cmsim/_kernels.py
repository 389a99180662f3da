"""Numba kernels of the top-level modules: the housing path of :mod:`cmsim.sensors`.

The housing path interpolates a force by an integer factor k through a FIR (a Nyquist
filter: it keeps the input samples), runs each housing mode (one biquad) over the
interpolated samples and keeps every k-th sample of their sum. Upsampling, a linear filter
and keeping every k-th sample make a linear time-invariant system at the force's own rate,
whose impulse response, once the FIR's span has passed, is each biquad's two poles raised
to the k-th power: mode s is ``N_s(z) / A_s(z)`` there, A_s of degree 2 and N_s a FIR as
long as the interpolation's span and two samples more
(:func:`cmsim.sensors.slow_rate_modes` builds it from the mode's impulse response).
:func:`housing_modes_jit` runs that form, the modes side by side: per output sample and
mode a FIR of about 2·32 + 3 taps and two poles, where the interpolated form took k·(its
taps per phase + a biquad); the same numbers to rounding (within 1e-13 to 3e-12 of the
largest for modes at 2-50 % of the force's rate, 1e-10 for one at 0.03 %). (Over
one common denominator the modes would share one FIR, but a recursion of six poles near
z = 1 loses digits: 3e-7 of the largest on a slowly wandering force at 200 kHz.)

The interpolated form starts each mode at rest at the first output sample, the force's
interpolated samples before it (its look-ahead into the first inputs) never fed; what that
leaves out decays as the mode does, so the slow form is given each mode's first two
outputs in that form (``init``) and runs its recursion from there: both start the same
way.

The numba rule (as in :mod:`cmsim.dynamics._rhs_kernels`): ``@njit(cache=True)``,
float64/int64 arrays and scalars only, no Python objects, no random numbers, no allocation in
the hot path.
"""

from __future__ import annotations

from numba import njit

#: Output samples per block of :func:`housing_modes_jit` (its scratch holds a block of each
#: mode's numerator sums, which stay in the first-level cache while the taps pass over them).
HOUSING_BLOCK = 512


@njit(cache=True, error_model="numpy", _nrt=False)
def housing_modes_jit(x, num, den, init, f, state, out):
    """``out[c, j] = Σ_s y_s[j]``, mode s at the force's rate: ``y_s[j] = Σ_q num[s, q]·
    x[c, j + L − 1 − q] − den[s, 0]·y_s[j − 1] − den[s, 1]·y_s[j − 2]`` for j >= 2,
    ``y_s[0], y_s[1] = init[c, s]`` (L taps).

    ``x`` (C, n + L − 1) holds each force after its first sample's value was taken away,
    with L − 1 − lead zeros before it and ``lead`` after (the interpolation's look-ahead
    past the last sample: output j reads the force's samples j + lead − q); ``f``
    (S, :data:`HOUSING_BLOCK`) and ``state`` (S, 2) scratch; ``out`` (C, n). A block of
    outputs at a time: the numerators' sums with the taps outside and the block's outputs
    inside (contiguous loops the vectoriser takes), then each mode's recursion, serial, the
    modes added in order."""
    n_cols, n = out.shape
    n_modes, n_taps = num.shape
    for c in range(n_cols):
        xc = x[c]
        oc = out[c]
        for j0 in range(0, n, HOUSING_BLOCK):
            m = min(HOUSING_BLOCK, n - j0)
            for s in range(n_modes):
                row = f[s]
                for r in range(m):
                    row[r] = 0.0
                # four taps a pass: a block's sums are loaded and stored a quarter as often
                q = 0
                while q + 4 <= n_taps:
                    b0 = num[s, q]
                    b1 = num[s, q + 1]
                    b2 = num[s, q + 2]
                    b3 = num[s, q + 3]
                    at = j0 + n_taps - 4 - q          # src3[r] = xc[at + r], src0 three on
                    src = xc[at: at + m + 3]
                    for r in range(m):
                        row[r] += (b0 * src[r + 3] + b1 * src[r + 2]) + (
                            b2 * src[r + 1] + b3 * src[r])
                    q += 4
                while q < n_taps:
                    b = num[s, q]
                    src = xc[j0 + n_taps - 1 - q: j0 + n_taps - 1 - q + m]
                    for r in range(m):
                        row[r] += b * src[r]
                    q += 1
            for r in range(m):
                oc[j0 + r] = 0.0
            for s in range(n_modes):
                a1 = den[s, 0]
                a2 = den[s, 1]
                y1 = state[s, 0]
                y2 = state[s, 1]
                row = f[s]
                for r in range(m):
                    j = j0 + r
                    if j < 2:
                        y = init[c, s, j]
                    else:
                        y = row[r] - a1 * y1 - a2 * y2
                    oc[j] += y
                    y2 = y1
                    y1 = y
                state[s, 0] = y1
                state[s, 1] = y2
