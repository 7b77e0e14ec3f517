"""The dynamic model an observer runs on, from whatever model dynid produced.

:class:`ObserverModel` holds what the residual needs: a robot whose link parameters give
``M``, ``C^T dq`` and ``g`` by the recursive algorithms (the identified model's *equivalent
robot*, whose standard parameters map to the identified base parameters, or a consistent
robot's physical parameters), the constant rotor part of the mass matrix
``M_r = K^T diag(I_a) K``, the friction ``tau_f(dq)`` and, for an identified model, the base
parameters with their covariance (the model's uncertainty, :mod:`dynid.observer.detection`).

Two adapters make one: :func:`from_identified` (an
:class:`~dynid.identification.model.IdentifiedModel`, read through its public attributes
only, in this one function) and :func:`from_robot` (a consistent robot of ``feasible.json``,
a URDF, TOML or MJCF robot, with a drive's rotor inertias and a friction model).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError
from ..friction.model import FrictionModel, FrictionSum
from ..friction.validation import own_friction
from ..identification.info import LogInfo
from ..identification.model import IdentifiedModel, IdentifiedTerm
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters
from ..regressors.spring import JointSpring
from ..regressors.terms import ModelTerm

__all__ = ["ObserverModel", "from_identified", "from_robot", "term_mass"]


@dataclass(frozen=True, slots=True, eq=False)
class ObserverModel:
    """What the momentum observer evaluates (module docstring); arrays read-only.

    Attributes
    ----------
    robot : Robot
        Kinematics, gravity and the link parameters ``M``, ``C`` and ``g`` are computed from.
    rotor_mass : ndarray, shape (n, n)
        Constant part of the mass matrix [kg m^2] (rotor inertias, ``K^T diag(I_a) K``).
    friction : FrictionModel, FrictionSum or None
        ``tau_f(dq)`` [N m], the measured torque's part spent on friction (a sum: friction
        at the motors and at the joints of a coupled drive, evaluated in Python).
    base : BaseParameters or None
        The identified base parameters' map (None for a robot's own parameters).
    beta : ndarray, shape (r,), or None
        Identified base parameters.
    covariance : ndarray, shape (r, r), or None
        Their covariance (None when unknown).
    drive : Drive or None
        The drive the logs are read through (motor-side logs brought to the joints).
    base_terms : tuple of ModelTerm
        The identified model's terms in the base (a rotor inertia), in the order of their
        standard parameters after the links': each gives its momentum columns
        (:meth:`~dynid.regressors.terms.ModelTerm.momentum_columns`).
    source : str
        What the model was made from (``"identified"``, ``"robot"``), for reports.
    position_terms : tuple of (ModelTerm, ndarray)
        The identified model's terms that are neither friction nor in the base (a joint
        spring), each with its coefficients: torques of the position that the measured
        torque spends beside the links' (:meth:`position_torques`), no momentum.
    position_covariance : ndarray, shape (s, s), or None
        The covariance of those coefficients, stacked in order (``s`` of them, in their
        units): the squares of an identified model's standard deviations on the
        diagonal, 0 for a coefficient not kept (a file keeps no covariance between
        them and the base parameters: taken as uncorrelated). The residual's uncertainty
        adds it to the base parameters' (:mod:`dynid.observer.detection`); None: no
        position term, or a robot's own (no uncertainty).
    torque_delay_s : float
        How far the torques lag the positions [s] as the model was identified
        (:attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`): the logs it
        observes are prepared with it by default; 0 for a robot's own.
    logs_read : LogInfo, optional
        How the identification read its logs (``drop_invalid``, ``max_gap_s``): the logs
        it observes are read so by default; None for a robot's own.
    """

    robot: Robot
    rotor_mass: NDArray[np.float64]
    friction: FrictionModel | FrictionSum | None = None
    base: BaseParameters | None = None
    beta: NDArray[np.float64] | None = None
    covariance: NDArray[np.float64] | None = None
    drive: Drive | None = None
    source: str = "robot"
    base_terms: tuple[ModelTerm, ...] = ()
    position_terms: tuple[tuple[ModelTerm, NDArray[np.float64]], ...] = ()
    position_covariance: NDArray[np.float64] | None = None
    torque_delay_s: float = 0.0
    logs_read: LogInfo | None = None

    def __post_init__(self) -> None:
        n = self.robot.n
        Mr = _checks.as_exact("rotor_mass", self.rotor_mass, (n, n))
        object.__setattr__(self, "rotor_mass", _checks.frozen(Mr))
        if self.friction is not None and self.friction.n != n:
            raise ShapeError(f"friction model has {self.friction.n} joints; the robot has {n}")
        if self.beta is not None:
            object.__setattr__(self, "beta", _checks.frozen(np.asarray(self.beta, float)))
        if self.covariance is not None:
            object.__setattr__(self, "covariance", _checks.frozen(np.asarray(self.covariance)))
        if self.position_covariance is not None:
            s = sum(len(term.labels) for term, _ in self.position_terms)
            P = _checks.as_exact("position_covariance", self.position_covariance, (s, s))
            object.__setattr__(self, "position_covariance", _checks.frozen(P))

    @property
    def n(self) -> int:
        """Joints."""
        return self.robot.n

    def with_friction(self, friction: FrictionModel | FrictionSum | None) -> ObserverModel:
        """The same model with another friction (None: none); every other field kept (the
        torque delay and the logs' reading too, which a copy field by field dropped)."""
        return replace(self, friction=friction)

    def position_torques(self, q: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The torques (N, n) [N m] of :attr:`position_terms` at the positions ``q`` (N, n)
        [rad] (at rest), or None without such terms."""
        if not self.position_terms:
            return None
        z = np.zeros_like(q)
        return sum(
            (term.torque_columns(q, z, z) @ values for term, values in self.position_terms),
            np.zeros_like(q),
        )

    def position_columns(self, q: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The torque columns (N, n, s) of :attr:`position_terms` at the positions ``q``
        (N, n) [rad], stacked in order (``position_torques = columns @ values``), or None
        without such terms."""
        if not self.position_terms:
            return None
        z = np.zeros_like(q)
        return np.concatenate([term.torque_columns(q, z, z) for term, _ in self.position_terms], -1)

    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]:
        """``M(q)`` [kg m^2] with the rotor part: (..., n) -> (..., n, n)."""
        from ..dynamics.terms import mass_matrix

        return mass_matrix(self.robot, q) + self.rotor_mass


def from_identified(
    model: IdentifiedModel, friction: FrictionModel | FrictionSum | None | str = "model"
) -> ObserverModel:
    """The observer model of an identified model (the one adapter to its attributes).

    Parameters
    ----------
    model : IdentifiedModel
        Base parameters (through ``equivalent_robot``), the rotor inertias (the drive's
        known ones, and the terms in the base, each its own mass through its momentum
        columns: :func:`term_mass`), the identified friction, the covariance of ``fit``
        and the terms of the positions (a joint spring) with their standard deviations.
    friction : FrictionModel, None or "model"
        ``"model"`` (default): the friction identified with the model (each friction term
        where it acts: :func:`~dynid.friction.validation.own_friction`), none if it has none.

    Returns
    -------
    ObserverModel
    """
    n = model.robot.n
    Mr = np.zeros((n, n))
    if model.drive is not None and model.drive.rotor_inertia is not None:  # known ones
        Mr = model.drive.rotor_mass_matrix(model.drive.rotor_inertia)
    in_base = [t for t in model.terms.values() if t.term.in_base]
    for t in in_base:  # identified ones: each term's momentum per unit velocity
        Mr = Mr + term_mass(t.term, t.values, n)
    fr = own_friction(model) if isinstance(friction, str) else friction
    fit = model.fit
    held = [
        t for t in model.terms.values() if not t.term.in_base and t.term.friction(t.values) is None
    ]
    return ObserverModel(
        robot=model.equivalent_robot,
        rotor_mass=Mr,
        friction=fr,
        base=model.base,
        beta=np.asarray(fit.beta),
        covariance=None if fit.covariance is None else np.asarray(fit.covariance),
        drive=model.drive,
        source="identified",
        base_terms=tuple(t.term for t in in_base),
        position_terms=tuple((t.term, np.asarray(t.values, dtype=np.float64)) for t in held),
        position_covariance=None if not held else np.diag(_variances(held)),
        torque_delay_s=0.0 if model.info.log is None else float(model.info.log.torque_delay_s),
        logs_read=model.info.log,
    )


def _variances(terms: list[IdentifiedTerm]) -> NDArray[np.float64]:
    """The squared standard deviations of the terms' coefficients, stacked (0 where one is
    not kept or has none)."""
    std = np.concatenate([np.where(t.kept, t.std, 0.0) for t in terms])
    return np.square(np.nan_to_num(std, nan=0.0, posinf=0.0))


def term_mass(term: ModelTerm, values: ArrayLike, n: int) -> NDArray[np.float64]:
    """The constant mass matrix (n, n) [kg m^2] of a term of constant inertia (a rotor's
    ``K^T diag(I_a) K``) with its coefficients ``values`` (p,): its momentum columns at
    unit joint velocities, ``M[:, j] = Y_p(e_j) values``; zeros for a term without
    inertia."""
    cols = term.momentum_columns(np.zeros((n, n)), np.eye(n))  # (j, i, k)
    out: NDArray[np.float64] = (cols @ np.asarray(values, dtype=np.float64)).T
    return out


def from_robot(
    robot: Robot,
    *,
    friction: FrictionModel | FrictionSum | None | str = "robot",
    drive: Drive | None = None,
) -> ObserverModel:
    """The observer model of a robot's own link parameters (a consistent robot, a URDF).

    Parameters
    ----------
    robot : Robot
    friction : FrictionModel, None or "robot"
        ``"robot"`` (default): the robot's own friction (any law) where ``drive`` puts it
        (:func:`~dynid.friction.validation.own_friction`), none if it has none.
    drive : Drive, optional
        Its known rotor inertias add ``K^T diag(I_a) K`` to ``M``.

    Returns
    -------
    ObserverModel

    Raises
    ------
    ShapeError
        A drive or friction for another number of joints.
    """
    n = robot.n
    Mr = np.zeros((n, n))
    if drive is not None:
        drive.check(n)
        if drive.rotor_inertia is not None:
            Mr = drive.rotor_mass_matrix(drive.rotor_inertia)
    fr = own_friction(robot, drive) if isinstance(friction, str) else friction
    s = robot.spring  # the robot's joint spring: a term of the positions, as identified
    springs = () if s is None else ((JointSpring(tuple(map(float, s.q0))), np.array(s.k)),)
    return ObserverModel(
        robot=robot,
        rotor_mass=Mr,
        friction=fr,
        drive=drive,
        source="robot",
        position_terms=springs,
    )
