"""Datasets and sweeps: one spec → records on local processes or Dask → one Parquet manifest.

* :mod:`~cmsim.datasets.variation` — what a spec can vary (operating-point fields, named rig
  transformations, any rig field by dotted path), :class:`Variation` (a grid axis);
* :mod:`~cmsim.datasets.distribution` — :class:`Distribution`, one spec value;
* :mod:`~cmsim.datasets.spec` — :class:`DatasetSpec`, the one recipe (grid or random
  sampling; a sweep is a grid spec without drawn faults) and its one seed rule;
* :mod:`~cmsim.datasets.spec_toml` — its TOML form (``datasets/*.toml``);
* :mod:`~cmsim.datasets.plan` — :class:`RecordPlan`, what a spec draws for one record;
* :mod:`~cmsim.datasets.records` — one record: simulate, write its file and its row;
* :mod:`~cmsim.datasets.manifest` — ``DIR/manifest.parquet``, sidecar rows, resume checks;
* :mod:`~cmsim.datasets.runner` — :func:`generate_dataset`, the one runner;
* :mod:`~cmsim.datasets.pool` — the task pool (local processes or Dask, Ctrl-C/SIGTERM);
* :mod:`~cmsim.datasets.lock` — one run per directory (``fcntl.flock``);
* :mod:`~cmsim.datasets.windows` — the one window rule, the train/val/test split of groups,
  the windowed Parquet layout;
* :mod:`~cmsim.datasets.load` — :func:`load`: the manifest, lazy :class:`DatasetRecord` s,
  ML arrays (by default only the channels a real machine measures);
* :mod:`~cmsim.datasets.export` — a run or a dataset as npz/csv/wav/mat/uff/tdms/parquet files
  (``cmsim export``), the bearing-datasets schema;
* :mod:`~cmsim.datasets.torch_windows` — ``WindowDataset``, the windows for PyTorch.

Examples
--------
>>> from cmsim.datasets import DatasetSpec, Variation
>>> spec = DatasetSpec([Variation("torque_nm", [10, 100]), Variation("clearance_m", [15e-6, 0])],
...                    fixed={"speed_rpm": 1000}, duration_s=0.1)
>>> [spec.record_id(i) for i in range(len(spec))]
['000_T10Nm_c15um', '001_T10Nm_c0um', '002_T100Nm_c15um', '003_T100Nm_c0um']
"""

from cmsim.datasets.distribution import Distribution
from cmsim.datasets.load import Dataset, DatasetRecord, load
from cmsim.datasets.lock import LOCK_NAME, DirectoryLock
from cmsim.datasets.manifest import PARQUET_NAME, RECORDS_DIR, SPEC_NAME, read_rows
from cmsim.datasets.plan import RecordPlan
from cmsim.datasets.pool import START_METHODS, Interrupted
from cmsim.datasets.records import FEATURE_SIGNALS, manifest_features, simulate_record
from cmsim.datasets.runner import DatasetSummary, generate_dataset
from cmsim.datasets.spec import SAMPLINGS, SEED_POLICIES, DatasetSpec
from cmsim.datasets.variation import OPERATING_POINT_FIELDS, RIG_TRANSFORMS, Variation

__all__ = ["DatasetSpec", "Variation", "Distribution", "RecordPlan", "DatasetSummary",
           "generate_dataset", "simulate_record", "load", "Dataset", "DatasetRecord",
           "read_rows", "manifest_features", "DirectoryLock", "Interrupted", "SAMPLINGS",
           "SEED_POLICIES", "START_METHODS", "PARQUET_NAME", "RECORDS_DIR", "SPEC_NAME",
           "LOCK_NAME", "FEATURE_SIGNALS", "OPERATING_POINT_FIELDS", "RIG_TRANSFORMS"]
