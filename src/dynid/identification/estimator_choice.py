"""The estimator chosen on held-out data: ordinary or weighted least squares.

The joints of a torque log are measured with noise of different levels: a motor current's
noise times its torque constant and gear ratio is a hundred times larger at a shoulder
than at a wrist. Ordinary least squares (:class:`~.estimators.OLS`) weighs every row
alike, so that the large joints' noise sets the parameters the wrists' small torques
alone determine; weighted least squares (:class:`~.estimators.WLS`, Gautier 1997) weighs
each joint by its own residual level. Of equal noise on every joint the two fits are the
same up to noise, and the simpler one is kept.

:func:`choose_estimator` judges the fits of one structure, one per estimator, the way the
structure is chosen (:mod:`dynid.identification.selection`): on the same held-out folds,
each joint's torques in units of its own noise (the whitened held-out error,
:attr:`~.candidates.Candidate.score`), and keeps the first (the simplest: ``ols``) within
one standard error of the lowest, the standard error that of the difference paired over
the folds (:func:`~.candidates.within_best`). Where the noise of the joints is not known
(no whitened rows) no choice is made: the pooled error in N m is what ordinary least
squares already minimises.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .candidates import Candidate, candidate_judged, paired_se, within_best
from .model import IdentifiedModel
from .structure import Structure

__all__ = ["ESTIMATOR_RULE", "EstimatorChoice", "choose_estimator"]

#: How the estimator is chosen (:func:`choose_estimator`).
ESTIMATOR_RULE = (
    "ols unless wls predicts the held-out data better by more than one standard error "
    "(each joint in units of its own noise, paired over the folds, the same folds as the "
    "structure's)"
)


@dataclass(frozen=True, slots=True)
class EstimatorChoice:
    """The estimators judged on held-out data and the one kept (module docstring).

    Attributes
    ----------
    chosen : str
        The estimator kept (``"ols"`` or ``"wls"``).
    names : tuple of str
        The estimators judged, the simplest first.
    candidates : tuple of Candidate
        Each one's fit of the structure judged on the folds, in the order of ``names``;
        ``se_vs_best_percent`` set.
    rule : str
        How it was chosen.
    """

    chosen: str
    names: tuple[str, ...]
    candidates: tuple[Candidate, ...]
    rule: str = ESTIMATOR_RULE

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (``identification.json``'s ``metadata.estimator_choice``)."""
        return {
            "rule": self.rule,
            "chosen": self.chosen,
            "candidates": [
                {
                    "estimator": name,
                    "train_error_percent": c.train_error_percent,
                    "heldout_error_percent": c.heldout_error_percent,
                    "heldout_whitened_percent": c.whitened_error_percent,
                    "heldout_se_vs_best_percent": c.se_vs_best_percent,
                    "heldout_per_fold_percent": list(c.fold_errors_percent),
                }
                for name, c in zip(self.names, self.candidates, strict=True)
            ],
        }


def choose_estimator(
    structure: Structure, fits: Sequence[tuple[str, IdentifiedModel]], rtol: float
) -> EstimatorChoice | None:
    """The estimator whose fit of ``structure`` predicts the held-out data as well as the
    best one, the first (simplest) such of ``fits`` (module docstring).

    Parameters
    ----------
    structure : Structure
        The structure every fit holds.
    fits : sequence of (str, IdentifiedModel)
        Each estimator's name and its fit, the simplest first, each with its held-out
        folds (:attr:`~.model.IdentifiedModel.holdout`, the same folds for all).
    rtol : float
        Relative rank tolerance of the folds' fits.

    Returns
    -------
    EstimatorChoice or None
        None when a fit has no held-out folds or the joints' noise is not known (no
        whitened rows to judge on).
    """
    judged = []
    for _, model in fits:
        held = model.holdout
        if held is None or not held.whitened:
            return None
        fit = model.joint_fit if model.joint_fit is not None else model.fit
        use = np.ones(len(fit.kept), dtype=bool)
        judged.append(candidate_judged(structure, use, model, held, rtol))
    best = min(judged, key=lambda c: c.score)
    judged = [replace(c, se_vs_best_percent=paired_se(c, best)) for c in judged]
    first = next(i for i, c in enumerate(judged) if within_best(c, best))
    return EstimatorChoice(fits[first][0], tuple(n for n, _ in fits), tuple(judged))
