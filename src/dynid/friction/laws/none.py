"""No friction: ``tau_f = 0``, no parameters.

The candidate "no extra friction" of the selection (:mod:`dynid.friction.select`), and
what ``friction.json`` holds when it wins: the rigid-body model alone predicted best.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .base import FrictionLaw, JointFit, MjcfTerms, canonical_rows

__all__ = ["LAW"]


def _torques(
    dq: NDArray[np.float64], P: NDArray[np.float64], band: NDArray[np.float64]
) -> NDArray[np.float64]:
    return np.zeros(np.shape(dq))


def _fit(dq: NDArray[np.float64], r: NDArray[np.float64], band: float) -> JointFit:
    return JointFit(np.zeros(0))


def _mjcf(P: NDArray[np.float64], dq_max: NDArray[np.float64]) -> MjcfTerms:
    z = np.zeros(P.shape[0])
    return MjcfTerms(z, z, z)


def _canonical(P: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    return canonical_rows(band)


LAW = FrictionLaw("none", (), (), "tau_f = 0", _torques, _fit, (), (), _mjcf, _canonical)
