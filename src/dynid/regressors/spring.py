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

__all__ = ["SPRING_LABEL", "JointSpring", "spring_mask"]

#: The label of a joint's stiffness: ``k2``.
SPRING_LABEL = "k"


def spring_mask(drop: tuple[str, ...], n: int) -> tuple[bool, ...]:
    """Which of ``n`` joints hold a spring: all but those whose stiffness label
    (``k3``, 1-based) ``drop`` names; empty when every one does."""
    held = tuple(f"{SPRING_LABEL}{j + 1}" not in drop for j in range(n))
    return () if all(held) else held


@dataclass(frozen=True, slots=True, eq=False)
class JointSpring:
    """A spring ``k_j (q_j - q0_j)`` at every joint (module docstring).

    Attributes
    ----------
    q0 : tuple of float
        The rest position [rad] (or [m] for a prismatic joint) per joint.
    name : str
        The term's name in the model (``"spring"``).
    mask : tuple of bool
        Which joints hold a spring (empty: every one); a joint without has no column and a
        stiffness of 0.
    """

    q0: tuple[float, ...]
    name: str = "spring"
    in_base: bool = False
    kind: str = "joint_spring"
    mask: tuple[bool, ...] = ()

    def __post_init__(self) -> None:
        if self.mask and len(self.mask) != len(self.q0):
            raise ValueError(f"mask must have {len(self.q0)} entries; got {len(self.mask)}")
        if all(self.mask):  # every joint: the plain term
            object.__setattr__(self, "mask", ())

    @property
    def held(self) -> NDArray[np.bool_]:
        """(n,): the joints holding a spring (:attr:`mask`, or all)."""
        return np.asarray(self.mask, dtype=bool) if self.mask else np.ones(len(self.q0), bool)

    @property
    def labels(self) -> tuple[str, ...]:
        """``k1 .. k_n`` (those of :attr:`mask`)."""
        return tuple(f"{SPRING_LABEL}{j + 1}" for j in np.flatnonzero(self.held))

    @property
    def units(self) -> tuple[str, ...]:
        """N m/rad each."""
        return ("N m/rad",) * len(self.labels)

    @property
    def nonnegative(self) -> NDArray[np.bool_]:
        """Every stiffness is ``>= 0`` (a spring stores energy)."""
        return np.ones(len(self.labels), dtype=bool)

    def torque_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(B, n, p): ``diag(q - q0)``, the columns of the joints held."""
        d = np.asarray(q, dtype=np.float64) - np.asarray(self.q0, dtype=np.float64)
        out: NDArray[np.float64] = d[..., :, None] * np.eye(len(self.q0))[:, self.held]
        return out

    def static_columns(self, n_samples: int) -> None:
        """None: taken without the configuration (module docstring)."""
        return None

    def momentum_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(B, n, p) zeros: a spring holds no momentum."""
        return np.zeros(np.shape(dq) + (len(self.labels),))

    def friction(self, values: NDArray[np.float64]) -> None:
        """None: not friction."""
        return None

    def dissipation_rows(self, dq_max: NDArray[np.float64]) -> NDArray[np.float64]:
        """(0, p): nothing beside :attr:`nonnegative`."""
        return np.zeros((0, len(self.labels)))

    def inertia(self, values: NDArray[np.float64]) -> None:
        """None: not rotor inertias."""
        return None

    def stiffness(self, values: NDArray[np.float64]) -> JointStiffness:
        """The stiffnesses ``values`` (p,) [N m/rad] of the joints held about :attr:`q0`
        (n,), 0 on the others."""
        k = np.zeros(len(self.q0))
        k[self.held] = np.asarray(values, dtype=np.float64)
        return JointStiffness(k, np.asarray(self.q0))

    def definition(self) -> dict[str, Any]:
        """``{"q0": [...]}`` (and ``"mask"`` when not every joint holds one)."""
        return {"q0": [float(x) for x in self.q0]} | (
            {"mask": list(self.mask)} if self.mask else {}
        )

    @classmethod
    def from_definition(
        cls, name: str, definition: Mapping[str, Any], drive: Drive | None, n: int
    ) -> JointSpring:
        """From :meth:`definition` (``q0`` of ``n`` joints)."""
        q0 = tuple(float(x) for x in definition["q0"])
        if len(q0) != n:
            raise ValueError(f"q0 must have {n} entries; got {len(q0)}")
        mask = tuple(bool(x) for x in definition.get("mask", ()))
        return cls(q0, name=name, mask=mask)
