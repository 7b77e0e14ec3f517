"""Joint trajectories for identification and validation, and their limit checks.

A :class:`Trajectory` holds samples ``t`` (N,) [s] and ``q``, ``dq``, ``ddq`` (N, n)
[rad, rad/s, rad/s^2]. Two closed-form families are provided, both evaluated at any
(possibly non-uniform) times ``t``:

* **velocity-mode sinusoids** (Gaz et al. 2019, eq. 31, the validation trajectory),
  ``dq_i(t) = A_i sin(2 pi t / T_i)``, integrated from a start ``q0``:

  .. math:: q_i = q_{0,i} + \\frac{A_i T_i}{2 \\pi} \\left(1 - \\cos\\frac{2 \\pi t}{T_i}\\right),
            \\quad \\ddot q_i(t) = \\frac{2 \\pi A_i}{T_i} \\cos\\frac{2 \\pi t}{T_i}

  Each joint sweeps ``[q0, q0 + A T / pi]`` (or the reverse for ``A < 0``).
  :func:`centered_start` puts the middle of every sweep at the middle of the joint
  range. With the paper's amplitudes (Table I) joints 1 and 2 exceed the Panda's
  velocity limit of 2.175 rad/s (2.21 rad/s); :func:`check_limits` reports it and
  :func:`scale_into_limits` fixes it.

* **finite Fourier series** (Swevers et al., IEEE TRA 13(5), 1997), the usual exciting
  trajectory for the classical identification:

  .. math:: \\dot q_i(t) = \\sum_{l=1}^{L} a_{il} \\cos(l \\omega_f t) + b_{il} \\sin(l \\omega_f t)

  with ``q`` and ``ddq`` its exact integral (plus ``q0``) and derivative.
  :func:`random_fourier` draws seeded coefficients and scales each joint so that
  bounds of ``|q - q0|``, ``|dq|`` and ``|ddq|`` that hold for every ``t`` stay inside the
  limits.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import DataError, LimitError, OptionError, ShapeError
from ..model.robot import Robot

__all__ = [
    "GAZ2019_SINUSOID_AMPLITUDES",
    "GAZ2019_SINUSOID_PERIODS",
    "FourierSeries",
    "LimitReport",
    "LimitScaling",
    "LimitViolation",
    "MAX_SAMPLES",
    "Trajectory",
    "centered_start",
    "check_limits",
    "check_limits_blocks",
    "limit_scaling",
    "random_fourier",
    "scale_into_limits",
    "sinusoid_trajectory",
    "uniform_times",
]

#: Amplitudes A_i [rad/s] of the validation sinusoids dq_i = A_i sin(2 pi t / T_i),
#: Gaz et al. 2019, Table I (Franka Emika Panda, joints 1..7).
GAZ2019_SINUSOID_AMPLITUDES = (2.21, -2.21, 1.2, -2.1, -2.3, 2.1, -2.5)
#: Periods T_i [s] of the validation sinusoids, Gaz et al. 2019, Table I.
GAZ2019_SINUSOID_PERIODS = (3.68, 2.04, 2.98, 1.75, 4.43, 2.749, 1.06)


@dataclass(frozen=True, slots=True, eq=False)
class Trajectory:
    """Sampled joint trajectory; arrays are read-only.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Strictly increasing sample times [s].
    q, dq, ddq : ndarray, shape (N, n)
        Joint positions [rad], velocities [rad/s], accelerations [rad/s^2].

    Raises
    ------
    ShapeError
        Shapes inconsistent.
    NonFiniteError
        NaN or inf in an array.
    DataError
        ``t`` not strictly increasing.
    """

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    dq: NDArray[np.float64]
    ddq: NDArray[np.float64]

    def __post_init__(self) -> None:
        t = _checks.as_array("t", self.t)
        if t.ndim != 1 or t.shape[0] < 1:
            raise ShapeError(f"t must have shape (N,) with N >= 1; got {t.shape}")
        if t.shape[0] > 1 and np.any(np.diff(t) <= 0):
            k = int(np.flatnonzero(np.diff(t) <= 0)[0])
            raise DataError(
                f"t must be strictly increasing; t[{k}] = {t[k]} >= t[{k + 1}] = {t[k + 1]}"
            )
        q = _checks.as_array("q", self.q)
        if q.ndim != 2 or q.shape[0] != t.shape[0]:
            raise ShapeError(f"q must have shape ({t.shape[0]}, n); got {q.shape}")
        shape = q.shape
        object.__setattr__(self, "t", _checks.frozen(t))
        object.__setattr__(self, "q", _checks.frozen(q))
        for attr in ("dq", "ddq"):
            object.__setattr__(
                self, attr, _checks.frozen(_checks.as_exact(attr, getattr(self, attr), shape))
            )

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.q.shape[1]

    @property
    def duration(self) -> float:
        """``t[-1] - t[0]`` [s]."""
        return float(self.t[-1] - self.t[0])

    def __len__(self) -> int:
        return self.t.shape[0]


#: The most samples a uniform time grid may hold: 2**40 (8 TiB of float64 times alone).
MAX_SAMPLES = 2**40


def uniform_times(duration: float, fs: float = 1000.0) -> NDArray[np.float64]:
    """Times ``k / fs`` for ``k = 0 .. round(duration fs)`` [s], shape (N,).

    Raises
    ------
    OptionError
        ``duration`` or ``fs`` not positive, or more than :data:`MAX_SAMPLES` samples
        (``duration = 1e300``: no memory holds them, and numpy's own error says nothing
        of the duration).
    """
    if not (duration > 0 and fs > 0):
        raise OptionError(f"duration and fs must be positive; got {duration} s and {fs} Hz")
    count = duration * fs
    if not count < MAX_SAMPLES:
        raise OptionError(
            f"{duration:g} s at {fs:g} Hz is {count:.3g} samples, more than any memory holds "
            f"(at most {MAX_SAMPLES:.3g}); give a shorter duration or a lower rate"
        )
    return np.arange(int(round(count)) + 1) / float(fs)


def _times(t: ArrayLike) -> NDArray[np.float64]:
    t = _checks.as_array("t", t)
    if t.ndim != 1:
        raise ShapeError(f"t must have shape (N,); got {t.shape}")
    return t


def sinusoid_trajectory(
    t: ArrayLike,
    q0: ArrayLike,
    amplitudes: ArrayLike = GAZ2019_SINUSOID_AMPLITUDES,
    periods: ArrayLike = GAZ2019_SINUSOID_PERIODS,
) -> Trajectory:
    """Velocity-mode sinusoids ``dq_i = A_i sin(2 pi t / T_i)`` integrated from ``q0``.

    .. math:: q_i = q_{0,i} + \\frac{A_i T_i}{2\\pi}\\left(1 - \\cos\\frac{2\\pi t}{T_i}\\right)

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s], strictly increasing (``t = 0`` is the start, where ``q = q0``).
    q0 : array_like, shape (n,)
        Start configuration [rad].
    amplitudes : array_like, shape (n,)
        ``A_i`` [rad/s]; default Gaz et al. 2019, Table I.
    periods : array_like, shape (n,)
        ``T_i`` [s], positive; default Gaz et al. 2019, Table I.

    Returns
    -------
    Trajectory

    Raises
    ------
    ShapeError
        ``q0``, ``amplitudes`` and ``periods`` differ in shape.
    OptionError
        A period is not positive.
    """
    t = _times(t)
    q0 = _checks.as_array("q0", q0)
    if q0.ndim != 1:
        raise ShapeError(f"q0 must have shape (n,); got {q0.shape}")
    n = q0.shape[0]
    A = _checks.as_exact("amplitudes", amplitudes, (n,))
    T = _checks.as_exact("periods", periods, (n,))
    if np.any(T <= 0):
        raise OptionError(f"periods must be positive; got {T}")
    w = 2.0 * np.pi / T
    ph = np.outer(t, w)
    return Trajectory(
        t=t,
        q=q0 + (A / w) * (1.0 - np.cos(ph)),
        dq=A * np.sin(ph),
        ddq=(A * w) * np.cos(ph),
    )


def centered_start(
    robot: Robot,
    amplitudes: ArrayLike = GAZ2019_SINUSOID_AMPLITUDES,
    periods: ArrayLike = GAZ2019_SINUSOID_PERIODS,
) -> NDArray[np.float64]:
    """Start ``q0`` [rad] (n,) that centres every sinusoid sweep in its joint range.

    ``q0 = (q_min + q_max) / 2 - A T / (2 pi)``; for an unlimited joint the range centre
    is taken as 0.
    """
    A = _checks.as_exact("amplitudes", amplitudes, (robot.n,))
    T = _checks.as_exact("periods", periods, (robot.n,))
    lo, hi = robot.q_min, robot.q_max
    mid = np.where(np.isfinite(lo) & np.isfinite(hi), 0.5 * (lo + hi), 0.0)
    return mid - A * T / (2.0 * np.pi)


@dataclass(frozen=True, slots=True, eq=False)
class FourierSeries:
    """Finite Fourier series joint trajectory (Swevers et al. 1997).

    .. math:: \\dot q_i = \\sum_{l=1}^{L} a_{il} \\cos(l\\omega_f t) + b_{il} \\sin(l\\omega_f t),
              \\quad q_i = q_{0,i} + \\sum_{l=1}^{L} \\frac{a_{il}}{l\\omega_f} \\sin(l\\omega_f t)
              - \\frac{b_{il}}{l\\omega_f} \\cos(l\\omega_f t)

    Attributes
    ----------
    w_f : float
        Base angular frequency [rad/s]; the trajectory is periodic with ``2 pi / w_f``.
    a, b : ndarray, shape (n, L)
        Cosine and sine coefficients of the velocity [rad/s].
    q0 : ndarray, shape (n,)
        Position offset [rad] (the mean position over a period).
    """

    w_f: float
    a: NDArray[np.float64]
    b: NDArray[np.float64]
    q0: NDArray[np.float64]

    def __post_init__(self) -> None:
        if not self.w_f > 0:
            raise OptionError(f"w_f must be positive; got {self.w_f}")
        a = _checks.as_array("a", self.a)
        if a.ndim != 2:
            raise ShapeError(f"a must have shape (n, L); got {a.shape}")
        object.__setattr__(self, "w_f", float(self.w_f))
        object.__setattr__(self, "a", _checks.frozen(a))
        object.__setattr__(self, "b", _checks.frozen(_checks.as_exact("b", self.b, a.shape)))
        object.__setattr__(
            self, "q0", _checks.frozen(_checks.as_exact("q0", self.q0, (a.shape[0],)))
        )

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.a.shape[0]

    @property
    def period(self) -> float:
        """``2 pi / w_f`` [s]."""
        return 2.0 * np.pi / self.w_f

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Bounds (n,) of ``|q - q0|``, ``|dq|``, ``|ddq|`` valid at every time.

        ``sum_l c_l / (l w_f)``, ``sum_l c_l`` and ``sum_l l w_f c_l`` with
        ``c_l = sqrt(a_l^2 + b_l^2)`` (each harmonic is a sinusoid of amplitude ``c_l``).
        """
        lw = self.w_f * np.arange(1, self.a.shape[1] + 1)
        c = np.hypot(self.a, self.b)
        return (c / lw).sum(axis=1), c.sum(axis=1), (c * lw).sum(axis=1)

    def __call__(self, t: ArrayLike) -> Trajectory:
        """Samples at times ``t`` (N,) [s]."""
        t = _times(t)
        lw = self.w_f * np.arange(1, self.a.shape[1] + 1)
        ph = t[:, None] * lw  # (N, L)
        s, c = np.sin(ph), np.cos(ph)
        q = self.q0 + s @ (self.a / lw).T - c @ (self.b / lw).T
        dq = c @ self.a.T + s @ self.b.T
        ddq = -s @ (self.a * lw).T + c @ (self.b * lw).T
        return Trajectory(t=t, q=q, dq=dq, ddq=ddq)


def random_fourier(
    robot: Robot,
    rng: np.random.Generator,
    *,
    n_harmonics: int = 5,
    w_f: float = 2.0 * np.pi * 0.1,
    margin: float = 0.9,
    q0: ArrayLike | None = None,
) -> FourierSeries:
    """Seeded random Fourier-series trajectory inside the robot's limits.

    Coefficients are drawn standard normal; then each joint's coefficients are scaled
    by the largest factor for which the bounds of :meth:`FourierSeries.bounds` stay
    within ``margin`` times the distance from ``q0`` to the nearer position limit, the
    velocity limit and the acceleration limit. The limits then hold at every time, not
    only at the samples.

    Parameters
    ----------
    robot : Robot
        Limits ``q_min``, ``q_max``, ``dq_max``, ``ddq_max`` (infinite ones ignored; a joint
        without any finite limit is capped at 1 rad/s).
    rng : numpy.random.Generator
    n_harmonics : int
        ``L``.
    w_f : float
        Base angular frequency [rad/s] (default 0.1 Hz: a 10 s period; the highest
        harmonic is then at ``L w_f / (2 pi) = 0.5`` Hz).
    margin : float
        Fraction of each limit used, in (0, 1].
    q0 : array_like, shape (n,), optional
        Position offset [rad]; default the middle of each joint range (0 if unlimited).

    Returns
    -------
    FourierSeries

    Raises
    ------
    LimitError
        ``q0`` is not strictly inside the position limits.
    """
    if not 0 < margin <= 1:
        raise OptionError(f"margin must be in (0, 1]; got {margin}")
    lo, hi = robot.q_min, robot.q_max
    if q0 is None:
        bounded = np.isfinite(lo) & np.isfinite(hi)  # a continuous joint starts at 0
        q0 = 0.5 * (np.where(bounded, lo, 0.0) + np.where(bounded, hi, 0.0))
    q0 = _checks.as_exact("q0", q0, (robot.n,))
    room = np.minimum(q0 - lo, hi - q0)
    if np.any(room <= 0):
        j = int(np.argmin(room))
        raise LimitError(
            f"q0 must lie strictly inside the position limits; joint {robot.joint_names[j]}: "
            f"q0 = {q0[j]:.4g}, limits [{lo[j]:.4g}, {hi[j]:.4g}]"
        )
    a = rng.standard_normal((robot.n, n_harmonics))
    b = rng.standard_normal((robot.n, n_harmonics))
    pb, vb, ab = FourierSeries(w_f, a, b, q0).bounds()
    with np.errstate(divide="ignore"):
        s = np.minimum.reduce(
            [margin * room / pb, margin * robot.dq_max / vb, margin * robot.ddq_max / ab]
        )
    s = np.where(np.isfinite(s), s, 1.0 / vb)
    return FourierSeries(w_f, a * s[:, None], b * s[:, None], q0)


# ----------------------------------------------------------------------------- limits
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
