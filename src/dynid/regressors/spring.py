"""A linear spring at each joint about a known rest position: a model term
(:mod:`dynid.regressors.terms`), and the worked example of adding one (``ARCHITECTURE.md``).

.. math:: \\tau_{s,j} = k_j \\, (q_j - q_{0,j})

``k_j`` [N m/rad] (labels ``k1 .. k_n``) is identified; the rest position ``q0`` [rad] is
given (with it unknown, ``k_j q_{0,j}`` would be a constant torque, the friction's offset).
A gravity compensator spring or a cable's stiffness near its rest position is of this form.
The spring acts at rest too, but the static regressor's columns of a term are taken without
the configuration (:meth:`~dynid.regressors.terms.ModelTerm.static_columns`): it is
identified from torque logs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..model.drive import Drive
from ..model.stiffness import JointStiffness

__all__ = ["JointSpring"]


@dataclass(frozen=True, slots=True, eq=False)
class JointSpring:
    """A spring ``k_j (q_j - q0_j)`` at every joint (module docstring).

    Attributes
    ----------
    q0 : tuple of float
        The rest position [rad] (or [m] for a prismatic joint) per joint.
    name : str
        The term's name in the model (``"spring"``).
    """

    q0: tuple[float, ...]
    name: str = "spring"
    in_base: bool = False
    kind: str = "joint_spring"

    @property
    def labels(self) -> tuple[str, ...]:
        """``k1 .. k_n``."""
        return tuple(f"k{j + 1}" for j in range(len(self.q0)))

    @property
    def units(self) -> tuple[str, ...]:
        """N m/rad each."""
        return ("N m/rad",) * len(self.q0)

    @property
    def nonnegative(self) -> NDArray[np.bool_]:
        """Every stiffness is ``>= 0`` (a spring stores energy)."""
        return np.ones(len(self.q0), dtype=bool)

    def torque_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(B, n, n): ``diag(q - q0)``."""
        d = np.asarray(q, dtype=np.float64) - np.asarray(self.q0, dtype=np.float64)
        out: NDArray[np.float64] = d[..., :, None] * np.eye(len(self.q0))
        return out

    def static_columns(self, n_samples: int) -> None:
        """None: taken without the configuration (module docstring)."""
        return None

    def momentum_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(B, n, n) zeros: a spring holds no momentum."""
        return np.zeros(np.shape(dq) + (len(self.q0),))

    def friction(self, values: NDArray[np.float64]) -> None:
        """None: not friction."""
        return None

    def dissipation_rows(self, dq_max: NDArray[np.float64]) -> NDArray[np.float64]:
        """(0, p): nothing beside :attr:`nonnegative`."""
        return np.zeros((0, len(self.q0)))

    def inertia(self, values: NDArray[np.float64]) -> None:
        """None: not rotor inertias."""
        return None

    def stiffness(self, values: NDArray[np.float64]) -> JointStiffness:
        """The stiffnesses ``values`` (n,) [N m/rad] about :attr:`q0`."""
        return JointStiffness(np.asarray(values, dtype=np.float64), np.asarray(self.q0))

    def definition(self) -> dict[str, Any]:
        """``{"q0": [...]}``."""
        return {"q0": [float(x) for x in self.q0]}

    @classmethod
    def from_definition(
        cls, name: str, definition: Mapping[str, Any], drive: Drive | None, n: int
    ) -> JointSpring:
        """From :meth:`definition` (``q0`` of ``n`` joints)."""
        q0 = tuple(float(x) for x in definition["q0"])
        if len(q0) != n:
            raise ValueError(f"q0 must have {n} entries; got {len(q0)}")
        return cls(q0, name=name)
