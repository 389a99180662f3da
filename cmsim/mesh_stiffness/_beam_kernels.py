"""Numba kernel of the cantilever integrals of :func:`cmsim.mesh_stiffness.potential_energy.
cantilever_compliance`: the composite Simpson sums over a block of load sections in one pass.

Summed in numpy, each of the sums' terms was a temporary the size of the block (257 sections by
1001 nodes, 2 MB) that the allocator mapped and faulted in afresh: 5.5 ms of a cracked tooth's
5.7. The numba convention of :mod:`cmsim.mesh_stiffness._kernels` holds: ``@njit(cache=True)``,
float64 arrays only, no Python objects.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, error_model="numpy")
def beam_sums_jit(h, arm2, w, face_width, bending, area):
    """``bending[i] = Σⱼ wⱼ·arm2[i, j]/I(h[i, j])`` and ``area[i] = Σⱼ wⱼ/A(h[i, j])`` over the
    nodes j of each section i, with I = (2/3)·h³·b and A = 2·h·b (b = ``face_width``).

    ``h``, ``arm2`` (rows, n) half-thicknesses (> 0, finite: the caller checks) and bending
    arms squared, ``w`` (n,) the rule's weights; ``bending``, ``area`` (rows,) filled.
    """
    rows, n = h.shape
    for i in range(rows):
        sb = 0.0
        sa = 0.0
        for j in range(n):
            r = 1.0 / (h[i, j] * face_width)            # 1/(h b): 2/A and b²·h⁻²·…
            rb = r * face_width                         # 1/h
            sa += w[j] * (0.5 * r)
            sb += w[j] * arm2[i, j] * (1.5 * r * rb * rb)
        bending[i] = sb
        area[i] = sa
