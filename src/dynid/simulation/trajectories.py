"""Joint trajectories for identification and validation.

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
  velocity limit of 2.175 rad/s (2.21 rad/s);
  :func:`~dynid.simulation.limits.check_limits` reports it and
  :func:`~dynid.simulation.limits.scale_into_limits` fixes it.

* **finite Fourier series** (Swevers et al., IEEE TRA 13(5), 1997), the usual exciting
  trajectory for the classical identification:

  .. math:: \\dot q_i(t) = \\sum_{l=1}^{L} a_{il} \\cos(l \\omega_f t) + b_{il} \\sin(l \\omega_f t)

  with ``q`` and ``ddq`` its exact integral (plus ``q0``) and derivative.
  :func:`random_fourier` draws seeded coefficients and scales each joint so that
  bounds of ``|q - q0|``, ``|dq|`` and ``|ddq|`` that hold for every ``t`` stay inside the
  limits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import DataError, LimitError, OptionError, ShapeError
from ..model.robot import Robot, checked_robot

__all__ = [
    "GAZ2019_SINUSOID_AMPLITUDES",
    "GAZ2019_SINUSOID_PERIODS",
    "FourierSeries",
    "MAX_SAMPLES",
    "Trajectory",
    "centered_start",
    "random_fourier",
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
    _checks.checked_rng(rng)
    checked_robot(robot)
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


#: How a message says what a sampled trajectory argument must be.
TRAJECTORY_EXPECTED = "a Trajectory (sinusoid_trajectory(...), or random_fourier(robot, rng)(t))"
