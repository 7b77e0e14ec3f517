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
  and the largest weight whose error is within ``residual_increase`` (1 %) of the best is
  kept, refined by :data:`BISECTIONS` bisections of its logarithm towards the next grid
  point. The prior decides what the held-out data do not ask for.
* **the acceptance**: the consistent fit is accepted when its held-out error is at most
  ``heldout_tol`` (:data:`DEFAULT_HELDOUT_TOL`, 5 %) above that of unconstrained least
  squares over the same folds, whatever its training residual.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

__all__ = [
    "BISECTIONS",
    "DEFAULT_HELDOUT_TOL",
    "GRID_DECADES",
    "HeldOutJudgement",
    "search_weight",
]

#: Accepted when the held-out error is at most this fraction above least squares'.
DEFAULT_HELDOUT_TOL = 0.05
#: Decades between the weights of the grid.
GRID_DECADES = 2.0
#: Bisections of the logarithm of the weight after the grid.
BISECTIONS = 3


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


def search_weight(
    heldout_at: Callable[[float], float],
    allowance: float,
    weight_range: tuple[float, float],
) -> tuple[float, list[tuple[float, float]], str]:
    """The largest weight whose held-out error is within ``allowance`` of the best.

    Parameters
    ----------
    heldout_at : callable
        ``w -> pooled held-out error [%]`` of the consistent fit at weight ``w``.
    allowance : float
        Relative allowance over the best error (0.01 = 1 %).
    weight_range : (float, float)
        Smallest and largest weight of the grid.

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
    limit = best * (1.0 + allowance)
    good = max(i for i, (_, err) in enumerate(search) if err <= limit)
    if good == len(grid) - 1:
        w = search[good][0]
        return (
            w,
            search,
            (
                f"the top of the search range, whose held-out error is within "
                f"{100 * allowance:g} % of the best ({best:.3g} %)"
            ),
        )
    a, b = grid[good], grid[good + 1]
    for _ in range(BISECTIONS):
        mid = 0.5 * (a + b)
        err = heldout_at(10.0**mid)
        search.append((10.0**mid, err))
        if err <= limit:
            a = mid
        else:
            b = mid
    w = 10.0**a
    return (
        w,
        search,
        (
            f"the largest whose held-out error is within {100 * allowance:g} % of the best "
            f"({best:.3g} % at w = {min(search, key=lambda s: s[1])[0]:.3g})"
        ),
    )
