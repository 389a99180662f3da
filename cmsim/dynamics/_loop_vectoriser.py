"""What LLVM's loop vectoriser may do for the batch kernels' loops over the runs.

A loop over the runs of a batch (:mod:`cmsim.dynamics._batch_kernels`,
:mod:`cmsim.dynamics._batch_mesh_kernels`) reads and writes many rows, each a separate numba
array that LLVM cannot prove distinct (numba marks no argument ``noalias``). The vectoriser
then versions the loop: a check that no two rows overlap picks the vector body, the original
scalar loop runs otherwise. Past 8 such checks (LLVM's ``-runtime-memory-check-threshold``)
it gives up and leaves the loop scalar: the tooth contacts' passes need 30-200. This module
raises the limits once per process, before the kernels are compiled (they are cached
compiled, so a loaded kernel is what its first compile made).

The checks keep the result what the scalar loop computes: the vector body runs only where
the rows are apart, and without fastmath each run's operations are the same IEEE operations
in the same order in the vector body and in the scalar remainder (no reassociation, no fused
multiply-add). What it changes for other numba code in the process is the same: more loops
vectorised behind a runtime check, none computed differently.
"""

from __future__ import annotations

import llvmlite.binding as llvm

#: Runtime pointer checks LLVM may emit to vectorise one loop (its default: 8).
MAX_RUNTIME_CHECKS = 512

_done = False


def allow_runtime_alias_checks():
    """Raise LLVM's limits on runtime alias checks (once per process)."""
    global _done
    if _done:
        return
    for option in ("-runtime-memory-check-threshold", "-vectorize-memory-check-threshold",
                   "-memory-check-merge-threshold"):
        llvm.set_option("cmsim", f"{option}={MAX_RUNTIME_CHECKS}")
    _done = True
