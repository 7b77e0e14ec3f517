"""Joint friction: the one friction type and the constructors people call.

Sign convention: ``tau_f`` is the part of the measured joint torque spent on friction,

.. math:: \\tau = M(q)\\ddot q + c(q, \\dot q) + g(q) + \\tau_f(\\dot q)

so ``tau_f`` has the sign of the velocity for a dissipative joint.

Every friction model is a :class:`Friction`: a law of the registry
(:mod:`dynid.friction.laws`), its parameters per joint, a standstill band and where it acts
(the joints, or the motors of a drive: ``tau_f = K^T f(K dq)``). What differs between laws
is asked of the law, never of a class. The constructors below build the common ones (and
``isinstance(fr, SigmoidFriction)`` asks whether ``fr`` is that law at the joints):

* :func:`SigmoidFriction` (Gaz et al. 2019, eq. 25), per joint, zero at rest:

  .. math:: \\tau_f(\\dot q) = \\frac{\\varphi_1}{1 + e^{-\\varphi_2 (\\dot q + \\varphi_3)}}
            - \\frac{\\varphi_1}{1 + e^{-\\varphi_2 \\varphi_3}}

  ``phi1`` [N m] is the span between the two saturation levels, ``phi2`` [s/rad] the
  steepness, ``phi3`` [rad/s] the velocity offset of the transition.

* :func:`ClassicalFriction` (Gaz et al. 2019, eq. 24): viscous, Coulomb and offset terms,
  linear in the parameters,

  .. math:: \\tau_f(\\dot q) = f_v \\dot q + f_c \\, \\mathrm{sign}(\\dot q) + f_o

  with ``sign(0) = 0``; ``fv`` [N m s/rad], ``fc`` [N m], ``fo`` [N m]. With a standstill
  band ``b`` (n,) [rad/s] the sign is 0 where ``|dq| <= b`` (:func:`coulomb_sign`: at rest
  the measured velocity is encoder noise, whose sign must not switch Coulomb friction on).

* :func:`DriveFriction`: a friction acting at the motors of a drive.

* :class:`FrictionSum`: frictions acting together in different places (a coupled wrist
  with friction at its motors and at its joints), ``tau_f = sum_i tau_f,i``; it has no
  single law (``law`` None), so the observer evaluates it in Python.

Any other law: ``LAWS[name].model(params, band, drive)`` or ``Friction(law, params, ...)``.
All evaluate on velocities of shape ``(..., n)`` and return torques of the same shape.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.terms import FrictionValues
from .laws import LAWS
from .laws.base import Friction
from .torques import classical_friction, coulomb_sign, sigmoid_friction

__all__ = [
    "ClassicalFriction",
    "DriveFriction",
    "Friction",
    "FrictionModel",
    "FrictionSum",
    "LawFriction",
    "SigmoidFriction",
    "classical_friction",
    "combined",
    "friction_parts",
    "friction_words",
    "joint_separable",
    "through_drive",
    "coulomb_sign",
    "friction_of",
    "placed_friction",
    "own_at_motors_note",
    "robot_friction",
    "sigmoid_friction",
    "sigmoid_parameters",
]

#: A friction model (the one type; the name kept for annotations).
FrictionModel = Friction
#: The name of the one type before the constructors below returned it.
LawFriction = Friction


def _law_array(who: str, law: str, columns: dict[str, ArrayLike]) -> Friction:
    """The ``law`` with its parameter columns (each (n,)) as given by name."""
    names = tuple(columns)
    first = _checks.as_array(names[0], columns[names[0]])
    if first.ndim != 1:
        raise ShapeError(f"{who}.{names[0]} must have shape (n,); got {first.shape}")
    n = first.shape[0]
    P = np.stack([_checks.as_exact(k, v, (n,)) for k, v in columns.items()], axis=1)
    return LAWS[law].model(P)


def _from_array(law: str, params: ArrayLike, band: ArrayLike | None = None) -> Friction:
    p = _checks.as_array("params", params)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ShapeError(f"params must have shape (n, 3); got {p.shape}")
    return LAWS[law].model(p, band)


class _Sigmoid:
    """Build sigmoid friction (module docstring; Gaz et al. 2019, eq. 25)."""

    def __call__(self, phi1: ArrayLike, phi2: ArrayLike, phi3: ArrayLike) -> Friction:
        """The sigmoid law at the joints: span ``phi1`` [N m], steepness ``phi2`` [s/rad]
        and velocity offset ``phi3`` [rad/s], each (n,)."""
        return _law_array("SigmoidFriction", "sigmoid", dict(phi1=phi1, phi2=phi2, phi3=phi3))

    @staticmethod
    def from_array(params: ArrayLike) -> Friction:
        """From an (n, 3) array with columns ``phi1, phi2, phi3`` (as description files and
        the Panda's published data hold them)."""
        return _from_array("sigmoid", params)

    def __instancecheck__(self, obj: object) -> bool:
        """``isinstance(fr, SigmoidFriction)``: the sigmoid law at the joints."""
        return isinstance(obj, Friction) and obj.kind == "sigmoid" and obj.drive is None


class _Classical:
    """Build classical friction (module docstring; Gaz et al. 2019, eq. 24)."""

    def __call__(
        self, fv: ArrayLike, fc: ArrayLike, fo: ArrayLike, band: ArrayLike | None = None
    ) -> Friction:
        """The classical law at the joints: viscous ``fv`` [N m s/rad], Coulomb ``fc``
        [N m] and offset ``fo`` [N m], each (n,), and the standstill band (n,) [rad/s]
        (default 0: the plain ``sign(dq)``)."""
        fr = _law_array("ClassicalFriction", "classical", dict(fv=fv, fc=fc, fo=fo))
        return fr if band is None else LAWS["classical"].model(fr.params, band)

    @staticmethod
    def from_array(params: ArrayLike, band: ArrayLike | None = None) -> Friction:
        """From an (n, 3) array with columns ``fv, fc, fo`` and an optional standstill band
        (n,) [rad/s]."""
        return _from_array("classical", params, band)

    def __instancecheck__(self, obj: object) -> bool:
        """``isinstance(fr, ClassicalFriction)``: the classical law at the joints."""
        return isinstance(obj, Friction) and obj.kind == "classical" and obj.drive is None


class _Drive:
    """Build friction acting where a drive says (module docstring)."""

    def __call__(self, law: Friction, drive: Drive) -> Friction:
        """``law`` (per motor, in motor units: velocities [rad/s] and torques [N m] at the
        motor) acting where ``drive`` says: ``tau_f = K^T f(K dq)`` at the motors, ``f(dq)``
        with ``friction_at="joint"``.

        Raises
        ------
        ShapeError
            A drive of another number of joints.
        """
        return law.at(drive)

    def __instancecheck__(self, obj: object) -> bool:
        """``isinstance(fr, DriveFriction)``: a law with a drive."""
        return isinstance(obj, Friction) and obj.drive is not None


#: ``SigmoidFriction(phi1, phi2, phi3)`` and ``SigmoidFriction.from_array(P)``: a
#: :class:`Friction` of the sigmoid law.
SigmoidFriction = _Sigmoid()
#: ``ClassicalFriction(fv, fc, fo, band=None)`` and ``ClassicalFriction.from_array(P, band)``:
#: a :class:`Friction` of the classical law.
ClassicalFriction = _Classical()
#: ``DriveFriction(law, drive)``: the :class:`Friction` ``law`` acting where ``drive`` says.
DriveFriction = _Drive()


def friction_of(values: FrictionValues) -> Friction:
    """The friction type of a model term's identified law and parameters
    (:meth:`~dynid.regressors.terms.ModelTerm.friction`; ``IdentifiedModel.frictions``)."""
    return LAWS[values.law].model(values.params, values.band, values.drive)


@dataclass(frozen=True, slots=True, eq=False)
class FrictionSum:
    """Frictions acting together where each says (module docstring).

    Attributes
    ----------
    parts : tuple of Friction
        Two or more, of the same number of joints.

    Raises
    ------
    ShapeError
        Fewer than two parts, or parts of different numbers of joints.
    """

    parts: tuple[Friction, ...]

    def __post_init__(self) -> None:
        if len(self.parts) < 2 or len({p.n for p in self.parts}) != 1:
            raise ShapeError(
                "a friction sum needs two or more frictions of the same number of joints; got "
                + str([p.n for p in self.parts])
            )

    @property
    def law(self) -> None:
        """None: no single law (the observer evaluates :meth:`torques` in Python)."""
        return None

    @property
    def kind(self) -> str:
        """The parts' laws and places: ``"classical at the motors + classical"``."""
        return " + ".join(p.kind + (" at the motors" if p.at_motors else "") for p in self.parts)

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.parts[0].n

    @property
    def drive(self) -> Drive | None:
        """The drive of the part at the motors (None: every part acts at the joints)."""
        return next((p.drive for p in self.parts if p.at_motors), None)

    @property
    def at_motors(self) -> bool:
        """Whether a part acts at the motors of a drive."""
        return any(p.at_motors for p in self.parts)

    @property
    def names(self) -> tuple[str, ...]:
        """The parts' parameter names in order, each part's after its index
        (``fv@1, fc@1, ..., fv@2, ...``)."""
        return tuple(f"{name}@{i + 1}" for i, p in enumerate(self.parts) for name in p.names)

    def as_array(self) -> NDArray[np.float64]:
        """The parts' parameters side by side (n, k1 + k2 + ...), in the order of
        :attr:`names`."""
        return np.concatenate([p.as_array() for p in self.parts], axis=1)

    def placed(self, drive: Drive | None) -> FrictionSum:
        """A given friction sum where ``drive`` puts it: each part placed as
        :meth:`Friction.placed` places it (a part naming its own drive acts as it says)."""
        return FrictionSum(tuple(p.placed(drive) for p in self.parts))

    def torques(self, dq: ArrayLike) -> NDArray[np.float64]:
        """Joint friction torques [N m] (..., n): the sum of the parts'."""
        out = self.parts[0].torques(dq)
        for p in self.parts[1:]:
            out = out + p.torques(dq)
        return out


def friction_parts(friction: Friction | FrictionSum | None) -> tuple[Friction, ...]:
    """The frictions of a model: none, the one, or a sum's parts."""
    if friction is None:
        return ()
    return friction.parts if isinstance(friction, FrictionSum) else (friction,)


def joint_separable(friction: Friction | FrictionSum | None) -> bool:
    """Whether each joint's friction torque [N m] depends on that joint's velocity alone:
    every part a :class:`Friction` at the joints, or at the motors of a drive whose
    friction transmission ``K_f`` has no entry off its diagonal (a coupled wrist's does).
    Then a velocity moved on one joint moves that joint's friction torque only, exactly
    (the others' are computed from the same numbers)."""
    for part in friction_parts(friction):
        if not isinstance(part, Friction):
            return False
        K = part.transmission
        if np.any(K[~np.eye(K.shape[0], dtype=bool)] != 0):
            return False
    return True


#: Joint velocities [rad/s] at which :func:`friction_words` reads what a model adds: from
#: inside any standstill band to beyond any joint's speed, each sign.
_PROBE_SPEEDS = np.array([0.0, 1e-3, -1e-3, 1e-2, -1e-2, 0.1, -0.1, 1.0, -1.0, 10.0, -10.0])


def friction_words(friction: Friction | FrictionSum | None) -> str:
    """What ``friction`` adds to a model's torques, in words: ``"friction"`` (torques that
    change with the velocity), ``"offsets"`` (constant torques, the same at rest: not
    friction; an identified model with the offset term alone) or ``"friction and
    offsets"``; ``"friction"`` for None or a model that adds nothing.

    Read from its torques: the offsets are the torques at rest (every law's friction is
    zero at ``dq = 0``), the friction what changes over ``dq`` from -10 to 10 rad/s."""
    if friction is None:
        return "friction"
    v = _PROBE_SPEEDS[:, None] * np.ones(friction.n)
    tau = friction.torques(v)
    offsets = bool(np.any(tau[0] != 0))
    moves = bool(np.any(tau != tau[0]))
    if offsets and not moves:
        return "offsets"
    return "friction and offsets" if offsets else "friction"


def through_drive(
    friction: Friction | FrictionSum | None, drive: Drive
) -> Friction | FrictionSum | None:
    """``friction`` with its parts at the motors acting through ``drive`` (the same
    transmission, its rotor inertias now known); the parts at the joints as they are."""
    parts = tuple(p.at(drive) if p.at_motors else p for p in friction_parts(friction))
    if not parts:
        return None
    return parts[0] if len(parts) == 1 else FrictionSum(parts)


def combined(frictions: tuple[FrictionValues, ...]) -> Friction | FrictionSum | None:
    """The friction of a model's friction terms: None for none, the one friction type for
    one, their :class:`FrictionSum` for several."""
    if not frictions:
        return None
    if len(frictions) == 1:
        return friction_of(frictions[0])
    return FrictionSum(tuple(friction_of(f) for f in frictions))


def robot_friction(robot: Robot, drive: Drive | None = None) -> Friction | FrictionSum | None:
    """A robot's friction, ``robot.friction``, typed as the :class:`Friction` it is (the
    model layer names it by a protocol), or None.

    A robot description holds its friction per joint, without a drive: a URDF's
    ``<dynamics>``, an MJCF's ``damping`` and ``frictionloss``, a robot TOML's sigmoid per
    joint are the joints' by definition. With ``drive`` such a part stays at the joints
    unless the drive file says ``friction_at = "motor"`` itself, which moves it to the
    motors (``tau_f = K^T f(K dq)``; :func:`own_at_motors_note` says so); a geared
    drive's default place (:attr:`Drive.friction_place`) is where identification fits
    friction, not where a description's acts (an MJCF exported from a model identified
    through a gear-50..100 drive, read back with the same drive file, validated at
    6.3e5 %). A part that names its own drive (a robot TOML's ``[friction]`` table with
    ``at``) acts as it says, and so does every part of a sum that holds one: its parts
    without a drive are the joints' by placement (friction identified at the motors and at
    the joints of a coupled drive, a ``feasible.json``'s ``joint_friction``, a TOML's
    ``[joint_friction]``), not moved. This is the one place a robot's own friction is
    placed: simulation, validation, payload identification and the observer all read it
    here. Without ``drive``: as held (what a robot description file writes)."""
    own = cast(Friction | FrictionSum | None, robot.friction)
    if own is None or drive is None or drive.friction_at != "motor" or _placed(own):
        return own
    parts = tuple(p.at(drive) for p in friction_parts(own))
    return parts[0] if len(parts) == 1 else FrictionSum(parts)


def _placed(friction: Friction | FrictionSum) -> bool:
    """Whether a part of ``friction`` names its drive: each part then acts as held."""
    return any(p.drive is not None for p in friction_parts(friction))


def own_at_motors_note(robot: Robot, drive: Drive | None) -> str | None:
    """The one line when ``robot``'s own friction (a description file's: the joints' by
    definition) is read at the motors of a geared ``drive`` because the drive file says
    ``friction_at = "motor"`` itself (:meth:`~dynid.friction.laws.base.Friction.placed`):
    its coefficients are then read as the motors', the gear ratio squared apart from the
    joints' for a viscous term; None otherwise (no such friction, no such drive, or the
    default place, which leaves a description's friction at the joints). A dynid export's
    joint friction read this way validated at 6e5 % (unusable)."""
    if robot.friction is None or drive is None or drive.friction_at != "motor":
        return None
    if np.allclose(drive.transmission, np.eye(robot.n)):
        return None
    if _placed(cast(Any, robot.friction)):
        return None  # its parts record their places and hold them
    return (
        f"the robot's own friction ({robot.name}: a description's, the joints' by "
        "definition) is read at the motors because the drive file says friction_at = "
        "\"motor\": its coefficients are taken as the motors' (a joint's damping is the "
        "motor's times the gear ratio squared); without friction_at the drive leaves a "
        "description's friction at the joints, as a URDF and an MJCF (and dynid's exports) "
        "write it"
    )


def placed_friction(
    friction: FrictionModel | FrictionSum | None, drive: Drive | None
) -> FrictionModel | FrictionSum | None:
    """A friction given for a model (a ``friction.json``, a ground truth) where ``drive``
    puts it (:meth:`~dynid.friction.laws.base.Friction.placed`): a law per joint without
    a drive of its own acts per motor (``K^T f(K dq)``) when the drive's friction acts at
    the motors (:attr:`Drive.friction_place`); any other acts as it says. Simulation,
    validation and the observer read a given friction alike (a file validated through a
    geared drive read at the joints what simulation put at the motors: "unusable, 100 %"
    for the true model)."""
    return friction.placed(drive) if isinstance(friction, Friction) else friction


def sigmoid_parameters(friction: object) -> NDArray[np.float64] | None:
    """The (n, 3) parameters ``phi1, phi2, phi3`` of ``friction`` when it is the sigmoid law
    at the joints (what robot description files hold), else None (another law, a drive,
    no friction)."""
    if isinstance(friction, Friction) and friction.kind == "sigmoid" and friction.drive is None:
        return friction.as_array()
    return None
