"""Measured data against the model: records, scale-free features, causes, fit and gain.

>>> from cmsim.discrepancy import CAUSES
>>> "bearing_outer_race" in CAUSES and "transfer_path" in CAUSES
True

Measured records come from :mod:`cmsim.measured` (:func:`cmsim.measured.read_record`);
what is compared is :func:`cmsim.features.relative_features`. See :mod:`~.causes` (the
catalogue), :mod:`~.compare` (the loop), :mod:`~.evaluator` (the model of a record read like
the record), :mod:`~.ranking` (evidence, decision, fit), :mod:`~.angle_domain` (records
from a generator that shares no code with the model),
:mod:`~.synthetic` (records with a hidden effect, for tests and benchmarks) and
:mod:`~.report` (HTML). Layering: above dynamics, sensors, measured, features, spectra and faults;
only the CLI imports it.
"""

from cmsim.discrepancy.causes import (CAUSES, Cause, ModelSetup, applicable_causes,
                                      register_cause)
from cmsim.discrepancy.compare import Comparison, compare
from cmsim.discrepancy.evaluator import simulate_setup

__all__ = ["CAUSES", "Cause", "ModelSetup", "applicable_causes", "register_cause",
           "Comparison", "compare", "simulate_setup"]
