"""Exciting trajectories: finite Fourier series with (1 - cos) ramps, optimised for identification.

Form (Gaz et al. 2019, supplementary material Sec. II): a finite Fourier series of ``L``
harmonics of ``w_f`` between two (1 - cos) ramps, at rest at both ends
(:class:`~dynid.simulation.exciting_trajectory.ExcitingTrajectory`, which states it in full).

Optimisation (:func:`optimise_excitation`). The coefficients and the start position
minimise the condition number of the classical regressor ``[Y_b(q, dq, ddq), F(dq)]``
(base parameters of :func:`~dynid.regressors.base.base_parameters` ``kind="torque"``,
then ``fv, fc, fo`` per joint; unscaled, as Gaz et al. report it; Swevers et al., IEEE TRA
13(5), 1997, and FIGAROH/FloBaRoID/BIRDy do the same) or, with ``criterion="logdet"``,
maximise ``log det`` of its column-scaled Gram matrix (D-optimality). Constraints:

* position, velocity and acceleration limits with margins hold by construction (the
  robot's, or narrower ones given: ``ranges``, ``max_velocity``, ``max_acceleration``,
  ``max_torque``, :func:`design_limits`; where the robot gives no velocity or
  acceleration limit, :data:`UNLIMITED_VELOCITY` and :data:`UNLIMITED_ACCELERATION`): each
  candidate is scaled per joint into ``[q_min + m_q, q_max - m_q]``,
  ``|dq| <= dq_max - m_dq`` and ``|ddq| <= (1 - m_ddq) ddq_max`` on a 100 Hz grid, and its
  start position is the requested one clipped to where the motion fits;
* torques ``|M ddq + c + g + tau_f(dq)| <= (1 - m_tau) tau_max`` (the model's, with its
  friction), capsule clearances to obstacles and between non-adjacent links
  (:mod:`dynid.simulation.collision`; radius and clearances by default scaled to the arm,
  :func:`~dynid.simulation.collision.collision_sizes`) enter as quadratic penalties;
* the result is the best iterate (the start included) free of penalty, else the optimiser's
  last; it is checked at 1 kHz and, if a torque or clearance is still violated, its
  amplitudes are reduced until none is, the motion drawn toward the requested start
  (``status`` says so; kept unreduced when reducing does not help). The start itself is
  returned when it is admissible and the result is not better on the same 200 Hz grid
  (``improved`` is then False). The closest pair of links and the closest link to each
  obstacle are named with their distances (:mod:`dynid.simulation.clearance`).

scipy's L-BFGS-B; the ``cond`` criterion's gradient by the chain rule through the
samples (:mod:`dynid.simulation.excitation_gradient`: about 16 times cheaper than the
finite differences it replaced), ``logdet``'s by forward differences of scipy's steps,
evaluated in one batch. The start is the best of ``n_starts``
seeded random candidates, each as large as its joints' limits allow; when the best
violates a torque or a clearance (a small arm's elbow folded into its shoulder at the top
of its range), the candidates at 80, 60, 40 and 20 % of that amplitude too, the best of
those that keep the torques and clearances first (an arm whose joints turn +-2 pi reaches
the floor and itself at most of those amplitudes), from which the optimiser can shrink or
grow a motion (at the largest that fits, the scaling undoes either, and a start in
collision was never left). Seeded and reproducible; ``progress(iteration, max_iter,
cond)`` is called after each iteration and ``evaluated(evaluations, budget)`` after each
evaluation of the objective (a batch of them with finite differences; an iteration can
take dozens when its line search struggles); both are also told to :mod:`dynid.progress`
(the command line's progress lines) and each iteration logged at ``INFO`` (``-v``).
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from .. import progress as _progress
from ..dynamics.rnea import rnea
from ..exceptions import OptionError
from ..friction.model import robot_friction
from ..identification.classical import friction_regressor
from ..model.drive import Drive
from ..model.robot import Robot, checked_robot
from ..regressors.base import BaseParameters, base_parameters
from ..regressors.torque import torque_regressor_prepared
from .clearance import Approach, closest_approaches
from .collision import (
    CapsuleModel,
    CollisionSizes,
    Obstacles,
    capsule_model,
    capsule_segments,
    collision_sizes,
    obstacle_distances,
    self_distances,
)
from .excitation_gradient import objective_gradient
from .exciting_trajectory import ExcitingTrajectory, _basis
from .trajectories import Trajectory, uniform_times

__all__ = [
    "ExcitationOptions",
    "ExcitationResult",
    "STATUSES",
    "TIGHTENED",
    "UNLIMITED_ACCELERATION",
    "UNLIMITED_VELOCITY",
    "design_limits",
    "not_tightened",
    "ExcitingTrajectory",
    "excitation_condition_number",
    "limit_margins",
    "optimise_excitation",
    "within_ranges",
]

_log = logging.getLogger(__name__)
#: The statuses a design ends with (:attr:`ExcitationResult.status`).
STATUSES = ("ok", "reduced", "infeasible")
#: Rate [Hz] of the samples the result and its start are compared on (and reported).
#: The optimiser's absolute finite-difference step in its variables (scipy's ``eps``).
_FD_STEP = 1e-4
#: Samples of the limits' grid evaluated together in one batch (about 25 MB of states and
#: torques; the Panda's 20 s design: 31 evaluations a batch).
_BATCH_SAMPLES = 2**16
_FS_REPORTED = 200.0
#: Fractions of their amplitudes the random starts are also tried at when none at full
#: amplitude keeps the torques and clearances (:func:`_start`).
_START_FRACTIONS = (0.8, 0.6, 0.4, 0.2)
#: The bound [rad/s] the design keeps a joint's velocity within where the robot gives no
#: velocity limit (on its 100 Hz grid; not checked at 1 kHz).
UNLIMITED_VELOCITY = 2.0
#: The bound [rad/s^2] the design keeps a joint's acceleration within where the robot
#: gives no acceleration limit (a URDF holds none; on its 100 Hz grid, not checked at 1 kHz).
UNLIMITED_ACCELERATION = 10.0
#: The limits the options tighten: option field -> (the robot's field, unit).
TIGHTENED = {
    "max_velocity": ("dq_max", "rad/s"),
    "max_acceleration": ("ddq_max", "rad/s^2"),
    "max_torque": ("tau_max", "N m"),
}


@dataclass(frozen=True, slots=True)
class ExcitationOptions:
    """Settings of :func:`optimise_excitation` (defaults: the paper's form and margins).

    Raises
    ------
    OptionError
        An unknown criterion, no harmonic, a duration or frequency not positive, a highest
        harmonic at or above half of ``fs_regressor``, a margin or clearance negative or
        infinite, a fractional margin outside [0, 1).

    Attributes
    ----------
    duration : float
        Fourier part [s] (20).
    harmonics : int
        ``L`` (5).
    base_frequency : float
        ``w_f / (2 pi)`` [Hz] (0.075, the paper's 0.15 pi rad/s).
    ramp : float
        Both ramps together [s] (1).
    position_margin : float
        Distance kept from the position limits [rad] (5 degrees, the paper's).
    velocity_margin : float
        Subtracted from the velocity limits [rad/s] (10 degrees/s, the paper's).
    acceleration_margin : float
        Fraction of the acceleration limits kept free (0.1).
    torque_margin : float
        Fraction of the torque limits kept free (0.1).
    obstacle_clearance : float, optional
        Smallest capsule distance to an obstacle [m] (default scaled to the arm: 0.05 for
        a chain of 1.3 m or longer, :func:`~dynid.simulation.collision.collision_sizes`).
    self_clearance : float, optional
        Smallest distance between non-adjacent capsules [m] (default scaled to the arm:
        0.02 for a chain of 1.3 m or longer).
    radii : float or tuple of float, optional
        Capsule radii [m] (default scaled to the arm: 0.06 for a chain of 1.3 m or
        longer).
    criterion : {"cond", "logdet"}
        Minimise the (unscaled) condition number, or maximise ``log det`` of the
        column-scaled Gram matrix.
    max_iter : int
        L-BFGS-B iterations (60).
    max_evaluations : int
        Objective evaluations allowed to L-BFGS-B (6000): each with its gradient one
        (``cond``; about 20 ms for the Panda's 20 s design, so that ``max_iter`` ends the
        optimisation first), each with its finite differences ``n (2 L + 1) + 1``
        (``logdet``; about 2 ms each).
    n_starts : int
        Random candidates the start is chosen from (16).
    fs_regressor, fs_limits, fs_collision : float
        Grids [Hz] of the regressor (5), of the limit and torque checks (100) and of
        the collision checks (15) during the optimisation; the clearances there are
        required with 1 cm to spare (the result is checked at 1 kHz).
    ranges : tuple of (int, float, float)
        Joint ranges the design keeps to, narrower than the robot's limits: ``(j, lo,
        hi)`` with ``j`` the joint's index from 0 and ``lo < hi`` [rad] (default none: the
        limits); they replace the limits of the design and its checks
        (:func:`within_ranges`), the position margin kept inside them.
    max_velocity, max_acceleration, max_torque : tuple of (int, float)
        Limits of the cell tighter than the robot's: ``(j, limit)`` with ``j`` the joint's
        index from 0 and ``limit > 0`` [rad/s, rad/s^2, N m] (default none). Each joint
        keeps the smaller of its own limit and the one given (:func:`design_limits`; a
        larger one never loosens it, :func:`not_tightened`), with the margins above kept
        inside it.
    """

    duration: float = 20.0
    harmonics: int = 5
    base_frequency: float = 0.075
    ramp: float = 1.0
    position_margin: float = float(np.deg2rad(5.0))
    velocity_margin: float = float(np.deg2rad(10.0))
    acceleration_margin: float = 0.1
    torque_margin: float = 0.1
    obstacle_clearance: float | None = None
    self_clearance: float | None = None
    radii: float | tuple[float, ...] | None = None
    criterion: str = "cond"
    max_iter: int = 60
    max_evaluations: int = 6000
    n_starts: int = 16
    fs_regressor: float = 10.0
    fs_limits: float = 100.0
    fs_collision: float = 15.0
    ranges: tuple[tuple[int, float, float], ...] = ()
    max_velocity: tuple[tuple[int, float], ...] = ()
    max_acceleration: tuple[tuple[int, float], ...] = ()
    max_torque: tuple[tuple[int, float], ...] = ()

    def __post_init__(self) -> None:
        for k in TIGHTENED:
            for j, v in getattr(self, k):
                if not (j >= 0 and 0 < v < float("inf")):
                    raise OptionError(
                        f"{k} (--{k.replace('_', '-')}) must name a joint and a finite limit "
                        f"> 0; got joint {j + 1}: {v:g}"
                    )
        for j, lo, hi in self.ranges:
            if not (j >= 0 and np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                raise OptionError(
                    f"ranges (--range) must name a joint and finite lo < hi; got joint "
                    f"{j + 1}: {lo:g}:{hi:g}"
                )
        if self.criterion not in ("cond", "logdet"):
            raise OptionError(f"criterion must be 'cond' or 'logdet'; got {self.criterion!r}")
        if self.harmonics < 1 or not (self.duration > 0 and self.base_frequency > 0):
            raise OptionError("harmonics must be >= 1, duration and base_frequency positive")
        top = self.harmonics * self.base_frequency
        if not top < 0.5 * self.fs_regressor:  # aliased: the optimum is of other samples
            raise OptionError(
                f"the highest harmonic, {self.harmonics} x {self.base_frequency:g} Hz = "
                f"{top:g} Hz, must lie below {0.5 * self.fs_regressor:g} Hz, half the rate at "
                "which the regressor is optimised; lower --base-frequency or --harmonics"
            )
        for k in ("acceleration_margin", "torque_margin"):
            if not 0 <= getattr(self, k) < 1:
                raise OptionError(f"{k} must be in [0, 1); got {getattr(self, k)}")
        for k in ("position_margin", "velocity_margin", "obstacle_clearance", "self_clearance"):
            v = getattr(self, k)
            if v is not None and not 0 <= v < float("inf"):  # a negative one widens the limits
                flag = f"--{k.replace('_', '-')}"
                raise OptionError(f"{k} ({flag}) must be finite and >= 0; got {v:g}")

    def sized_for(self, robot: Robot) -> ExcitationOptions:
        """These options with the radius and clearances not given set to ``robot``'s
        (:func:`~dynid.simulation.collision.collision_sizes`)."""
        sizes = collision_sizes(robot)
        return dataclasses.replace(
            self,
            radii=sizes.radius if self.radii is None else self.radii,
            self_clearance=_given(self.self_clearance, sizes.self_clearance),
            obstacle_clearance=_given(self.obstacle_clearance, sizes.obstacle_clearance),
        )

    @property
    def derived(self) -> tuple[str, ...]:
        """The options left to their defaults scaled to the arm (not given)."""
        return tuple(
            k for k in ("radii", "self_clearance", "obstacle_clearance") if getattr(self, k) is None
        )


def within_ranges(robot: Robot, ranges: tuple[tuple[int, float, float], ...]) -> Robot:
    """``robot`` with its position limits narrowed to ``ranges`` (``(j, lo, hi)`` [rad],
    :attr:`ExcitationOptions.ranges`); its neutral position clipped into them.

    Raises
    ------
    OptionError
        A joint index beyond the robot's, or a range not inside the joint's limits.
    """
    if not ranges:
        return robot
    q_min, q_max = robot.q_min.copy(), robot.q_max.copy()
    for j, lo, hi in ranges:
        if j >= robot.n:
            raise OptionError(f"--range: joint {j + 1} of a robot of {robot.n} joints")
        if lo < robot.q_min[j] or hi > robot.q_max[j]:
            raise OptionError(
                f"--range: joint {j + 1}'s {lo:g}:{hi:g} rad is not within its limits "
                f"{robot.q_min[j]:g}:{robot.q_max[j]:g} rad"
            )
        q_min[j], q_max[j] = lo, hi
    qn = None if robot.q_neutral is None else np.clip(robot.q_neutral, q_min, q_max)
    return robot.replace(q_min=q_min, q_max=q_max, q_neutral=qn)


def design_limits(robot: Robot, options: ExcitationOptions) -> Robot:
    """``robot`` with the limits the design keeps to: its position limits narrowed to
    ``options.ranges`` (:func:`within_ranges`) and its velocity, acceleration and torque
    limits to ``options.max_velocity``, ``max_acceleration`` and ``max_torque``, each
    joint's the smaller of its own and the one given [rad/s, rad/s^2, N m].

    Raises
    ------
    OptionError
        A joint index beyond the robot's, a range not inside the joint's limits, or a
        velocity limit given at or below the velocity margin kept inside it (no motion
        left).
    """
    robot = within_ranges(robot, options.ranges)
    low = [(j, v) for j, v in options.max_velocity if v <= options.velocity_margin]
    if low:
        j, v = low[0]
        m = options.velocity_margin
        raise OptionError(
            f"--max-velocity: {v:g} rad/s on joint {j + 1} leaves no motion within the "
            f"velocity margin {m:.4g} rad/s ({np.rad2deg(m):.3g} deg/s) kept inside it; give a "
            "larger limit or a smaller --velocity-margin [deg/s]"
        )
    changes = {}
    for k, (field_name, _) in TIGHTENED.items():
        given = getattr(options, k)
        if not given:
            continue
        limit = np.array(getattr(robot, field_name), dtype=np.float64)
        for j, v in given:
            if j >= robot.n:
                flag = f"--{k.replace('_', '-')}"
                raise OptionError(f"{flag}: joint {j + 1} of a robot of {robot.n} joints")
            limit[j] = min(limit[j], v)
        changes[field_name] = limit
    return robot.replace(**changes) if changes else robot


def not_tightened(
    robot: Robot, options: ExcitationOptions
) -> tuple[tuple[str, int, float, float], ...]:
    """The limits given above the robot's own, which the design leaves at the robot's:
    ``(option field, j, given, robot's limit)`` [rad/s, rad/s^2 or N m], j from 0."""
    out = []
    for k, (field_name, _) in TIGHTENED.items():
        own = getattr(robot, field_name)
        out += [(k, j, v, float(own[j])) for j, v in getattr(options, k) if j < robot.n]
    return tuple(x for x in out if x[2] > x[3])


def _given(value: float | None, default: float) -> float:
    return default if value is None else value


@dataclass(frozen=True, slots=True, eq=False)
class ExcitationResult:
    """An optimised exciting trajectory and its checks at 1 kHz.

    Attributes
    ----------
    trajectory : ExcitingTrajectory
    condition_number : float
        Unscaled condition number of ``[Y_b, F]`` along the trajectory (200 Hz samples).
    scaled_condition_number : float
        The same with unit column norms.
    initial_condition_number : float
        That of the start of the optimisation (the same 200 Hz samples).
    margins : dict
        Smallest margin to every limit at 1 kHz (:func:`limit_margins`), plus
        ``"obstacles"`` (name -> smallest clearance minus the required one [m]) and
        ``"self_collision"`` (smallest clearance between non-adjacent capsules minus the
        required one [m]); all >= 0 when the trajectory is admissible. ``"closest"``: the
        closest pair of links, then the closest link to each obstacle
        (:class:`~dynid.simulation.clearance.Approach`, naming them).
    status : str
        ``"ok"``, ``"reduced"`` when the amplitudes had to be reduced after the
        optimisation, ``"infeasible"`` when no admissible trajectory was found.
    iterations : int
    evaluations : int
    history : tuple of float
        Condition number after each iteration.
    options : ExcitationOptions
        The options used: the radius and clearances not given set to the arm's
        (:meth:`ExcitationOptions.sized_for`).
    obstacles : Obstacles
    start_margins : dict
        :attr:`margins` of the start of the optimisation.
    improved : bool
        Whether the result is better than the start by the criterion (on the same 200 Hz
        samples); False when the start, admissible, is returned, or when neither is
        admissible and the optimiser only reduced the violations.
    sizes : CollisionSizes or None
        The arm's default radius and clearances and the chain length they are scaled by.
    derived : tuple of str
        The options among ``radii``, ``self_clearance``, ``obstacle_clearance`` that were
        not given and took the arm's defaults (``sizes``).
    drive : Drive or None
        The drive whose known rotor inertias the torques checked include.
    rest : ndarray, shape (n,), or None
        The rest position the motion is centred on and every reduction of its amplitudes
        shrinks toward [rad] (the preferred one within the limits).
    rest_clearances : tuple of Approach
        The obstacle clearances the rest position already violates: then no trajectory
        about it is admissible.
    n_base : int
        Base parameters in the regressor whose condition number is optimised (its columns
        ``n_base + 3 n``: viscous, Coulomb and offset friction per joint after them).
    """

    trajectory: ExcitingTrajectory
    condition_number: float
    scaled_condition_number: float
    initial_condition_number: float
    margins: dict[str, Any]
    status: str
    iterations: int
    evaluations: int
    history: tuple[float, ...]
    options: ExcitationOptions
    obstacles: Obstacles = field(default_factory=Obstacles)
    start_margins: dict[str, Any] = field(default_factory=dict)
    improved: bool = True
    sizes: CollisionSizes | None = None
    derived: tuple[str, ...] = ()
    drive: Drive | None = None
    rest: NDArray[np.float64] | None = None
    rest_clearances: tuple[Approach, ...] = ()
    n_base: int = 0

    @property
    def start_admissible(self) -> bool:
        """Whether the start of the optimisation kept every limit and clearance at 1 kHz."""
        return bool(self.start_margins) and _admissible(self.start_margins)

    def violations(self, start: bool = False) -> list[str]:
        """The negative margins of the result (or of the start), e.g. ``torque[2] -8.34``,
        ``self_collision -0.031 (link2, link5)``."""
        return _violations(self.start_margins if start else self.margins)

    def violated_clearances(self, start: bool = False) -> tuple[Approach, ...]:
        """The closest approaches of the result (or of the start) that violate a clearance."""
        m = self.start_margins if start else self.margins
        return tuple(a for a in m.get("closest", ()) if a.margin < -1e-9)


def _max_over_samples(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """The largest of ``a`` (..., N, k) over its N samples: (..., k), reduced along a
    contiguous copy with the samples last (several times faster than ``max(axis=-2)`` for
    N samples of a few columns; the same values)."""
    return _samples_last(a).max(axis=-1)


def _min_over_samples(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """The smallest of ``a`` (..., N, k) over its N samples, as :func:`_max_over_samples`."""
    return _samples_last(a).min(axis=-1)


def _samples_last(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """A contiguous copy of ``a`` (..., N, k) as (..., k, N)."""
    return np.ascontiguousarray(np.swapaxes(a, -1, -2))


def _classical_regressor(
    robot: Robot, base: BaseParameters, traj: Trajectory
) -> NDArray[np.float64]:
    """``[Y_b, F]`` stacked sample-major (N n, r + 3 n)."""
    return _regressor_of(robot, base, np.asarray(traj.q), np.asarray(traj.dq), np.asarray(traj.ddq))


def _regressor_of(
    robot: Robot,
    base: BaseParameters,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
) -> NDArray[np.float64]:
    """:func:`_classical_regressor` of validated (..., N, n) samples [rad, rad/s, rad/s^2]:
    (..., N n, r + 3 n), one stacked regressor per leading index. The base columns are
    written by the regressor straight into the first ``r`` of a contiguous array (no
    gather into a strided slice), the friction columns after."""
    r, n = len(base.independent), q.shape[-1]
    q2, dq2, ddq2 = (np.reshape(x, (-1, n)) for x in (q, dq, ddq))
    W = torque_regressor_prepared(
        robot, q2, dq2, ddq2, robot.gravity, columns=base.independent, width=r + 3 * n
    )
    W[..., r:] = friction_regressor(dq2)
    return W.reshape(q.shape[:-2] + (-1, W.shape[-1]))


def _criterion(W: NDArray[np.float64], criterion: str) -> float:
    """The optimised criterion of one ``[Y_b, F]`` (N n, r + 3 n) (:func:`_criteria`)."""
    return float(_criteria(W[None], criterion)[0])


def _criteria(W: NDArray[np.float64], criterion: str) -> NDArray[np.float64]:
    """The optimised criterion of each ``[Y_b, F]`` of a stack (B, N n, r + 3 n) (lower is
    better): ``log cond`` (unscaled) or ``-mean log s`` of the column-scaled singular
    values (``logdet``): (B,).

    ``log cond`` is ``log(lambda_max / lambda_min) / 2`` of the Gram matrix ``W^T W`` (its
    eigenvalues are the squared singular values): a ninth of the SVD's time on the
    optimiser's (N n, r + 3 n) regressors, and at the conditions met here (up to about 1e4,
    squared 1e8) its relative error stays near 1e-8, far below the finite-difference step.
    The reported numbers (:func:`_conds`) come from the SVD."""
    if criterion == "cond":
        # each Gram matrix on its own: numpy's product of a matrix with its own transpose
        # (one triangle, half the work of a batched product)
        lam = np.linalg.eigvalsh(np.stack([w.T @ w for w in W]))
        return 0.5 * np.log(lam[:, -1] / np.maximum(lam[:, 0], 1e-300))
    nrm = np.linalg.norm(W, axis=-2)
    s = np.linalg.svd(W / np.where(nrm > 0, nrm, 1.0)[:, None, :], compute_uv=False)
    return -np.mean(np.log(np.maximum(s, 1e-300)), axis=-1)


def _conds(W: NDArray[np.float64]) -> tuple[float, float]:
    s = np.linalg.svd(W, compute_uv=False)
    nrm = np.linalg.norm(W, axis=0)
    ss = np.linalg.svd(W / np.where(nrm > 0, nrm, 1.0), compute_uv=False)
    cu = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
    cs = float(ss[0] / ss[-1]) if ss[-1] > 0 else float("inf")
    return cu, cs


def excitation_condition_number(
    robot: Robot,
    traj: Trajectory | ExcitingTrajectory,
    *,
    base: BaseParameters | None = None,
    fs: float = _FS_REPORTED,
) -> tuple[float, float]:
    """Unscaled and scaled condition numbers of the classical regressor along a trajectory.

    ``[Y_b(q, dq, ddq), F(dq)]`` (base parameters ``kind="torque"``, then ``fv, fc, fo``
    per joint; Gaz et al. 2019 report 121.88 for theirs), sampled at ``fs`` [Hz] when an
    :class:`ExcitingTrajectory` is given, at its own samples otherwise.
    """
    _checks.of_type(
        "traj", traj, (Trajectory, ExcitingTrajectory), "a Trajectory or an ExcitingTrajectory"
    )
    checked_robot(robot)
    base = base_parameters(robot, kind="torque") if base is None else base
    tr = traj.sample(fs) if isinstance(traj, ExcitingTrajectory) else traj
    return _conds(_classical_regressor(robot, base, tr))


def _motor_torques(robot: Robot, tr: Trajectory, drive: Drive | None = None) -> NDArray[np.float64]:
    """Joint torques [N m] (N, n): ``M ddq + c + g``, the model's friction (where the
    drive puts it: at the motors, ``K^T f(K dq)``, for a drive whose friction acts there,
    :func:`~dynid.friction.model.robot_friction`) and, with a drive of known rotor
    inertias, their reflected torques ``K^T diag(I_a) K ddq``."""
    return _torques_of(robot, np.asarray(tr.q), np.asarray(tr.dq), np.asarray(tr.ddq), drive)


def _torques_of(
    robot: Robot,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    drive: Drive | None = None,
) -> NDArray[np.float64]:
    """:func:`_motor_torques` of validated (N, n) samples [rad, rad/s, rad/s^2]."""
    tau = rnea(robot, q, dq, ddq)
    friction = robot.friction if drive is None else robot_friction(robot, drive)
    if friction is not None:
        tau = tau + friction.torques(dq)
    if drive is not None and drive.rotor_inertia is not None:
        tau = tau + drive.rotor_torques(ddq, drive.rotor_inertia)
    return tau


def limit_margins(
    robot: Robot,
    tr: Trajectory,
    options: ExcitationOptions = ExcitationOptions(),
    *,
    drive: Drive | None = None,
) -> dict[str, list[float]]:
    """Smallest margin of each joint to each limit, after the required margins (>= 0: ok).

    Keys ``position`` [rad], ``velocity`` [rad/s], ``acceleration`` [rad/s^2] and
    ``torque`` [N m], each a list of n floats: e.g. ``min_t (q_max - m_q - q_j(t))`` and
    the same at the lower limit; ``inf`` where a limit is infinite. Torques are the
    model's (``M ddq + c + g`` plus its friction, where ``drive`` puts it) plus, with a
    ``drive`` of known rotor inertias, their reflected torques ``K^T diag(I_a) K ddq``
    (``k^2 I_a ddq`` on a joint of gear ratio ``k``, uncoupled).
    """
    q, dq, ddq = np.asarray(tr.q), np.asarray(tr.dq), np.asarray(tr.ddq)
    m = options
    with np.errstate(invalid="ignore"):
        pos = np.minimum(
            (robot.q_max - m.position_margin) - q.max(axis=0),
            q.min(axis=0) - (robot.q_min + m.position_margin),
        )
        vel = (robot.dq_max - m.velocity_margin) - np.abs(dq).max(axis=0)
        acc = (1 - m.acceleration_margin) * robot.ddq_max - np.abs(ddq).max(axis=0)
        tau = (1 - m.torque_margin) * robot.tau_max - np.abs(_motor_torques(robot, tr, drive)).max(
            axis=0
        )
    return {
        k: [float(x) for x in v]
        for k, v in (("position", pos), ("velocity", vel), ("acceleration", acc), ("torque", tau))
    }


class _Problem:
    """Precomputed grids and maps of one optimisation (internal)."""

    def __init__(
        self,
        robot: Robot,
        opts: ExcitationOptions,
        obstacles: Obstacles,
        caps: CapsuleModel,
        base: BaseParameters,
        q_start: NDArray[np.float64],
    ) -> None:
        self.robot, self.opts, self.obstacles, self.caps, self.base = (
            robot,
            opts,
            obstacles,
            caps,
            base,
        )
        n, L = robot.n, opts.harmonics
        self.n, self.L = n, L
        self.w_f = 2 * np.pi * opts.base_frequency
        total = opts.duration + opts.ramp
        D, T = opts.duration, opts.ramp
        self.t_lim = uniform_times(total, opts.fs_limits)
        self.t_reg = uniform_times(total, opts.fs_regressor)
        self.t_col = uniform_times(total, opts.fs_collision)
        self.B_lim = _basis(self.t_lim, self.w_f, L, D, T)
        self.B_reg = _basis(self.t_reg, self.w_f, L, D, T)
        self.B_col = _basis(self.t_col, self.w_f, L, D, T)[0]
        # continuity of the acceleration at both ends of the Fourier part: C c = 0
        lw = self.w_f * np.arange(1, L + 1)
        C = np.stack(
            [
                np.concatenate([np.zeros(L), lw]),
                np.concatenate([-np.sin(D * lw) * lw, np.cos(D * lw) * lw]),
            ]
        )
        self.Pi = np.eye(2 * L) - np.linalg.pinv(C) @ C  # (rows equal when D w_f = 2 pi k)
        finite = np.isfinite(robot.q_min) & np.isfinite(robot.q_max)
        self.lo = np.where(finite, robot.q_min + opts.position_margin, -np.pi)
        self.hi = np.where(finite, robot.q_max - opts.position_margin, np.pi)
        self.vmax = np.where(
            np.isfinite(robot.dq_max), robot.dq_max - opts.velocity_margin, UNLIMITED_VELOCITY
        )
        self.amax = np.where(
            np.isfinite(robot.ddq_max),
            (1 - opts.acceleration_margin) * robot.ddq_max,
            UNLIMITED_ACCELERATION,
        )
        self.tmax = (1 - opts.torque_margin) * robot.tau_max
        self.q_start = q_start
        self.evaluations = 0
        #: Called after each evaluation with the evaluations so far and their budget.
        self.evaluated: Callable[[int, int], None] | None = None
        self.budget = opts.max_evaluations
        #: The optimiser's iterations done and the last one's condition number (told with
        #: each evaluation's progress).
        self.iteration, self.cond = 0, float("nan")
        #: The drive whose known rotor inertias the torques include (None: none).
        self.drive: Drive | None = None
        #: Evaluations computed together (:meth:`objectives`): about
        #: :data:`_BATCH_SAMPLES` samples of the limits' grid.
        self.chunk = max(1, _BATCH_SAMPLES // len(self.t_lim))

    def coefficients(self, x: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
        """Coefficients (n, 2L) within the limits and start position (n,) of ``x``
        (:meth:`coefficients_of` of one)."""
        c, q0 = self.coefficients_of(np.asarray(x)[None])
        return c[0], q0[0]

    def coefficients_of(self, X: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
        """Coefficients (B, n, 2L) within the limits and start positions (B, n) of the
        variables ``X`` (B, n 2L + n): each joint's raw coefficients (n 2L) scaled down to
        fit the limits when they exceed them, and its rest position's offset from
        ``q_start`` (n) [rad], clipped to where the motion fits."""
        n, k = self.n, self.n * 2 * self.L
        c, lo, hi = self._fitted(X[:, :k].reshape(-1, n, 2 * self.L) @ self.Pi.T)
        return c, np.clip(self.q_start + X[:, k:], lo, hi)

    def joint_coefficients(
        self, X: NDArray[np.float64], joint: NDArray[np.intp]
    ) -> tuple[NDArray, NDArray]:
        """Of each row of ``X`` (B, n 2L + n), only joint ``joint[b]``'s coefficients
        (B, 2L) and rest position (B,) [rad] (:meth:`coefficients_of`'s row ``joint[b]``)."""
        n, L2 = self.n, 2 * self.L
        raw = X[:, : n * L2].reshape(-1, n, L2)[np.arange(len(X)), joint]
        c, lo, hi = self._fitted(raw @ self.Pi.T, joint=joint)
        return c, np.clip(self.q_start[joint] + X[np.arange(len(X)), n * L2 + joint], lo, hi)

    def steps(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The forward-difference steps of the variables ``x`` (:func:`_fd_steps`)."""
        return _fd_steps(x)

    def _fitted(
        self,
        c: NDArray[np.float64],
        fraction: float = 1.0,
        joint: NDArray[np.intp] | slice = slice(None),
    ) -> tuple[NDArray, ...]:
        """Coefficients ``c`` (..., n, 2L) scaled to ``fraction`` of the largest motion
        within the position, velocity and acceleration limits (never up), and the lowest
        and highest rest positions (..., n each) [rad] that keep that motion within the
        position limits and their margins; with ``joint`` (B,), ``c`` (B, 2L) is one row
        each of those joints."""
        flat = c.reshape(-1, c.shape[-1])
        q, dq, ddq = (
            (flat @ P.T).reshape(c.shape[:-1] + (len(P),)) for P in self.B_lim
        )  # (..., n, N): the samples last, reduced along contiguous rows
        q_lo, q_hi = q.min(axis=-1), q.max(axis=-1)
        span = q_hi - q_lo
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.minimum.reduce(
                [
                    np.ones(span.shape),
                    (self.hi - self.lo)[joint] / span,
                    self.vmax[joint] / np.abs(dq).max(axis=-1),
                    self.amax[joint] / np.abs(ddq).max(axis=-1),
                ]
            )
        # 1e-3 to spare: the peaks between the 100 Hz samples are higher by < 5e-4
        s = np.where(np.isfinite(s), s, 1.0) * (1 - 1e-3)
        if fraction != 1:
            s = s * fraction
        lo, hi = self.lo[joint], self.hi[joint]
        tol = 2.5e-4 * (hi - lo)  # inside the 1e-3 spared by the scaling
        qmin, qmax = q_lo * s, q_hi * s
        return c * s[..., None], lo - qmin + tol, hi - qmax - tol

    def initial(
        self, raw: NDArray[np.float64], offset: NDArray[np.float64], fraction: float = 1.0
    ) -> NDArray:
        """The variables of raw coefficients ``raw`` (n 2L) and a rest position offset
        ``offset`` (n) [rad]; below 1, ``fraction`` scales each joint's motion to that
        fraction of the largest that fits (the optimiser can then grow or shrink it; at
        the largest, the scaling to the limits undoes either) and moves the offset to
        where the motion fits (within the window, the optimiser can move it)."""
        if fraction == 1:
            return np.concatenate([raw, offset])
        n, L = self.n, self.L
        c = raw.reshape(n, 2 * L) @ self.Pi.T
        scaled, lo, hi = self._fitted(c, fraction)
        ratio = np.linalg.norm(scaled, axis=1) / np.maximum(np.linalg.norm(c, axis=1), 1e-300)
        q0 = np.clip(self.q_start + offset, lo, hi)
        return np.concatenate([raw * np.repeat(ratio, 2 * L), q0 - self.q_start])

    def trajectory(self, x: NDArray[np.float64]) -> ExcitingTrajectory:
        c, q0 = self.coefficients(x)
        return ExcitingTrajectory(
            self.w_f, c[:, : self.L], c[:, self.L :], q0, self.opts.duration, self.opts.ramp
        )

    def samples(self, B: tuple, c: NDArray, q0: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """Positions, velocities and accelerations (..., N, n each) [rad, rad/s, rad/s^2]
        of coefficients ``c`` (..., n, 2L) and rest positions ``q0`` (..., n) on the grid
        of basis ``B``: finite by construction, so no :class:`Trajectory` checks them
        (thousands of evaluations)."""
        Pq, Pd, Pa = B
        cT = np.swapaxes(c, -1, -2)
        return q0[..., None, :] + Pq @ cT, Pd @ cT, Pa @ cT

    def regressor(self, c: NDArray, q0: NDArray) -> NDArray[np.float64]:
        """``[Y_b, F]`` on the regressor's grid (:func:`_classical_regressor`): (..., N n,
        r + 3 n) of coefficients (..., n, 2L) and rest positions (..., n)."""
        return _regressor_of(self.robot, self.base, *self.samples(self.B_reg, c, q0))

    def regressor_of(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """``[Y_b, F]`` (..., N n, r + 3 n) of samples (..., N, n) [rad, rad/s, rad/s^2]."""
        return _regressor_of(self.robot, self.base, q, dq, ddq)

    def base_regressor_of(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """``Y_b`` (..., N n, r), without the friction columns, of samples (..., N, n)."""
        n = q.shape[-1]
        q2, dq2, ddq2 = (np.reshape(x, (-1, n)) for x in (q, dq, ddq))
        cols = self.base.independent
        Y = torque_regressor_prepared(self.robot, q2, dq2, ddq2, self.robot.gravity, columns=cols)
        return Y.reshape(q.shape[:-2] + (-1, len(cols)))

    def torques(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """The torques checked [N m] (S, n) of samples (S, n) (:func:`_torques_of`)."""
        return _torques_of(self.robot, q, dq, ddq, self.drive)

    def distances(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """The clearances penalised [m] (S, p) of positions (S, n) [rad]: of the
        self-collision pairs, then of each obstacle (its closest capsule)."""
        seg = capsule_segments(self.robot, q)
        out = [np.zeros((len(q), 0))]
        if self.caps.pairs.size:
            out.append(self_distances(self.robot, q, self.caps, segments=seg))
        if len(self.obstacles):
            out.append(obstacle_distances(self.robot, q, self.obstacles, self.caps, segments=seg))
        return np.concatenate(out, axis=-1)

    def required_distances(self) -> NDArray[np.float64]:
        """The distances (p,) [m] below which :meth:`distances` are penalised: each
        clearance with 1 cm to spare."""
        c_self, c_obstacle = _clearances(self.opts)
        pairs = len(self.caps.pairs) if self.caps.pairs.size else 0
        return np.concatenate(
            [np.full(pairs, c_self + 0.01), np.full(len(self.obstacles), c_obstacle + 0.01)]
        )

    def criterion(self, c: NDArray, q0: NDArray) -> float:
        """The criterion on the regressor's grid (:func:`_criterion`)."""
        return _criterion(self.regressor(c, q0), self.opts.criterion)

    def objective(self, x: NDArray[np.float64]) -> float:
        """The criterion plus the penalties of the variables ``x`` (one evaluation)."""
        return float(self.objectives(np.asarray(x)[None])[0])

    def objectives(self, X: NDArray[np.float64]) -> NDArray[np.float64]:
        """:meth:`objective` of each row of ``X`` (B, n 2L + n): (B,), computed
        :attr:`chunk` rows at a time through the batch-first kinematics, regressors and
        dynamics (each row one evaluation, told as the optimiser's progress)."""
        out = np.empty(len(X))
        for i in range(0, len(X), self.chunk):
            c, q0 = self.coefficients_of(X[i : i + self.chunk])
            out[i : i + len(c)] = _criteria(
                self.regressor(c, q0), self.opts.criterion
            ) + self.penalties(c, q0)
            self._told(len(c))
        return out

    def value_and_gradient(self, x: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        """The objective at ``x`` and its gradient: by the chain rule through the samples
        for the ``cond`` criterion (:func:`~dynid.simulation.excitation_gradient.
        objective_gradient`), told as the ``len(x) + 1`` evaluations of the finite
        differences it replaces; else :meth:`finite_difference_gradient`."""
        if self.opts.criterion != "cond":
            return self.finite_difference_gradient(x)
        value, grad = objective_gradient(self, x)
        self._told(1)
        return value, grad

    def finite_difference_gradient(
        self, x: NDArray[np.float64]
    ) -> tuple[float, NDArray[np.float64]]:
        """The objective at ``x`` and its forward-difference gradient: the steps
        ``(x + h e_i) - x`` of :data:`_FD_STEP` scipy's L-BFGS-B takes with ``eps`` (its
        ``2-point`` differences), all ``x + h e_i`` evaluated in one batch (:meth:`objectives`)."""
        h = _fd_steps(x)
        X = np.repeat(x[None], len(x) + 1, axis=0)
        X[1:][np.diag_indices(len(x))] += h
        f = self.objectives(X)
        return float(f[0]), (f[1:] - f[0]) / ((x + h) - x)

    def _told(self, k: int) -> None:
        """``k`` evaluations done: counted, told to ``evaluated`` and :mod:`dynid.progress`."""
        self.evaluations += k
        if self.evaluated is not None:
            self.evaluated(self.evaluations, self.budget)
        cond = f" (condition number {self.cond:.4g})" if self.iteration else ""
        _progress.report(
            f"iteration {self.iteration} of {self.opts.max_iter}{cond}, "
            f"{self.evaluations:,} of {self.budget:,} evaluations"
        )

    def penalty(self, c: NDArray, q0: NDArray) -> float:
        """The penalty of coefficients (n, 2L) and a rest position (n,) (:meth:`penalties`)."""
        return float(self.penalties(c[None], q0[None])[0])

    def penalties(self, c: NDArray, q0: NDArray) -> NDArray[np.float64]:
        """The quadratic penalties of torques and clearances beyond their limits, of
        coefficients (B, n, 2L) and rest positions (B, n): (B,)."""
        pen = np.zeros(len(c))
        if np.any(np.isfinite(self.tmax)):
            q, dq, ddq = (x.reshape(-1, self.n) for x in self.samples(self.B_lim, c, q0))
            tau = np.abs(_torques_of(self.robot, q, dq, ddq, self.drive))
            tau = _max_over_samples(tau.reshape(len(c), -1, self.n))
            with np.errstate(invalid="ignore"):
                v = np.where(np.isfinite(self.tmax), (tau - self.tmax) / self.tmax, 0.0)
            pen += np.sum(np.maximum(v, 0.0) ** 2, axis=-1)
        qc = q0[:, None, :] + self.B_col @ np.swapaxes(c, -1, -2)
        seg = capsule_segments(self.robot, qc)
        c_self, c_obstacle = _clearances(self.opts)
        if self.caps.pairs.size:
            d = _min_over_samples(self_distances(self.robot, qc, self.caps, segments=seg))
            pen += np.sum(np.maximum(c_self + 0.01 - d, 0.0) ** 2, axis=-1) / 0.05**2
        if len(self.obstacles):
            d = obstacle_distances(self.robot, qc, self.obstacles, self.caps, segments=seg)
            d = _min_over_samples(d)
            pen += np.sum(np.maximum(c_obstacle + 0.01 - d, 0.0) ** 2, axis=-1) / 0.05**2
        return 100.0 * pen


def _fd_steps(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """The forward-difference steps of ``x`` scipy takes with an absolute step
    :data:`_FD_STEP` (``approx_derivative``'s ``2-point``): :data:`_FD_STEP`, or where it
    is lost to rounding, the square root of the float64 epsilon times ``max(1, |x|)``
    with ``x``'s sign."""
    sign = np.where(x >= 0, 1.0, -1.0)
    fallback = np.sqrt(np.finfo(np.float64).eps) * sign * np.maximum(1.0, np.abs(x))
    return np.where((x + _FD_STEP) - x == 0, fallback, _FD_STEP)


def _check(
    robot: Robot,
    traj: ExcitingTrajectory,
    opts: ExcitationOptions,
    obstacles: Obstacles,
    caps: CapsuleModel,
    drive: Drive | None = None,
) -> dict[str, Any]:
    """Margins at 1 kHz (limits, obstacles, self-collision) and the closest approaches."""
    tr = traj.sample(1000.0)
    margins: dict[str, Any] = limit_margins(robot, tr, opts, drive=drive)
    c_self, c_obstacle = _clearances(opts)
    pair, near = closest_approaches(
        robot, tr.t, tr.q, caps, obstacles, self_clearance=c_self, obstacle_clearance=c_obstacle
    )
    # a one-joint arm checks no capsule against obstacles: none can touch (inf)
    margins["obstacles"] = {k: float("inf") for k in obstacles.names}
    margins["obstacles"].update({a.other: a.margin for a in near})
    margins["self_collision"] = pair[0].margin if pair else float("inf")
    margins["closest"] = pair + near
    return margins


def _clearances(opts: ExcitationOptions) -> tuple[float, float]:
    """The self and obstacle clearances [m] of options sized for the arm."""
    if opts.self_clearance is None or opts.obstacle_clearance is None:
        raise OptionError("the options must be sized for the arm first (sized_for(robot))")
    return opts.self_clearance, opts.obstacle_clearance


def _violations(m: dict[str, Any]) -> list[str]:
    """Names of the negative margins (``velocity[3]``, ``obstacles[floor]``, ...)."""
    out = [
        f"{k}[{j + 1}] {v:.3g}"
        for k in ("position", "velocity", "acceleration", "torque")
        for j, v in enumerate(m[k])
        if v < -1e-9
    ]
    near = {a.other: a for a in m.get("closest", ()) if a.obstacle}
    out += [
        f"obstacles[{k}] {v:.3g}" + (f" ({near[k].link})" if k in near else "")
        for k, v in m["obstacles"].items()
        if v < -1e-9
    ]
    if m["self_collision"] < -1e-9:
        pair = [a for a in m.get("closest", ()) if not a.obstacle]
        names = f" ({pair[0].link}, {pair[0].other})" if pair else ""
        out.append(f"self_collision {m['self_collision']:.3g}{names}")
    return out


def _admissible(m: dict[str, Any]) -> bool:
    vals = [v for k in ("position", "velocity", "acceleration", "torque") for v in m[k]]
    vals += list(m["obstacles"].values()) + [m["self_collision"]]
    return bool(np.all(np.asarray(vals) >= -1e-9))


def _preferred_rest(robot: Robot, q_start: ArrayLike | None) -> NDArray[np.float64]:
    """The rest position the design prefers [rad]: ``q_start``, else ``robot.q_neutral``,
    else the middle of the limits (a continuous joint, ``(-inf, inf)``, at 0).

    Raises
    ------
    ShapeError
        ``q_start`` not (n,).
    """
    if q_start is None:
        finite = np.isfinite(robot.q_min) & np.isfinite(robot.q_max)
        lo, hi = np.where(finite, robot.q_min, 0.0), np.where(finite, robot.q_max, 0.0)
        q_start = robot.q_neutral if robot.q_neutral is not None else 0.5 * (lo + hi)
    return _checks.as_exact("q_start", q_start, (robot.n,))


def _minimize(*args: Any, **kwargs: Any) -> Any:
    """``scipy.optimize.minimize``, imported on first use (start-up time)."""
    import scipy.optimize

    return scipy.optimize.minimize(*args, **kwargs)


def optimise_excitation(
    robot: Robot,
    rng: np.random.Generator,
    options: ExcitationOptions = ExcitationOptions(),
    *,
    obstacles: Obstacles | None = None,
    q_start: ArrayLike | None = None,
    base: BaseParameters | None = None,
    progress: Callable[[int, int, float], None] | None = None,
    evaluated: Callable[[int, int], None] | None = None,
    drive: Drive | None = None,
) -> ExcitationResult:
    """Optimise an exciting trajectory for the classical identification.

    Parameters
    ----------
    robot : Robot
        Kinematics, dynamics (for the torques), limits and friction.
    rng : numpy.random.Generator
        Source of the random starts.
    options : ExcitationOptions
        With ``ranges``, the design keeps to them instead of the robot's position limits.
    obstacles : Obstacles, optional
        Default :meth:`Obstacles.floor` (the plane ``z = 0`` of the base frame).
    q_start : array_like, shape (n,), optional
        Preferred rest position [rad] (moved where the motion fits); default the middle
        of the limits (``robot.q_neutral`` if set); its clearances: ``rest_clearances``.
    base : BaseParameters, optional
        Default ``base_parameters(robot, kind="torque")``.
    progress : callable, optional
        ``progress(iteration, max_iter, condition_number)`` after each iteration.
    evaluated : callable, optional
        ``evaluated(evaluations, budget)`` after each evaluation (or batch of them);
        ``budget``: ``options.max_evaluations`` and those of the start (L-BFGS-B may overrun).
    drive : Drive, optional
        The drive train: the torques checked include its known rotor inertias' reflected
        torques ``K^T diag(I_a) K ddq`` (none when it leaves them to be identified).

    Returns
    -------
    ExcitationResult

    Raises
    ------
    ShapeError
        ``q_start`` not (n,), or a drive for another number of joints.
    """
    _checks.checked_rng(rng)
    checked_robot(robot)
    if drive is not None:
        drive.check(robot.n)
    robot = design_limits(robot, options)
    obstacles = Obstacles.floor() if obstacles is None else obstacles
    base = base_parameters(robot, kind="torque") if base is None else base
    derived = options.derived
    options = options.sized_for(robot)
    caps = capsule_model(robot, options.radii, clearance=_clearances(options)[0])
    q_start = _preferred_rest(robot, q_start)
    prob = _Problem(robot, options, obstacles, caps, base, q_start)
    prob.drive, prob.evaluated = drive, evaluated
    prob.budget = options.max_evaluations + options.n_starts
    x0 = _start(prob, rng)
    prob.budget = options.max_evaluations + prob.evaluations
    history: list[float] = []
    best = _BestFeasible(prob)
    best.offer(x0)

    def callback(xk: NDArray[np.float64]) -> None:
        # the unscaled condition number (the objective adds the penalties)
        c, q0 = prob.coefficients(xk)
        cond = float(_conds(prob.regressor(c, q0))[0])
        history.append(cond)
        best.offer(xk)
        _tell_iteration(prob, len(history), cond, progress)

    x_last, iterations = _lbfgsb(prob, x0, callback)
    best.offer(x_last)
    # the best penalty-free iterate; without one, the optimiser's (the least violation)
    chosen = prob.trajectory(x_last if best.x is None else best.x)
    centre = np.clip(q_start, prob.lo, prob.hi)  # within the limits and their margins
    traj, margins, status = _admissible_version(
        robot, chosen, options, obstacles, caps, centre, drive
    )
    start = prob.trajectory(x0)
    start_margins = _check(robot, start, options, obstacles, caps, drive)
    W = _classical_regressor(robot, base, traj.sample(_FS_REPORTED))
    W0 = _classical_regressor(robot, base, start.sample(_FS_REPORTED))
    crit = (_criterion(W, options.criterion), _criterion(W0, options.criterion))
    kept_start = _admissible(start_margins) and (status == "infeasible" or crit[0] >= crit[1])
    if kept_start:  # never worse than an admissible start
        _log.info("excitation: the start is kept (%s, criterion %.4g)", status, crit[0])
        traj, margins, status, W = start, start_margins, "ok", W0
    (cu, cs), init_cond = _conds(W), _conds(W0)[0]
    _log.info("excitation: cond %.4g -> %.4g (%s)", init_cond, cu, status)
    return ExcitationResult(
        trajectory=traj,
        condition_number=cu,
        scaled_condition_number=cs,
        initial_condition_number=init_cond,
        margins=margins,
        status=status,
        iterations=iterations,
        evaluations=prob.evaluations,
        history=tuple(history),
        options=options,
        obstacles=obstacles,
        start_margins=start_margins,
        improved=not kept_start and crit[0] < crit[1],
        sizes=collision_sizes(robot),
        derived=derived,
        drive=drive,
        rest=centre,
        rest_clearances=_rest_clearances(robot, centre, options, obstacles, caps),
        n_base=len(base.independent),
    )


def _lbfgsb(
    prob: _Problem, x0: NDArray[np.float64], callback: Callable[[NDArray[np.float64]], None]
) -> tuple[NDArray[np.float64], int]:
    """L-BFGS-B on the objective from ``x0`` within ``max_iter`` iterations and
    ``max_evaluations``: the last iterate and the iterations made.

    A line search that fails (scipy's status 2: the penalties' steep walls and the kinks
    of the scaling to the limits, where the gradient does not foretell the step) starts
    the method again from its last iterate, with the iterations and evaluations left,
    until one makes no iteration. Before, a design ended there (the FR3's 20 s design in
    a cell: 12 of its 60 iterations, condition number 49.8).
    """
    opts = prob.opts
    x, done, calls = x0, 0, _gradients_allowed(opts, len(x0))
    while done < opts.max_iter and calls > 0:
        # scipy counts an evaluation with its gradient as one: finite differences, len(x) + 1
        res = _minimize(
            prob.value_and_gradient,
            x,
            jac=True,
            method="L-BFGS-B",
            callback=callback,
            options={"maxiter": opts.max_iter - done, "maxfun": calls},
        )
        x, done, calls = res.x, done + int(res.nit), calls - int(res.nfev)
        if res.status != 2 or res.nit == 0:
            break
    return x, done


def _gradients_allowed(options: ExcitationOptions, variables: int) -> int:
    """The evaluations with their gradients L-BFGS-B may make within
    ``options.max_evaluations``: each one evaluation with the ``cond`` criterion's gradient
    (:mod:`~dynid.simulation.excitation_gradient`), ``variables + 1`` with the finite
    differences of ``logdet``'s."""
    per = 1 if options.criterion == "cond" else variables + 1
    return options.max_evaluations // per


def _tell_iteration(
    prob: _Problem,
    k: int,
    cond: float,
    progress: Callable[[int, int, float], None] | None,
) -> None:
    """Iteration ``k`` done at condition number ``cond``: kept in ``prob`` (told with the
    evaluations that follow), told to ``progress`` and :mod:`dynid.progress`, and logged
    at INFO (``-v``)."""
    prob.iteration, prob.cond, total = k, cond, prob.opts.max_iter
    if progress is not None:
        progress(k, total, cond)
    _log.info(
        "excitation: iteration %d of %d, condition number %.4g, %d evaluations",
        k, total, cond, prob.evaluations,
    )  # fmt: skip
    _progress.report(f"iteration {k} of {total} done, condition number {cond:.4g}")


def _rest_clearances(
    robot: Robot,
    rest: NDArray[np.float64],
    opts: ExcitationOptions,
    obstacles: Obstacles,
    caps: CapsuleModel,
) -> tuple[Approach, ...]:
    """The obstacle clearances the rest position ``rest`` (n,) [rad] violates."""
    near = closest_approaches(
        robot, np.zeros(1), rest[None], caps, obstacles,
        self_clearance=_clearances(opts)[0], obstacle_clearance=_clearances(opts)[1],
    )[1]  # fmt: skip
    return tuple(a for a in near if a.margin < -1e-9)


def _start(prob: _Problem, rng: np.random.Generator) -> NDArray[np.float64]:
    """The start of the optimisation: the best of ``n_starts`` random candidates at full
    amplitude (lowest criterion plus penalty); when even that one violates a torque or a
    clearance, the best of them all at :data:`_START_FRACTIONS` of their amplitudes too,
    one free of penalty (clear of the floor, the obstacles and itself, within the
    torques) first when there is one.

    Regression (SO-101): every full-amplitude candidate filled each joint's range, the
    elbow folded into the shoulder, and the optimiser, started in that collision, never
    left it (status reduced).
    """
    n, L = prob.n, prob.L
    draws = [
        (rng.standard_normal(n * 2 * L), 0.3 * rng.standard_normal(n))
        for _ in range(max(prob.opts.n_starts, 1))
    ]
    scored = [(prob.objective(x), x) for x in (prob.initial(*d) for d in draws)]
    x0 = min(scored, key=lambda p: p[0])[1]
    if prob.penalty(*prob.coefficients(x0)) == 0:
        return x0
    for f in _START_FRACTIONS:
        scored += [(prob.objective(x), x) for x in (prob.initial(*d, f) for d in draws)]
    # a candidate clear of every torque and clearance (by the penalty the optimiser
    # sees) before one that is less so, however better its criterion
    clear = [(v, x) for v, x in scored if prob.penalty(*prob.coefficients(x)) == 0]
    return min(clear or scored, key=lambda p: p[0])[1]


class _BestFeasible:
    """The iterate of lowest criterion among those without penalty (internal)."""

    def __init__(self, prob: _Problem) -> None:
        self.prob = prob
        self.x: NDArray[np.float64] | None = None
        self.value = float("inf")

    def offer(self, x: NDArray[np.float64]) -> None:
        c, q0 = self.prob.coefficients(x)
        if self.prob.penalty(c, q0) > 0:
            return
        f = self.prob.criterion(c, q0)
        if f < self.value:
            self.x, self.value = np.array(x, copy=True), f


def _admissible_version(
    robot: Robot,
    traj: ExcitingTrajectory,
    options: ExcitationOptions,
    obstacles: Obstacles,
    caps: CapsuleModel,
    centre: NDArray[np.float64],
    drive: Drive | None = None,
) -> tuple[ExcitingTrajectory, dict[str, Any], str]:
    """``traj`` checked at 1 kHz, its amplitudes reduced (by 3 % steps, at most 60) until it
    is admissible: the trajectory, its margins and ``"ok"``/``"reduced"``; unreduced and
    ``"infeasible"`` when no reduction is admissible (it would only lose excitation).

    A reduction by ``f`` draws the whole motion toward ``centre`` (the requested start,
    within the limits): ``q'(t) = centre + f (q(t) - centre)``, inside the position limits
    as ``q`` and ``centre`` are, and at rest at ``centre`` as ``f -> 0``: a rest position
    the optimiser moved into a collision (a joint's range filled to a limit where two
    links meet) is drawn out of it, which a reduction about that rest position never did.
    """
    margins = _check(robot, traj, options, obstacles, caps, drive)
    reduced, m = traj, margins
    for k in range(1, 61):
        if _admissible(m):
            return reduced, m, ("ok" if reduced is traj else "reduced")
        _log.info("violated at 1 kHz: %s", _violations(m))
        f = 0.97**k
        q0 = centre + f * (traj.q_start - centre)
        reduced = ExcitingTrajectory(traj.w_f, f * traj.a, f * traj.b, q0, traj.duration, traj.ramp)
        m = _check(robot, reduced, options, obstacles, caps, drive)
    if _admissible(m):
        return reduced, m, "reduced"
    return traj, margins, "infeasible"
