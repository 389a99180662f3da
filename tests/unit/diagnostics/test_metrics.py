"""Metrics of the diagnostics harness against hand-computed values.

Tier (a) closed form: every expected number below is worked out by hand in the comment
beside it (confusion counts, F1 = 2TP/(2TP+FP+FN), AUC = pairs ranked right / all pairs,
the 95th percentile by linear interpolation).
"""

import math

import numpy as np
import pytest

from cmsim.diagnostics import (Diagnosis, accuracy, as_diagnosis, confusion_matrix,
                               detection_threshold, detection_vs_severity, macro_f1,
                               one_vs_rest_auc, roc_auc)
from cmsim.errors import ParameterError

TRUE = ["healthy", "healthy", "healthy", "outer_race", "outer_race", "inner_race"]
PRED = ["healthy", "outer_race", "healthy", "outer_race", "inner_race", "inner_race"]


def test_accuracy_and_confusion():
    # correct: 0, 2, 3, 5 -> 4 of 6
    assert accuracy(TRUE, PRED) == pytest.approx(4 / 6)
    classes, m = confusion_matrix(TRUE, PRED)
    assert classes == ["healthy", "inner_race", "outer_race"]
    assert m.tolist() == [[2, 0, 1], [0, 1, 0], [0, 1, 1]]


def test_macro_f1_by_hand():
    # healthy: TP 2, FP 0, FN 1 -> 4/5; inner: TP 1, FP 1, FN 0 -> 2/3;
    # outer: TP 1, FP 1, FN 1 -> 1/2; mean = (0.8 + 0.6667 + 0.5) / 3
    assert macro_f1(TRUE, PRED) == pytest.approx((0.8 + 2 / 3 + 0.5) / 3)
    # a class only predicted counts with F1 = 0 (union of labels, as scikit-learn)
    assert macro_f1(["a", "a"], ["a", "b"]) == pytest.approx((2 / 3 + 0.0) / 2)


def test_auc_of_a_known_ranking():
    # positives 0.35, 0.8 vs negatives 0.1, 0.4: pairs right (0.35>0.1, 0.8>0.1, 0.8>0.4) = 3/4
    assert roc_auc([0, 0, 1, 1], [0.1, 0.4, 0.35, 0.8]) == pytest.approx(0.75)
    assert roc_auc([0, 0, 1, 1], [0.1, 0.2, 0.3, 0.4]) == pytest.approx(1.0)
    assert roc_auc([0, 0, 1, 1], [0.4, 0.3, 0.2, 0.1]) == pytest.approx(0.0)
    # a tie counts one half: (1 + 0.5) / 2
    assert roc_auc([0, 1, 1], [0.5, 0.5, 0.9]) == pytest.approx(0.75)
    assert math.isnan(roc_auc([1, 1], [0.1, 0.2]))
    auc = one_vs_rest_auc(["healthy", "ball", "ball"],
                          [{"healthy": 2.0, "ball": 0.0}, {"healthy": 1.0, "ball": 3.0},
                           {"healthy": 0.0, "ball": 1.0}])
    assert auc["ball"] == pytest.approx(1.0) and auc["healthy"] == pytest.approx(1.0)


def test_detection_threshold_at_5_percent():
    # 95th percentile of 1..20: position 0.95 * 19 = 18.05 -> 19 + 0.05 * (20 - 19) = 19.05
    assert detection_threshold(np.arange(1.0, 21.0)) == pytest.approx(19.05)
    # one healthy score in 20 is above it: the false-alarm rate is 5 %
    y = ["healthy"] * 20 + ["ball"] * 4
    sev = [math.nan] * 20 + [1e-4, 2e-4, 3e-4, 4e-4]
    score = list(np.arange(1.0, 21.0)) + [5.0, 19.5, 18.0, 25.0]
    det = detection_vs_severity(y, sev, score)
    assert det["threshold"] == pytest.approx(19.05)
    assert det["false_alarm_rate"] == pytest.approx(0.05)
    ball = det["classes"]["ball"]
    assert ball["detection_rate"] == [0.0, 1.0, 0.0, 1.0]
    assert ball["min_detected_severity"] == pytest.approx(2e-4)
    assert ball["min_reliable_severity"] == pytest.approx(4e-4)   # 3e-4 is missed
    assert ball["detection_rate_all"] == pytest.approx(0.5)


def test_detection_without_healthy_records_is_not_scored():
    det = detection_vs_severity(["ball", "ball"], [1e-4, 2e-4], [3.0, 4.0])
    assert math.isnan(det["threshold"]) and det["classes"]["ball"]["detection_rate_all"] == 0.0


def test_diagnosis_forms():
    assert Diagnosis(scores={"healthy": 0.2, "ball": 0.7}).label == "ball"
    assert Diagnosis(scores={"healthy": 0.2, "ball": 0.7}).fault_score == pytest.approx(0.7)
    assert as_diagnosis("outer_race").fault_score == 1.0
    assert as_diagnosis("healthy").fault_score == 0.0
    assert as_diagnosis({"healthy": 1.0, "gear": -1.0}).label == "healthy"
    with pytest.raises(ParameterError, match="must return"):
        as_diagnosis(None)
    with pytest.raises(ParameterError, match="label or at least one finite score"):
        Diagnosis()
    with pytest.raises(ParameterError, match="differ in length"):
        accuracy(["a"], ["a", "b"])
