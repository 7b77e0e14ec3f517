"""A motor (joint) recorded reversed in one of several recordings, told by the other
recordings rather than by the robot description alone.

:func:`~dynid.identification.recorded_signs.reversed_joint` judges a log against the
description's rigid-body torques summed over every joint: a wrist's share of them is too
small for a reversal there to pass that whole-arm test. Here each recording is predicted by
the rigid-body regressor and each motor's own friction and rotor fitted to the OTHER
recordings (each recording its own offsets), and a motor's residual in that recording with
its columns as read is compared with its residual with them reversed (position and
effort: a motor mounted the other way); the few candidates are judged by one fit to every
recording pooled, against the columns as read and against the other recordings' reversed
instead. A motor's own friction and rotor cannot tell a reversal (both columns flip
together); the coupling with the links can, and a joint whose reversal the links do not
see (a last joint with a tool symmetric about its axis) is not named.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.torque import torque_regressor
from .log import TorqueLog
from .model_sign import MOTION_HALF_SPAN_S, MOTION_MIN_SAMPLES, motion_accelerations
from .recorded_signs import SignFinding, reversal_hint

__all__ = [
    "held_out_ratios",
    "reversed_among",
    "REVERSED_AMONG_SHARE",
    "REVERSED_POOLED_SHARE",
    "REVERSED_AMONG_PAIR_SHARE",
    "AMONG_SAMPLES",
]

#: A recording's motor is a candidate when, predicted by the fit to the other recordings,
#: what is left at the joints it reaches with its position and effort reversed is at most
#: this share of that as read (sums of squares), and reversing it lowers what is left of
#: the recording's every joint. Measured on simulated recordings (the docs page): reversed
#: motors 3e-6 to 0.3 (a geared Panda's, two 3 s recordings); clean recordings 0.93 or
#: more (a TIAGo arm's symmetric last joint), 0.30 for two 3 s geared Panda recordings,
#: which the pooled fit clears (:data:`REVERSED_POOLED_SHARE`).
REVERSED_AMONG_SHARE = 0.5
#: A candidate is named when one fit to every recording pooled leaves at the joints the
#: motor reaches, with its columns reversed in that recording, at most this share of what
#: it leaves as read: reversed motors named left 0.11 or less (a TIAGo arm's wrist motors
#: 0.061 and 0.006, a Panda's joint 7 0.08 to 0.11), clean candidates 0.63 or more.
REVERSED_POOLED_SHARE = 0.25
#: ... and at most this share of what it leaves with them reversed in every other
#: recording instead (the same data in the mirrored convention of the motor, which only
#: the description's kinematics tell apart: with two recordings each one's fit predicts
#: the other better reversed). Named: 0.21 or less; a joint whose reversal the links
#: barely see 0.57 or more (a coupled wrist's motor 7, a UR5's vertical first joint in two
#: recordings), a last joint with a tool symmetric about its axis about 1.
REVERSED_AMONG_PAIR_SHARE = 0.5
#: Samples per recording the check uses, evenly spaced (a statistic; its cost grows with
#: the samples times the joints).
AMONG_SAMPLES = 600
#: At most this many recordings and motors, those whose reversal leaves least held out
#: first, are judged by the pooled fit (:func:`_pooled_shares`): a fit to a recording
#: read reversed predicts the others better with other motors reversed too.
AMONG_CANDIDATES = 3


@dataclass(frozen=True, slots=True)
class _Sampled:
    """One recording's samples as recorded (the drive's side and effort): positions,
    velocities, accelerations and efforts (N, n)."""

    q: NDArray[np.float64]
    dq: NDArray[np.float64]
    ddq: NDArray[np.float64]
    tau: NDArray[np.float64]


def _sampled(log: TorqueLog) -> _Sampled | None:
    """:class:`_Sampled` of ``log`` at :data:`AMONG_SAMPLES` evenly spaced samples whose
    accelerations are known (:func:`motion_accelerations`), or None."""
    at = np.arange(0, log.n_samples, max(1, log.n_samples // AMONG_SAMPLES))
    found = motion_accelerations(log, at)
    if found is None:
        return None
    ddq, ok = found
    tau = log.tau[at]
    if log.ddq is None:  # derived: the efforts their mean over the same span
        tau = _window_mean(log, at)
        h = max(MOTION_HALF_SPAN_S, 1.5 * float(np.median(np.diff(log.t))))
        ok &= np.all(np.abs(log.dq[at]) > 2 * h * np.abs(ddq), axis=1)  # no turn within it
    if np.count_nonzero(ok) < MOTION_MIN_SAMPLES:
        return None
    return _Sampled(log.q[at][ok], log.dq[at][ok], ddq[ok], tau[ok])


def _window_mean(log: TorqueLog, at: NDArray[np.intp]) -> NDArray[np.float64]:
    """The efforts (at.size, n) at the samples ``at`` of ``log``, each the mean over the
    span the accelerations of :func:`motion_accelerations` are the mean over (+-
    :data:`MOTION_HALF_SPAN_S`, at least one and a half sample steps): the effort noise
    divided by the root of the samples in it (7 at 1 kHz), the accelerations' terms alike.
    Where the span leaves the log the value is unused (no acceleration there)."""
    t = log.t
    h = max(MOTION_HALF_SPAN_S, 1.5 * float(np.median(np.diff(t))))
    area = np.concatenate(
        [
            np.zeros((1, log.n)),
            np.cumsum(0.5 * (log.tau[1:] + log.tau[:-1]) * np.diff(t)[:, None], axis=0),
        ]
    )
    ts = t[at]
    hi, lo = np.minimum(ts + h, t[-1]), np.maximum(ts - h, t[0])
    span = np.maximum(hi - lo, 1e-300)
    out = np.column_stack(
        [(np.interp(hi, t, area[:, j]) - np.interp(lo, t, area[:, j])) / span for j in range(log.n)]
    )
    return out


def _rows(
    robot: Robot, s: _Sampled, drive: Drive | None, sign: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The rows of recording ``s`` with its columns times ``sign`` (n,): the joint
    torques [N m] (N, n) and their columns (N, n, p): the rigid-body regressor (10 n), each
    motor's viscous and Coulomb friction where its friction acts and its rotor (3 n), each
    joint's mean over the recording taken out (its own offsets)."""
    q, dq, ddq, tau = s.q * sign, s.dq * sign, s.ddq * sign, s.tau * sign
    n = robot.n
    Kf = np.eye(n) if drive is None else drive.friction_transmission
    K = np.eye(n) if drive is None else drive.transmission
    if drive is not None:
        q, dq, ddq = drive.joint_states(q, dq, ddq)
        tau = drive.joint_torques(tau)
    v, a = dq @ Kf.T, ddq @ K.T
    own = np.concatenate(
        [v[:, None, :] * Kf.T, np.sign(v)[:, None, :] * Kf.T, a[:, None, :] * K.T], axis=2
    )
    X = np.concatenate([torque_regressor(robot, q, dq, ddq), own], axis=2)
    return tau - tau.mean(axis=0), X - X.mean(axis=0)


Gram = tuple[NDArray[np.float64], NDArray[np.float64]]


def _gram(row: tuple[NDArray[np.float64], NDArray[np.float64]], w: NDArray[np.float64]) -> Gram:
    """The normal equations ``A^T A`` (p, p) and ``A^T b`` (p,) of one recording's rows
    (joint torques and columns), each joint's rows weighted by ``w`` (n,) [1/(N m)]."""
    y, X = row
    A = (X * w[None, :, None]).reshape(-1, X.shape[2])
    return A.T @ A, A.T @ (y * w).ravel()


def _fit(grams: Sequence[Gram]) -> NDArray[np.float64]:
    """The least-squares coefficients (p,) of the recordings whose normal equations are
    ``grams`` summed, each column scaled to unit norm (the minimum-norm solution where the
    rows do not determine them: the base parameters' combinations)."""
    G = sum((g for g, _ in grams), np.zeros_like(grams[0][0]))
    h = sum((x for _, x in grams), np.zeros_like(grams[0][1]))
    scale = np.sqrt(np.diag(G))
    scale[scale == 0] = 1.0
    coef = np.linalg.lstsq(G / np.outer(scale, scale), h / scale, rcond=1e-12)[0]
    out: NDArray[np.float64] = coef / scale
    return out


def _left(
    row: tuple[NDArray[np.float64], NDArray[np.float64]], coef: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Per joint (n,), the sum of squares [N^2 m^2] of what ``coef`` leaves of ``row``."""
    y, X = row
    out: NDArray[np.float64] = np.sum((y - X @ coef) ** 2, axis=0)
    return out


def _reaches(drive: Drive | None, n: int) -> list[NDArray[np.intp]]:
    """Per motor (joint), the joints whose torques its effort reaches."""
    if drive is None:
        return [np.array([k]) for k in range(n)]
    acts = (drive.transmission != 0) | (drive.friction_transmission != 0)
    return [np.flatnonzero(acts[k]) for k in range(n)]


@dataclass(frozen=True, slots=True)
class _Among:
    """The recordings as :func:`held_out_ratios` and :func:`reversed_among` judge them:
    their samples, rows as read (:func:`_rows`), each joint's weight [1/(N m)] (n,) (the
    root of its mean square left by one fit to them all) and, per motor, the joints its
    effort reaches."""

    robot: Robot
    drive: Drive | None
    sampled: list[_Sampled]
    rows: list[tuple[NDArray[np.float64], NDArray[np.float64]]]
    w: NDArray[np.float64]
    reach: list[NDArray[np.intp]]
    #: Per recording, the normal equations of its rows as read (:func:`_gram`).
    grams: list[Gram]
    #: :meth:`flipped`'s rows by recording and motor, computed once.
    seen: dict[tuple[int, int], tuple[NDArray[np.float64], NDArray[np.float64]]] = field(
        default_factory=dict, compare=False, repr=False
    )

    def flipped(self, r: int, k: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Recording ``r``'s rows with motor (joint) ``k``'s position and effort reversed."""
        if (r, k) not in self.seen:
            sign = np.ones(self.robot.n)
            sign[k] = -1.0
            self.seen[r, k] = _rows(self.robot, self.sampled[r], self.drive, sign)
        return self.seen[r, k]

    def left(
        self,
        row: tuple[NDArray[np.float64], NDArray[np.float64]],
        coef: NDArray[np.float64],
        k: int,
    ) -> float:
        """What ``coef`` leaves of ``row`` at the joints motor ``k`` reaches, each in units
        of its weight (dimensionless sum of squares)."""
        return float(np.sum((_left(row, coef) * self.w**2)[self.reach[k]]))


def _among(robot: Robot, logs: Sequence[TorqueLog], drive: Drive | None) -> _Among | None:
    """:class:`_Among` of ``logs``, or None for fewer than two or one too short to judge."""
    if len(logs) < 2:
        return None
    sampled = [_sampled(log) for log in logs]
    if any(s is None for s in sampled):
        return None
    kept = [s for s in sampled if s is not None]
    one = np.ones(robot.n)
    rows = [_rows(robot, s, drive, one) for s in kept]
    coef = _fit([_gram(r, one) for r in rows])
    pooled = sum((_left(r, coef) for r in rows), np.zeros(robot.n))
    count = sum(r[0].shape[0] for r in rows)
    w = 1.0 / np.sqrt(np.maximum(pooled / count, 1e-30))
    grams = [_gram(r, w) for r in rows]
    return _Among(robot, drive, kept, rows, w, _reaches(drive, robot.n), grams)


def held_out_ratios(
    robot: Robot, logs: Sequence[TorqueLog], drive: Drive | None = None
) -> NDArray[np.float64] | None:
    """Per recording and motor (joint) (R, n): what the fit to the other recordings leaves
    of the joints that motor reaches, with its position and effort reversed in that
    recording, over what it leaves as read (sums of squares, each joint in units of its
    residual); None for fewer than two recordings or one too short to judge."""
    among = _among(robot, logs, drive)
    if among is None:
        return None
    return _ratios(among)[0]


def _ratios(among: _Among) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`held_out_ratios` of ``among``, and per recording and motor what reversing
    it takes off what is left of every joint of that recording (weighted sums of squares)."""
    R, n = len(among.rows), among.robot.n
    out, gain = np.ones((R, n)), np.zeros((R, n))
    every = np.arange(n)
    for r in range(R):
        coef = _fit([g for i, g in enumerate(among.grams) if i != r])
        read = _left(among.rows[r], coef) * among.w**2
        for k in range(n):
            flipped = _left(among.flipped(r, k), coef) * among.w**2
            out[r, k] = flipped[among.reach[k]].sum() / max(read[among.reach[k]].sum(), 1e-300)
            gain[r, k] = read[every].sum() - flipped.sum()
    return out, gain


def _pooled(among: _Among, signs: Sequence[bool], k: int) -> NDArray[np.float64]:
    """Per joint (n,), what one fit to every recording pooled leaves (weighted sums of
    squares), with motor ``k``'s columns reversed in the recordings ``signs`` says (R,)."""
    rows = [
        among.flipped(i, k) if f else x
        for i, (x, f) in enumerate(zip(among.rows, signs, strict=True))
    ]
    grams = [
        _gram(x, among.w) if f else g for x, g, f in zip(rows, among.grams, signs, strict=True)
    ]
    coef = _fit(grams)
    out: NDArray[np.float64] = sum(
        (_left(x, coef) * among.w**2 for x in rows), np.zeros(len(among.w))
    )
    return out


def _pooled_shares(
    among: _Among, r: int, k: int, read: NDArray[np.float64]
) -> tuple[float, float, float]:
    """What one fit to every recording pooled leaves with motor ``k``'s columns reversed
    in recording ``r`` alone: at the joints motor ``k`` reaches, over what it leaves as
    read (``read``: :func:`_pooled` of none reversed) and over what it leaves with them
    reversed in every other recording instead (the same data in the mirrored convention
    of motor ``k``: only the description's kinematics tell them apart); and at every
    joint over what it leaves as read."""
    R = len(among.rows)
    mine = _pooled(among, [i == r for i in range(R)], k)
    theirs = _pooled(among, [i != r for i in range(R)], k)
    at = among.reach[k]
    return (
        float(mine[at].sum() / max(read[at].sum(), 1e-300)),
        float(mine[at].sum() / max(theirs[at].sum(), 1e-300)),
        float(mine.sum() / max(read.sum(), 1e-300)),
    )


def _named(
    among: _Among, ratios: NDArray[np.float64], gain: NDArray[np.float64]
) -> tuple[int, int, float, float] | None:
    """The recording and motor :func:`reversed_among` names, with the pooled shares it
    says (at the joints the motor reaches: over as read, over the mirrored convention), or
    None. The held-out candidates (:data:`AMONG_CANDIDATES`) say the recording; of its
    motors, the one whose reversal lets the pooled fit leave least at every joint is
    named (a Panda's motors 1 and 3, parallel near ``q2 = 0``, read alike held out)."""
    order = [
        (int(r), int(k))
        for r, k in zip(*np.unravel_index(np.argsort(ratios, axis=None), ratios.shape), strict=True)
        if ratios[r, k] <= REVERSED_AMONG_SHARE and gain[r, k] > 0
    ][:AMONG_CANDIDATES]
    if not order:
        return None
    read = _pooled(among, [False] * len(among.rows), 0)
    for r, k in order:
        shares = _pooled_shares(among, r, k, read)
        if shares[0] <= REVERSED_POOLED_SHARE and shares[1] <= REVERSED_AMONG_PAIR_SHARE:
            break
    else:
        return None
    every = [(j, *_pooled_shares(among, r, j, read)) for j in range(among.robot.n)]
    j, at, mirrored, _ = min(every, key=lambda x: x[3])
    if at > REVERSED_POOLED_SHARE or mirrored > REVERSED_AMONG_PAIR_SHARE:
        return None
    return r, j, at, mirrored


def reversed_among(
    robot: Robot, logs: Sequence[TorqueLog], names: Sequence[str], drive: Drive | None = None
) -> SignFinding | None:
    """The finding that one recording's motor (joint) was recorded reversed, its position
    and effort of the opposite sign to the other recordings', told by those recordings; or
    None (fewer than two recordings, or none so).

    Each recording is predicted by the robot's rigid-body regressor and each motor's own
    viscous and Coulomb friction and rotor fitted to the others (:func:`held_out_ratios`,
    each recording its own offsets, each joint in units of its residual, the efforts the
    mean over the span the accelerations are derived over, the samples where a motor turns
    back within it left out); the recordings and motors whose reversal leaves at most
    :data:`REVERSED_AMONG_SHARE` of what is left as read at the joints they reach, least
    first, are candidates (:func:`_named`), and one is named when one fit to every
    recording pooled leaves with its columns reversed at most
    :data:`REVERSED_POOLED_SHARE` of what it leaves as read, and at most
    :data:`REVERSED_AMONG_PAIR_SHARE` of what it leaves with every other recording's
    reversed instead (a fit to a recording read reversed predicts the others better
    reversed too; a last joint whose tool is symmetric about its axis reads alike either
    way, and is not named); of that recording's motors, the one the pooled fit explains
    best. Before,
    :func:`~dynid.identification.recorded_signs.reversed_joint`, judged on the
    description's torques over the whole arm, let a geared TIAGo arm's wrist motor 5 or 6
    logged reversed in one of two recordings through: the fit's verdict was "poor" (1.46
    times its noise floor) or even "at the noise floor", the wrist's base parameters 9
    standard deviations off.

    Parameters
    ----------
    robot : Robot
    logs : sequence of TorqueLog
        As recorded (the drive's side and effort), at least two.
    names : sequence of str
        One per recording, its file.
    drive : Drive, optional
        What reads ``logs``.

    Returns
    -------
    SignFinding or None
        Of kind ``"reversed"``, its ``--units`` entries that recording's own
        (``rec2.csv:q6=-1,rec2.csv:tau6=-1``).
    """
    among = _among(robot, logs, drive)
    if among is None:
        return None
    found = _named(among, *_ratios(among))
    if found is None:
        return None
    r, k, share, mirrored = found
    others = [x for i, x in enumerate(names) if i != r]
    return SignFinding(
        names[r], "reversed", _line(robot, drive, int(k), names[r], others, (share, mirrored))
    )


def _line(
    robot: Robot,
    drive: Drive | None,
    k: int,
    name: str,
    others: Sequence[str],
    shares: tuple[float, float],
) -> str:
    """:func:`reversed_among`'s finding, without the file's name: motor (joint) ``k``
    (from 0) of recording ``name`` reversed, the shares the pooled fit leaves (of that as
    read, of that with the others' reversed instead) and the
    ``--units`` entries of that file alone."""
    motors = drive is not None and drive.side == "motor"
    who = f"motor {k + 1}" if motors else robot.joint_names[k]
    own = (
        "motor's own friction and rotor"
        if drive is not None
        else "joint's own friction and armature"
    )
    return (
        f"{who} looks recorded reversed: its position and torque have the opposite sign "
        f"to those of {', '.join(others)} (with it reversed, one fit of the robot's "
        f"rigid-body torques and each {own} to every recording leaves a residual of "
        f"{np.sqrt(shares[0]):.2g} of that as read on {who}, and "
        f"{np.sqrt(shares[1]):.2g} of that with {who} of {', '.join(others)} reversed "
        "instead): a motor or encoder mounted the other way; "
        + reversal_hint([(k, True)], [], name, motors)
    )
