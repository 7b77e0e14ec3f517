"""Asymmetric friction: separate viscous and Coulomb coefficients for each direction.

.. math:: \\tau_f(\\dot q) = f_{v+} \\dot q^+ + f_{v-} \\dot q^-
          + f_{c+} [s(\\dot q) > 0] - f_{c-} [s(\\dot q) < 0]

with ``dq+ = max(dq, 0)``, ``dq- = min(dq, 0)`` and ``s`` the sign outside the standstill
band (:func:`~dynid.friction.model.coulomb_sign`): zero at rest. An offset is the
difference of ``fc+`` and ``fc-``, which therefore have either sign; ``fv+``, ``fv-``
[N m s/rad] ``>= 0``, ``fc+``, ``fc-`` [N m]. MuJoCo's joints are symmetric: the MJCF
export writes the means (``damping = (fv+ + fv-) / 2``, ``frictionloss = (fc+ + fc-) / 2``)
and drops the asymmetry.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..torques import coulomb_sign
from .base import MjcfTerms, canonical_rows, linear_law

__all__ = ["LAW", "columns"]


def columns(dq: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    """Regressor (..., n, 4): ``(dq+, dq-, [s > 0], -[s < 0])`` per joint."""
    s = coulomb_sign(dq, band)
    return np.stack(
        [np.maximum(dq, 0.0), np.minimum(dq, 0.0), (s > 0).astype(float), -(s < 0).astype(float)],
        axis=-1,
    )


def _mjcf(P: NDArray[np.float64], dq_max: NDArray[np.float64]) -> MjcfTerms:
    asym = np.any(P[:, 0] != P[:, 1]) or np.any(P[:, 2] != P[:, 3])
    return MjcfTerms(
        (P[:, 0] + P[:, 1]) / 2.0,
        np.maximum((P[:, 2] + P[:, 3]) / 2.0, 0.0),
        (P[:, 2] - P[:, 3]) / 2.0,
        "the asymmetry of fv+/fv- and fc+/fc- (MuJoCo joints are symmetric)" if asym else "",
    )


def _canonical(P: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    fvp, fvn, fcp, fcn = P.T
    return canonical_rows(band, fv_pos=fvp, fv_neg=fvn, fc_pos=fcp, fc_neg=fcn)


LAW = linear_law(
    "asymmetric",
    ("fv_pos", "fv_neg", "fc_pos", "fc_neg"),
    ("N m s/rad", "N m s/rad", "N m", "N m"),
    "tau_f = fv_pos max(dq, 0) + fv_neg min(dq, 0) + fc_pos [s(dq) > 0] - fc_neg [s(dq) < 0], "
    "s(dq) = sign(dq) where |dq| > standstill_band, else 0",
    columns,
    (0.0, 0.0, -np.inf, -np.inf),
    (np.inf, np.inf, np.inf, np.inf),
    _mjcf,
    _canonical,
)
