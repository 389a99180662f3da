"""The one measured record: ``metadata.json`` schema, signal readers, inference, model, dataset.

A measured recording is a signal file, usually in a folder with ``metadata.json`` (the
schema of ``../shared/datasets/README.md``); what neither states, the caller gives. Modules,
in reading order:

* :mod:`~cmsim.measured.schema` — the keys the pipeline reads, the answer key it never reads,
  unit constants (lbf, inch, g);
* :mod:`~cmsim.measured.readers` — file I/O, one module per type with its reader and writer
  side by side (``.npz``, ``.csv``, ``.wav``, ``.mat``, ``.uff``/``.unv``, ``.tdms``);
* :mod:`~cmsim.measured.stated` — one rule for what the file, ``metadata.json`` and the
  caller state (rate, speed, unit, calibration): the first gives it, the others must agree;
* :mod:`~cmsim.measured.importing` — a folder of recordings documented as ``metadata.json``
  (``cmsim import``);
* :mod:`~cmsim.measured.inference` — speed and sample rate from the signal when the metadata
  lacks them (one rule for an undocumented sample rate; a metadata note only cross-checks);
* :mod:`~cmsim.measured.model_rig` — the model rig, operating point and characteristic
  frequencies from the documented geometry;
* :mod:`~cmsim.measured.consistency` — a stated sample rate and speed checked against the
  record's own lines (shaft comb, bearing defect families) before anything is computed;
* :mod:`~cmsim.measured.record` — :class:`MeasuredRecord` (a measured :class:`~cmsim.run.Run`
  plus what a diagnosis and a comparison need), :func:`read_record`, and :func:`read_run`
  (any record cmsim writes or reads, as a run: ``cmsim spectrum``);
* :mod:`~cmsim.measured.dataset` — a folder as a dataset for the diagnostics harness.

Layering: above :mod:`cmsim.spectra`, below features, diagnostics and discrepancy.

>>> from cmsim.measured import LBF_N, unit_scale_of
>>> round(LBF_N, 4), unit_scale_of("g (believed)")
(4.4482, 9.80665)
"""

from cmsim.measured.dataset import MEASURED_DATASETS, MeasuredDataset, data_root, load_measured
from cmsim.measured.inference import estimate_shaft_hz
from cmsim.measured.record import MeasuredRecord, read_record, read_run, record_from_run
from cmsim.measured.schema import (ACCELERATION_UNITS, INCH_M, LBF_N, RECORDING_KEYS,
                                   STANDARD_GRAVITY_M_S2, answer_key, label_of, unit_scale_of)

__all__ = ["MeasuredRecord", "read_record", "read_run", "record_from_run", "MeasuredDataset",
           "load_measured", "data_root", "MEASURED_DATASETS", "estimate_shaft_hz",
           "RECORDING_KEYS", "ACCELERATION_UNITS", "LBF_N", "INCH_M", "STANDARD_GRAVITY_M_S2",
           "answer_key", "label_of", "unit_scale_of"]
