"""Estimators of the base parameters: ordinary, weighted and outlier-robust least squares.

Every route gives the one least-squares engine (:mod:`dynid.identification.engine`) rows of
a regressor ``W`` and measurements ``y`` in *groups* of equal noise: the joints of a torque
log (row ``k n + j`` is joint ``j``), the rows of ``[tril M; g]`` of static data. An
estimator is a row-weighting policy (:class:`~dynid.identification.estimators.base.Estimator`):
the engine fits, shows it the residual, and fits again with the weights it gives until it
answers None:

* :class:`OLS` (:mod:`.ols`): ordinary least squares (Gaz et al. 2019, eq. 21);
* :class:`WLS` (:mod:`.wls`): one noise level per group from a first OLS fit (Gautier 1997);
* :class:`IRLS` (:mod:`.irls`): Huber's weights from the WLS start (Huber 1981).

Standard deviations come from the last weighted fit (``std`` ``"classical"`` or
``"robust"``); the residual statistics (``relative_error_percent``, ``residual_rms``) are
those of the unweighted data, so that they compare across estimators.

**A new estimator** is one module in this package with a class that has the protocol
(``name``, ``weighted``, ``per_row``, ``reweight``, ``row_weights``) and one line in
:data:`ESTIMATORS`.
The engine fits it on rows held whole and on rows read in blocks alike, the held-out
judgement weighs held-out rows with its ``row_weights`` and the one-step consistent fit
takes its weighted covariance.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

from ...exceptions import OptionError, WrongTypeError
from .base import (
    Estimator,
    Residuals,
    Weights,
    group_noise,
    huber_weights,
    noise_from_squares,
    row_weights,
)
from .irls import IRLS
from .ols import OLS
from .wls import WLS

__all__ = [
    "ESTIMATORS",
    "IRLS",
    "OLS",
    "WLS",
    "Estimator",
    "EstimatorName",
    "Residuals",
    "Weights",
    "estimator_named",
    "group_noise",
    "huber_weights",
    "noise_from_squares",
    "row_weights",
]

#: The estimators by name (``--estimator``): each makes the estimator with its defaults.
ESTIMATORS: dict[str, Callable[[], Estimator]] = {
    "ols": OLS,
    "wls": WLS,
    "irls": IRLS,
}

#: The names of the estimators built in (the keys of :data:`ESTIMATORS`).
EstimatorName = Literal["ols", "wls", "irls"]


def estimator_named(estimator: str | Estimator) -> Estimator:
    """An estimator object from its name (or the object itself).

    Raises
    ------
    OptionError
        An unknown name.
    WrongTypeError
        An object without the :class:`~dynid.identification.estimators.base.Estimator`
        protocol.
    """
    if not isinstance(estimator, str):
        if not isinstance(estimator, Estimator):
            raise WrongTypeError(
                "estimator must be a name or an object with name, weighted, per_row, reweight and "
                f"row_weights (the Estimator protocol); got {type(estimator).__name__}"
            )
        return estimator
    make = ESTIMATORS.get(estimator)
    if make is None:
        raise OptionError(f"estimator must be one of {sorted(ESTIMATORS)}; got {estimator!r}")
    return make()
