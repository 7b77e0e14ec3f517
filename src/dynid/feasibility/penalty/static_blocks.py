"""The static regressor of many configurations for the penalty method's single-step
problem (:func:`~dynid.feasibility.penalty.objective.static_problem`), a block at a time.

:class:`StaticBlocks` gives the base static regressor of consecutive blocks of
configurations, each within ``DYNID_MAX_STACK_BYTES``; :func:`r_factor` accumulates the
triangular factor of ``[W, y]`` over the blocks (its first ``r`` columns are ``R`` of
``W``, its last ``Q^T y`` and, in its corner, the residual's norm), so that no more than
one block of rows is held, whatever the number of configurations or the chain's length.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ...identification.streaming import max_stack_bytes
from ...model.robot import Robot
from ...regressors.base import BaseParameters
from ...regressors.static import static_regressor_columns, static_rows

__all__ = ["StaticBlocks", "r_factor"]


class StaticBlocks:
    """The base static regressor ``(B, rows, r)`` of consecutive blocks of configurations,
    each at most :func:`~dynid.identification.streaming.max_stack_bytes` (only the base
    columns computed); iterated once per pass, one block held at a time (a single block
    is computed once)."""

    def __init__(self, robot: Robot, q: NDArray[np.float64], base: BaseParameters) -> None:
        self.robot, self.q, self.ind = robot, q, np.asarray(base.independent)
        per = 8 * static_rows(robot.n) * (base.rank + 1) * 4  # the block, weighted, stacked
        self.step = max(1, max_stack_bytes() // per)
        self._whole: NDArray[np.float64] | None = None

    def __iter__(self) -> Iterator[tuple[slice, NDArray[np.float64]]]:
        N = self.q.shape[0]
        if N <= self.step:
            if self._whole is None:
                self._whole = self._rows(slice(0, N))
            yield slice(0, N), self._whole
            return
        for a in range(0, N, self.step):
            sl = slice(a, min(a + self.step, N))
            yield sl, self._rows(sl)

    def _rows(self, sl: slice) -> NDArray[np.float64]:
        Y = static_regressor_columns(self.robot, self.q[sl], self.ind)  # (r, rows, B)
        return np.ascontiguousarray(Y.transpose(2, 1, 0))


def r_factor(
    R: NDArray[np.float64] | None, W: NDArray[np.float64], y: NDArray[np.float64]
) -> NDArray[np.float64]:
    """R (at most r + 1 rows) of the rows ``[W, y]`` stacked under the factor ``R`` so far."""
    X = np.column_stack([W, y])
    X = X if R is None else np.vstack([R, X])
    return cast("NDArray[np.float64]", np.linalg.qr(X, mode="r"))  # (min(rows, r + 1), r + 1)
