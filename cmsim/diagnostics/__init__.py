"""Benchmark harness for diagnostic algorithms: run a user's function over a dataset, score it.

A diagnostic function has this signature (``cmsim evaluate DIR --algorithm MODULE:FUNCTION``)::

    def diagnose(signals, fs_hz, operating_point, frequencies):
        ...
        return Diagnosis(label="outer_race", scores={"healthy": 0.1, "outer_race": 4.2})

* ``signals`` — dict channel name → 1-D array (float32 from a generated dataset, float64
  from measured records; e.g. ``accel_1b1_x``, ``accel_1b1_y`` in m/s², ``tacho`` in V;
  measured records keep their own names: ``DE``, ``acc``, ``a1`` ...), all at ``fs_hz``;
* ``fs_hz`` — sample rate, Hz (float);
* ``operating_point`` — :class:`cmsim.rig.OperatingPoint` (``speed_rpm`` of the input shaft,
  ``torque_nm``, ``radial_load_n``);
* ``frequencies`` — :class:`cmsim.frequencies.RigFrequencies` of the rig at that speed
  (``fr1_hz``, ``fr2_hz``, ``gmf_hz``, per bearing ``bpfo_hz``, ``bpfi_hz``, ``bsf_hz``,
  ``ftf_hz``).

It returns a predicted label (``str``), or scores per class (``dict`` label → float, higher
= more likely; the label is then the top class), or both as a :class:`Diagnosis`. Labels are
the dataset's ``fault_label`` values: ``"healthy"``, ``"outer_race"``, ``"inner_race"``,
``"ball"``, ``"tooth_crack"``, ``"tooth_spall"`` … (several faults: ``"+"``-joined sorted
types). A function may carry a ``label_map`` attribute (true label → its class, e.g. every
tooth fault → ``"gear"``) that the harness applies to the answer key. The function never
sees the answer key; if it raises on a record (``sys.exit`` included), that record is
reported with the error and its traceback and left out of the scores, and the evaluation goes
on (with ``isolated=True``, as ``cmsim evaluate`` runs it, also where it ends the process
itself: ``os._exit``, a crash in compiled code). What it prints goes to stderr (:mod:`~cmsim.diagnostics.user_code`), so that
``cmsim evaluate --json`` prints one JSON object on stdout; an evaluation in which it answered
no record exits with status 2.

Scores (:mod:`~cmsim.diagnostics.metrics`): accuracy, macro-F1, confusion matrix, per-class
ROC AUC (one-vs-rest, from the scores), and detection against severity at a 5 % false-alarm
rate (threshold = 95th percentile of the healthy records' fault scores; the fault score is the
largest score of a non-healthy class, or 1/0 from the label alone).

Modules: :mod:`~cmsim.diagnostics.diagnosis` (:class:`Diagnosis`),
:mod:`~cmsim.diagnostics.metrics`, :mod:`~cmsim.diagnostics.harness` (:func:`evaluate`),
:mod:`~cmsim.diagnostics.user_code` (the user's function run isolated),
:mod:`~cmsim.diagnostics.baselines` (``envelope``, ``tsa``, ``sideband``),
measured records of ``../shared/datasets`` come from :mod:`cmsim.measured`;
:mod:`~cmsim.diagnostics.report` (HTML page).

Example
-------
>>> from cmsim.diagnostics import Diagnosis
>>> Diagnosis(scores={"healthy": 0.2, "ball": 0.7}).label
'ball'
"""

from cmsim.diagnostics.baselines import BASELINES
from cmsim.diagnostics.diagnosis import HEALTHY, Diagnosis, as_diagnosis
from cmsim.diagnostics.harness import (Evaluation, RecordResult, evaluate, load_algorithm,
                                       load_dataset, score)
from cmsim.diagnostics.metrics import (FALSE_ALARM_RATE, accuracy, confusion_matrix,
                                       detection_threshold, detection_vs_severity, macro_f1,
                                       one_vs_rest_auc, roc_auc)

__all__ = ["Diagnosis", "as_diagnosis", "HEALTHY", "Evaluation", "RecordResult", "evaluate",
           "score", "load_algorithm", "load_dataset", "BASELINES", "FALSE_ALARM_RATE", "accuracy", "confusion_matrix",
           "detection_threshold", "detection_vs_severity", "macro_f1", "one_vs_rest_auc",
           "roc_auc"]
