"""Joint friction models: the sigmoid of Gaz et al. 2019 and the classical linear model.

Sign convention: ``tau_f`` is the part of the measured joint torque spent on friction,

.. math:: \\tau = M(q)\\ddot q + c(q, \\dot q) + g(q) + \\tau_f(\\dot q)

so ``tau_f`` has the sign of the velocity for a dissipative joint.

* **Sigmoid** (Gaz et al. 2019, eq. 25), per joint, zero at rest:

  .. math:: \\tau_f(\\dot q) = \\frac{\\varphi_1}{1 + e^{-\\varphi_2 (\\dot q + \\varphi_3)}}
            - \\frac{\\varphi_1}{1 + e^{-\\varphi_2 \\varphi_3}}

  ``phi1`` [N m] is the span between the two saturation levels, ``phi2`` [s/rad] the
  steepness, ``phi3`` [rad/s] the velocity offset of the transition.

* **Classical** (Gaz et al. 2019, eq. 24): viscous, Coulomb and offset terms, linear in
  the parameters,

  .. math:: \\tau_f(\\dot q) = f_v \\dot q + f_c \\, \\mathrm{sign}(\\dot q) + f_o

  with ``sign(0) = 0``; ``fv`` [N m s/rad], ``fc`` [N m], ``fo`` [N m]. With a standstill
  band ``b`` (n,) [rad/s] the sign is 0 where ``|dq| <= b`` (:func:`coulomb_sign`: at rest
  the measured velocity is encoder noise, whose sign must not switch Coulomb friction on).

* :class:`LawFriction`: any other law of the registry (:mod:`dynid.friction.laws`) with
  its parameters per joint.

All evaluate on velocities of shape ``(..., n)`` and return torques of the same shape.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError
from ..model.drive import Drive

__all__ = [
    "ClassicalFriction",
    "DriveFriction",
    "FrictionModel",
    "Law",
    "LawFriction",
    "SigmoidFriction",
    "classical_friction",
    "coulomb_sign",
    "sigmoid_friction",
]


def coulomb_sign(dq: ArrayLike, band: ArrayLike = 0.0) -> NDArray[np.float64]:
    """``sign(dq)`` outside the standstill band, 0 inside: (..., n).

    Parameters
    ----------
    dq : array_like, shape (..., n)
        Velocities [rad/s].
    band : array_like, shape (n,) or scalar
        Standstill band per joint [rad/s]; 0 gives the plain ``sign(dq)`` (``sign(0) = 0``).

    Returns
    -------
    ndarray, shape (..., n)
    """
    v = np.asarray(dq, dtype=np.float64)
    out: NDArray[np.float64] = np.where(
        np.abs(v) > np.asarray(band, dtype=np.float64), np.sign(v), 0.0
    )
    return out


def sigmoid_friction(
    dq: ArrayLike, phi1: ArrayLike, phi2: ArrayLike, phi3: ArrayLike
) -> NDArray[np.float64]:
    """Sigmoid friction torques (Gaz et al. 2019, eq. 25).

    Parameters
    ----------
    dq : array_like, shape (..., n)
        Joint velocities [rad/s].
    phi1, phi2, phi3 : array_like, shape (n,)
        Span [N m], steepness [s/rad] and velocity offset [rad/s] per joint (broadcast
        against ``dq``).

    Returns
    -------
    tau_f : ndarray, shape (..., n)
        Friction torques [N m], zero at ``dq = 0``.
    """
    from scipy.special import expit  # here: importing scipy.special costs 0.15 s

    dq = _checks.as_array("dq", dq)
    phi1, phi2, phi3 = (np.asarray(p, dtype=np.float64) for p in (phi1, phi2, phi3))
    return phi1 * (expit(phi2 * (dq + phi3)) - expit(phi2 * phi3))


def classical_friction(
    dq: ArrayLike, fv: ArrayLike, fc: ArrayLike, fo: ArrayLike, band: ArrayLike = 0.0
) -> NDArray[np.float64]:
    """Viscous + Coulomb + offset friction torques (Gaz et al. 2019, eq. 24).

    Parameters
    ----------
    dq : array_like, shape (..., n)
        Joint velocities [rad/s].
    fv, fc, fo : array_like, shape (n,)
        Viscous [N m s/rad], Coulomb [N m] and offset [N m] coefficients.
    band : array_like, shape (n,) or scalar
        Standstill band [rad/s] of the Coulomb term (:func:`coulomb_sign`); default 0.

    Returns
    -------
    tau_f : ndarray, shape (..., n)
        ``fv dq + fc sign(dq) + fo`` [N m].
    """
    dq = _checks.as_array("dq", dq)
    fv, fc, fo = (np.asarray(p, dtype=np.float64) for p in (fv, fc, fo))
    return fv * dq + fc * coulomb_sign(dq, band) + fo


def _params(cls_name: str, names: tuple[str, ...], obj: object) -> int:
    first = _checks.as_array(names[0], getattr(obj, names[0]))
    if first.ndim != 1:
        raise ShapeError(f"{cls_name}.{names[0]} must have shape (n,); got {first.shape}")
    n = first.shape[0]
    for k in names:
        object.__setattr__(obj, k, _checks.frozen(_checks.as_exact(k, getattr(obj, k), (n,))))
    return n


@dataclass(frozen=True, slots=True, eq=False)
class SigmoidFriction:
    """Sigmoid friction parameters per joint (Gaz et al. 2019, eq. 25); arrays read-only.

    Attributes
    ----------
    phi1 : ndarray, shape (n,)
        Span [N m].
    phi2 : ndarray, shape (n,)
        Steepness [s/rad].
    phi3 : ndarray, shape (n,)
        Velocity offset [rad/s].
    """

    phi1: NDArray[np.float64]
    phi2: NDArray[np.float64]
    phi3: NDArray[np.float64]

    kind: ClassVar[str] = "sigmoid"
    names: ClassVar[tuple[str, ...]] = ("phi1", "phi2", "phi3")

    def __post_init__(self) -> None:
        _params("SigmoidFriction", self.names, self)

    @classmethod
    def from_array(cls, params: ArrayLike) -> SigmoidFriction:
        """From an (n, 3) array with columns ``phi1, phi2, phi3`` (as ``Robot.friction``)."""
        p = _checks.as_array("params", params)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ShapeError(f"params must have shape (n, 3); got {p.shape}")
        return cls(p[:, 0], p[:, 1], p[:, 2])

    def as_array(self) -> NDArray[np.float64]:
        """The parameters as an (n, 3) array, columns ``phi1, phi2, phi3``."""
        return np.stack([self.phi1, self.phi2, self.phi3], axis=1)

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.phi1.shape[0]

    def torques(self, dq: ArrayLike) -> NDArray[np.float64]:
        """Friction torques [N m] (..., n) at velocities ``dq`` [rad/s] (..., n)."""
        dq = _checks.as_batch("dq", dq, (self.n,))
        return sigmoid_friction(dq, self.phi1, self.phi2, self.phi3)


@dataclass(frozen=True, slots=True, eq=False)
class ClassicalFriction:
    """Viscous, Coulomb and offset friction per joint (Gaz et al. 2019, eq. 24).

    Attributes
    ----------
    fv : ndarray, shape (n,)
        Viscous coefficients [N m s/rad].
    fc : ndarray, shape (n,)
        Coulomb coefficients [N m].
    fo : ndarray, shape (n,)
        Offsets [N m].
    band : ndarray, shape (n,)
        Standstill band of the Coulomb term [rad/s] (:func:`coulomb_sign`); zeros (the
        plain ``sign(dq)``) when not given.
    """

    fv: NDArray[np.float64]
    fc: NDArray[np.float64]
    fo: NDArray[np.float64]
    band: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    kind: ClassVar[str] = "classical"
    names: ClassVar[tuple[str, ...]] = ("fv", "fc", "fo")

    def __post_init__(self) -> None:
        n = _params("ClassicalFriction", self.names, self)
        b = np.zeros(n) if np.size(self.band) == 0 else _checks.as_exact("band", self.band, (n,))
        object.__setattr__(self, "band", _checks.frozen(b))

    @classmethod
    def from_array(cls, params: ArrayLike, band: ArrayLike | None = None) -> ClassicalFriction:
        """From an (n, 3) array with columns ``fv, fc, fo`` (as ``IdentifiedModel.friction``)
        and an optional standstill band (n,) [rad/s]."""
        p = _checks.as_array("params", params)
        if p.ndim != 2 or p.shape[1] != 3:
            raise ShapeError(f"params must have shape (n, 3); got {p.shape}")
        if band is None:
            return cls(p[:, 0], p[:, 1], p[:, 2])
        return cls(p[:, 0], p[:, 1], p[:, 2], np.asarray(band, dtype=np.float64))

    def as_array(self) -> NDArray[np.float64]:
        """The parameters as an (n, 3) array, columns ``fv, fc, fo``."""
        return np.stack([self.fv, self.fc, self.fo], axis=1)

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.fv.shape[0]

    def torques(self, dq: ArrayLike) -> NDArray[np.float64]:
        """Friction torques [N m] (..., n) at velocities ``dq`` [rad/s] (..., n)."""
        dq = _checks.as_batch("dq", dq, (self.n,))
        return classical_friction(dq, self.fv, self.fc, self.fo, self.band)


class Law(Protocol):
    """What a :class:`LawFriction` reads of its law, a
    :class:`~dynid.friction.laws.base.FrictionLaw` (named here by its shape, so that this
    module imports nothing of the laws, which import it)."""

    @property
    def name(self) -> str:
        """The law's registry name."""
        ...

    @property
    def params(self) -> tuple[str, ...]:
        """Its parameter names."""
        ...

    @property
    def torques(self) -> Callable[..., Any]:
        """``torques(dq, params, band)``: friction torques [N m]."""
        ...


@dataclass(frozen=True, slots=True, eq=False)
class LawFriction:
    """A registry law with parameters per joint; arrays read-only.

    Attributes
    ----------
    law : FrictionLaw
        The registry law (:class:`Law` is what is read of it).
    params : ndarray, shape (n, k)
        Parameters per joint, columns ``law.params``.
    band : ndarray, shape (n,)
        Standstill band [rad/s] (:func:`coulomb_sign`); zeros when not given.
    """

    law: Law
    params: NDArray[np.float64]
    band: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        p = _checks.as_array("params", self.params)
        k = len(self.law.params)
        if p.ndim != 2 or p.shape[1] != k:
            raise ShapeError(
                f"params of the {self.law.name} law must have shape (n, {k}); got {p.shape}"
            )
        n = p.shape[0]
        b = np.zeros(n) if np.size(self.band) == 0 else _checks.as_exact("band", self.band, (n,))
        object.__setattr__(self, "params", _checks.frozen(p))
        object.__setattr__(self, "band", _checks.frozen(b))

    @property
    def kind(self) -> str:
        """The law's registry name."""
        return self.law.name

    @property
    def names(self) -> tuple[str, ...]:
        """The parameter names."""
        return self.law.params

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.params.shape[0])

    def as_array(self) -> NDArray[np.float64]:
        """The parameters (n, k)."""
        return np.array(self.params)

    def torques(self, dq: ArrayLike) -> NDArray[np.float64]:
        """Friction torques [N m] (..., n) at velocities ``dq`` [rad/s] (..., n)."""
        v = _checks.as_batch("dq", dq, (self.n,))
        out: NDArray[np.float64] = np.asarray(self.law.torques(v, self.params, self.band))
        return out


@dataclass(frozen=True, slots=True, eq=False)
class DriveFriction:
    """A friction law acting at the motors of a drive: ``tau_f = K^T f(K dq)``.

    Attributes
    ----------
    law : SigmoidFriction, ClassicalFriction or LawFriction
        The law per motor, in motor units (velocities [rad/s] and torques [N m] at the
        motor).
    drive : Drive
        The transmission ``K`` (:mod:`dynid.model.drive`); with ``friction_at="joint"`` the
        law acts at the joints.
    """

    law: SigmoidFriction | ClassicalFriction | LawFriction
    drive: Drive

    def __post_init__(self) -> None:
        self.drive.check(self.law.n)

    @property
    def kind(self) -> str:
        """The law's registry name (:mod:`dynid.friction.laws`)."""
        return self.law.kind

    @property
    def names(self) -> tuple[str, ...]:
        """The law's parameter names."""
        return self.law.names

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.law.n

    def as_array(self) -> NDArray[np.float64]:
        """The law's parameters (n, k), per motor."""
        return self.law.as_array()

    def torques(self, dq: ArrayLike) -> NDArray[np.float64]:
        """Joint friction torques [N m] (..., n) at joint velocities ``dq`` (..., n)."""
        v = _checks.as_batch("dq", dq, (self.n,))
        return self.drive.joint_friction(self.law.torques(self.drive.motor_velocities(v)))


#: A friction model; each has ``kind``, ``names``, ``n``, ``torques(dq)`` and ``as_array()``.
FrictionModel = SigmoidFriction | ClassicalFriction | LawFriction | DriveFriction
