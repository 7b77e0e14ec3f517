"""The immutable serial-chain robot model.

A :class:`Robot` is a chain of ``n`` revolute or prismatic joints. Joint ``i`` (1-based)
connects link ``i-1`` to link ``i``; link 0 is the fixed base. The pose of link ``i`` in
link ``i-1`` is

.. math:: T_{i-1,i}(q_i) = T^{fix}_i \\; \\mathrm{Motion}(a_i, q_i)

where ``T_parent_joint[i-1]`` is the fixed transform :math:`T^{fix}_i` and ``axes[i-1]``
the unit joint axis :math:`a_i` in link-``i`` coordinates; the motion is a rotation about
``a_i`` by ``q_i`` [rad] or a translation along it by ``q_i`` [m]. Modified DH (Craig) is
the special case ``T_fix = RotX(alpha) TransX(a) RotZ(theta_0) TransZ(d)``, ``a_i = z``.

Inertial parameters are held as the standard parameters ``phi`` (``(n, 10)``, see
:mod:`dynid.model.inertia`): about the link origin, in link axes. Gravity is a vector in
the base frame [m/s^2], by default ``(0, 0, -9.80665)``. Named frames are fixed to links
(``robot.frames``); every link name is a frame, and ``flange`` is the mounting frame.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ModelError, ShapeError, UnknownNameError, WrongTypeError
from .inertia import inertial_from_phi, param_labels, phi_from_inertial
from .stiffness import JointStiffness

__all__ = ["Frame", "MAX_LINK_MASS", "MAX_LINK_OFFSET", "Robot", "STANDARD_GRAVITY"]

#: Standard acceleration of gravity [m/s^2] (CGPM 1901, ISO 80000-3), used by Gaz et al. 2019.
STANDARD_GRAVITY = 9.80665
#: Largest link mass [kg] the robot readers (TOML, URDF) accept: a thousand tonnes, far
#: above any manipulator; a mass of 1e12 kg is a typing error, and the identification's
#: scaling (and the retrieval's bounds) would lose its other links to rounding.
MAX_LINK_MASS = 1e6
#: Largest offset [m] of a joint from its parent link's frame, or of a named frame from its
#: link: ten kilometres, far above any manipulator or gantry; at 1e200 m the inertia
#: matrix overflows and every command failed on a NaN far from the cause.
MAX_LINK_OFFSET = 1e4


@dataclass(frozen=True, slots=True, eq=False)
class Frame:
    """A frame rigidly attached to a link.

    Attributes
    ----------
    link : int
        Index of the link that carries the frame (0 = base, ``i`` = link ``i``).
    T_link_frame : ndarray, shape (4, 4)
        Pose of the frame in the link frame [m].
    joint : str, optional
        The name of the fixed joint that attaches it in the robot's source (a URDF), kept
        so that an export names that joint as the source did; None: a frame of its own.
    """

    link: int
    T_link_frame: NDArray[np.float64]
    joint: str | None = None


def _fixed_frames(frames: Mapping[str, Frame]) -> Mapping[str, Frame]:
    out = {}
    for k, f in frames.items():
        T = _checks.as_exact(f"frames[{k!r}].T_link_frame", f.T_link_frame, (4, 4))
        joint = None if f.joint is None else str(f.joint)
        out[str(k)] = Frame(int(f.link), _checks.frozen(T), joint)
    _check_names("joint", [f.joint for f in out.values() if f.joint is not None])
    return _checks.frozen_mapping(out)


def _check_names(kind: str, names: Sequence[str]) -> None:
    """Refuse a name holding a control character other than a tab (NUL, a line break, ...)
    or half of a surrogate pair: URDF and MJCF cannot hold it (a NUL made the export
    unparseable), and it would break the one-line messages and CSV headers naming it."""
    for name in names:
        bad = _checks.control_character(str(name))
        if bad is not None:
            raise ModelError(
                f"{kind} name {_checks.short(str(name))} holds the character "
                f"{ascii(bad)}; give a name without control characters"
            )


def _check_offsets(kind: str, names: Sequence[str], T: NDArray[np.float64]) -> None:
    """Refuse a joint or frame placed beyond :data:`MAX_LINK_OFFSET` from its link."""
    if len(names) == 0:
        return
    far = np.max(np.abs(np.asarray(T)[:, :3, 3]), axis=1)
    bad = np.flatnonzero(~(far <= MAX_LINK_OFFSET))
    if bad.size:
        k = int(bad[0])
        raise ModelError(
            f"{kind} {_checks.short(str(names[k]))} lies {far[k]:.3g} m from its link's frame; "
            f"at most {MAX_LINK_OFFSET:g} m (lengths are in metres)"
        )


def _check_link_frames(links: Mapping[str, Frame], frames: Mapping[str, Frame]) -> None:
    """Refuse a named frame that has a link's name but another place: it would replace the
    link's own frame silently (``fk --frame l1`` then gave another link's pose). ``flange``
    is the mounting frame whatever link bears the name (the URDF reader warns)."""
    for k, f in frames.items():
        own = None if str(k) == "flange" else links.get(str(k))
        if own is not None and not (
            int(f.link) == own.link and np.array_equal(np.asarray(f.T_link_frame), np.eye(4))
        ):
            raise ModelError(
                f"frame {str(k)!r} has the name of a link but another pose (on link "
                f"{int(f.link)}); every link is a frame already: give the frame another name"
            )


def _restore_robot(state: dict[str, Any]) -> Robot:
    """The robot of :meth:`Robot.__reduce__`'s ``state`` (arrays frozen again)."""
    robot = object.__new__(Robot)
    for k, v in state.items():
        if k == "frames":
            v = _fixed_frames(v)
        elif isinstance(v, np.ndarray):
            v = _checks.frozen(v)
        object.__setattr__(robot, k, v)
    return robot


@runtime_checkable
class FrictionLike(Protocol):
    """What a robot reads of the friction it holds: the one friction type,
    :class:`~dynid.friction.model.Friction`, of a later layer (this layer cannot name it)."""

    @property
    def n(self) -> int:
        """Number of joints."""
        ...

    @property
    def kind(self) -> str:
        """The law's registry name."""
        ...

    @property
    def drive(self) -> Any:
        """Where the law acts (None: the joints)."""
        ...

    def as_array(self) -> NDArray[np.float64]:
        """The parameters (n, k)."""
        ...

    def torques(self, dq: ArrayLike) -> NDArray[np.float64]:
        """Joint friction torques [N m] (..., n) at joint velocities (..., n) [rad/s]."""
        ...


def _check_friction(friction: object, n: int) -> None:
    """Refuse what is not a friction model of ``n`` joints: a bare array says no law (it was
    once read as sigmoid parameters), so it is refused with the constructor to call."""
    if not isinstance(friction, FrictionLike):
        what = (
            f"an array of shape {np.shape(friction)}"
            if isinstance(friction, np.ndarray | list | tuple)
            else f"a {type(friction).__name__}"
        )
        raise WrongTypeError(
            f"a robot's friction must be a Friction (dynid.Friction, of any law), not {what}; "
            "sigmoid parameters (n, 3) make one with dynid.SigmoidFriction.from_array(P)"
        )
    if friction.n != n:
        raise ShapeError(f"friction has {friction.n} joints; robot has {n}")


@dataclass(frozen=True, slots=True, eq=False, weakref_slot=True)
class Robot:
    """Immutable serial-chain robot: kinematics, inertial parameters, limits, friction.

    Build it with :func:`dynid.panda`, :meth:`from_mdh`, :meth:`from_urdf` or
    :meth:`from_toml`; derive variants with :meth:`with_params`, :meth:`with_tool`,
    :meth:`with_friction`, :meth:`with_gravity`. Arrays are read-only.

    Attributes
    ----------
    name : str
    joint_names : tuple of str, length n
    link_names : tuple of str, length n + 1 (``link_names[0]`` is the base)
    T_parent_joint : ndarray, shape (n, 4, 4)
        Fixed pose of joint frame ``i`` (at ``q_i = 0``) in link ``i-1`` [m].
    axes : ndarray, shape (n, 3)
        Unit joint axes in link coordinates.
    prismatic : ndarray of bool, shape (n,)
    phi : ndarray, shape (n, 10)
        Standard parameters per link (m, m c, J about the link origin) [SI].
    q_min, q_max : ndarray, shape (n,)
        Position limits [rad or m]; ``-inf``/``inf`` where none.
    dq_max, ddq_max, tau_max : ndarray, shape (n,)
        Velocity [rad/s], acceleration [rad/s^2] and torque [N m] limits; ``inf`` where none.
    gravity : ndarray, shape (3,)
        Gravity acceleration in the base frame [m/s^2].
    frames : mapping of str to Frame
        Named frames; includes every link name and ``flange``.
    friction : Friction or None
        The robot's friction: a :class:`~dynid.friction.model.Friction` (a law of the
        registry, its parameters, standstill band and where it acts), None for none. The
        Panda's is the sigmoid of Gaz et al. 2019 (eq. 25); sigmoid parameters ``(n, 3)``
        (``phi1 [N m], phi2 [s/rad], phi3 [rad/s]``, as description files hold them) make
        one with ``dynid.SigmoidFriction.from_array(P)``; a bare array is refused.
    q_neutral : ndarray, shape (n,), or None
        A documented neutral pose (start of IK, demos); None: the middle of the limits.
    spring : JointStiffness or None
        A linear spring at every joint, ``tau_s = k (q - q0)`` (the torque the motors supply
        against it [N m], added to the rigid-body torques like friction:
        :class:`~dynid.model.stiffness.JointStiffness`); None for none. An identified
        spring term carried by a consistent fit (``feasible.json``, a TOML ``[spring]``).

    Raises
    ------
    ModelError
        Among others: a zero or overflowing axis, limits out of order, a joint or frame
        farther than :data:`MAX_LINK_OFFSET` from its link, a name with a control character.
    """

    name: str
    joint_names: tuple[str, ...]
    link_names: tuple[str, ...]
    T_parent_joint: NDArray[np.float64]
    axes: NDArray[np.float64]
    prismatic: NDArray[np.bool_]
    phi: NDArray[np.float64]
    q_min: NDArray[np.float64]
    q_max: NDArray[np.float64]
    dq_max: NDArray[np.float64]
    ddq_max: NDArray[np.float64]
    tau_max: NDArray[np.float64]
    gravity: NDArray[np.float64] = field(
        default_factory=lambda: np.array([0.0, 0.0, -STANDARD_GRAVITY])
    )
    frames: Mapping[str, Frame] = field(default_factory=dict)
    friction: FrictionLike | None = None
    q_neutral: NDArray[np.float64] | None = None
    spring: JointStiffness | None = None

    def __post_init__(self) -> None:
        n = len(self.joint_names)
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 (frozen init)
        if n < 1:
            raise ModelError("a robot needs at least one joint")
        if len(self.link_names) != n + 1:
            raise ModelError(
                f"link_names must have n + 1 = {n + 1} entries (base first); "
                f"got {len(self.link_names)}"
            )
        for kind, names in (("joint", self.joint_names), ("link", self.link_names)):
            dup = sorted({x for x in names if list(names).count(x) > 1})
            if dup:
                raise ModelError(f"duplicate {kind} names: {dup}")
        put("joint_names", tuple(str(x) for x in self.joint_names))
        put("link_names", tuple(str(x) for x in self.link_names))
        put(
            "T_parent_joint",
            _checks.frozen(_checks.as_exact("T_parent_joint", self.T_parent_joint, (n, 4, 4))),
        )
        _check_offsets("joint", self.joint_names, self.T_parent_joint)
        axes = _checks.as_exact("axes", self.axes, (n, 3))
        with np.errstate(over="ignore"):
            norm = np.linalg.norm(axes, axis=1)
        if np.any(norm < 1e-9):
            raise ModelError(f"joint axis of {self.joint_names[int(np.argmin(norm))]} is zero")
        if not np.all(np.isfinite(norm)):  # [0, 0, 1e300]: the norm overflows, axis / inf = 0
            j = int(np.argmax(~np.isfinite(norm)))
            raise ModelError(
                f"joint axis of {self.joint_names[j]}, {axes[j].tolist()}, is too large to "
                "normalise (its squared length overflows a float); give the axis as a unit vector"
            )
        put("axes", _checks.frozen(axes / norm[:, None]))
        pri = np.asarray(self.prismatic, dtype=bool)
        if pri.shape != (n,):
            raise ShapeError(f"prismatic must have shape ({n},); got {pri.shape}")
        put("prismatic", _checks.frozen(pri))
        put("phi", _checks.frozen(_checks.as_exact("phi", self.phi, (n, 10))))
        for k in ("q_min", "q_max", "dq_max", "ddq_max", "tau_max"):
            v = _checks.as_exact(k, getattr(self, k), (n,), allow_nonfinite=True)
            if np.any(np.isnan(v)):
                raise ModelError(f"{k} holds NaN at joint {int(np.argmax(np.isnan(v))) + 1}")
            put(k, _checks.frozen(v))
        bad = np.flatnonzero(~(self.q_min < self.q_max))
        if bad.size:
            j = int(bad[0])
            raise ModelError(
                f"lower position limit must be below the upper one; joint {self.joint_names[j]}: "
                f"{self.q_min[j]} >= {self.q_max[j]}"
            )
        for k in ("dq_max", "ddq_max", "tau_max"):
            bad = np.flatnonzero(getattr(self, k) <= 0)
            if bad.size:
                j = int(bad[0])
                raise ModelError(
                    f"{k} must be positive; joint {self.joint_names[j]}: {getattr(self, k)[j]}"
                )
        put("gravity", _checks.frozen(_checks.as_exact("gravity", self.gravity, (3,))))
        frames = {name: Frame(i, np.eye(4)) for i, name in enumerate(self.link_names)}
        _check_link_frames(frames, self.frames)
        frames.update(self.frames)
        frames.setdefault("flange", Frame(n, np.eye(4)))
        _check_names("robot", [self.name])
        _check_names("joint", self.joint_names)
        _check_names("frame", list(frames))
        for k, f in frames.items():
            if not 0 <= int(f.link) <= n:
                raise ModelError(f"frame {k!r} is attached to link {f.link}, not in 0..{n}")
        put("frames", _fixed_frames(frames))
        _check_offsets(
            "frame", list(self.frames), np.array([f.T_link_frame for f in self.frames.values()])
        )
        if self.friction is not None:
            _check_friction(self.friction, n)
        if self.q_neutral is not None:
            qn = _checks.as_exact("q_neutral", self.q_neutral, (n,))
            if np.any((qn < self.q_min) | (qn > self.q_max)):
                raise ModelError("q_neutral must lie within the position limits")
            put("q_neutral", _checks.frozen(qn))
        if self.spring is not None:
            if not isinstance(self.spring, JointStiffness):
                raise WrongTypeError(
                    f"a robot's spring must be a JointStiffness; got {type(self.spring).__name__}"
                )
            if self.spring.n != n:
                raise ShapeError(f"spring has {self.spring.n} joints; robot has {n}")

    # ------------------------------------------------------------------ properties
    @property
    def n(self) -> int:
        """Number of joints (degrees of freedom)."""
        return len(self.joint_names)

    @property
    def param_labels(self) -> tuple[str, ...]:
        """Labels of the flattened standard parameters ``phi.reshape(-1)``."""
        return param_labels(self.n)

    @property
    def mass(self) -> NDArray[np.float64]:
        """Link masses [kg], shape (n,)."""
        return inertial_from_phi(self.phi)[0]

    @property
    def com(self) -> NDArray[np.float64]:
        """Centres of mass in the link frames [m], shape (n, 3)."""
        return inertial_from_phi(self.phi)[1]

    @property
    def inertia(self) -> NDArray[np.float64]:
        """Inertia tensors about the CoM, link axes [kg m^2], shape (n, 3, 3)."""
        return inertial_from_phi(self.phi)[2]

    def frame(self, name: str) -> Frame:
        """The named frame; raises :class:`UnknownNameError` listing the available ones,
        :class:`WrongTypeError` for anything but a name (a list of names: one call each)."""
        if not isinstance(name, str):
            raise _checks.wrong_type("frame", name, "a frame's name (str; one call a frame)")
        try:
            return self.frames[name]
        except (KeyError, TypeError):  # TypeError: not a name (unhashable)
            raise UnknownNameError(
                f"Unknown frame {name!r}; available: {sorted(self.frames)}"
            ) from None

    def joint_index(self, name: str) -> int:
        """0-based index of a joint by name."""
        try:
            return self.joint_names.index(name)
        except ValueError:
            raise UnknownNameError(
                f"Unknown joint {name!r}; available: {list(self.joint_names)}"
            ) from None

    # ------------------------------------------------------------------ variants
    def replace(self, **changes: Any) -> Robot:
        """A copy with some fields changed (``dataclasses.replace``), validated again."""
        return dataclasses.replace(self, **changes)

    def with_params(self, phi: ArrayLike) -> Robot:
        """A copy with standard parameters ``phi``, shape (n, 10) or (10 n,)."""
        p = _checks.as_array("phi", phi)
        if p.shape == (self.n * 10,):
            p = p.reshape(self.n, 10)
        return self.replace(phi=p)

    def with_inertials(self, mass: ArrayLike, com: ArrayLike, inertia: ArrayLike) -> Robot:
        """A copy with masses [kg] (n,), CoMs [m] (n, 3), CoM inertias (n, 3, 3) or (n, 6)."""
        return self.replace(phi=phi_from_inertial(mass, com, inertia))

    def with_friction(self, friction: FrictionLike | None) -> Robot:
        """A copy with ``friction``: a :class:`~dynid.friction.model.Friction` of any law,
        standstill band and drive, or None (sigmoid parameters (n, 3):
        ``dynid.SigmoidFriction.from_array(P)``)."""
        return self.replace(friction=friction)

    def with_spring(self, spring: JointStiffness | None) -> Robot:
        """A copy with a spring at every joint (:attr:`spring`), or None."""
        return self.replace(spring=spring)

    def with_gravity(self, gravity: ArrayLike) -> Robot:
        """A copy with the gravity vector (3,) [m/s^2] in the base frame."""
        return self.replace(gravity=gravity)

    def with_frame(self, name: str, T_parent_frame: ArrayLike, parent: str = "flange") -> Robot:
        """A copy with a new frame ``name`` fixed at ``T_parent_frame`` in frame ``parent``."""
        T = _checks.as_exact("T_parent_frame", T_parent_frame, (4, 4))
        f = self.frame(parent)
        frames = dict(self.frames)
        frames[name] = Frame(f.link, f.T_link_frame @ T)
        return self.replace(frames=frames)

    def with_tool(
        self,
        T_flange_tool: ArrayLike,
        mass: float = 0.0,
        com: ArrayLike = (0.0, 0.0, 0.0),
        inertia: ArrayLike | None = None,
        *,
        parent: str = "flange",
        name: str = "tool",
    ) -> Robot:
        """A copy with a tool rigidly fixed to frame ``parent``.

        Adds frame ``name`` at ``T_flange_tool`` and adds the tool's inertia to the
        carrying link.

        Parameters
        ----------
        T_flange_tool : array_like, shape (4, 4)
            Pose of the tool frame in the ``parent`` frame [m].
        mass : float
            Tool mass [kg] (0: kinematic tool only).
        com : array_like, shape (3,)
            Tool CoM in the tool frame [m].
        inertia : array_like, shape (3, 3) or (6,)
            Tool inertia about its CoM, tool-frame axes [kg m^2].
        """
        robot = self.with_frame(name, T_flange_tool, parent)
        if inertia is None:
            inertia = np.zeros((3, 3))
        if mass == 0.0 and not np.any(np.asarray(inertia)):
            return robot
        f = robot.frame(name)
        if f.link == 0:
            raise ModelError("a tool with inertia cannot be fixed to the base")
        R, p = f.T_link_frame[:3, :3], f.T_link_frame[:3, 3]
        I = _checks.as_array("inertia", inertia)
        if I.shape == (6,):
            from .inertia import matrix_from_inertia6

            I = matrix_from_inertia6(I)
        c_link = R @ _checks.as_exact("com", com, (3,)) + p
        phi_tool = phi_from_inertial(mass, c_link, R @ I @ R.T)
        phi = np.array(robot.phi)
        phi[f.link - 1] += phi_tool
        return robot.replace(phi=phi)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_mdh(
        cls,
        a: Sequence[float],
        d: Sequence[float],
        alpha: Sequence[float],
        theta: Sequence[float] | None = None,
        *,
        joint_types: str | Sequence[str] = "R",
        flange: Sequence[float] | None = None,
        mass: ArrayLike | None = None,
        com: ArrayLike | None = None,
        inertia: ArrayLike | None = None,
        q_min: ArrayLike | None = None,
        q_max: ArrayLike | None = None,
        dq_max: ArrayLike | None = None,
        ddq_max: ArrayLike | None = None,
        tau_max: ArrayLike | None = None,
        gravity: ArrayLike = (0.0, 0.0, -STANDARD_GRAVITY),
        friction: FrictionLike | None = None,
        name: str = "robot",
        link_names: Sequence[str] | None = None,
        joint_names: Sequence[str] | None = None,
    ) -> Robot:
        """Robot from a modified Denavit-Hartenberg table (Craig's convention).

        .. math:: T_{i-1,i} = R_x(\\alpha_{i-1}) T_x(a_{i-1}) R_z(\\theta_i) T_z(d_i)

        Row ``i`` holds ``a_{i-1}, d_i, alpha_{i-1}, theta_i``. For a revolute joint
        ``theta_i`` is the offset added to ``q_i``; for a prismatic one ``d_i`` is.

        Parameters
        ----------
        a, d, alpha : sequence of float, length n
            Link lengths [m], offsets [m] and twists [rad].
        theta : sequence of float, length n, optional
            Joint angle offsets [rad] (default 0).
        joint_types : str or sequence of str
            ``"R"``/``"P"`` per joint (``"RRP"``), or one letter for all.
        flange : sequence of 4 floats, optional
            ``(a, d, alpha, theta)`` of a fixed MDH row after the last joint: the ``flange``.
        mass, com, inertia : array_like, optional
            Link masses (n,) [kg], CoMs (n, 3) [m], inertias about the CoM (n, 3, 3) or
            (n, 6) [kg m^2]. Default zero.
        q_min, q_max, dq_max, ddq_max, tau_max : array_like, optional
            Joint limits (n,); default unbounded.
        friction : Friction, optional
            The robot's friction (:class:`~dynid.friction.model.Friction`); default none.
        """
        a_, d_, al = (np.asarray(x, dtype=np.float64) for x in (a, d, alpha))
        n = a_.shape[0]
        if not (a_.shape == d_.shape == al.shape == (n,)):
            raise ShapeError(
                f"a, d and alpha must have the same shape (n,); "
                f"got {a_.shape}, {d_.shape}, {al.shape}"
            )
        th = np.zeros(n) if theta is None else _checks.as_exact("theta", theta, (n,))
        types = (
            joint_types * n
            if isinstance(joint_types, str) and len(joint_types) == 1
            else joint_types
        )
        if len(types) != n or any(str(t).upper() not in ("R", "P") for t in types):
            raise ModelError(
                f"joint_types must be 'R' or 'P' for each of the {n} joints; got {joint_types!r}"
            )
        pri = np.array([t.upper() == "P" for t in types])
        T = np.stack([mdh_transform(a_[i], d_[i], al[i], th[i]) for i in range(n)])
        frames = {}
        if flange is not None:
            fa, fd, fal, fth = (float(x) for x in flange)
            frames["flange"] = Frame(n, mdh_transform(fa, fd, fal, fth))
        zeros = np.zeros(n)
        phi = phi_from_inertial(
            zeros if mass is None else mass,
            np.zeros((n, 3)) if com is None else com,
            np.zeros((n, 3, 3)) if inertia is None else inertia,
        )
        inf = np.full(n, np.inf)

        def limit(
            name: str, x: ArrayLike | None, default: NDArray[np.float64]
        ) -> NDArray[np.float64]:
            # the same conversion __post_init__ does; it checks the shape and NaN after
            return default if x is None else _checks.as_array(name, x, allow_nonfinite=True)

        return cls(
            name=name,
            joint_names=tuple(joint_names or [f"joint{i}" for i in range(1, n + 1)]),
            link_names=tuple(link_names or [f"link{i}" for i in range(n + 1)]),
            T_parent_joint=T,
            axes=np.tile([0.0, 0.0, 1.0], (n, 1)),
            prismatic=pri,
            phi=phi,
            q_min=limit("q_min", q_min, -inf),
            q_max=limit("q_max", q_max, inf),
            dq_max=limit("dq_max", dq_max, inf),
            ddq_max=limit("ddq_max", ddq_max, inf),
            tau_max=limit("tau_max", tau_max, inf),
            gravity=np.asarray(gravity, dtype=np.float64),
            frames=frames,
            friction=friction,
        )

    # The two file constructors are facades over dynid.io.robot, imported when called: the
    # model layer holds no file format, and importing it loads no reader (tests/test_layers.py
    # allows exactly these two deferred imports).
    @classmethod
    def from_urdf(
        cls, path: str | Path, base_link: str | None = None, tip_link: str | None = None
    ) -> Robot:
        """Serial chain of a URDF file between ``base_link`` and ``tip_link``.

        The same as :func:`dynid.io.robot.urdf.load_urdf` (see it for the conventions,
        Raises and Warns).
        """
        from ..io.robot.urdf import load_urdf

        return load_urdf(path, base_link=base_link, tip_link=tip_link)

    @classmethod
    def from_toml(cls, path: str | Path) -> Robot:
        """Robot from a dynid TOML description file.

        The same as :func:`dynid.io.robot.toml.load_toml` (see it for the schema and Raises).
        """
        from ..io.robot.toml import load_toml

        return load_toml(path)

    def __reduce__(self) -> tuple[Any, tuple[dict[str, Any]]]:
        """Pickle (and copy) by the model's fields, restored as they are, not re-validated
        (so not re-normalised: bit for bit); the kernels' packed arrays are made anew."""
        state = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.init}
        state["frames"] = dict(self.frames)
        return _restore_robot, (state,)

    def __repr__(self) -> str:
        kinds = "".join("P" if p else "R" for p in self.prismatic)
        return f"Robot(name={self.name!r}, n={self.n}, joints={kinds!r}, frames={len(self.frames)})"


def mdh_transform(a: float, d: float, alpha: float, theta: float) -> NDArray[np.float64]:
    """Modified DH transform ``RotX(alpha) TransX(a) RotZ(theta) TransZ(d)``, shape (4, 4)."""
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(theta), np.sin(theta)
    return np.array(
        [
            [ct, -st, 0.0, a],
            [st * ca, ct * ca, -sa, -sa * d],
            [st * sa, ct * sa, ca, ca * d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


#: How a message says what a ``robot`` argument must be.
ROBOT_EXPECTED = "a Robot (dynid.panda(), Robot.from_urdf(...), Robot.from_mdh(...))"


def checked_robot(robot: object, name: str = "robot") -> Robot:
    """``robot`` when it is a :class:`Robot`: the check of a public function's robot
    argument at its entry.

    Raises
    ------
    WrongTypeError
        It is not (``"robot: expected a Robot (...), got str"``).
    """
    out: Robot = _checks.of_type(name, robot, Robot, ROBOT_EXPECTED)
    return out
