"""Inverse kinematics by kinematic simulation (closed-loop inverse kinematics).

The solver simulates the joint motion that a resolved-rate controller would command
(Siciliano, "A closed-loop inverse kinematic scheme for on-line joint-based robot
control", Robotica 8(3), 1990; Siciliano et al., *Robotics*, 2009, sec. 3.7):

.. math::

    e_k = \\begin{bmatrix} p_{goal} - p(q_k) \\\\
          \\log(R_{goal} R(q_k)^T) \\end{bmatrix}, \\qquad
    \\dot q_k = J^{\\#}(q_k)\\, K\\, e_k, \\qquad
    q_{k+1} = \\mathrm{clip}(q_k + \\Delta t\\, \\dot q_k,\\; q_{min},\\; q_{max})

Conventions:

* ``e`` is the pose error in the **base frame**: the position error [m] of the frame's
  origin, then the orientation error as an angle-axis vector [rad] (``log`` as in
  :func:`dynid.spatial.angle_axis_from_matrix`, angle in ``[0, pi]``). ``J`` is the
  geometric Jacobian of the same origin, rows ``[v; w]`` in the base frame
  (:func:`dynid.kinematics.jacobian.jacobian`), so both halves of ``e`` match its rows.
* ``J^#`` is the damped least-squares inverse (Nakamura and Hanafusa 1986; Wampler 1986),
  the exact pseudo-inverse away from singularities; the damping grows as the smallest
  singular value falls below ``eps`` (Maciejewski and Klein 1988; Chiaverini 1997) and
  shrinks with the error (Sugihara 2011).
* Joint position limits: ``q`` is clipped into ``[q_min, q_max]`` after every step, and a
  joint resting on a limit whose step would push it further out is removed from ``J`` for
  that step (an active set), so that the other joints take over the task. Every row of
  the returned path lies within the limits.
* Joint velocity limits (``IKOptions.velocity_limits``): each step is scaled uniformly so
  that ``|dq_i| <= dq_max_i``, which keeps the simulated motion feasible.
* The error fed to the controller is clamped to ``max_position_step`` and
  ``max_orientation_step`` (Buss 2004, "Introduction to inverse kinematics with Jacobian
  transpose, pseudoinverse and damped least squares methods", sec. 6), so a distant goal
  is approached along a line instead of through one large linearised step.
* ``dt * gain = 1`` (the default) is a full Gauss-Newton step; the discrete loop contracts
  the error when ``0 < dt * gain < 2``.
* Restarts: when the error stalls for ``stall_iterations`` steps, the arm moves (at the
  velocity limits) to a random configuration drawn from ``rng`` and the simulation
  resumes, at most ``max_restarts`` times (0: the plain local simulation).

Batches: ``T_goal`` of shape (..., 4, 4) solves every goal independently and returns
arrays of the batch shape (no paths). The solve runs in one compiled call per goal when
numba is installed, in a numpy loop otherwise (or with ``DYNID_NO_NUMBA=1``); both take
the same steps. The damping schedule, the restarts, batches and the two implementations
are described in ``docs/inverse-kinematics.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..exceptions import DataError, LimitError, ShapeError, WrongTypeError
from ..model.robot import Robot, checked_robot
from ._ik_numpy import Chain, rotvec, solve_numpy
from .forward import frame_constants

__all__ = ["IKOptions", "IKResult", "check_pose", "default_q0", "ik"]

#: Largest deviation ``max |R^T R - I|`` accepted for the rotation block of a goal pose.
ORTHONORMALITY_TOLERANCE = 1e-5


@dataclass(frozen=True, slots=True)
class IKOptions:
    """Settings of :func:`ik`.

    Attributes
    ----------
    dt : float
        Time step of the kinematic simulation [s].
    gain : float
        Task-space gain ``K`` [1/s]; ``dt * gain`` must lie in ``(0, 2)`` (1: a full
        Gauss-Newton step).
    damping : float
        Largest damping ``lambda_max`` of the least-squares inverse, reached at a singular
        configuration [units of ``J``]; 0 gives the plain pseudo-inverse.
    singular_threshold : float
        Smallest singular value ``eps`` of ``J`` below which damping starts.
    damping_error : float
        Error norm ``|[e_p; e_o]|`` below which the damping fades (linearly in
        ``lambda^2``) to 0, so that a goal at a near-singular configuration is still
        reached to the tolerances [m and rad].
    position_tolerance : float
        Convergence threshold on ``|p_goal - p|`` [m].
    orientation_tolerance : float
        Convergence threshold on the angle of ``R_goal R^T`` [rad].
    max_iterations : int
        Largest number of simulation steps, restarts included.
    max_position_step : float
        Clamp on the norm of the position error fed to the controller [m].
    max_orientation_step : float
        Clamp on the norm of the orientation error fed to the controller [rad].
    velocity_limits : bool
        Scale each step so that ``|dq_i| <= robot.dq_max[i]`` (joints without a finite
        limit are not constrained).
    stall_iterations : int
        Steps without a 0.1 % decrease of the error norm after which the simulation
        restarts (or stops, once ``max_restarts`` are used).
    max_restarts : int
        Largest number of restarts from random configurations (0: none).
    """

    dt: float = 0.1
    gain: float = 10.0
    damping: float = 0.1
    singular_threshold: float = 0.05
    damping_error: float = 0.1
    position_tolerance: float = 1e-6
    orientation_tolerance: float = 1e-6
    max_iterations: int = 2000
    max_position_step: float = 0.2
    max_orientation_step: float = 0.5
    velocity_limits: bool = True
    stall_iterations: int = 30
    max_restarts: int = 20

    def __post_init__(self) -> None:
        for name in (
            "dt",
            "gain",
            "singular_threshold",
            "damping_error",
            "position_tolerance",
            "orientation_tolerance",
            "max_position_step",
            "max_orientation_step",
        ):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise DataError(
                    f"IKOptions.{name} must be a positive finite number; got {_checks.short(v)}"
                )
        if not (
            isinstance(self.damping, (int, float))
            and math.isfinite(self.damping)
            and self.damping >= 0
        ):
            raise DataError(
                f"IKOptions.damping must be a finite number >= 0; got {_checks.short(self.damping)}"
            )
        if not 0 < self.dt * self.gain < 2:
            raise DataError(
                "IKOptions.dt * gain must lie in (0, 2) for the discrete loop to converge; "
                f"got {_checks.short(self.dt * self.gain)}"
            )
        for name, low in (("max_iterations", 1), ("stall_iterations", 1), ("max_restarts", 0)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < low:
                raise DataError(
                    f"IKOptions.{name} must be an integer >= {low}; got {_checks.short(v)}"
                )


@dataclass(frozen=True, slots=True, eq=False)
class IKResult:
    """Outcome of :func:`ik`.

    For one goal (``T_goal`` of shape (4, 4)) the fields are as listed; for a batch of
    goals (shape (..., 4, 4)) every field but ``path`` is an array with the batch shape
    ``...`` in front (``q`` (..., n), ``converged`` (...) bool, ``iterations`` and
    ``restarts`` (...) int, the errors (...) float) and ``path`` is None.

    Attributes
    ----------
    q : ndarray, shape (n,)
        Joint positions [rad or m] of the best point of the path (the last one when
        converged), within the limits.
    converged : bool
        Both errors at ``q`` are within their tolerances.
    iterations : int
        Number of simulation steps taken.
    position_error : float
        ``|p_goal - p(q)|`` at ``q`` [m], base frame.
    orientation_error : float
        Angle of ``R_goal R(q)^T`` at ``q`` [rad].
    path : ndarray, shape (iterations + 1, n), or None
        The simulated joint motion from ``q0``; row ``k`` is the state after ``k`` steps
        (time ``k * dt``). None for a batch of goals.
    restarts : int
        Number of restarts used.
    """

    q: NDArray[np.float64]
    converged: Any
    iterations: Any
    position_error: Any
    orientation_error: Any
    path: Any
    restarts: Any = 0


def default_q0(robot: Robot) -> NDArray[np.float64]:
    """The documented default start of :func:`ik`, shape (n,) [rad or m].

    ``robot.q_neutral`` when the robot has one (the Panda: :data:`dynid.PANDA_NEUTRAL_Q`);
    otherwise the middle of the joint limits, with 0 for a joint whose range is unbounded
    on either side.
    """
    if robot.q_neutral is not None:
        return np.array(robot.q_neutral)
    bounded = np.isfinite(robot.q_min) & np.isfinite(robot.q_max)
    mid = 0.5 * (np.where(bounded, robot.q_min, 0.0) + np.where(bounded, robot.q_max, 0.0))
    return np.where(bounded, mid, 0.0)


def check_pose(name: str, T: ArrayLike) -> NDArray[np.float64]:
    """Validate a rigid transform (4, 4): finite, last row ``[0, 0, 0, 1]``, rotation block.

    Returns a new array whose rotation block is re-orthonormalised (the nearest rotation,
    by SVD) when it deviates by more than 1e-13, so that a goal written with 6 decimals
    can still be reached to 1e-6.

    Raises
    ------
    ShapeError, NonFiniteError
        ``T`` is not a finite (4, 4) array.
    DataError
        The last row is not ``[0, 0, 0, 1]`` or the rotation block is not a rotation
        (``max |R^T R - I| > 1e-5`` or ``det R <= 0``).
    """
    T = np.array(_checks.as_exact(name, T, (4, 4)))
    (a, b, c, _), (d, e, f, _), (g, h, i, _), (w0, w1, w2, w3) = T.tolist()
    last = max(abs(w0), abs(w1), abs(w2), abs(w3 - 1.0))
    if last > ORTHONORMALITY_TOLERANCE:
        raise DataError(f"{name} must have last row [0, 0, 0, 1]; got {[w0, w1, w2, w3]}")
    # max |R^T R - I| over the six distinct entries (columns (a, d, g), (b, e, h), (c, f, i))
    dev = max(
        abs(a * a + d * d + g * g - 1.0),
        abs(b * b + e * e + h * h - 1.0),
        abs(c * c + f * f + i * i - 1.0),
        abs(a * b + d * e + g * h),
        abs(a * c + d * f + g * i),
        abs(b * c + e * f + h * i),
    )
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    if dev > ORTHONORMALITY_TOLERANCE or det <= 0:
        raise DataError(
            f"{name} rotation block must be orthonormal with det +1 (max |R^T R - I| <= "
            f"{ORTHONORMALITY_TOLERANCE:g}); got deviation {dev:.3g}, det {det:.3g}"
        )
    if dev > 1e-13:
        U, _, Vt = np.linalg.svd(T[:3, :3])
        T[:3, :3] = U @ Vt
    T[3] = (0.0, 0.0, 0.0, 1.0)
    return T


_DEFAULT_OPTIONS = IKOptions()


_IK = _kernels.KERNELS["ik"]


def _kernel(ndim: int) -> Any:
    """The compiled solver (:mod:`dynid._kernels.ik`) for one goal (``ndim`` 1) or a batch
    of goals, or None for the numpy loop (:func:`dynid._kernels.dispatch.compiled`: numba
    missing or ``DYNID_NO_NUMBA`` set, or a one-shot single goal)."""
    return _kernels.compiled(_IK, ndim)


# ---------------------------------------------------------------------- solver
def ik(
    robot: Robot,
    T_goal: ArrayLike,
    q0: ArrayLike | None = None,
    frame: str = "flange",
    tool: ArrayLike | None = None,
    options: IKOptions | None = None,
    *,
    rng: np.random.Generator | None = None,
) -> IKResult:
    """Joint positions that put a frame (or a tool fixed to it) at a goal pose.

    Simulates ``q <- clip(q + dt J^#(q) K e(q))`` from ``q0`` until the position and the
    orientation errors are within their tolerances (see the module docstring for the
    damping, the limits and the restarts).

    Parameters
    ----------
    robot : Robot
    T_goal : array_like, shape (4, 4) or (..., 4, 4)
        Goal pose of the frame (of the tool when given) in the base frame [m]. The
        rotation block must be orthonormal to 1e-5; it is re-orthonormalised. A batch of
        goals (an ndarray with more than two dimensions) is solved goal by goal, in
        parallel (see the module docstring).
    q0 : array_like, shape (n,) or broadcastable to (..., n), optional
        Start [rad or m], within the position limits. Default :func:`default_q0`: the
        Panda's neutral pose :data:`~dynid.model.panda.PANDA_NEUTRAL_Q`, else the middle
        of the limits.
    frame : str
        A frame of ``robot.frames``.
    tool : array_like, shape (4, 4), optional
        Pose of a tool in ``frame`` [m]; the goal is then the tool's.
    options : IKOptions, optional
        Step, gain, damping, tolerances, iteration and restart limits.
    rng : numpy.random.Generator, optional
        Source of the restart configurations; default ``np.random.default_rng(0)``, made
        anew on each call so results are reproducible.

    Returns
    -------
    IKResult
        ``converged=False`` (no exception) when the goal is not reached: ``q`` is then
        the point of the path with the smallest ``|[e_p; e_o]|``, with its errors. For a
        batch, arrays of the batch shape and ``path=None``.

    Raises
    ------
    ShapeError
        ``T_goal`` or ``tool`` is not (4, 4) (or (..., 4, 4)), or ``q0`` is not (n,) (or
        does not broadcast to the goals' batch shape).
    NonFiniteError
        ``T_goal``, ``tool`` or ``q0`` holds NaN or inf.
    DataError
        ``T_goal`` is not a rigid transform.
    UnknownNameError
        ``frame`` is not a frame of the robot.
    LimitError
        ``q0`` lies outside the joint position limits.

    Examples
    --------
    >>> import dynid
    >>> from dynid.kinematics import ik
    >>> robot = dynid.panda()
    >>> T = dynid.fk(robot, [0.1, -0.5, 0.2, -2.0, 0.1, 1.8, 0.5])
    >>> ik(robot, T).converged
    True
    """
    checked_robot(robot)
    opts = _DEFAULT_OPTIONS if options is None else options
    if not isinstance(opts, IKOptions):
        raise WrongTypeError(f"options must be an IKOptions; got {type(opts).__name__}")
    link, T_link_frame, CF = frame_constants(robot, frame, tool)
    Tg = np.asarray(T_goal) if isinstance(T_goal, np.ndarray) else None
    if Tg is not None and Tg.ndim > 2:
        return _ik_batch(robot, Tg, q0, link, T_link_frame, CF, opts, rng)
    return _ik_one(robot, T_goal, q0, link, T_link_frame, CF, opts, rng)


def _ik_one(
    robot: Robot,
    T_goal: ArrayLike,
    q0: ArrayLike | None,
    link: int,
    T_link_frame: NDArray[np.float64],
    CF: NDArray[np.float64],
    opts: IKOptions,
    rng: np.random.Generator | None,
) -> IKResult:
    """:func:`ik` for one goal (4, 4), keeping the path."""
    n = robot.n
    T_goal = check_pose("T_goal", T_goal)
    q = default_q0(robot) if q0 is None else _checks.as_exact("q0", q0, (n,))
    _check_within_limits(robot, q[None])
    m = link  # joints 1..m move the frame
    q_min, q_max, inv_vmax = _limits(robot, m, opts)
    fpar, ipar = _parameters(opts)
    path = np.empty((opts.max_iterations + 1, n))
    path[0] = q
    # one goal: the kernel once loaded or as the dispatcher decides (a one-shot call takes
    # the numpy loop: no start-up cost)
    solve = _kernel(1) if m > 0 else None
    q_best = np.empty(n)
    q_restart = np.empty((0, m))
    while True:  # a second pass only when the first one asks for restart configurations
        if solve is not None:
            k, best_k, err_p, err_o, converged, restarts, more = solve(
                CF, m, q_min, q_max, inv_vmax, q_restart, T_goal, fpar, ipar, path, q_best
            )
        else:
            k, best_k, err_p, err_o, converged, restarts, more = solve_numpy(
                Chain(robot, link, T_link_frame), q_min, q_max, inv_vmax, q_restart,
                np.array(T_goal[:3, 3]), np.array(T_goal[:3, :3]), fpar, ipar, path,
            )  # fmt: skip
        if not more:
            break
        rng = np.random.default_rng(0) if rng is None else rng
        q_restart = _restart_configurations(q_min, q_max, q[None, :m], opts, rng)[0]
    path = _checks.frozen(path[: k + 1])
    return IKResult(
        q=_checks.frozen(path[best_k]),
        converged=bool(converged),
        iterations=int(k),
        position_error=float(err_p),
        orientation_error=float(err_o),
        path=path,
        restarts=int(restarts),
    )


def _check_within_limits(robot: Robot, q: NDArray[np.float64]) -> None:
    """Raise :class:`LimitError` naming the first start (row of ``q`` (B, n)) outside."""
    if q.shape[0] == 1:  # one start: a Python loop beats four numpy calls
        row = q[0].tolist()
        lo, hi = robot.q_min.tolist(), robot.q_max.tolist()
        if all(lo[j] <= row[j] <= hi[j] for j in range(len(row))):
            return
    bad = (q < robot.q_min) | (q > robot.q_max)
    if bad.any():
        outside = np.argwhere(bad)
        b, j = (int(x) for x in outside[0])
        where = "" if q.shape[0] == 1 else f" (start {b})"
        raise LimitError(
            f"q0 must lie within the joint limits{where}; {robot.joint_names[j]} = "
            f"{q[b, j]:.6g} is outside [{robot.q_min[j]:.6g}, {robot.q_max[j]:.6g}]"
        )


def _limits(robot: Robot, m: int, opts: IKOptions) -> tuple[NDArray, NDArray, NDArray]:
    """Position limits and inverse velocity limits (0: none) of the first ``m`` joints.

    Remembered per robot in the kernels' cache (:class:`dynid._kernels.dispatch.Packed`;
    robots are immutable); never written to.
    """
    memo = _kernels.packed(robot).limits
    key = (m, bool(opts.velocity_limits))
    hit = memo.get(key)
    if hit is not None:
        return hit
    q_min, q_max = np.array(robot.q_min[:m]), np.array(robot.q_max[:m])
    inv_vmax = np.zeros(m)
    if opts.velocity_limits:
        dq_max = robot.dq_max[:m]
        inv_vmax = np.where(np.isfinite(dq_max), 1.0 / dq_max, 0.0)
    memo[key] = (q_min, q_max, inv_vmax)
    return q_min, q_max, inv_vmax


def _parameters(opts: IKOptions) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The options as the solvers' ``fpar`` and ``ipar`` arrays (remembered per options in
    the kernels' cache, :data:`dynid._kernels.CACHE`; at most 16)."""
    memo = _kernels.CACHE.options
    hit = memo.get(id(opts))  # (by identity: hashing the options costs a Python call)
    if hit is not None and hit[0] is opts:
        return hit[1]
    fpar = np.array(
        [
            opts.dt,
            opts.gain,
            opts.damping,
            opts.singular_threshold,
            opts.position_tolerance,
            opts.orientation_tolerance,
            opts.max_position_step,
            opts.max_orientation_step,
            opts.damping_error,
        ]
    )
    ipar = np.array([opts.max_iterations, opts.stall_iterations, opts.max_restarts], np.int64)
    if len(memo) >= 16:
        memo.pop(next(iter(memo)))
    memo[id(opts)] = (opts, (fpar, ipar))
    return fpar, ipar


def _restart_configurations(
    q_min: NDArray, q_max: NDArray, q0: NDArray, opts: IKOptions, rng: np.random.Generator
) -> NDArray[np.float64]:
    """Restart configurations (B, max_restarts, m) within the limits, one draw for all B.

    Unbounded joints draw within pi of the start ``q0`` (B, m).
    """
    lo = np.where(np.isfinite(q_min), q_min, np.minimum(q0, q_max) - np.pi)
    hi = np.where(np.isfinite(q_max), q_max, np.maximum(q0, q_min) + np.pi)
    u = rng.random((opts.max_restarts, q_min.shape[0]))
    return lo[:, None, :] + (hi - lo)[:, None, :] * u


def check_poses(name: str, T: ArrayLike) -> NDArray[np.float64]:
    """:func:`check_pose` for a batch (..., 4, 4): a new array; errors name the first pose."""
    T = np.array(_checks.as_batch(name, T, (4, 4)))
    flat = T.reshape(-1, 4, 4)
    last = np.max(np.abs(flat[:, 3] - (0.0, 0.0, 0.0, 1.0)), axis=-1)
    bad = np.flatnonzero(last > ORTHONORMALITY_TOLERANCE)
    if bad.size:
        b = int(bad[0])
        raise DataError(f"{name}[{b}] must have last row [0, 0, 0, 1]; got {flat[b, 3].tolist()}")
    R = flat[:, :3, :3]
    dev = np.max(np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(3)), axis=(1, 2))
    det = np.linalg.det(R)
    bad = np.flatnonzero((dev > ORTHONORMALITY_TOLERANCE) | (det <= 0))
    if bad.size:
        b = int(bad[0])
        raise DataError(
            f"{name}[{b}] rotation block must be orthonormal with det +1 (max |R^T R - I| <= "
            f"{ORTHONORMALITY_TOLERANCE:g}); got deviation {dev[b]:.3g}, det {det[b]:.3g}"
        )
    fix = np.flatnonzero(dev > 1e-13)
    if fix.size:
        U, _, Vt = np.linalg.svd(R[fix])
        flat[fix, :3, :3] = U @ Vt
    flat[:, 3] = (0.0, 0.0, 0.0, 1.0)
    return T


def _ik_batch(
    robot: Robot,
    T_goal: NDArray,
    q0: ArrayLike | None,
    link: int,
    T_link_frame: NDArray[np.float64],
    CF: NDArray[np.float64],
    opts: IKOptions,
    rng: np.random.Generator | None,
) -> IKResult:
    """:func:`ik` for goals (..., 4, 4): every goal from its start, in parallel if compiled."""
    goals = check_poses("T_goal", T_goal)
    shape = goals.shape[:-2]
    n, m = robot.n, link
    start = default_q0(robot) if q0 is None else _checks.as_batch("q0", q0, (n,))
    try:
        # a new C array, writable whether q0 was broadcast or not: one compiled signature
        starts = np.array(np.broadcast_to(start, shape + (n,)), order="C").reshape(-1, n)
    except ValueError:
        raise ShapeError(
            f"q0 must broadcast to the goals' batch shape {shape}; got {np.shape(start)}"
        ) from None
    _check_within_limits(robot, starts)
    G = starts.shape[0]
    goals = goals.reshape(G, 4, 4)
    q_min, q_max, inv_vmax = _limits(robot, m, opts)
    fpar, ipar = _parameters(opts)
    if opts.max_restarts > 0 and m > 0:
        rng = np.random.default_rng(0) if rng is None else rng
        q_restart = _restart_configurations(q_min, q_max, starts[:, :m], opts, rng)
    else:
        q_restart = np.empty((G, 0, m))
    solve = _kernel(2) if m > 0 else None
    out = np.array(starts)
    stats = np.zeros((G, 6))
    if solve is not None:
        solve(CF, m, q_min, q_max, inv_vmax, q_restart, goals, fpar, ipar, starts, out, stats)
    elif m > 0:
        chain = Chain(robot, link, T_link_frame)
        path = np.empty((opts.max_iterations + 1, n))
        for g in range(G):
            path[0] = starts[g]
            k, best_k, ep, eo, conv, rs, _ = solve_numpy(
                chain, q_min, q_max, inv_vmax, q_restart[g], np.array(goals[g, :3, 3]),
                np.array(goals[g, :3, :3]), fpar, ipar, path,
            )  # fmt: skip
            out[g] = path[best_k]
            stats[g] = (k, ep, eo, conv, rs, 0.0)
    else:  # the frame is fixed to the base: nothing moves
        for g in range(G):
            T = T_link_frame
            ep = float(np.linalg.norm(goals[g, :3, 3] - T[:3, 3]))
            eo = rotvec(goals[g, :3, :3] @ T[:3, :3].T)[3]
            conv = ep <= opts.position_tolerance and eo <= opts.orientation_tolerance
            stats[g] = (0, ep, eo, conv, 0, 0.0)
    return IKResult(
        q=_checks.frozen(out.reshape(shape + (n,))),
        converged=_checks.frozen(stats[:, 3].reshape(shape) > 0.5),
        iterations=_checks.frozen(stats[:, 0].astype(np.int64).reshape(shape)),
        position_error=_checks.frozen(stats[:, 1].reshape(shape)),
        orientation_error=_checks.frozen(stats[:, 2].reshape(shape)),
        path=None,
        restarts=_checks.frozen(stats[:, 4].astype(np.int64).reshape(shape)),
    )
