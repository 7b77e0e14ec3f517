"""A linear spring at every joint with known values: :class:`JointStiffness`.

.. math:: \\tau_{s,j} = k_j \\, (q_j - q_{0,j})

The values of the identified spring term (:class:`dynid.regressors.spring.JointSpring`)
as a consistent fit carries them and the exports write them (MJCF's joint ``stiffness``
and ``springref``, a TOML robot's ``[spring]`` table). ``k`` [N m/rad] (or [N/m] for a
prismatic joint), ``q0`` [rad] (or [m]); the torque is the one the motors supply against
the spring, added to the rigid-body torques like friction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import ShapeError

__all__ = ["JointStiffness"]


@dataclass(frozen=True, slots=True, eq=False)
class JointStiffness:
    """Stiffnesses ``k`` (n,) [N m/rad] about rest positions ``q0`` (n,) [rad].

    Raises
    ------
    ShapeError
        ``k`` and ``q0`` are not vectors of one length, or hold a non-finite number.
    """

    k: NDArray[np.float64]
    q0: NDArray[np.float64]

    def __post_init__(self) -> None:
        k = np.array(self.k, dtype=np.float64)
        q0 = np.array(self.q0, dtype=np.float64)
        if k.ndim != 1 or k.shape != q0.shape:
            raise ShapeError(f"k and q0 must be (n,) alike; got {k.shape} and {q0.shape}")
        if not (np.all(np.isfinite(k)) and np.all(np.isfinite(q0))):
            raise ShapeError("k and q0 must be finite")
        k.setflags(write=False)
        q0.setflags(write=False)
        object.__setattr__(self, "k", k)
        object.__setattr__(self, "q0", q0)

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.k.shape[0])

    def torques(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """``k * (q - q0)`` [N m], the shape of ``q`` (..., n) [rad]."""
        out: NDArray[np.float64] = self.k * (np.asarray(q, dtype=np.float64) - self.q0)
        return out
