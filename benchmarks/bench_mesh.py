"""Speed of the hybrid mesh stiffness (issue 3), measured side by side in one run.

Prints
1. the time to build the FE influence-coefficient tables of the paper gear from scratch
   (mesh, assembly, factorisation, solves; the on-disk cache is bypassed);
2. the time for a 10-torque table set over one mesh cycle with λ cached (target < 60 s),
   with the paper's bearing-cycle centroids, and its share spent on the orbits;
3. the realtime factor of model A (on-line hybrid contact) and model B (torque table) at
   1000 rpm / 100 N m, timed alternately, and their ratio (target: A no slower than 5x B).

Run: ``python benchmarks/bench_mesh.py`` (about a minute). Compare ratios, not absolute
times: the machines are noisy.
"""

from __future__ import annotations

import time

import numpy as np

import cmsim
from cmsim.dynamics.simulation import simulate
from cmsim.mesh_stiffness.hybrid import HybridMeshModel
from cmsim.mesh_stiffness.influence import influence_table
from cmsim.dynamics.torque_tables import torque_tables

REPEATS = 3


def main():
    rig = cmsim.Rig.paper_2016()
    start = time.perf_counter()
    table = influence_table(rig.gears.driving, use_cache=False)
    build = time.perf_counter() - start
    meta = table.meta
    print(f"1. influence tables of the paper gear from scratch: {build:.1f} s "
          f"(mesh {meta.get('mesh_seconds', float('nan')):.1f} s, factorisation "
          f"{meta.get('factor_seconds', float('nan')):.1f} s, solves "
          f"{meta.get('solve_seconds', float('nan')):.1f} s; {meta.get('n_triangles')} "
          f"triangles, {meta.get('n_dofs')} DOFs)")

    model = HybridMeshModel.from_pair(rig.gears)           # cached from here on
    torque_tables(rig, [50.0], mesh_model=model)           # compile the kernels
    torques = np.linspace(10.0, 100.0, 10)
    start = time.perf_counter()
    tables = torque_tables(rig, torques, mesh_model=model)
    total = time.perf_counter() - start
    start = time.perf_counter()
    torque_tables(rig, torques, mesh_model=model, centres="nominal")
    nominal = time.perf_counter() - start
    print(f"2. 10-torque table set, one mesh cycle of 120 angles each: {total:.1f} s "
          f"({total / 10:.2f} s per torque; {total - nominal:.1f} s of it the bearing-cycle "
          f"orbits for the centroids); target < 60 s: {'met' if total < 60 else 'NOT met'}")

    op = cmsim.OperatingPoint(1000.0, 100.0)
    b_table = tables.at(100.0)
    kw = dict(seed=0, cage_phases_rad=None, warmup_s=0.01)
    simulate(rig, op, 0.01, mesh=model, **kw)        # compile outside the timing
    rtf_a, rtf_b = 0.0, 0.0
    for _ in range(REPEATS):
        rtf_a = max(rtf_a, simulate(rig, op, 0.3, mesh=model, **kw)
                    .meta["realtime_factor"])
        rtf_b = max(rtf_b, simulate(rig, op, 0.3, mesh=b_table, **kw)
                    .meta["realtime_factor"])
    ratio = rtf_b / rtf_a
    print(f"3. realtime factor at 75 kHz: model A {rtf_a:.2f}, model B {rtf_b:.2f}; "
          f"A is {ratio:.2f}x slower than B (target <= 5: {'met' if ratio <= 5 else 'NOT met'})")


if __name__ == "__main__":
    main()
