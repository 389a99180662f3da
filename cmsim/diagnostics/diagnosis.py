"""What a diagnostic function returns: a label and/or a score per class."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from cmsim.errors import ParameterError

__all__ = ["Diagnosis", "as_diagnosis", "HEALTHY"]

#: Label of a fault-free record.
HEALTHY = "healthy"


@dataclass(frozen=True)
class Diagnosis:
    """What a diagnostic function says about one record.

    Attributes
    ----------
    label : str or None
        Predicted class (``"healthy"``, ``"outer_race"`` ...); ``None``: the class with the
        largest score.
    scores : dict of str to float
        Class → score (higher = more likely; any scale, only the order within a class counts
        for the ROC AUC). May be empty when a label is given.
    """

    label: str | None = None
    scores: dict = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.scores, dict):
            raise ParameterError(f"scores must be a dict of class -> float, got "
                                 f"{type(self.scores).__name__}", param="scores")
        scores = {str(k): float(v) for k, v in self.scores.items()}
        object.__setattr__(self, "scores", scores)
        if self.label is None:
            finite = {k: v for k, v in scores.items() if math.isfinite(v)}
            if not finite:
                raise ParameterError("a diagnosis needs a label or at least one finite score",
                                     param="label")
            object.__setattr__(self, "label", max(finite, key=finite.get))
        elif not isinstance(self.label, str):
            raise ParameterError(f"label must be a str, got {type(self.label).__name__}",
                                 param="label")

    @property
    def fault_score(self):
        """Score that the record is faulty: the largest score of a class other than
        ``"healthy"`` (NaN if none is finite); without scores 1.0 for a faulty label and 0.0
        for ``"healthy"``."""
        faults = [v for k, v in self.scores.items() if k != HEALTHY and math.isfinite(v)]
        if faults:
            return max(faults)
        if self.scores:
            return math.nan
        return 0.0 if self.label == HEALTHY else 1.0


def as_diagnosis(result):
    """A :class:`Diagnosis` from what a diagnostic function returned.

    Parameters
    ----------
    result : Diagnosis, str or dict of str to float
        A Diagnosis, a label, or class → score.
    """
    if isinstance(result, Diagnosis):
        return result
    if isinstance(result, str):
        return Diagnosis(label=result)
    if isinstance(result, dict):
        return Diagnosis(scores=result)
    raise ParameterError(f"a diagnostic function must return a Diagnosis, a label (str) or a "
                         f"dict of class -> score, got {type(result).__name__}",
                         param="algorithm")
