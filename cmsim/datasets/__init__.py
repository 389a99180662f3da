"""Sweeps and datasets: named variations of a rig → many runs on local processes → a manifest.

* :mod:`~cmsim.datasets.variation` — what can vary (operating-point fields, named rig
  transformations, any rig field by dotted path): :class:`Variation`;
* :mod:`~cmsim.datasets.spec` — :class:`SweepSpec` (base rig, variations, sampling, mesh,
  seeds) and its :class:`SweepCase` s, the Cartesian product of the variations;
* :mod:`~cmsim.datasets.manifest` — ``DIR/manifest.json``: read, write, resume checks;
* :mod:`~cmsim.datasets.lock` — one sweep per directory (``fcntl.flock``);
* :mod:`~cmsim.datasets.runner` — :func:`run_sweep`: local process pool, resumable;
* :mod:`~cmsim.datasets.pool` — the one task runner (local processes or Dask, Ctrl-C/SIGTERM);
* :mod:`~cmsim.datasets.dataset_spec` — :class:`DatasetSpec`: a labelled dataset from TOML;
* :mod:`~cmsim.datasets.generate` — :func:`generate_dataset`: records, Parquet manifest;
* :mod:`~cmsim.datasets.load` — :func:`load`: the manifest, lazy records, ML arrays.

Example
-------
>>> from cmsim.datasets import SweepSpec, Variation
>>> spec = SweepSpec([Variation("torque_nm", [10, 100]), Variation("clearance_m", [15e-6, 0])],
...                  fixed={"speed_rpm": 1000}, duration_s=0.1)
>>> [c.name for c in spec.cases()]
['000_T10Nm_c15um', '001_T10Nm_c0um', '002_T100Nm_c15um', '003_T100Nm_c0um']
"""

from cmsim.datasets.dataset_spec import DatasetRecord, DatasetSpec
from cmsim.datasets.generate import DatasetSummary, generate_dataset
from cmsim.datasets.load import Dataset, Record, load
from cmsim.datasets.lock import LOCK_NAME, DirectoryLock
from cmsim.datasets.pool import Interrupted
from cmsim.datasets.manifest import (FEATURE_SIGNALS, MANIFEST_NAME, RUNS_DIR,
                                     manifest_features, read_manifest)
from cmsim.datasets.runner import START_METHODS, SweepSummary, run_sweep
from cmsim.datasets.spec import SEED_POLICIES, SweepCase, SweepSpec
from cmsim.datasets.variation import OPERATING_POINT_FIELDS, RIG_TRANSFORMS, Variation

__all__ = ["SweepSpec", "SweepCase", "Variation", "SweepSummary", "run_sweep", "read_manifest",
           "manifest_features", "DirectoryLock", "SEED_POLICIES", "START_METHODS",
           "MANIFEST_NAME", "RUNS_DIR", "LOCK_NAME", "FEATURE_SIGNALS",
           "OPERATING_POINT_FIELDS", "RIG_TRANSFORMS", "DatasetSpec", "DatasetRecord",
           "DatasetSummary", "generate_dataset", "load", "Dataset", "Record",
           "Interrupted"]
