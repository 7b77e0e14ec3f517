"""Held-out judgement of the consistent fit: the prior's weight and the acceptance.

The consistent fit (:mod:`dynid.feasibility.convex`) trades the data against the prior with a
weight ``w``. On the training data, any constraint raises the residual, and unconstrained
least squares, which absorbs noise and unmodelled effects into unphysical coefficients,
always looks best; on data the fit has not seen it may predict worse than a consistent
set. Both decisions are therefore taken on held-out data
(:mod:`dynid.identification.holdout`: k-fold over contiguous time blocks, or a separate
log):

* **the weight** (automatic): every fold is fitted on its training blocks at weights
  ``10^-4, 10^-2, .., 10^6`` (times the fold's share of the rows, so that the balance of data
  and prior is that of the full fit at ``w``); the pooled held-out error is taken at each,
  and the largest weight that predicts as well as the best is kept, refined by
  :data:`BISECTIONS` bisections of its logarithm towards the next grid point: its error
  within ``residual_increase`` (1 %) of the best, and, with two folds or more, above it
  by at most one standard error of the difference, paired over the folds (the rule that
  chooses the model's structure). The prior decides what the held-out data do not ask
  for; a 1 % allowance alone let it move coefficients the data determine to 0.2 % by 28
  of their standard deviations (a 7-joint arm, its own description as the prior).
* **the acceptance**: the consistent fit is accepted when its held-out error is at most
  ``heldout_tol`` (:data:`DEFAULT_HELDOUT_TOL`, 5 %) above that of unconstrained least
  squares over the same folds, whatever its training residual.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

__all__ = [
    "BISECTIONS",
    "DEFAULT_HELDOUT_TOL",
    "GRID_DECADES",
    "TIE_FLOOR_PERCENT",
    "HeldOutJudgement",
    "paired_se",
    "search_weight",
]

#: Accepted when the held-out error is at most this fraction above least squares'.
DEFAULT_HELDOUT_TOL = 0.05
#: Decades between the weights of the grid.
GRID_DECADES = 2.0
#: Bisections of the logarithm of the weight after the grid.
BISECTIONS = 3
#: Held-out errors [%] closer than this tie, whatever the folds' spread (round-off of the
#: normal equations on exact data is near 1e-6 %).
TIE_FLOOR_PERCENT = 1e-4


@dataclass(frozen=True, slots=True)
class HeldOutJudgement:
    """Training and held-out errors of the consistent fit against least squares.

    Attributes
    ----------
    scheme : str
        ``"blocks"`` (k-fold over contiguous time blocks) or ``"file"`` (a separate log).
    folds : int
    ls_training_percent, ls_heldout_percent : float
        Relative torque error [%] of unconstrained least squares on its training data and
        on held-out data.
    training_percent, heldout_percent : float
        The same for the consistent fit (held-out: its folds at the chosen weight).
    tolerance : float
        Accepted when ``heldout_percent <= (1 + tolerance) ls_heldout_percent``.
    weight_search : tuple of (float, float)
        ``(w, held-out error [%])`` of every weight tried.
    choice : str
        How the weight was chosen, in words.
    """

    scheme: str
    folds: int
    ls_training_percent: float
    ls_heldout_percent: float
    training_percent: float
    heldout_percent: float
    tolerance: float
    weight_search: tuple[tuple[float, float], ...]
    choice: str

    @property
    def ratio(self) -> float:
        """Held-out error of the consistent fit over least squares'."""
        if self.ls_heldout_percent <= 0:
            return 1.0 if self.heldout_percent <= 0 else math.inf
        return self.heldout_percent / self.ls_heldout_percent

    @property
    def accepted(self) -> bool:
        """The held-out error is within the tolerance of least squares'."""
        return self.ratio <= 1.0 + self.tolerance

    def as_dict(self) -> dict[str, object]:
        """JSON-ready (``feasible.json``'s ``heldout``)."""
        return {
            "scheme": self.scheme,
            "folds": self.folds,
            "least_squares": {
                "training_error_percent": self.ls_training_percent,
                "heldout_error_percent": self.ls_heldout_percent,
            },
            "consistent": {
                "training_error_percent": self.training_percent,
                "heldout_error_percent": self.heldout_percent,
            },
            "ratio": self.ratio,
            "tolerance": self.tolerance,
            "accepted": self.accepted,
            "weight_search": [[w, e] for w, e in self.weight_search],
            "weight_choice": self.choice,
        }


def paired_se(a: Sequence[float], b: Sequence[float]) -> float:
    """Standard error of the mean of ``a - b`` (per-fold errors of two weights, paired over
    the same folds); 0 for fewer than two folds."""
    if len(a) < 2 or len(a) != len(b):
        return 0.0
    d = [x - y for x, y in zip(a, b, strict=True)]
    mean = sum(d) / len(d)
    var = sum((x - mean) ** 2 for x in d) / (len(d) - 1)
    return math.sqrt(var / len(d))


def search_weight(
    heldout_at: Callable[[float], float],
    allowance: float,
    weight_range: tuple[float, float],
    fold_errors: Callable[[float], Sequence[float]] | None = None,
) -> tuple[float, list[tuple[float, float]], str]:
    """The largest weight that predicts held-out data as well as the best one (module
    docstring).

    Parameters
    ----------
    heldout_at : callable
        ``w -> pooled held-out error [%]`` of the consistent fit at weight ``w``.
    allowance : float
        Relative allowance over the best error (0.01 = 1 %).
    weight_range : (float, float)
        Smallest and largest weight of the grid.
    fold_errors : callable, optional
        ``w -> held-out error [%] of each fold`` at a weight ``heldout_at`` was called
        with; with two folds or more a weight is also held to one paired standard error
        of the difference from the best (:func:`paired_se`, at least
        :data:`TIE_FLOOR_PERCENT`).

    Returns
    -------
    w : float
    search : list of (float, float)
        ``(w, error)`` of every weight tried, in order.
    choice : str
        The choice in words.
    """
    lo, hi = (math.log10(x) for x in weight_range)
    grid = [lo + GRID_DECADES * i for i in range(int(math.floor((hi - lo) / GRID_DECADES)) + 1)]
    search = [(10.0**e, heldout_at(10.0**e)) for e in grid]
    best = min(err for _, err in search)
    w_best = min(search, key=lambda s: s[1])[0]
    limit = best * (1.0 + allowance)
    paired = fold_errors is not None and len(fold_errors(w_best)) >= 2

    def ties(w: float, err: float) -> bool:
        if err > limit:
            return False
        if not paired or fold_errors is None:
            return True
        se = paired_se(fold_errors(w), fold_errors(w_best))
        return err <= best + max(se, TIE_FLOOR_PERCENT)

    good = max(i for i, (w, err) in enumerate(search) if ties(w, err))
    rule = (
        f"within {100 * allowance:g} % of the best and one standard error of the difference "
        "(paired over the folds)"
        if paired
        else f"within {100 * allowance:g} % of the best"
    )
    if good == len(grid) - 1:
        w = search[good][0]
        return w, search, f"the top of the search range, whose held-out error is {rule}"
    a, b = grid[good], grid[good + 1]
    for _ in range(BISECTIONS):
        mid = 0.5 * (a + b)
        err = heldout_at(10.0**mid)
        search.append((10.0**mid, err))
        if ties(10.0**mid, err):
            a = mid
        else:
            b = mid
    w = 10.0**a
    return (
        w,
        search,
        (f"the largest whose held-out error is {rule} ({best:.3g} % at w = {w_best:.3g})"),
    )
