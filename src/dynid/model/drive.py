"""Drive trains: gear ratios, coupled joints, encoder offsets, rotor inertia, motor currents.

A drive maps joint coordinates to motor coordinates through the transmission matrix ``K``
(n, n), row ``k`` for motor ``k``:

.. math:: q_m = K (q - q_0), \\qquad \\dot q_m = K \\dot q, \\qquad
          \\tau = K^T \\tau_m \\quad \\text{(power conservation)}

with ``q_0`` the encoder zero offsets [rad or m]. A diagonal ``K`` holds the gear ratios; a
coupled wrist adds off-diagonal entries (motor 6 turning with joints 5 and 6). The motors add
two terms to the rigid-body joint torques, both linear in their parameters (Khalil and Dombre,
*Modeling, Identification and Control of Robots*, ch. 9 and 12):

.. math:: \\tau_{rotor} = K^T \\mathrm{diag}(I_a) K \\ddot q, \\qquad
          \\tau_f = K^T f(K \\dot q)

``I_a`` [kg m^2] is each rotor's inertia about its axis, at the motor; ``f`` is the friction
law evaluated at the motor velocities (``friction_at="motor"``) or at the joints (``K``
replaced by the identity in ``tau_f``). The drive keeps ``friction_at`` as given (None: not
said) and resolves it in :attr:`Drive.friction_place`: the motors when ``K`` is not the
identity, else the joints. That default is where identification puts the friction it fits;
a robot description's own friction (a URDF's ``<dynamics>``, an MJCF's ``damping`` and
``frictionloss``, a robot TOML's sigmoid per joint) is the joints' by definition and moves to
the motors only when the drive says ``friction_at="motor"`` itself
(:meth:`dynid.friction.laws.base.Friction.placed`).

A log records either side (``side``) and either effort (``effort``): motor currents
``i`` [A] become torques through ``torque_constant`` (N m per A at the motor for a
motor-side log, joint torque per A for a joint-side one). :meth:`Drive.joint_log` turns any
such log into joint positions, velocities and torques; :meth:`Drive.recorded_log` is its
inverse (for simulated logs).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ModelError, OptionError, ShapeError

__all__ = ["DRIVE_SCHEMA", "Drive", "Effort", "FrictionAt", "Side"]

#: Schema key of a drive description (TOML ``schema`` and JSON records).
DRIVE_SCHEMA = "dynid-drive/1"

Side = Literal["joint", "motor"]
Effort = Literal["torque", "current"]
FrictionAt = Literal["motor", "joint"]

#: A transmission whose condition number exceeds this is refused as singular.
MAX_TRANSMISSION_CONDITION = 1e12


@dataclass(frozen=True, slots=True, eq=False)
class Drive:
    """The drive train of an arm (module docstring); arrays read-only.

    Attributes
    ----------
    transmission : ndarray, shape (n, n)
        ``K``, motor coordinates per joint coordinate (row ``k``: motor ``k``).
    offset : ndarray, shape (n,)
        Encoder zero offsets ``q_0`` [rad or m], in joint coordinates.
    side : {"joint", "motor"}
        What a log's ``q, dq, ddq, tau`` columns are.
    effort : {"torque", "current"}
        Whether a log's ``tau`` columns are torques [N m] or currents [A].
    torque_constant : ndarray, shape (n,), or None
        Torque per current [N m / A] (at the motor for ``side="motor"``); required with
        currents.
    rotor_inertia : ndarray, shape (n,), or None
        Known rotor inertias [kg m^2] at the motors, or None to identify them.
    friction_at : {"motor", "joint"} or None
        Where the friction law acts, as given; None when not given (:attr:`friction_place`
        resolves it: the motors when ``K`` is not the identity, else the joints).

    Raises
    ------
    ShapeError
        Shapes that disagree.
    ModelError
        A singular transmission, currents without torque constants, a zero torque constant
        or a negative rotor inertia.
    OptionError
        An unknown ``side``, ``effort`` or ``friction_at``.
    """

    transmission: NDArray[np.float64]
    offset: NDArray[np.float64]
    side: Side = "joint"
    effort: Effort = "torque"
    torque_constant: NDArray[np.float64] | None = None
    rotor_inertia: NDArray[np.float64] | None = None
    friction_at: FrictionAt | None = None

    def __post_init__(self) -> None:
        K = _checks.as_array("transmission", self.transmission)
        if K.ndim != 2 or K.shape[0] != K.shape[1] or K.shape[0] < 1:
            raise ShapeError(f"transmission must have shape (n, n); got {K.shape}")
        n = K.shape[0]
        cond = float(np.linalg.cond(K))
        if not cond < MAX_TRANSMISSION_CONDITION:
            raise ModelError(
                f"transmission K is singular (condition number {cond:.3g}); every motor needs "
                "a non-zero gear ratio and the coupling must leave K invertible"
            )
        off = _checks.as_exact("offset", self.offset, (n,))
        for name, value, allowed in (
            ("side", self.side, ("joint", "motor")),
            ("effort", self.effort, ("torque", "current")),
            ("friction_at", self.friction_at, ("motor", "joint", None)),
        ):
            if value not in allowed:
                raise OptionError(f"drive {name} must be one of {list(allowed)}; got {value!r}")
        kt = None
        if self.torque_constant is not None:
            kt = _checks.as_exact("torque_constant", self.torque_constant, (n,))
            if np.any(kt == 0):
                raise ModelError(f"torque_constant must be non-zero; got {kt.tolist()}")
        if self.effort == "current" and kt is None:
            raise ModelError("effort = 'current' needs torque_constant (one per joint, N m per A)")
        ia = None
        if self.rotor_inertia is not None:
            ia = _checks.as_exact("rotor_inertia", self.rotor_inertia, (n,))
            if np.any(ia < 0):
                raise ModelError(f"rotor_inertia must be >= 0 [kg m^2]; got {ia.tolist()}")
        object.__setattr__(self, "transmission", _checks.frozen(K))
        object.__setattr__(self, "offset", _checks.frozen(off))
        object.__setattr__(self, "torque_constant", None if kt is None else _checks.frozen(kt))
        object.__setattr__(self, "rotor_inertia", None if ia is None else _checks.frozen(ia))

    # ------------------------------------------------------------------ construction
    @classmethod
    def identity(cls, n: int) -> Drive:
        """A direct drive of ``n`` joints (``K = 1``, no offsets, joint-side torques)."""
        return cls(transmission=np.eye(n), offset=np.zeros(n))

    @classmethod
    def from_gears(
        cls,
        gear_ratio: ArrayLike,
        coupling: tuple[tuple[int, int, float], ...] | list[tuple[int, int, float]] = (),
        *,
        n: int | None = None,
        **kw: object,
    ) -> Drive:
        """``K = diag(gear_ratio)`` with ``coupling`` entries ``(motor, joint, value)``
        (1-based) set off the diagonal; other attributes as keywords (``offset`` defaults to
        zeros). A single ``gear_ratio`` (1: a direct drive) is every joint's, with ``n``."""
        g = _checks.as_array("gear_ratio", gear_ratio)
        if g.ndim == 0 and n is not None:
            g = np.full(int(n), float(g))
        if g.ndim != 1 or g.size < 1 or (n is not None and g.size != n):
            want = "(n,)" if n is None else f"({n},) or a single number"
            raise ShapeError(f"gear_ratio must have shape {want}; got {g.shape}")
        n = g.size
        K = np.diag(g)
        for entry in coupling:
            m, j, v = entry
            if not (1 <= int(m) <= n and 1 <= int(j) <= n):
                raise ModelError(f"coupling entry {list(entry)}: motor and joint must be in 1..{n}")
            K[int(m) - 1, int(j) - 1] = float(v)
        kw.setdefault("offset", np.zeros(n))
        return cls(transmission=K, **kw)  # type: ignore[arg-type]

    # ------------------------------------------------------------------ properties
    @property
    def n(self) -> int:
        """Number of joints (and motors)."""
        return int(self.transmission.shape[0])

    @property
    def effort_unit(self) -> str:
        """The unit of a log's ``tau`` columns: ``"A"`` for currents, else ``"N m"``."""
        return "A" if self.effort == "current" else "N m"

    @property
    def is_bare(self) -> bool:
        """True for :meth:`identity`: ``K = 1``, no offsets, joint-side torques, no torque
        constants or rotor inertias (a drive with nothing to write or to add)."""
        return self.as_dict() == Drive.identity(self.n).as_dict()

    @property
    def identifies_rotor_inertia(self) -> bool:
        """True when the rotor inertias are unknown (identified with the links)."""
        return self.rotor_inertia is None

    @property
    def friction_place(self) -> FrictionAt:
        """Where the friction law acts: ``friction_at`` when given, else the motors when
        ``K`` is not the identity and the joints when it is (module docstring)."""
        if self.friction_at is not None:
            return self.friction_at
        return "joint" if np.array_equal(self.transmission, np.eye(self.n)) else "motor"

    @property
    def friction_at_given(self) -> bool:
        """True when ``friction_at`` was given (the drive file says it), False when
        :attr:`friction_place` is the default."""
        return self.friction_at is not None

    @property
    def friction_transmission(self) -> NDArray[np.float64]:
        """The ``K`` of the friction term: the transmission, or the identity at the joints."""
        return self.transmission if self.friction_place == "motor" else np.eye(self.n)

    @property
    def is_coupled(self) -> bool:
        """True when ``K`` has off-diagonal entries."""
        return bool(self.coupled)

    @property
    def coupled(self) -> tuple[int, ...]:
        """The joints (motors; 0-based) that ``K`` couples to another: an off-diagonal
        entry in their row or column."""
        K = np.asarray(self.transmission)
        off = (K != 0.0) & ~np.eye(K.shape[0], dtype=bool)
        return tuple(int(k) for k in np.flatnonzero(off.any(axis=0) | off.any(axis=1)))

    @property
    def rotor_labels(self) -> tuple[str, ...]:
        """``Ia1 .. Ia_n``: rotor inertias [kg m^2] at the motors."""
        return tuple(f"Ia{k + 1}" for k in range(self.n))

    def check(self, n: int) -> None:
        """Raise ShapeError when the drive is for another number of joints."""
        if self.n != n:
            raise ShapeError(f"the drive has {self.n} joints; the robot has {n}")

    # ------------------------------------------------------------------ model terms
    def rotor_columns(self, ddq: NDArray[np.float64]) -> NDArray[np.float64]:
        """Regressor of the rotor inertias: (..., n) -> (..., n, n), column ``k`` the joint
        torques of ``I_a,k = 1``: ``K[k]^T (K[k] . ddq)``."""
        K = self.transmission
        return K.T * (ddq @ K.T)[..., None, :]

    def rotor_mass_columns(self) -> NDArray[np.float64]:
        """Mass-matrix contribution of each unit rotor inertia: (n, n, n), ``[k] = K[k] K[k]^T``."""
        K = self.transmission
        return np.einsum("ki,kj->kij", K, K)

    def rotor_mass_matrix(self, ia: ArrayLike) -> NDArray[np.float64]:
        """``K^T diag(I_a) K`` (n, n) [kg m^2]."""
        a = _checks.as_exact("rotor inertia", ia, (self.n,))
        K = self.transmission
        return K.T @ (a[:, None] * K)

    def rotor_torques(self, ddq: NDArray[np.float64], ia: ArrayLike) -> NDArray[np.float64]:
        """``K^T diag(I_a) K ddq`` [N m]: (..., n) -> (..., n)."""
        a = _checks.as_exact("rotor inertia", ia, (self.n,))
        K = self.transmission
        return ((ddq @ K.T) * a) @ K

    def motor_velocities(self, dq: NDArray[np.float64]) -> NDArray[np.float64]:
        """Velocities where friction acts: ``K dq`` (motor) or ``dq`` (joint); (..., n)."""
        return dq @ self.friction_transmission.T

    def joint_friction(self, f_motor: NDArray[np.float64]) -> NDArray[np.float64]:
        """Friction torques at the joints from those where the law acts: ``K^T f``."""
        return f_motor @ self.friction_transmission

    # ------------------------------------------------------------------ logs
    def joint_states(
        self, q: NDArray[np.float64], *rates: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], ...]:
        """Joint positions (and velocities, accelerations) from the logged ones: on the
        motor side ``q = K^-1 q_m + q_0``, ``dq = K^-1 dq_m``; on the joint side
        ``q = q_log + q_0``."""
        if self.side == "joint":
            return (q + self.offset, *rates)
        Kinv_T = np.linalg.inv(self.transmission).T
        return (q @ Kinv_T + self.offset, *(r @ Kinv_T for r in rates))

    def joint_torques(self, effort: NDArray[np.float64]) -> NDArray[np.float64]:
        """Joint torques [N m] from the logged efforts (currents times the torque constants,
        then ``K^T`` on the motor side)."""
        tau = effort
        if self.effort == "current" and self.torque_constant is not None:
            tau = effort * self.torque_constant
        return tau @ self.transmission if self.side == "motor" else tau

    def recorded_states(
        self, q: NDArray[np.float64], *rates: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], ...]:
        """Inverse of :meth:`joint_states`: what a log on ``side`` records."""
        if self.side == "joint":
            return (q - self.offset, *rates)
        K_T = self.transmission.T
        return ((q - self.offset) @ K_T, *(r @ K_T for r in rates))

    def recorded_efforts(self, tau: NDArray[np.float64]) -> NDArray[np.float64]:
        """Inverse of :meth:`joint_torques`: motor torques ``K^-T tau`` on the motor side,
        divided by the torque constants for currents."""
        e = np.linalg.solve(self.transmission.T, tau.T).T if self.side == "motor" else tau
        if self.effort == "current" and self.torque_constant is not None:
            e = e / self.torque_constant
        return np.asarray(e, dtype=np.float64)

    @property
    def is_identity(self) -> bool:
        """True when a log needs no conversion (joint side, torques, no offsets)."""
        return self.side == "joint" and self.effort == "torque" and not np.any(self.offset)

    # ------------------------------------------------------------------ records
    def as_dict(self) -> dict[str, object]:
        """JSON/TOML-ready record (schema ``dynid-drive/1``): ``transmission`` as rows,
        ``friction_at`` resolved (:attr:`friction_place`: where a model identified through
        the drive holds its friction)."""
        return {
            "schema": DRIVE_SCHEMA,
            "side": self.side,
            "effort": self.effort,
            "transmission": self.transmission.tolist(),
            "offset": self.offset.tolist(),
            "torque_constant": None
            if self.torque_constant is None
            else self.torque_constant.tolist(),
            "rotor_inertia": "identify"
            if self.rotor_inertia is None
            else self.rotor_inertia.tolist(),
            "friction_at": self.friction_place,
        }

    def describe(self) -> str:
        """One line: side, effort, gear ratios, coupling, rotor inertia."""
        K = self.transmission
        parts = [f"{self.side}-side {'currents' if self.effort == 'current' else 'torques'}"]
        parts.append("gear ratios " + " ".join(f"{x:g}" for x in np.diag(K)))
        off = [
            f"motor {i + 1} on joint {j + 1}: {K[i, j]:g}"
            for i, j in zip(*np.nonzero(K - np.diag(np.diag(K))), strict=True)
        ]
        if off:
            parts.append("coupling " + ", ".join(off))
        parts.append(
            "rotor inertia identified"
            if self.rotor_inertia is None
            else "rotor inertia " + " ".join(f"{x:.4g}" for x in self.rotor_inertia) + " kg m^2"
        )
        parts.append(f"friction at the {self.friction_place}s")
        return "; ".join(parts)
