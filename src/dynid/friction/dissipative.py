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
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..identification.dissipation import Violation, power_violations, speed_limits
from .model import FrictionModel, FrictionSum, friction_parts

__all__ = ["law_violations"]


def law_violations(
    friction: FrictionModel | FrictionSum, dq_max: ArrayLike
) -> tuple[Violation, ...]:
    """Where ``friction`` is not dissipative within the velocity limits, its offset aside
    (module docstring).

    Parameters
    ----------
    friction : FrictionModel or FrictionSum
        A law with its parameters (per motor at the motors of a drive); a sum's parts are
        each judged where they act.
    dq_max : array_like, shape (n,)
        Joint velocity limits [rad/s] (``inf``: a joint not checked).

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

        def odd(v: NDArray[np.float64], part: FrictionModel = part) -> NDArray[np.float64]:
            law, p, b = part.law, part.params, part.band
            return np.asarray(0.5 * (law.torques(v, p, b) - law.torques(-v, p, b)))

        coefficients = [
            {f"{name}{j + 1}": float(P[j, i]) for i, name in enumerate(part.names)}
            for j in range(part.n)
        ]
        out += power_violations(odd, vmax, coefficients, place)
    return tuple(out)
