"""The paper's penalty method of feasible link parameters (Gaz et al. 2019, Sec. V, Algorithm 1).

* :mod:`.objective`: the penalised objective (:class:`PenaltyProblem`), from identified
  coefficients (:func:`coefficient_problem`, eq. 29) or static data (:func:`static_problem`);
* :mod:`.options`: :class:`RetrievalOptions`; :mod:`.result`: :class:`RetrievalResult`;
* :mod:`.algorithm`: Algorithm 1 (independent runs of annealing and refinement stages);
* :mod:`.fit`: the entry points :func:`retrieve` (an identified model),
  :func:`retrieve_from_coefficients` and :func:`retrieve_from_static`.
"""

from .fit import retrieve, retrieve_from_coefficients, retrieve_from_static
from .objective import (
    DEFAULT_MARGIN,
    DEFAULT_SCALE_FLOOR,
    PenaltyProblem,
    coefficient_problem,
    coefficient_scales,
    phi_from_params,
    static_problem,
    with_prior,
)
from .options import RetrievalOptions
from .result import ParameterDistance, RetrievalProgress, RetrievalResult, RetrievalRun

__all__ = [
    "DEFAULT_MARGIN",
    "DEFAULT_SCALE_FLOOR",
    "ParameterDistance",
    "PenaltyProblem",
    "RetrievalOptions",
    "RetrievalProgress",
    "RetrievalResult",
    "RetrievalRun",
    "coefficient_problem",
    "coefficient_scales",
    "phi_from_params",
    "retrieve",
    "retrieve_from_coefficients",
    "retrieve_from_static",
    "static_problem",
    "with_prior",
]
