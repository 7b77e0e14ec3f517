"""Export a robot as MJCF, MuJoCo's model format.

:func:`mjcf_from_robot` writes one nested ``<body>`` per link under ``<worldbody>``,
keeping the robot's link and joint names:

* the base link is a body fixed to the world at the origin (the base frame is MuJoCo's
  world frame); a base link named ``world`` is MuJoCo's world body itself (MuJoCo keeps
  that name: another link named so is refused); body ``i`` sits at ``T_parent_joint[i]``
  in its parent (``pos`` [m], ``quat`` ``w x y z``) and holds joint ``i``: ``hinge``
  (revolute) or ``slide`` (prismatic) about/along ``axis`` in the body frame, with
  ``range`` [rad or m] when both position limits are finite
  (``<compiler angle="radian" autolimits="true"/>``);
* ``<inertial pos="c" mass="m" fullinertia="xx yy zz xy xz yz"/>``: CoM [m] in the link
  frame and the inertia about the CoM in link axes [kg m^2] (MuJoCo's ``fullinertia``
  order); omitted for a link whose parameters are all zero (MuJoCo refuses a zero
  ``fullinertia``). MuJoCo also refuses moving bodies without mass, so the compiler
  bounds every body's mass to at least 1e-10 kg and its principal moments to 1e-14 kg m^2
  (``boundmass``, ``boundinertia``): massless links weigh 1e-10 kg, real links are
  unchanged;
* every named frame that is not a link (``flange``, tools) becomes a ``<site>``;
* ``<option timestep>`` is MuJoCo's default, 0.002 s (:data:`MJCF_TIMESTEP`), and
  ``gravity`` the robot's [m/s^2]; one ``<motor>`` per joint with
  ``ctrlrange`` = the torque limit when it is finite (gear 1, so ``ctrl`` is the joint
  torque [N m]);
* friction (``friction=True`` and a sigmoid on the robot): the sigmoid's odd part fitted
  as ``frictionloss`` [N m] + ``damping`` [N m s/rad]
  (:func:`dynid.friction.mujoco.coulomb_viscous_from_sigmoid`; an approximation: MuJoCo
  cannot hold the sigmoid's offset and curvature). ``friction=`` a
  :class:`~dynid.friction.model.Friction` of any law of the registry
  (:mod:`dynid.friction.laws`) is written as its law maps itself
  (:attr:`~dynid.friction.laws.base.FrictionLaw.mjcf`: the classical law's ``fc`` and
  ``fv`` as they are, the smooth law's too, the asymmetric law's means, the Stribeck law's
  ``fv`` and ``fc``). MuJoCo's ``frictionloss`` is a soft constraint, a ramp of the
  velocity saturating at ``frictionloss``: each joint's ``solreffriction`` and
  ``solimpfriction`` set its slope at rest (:mod:`dynid.friction.mujoco_soft`, from the
  file's own inverse weights, :func:`invweight0`), a smooth law's rounding
  ``fc tanh(dq / width)`` as the closest ramp (about ``0.8 fc / width``), any other
  law's as the ramp closest to it, a sharp law's without a band as the steepest MuJoCo
  holds. Near a velocity reversal the constraint's torque takes the acceleration's sign
  (for ``d timeconst / 2``, 2 ms at the steepest): how far ``mj_inverse``'s friction of
  the file is from the law's, RMS and the worst case with where it happens, along a sine of
  each joint or a trajectory given (:class:`~dynid.io.robot.export_options.Along`), ends
  the warning (:func:`~dynid.friction.mujoco_soft.dry_friction_error`); with
  ``frictionloss=False`` the joints hold ``damping`` only and the Coulomb friction left out
  is said instead. What MJCF cannot hold (the offsets, a standstill band, an
  asymmetry, a Stribeck peak, a quadratic term, friction at the motors, coupled terms;
  :func:`dynid.friction.mujoco.unheld_friction`) is named in one warning line with the
  files that hold it, with how a smooth law's rounding was written.
  With ``friction=False`` the joints are frictionless, and ``mj_inverse`` equals
  :func:`dynid.rnea`;
* a joint spring (:attr:`~dynid.model.robot.Robot.spring`, the motors' torque
  ``k (q - q0)`` against it) as MuJoCo's passive spring, joint ``stiffness = k``
  [N m/rad] and ``springref = q0`` [rad]: MuJoCo's ``qfrc_spring = -k (q - q0)`` is the
  spring's own torque, the opposite of dynid's. The friction offset ``fo`` of a joint
  with a spring is its rest position's (the spring term acts about the middle of the
  limits, and the offset takes up the difference): written as ``springref = q0 - fo / k``
  (:func:`spring_held_offsets`), not dropped.

Numbers use Python's shortest round-trip representation.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import NDArray

from ... import __version__
from ..._checks import caller_level
from ...dynamics.terms import mass_matrix
from ...exceptions import DynidWarning, ModelError, ShapeError
from ...friction.model import FrictionModel, FrictionSum, robot_friction, sigmoid_parameters
from ...friction.mujoco import (
    ROUND_OFF_NM,
    CoulombViscous,
    coulomb_viscous_from_sigmoid,
    drive_joint_terms,
    joint_coulomb_viscous,
    unheld_friction,
)
from ...friction.mujoco_soft import (
    MOTION_PERIOD_S,
    DryFrictionError,
    SoftFrictionLoss,
    dry_friction_error,
    mujoco_dry_friction,
    representative_motion,
    soft_frictionloss,
)
from ...model.drive import Drive
from ...model.inertia import inertia6_from_matrix
from ...model.robot import Robot
from ..atomic import write_text
from .export_options import (
    Along,
    ExportOptions,
    friction_losses,
    kept_elsewhere,
    with_caveat,
    xml_comment,
)

__all__ = [
    "MJCF_TIMESTEP",
    "export_mjcf",
    "invweight0",
    "mjcf_from_robot",
    "save_mjcf",
    "spring_held_offsets",
]

#: The timestep [s] the file writes (MuJoCo's default): the dry friction's time constant
#: is two of it (:mod:`dynid.friction.mujoco_soft`).
MJCF_TIMESTEP = 0.002


def _f(x: float) -> str:
    x = float(x)
    return "0" if x == 0.0 else repr(x)


def _v(v: np.ndarray) -> str:
    return " ".join(_f(x) for x in v)


def _pose(T: np.ndarray) -> str:
    """``pos`` and ``quat`` (w x y z) attributes of a pose (4, 4)."""
    from scipy.spatial.transform import Rotation  # scipy on first use (start-up time)

    x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
    return f'pos="{_v(T[:3, 3])}" quat="{_v(np.array([w, x, y, z]))}"'


def spring_held_offsets(
    robot: Robot, offset: NDArray[np.float64], at_motors: bool
) -> NDArray[np.bool_]:
    """The joints (n,) whose friction offset ``offset`` [N m] the robot's spring holds as
    its reference: ``k (q - q0) + fo = k (q - (q0 - fo / k))``. A spring term acts about a
    fixed ``q0`` (the middle of the limits) and the offset takes up its true rest position,
    so an MJCF written with ``springref = q0`` and no offset was off by ``fo`` at every
    position. Only where ``k > 0``, the offset acts at the joint, and the reference moves
    by no more than the joint's range (else the offset is not the spring's)."""
    spring = robot.spring
    if spring is None or at_motors:
        return np.zeros(robot.n, dtype=bool)
    span = np.where(np.isfinite(robot.q_max - robot.q_min), robot.q_max - robot.q_min, 2 * np.pi)
    out: NDArray[np.bool_] = (spring.k > 0) & (offset != 0) & (np.abs(offset) <= spring.k * span)
    return out


def invweight0(robot: Robot, armature: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """MuJoCo's ``dof_invweight0`` (n,) [1/(kg m^2), m/kg for a prismatic joint] of the
    file: the diagonal of ``(M(0) + diag(armature))^{-1}``, the inverse mass matrix at the
    joints' zero (MuJoCo's ``qpos0``) with the rotors' ``armature`` [kg m^2] (n,)."""
    n = robot.n
    M = mass_matrix(robot, np.zeros(n)) + np.diag(np.zeros(n) if armature is None else armature)
    L = np.linalg.cholesky(M)
    Linv = np.linalg.solve(L, np.eye(n))  # M^-1 = L^-T L^-1: its diagonal, column sums
    return np.asarray(np.sum(Linv**2, axis=0), dtype=np.float64)


def _velocity_range(robot: Robot) -> NDArray[np.float64]:
    """The joints' velocity limits [rad/s], 2 rad/s where none is given."""
    return np.where(np.isfinite(robot.dq_max), robot.dq_max, 2.0)


def _soft(
    model: FrictionModel | FrictionSum,
    approx: CoulombViscous,
    robot: Robot,
    armature: NDArray[np.float64] | None,
) -> tuple[SoftFrictionLoss, tuple[str, ...]]:
    """The dry friction's slope at rest per joint (:mod:`dynid.friction.mujoco_soft`) and
    the line saying how it holds a smooth law's rounding (none below round-off)."""
    soft = soft_frictionloss(
        model,
        approx.viscous,
        approx.coulomb,
        _velocity_range(robot),
        invweight0(robot, armature),
        MJCF_TIMESTEP,
    )
    smooth = [
        p
        for p in (model.parts if isinstance(model, FrictionSum) else (model,))
        if p.kind in ("smooth", "smooth_stribeck") and np.any(np.asarray(p.band) > 0)
    ]
    if not smooth or np.max(soft.rms_error) < ROUND_OFF_NM:
        return soft, ()
    return soft, (_rounding_note(model.kind, smooth[0], approx.coulomb, soft),)


def _span(x: NDArray[np.float64]) -> str:
    """``x``'s range as a warning says it: ``0.02`` or ``0.0189-0.0198``."""
    lo, hi = f"{float(np.min(x)):.3g}", f"{float(np.max(x)):.3g}"
    return lo if lo == hi else f"{lo}-{hi}"


def _rounding_note(
    kind: str, law: FrictionModel, coulomb: NDArray[np.float64], soft: SoftFrictionLoss
) -> str:
    """The line naming the smooth ``law`` (its width [rad/s], at the motors where it acts
    there, over the gear ratio at the joints) and what MuJoCo applies in its place: a ramp
    of the velocity up to ``frictionloss`` ``coulomb`` (n,) [N m], its slope at rest
    ``soft.slope``, the joint velocity it reaches ``fc`` at and its RMS against the law.
    ``kind``: the friction model's (the sentence's head,
    :func:`~dynid.io.robot.export_options.friction_losses`)."""
    band = np.asarray(law.band)
    held = coulomb > 0
    corner = coulomb[held] / soft.slope[held]
    where = ""
    if law.at_motors and law.drive is not None:  # fc tanh(G dq / w): w / G at the joint
        gear = np.abs(np.diag(law.drive.transmission))
        at_joints = (band / np.where(gear > 0, gear, 1.0))[band > 0]
        where = f" at the motors, {_span(at_joints)} rad/s at the joints"
    return (
        f"{kind} friction: written with its rounding fc tanh(dq / width) (width "
        f"{_span(band[band > 0])} rad/s{where}) as the ramp of the velocity MuJoCo applies "
        f"in its place (frictionloss is no tanh): slope {_span(soft.slope[held])} N m s/rad "
        "at rest (solreffriction, solimpfriction), reaching fc at "
        f"|dq| = {_span(corner)} rad/s at the joints (RMS {np.max(soft.rms_error):.2g} N m "
        "off the law, each joint alone), which dynid reads the file's frictionloss back as"
    )


def _motion(robot: Robot, along: Along | None) -> tuple[NDArray, NDArray, str, str]:
    """The velocities and accelerations (N, n) the friction is measured along, how the
    warning names them, and the reversals a second it says the RMS grows with."""
    if along is None:
        dq, ddq = representative_motion(_velocity_range(robot))
        rate = 2.0 / MOTION_PERIOD_S
        said = (
            f"along a sine of each joint's velocity ({MOTION_PERIOD_S:g} s period, {rate:g} "
            "reversals a second, at half its velocity limit)"
        )
        return dq, ddq, said, f"{rate:g}"
    tr = along.trajectory
    if tr.dq.shape[1] != robot.n:
        raise ShapeError(f"{along.name} has {tr.dq.shape[1]} joints; robot has {robot.n}")
    span = float(tr.t[-1] - tr.t[0]) if tr.t.size > 1 else 0.0
    flips = np.sum(tr.dq[1:] * tr.dq[:-1] < 0, axis=0)
    per_s = f"{np.max(flips) / span:.2g}" if span > 0 else "its"
    return tr.dq, tr.ddq, f"along {along.name} ({tr.t.size} samples)", per_s


def _reversal_note(
    model: FrictionModel | FrictionSum,
    approx: CoulombViscous,
    soft: SoftFrictionLoss,
    robot: Robot,
    along: Along | None,
) -> tuple[str, ...]:
    """The line saying how far ``mj_inverse``'s friction of the file is from the law's
    along ``along`` (None: the representative sine,
    :func:`~dynid.friction.mujoco_soft.representative_motion`; RMS, and the worst case with
    where it happens, at a velocity reversal:
    :func:`~dynid.friction.mujoco_soft.dry_friction_error`) and what to do where it
    matters; none without dry friction or below round-off."""
    if not np.any(approx.coulomb > 0):
        return ()
    dq, ddq, motion, rate = _motion(robot, along)
    err = dry_friction_error(model, approx.viscous, approx.coulomb, soft, dq, ddq)
    if np.max(err.worst) < ROUND_OFF_NM:
        return ()
    j, w = int(np.argmax(err.rms)), int(np.argmax(err.worst))
    where = f"dq {err.worst_dq[w]:+.2g} rad/s, ddq {err.worst_ddq[w]:+.3g} rad/s^2"
    slow = abs(err.worst_dq[w]) < 0.01 * _velocity_range(robot)[w]
    made = _acceleration_made(err, w, approx.coulomb, soft)
    reversal = slow and made
    corner = approx.coulomb[w] / soft.slope[w] if soft.slope[w] > 0 else 0.0
    if not reversal and abs(err.worst_dq[w]) <= 2.0 * corner:  # where the ramp bends
        why = (
            "the constraint's torque depends on the acceleration too"
            if made
            else "MuJoCo's ramp of the velocity departs from the law"
        )
        where = f"near rest, where {why}: {where}"
    if reversal:
        where = (
            f"at a velocity reversal, where for about {1e3 * err.window_s[w]:.2g} ms before "
            f"it the constraint's torque follows the acceleration's sign: {where}"
        )
    said = (
        "mj_inverse's friction (frictionloss is MuJoCo's dry friction as a constraint): "
        f"{motion} it differs from the law's by RMS up to {err.rms[j]:.3g} N m (joint "
        f"{j + 1}) and at worst {err.worst[w]:.3g} N m (joint {w + 1}, {where})"
    )
    if reversal:
        said += (
            f"; the RMS grows with the square root of the reversals a second ({rate} here); "
            "where inverse dynamics at reversals matters, export with frictionloss=False "
            "(--no-frictionloss) and add the Coulomb friction as a force of the velocity "
            "(fc tanh(dq / width) as qfrc_applied or a velocity-dependent actuator)"
        )
    return (said,)


def _acceleration_made(
    err: DryFrictionError, w: int, coulomb: NDArray[np.float64], soft: SoftFrictionLoss
) -> bool:
    """Whether the worst difference of joint ``w`` comes from the constraint's torque taking
    the acceleration's sign before a reversal: MuJoCo's dry friction (``coulomb`` (n,)
    [N m], ``soft``) at that velocity with the acceleration reversed differs by at least
    half of it (an xArm7's worst, 0.22 N m at 0.026 rad/s, was the ramp's departure from
    the law, the same at either acceleration's sign, and was said to be a reversal's)."""
    dq = np.zeros((2, coulomb.size))
    ddq = np.zeros((2, coulomb.size))
    dq[:, w] = err.worst_dq[w]
    ddq[:, w] = (err.worst_ddq[w], -err.worst_ddq[w])
    both = mujoco_dry_friction(dq, ddq, coulomb, soft)[:, w]
    return bool(abs(both[0] - both[1]) >= 0.5 * err.worst[w])


def _without_frictionloss(
    approx: CoulombViscous, robot: Robot
) -> tuple[CoulombViscous, tuple[str, ...]]:
    """``approx`` with no dry friction (``frictionloss=False``), and the line that says
    what was left out."""
    if not np.any(approx.coulomb > 0):
        return approx, ()
    j = int(np.argmax(approx.coulomb))
    return replace(approx, coulomb=np.zeros_like(approx.coulomb)), (
        "dry friction left out (frictionloss=False): no frictionloss, the law's Coulomb "
        f"friction (up to {approx.coulomb[j]:.4g} N m, at joint {j + 1}) to be added as a "
        "force of the velocity",
    )


def _law_terms(
    friction: FrictionModel | FrictionSum,
    robot: Robot,
    kept: str,
    armature: NDArray[np.float64] | None,
    dry: bool = True,
) -> tuple[CoulombViscous, SoftFrictionLoss, tuple[str, ...], NDArray[np.bool_]]:
    """A friction model as MuJoCo holds it (the smooth laws' ``fv`` and ``fc`` as they
    are, their rounding as the dry friction's slope, :func:`_soft`), what it drops (one
    line each, ending with ``kept``: the files that hold it,
    :func:`~dynid.io.robot.export_options.kept_elsewhere`), and the joints whose offset the
    robot's spring holds (:func:`spring_held_offsets`), which are not dropped; ``dry``
    False: the dry friction is not written, nor how its rounding would be."""
    vmax = _velocity_range(robot)
    jt = joint_coulomb_viscous(friction, vmax, sharp=False)
    z = np.zeros(friction.n)
    offset = z if jt.offset is None else jt.offset
    held = spring_held_offsets(robot, offset, friction.at_motors)
    approx = CoulombViscous(jt.frictionloss, jt.damping, offset, z, z)
    soft, rounding = _soft(friction, approx, robot, armature)
    lost = (rounding if dry else ()) + jt.notes + unheld_friction(friction, vmax, held, sharp=False)
    if not lost:
        return approx, soft, (), held
    written, left = friction_losses(friction.kind, lost)
    note = (
        f"the joints' frictionloss and damping (Coulomb and viscous friction at the joints) "
        f"hold the {friction.kind} friction"
        + (f", written {written}" if written else "")
        + (f", without {left}" if left else "")
        + (f"; {kept}" if kept else "")
    )
    return approx, soft, (note,), held


_Terms = tuple[
    CoulombViscous | None,
    SoftFrictionLoss | None,
    NDArray[np.float64] | None,
    tuple[str, ...],
    NDArray[np.bool_],
]


def _joint_terms(
    robot: Robot,
    friction: bool | FrictionModel | FrictionSum,
    drive: Drive | None,
    kept: str,
    dry: bool = True,
    along: Along | None = None,
) -> _Terms:
    """The friction written to the joints, the rotor ``armature`` and what MJCF cannot hold.

    Returns ``(approximation, soft, armature, notes, held)``: the Coulomb and viscous terms
    per joint (None: frictionless), the dry friction's slope at rest
    (:mod:`dynid.friction.mujoco_soft`; None: frictionless), the armature (n,) [kg m^2]
    (None: no drive with rotor inertias), one note per thing dropped
    (:func:`dynid.friction.mujoco.drive_joint_terms`, :func:`_law_terms`) and the joints
    (n,) whose friction offset the spring's reference holds (:func:`spring_held_offsets`).
    ``friction=True`` is the robot's own friction: its sigmoid (``Robot.friction``) by the
    fit of its odd part up to ``dq_max``, another law as that law maps itself. The notes
    end with how far ``mj_inverse``'s friction is from the law's along ``along``
    (:func:`_reversal_note`);
    ``dry`` False: no ``frictionloss`` (:func:`_without_frictionloss`).
    """
    n = robot.n
    model = robot_friction(robot) if friction is True else friction or None
    if model is not None and model.n != n:
        raise ShapeError(f"friction has {model.n} joints; robot {robot.name!r} has {n}")
    own = None if model is None else model.drive  # a friction's own drive, if not bare
    d = own if own is not None and not own.is_bare else drive
    notes: tuple[str, ...] = ()
    armature = None
    if d is not None:
        d.check(n)
        jt = drive_joint_terms(
            d.transmission,
            d.rotor_inertia,
            None,
            None,
            friction_at_motor=d.friction_place == "motor",
        )
        notes = jt.notes
        armature = jt.armature if d.rotor_inertia is not None else None
    sigmoid = sigmoid_parameters(model) if friction is True else None
    if model is None:
        return None, None, armature, notes, np.zeros(n, dtype=bool)
    if sigmoid is not None:  # the description's sigmoid
        approx = coulomb_viscous_from_sigmoid(sigmoid, robot.dq_max)
        soft, _ = _soft(model, approx, robot, armature)
        held = spring_held_offsets(robot, approx.offset, model.at_motors)
    else:
        approx, soft, more, held = _law_terms(model, robot, kept, armature, dry)
        notes += more
    if not dry:
        approx, left = _without_frictionloss(approx, robot)
        return approx, soft, armature, notes + left, held
    return approx, soft, armature, notes + _reversal_note(model, approx, soft, robot, along), held


def _comment(
    robot: Robot,
    friction: bool | FrictionModel | FrictionSum,
    approx: CoulombViscous | None,
    armature: NDArray[np.float64] | None,
    notes: tuple[str, ...],
) -> str:
    """The default comment: the writer, the units, how friction and rotors are written."""
    text = f"written by dynid {__version__}: inertials about the CoM in link axes [kg, m, kg m^2]"
    if approx is None:
        text += "; frictionless joints"
    elif not np.any(approx.coulomb > 0):
        text += "; friction: viscous as damping"
    else:
        text += (
            "; friction: Coulomb as frictionloss (MuJoCo's soft dry friction, its slope at "
            "rest set per joint by solreffriction and solimpfriction), viscous as damping"
        )
        if isinstance(friction, bool):
            text += " (fit of the sigmoid)"
        elif friction.at_motors:
            text += " (reflected from the motors)"
    if armature is not None:
        text += "; rotor inertia as armature"
    if robot.spring is not None:
        text += "; joint spring as stiffness about springref"
    return text + "".join(f"; {note}" for note in notes)


def _friction_attrs(approx: CoulombViscous, soft: SoftFrictionLoss | None, i: int) -> str:
    """Joint ``i``'s ``frictionloss`` and ``damping``, with the dry friction's
    ``solreffriction`` and ``solimpfriction`` (:mod:`dynid.friction.mujoco_soft`)."""
    attrs = f' frictionloss="{_f(approx.coulomb[i])}" damping="{_f(approx.viscous[i])}"'
    if soft is not None and approx.coulomb[i] > 0:
        d = _f(soft.impedance[i])
        attrs += f' solreffriction="{_f(soft.timeconst[i])} 1" solimpfriction="{d} {d} 0.001"'
    return attrs


def _bodies(
    robot: Robot,
    approx: CoulombViscous | None,
    soft: SoftFrictionLoss | None,
    armature: NDArray[np.float64] | None,
    held: NDArray[np.bool_],
) -> list[str]:
    """The nested ``<body>`` lines of the links (the base's sites first), closed; a joint
    spring's reference holds the friction offset of the joints ``held`` (n,)
    (:func:`spring_held_offsets`)."""
    n = robot.n
    I6 = inertia6_from_matrix(robot.inertia)[:, [0, 3, 5, 1, 2, 4]]  # xx yy zz xy xz yz
    mass, com = robot.mass, robot.com
    sites: dict[int, list[str]] = {}
    links = set(robot.link_names)
    for name, fr in robot.frames.items():
        if name not in links:
            sites.setdefault(fr.link, []).append(
                f'<site name={quoteattr(name)} {_pose(fr.T_link_frame)} size="0.005"/>'
            )
    if "world" in robot.link_names[1:]:
        raise ModelError(
            f"link {robot.link_names.index('world')} of robot {robot.name!r} is named 'world', "
            "which MuJoCo keeps for its world body; only the base link may be named so"
        )
    world = robot.link_names[0] == "world"  # the base is MuJoCo's world body itself
    lines = [] if world else [f'    <body name={quoteattr(robot.link_names[0])} pos="0 0 0">']
    lines += ["      " + s for s in sites.get(0, [])]
    for i in range(n):
        ind = "    " + "  " * (i + 2)
        kind = "slide" if robot.prismatic[i] else "hinge"
        attrs = f'name={quoteattr(robot.joint_names[i])} type="{kind}" axis="{_v(robot.axes[i])}"'
        lo, hi = robot.q_min[i], robot.q_max[i]
        if np.isfinite(lo) and np.isfinite(hi):
            attrs += f' range="{_f(lo)} {_f(hi)}"'
        if approx is not None:
            attrs += _friction_attrs(approx, soft, i)
        if armature is not None:
            attrs += f' armature="{_f(armature[i])}"'
        if robot.spring is not None:  # MuJoCo's own torque -k (q - q0): dynid's tau_s held
            k, q0 = robot.spring.k[i], robot.spring.q0[i]
            if approx is not None and held[i]:  # the offset, as the spring's reference
                q0 = q0 - approx.offset[i] / k
            attrs += f' stiffness="{_f(k)}" springref="{_f(q0)}"'
        lines += [
            f"{ind[:-2]}<body name={quoteattr(robot.link_names[i + 1])} "
            f"{_pose(robot.T_parent_joint[i])}>",
            f"{ind}<joint {attrs}/>",
        ]
        if np.any(robot.phi[i] != 0.0):  # MuJoCo refuses a zero fullinertia; omit it
            lines.append(
                f'{ind}<inertial pos="{_v(com[i])}" mass="{_f(mass[i])}" '
                f'fullinertia="{_v(I6[i])}"/>'
            )
        lines += [ind + s for s in sites.get(i + 1, [])]
    for i in reversed(range(n)):
        lines.append("    " + "  " * (i + 1) + "</body>")
    return lines if world else lines + ["    </body>"]


def _actuators(robot: Robot) -> list[str]:
    """One ``<motor>`` per joint, gear 1, ``ctrlrange`` the torque limit when finite."""
    lines = []
    for i in range(robot.n):
        t = robot.tau_max[i]
        rng = f' ctrlrange="{_f(-t)} {_f(t)}"' if np.isfinite(t) else ""
        lines.append(
            f"    <motor name={quoteattr(robot.joint_names[i] + '_motor')} "
            f'joint={quoteattr(robot.joint_names[i])} gear="1"{rng}/>'
        )
    return lines


def mjcf_from_robot(
    robot: Robot,
    *,
    friction: bool | FrictionModel | FrictionSum = True,
    comment: str | None = None,
    drive: Drive | None = None,
    kept: str = "",
    frictionloss: bool = True,
    along: Along | None = None,
) -> tuple[str, CoulombViscous | None]:
    """The MJCF document of a robot, and the friction approximation it holds.

    Parameters
    ----------
    robot : Robot
    friction : bool or FrictionModel
        True: the robot's sigmoid friction (if any) as ``frictionloss`` and ``damping``;
        a friction model of any law: what its law maps to them
        (:func:`dynid.friction.mujoco.joint_coulomb_viscous`: a classical model's ``fc`` and
        ``fv``; what MJCF cannot hold is named in a :class:`~dynid.exceptions.DynidWarning`);
        friction at the motors of a drive: reflected to the joints
        (:func:`dynid.friction.mujoco.drive_joint_terms`); False: none.
    comment : str, optional
        Text of an XML comment at the top (default: the writer and the conventions).
    drive : Drive, optional
        A drive with known rotor inertias: ``armature`` = ``diag(K^T diag(I_a) K)``; what
        MJCF cannot hold (a coupled rotor's off-diagonal inertia) is said in a
        :class:`~dynid.exceptions.DynidWarning` and in the comment, never dropped silently.
    kept : str
        The files that hold the friction exactly, said after what MJCF drops of it
        (:func:`~dynid.io.robot.export_options.kept_elsewhere`); empty: none named.
    frictionloss : bool
        Write the dry friction as ``frictionloss`` (MuJoCo's constraint; the warning says
        how far ``mj_inverse``'s friction is from the law's at velocity reversals); False:
        ``damping`` only, the Coulomb friction left out and said so.
    along : Along, optional
        The motion the warning measures ``mj_inverse``'s friction along (default: a sine
        of each joint, :func:`~dynid.friction.mujoco_soft.representative_motion`).

    Returns
    -------
    text : str
        The MJCF XML text.
    approximation : CoulombViscous or None
        The fitted friction written to the joints, or None when none was written.

    Raises
    ------
    ModelError
        A link other than the base is named ``world`` (MuJoCo's world body).
    """
    approx, soft, armature, notes, held = _joint_terms(
        robot, friction, drive, kept, frictionloss, along
    )
    if notes:  # one line: what MJCF cannot hold
        warnings.warn(f"MJCF export: {'; '.join(notes)}", DynidWarning, stacklevel=caller_level())
    text = comment or _comment(robot, friction, approx, armature, notes)
    lines = [
        '<?xml version="1.0"?>',
        xml_comment(text),
        f"<mujoco model={quoteattr(robot.name)}>",
        '  <compiler angle="radian" autolimits="true" boundmass="1e-10" boundinertia="1e-14"/>',
        f'  <option timestep="{_f(MJCF_TIMESTEP)}" gravity="{_v(robot.gravity)}"/>',
        "  <worldbody>",
        *_bodies(robot, approx, soft, armature, held),
        "  </worldbody>",
        "  <actuator>",
        *_actuators(robot),
        "  </actuator>",
        "</mujoco>",
    ]
    return "\n".join(lines) + "\n", approx


def save_mjcf(
    path: str | Path,
    robot: Robot,
    *,
    friction: bool | FrictionModel | FrictionSum = True,
    drive: Drive | None = None,
    kept: str = "",
    caveat: str | None = None,
    frictionloss: bool = True,
    along: Along | None = None,
) -> Path:
    """Write :func:`mjcf_from_robot` to ``path``; returns the path. ``caveat``: a comment
    at the top, why the fit was not accepted."""
    path = Path(path)
    text, _ = mjcf_from_robot(
        robot, friction=friction, drive=drive, kept=kept, frictionloss=frictionloss, along=along
    )
    write_text(path, with_caveat(text, caveat, xml=True))
    return path


def export_mjcf(path: str | Path, robot: Robot, options: ExportOptions) -> Path:
    """:func:`save_mjcf` with the export options' ``friction`` and ``drive`` (the entry of
    ``mjcf`` in the exports); the friction's warning names the files that hold it exactly
    (``options.beside``, ``options.source``) or how to write them."""
    exact = () if isinstance(options.friction, FrictionSum) else (("toml", "exactly"),)
    kept = kept_elsewhere(options, path, "it", exact, source="exactly")
    return save_mjcf(
        path,
        robot,
        friction=options.friction,
        drive=options.drive,
        kept=kept,
        caveat=options.caveat,
        frictionloss=options.frictionloss,
        along=options.along,
    )
