"""Whether a fitted friction law dissipates: ``f(v) v >= 0`` within the velocity limits,
the offset aside, judged as identification judges its friction.

The check is identification's (:func:`~dynid.identification.dissipation.power_violations`,
which ``identify``'s structure selection reads to skip a candidate whose friction pushes
the arm), on the law's own torques. The offset aside is the odd part of the law,

.. math:: f_{odd}(v) = \\tfrac12 \\big(f(v) - f(-v)\\big)

which is ``f(v) - f_o`` for every law symmetric but for its offset (classical, smooth,
quadratic, Stribeck) and, for the asymmetric law, ``(fv+ v+ + fv- v-) + (fc+ + fc-) / 2
s(v)`` less its viscous asymmetry: the offset ``(fc+ - fc-) / 2`` left aside, the Coulomb
level ``(fc+ + fc-) / 2`` judged (``fc+ = 7.86``, ``fc- = -13.8`` on a UR5 elbow: an offset
and a Coulomb level of -2.97 N m that pushes the arm). A law at the motors of a drive is
checked per motor up to ``sum_j |K_mj| dq_max_j``
(:func:`~dynid.identification.dissipation.speed_limits`).

With the fitted parameters' covariance ``C`` (a law linear in them:
:attr:`~dynid.friction.fit.FrictionFit.covariance`), a velocity counts only where the
law pushes beyond its uncertainty: ``f_odd(v) sign(v) < -ALLOWANCE_STD sigma(v)``, with
``sigma(v)^2 = a(v)^T C a(v)`` the variance of ``f_odd(v) = a(v)^T p`` (a Coulomb level of
-0.002 N m fitted with a standard deviation of 0.003 N m on a joint without Coulomb
friction is no violation; one of -0.5 N m is).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..identification.dissipation import Violation, power_violations, speed_limits
from .laws.base import _LinearFit
from .model import FrictionModel, FrictionSum, friction_parts

__all__ = ["ALLOWANCE_STD", "law_violations"]

#: Standard deviations of the law's odd torque by which it may push the arm before it is
#: flagged (the fit's uncertainty; about 2: a 5 % chance for a truly dissipative law).
ALLOWANCE_STD = 2.0


def law_violations(
    friction: FrictionModel | FrictionSum,
    dq_max: ArrayLike,
    covariance: ArrayLike | None = None,
) -> tuple[Violation, ...]:
    """Where ``friction`` is not dissipative within the velocity limits, its offset aside,
    beyond :data:`ALLOWANCE_STD` standard deviations when its covariance is given (module
    docstring).

    Parameters
    ----------
    friction : FrictionModel or FrictionSum
        A law with its parameters (per motor at the motors of a drive); a sum's parts are
        each judged where they act.
    dq_max : array_like, shape (n,)
        Joint velocity limits [rad/s] (``inf``: a joint not checked).
    covariance : array_like, shape (n, k, k), optional
        The covariance of each joint's (motor's) ``k`` parameters of a law linear in them
        (:attr:`~dynid.friction.fit.FrictionFit.covariance`); None: no allowance.

    Returns
    -------
    tuple of Violation
        One per joint (motor) where ``f(v) v < 0`` for some ``|v|`` within its limit,
        naming the law's coefficients below zero (``fc_neg3 = -13.8``), else all of them.
    """
    out: list[Violation] = []
    for part in friction_parts(friction):
        P = part.as_array()
        place = "motor" if part.at_motors else "joint"
        K = part.transmission if part.at_motors else np.eye(part.n)
        vmax = speed_limits(K, dq_max)

        C = _linear_covariance(part, covariance) if len(friction_parts(friction)) == 1 else None

        def odd(
            v: NDArray[np.float64],
            part: FrictionModel = part,
            C: NDArray[np.float64] | None = C,
        ) -> NDArray[np.float64]:
            law, p, b = part.law, part.params, part.band
            f = np.asarray(0.5 * (law.torques(v, p, b) - law.torques(-v, p, b)))
            if C is None:
                return f
            assert isinstance(law.fit, _LinearFit)  # (_linear_covariance checked it)
            a = 0.5 * (law.fit.columns(v, b) - law.fit.columns(-v, b))  # (s, n, k)
            sigma = np.sqrt(np.maximum(np.einsum("snk,nkl,snl->sn", a, C, a), 0.0))
            return f + ALLOWANCE_STD * sigma * np.sign(v)  # moved towards dissipating

        coefficients = [
            {f"{name}{j + 1}": float(P[j, i]) for i, name in enumerate(part.names)}
            for j in range(part.n)
        ]
        out += power_violations(odd, vmax, coefficients, place)
    return tuple(out)


def _linear_covariance(
    part: FrictionModel, covariance: ArrayLike | None
) -> NDArray[np.float64] | None:
    """``covariance`` as (n, k, k) for ``part``'s law, linear in its ``k`` parameters;
    None without one or for a law that is not linear (no allowance)."""
    if covariance is None or not isinstance(part.law.fit, _LinearFit):
        return None
    C = np.asarray(covariance, dtype=np.float64)
    k = len(part.law.params)
    return C if C.shape == (part.n, k, k) and np.all(np.isfinite(C)) else None
