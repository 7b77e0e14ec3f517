"""Signs as recorded: columns of a log recorded reversed, and one recording of the opposite
sign to the others.

* **Reversed columns**: a motor or encoder mounted the other way, its position and velocity
  (with its effort or without) of the opposite sign; several at once, named in the log's own
  columns (a motor-side log's motors) with one ``--units`` hint, judged through the drive
  before the sign (:func:`reversed_joint`).
* **Opposite sign between recordings**: of several recordings, one motor (joint) the links
  barely load of the opposite sign to the others' is told by its own friction and rotor
  (:func:`opposite_friction_among`), confirmed by one friction, rotor and offset fitted to
  the recordings pooled; where none reads right to compare with (two recordings), that
  pooled fit names the disagreement, and the file when the model's torques or
  dissipating friction tell it (:func:`opposite_among_pooled`). A coupled wrist's motor
  reaches two joints, so its torque negated is no joint's, which the check against the
  model's torques cannot see; its own terms hold the friction of the joint no motor
  turns alone (a description's, at the joints) beside the motors'.

:func:`recording_sign_findings` runs these sign checks, with the sign against the model's
torques (:func:`~dynid.identification.model_sign.opposite_sign_among`), in the one order
``identify``, ``validate`` and ``observe`` share.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..dynamics.rnea import rnea
from ..model.drive import Drive
from ..model.robot import Robot
from .log import TorqueLog, joint_side_log
from .model_sign import (
    CHECKED_SAMPLES,
    NEGATED_DISTANCE_SHARE,
    NEGATED_MODEL_SHARE,
    flip_entries,
    motion_accelerations,
    opposite_sign_among,
)

__all__ = [
    "opposite_among_pooled",
    "opposite_friction_among",
    "reversal_hint",
    "reversed_joint",
    "recording_sign_findings",
    "SignFinding",
    "REVERSED_MODEL_SHARE",
    "REVERSED_STEP_SHARE",
    "DISAGREE_SHARE",
    "TOLD_SHARE",
    "DISSIPATION_SHARE",
]


#: :func:`reversed_joint` questions a log whose residual, each motor's own friction and
#: rotor taken out, is at least this share of the RMS of what they leave of the torques
#: (the links' share; clean simulated Panda logs left 0.04, and 0.05 geared with rotors
#: that outweigh the links; a geared Panda's motor 3 logged reversed 0.37, 0.053 once
#: reversed).
REVERSED_MODEL_SHARE = 0.1
#: :func:`reversed_joint` changes one more column's signs while that leaves at most this
#: share of the sum of squares left before (a Panda's joints 2 and 5 reversed: joint 2
#: alone left 0.004 of it as read, joint 5 alone 0.99, both 1.3e-4; a geared Panda's
#: motors 3 and 6: motor 1 alone left 0.15 against motor 3's 0.18, joints 1 and 3 being
#: parallel near q2 = 0, and the move from motor 1 to motor 3 then 0.011 for 0.072).
REVERSED_STEP_SHARE = 0.75


@dataclass(frozen=True, slots=True)
class _Recorded:
    """A log's samples as recorded, for :func:`reversed_joint`: positions, velocities,
    accelerations (one derivation, :func:`motion_accelerations`) and efforts (N, n) in
    the log's own columns, and the drive that reads them (None: joint-side torques)."""

    q: NDArray[np.float64]
    dq: NDArray[np.float64]
    ddq: NDArray[np.float64]
    tau: NDArray[np.float64]
    drive: Drive | None
    #: Per columns' signs ``motion`` (its bytes), the joint velocities, accelerations, the
    #: model's torques and the own terms' columns (:func:`_group_columns`) :meth:`left`
    #: computed with them (the search tries several efforts' signs beside one motion's).
    seen: dict[
        bytes,
        tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], list[_GroupColumns]],
    ] = field(default_factory=dict, compare=False, repr=False)

    @property
    def joint_torques(self) -> NDArray[np.float64]:
        """The efforts as joint torques [N m] (N, n)."""
        return self.signed_torques(np.ones(self.tau.shape[1]))

    def signed_torques(self, sign: NDArray[np.float64]) -> NDArray[np.float64]:
        """The efforts, each column times ``sign`` (n,), as joint torques [N m] (N, n)."""
        tau = self.tau * sign
        return tau if self.drive is None else self.drive.joint_torques(tau)

    def joint_states(
        self,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """The positions [rad], velocities [rad/s] and accelerations [rad/s^2] (N, n) at
        the joints."""
        if self.drive is None:
            return self.q, self.dq, self.ddq
        q, dq, ddq = self.drive.joint_states(self.q, self.dq, self.ddq)
        return q, dq, ddq

    def carried(self) -> float:
        """The sum of squares [N^2 m^2] of what each motor's friction and rotor leave of the
        joint torques (:func:`_left_over`): the links' share, which a reversal disturbs (a
        geared arm's rotors outweigh it)."""
        _, dq, ddq = self.joint_states()
        return _left_over(self.joint_torques, dq, ddq, self.drive)

    def left(self, robot: Robot, motion: NDArray[np.float64], torque: NDArray[np.float64]) -> float:
        """What the model and each motor's friction and rotor leave [N^2 m^2] (sum of
        squares over the joints) with the columns' signs ``motion`` and ``torque`` (n,)."""
        key = np.asarray(motion, dtype=np.float64).tobytes()
        if key not in self.seen:  # (the robot is the one of every call: reversed_joint's)
            q, dq, ddq = self.q * motion, self.dq * motion, self.ddq * motion
            if self.drive is not None:
                q, dq, ddq = self.drive.joint_states(q, dq, ddq)
            model = rnea(robot, q, dq, ddq)
            if robot.spring is not None:
                model = model + robot.spring.torques(q)
            self.seen[key] = (dq, ddq, model, _group_columns(dq, ddq, self.drive))
        dq, ddq, model, columns = self.seen[key]
        tau = self.tau * torque
        if self.drive is not None:
            tau = self.drive.joint_torques(tau)
        return _left_over(tau - model, dq, ddq, self.drive, columns)


def _recorded(log: TorqueLog, drive: Drive | None) -> _Recorded | None:
    """:class:`_Recorded` of ``log`` at every k-th of its samples whose accelerations are
    known (:func:`motion_accelerations`), or None when too few are."""
    at = np.arange(0, log.n_samples, max(1, log.n_samples // CHECKED_SAMPLES))
    found = motion_accelerations(log, at)
    if found is None:
        return None
    ddq, ok = found
    return _Recorded(log.q[at][ok], log.dq[at][ok], ddq[ok], log.tau[at][ok], drive)


def reversed_joint(
    robot: Robot, log: TorqueLog, drive: Drive | None = None, *, file: str | None = None
) -> str | None:
    """The finding that columns of a log were recorded reversed, each position (and
    velocity) of the opposite sign, with or without its effort (a motor mounted or wired
    the other way: its encoder and current both negated; or the encoder alone), or None;
    None too for a robot without inertial parameters.

    ``log`` is as recorded, read through ``drive`` (motor-side positions and efforts,
    currents): a reversed column is the log's own, a motor's of a motor-side log (a
    coupled wrist's motor turns two joints), named so with the ``--units`` entries in the
    log's columns (``q6=-1,tau6=-1``; ``file``: that recording's own,
    ``rec2.csv:q6=-1,rec2.csv:tau6=-1``, one recording among several whose others read
    right).

    Judged on the robot's whole rigid-body torques over every joint, at the accelerations
    :func:`motion_accelerations` derives (one derivation for the torques and the rotor
    columns, of the sign check's whole torques too), each joint's residual freed of its
    own viscous, Coulomb, offset and armature torques (least squares on ``dq``,
    ``sign(dq)``, 1, ``ddq``; through a drive, each motor's, where its friction acts, and
    its rotor's ``K^T (K ddq)``: a geared arm's rotors and motor friction, which the
    description lacks), against the torques those columns leave (the links' share: a
    geared arm's rotors outweigh it). The columns' signs change one step at a time
    (:func:`_changes`: a column's position and effort, position or effort reversed, or
    back, or a reversal moved to another column), the step that leaves least first, while
    it leaves at most :data:`REVERSED_STEP_SHARE` of what was left; the reversed columns
    are named when what they leave is within :data:`NEGATED_DISTANCE_SHARE` of the RMS as
    read, where that is at least :data:`REVERSED_MODEL_SHARE` of the links' share (a model
    that explains the log is not questioned), and below :data:`NEGATED_MODEL_SHARE` of it,
    a position among them, and better than every torque negated (then None: that is
    :func:`opposite_sign`'s finding, which a log of every torque negated, joint 2
    reversed, explained to 0.41 of its residual as read; where friction outweighs gravity
    on a joint, an encoder reversed and a torque negated look alike, and the reversal must
    explain it better). Efforts alone negated are named beside a reversal, and left to
    :func:`opposite_sign` without one. Judged before :func:`opposite_sign`, which read an
    encoder reversed as a torque of the opposite sign and asked for ``tau3=-1``. Before, a
    geared arm's motor 3 logged reversed was fitted to 34 % error with a spring suggested
    on joint 3; a coupled wrist's motor, which turns two joints, could not be named.

    Parameters
    ----------
    robot : Robot
    log : TorqueLog
        As recorded (its columns the drive's side and effort).
    drive : Drive, optional
        What reads ``log`` (:func:`~dynid.identification.log.joint_side_log`).

    Returns
    -------
    str or None
        The finding, one line with the ``--units`` entries.
    """
    found = _reversal(robot, log, drive)
    return None if found is None else _reversed_line(robot, drive, *found, file=file)


def _reversal(
    robot: Robot, log: TorqueLog, drive: Drive | None
) -> tuple[NDArray[np.bool_], NDArray[np.bool_], tuple[float, float, float]] | None:
    """:func:`reversed_joint`'s judgement: the columns reversed and the efforts negated
    (n,) with what they leave, as read and the links' share (sums of squares), or None."""
    if not np.any(robot.phi):
        return None
    rec = _recorded(log, drive)
    if rec is None:
        return None
    one = np.ones(log.n)
    total = rec.carried()
    read = rec.left(robot, one, one)
    if read < REVERSED_MODEL_SHARE**2 * total:
        return None
    motion, torque, left = one.copy(), one.copy(), read
    while True:  # the change of one column (or a move to another) that leaves least
        best = min(
            ((rec.left(robot, m, t), m, t) for m, t in _changes(motion, torque)),
            key=lambda x: x[0],
        )
        if not best[0] <= REVERSED_STEP_SHARE * left:
            break
        left, motion, torque = best
    if not left < NEGATED_DISTANCE_SHARE**2 * read or not left < NEGATED_MODEL_SHARE**2 * total:
        return None  # none explains it
    if np.all(motion > 0):
        return None  # torques alone negated explain it best: opposite_sign's
    if rec.left(robot, one, -one) <= left:  # every torque of the opposite sign
        return None
    return motion < 0, torque < 0, (left, read, total)


def _changes(
    motion: NDArray[np.float64], torque: NDArray[np.float64]
) -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Every sign of the columns (``motion``, ``torque``: +-1, n) one step from these: a
    column set to another of its signs (position and effort reversed, position alone,
    effort alone, neither), or a reversed column's signs moved to one not reversed (a
    Panda's joints 1 and 3, parallel when joint 2 is near zero, look alike)."""
    states = ((-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0))
    for j in range(motion.size):
        for m, t in states:
            if (m, t) != (motion[j], torque[j]):
                ms, ts = motion.copy(), torque.copy()
                ms[j], ts[j] = m, t
                yield ms, ts
    flipped = (motion < 0) | (torque < 0)
    for i in np.flatnonzero(flipped):
        for k in np.flatnonzero(~flipped):
            pair = np.array([i, k])
            ms, ts = motion.copy(), torque.copy()
            ms[pair], ts[pair] = ms[pair[::-1]], ts[pair[::-1]]
            yield ms, ts


def reversal_hint(
    reversed_: Sequence[tuple[int, bool]],
    torque_alone: Sequence[int],
    file: str | None,
    motors: bool,
    where: str = "",
) -> str:
    """The ``--units`` hint of columns recorded reversed: each of ``reversed_`` (column from
    0, with its effort or not), the efforts ``torque_alone`` negated alone, of ``file``'s
    own where given (``rec2.csv:q4=-1``), ``where`` said after "reads it so", the rates'
    entries, and (``motors``) that they are a motor-side log's motors' columns."""
    at = "" if file is None else f"{file}:"
    cols = ",".join(
        [f"{at}q{k + 1}=-1" + (f",{at}tau{k + 1}=-1" if tau else "") for k, tau in reversed_]
        + [f"{at}tau{k + 1}=-1" for k in torque_alone]
    )
    rates = ", ".join(f"{at}dq{k + 1}=-1, {at}ddq{k + 1}=-1" for k, _ in reversed_)
    return (
        f"hint: --units {cols} reads {'it' if len(reversed_) == 1 else 'them'} so{where} "
        f"(and {rates} for the log's velocity and acceleration columns, if it has them"
        + ("; the motors' columns of this motor-side log" if motors else "")
        + ")"
    )


def _reversed_line(
    robot: Robot,
    drive: Drive | None,
    motion: NDArray[np.bool_],
    torque: NDArray[np.bool_],
    sums: tuple[float, float, float],
    file: str | None = None,
) -> str:
    """:func:`reversed_joint`'s finding: the columns reversed (``motion``, n) and the
    efforts negated (``torque``, n) named in the log's own columns (a motor-side log's
    motors), what is left reversed and as read (``sums``: those and the torques' sums of
    squares), the ``--units`` entries (``file``'s own where given)."""
    left, read, total = sums
    motors = drive is not None and drive.side == "motor"
    names = [f"motor {k + 1}" if motors else robot.joint_names[k] for k in range(robot.n)]
    rev = np.flatnonzero(motion)
    alone = np.flatnonzero(torque & ~motion)
    one = rev.size == 1
    what = [
        ("its " if one else f"{names[k]}'s ") + ("position and torque" if torque[k] else "position")
        for k in rev
    ] + [f"{names[k]}'s torque" for k in alone]
    if not one and alone.size == 0 and len(set(torque[rev].tolist())) == 1:  # all alike
        what = ["their positions and torques" if torque[rev[0]] else "their positions"]
    single = len(what) == 1 and " and " not in what[0] and not what[0].startswith("their")
    gears = (
        file is None and drive is not None and not drive.is_coupled and bool(np.all(torque[rev]))
    )
    return (
        f"{', '.join(names[k] for k in rev)} {'looks' if one else 'look'} recorded reversed: "
        f"{', '.join(what)} {'has' if single else 'have'} the opposite sign to the model's "
        f"convention (with {'it' if one else 'them'} reversed, the model and each "
        + (
            "motor's own friction and rotor"
            if drive is not None
            else "joint's own friction and armature"
        )
        + f" leave a residual of {np.sqrt(left / total):.2g} of the links' RMS torque, "
        f"against {np.sqrt(read / total):.2g} as read): a motor or encoder mounted the "
        "other way; "
        + reversal_hint(
            [(int(k), bool(torque[k])) for k in rev],
            [int(k) for k in alone],
            file,
            motors,
            " in this recording alone (the others read right)" if file else "",
        )  # fmt: skip
        + (
            "; or a negative gear_ratio in the drive file, a motor turning the other way"
            if gears
            else ""
        )
    )


def _left_over(
    r: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    drive: Drive | None = None,
    columns: Sequence[_GroupColumns] | None = None,
) -> float:
    """The sum of squares [N^2 m^2] of the residuals ``r`` (N, n) left by each joint's own
    viscous, Coulomb, offset and armature columns (``dq``, ``sign(dq)``, 1, ``ddq``); with
    a ``drive``, each motor's where its friction acts (``K_f^T`` of those of ``K_f dq``)
    and its rotor's (``K^T`` of ``K ddq``), the joints a motor couples fitted together
    with the friction of those no motor turns alone (:func:`_own_terms`). ``columns``:
    :func:`_group_columns` at ``dq``, ``ddq`` when the caller has them already."""
    return sum(g.left for g in _group_fits(r, dq, ddq, drive, columns))


@dataclass(frozen=True)
class _OwnTerms:
    """One group's least-squares fit in :func:`_own_terms`: its motors (joints), per motor
    the coefficients ``fv, fc, fo, Ia`` (4,) and their covariance (4, 4) (white-noise
    formula), the residual sum of squares ``left`` [N^2 m^2], per motor the mean of
    ``|v|`` and of ``v^2`` at its velocities ``v``, and per motor the power [W] its
    friction dissipates with its standard deviation (:func:`_power`: with that of the
    joints it turns that no motor turns alone, a coupled wrist's last)."""

    motors: list[int]
    coef: NDArray[np.float64]
    cov: NDArray[np.float64]
    left: float
    speed: NDArray[np.float64]
    power: NDArray[np.float64]


def _shared_joints(Kf: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The joints (n,) no motor turns alone where friction acts (``Kf``, motors x joints):
    a coupled wrist's joint whose motor turns the joint before it too. Friction at such a
    joint (a description's, at the joints) is no motor's friction, and the motors' own
    terms alone leave it (two clean recordings of a coupled wrist left 0.2 to 0.4 of the
    sum of squares of one recording's motor 6 negated)."""
    alone = (Kf != 0).sum(axis=1) == 1
    covered = (Kf[alone] != 0).any(axis=0)
    out: NDArray[np.bool_] = ~covered & (Kf != 0).any(axis=0)
    return out


#: A shared joint's viscous friction is fitted beside its group's motors' when the part of
#: its map (``e_j e_j^T``) outside theirs (``Kf_k^T Kf_k``) and the shared joints' before
#: keeps at least this share of its norm (a differential's is theirs: ``K^T K`` of two
#: motors that each turn both joints spans ``1`` with the motors' viscous terms).
SHARED_VISCOUS_INDEPENDENCE = 1e-6


def _viscous_free(Kf: NDArray[np.float64], shared: Sequence[int]) -> list[bool]:
    """Per joint of ``shared`` (positions in a group whose friction map is ``Kf``, motors x
    joints): whether its viscous friction is independent of the motors' and the shared
    joints' before it (:data:`SHARED_VISCOUS_INDEPENDENCE`); the others' column is zero."""
    m = Kf.shape[1]
    basis = [np.outer(row, row).ravel() for row in Kf if np.any(row)]
    out = []
    for j in shared:
        e = np.zeros((m, m))
        e[j, j] = 1.0
        B = np.array([b / np.linalg.norm(b) for b in basis]).T
        left = e.ravel() - B @ np.linalg.lstsq(B, e.ravel(), rcond=None)[0]
        free = bool(np.linalg.norm(left) >= SHARED_VISCOUS_INDEPENDENCE)
        out.append(free)
        if free:
            basis.append(e.ravel())
    return out


def _own_terms(
    r: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    drive: Drive | None = None,
    columns: Sequence[_GroupColumns] | None = None,
) -> list[_OwnTerms]:
    """Each joint's (motor's) own viscous, Coulomb, offset and armature coefficients fitted
    to the residuals ``r`` (N, n), group by group (:func:`_motor_groups`: a coupled wrist's
    joints together), as :func:`_left_over` describes; in a coupled group, beside the
    motors', the viscous and Coulomb friction of the joints no motor turns alone
    (:func:`_shared_joints`), at the joint. ``columns``: :func:`_group_columns` at ``dq``,
    ``ddq`` when the caller has them already (or the groups of them it wants)."""
    Kf = np.eye(r.shape[1]) if drive is None else drive.friction_transmission
    out = []
    for fit in _group_fits(r, dq, ddq, drive, columns):
        X, motors, v = fit.columns.X, fit.columns.motors, fit.columns.v
        coef, left = fit.coef, fit.left
        dof = max(X.shape[0] - X.shape[1], 1)
        cov = (left / dof) * np.linalg.pinv(X.T @ X)
        m = len(motors)
        blocks = np.array([cov[4 * i : 4 * i + 4, 4 * i : 4 * i + 4] for i in range(m)])
        speed = np.array([[np.mean(np.abs(v[:, k])), np.mean(v[:, k] ** 2)] for k in motors])
        grads = np.zeros((m, X.shape[1]))  # d power / d coef, per motor
        for i, k in enumerate(motors):
            grads[i, 4 * i : 4 * i + 2] = speed[i, 1], speed[i, 0]
            for c, (j, unit) in enumerate(fit.columns.at_joint):
                grads[i, 4 * m + c] = unit if Kf[k, j] != 0 else 0.0
        power = np.array(
            [[g @ coef, math.sqrt(max(float(g @ cov @ g), 0.0))] for g in grads], dtype=np.float64
        ).reshape(m, 2)
        coefs = np.asarray(coef[: 4 * m], dtype=np.float64).reshape(m, 4)
        out.append(_OwnTerms(motors, coefs, blocks, left, speed, power))
    return out


@dataclass(frozen=True, slots=True)
class _GroupColumns:
    """One group's columns in :func:`_group_columns`: its joints and motors, the columns
    ``X`` (N m, c), per column at a joint (after the motors' 4 each) that joint and its
    power per unit, and every motor's velocities ``v`` (N, motors)."""

    joints: list[int]
    motors: list[int]
    X: NDArray[np.float64]
    at_joint: list[tuple[int, float]]
    v: NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class _GroupFit:
    """One group's least squares in :func:`_group_fits`: its columns (:class:`_GroupColumns`),
    the coefficients (c,) and the residual sum of squares ``left`` [N^2 m^2]."""

    columns: _GroupColumns
    coef: NDArray[np.float64]
    left: float


def _group_columns(
    dq: NDArray[np.float64], ddq: NDArray[np.float64], drive: Drive | None
) -> list[_GroupColumns]:
    """The columns of :func:`_own_terms`, group by group, at the joint velocities ``dq``
    and accelerations ``ddq`` (N, n): the same for every residual fitted at those states."""
    n = dq.shape[1]
    Kf = np.eye(n) if drive is None else drive.friction_transmission
    K = np.eye(n) if drive is None else drive.transmission
    v, a = dq @ Kf.T, ddq @ K.T
    shared = _shared_joints(Kf)
    out = []
    for joints, motors in _motor_groups((K != 0) | (Kf != 0)):
        cols = []
        for k in motors:  # motor k's columns at the group's joints: (N, m) each
            for f in (v[:, k], np.sign(v[:, k]), np.ones(len(dq))):
                cols.append(f[:, None] * Kf[k, joints])
            cols.append(a[:, k, None] * K[k, joints])
        extra = [j for j in joints if shared[j]] if len(joints) > 1 else []
        viscous = _viscous_free(Kf[np.ix_(motors, joints)], [joints.index(j) for j in extra])
        at_joint: list[tuple[int, float]] = []  # per column: its joint, its power per unit
        for j, free in zip(extra, viscous, strict=True):  # a joint no motor turns alone
            at = np.asarray(joints) == j
            if free:
                cols.append(dq[:, j, None] * at)
                at_joint.append((j, float(np.mean(dq[:, j] ** 2))))
            cols.append(np.sign(dq[:, j, None]) * at)
            at_joint.append((j, float(np.mean(np.abs(dq[:, j])))))
        X = np.stack(cols, axis=-1).reshape(len(dq) * len(joints), len(cols))
        out.append(_GroupColumns(joints, motors, X, at_joint, v))
    return out


def _group_fits(
    r: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    drive: Drive | None,
    columns: Sequence[_GroupColumns] | None = None,
) -> Iterator[_GroupFit]:
    """The least squares of :func:`_own_terms`, group by group: what :func:`_left_over`
    reads, without the coefficients' covariance and powers. ``columns``:
    :func:`_group_columns` at ``dq``, ``ddq`` when the caller has them already."""
    for c in _group_columns(dq, ddq, drive) if columns is None else columns:
        y = r[:, c.joints].reshape(-1)
        coef = np.asarray(np.linalg.lstsq(c.X, y, rcond=None)[0], dtype=np.float64)
        left = float(np.sum((y - c.X @ coef) ** 2))
        yield _GroupFit(c, coef, left)


#: A motor's (joint's) friction and rotor read of the opposite sign in one recording to
#: another's (:func:`opposite_friction_among`) when each is at least this many standard
#: deviations from zero (white-noise formula: samples a few ms apart are correlated, so a
#: wide margin).
OWN_TERMS_SIGNIFICANCE = 8.0
#: ... and the one's size at least this share of the other's (a sign, not a drift).
OWN_TERMS_SIZE_SHARE = 0.3


def _own_signs(
    robot: Robot, log: TorqueLog, drive: Drive | None
) -> dict[int, tuple[float, float, float, float, float, float]] | None:
    """Per motor (joint) of a log as recorded: the power its fitted friction dissipates
    (``fc mean|v| + fv mean(v^2)``) and the rotor inertia fitted (``Ia``), each with its
    standard deviation, fitted to what the robot's links leave of its torques
    (:func:`_own_terms`): both positive for torques of the right sign; then ``mean|v|``
    and ``mean(v^2)`` at the motor. None: too few samples with known accelerations."""
    side = _modelled(robot, log, drive)
    if side is None:
        return None
    out = {}
    for g in _own_terms(side.rec.joint_torques - side.model, side.dq, side.ddq, side.rec.drive):
        for i, k in enumerate(g.motors):
            power, power_std = _power(g, i)
            ia, ia_std = float(g.coef[i, 3]), math.sqrt(g.cov[i][3, 3])
            out[k] = (power, power_std, ia, ia_std, float(g.speed[i, 0]), float(g.speed[i, 1]))
    return out


def _power(g: _OwnTerms, i: int) -> tuple[float, float]:
    """The power [W] the friction fitted to motor ``g.motors[i]`` dissipates at its speeds
    (``fc mean|v| + fv mean(v^2)``, with that of the joints it turns that no motor turns
    alone at theirs) and its standard deviation."""
    return float(g.power[i, 0]), float(g.power[i, 1])


@dataclass(frozen=True, slots=True)
class _Modelled:
    """A log as recorded (:class:`_Recorded`), its velocities and accelerations at the
    joints (N, n) and the robot's rigid-body torques there [N m] (N, n), its spring's
    included."""

    rec: _Recorded
    dq: NDArray[np.float64]
    ddq: NDArray[np.float64]
    model: NDArray[np.float64]


def _modelled(robot: Robot, log: TorqueLog, drive: Drive | None) -> _Modelled | None:
    """:class:`_Modelled` of ``log`` (None: too few samples with known accelerations)."""
    rec = _recorded(log, drive)
    if rec is None:
        return None
    q, dq, ddq = rec.joint_states()
    model = rnea(robot, q, dq, ddq)
    if robot.spring is not None:
        model = model + robot.spring.torques(q)
    return _Modelled(rec, dq, ddq, model)


def _comparable(flipped: tuple, right: tuple, share: float) -> bool:
    """Whether a motor's terms read of the opposite sign (``flipped``: its
    :func:`_own_signs` values and the signs of its power and inertia) are of about the
    size of another recording's of the right sign (at least ``share`` of them), judged on
    the power where both tell it, else on the inertia."""
    (p, _, ia, *_), sp, si = flipped
    (q, _, ib, *_), sq, sj = right
    if sp and sq:
        return abs(p) >= share * abs(q)
    return bool(si and sj) and abs(ia) >= share * abs(ib)


def opposite_friction_among(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str],
    drive: Drive | None = None,
    *,
    reference: ArrayLike | None = None,
) -> str | None:
    """The finding that one recording's torques of a motor (joint) have the opposite sign
    to another recording's, read from the motor's own friction and rotor (:func:`_own_signs`):
    the friction dissipates and the inertia is positive in one, both the other way in
    the other, each beyond :data:`OWN_TERMS_SIGNIFICANCE` standard deviations and of a
    comparable size (:data:`OWN_TERMS_SIZE_SHARE`); or None.

    The check the whole rigid-body torques make (:func:`opposite_sign`) does not tell the
    sign of a joint whose torques the links barely make (a geared wrist: its rotor and
    friction outweigh them), and a fit of several recordings, one of them of the opposite
    sign there, averages that joint's friction to nothing (a current-logged UR5's motor
    4 flipped in one of two recordings: fitted to 9.4 %, its Coulomb friction left out,
    springs suggested). ``logs`` are as recorded (read through ``drive``); the hint is the
    file's own ``--units`` entry in the log's columns.

    ``reference`` (n, 3), a model's own ``fv, fc, Ia`` per motor (joint), where the drive's
    friction acts [N m s/rad, N m, kg m^2]: each recording is compared with it too, its
    power at the recording's own speeds (``fc mean|v| + fv mean(v^2)``), so that one
    recording alone is judged (a model identified on logs of the right sign dissipates
    where a flipped motor's fitted friction puts energy into the arm).

    A coupled wrist's motor (motor 6 turning joints 5 and 6) is judged with the friction of
    the joint no motor turns alone in its power (:func:`_own_terms`): the tutorial's arm,
    its description's friction at the joints, motor 6 negated in one of two recordings,
    had been fitted without a word (the clean file's motor-6 power 0.15 +- 0.02 W, short of
    :data:`OWN_TERMS_SIGNIFICANCE`, and the pooled fit left 0.40 with it negated; identify
    then judged the pair "poor", 0.68 %)."""
    if len(logs) < (1 if reference is not None else 2):
        return None
    if not np.any(robot.phi):  # the recordings' own terms compared with each other alone
        return opposite_among_pooled(robot, logs, names, drive)
    signs = [_own_signs(robot, log, drive) for log in logs]
    model = None if reference is None else np.asarray(reference, dtype=np.float64)
    z, share = OWN_TERMS_SIGNIFICANCE, OWN_TERMS_SIZE_SHARE

    def sign(x: float, sd: float) -> int:
        return 0 if not abs(x) > z * sd else (1 if x > 0 else -1)

    def of_model(k: int, s: tuple[float, ...]) -> tuple | None:
        """Motor k of the model at the speeds ``s`` of a recording's terms."""
        if model is None or k >= model.shape[0]:
            return None
        fv, fc, ia = (float(x) for x in model[k])
        power = fc * s[4] + fv * s[5]
        return ((power, 0.0, ia, 0.0), sign(power, 0.0), sign(ia, 0.0))

    found: dict[int, list[int]] = {}  # recording: its motors of the opposite sign
    for k in range(logs[0].n):
        each = [
            None
            if s is None or k not in s
            else (s[k], sign(s[k][0], s[k][1]), sign(s[k][2], s[k][3]))
            for s in signs
        ]
        right = [e for e in each if e is not None and min(e[1:]) >= 0 and max(e[1:]) > 0]
        for r, e in enumerate(each):
            if e is None or not (max(e[1:]) <= 0 and min(e[1:]) < 0):
                continue
            mine = signs[r]
            assert mine is not None  # e is not None
            own = of_model(k, mine[k])
            ok = [o for o in (*right, own) if o is not None and min(o[1:]) >= 0 < max(o[1:])]
            if any(_comparable(e, o, share) for o in ok):
                found.setdefault(r, []).append(k)
    found = _pooled_confirmed(robot, logs, drive, found)
    if not found:  # no recording reads right there to compare with (two recordings)
        return opposite_among_pooled(robot, logs, names, drive)
    r = min(found)
    motors = found[r]
    who = "motor" if drive is not None and drive.side == "motor" else "joint"
    named = ", ".join(f"motor {k + 1}" if who == "motor" else robot.joint_names[k] for k in motors)
    others = [names[i] for i in range(len(names)) if i != r and i not in found]
    mine = signs[r]
    assert mine is not None  # found holds recordings with their terms
    power = any(mine[k][0] < -z * mine[k][1] for k in motors)
    inertia = any(mine[k][2] < -z * mine[k][3] for k in motors)
    said = [
        f"the friction of {named}{_with_shared(robot, drive, motors)} fitted to {names[r]} puts "
        "energy into the arm"
        if power
        else "",
        (
            "its rotor inertia fitted there"
            if power
            else f"the rotor inertia of {named} fitted to {names[r]}"
        )
        + " is negative"
        if inertia
        else "",
    ]
    what = " and ".join(x for x in said if x)
    where = (
        f"in {', '.join(others) or 'the other recordings'} its friction and rotor inertia have "
        "the right sign"
        if others or model is None
        else "the model's identified friction and rotor inertia have the right sign"
    )
    against = (
        f"those of {', '.join(others) or 'the other recordings'}"
        if others or model is None
        else "the model's"
    )
    return (
        f"{names[r]}: the torques of {named} have the opposite sign to {against}: {what}, "
        f"while {where}: {names[r]} was likely logged with another sign convention "
        f"({_unseen(robot, drive, motors)}, so the check against the model's torques cannot "
        "tell); "
        f"hint: --units {flip_entries(motors, names[r] if len(names) > 1 else None)} reads it "
        "flipped"
    )


#: Of several recordings, a motor's (joint's) torques read of opposite signs in them
#: (:func:`opposite_among_pooled`) when one friction, rotor and offset fitted to them
#: pooled leave at most this share of the sum of squares they leave as read, once one
#: recording's column is negated (two FR3 recordings with a 1.2 kg payload the
#: description lacks, joint 7 negated in one: 0.056; clean pairs: 2.5 or more).
DISAGREE_SHARE = 0.25
#: ... and the model's rigid-body torques tell which recording when negating it leaves at
#: most this share of what negating the next likeliest leaves (the pair above: 0.26).
TOLD_SHARE = 0.5
#: ... or the friction's power, dissipated with it negated and pushing with the other,
#: is at least this share of the RMS of the torques the rigid bodies leave times the
#: mean speed (the pair above: 0.41 W at a scale of 0.40 W; a Panda's joint 7 without
#: friction, of a description without inertial parameters: 0.017 W at 0.19 W).
DISSIPATION_SHARE = 0.3


def _pooled_fits(
    sides: Sequence[_Modelled],
    signs: Sequence[NDArray[np.float64]],
    motor: int | None = None,
    columns: Sequence[_GroupColumns] | None = None,
) -> dict[int, tuple[float, float, float, float]]:
    """Per motor (joint): the sum of squares [N^2 m^2] its group's own terms
    (:func:`_own_terms`: one friction, rotor and offset for every recording) leave of what
    the robot's rigid-body torques leave of the recordings pooled, each column times its
    recording's ``signs`` (n,), the power [W] that friction dissipates with its standard
    deviation (:func:`_power`), and the scale of that power [W]: the RMS of what the
    rigid-body torques leave times the mean speed, at the joints the motor turns. Of the
    group of ``motor`` alone when given; ``columns``: :func:`_pooled_columns` of
    ``sides`` when the caller has them already."""
    r = np.concatenate(
        [s.rec.signed_torques(sign) - s.model for s, sign in zip(sides, signs, strict=True)]
    )
    dq = np.concatenate([s.dq for s in sides])
    ddq = np.concatenate([s.ddq for s in sides])
    drive = sides[0].rec.drive
    turns = np.eye(r.shape[1]) if drive is None else drive.friction_transmission
    each = np.sqrt(np.mean(r**2, axis=0)) * np.mean(np.abs(dq), axis=0)  # (n,) [W]
    groups = _group_columns(dq, ddq, drive) if columns is None else columns
    if motor is not None:
        groups = [c for c in groups if motor in c.motors]
    out = {}
    for g in _own_terms(r, dq, ddq, drive, groups):
        for i, k in enumerate(g.motors):
            out[k] = (g.left, *_power(g, i), float(np.max(each[turns[k] != 0], initial=0.0)))
    return out


def _pooled_columns(sides: Sequence[_Modelled]) -> list[_GroupColumns]:
    """The own terms' columns (:func:`_group_columns`) of the recordings ``sides`` pooled,
    as :func:`_pooled_fits` fits them (the same for every sign of the torques)."""
    dq = np.concatenate([s.dq for s in sides])
    ddq = np.concatenate([s.ddq for s in sides])
    return _group_columns(dq, ddq, sides[0].rec.drive)


def _told(
    fits: Sequence[tuple[float, float, float, float]],
    order: Sequence[int],
    z: float,
    residual: bool = True,
) -> int | None:
    """Of the hypotheses ``fits`` (per recording negated: :func:`_pooled_fits`' values),
    ``order`` (best first), the recording the model tells negated: its negation leaves at
    most :data:`TOLD_SHARE` of the next's and its friction does not push (where the
    residual tells, ``residual``: a description's torques, or a third recording); or, the
    two alike, the one whose friction dissipates where the other's pushes (beyond ``z``
    standard deviations and :data:`DISSIPATION_SHARE` of its scale); None when neither
    tells. Two recordings of a description without inertial parameters differ in what
    they leave by the links' torques neither holds: a coupled wrist without friction,
    motor 5 negated in one of two 3 s recordings, left 0.45 with the other negated, and
    the right file was named by chance."""
    b, c = order[0], order[1]

    def sign(fit: tuple[float, ...]) -> int:
        _, p, sd, scale = fit
        return 0 if abs(p) <= max(z * sd, DISSIPATION_SHARE * scale) else int(np.sign(p))

    pb, pc = sign(fits[b]), sign(fits[c])
    if residual and fits[b][0] <= TOLD_SHARE * fits[c][0]:
        return b if pb >= 0 else None
    if pb > 0 > pc:
        return b
    return c if pc > 0 > pb else None


def _pooled_confirmed(
    robot: Robot, logs: Sequence[TorqueLog], drive: Drive | None, found: dict[int, list[int]]
) -> dict[int, list[int]]:
    """Of ``found`` (recording: its motors read of the opposite sign by their own terms),
    those whose negation in that recording lets one friction, rotor and offset fitted to
    every recording pooled leave at most :data:`DISAGREE_SHARE` of what they leave as read
    (:func:`_pooled_fits`); all of them for one recording judged against a model alone.
    The own terms of a short recording take what the description lacks: two clean 3 s
    Panda recordings with a 1.2 kg payload the description lacked had joint 2 or 3
    named in one of them (their pooled fit left 0.66 or more with it negated)."""
    if not found or len(logs) < 2:
        return found
    sides = [_modelled(robot, log, drive) for log in logs]
    if any(x is None for x in sides):
        return found
    kept: list[_Modelled] = [x for x in sides if x is not None]
    n = kept[0].rec.tau.shape[1]
    columns = _pooled_columns(kept)
    read = _pooled_fits(kept, [np.ones(n)] * len(kept), columns=columns)
    out: dict[int, list[int]] = {}
    for r, motors in found.items():
        for k in motors:
            signs = [np.ones(n) for _ in kept]
            signs[r][k] = -1.0
            if _pooled_fits(kept, signs, k, columns)[k][0] <= DISAGREE_SHARE * read[k][0]:
                out.setdefault(r, []).append(k)
    return out


def opposite_among_pooled(
    robot: Robot, logs: Sequence[TorqueLog], names: Sequence[str], drive: Drive | None = None
) -> str | None:
    """The finding that the recordings' torques of a motor (joint) read of opposite signs,
    where none reads right to compare with (:func:`opposite_friction_among`: of two, each
    the other's only other): one friction, rotor and offset (:func:`_own_terms`) fitted to
    what the robot's rigid-body torques leave of the recordings pooled leave at most
    :data:`DISAGREE_SHARE` of their sum of squares as read once one recording's column
    is negated; or None.

    The recording is named when the model tells it (:func:`_told`): its rigid-body torques
    leave far less with that one negated than with the other (:data:`TOLD_SHARE`), or the
    friction fitted dissipates with that one negated and pushes with the other; else the
    disagreement is named with both recordings and both ``--units`` entries (a robot
    without inertial parameters, a joint with negligible friction). Before, two FR3
    recordings, joint 7's torques negated in one, were fitted without a word, joint 7's
    friction averaged to nothing, its held-out error 195 % and the other file blamed."""
    sides = [_modelled(robot, log, drive) for log in logs]
    have = [r for r, s in enumerate(sides) if s is not None]
    if len(have) < 2:
        return None
    kept: list[_Modelled] = [s for s in sides if s is not None]
    n = kept[0].rec.tau.shape[1]
    one = [np.ones(n) for _ in kept]
    columns = _pooled_columns(kept)
    read = _pooled_fits(kept, one, columns=columns)
    told: dict[int | None, list[tuple[int, list[int], tuple]]] = {}
    for k in range(n):
        fits = []
        for r in range(len(kept)):
            signs = [x.copy() for x in one]
            signs[r][k] = -1.0
            fits.append(_pooled_fits(kept, signs, k, columns)[k])
        order = sorted(range(len(kept)), key=lambda r: fits[r][0])
        if not fits[order[0]][0] <= DISAGREE_SHARE * read[k][0]:
            continue
        which = _told(fits, order, OWN_TERMS_SIGNIFICANCE, bool(np.any(robot.phi)) or len(kept) > 2)
        pair = [have[r] for r in ([which] if which is not None else sorted(order[:2]))]
        mine, other = (order[0], order[1]) if which != order[1] else (order[1], order[0])
        said = (fits[order[0]][0] / read[k][0], fits[mine], fits[other], other)
        told.setdefault(None if which is None else pair[0], []).append((k, pair, said))
    if not told:
        return None
    motors = drive is not None and drive.side == "motor"
    named = lambda ks: ", ".join(  # noqa: E731
        f"motor {k + 1}" if motors else robot.joint_names[k] for k in ks
    )
    first = min((x for x in told if x is not None), default=None)
    if first is None:
        pair = told[None][0][1]
        ks = [k for k, p, _ in told[None] if p == pair]
        left = max(x[0] for k, p, x in told[None] if p == pair)
        files = [names[i] for i in pair]
        return (
            f"{', '.join(files)}: the torques of {named(ks)} have opposite signs in "
            f"{' and '.join(files)}: one friction, rotor inertia and offset fit both "
            f"recordings {_times(left)} times better with either file's {_columns(ks)} "
            f"negated (residual {left:.2g} of that as read), but neither the robot "
            "description's torques nor the friction's sign tell which file is the wrong "
            "one (a description without inertial parameters, or a joint of negligible "
            f"friction); hint: --units {flip_entries(ks, files[0])} or --units "
            f"{flip_entries(ks, files[1])}, whichever file was logged with another sign "
            "convention than the robot's"
        )
    r = first
    ks = [k for k, _, _ in told[r]]
    others = [names[i] for i in have if i != r]
    k, _, (left, mine, alt, j) = told[r][0]
    other = names[have[j]]
    ratio = mine[0] / alt[0]
    tells = "the robot description's torques" if np.any(robot.phi) else "the recordings"
    agree = (
        f"; {tells} agree with {other} (residual {ratio:.2g} of that with {other}'s negated "
        "instead), and"
        if ratio <= TOLD_SHARE and (np.any(robot.phi) or len(kept) > 2)
        else f"; {tells} fit either about as well ({ratio:.2g}), and"
        if np.any(robot.phi)
        else ":"  # two recordings of a bare description: the friction alone tells
    )
    pushes = (
        f"with {other}'s negated instead it would put {-alt[1]:.3g} W into the arm"
        if alt[1] < 0
        else f"{alt[1]:.3g} W with {other}'s negated instead"
    )
    return (
        f"{names[r]}: the torques of {named(ks)} have the opposite sign to those of "
        f"{', '.join(others)}: one friction, rotor inertia and offset fit the recordings "
        f"{_times(left)} times better with {names[r]}'s {_columns(ks)} negated (residual "
        f"{left:.2g} of that as read){agree} the friction so fitted dissipates "
        f"{mine[1]:.3g} W ({pushes}): {names[r]} was "
        f"likely logged with another sign convention; hint: --units "
        f"{flip_entries(ks, names[r])} reads it flipped"
    )


def _times(share: float) -> str:
    """How many times better a fit leaving ``share`` of what another leaves is, rounded
    for a sentence ("18", "3.3")."""
    x = 1.0 / share if share > 0 else math.inf
    return f"{x:.2g}" if x < 10 else f"{x:,.0f}" if x < 1e6 else f"{x:.1e}"


def _coupled(drive: Drive | None, k: int) -> tuple[list[int], list[int]]:
    """The joints and motors (from 0) of motor ``k``'s group (:func:`_motor_groups`) when
    a motor-side ``drive`` couples it (its torque reaches several joints, or a joint's
    takes another motor's too: a coupled wrist), else none."""
    if drive is None or drive.side != "motor":
        return [], []
    for joints, motors in _motor_groups(drive.transmission != 0):
        if k in motors and len(motors) > 1:
            return joints, motors
    return [], []


def _shared_of(drive: Drive | None, ks: Sequence[int]) -> list[int]:
    """The joints (from 0) whose friction :func:`_own_terms` fits beside motors ``ks``'
    own: those of a coupled wrist no motor turns alone that these turn."""
    if drive is None or drive.side != "motor":
        return []
    Kf = drive.friction_transmission
    shared = _shared_joints(Kf)
    return sorted({j for k in ks for j in _coupled(drive, k)[0] if shared[j] and Kf[k, j] != 0})


def _with_shared(robot: Robot, drive: Drive | None, ks: Sequence[int]) -> str:
    """ " (with that of joint6, which no motor turns alone)": the joints whose friction
    :func:`_own_terms` counts with motors ``ks``' (a coupled wrist's), or ""."""
    if drive is None or drive.side != "motor":
        return ""
    js = _shared_of(drive, ks)
    if not js:
        return ""
    return (
        f" (with that of {', '.join(robot.joint_names[j] for j in js)}, which no motor turns alone)"
    )


def _unseen(robot: Robot, drive: Drive | None, ks: Sequence[int]) -> str:
    """Why the check against the model's torques does not see motors (joints) ``ks``
    negated: the links barely load them, or a coupled wrist's motor turns several joints,
    none of whose torques its negation negates alone."""
    groups = {tuple(_coupled(drive, k)[0]): _coupled(drive, k)[1] for k in ks}
    groups.pop((), None)
    if not groups:
        who = ", ".join(f"motor {k + 1}" for k in ks)
        if drive is None or drive.side != "motor":
            who = ", ".join(robot.joint_names[k] for k in ks)
        return f"the links barely load {who}"
    said = "; ".join(
        f"the torques of {' and '.join(robot.joint_names[j] for j in js)} take those of "
        f"{' and '.join(f'motor {k + 1}' for k in ms)}"
        for js, ms in groups.items()
    )
    return (
        f"{said}, a coupled wrist: negating one motor's negates no joint's, and the links "
        "barely load the wrist"
    )


def _columns(ks: Sequence[int]) -> str:
    """The log's effort columns of motors (joints) ``ks`` (from 0): "tau7", "tau5, tau7"."""
    return ", ".join(f"tau{k + 1}" for k in ks)


@dataclass(frozen=True, slots=True)
class SignFinding:
    """One recording's sign finding (:func:`recording_sign_findings`).

    Attributes
    ----------
    name : str
        The recording's name (its file).
    kind : {"reversed", "opposite"}
        Columns recorded reversed (position and effort, :func:`reversed_joint`), or torques
        of the opposite sign (:func:`opposite_sign_among`, :func:`opposite_friction_among`).
    text : str
        The finding, without the name: the joints (motors) and the ``--units`` entries.
    """

    name: str
    kind: str
    text: str


def recording_sign_findings(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str],
    drive: Drive | None = None,
    *,
    sides: Sequence[TorqueLog] | None = None,
    reference: ArrayLike | None = None,
    first: bool = False,
    among: bool = True,
) -> tuple[SignFinding, ...]:
    """The sign checks of several recordings, in the one order ``identify`` refuses by and
    ``validate`` and ``observe`` judge by: per recording, columns recorded reversed
    (:func:`reversed_joint`, on the log as recorded through ``drive``), else torques of
    the opposite sign to the robot's (:func:`opposite_sign_among`, on its joint side,
    against the others'); then, among the recordings not found so, one whose motor
    (joint) the links barely load reads of the opposite sign to the others', told by its
    own friction and rotor (:func:`opposite_friction_among`; against ``reference`` too,
    a model's ``fv, fc, Ia`` (n, 3), so that one recording alone is judged).

    Parameters
    ----------
    robot : Robot
    logs : sequence of TorqueLog
        The recordings as recorded (the drive's side and effort), each with enough samples
        (:func:`too_few_samples`).
    names : sequence of str
        One name per recording.
    drive : Drive, optional
        What reads ``logs`` (:func:`~dynid.identification.log.joint_side_log`).
    sides : sequence of TorqueLog, optional
        The recordings at the joints, when already mapped (default: mapped here).
    reference : array_like, shape (n, 3), optional
        As :func:`opposite_friction_among`.
    first : bool
        Stop at the first finding (a check that refuses).
    among : bool
        Compare the recordings' own friction and rotors (False: logs that may hold
        contacts, whose external torques the motors' own terms would take for a sign).

    Returns
    -------
    tuple of SignFinding
        In the recordings' order, then the finding among them; empty when all read right.
    """
    if sides is None:
        sides = [joint_side_log(log, drive) for log in logs]
    out: list[SignFinding] = []
    reversals = [_reversal(robot, log, drive) for log in logs]
    for r, name in enumerate(names):
        if (mine := reversals[r]) is not None:
            own = _reversed_alone(mine, [x for i, x in enumerate(reversals) if i != r])
            line = _reversed_line(robot, drive, *mine, file=name if own else None)
            out.append(SignFinding(name, "reversed", line))
        else:
            others = (x for i, x in enumerate(sides) if i != r)
            if (opposite := opposite_sign_among(robot, sides[r], name, others)) is not None:
                out.append(SignFinding(name, "opposite", opposite))
        if first and out:
            return tuple(out)
    if not among:
        return tuple(out)
    said = {f.name for f in out}
    rest = [r for r, name in enumerate(names) if name not in said]
    kept = [names[r] for r in rest]
    found = opposite_friction_among(
        robot, [logs[r] for r in rest], kept, drive, reference=reference
    )
    if found is not None:
        name = next(n for n in (", ".join(kept), *kept) if found.startswith(f"{n}: "))
        out.append(SignFinding(name, "opposite", found.removeprefix(f"{name}: ")))
    return tuple(out)


def _reversed_alone(
    mine: tuple[NDArray[np.bool_], NDArray[np.bool_], Any],
    others: Sequence[tuple[NDArray[np.bool_], NDArray[np.bool_], Any] | None],
) -> bool:
    """Whether a recording's reversal (``mine``: :func:`_reversal`'s columns and efforts)
    is its own: some other recording is not reversed so (its hint then names the file,
    ``rec2.csv:q4=-1``; an entry for every file would flip the others wrong)."""
    return any(
        o is None or not (np.array_equal(o[0], mine[0]) and np.array_equal(o[1], mine[1]))
        for o in others
    )


def _motor_groups(acts: NDArray[np.bool_]) -> list[tuple[list[int], list[int]]]:
    """The joints and motors ``acts`` (motors x joints: motor k acts on joint j) links,
    group by group: a joint alone with its motor, a coupled wrist's joints together."""
    group = list(range(acts.shape[1]))

    def root(j: int) -> int:
        while group[j] != j:
            j = group[j]
        return j

    for row in acts:
        on = np.flatnonzero(row)
        for j in on[1:]:
            group[root(int(j))] = root(int(on[0]))
    roots = sorted({root(j) for j in range(acts.shape[1])})
    out = []
    for g in roots:
        joints = [j for j in range(acts.shape[1]) if root(j) == g]
        out.append((joints, [int(k) for k in np.flatnonzero(acts[:, joints].any(axis=1))]))
    return out
