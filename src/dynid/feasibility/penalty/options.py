"""Settings of the penalty method (Gaz et al. 2019, Algorithm 1): :class:`RetrievalOptions`."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...exceptions import OptionError
from .objective import (
    DEFAULT_MARGIN,
    DEFAULT_SCALE_FLOOR,
)

__all__ = ["MAX_WEIGHT", "RetrievalOptions"]

#: Largest penalty weight ``xi`` and prior weight: a stage objective's penalty rows then
#: outweigh its data rows by at most 1e12 in the refinement's normal equations (about what
#: float64 resolves); a larger weight only loses the data term to rounding, and its powers
#: overflow. The default schedule stays at this weight once it reaches it.
MAX_WEIGHT = 1e12


@dataclass(frozen=True, slots=True)
class RetrievalOptions:
    """Settings of Algorithm 1.

    Attributes
    ----------
    runs : int
        Independent runs ``Q`` (Gaz et al. used 10).
    stages : int
        Stages ``kappa`` per run (Gaz et al. used 5).
    xi : tuple of float, optional
        Penalty weight of every stage (length ``stages``, ``xi[0]`` normally 0, each at
        most :data:`MAX_WEIGHT`). Default ``(0, xi_first, xi_first * xi_growth, ...)``,
        each capped at :data:`MAX_WEIGHT` (so any number of stages is valid: the last ones
        refine at the cap).
    xi_first, xi_growth : float
        Default schedule: the weight of stage 2 (in ``(0, MAX_WEIGHT]``) and the factor
        between later stages (``>= 1``).
    anneal_maxiter : int
        Iterations of the simulated annealing per stage (each visits ``2 * 10 n``
        points); 0 skips the annealing.
    anneal_temperature : float
        Initial temperature of the annealing (scipy's ``initial_temp``, in (0.01, 5e4]),
        for the stage objective divided by its value at the warm start: the annealing
        explores around the current point rather than restarting from scratch.
    local_maxiter : int
        Iterations of the local refinement per stage.
    margin : float
        Relative target margin of the constraints and shrink of the box
        (:mod:`~dynid.feasibility.penalty`).
    scale_floor : float
        Floor of the coefficient scales (two-step objective).
    tol : float
        Relative tolerance of the feasibility report.
    residual_tol : float or None
        Largest relative residual on the data for which the parameters count as
        reproducing them: the report holds a ``data_fit`` constraint with margin
        ``residual_tol - relative_residual``, so that a specification that contradicts
        the data (a total-mass band the coefficients rule out, say) is reported
        infeasible even when the penalties gave in to it. None leaves it out. 5 % by
        default: noise-free or well-identified coefficients are met to round-off, the
        single-step residual is about the noise level of the static data.
    prior_weight : float
        Weight of the pull towards a prior, when one is given
        (:func:`~dynid.feasibility.penalty.with_prior`): each relative deviation of a
        standard parameter from the prior's counts ``prior_weight`` times a relative
        coefficient error. Small by default (1e-6: the coefficients are still met to
        about 1e-6 relative): among parameter sets that fit equally, the one closest to the
        prior wins.
    """

    runs: int = 10
    stages: int = 5
    xi: tuple[float, ...] | None = None
    xi_first: float = 1.0
    xi_growth: float = 100.0
    anneal_maxiter: int = 5
    anneal_temperature: float = 0.1
    local_maxiter: int = 1000
    margin: float = DEFAULT_MARGIN
    scale_floor: float = DEFAULT_SCALE_FLOOR
    tol: float = 1e-9
    residual_tol: float | None = 0.05
    prior_weight: float = 1e-6

    def __post_init__(self) -> None:
        if self.residual_tol is not None and not self.residual_tol > 0:
            raise OptionError(f"residual_tol must be positive or None; got {self.residual_tol}")
        if not (math.isfinite(self.prior_weight) and 0 <= self.prior_weight <= MAX_WEIGHT):
            raise OptionError(
                f"prior_weight must be in [0, {MAX_WEIGHT:g}]; got {self.prior_weight}"
            )
        if not (math.isfinite(self.xi_first) and 0 < self.xi_first <= MAX_WEIGHT):
            raise OptionError(f"xi_first must be in (0, {MAX_WEIGHT:g}]; got {self.xi_first}")
        if not (math.isfinite(self.xi_growth) and self.xi_growth >= 1):
            raise OptionError(f"xi_growth must be finite and >= 1; got {self.xi_growth}")
        if self.runs < 1 or self.stages < 1:
            raise OptionError(f"runs and stages must be >= 1; got {self.runs}, {self.stages}")
        if self.anneal_maxiter < 0 or self.local_maxiter < 0:
            raise OptionError("anneal_maxiter and local_maxiter must be >= 0")
        if self.xi is not None:
            xi = tuple(float(x) for x in self.xi)
            if len(xi) != self.stages:
                raise OptionError(
                    f"xi must have one weight per stage ({self.stages}); got {len(xi)}"
                )
            if any(not 0 <= x <= MAX_WEIGHT for x in xi):  # (NaN fails too)
                raise OptionError(f"xi must be in [0, {MAX_WEIGHT:g}]; got {xi}")
            object.__setattr__(self, "xi", xi)

    def schedule(self) -> tuple[float, ...]:
        """Penalty weights ``xi_1 .. xi_kappa`` (each at most :data:`MAX_WEIGHT`)."""
        if self.xi is not None:
            return self.xi
        out, x = [0.0], self.xi_first
        for _ in range(self.stages - 1):
            out.append(x)
            x = min(x * self.xi_growth, MAX_WEIGHT)  # (no power: 100**199 overflows)
        return tuple(out)
