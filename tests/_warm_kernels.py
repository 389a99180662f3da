"""Compile the batch integrator once for a parallel test session: ``python -m tests._warm_kernels``.

``tests/conftest.py`` starts this in the background when ``pytest -n N`` begins. On a cold
numba cache each worker compiled the batch integrator (:mod:`cmsim.dynamics._batch_kernels`)
itself at its first batched test, the same kernel twice at about the same time: 184 and
156 s of the two workers of a 16.5-min suite on a 2-core Intel Xeon (2026-12-02). This
process compiles it once into the session's cache while the workers run other tests, and a
worker that reaches a batched test afterwards loads it. No test depends on it: a worker that
gets there first compiles as it did before, and the session ends it if it still runs.

The records are a batch of gear records with a cracked tooth, slip and a speed wobble, and of
records with an outer-race defect, 0.03 s each: every path of the batch kernel a test takes
is compiled with it (numba compiles a kernel's callees with it).
"""

import tempfile
from pathlib import Path

from cmsim.datasets import DatasetSpec, generate_dataset
from tests.unit.datasets.test_batches import SPEC as BATCHES

#: An outer-race defect beside the batch tests' cracked teeth: the race-defect pass of the
#: batched step compiles too.
OUTER_RACE = {"type": "outer_race", "bearing": ["1b1"], "size_m": 1e-3, "depth_m": 1e-4}

#: What the batch tests integrate (their spec, :mod:`tests.unit.datasets.test_batches`), with
#: an outer race among its faults.
SPEC = {**BATCHES, "dataset": {**BATCHES["dataset"], "name": "warm"},
        "faults": {**BATCHES["faults"], "types": [*BATCHES["faults"]["types"], OUTER_RACE]}}


def main():
    with tempfile.TemporaryDirectory(prefix="cmsim-warm-") as tmp:
        generate_dataset(DatasetSpec.from_dict(SPEC), Path(tmp) / "warm", batch_size=4,
                         workers=1, progress=False)


if __name__ == "__main__":
    main()
