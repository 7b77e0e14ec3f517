"""Limit checks of joint trajectories and the scalings that bring a trajectory inside them.

:func:`check_limits` (and :func:`check_limits_blocks` for a trajectory given in blocks)
reports every position, velocity and acceleration limit a
:class:`~dynid.simulation.trajectories.Trajectory` exceeds; :func:`scale_into_limits` (and
:func:`limit_scaling` for blocks) shrinks the amplitude about the start, or slows time down,
so that every limit holds with a margin.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import LimitError, OptionError, ShapeError
from ..model.robot import Robot, checked_robot
from .trajectories import TRAJECTORY_EXPECTED, Trajectory

__all__ = [
    "LimitReport",
    "LimitScaling",
    "LimitViolation",
    "check_limits",
    "check_limits_blocks",
    "limit_scaling",
    "scale_into_limits",
]


@dataclass(frozen=True, slots=True)
class LimitViolation:
    """One exceeded limit: the worst sample of one quantity on one joint.

    Attributes
    ----------
    kind : {"position", "velocity", "acceleration"}
    joint : int
        0-based joint index.
    joint_name : str
    time : float
        Time of the worst sample [s].
    value : float
        Worst value [rad, rad/s or rad/s^2].
    limit : float
        The limit it exceeds (the bound on its side; magnitudes for velocity and
        acceleration).
    first_time : float
        First time the limit is exceeded [s].
    fraction : float
        Fraction of the samples that exceed it.
    """

    kind: str
    joint: int
    joint_name: str
    time: float
    value: float
    limit: float
    first_time: float
    fraction: float

    def __str__(self) -> str:
        return (
            f"{self.kind} limit of {self.joint_name} exceeded: {self.value:+.4g} at t = "
            f"{self.time:.3f} s (limit {self.limit:+.4g}; first at {self.first_time:.3f} s, "
            f"{100 * self.fraction:.1f} % of samples)"
        )


@dataclass(frozen=True, slots=True)
class LimitReport:
    """Result of :func:`check_limits`: every exceeded limit, empty when all hold."""

    violations: tuple[LimitViolation, ...]

    @property
    def ok(self) -> bool:
        """True when no limit is exceeded."""
        return not self.violations

    def __bool__(self) -> bool:
        return self.ok

    def __str__(self) -> str:
        if self.ok:
            return "all position, velocity and acceleration limits hold"
        return "\n".join(str(v) for v in self.violations)


def check_limits(robot: Robot, traj: Trajectory) -> LimitReport:
    """Positions, velocities and accelerations of ``traj`` against the robot's limits.

    Parameters
    ----------
    robot : Robot
        ``q_min``, ``q_max`` [rad], ``dq_max`` [rad/s], ``ddq_max`` [rad/s^2] (symmetric).
    traj : Trajectory
        With ``n == robot.n``.

    Returns
    -------
    LimitReport
        One :class:`LimitViolation` per (quantity, joint, side) that is exceeded, in the
        order position, velocity, acceleration and by joint.

    Raises
    ------
    ShapeError
        ``traj.n != robot.n``.
    """
    checked_robot(robot)
    traj = _checks.of_type("traj", traj, Trajectory, TRAJECTORY_EXPECTED)
    return check_limits_blocks(robot, (traj,))


#: Where a (quantity, joint, side) exceeds its limit, over blocks: samples outside, the
#: first time, and the worst excess with its time and value.
_Excess = dict[tuple[int, int, int], list[float]]


def check_limits_blocks(robot: Robot, blocks: Iterable[Trajectory]) -> LimitReport:
    """:func:`check_limits` of a trajectory given in consecutive pieces (a long one never
    held whole): the same report as for the pieces joined.

    Raises
    ------
    ShapeError
        A piece with ``n != robot.n``.
    """
    seen: _Excess = {}
    total = 0
    for traj in blocks:
        if traj.n != robot.n:
            raise ShapeError(f"trajectory has {traj.n} joints; robot {robot.name!r} has {robot.n}")
        total += len(traj)
        checks = (
            (traj.q, robot.q_min, robot.q_max),
            (traj.dq, -robot.dq_max, robot.dq_max),
            (traj.ddq, -robot.ddq_max, robot.ddq_max),
        )
        for i, (x, lo, hi) in enumerate(checks):
            for j in range(robot.n):
                for side, bound, bad in ((0, lo[j], x[:, j] < lo[j]), (1, hi[j], x[:, j] > hi[j])):
                    if not bad.any():
                        continue
                    excess = np.where(bad, np.abs(x[:, j] - bound), -np.inf)
                    k = int(np.argmax(excess))
                    first = float(traj.t[int(np.argmax(bad))])
                    rec = seen.setdefault((i, j, side), [0.0, first, -np.inf, 0.0, 0.0])
                    rec[0] += float(bad.sum())
                    if excess[k] > rec[2]:
                        rec[2:] = [float(excess[k]), float(traj.t[k]), float(x[k, j])]
    out = []
    kinds = ("position", "velocity", "acceleration")
    limits = (
        (robot.q_min, robot.q_max),
        (-robot.dq_max, robot.dq_max),
        (-robot.ddq_max, robot.ddq_max),
    )
    for (i, j, side), (count, first, _, time, value) in sorted(seen.items()):
        out.append(
            LimitViolation(
                kind=kinds[i],
                joint=j,
                joint_name=robot.joint_names[j],
                time=time,
                value=value,
                limit=float(limits[i][side][j]),
                first_time=first,
                fraction=count / total,
            )
        )
    return LimitReport(tuple(out))


@dataclass(frozen=True, slots=True, eq=False)
class LimitScaling:
    """How :func:`scale_into_limits` changes a trajectory, to apply to each of its pieces.

    Attributes
    ----------
    method : {"amplitude", "time"}
    factor : float
        ``s <= 1`` (amplitude) or ``k >= 1`` (time); 1 leaves the trajectory unchanged.
    t0 : float
        Start time [s] (time scaling is about it).
    qs : ndarray, shape (n,)
        Start configuration [rad] (amplitude scaling is about it).
    """

    method: str
    factor: float
    t0: float
    qs: NDArray[np.float64]

    def apply(self, traj: Trajectory) -> Trajectory:
        """The scaled trajectory (``traj`` itself when the factor is 1)."""
        if self.factor == 1.0:
            return traj
        if self.method == "time":
            k, t0 = self.factor, self.t0
            return Trajectory(t0 + k * (traj.t - t0), traj.q, traj.dq / k, traj.ddq / k**2)
        s, qs = self.factor, self.qs
        return Trajectory(traj.t, qs + s * (traj.q - qs), s * traj.dq, s * traj.ddq)


def scale_into_limits(
    robot: Robot, traj: Trajectory, *, method: str = "amplitude", margin: float = 0.95
) -> tuple[Trajectory, float]:
    """Scale a trajectory so that it respects the robot's limits.

    * ``"amplitude"``: shrink the motion about its start ``q_s = q(t_0)``,
      ``q' = q_s + s (q - q_s)``, ``dq' = s dq``, ``ddq' = s ddq``, same times. For the
      velocity-mode sinusoids this is exactly scaling the amplitudes ``A`` by ``s``.
      Fixes position (if ``q_s`` is inside the margin), velocity and acceleration limits.
    * ``"time"``: slow down by ``k >= 1``, ``q'(t) = q(t_0 + (t - t_0) / k)``: samples at
      ``t_0 + k (t - t_0)``, ``dq' = dq / k``, ``ddq' = ddq / k^2`` (sinusoid periods times
      ``k``, amplitudes over ``k``). Positions are unchanged, so it cannot fix them.

    The factor is the largest ``s <= 1`` (smallest ``k >= 1``) that brings every sample
    within ``margin`` times each velocity and acceleration limit and, for ``"amplitude"``,
    within the position range shrunk by ``(1 - margin) / 2`` of its width at each end.
    An already admissible trajectory is returned unchanged with factor 1.

    Parameters
    ----------
    robot : Robot
    traj : Trajectory
    method : {"amplitude", "time"}
    margin : float
        In (0, 1].

    Returns
    -------
    scaled : Trajectory
    factor : float
        ``s`` (amplitude) or ``k`` (time).

    Raises
    ------
    LimitError
        ``"time"`` with positions outside the limits, or ``"amplitude"`` with a start
        configuration outside the shrunk position range.
    OptionError
        Unknown ``method``, or ``margin`` not in (0, 1].
    ShapeError
        ``traj.n != robot.n``.
    """
    traj = _checks.of_type("traj", traj, Trajectory, TRAJECTORY_EXPECTED)
    checked_robot(robot)
    scaling = limit_scaling(robot, lambda: (traj,), method=method, margin=margin)
    return scaling.apply(traj), scaling.factor


def limit_scaling(
    robot: Robot,
    blocks: Callable[[], Iterable[Trajectory]],
    *,
    method: str = "amplitude",
    margin: float = 0.95,
) -> LimitScaling:
    """The scaling of :func:`scale_into_limits` for a trajectory given in consecutive
    pieces (``blocks()`` yields them, one pass): the same factor as for the pieces joined.

    Raises
    ------
    LimitError, OptionError, ShapeError
        As :func:`scale_into_limits`.
    """
    if not 0 < margin <= 1:
        raise OptionError(f"margin must be in (0, 1]; got {margin}")
    if method not in ("amplitude", "time"):
        raise OptionError(f"method must be 'amplitude' or 'time'; got {method!r}")
    n = robot.n
    vmax, amax = np.zeros(n), np.zeros(n)
    qlo, qhi = np.full(n, np.inf), np.full(n, -np.inf)
    width = robot.q_max - robot.q_min
    shrink = np.where(np.isfinite(width), 0.5 * (1.0 - margin) * width, 0.0)
    lo, hi = robot.q_min + shrink, robot.q_max - shrink
    qs: NDArray[np.float64] | None = None
    t0, rq = 0.0, 0.0
    for traj in blocks():
        if traj.n != n:
            raise ShapeError(f"trajectory has {traj.n} joints; robot {robot.name!r} has {n}")
        if qs is None:
            qs, t0 = traj.q[0].copy(), float(traj.t[0])
            _check_start(robot, qs, lo, hi, margin, method)
        vmax = np.maximum(vmax, np.max(np.abs(traj.dq), axis=0))
        amax = np.maximum(amax, np.max(np.abs(traj.ddq), axis=0))
        qlo, qhi = np.minimum(qlo, traj.q.min(axis=0)), np.maximum(qhi, traj.q.max(axis=0))
        if method == "amplitude":
            d = traj.q - qs
            with np.errstate(divide="ignore", invalid="ignore"):
                rq_hi = np.where(d > 0, d / (hi - qs), 0.0)
                rq_lo = np.where(d < 0, d / (lo - qs), 0.0)
            r = np.nan_to_num(np.maximum(rq_hi, rq_lo), nan=0.0, posinf=np.inf)
            rq = max(rq, float(np.max(r)))
    if qs is None:
        raise ShapeError("the trajectory has no sample")
    with np.errstate(divide="ignore", invalid="ignore"):
        rv = np.max(np.where(vmax > 0, vmax / (margin * robot.dq_max), 0.0))
        ra = np.max(np.where(amax > 0, amax / (margin * robot.ddq_max), 0.0))
    if method == "time":
        bad = np.flatnonzero((qlo < robot.q_min) | (qhi > robot.q_max))
        if bad.size:
            j = int(bad[0])
            raise LimitError(
                f"time scaling cannot fix position limits; {robot.joint_names[j]} reaches "
                f"[{qlo[j]:.4g}, {qhi[j]:.4g}] rad, limits "
                f"[{robot.q_min[j]:.4g}, {robot.q_max[j]:.4g}]; hint: method='amplitude'"
            )
        k = max(1.0, float(rv), float(np.sqrt(ra)))
        return LimitScaling("time", k, t0, qs)
    worst = max(1.0, float(rv), float(ra), rq)
    return LimitScaling("amplitude", 1.0 if worst == 1.0 else 1.0 / worst, t0, qs)


def _check_start(
    robot: Robot,
    qs: NDArray[np.float64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    margin: float,
    method: str,
) -> None:
    """Amplitude scaling keeps the start: refuse one outside the shrunk range."""
    outside = np.flatnonzero((qs < lo) | (qs > hi))
    if method == "amplitude" and outside.size:
        j = int(outside[0])
        raise LimitError(
            f"amplitude scaling keeps the start; {robot.joint_names[j]} starts at {qs[j]:.4g} rad, "
            f"outside [{lo[j]:.4g}, {hi[j]:.4g}] (limits with margin {margin}); hint: choose "
            "another start (centered_start)"
        )
