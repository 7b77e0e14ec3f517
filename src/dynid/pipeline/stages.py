"""The stages of the paper's pipeline on a simulated robot, as library functions.

Each stage takes the robot (or the previous stage's model), a seed or generator and an
optional ``progress`` callback, computes, and returns a frozen result: arrays, the
library's own result objects and the key numbers. Nothing is printed or written here;
``dynid demo`` renders the results and saves the files.

Stages (Gaz et al., IEEE RA-L 4(4), 2019):

1. :func:`kinematics_stage`: flange pose and Jacobian at a pose; one IK solve with a tool.
2. :func:`identification_stage`: static configurations from the simulated controller,
   base parameters by least squares (Sec. IV-A).
3. :func:`friction_stage`: validation on the sinusoids of eq. 31, sigmoid friction fit
   (eq. 25), validation with friction (Sec. IV-B, VI).
4. :func:`feasible_stage`: feasible link parameters (Algorithm 1, Sec. V) and their
   Newton-Euler validation.
5. :func:`~dynid.pipeline.consistent.consistent_stage`: beyond the paper, the convex
   (LMI) retrieval against the penalty method on a robot with model error.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..exceptions import DynidError
from ..feasibility.penalty import RetrievalResult, retrieve
from ..friction.fit import FrictionFit, FrictionResidual, fit_sigmoid, friction_residual
from ..friction.model import Friction, FrictionSum, robot_friction
from ..friction.validation import (
    NewtonEulerValidation,
    Validation,
    validate_newton_euler,
    validate_torques,
)
from ..identification.data import StaticDataset
from ..identification.log import TorqueLog
from ..identification.model import IdentifiedModel
from ..identification.prepare import MEASURED, prepare_log
from ..identification.static import identify_static
from ..kinematics.forward import fk
from ..kinematics.inverse import IKOptions, IKResult, ik
from ..kinematics.jacobian import jacobian
from ..model.robot import Robot
from ..simulation.controller import SimulatedController, acquire_static
from ..simulation.limits import LimitReport, check_limits, scale_into_limits
from ..simulation.measurement import SensorNoise, sample_times, simulate_measurement
from ..simulation.trajectories import (
    Trajectory,
    centered_start,
    random_fourier,
    sinusoid_trajectory,
)
from ..spatial import rpy_from_matrix, transform_from_xyz_rpy

__all__ = [
    "DEMO_RELATIVE_NOISE",
    "DEMO_TOOL_XYZ",
    "DEMO_WORKERS",
    "FeasibleStageResult",
    "FrictionStageResult",
    "IdentificationStageResult",
    "KinematicsStageResult",
    "feasible_stage",
    "friction_stage",
    "identification_stage",
    "kinematics_only",
    "kinematics_stage",
    "seed_streams",
]

#: The demo's tool: 0.1 m along z of the flange [m] (kinematic only, no mass).
DEMO_TOOL_XYZ = (0.0, 0.0, 0.1)
#: Relative noise of the simulated controller in :func:`identification_stage`.
DEMO_RELATIVE_NOISE = 1e-4
#: Processes used by the retrievals of stages 4 and 5 at most.
DEMO_WORKERS = 2
#: Static configurations acquired in stages 2 and 5.
DEMO_CONFIGURATIONS = 1010

#: A progress callback: receives a :class:`~dynid.feasibility.penalty.result.RetrievalProgress`
#: per finished run of the penalty method, and the events of the stage that runs.
Progress = Callable[[Any], None]

FloatArray = NDArray[np.float64]


def seed_streams(seed: int) -> tuple[np.random.Generator, np.random.Generator]:
    """Two independent generators from one seed: configurations, then noise (as
    ``dynid acquire-static --seed`` draws them)."""
    a, b = np.random.SeedSequence(seed).spawn(2)
    return np.random.default_rng(a), np.random.default_rng(b)


def kinematics_only(model: IdentifiedModel) -> IdentifiedModel:
    """``model`` with a robot that keeps only its kinematics (no link parameters, friction
    or neutral pose): what an identification file records, and all later stages may use."""
    robot = model.robot.replace(phi=np.zeros((model.robot.n, 10)), friction=None, q_neutral=None)
    return IdentifiedModel(robot, model.base, model.fit, model.terms, model.info, model.joint_fit)


# ----------------------------------------------------------------------------- stage 1
@dataclass(frozen=True, slots=True, eq=False)
class KinematicsStageResult:
    """Stage 1: forward kinematics and Jacobian at ``q``, and one IK solve with a tool.

    Attributes
    ----------
    q : ndarray, shape (n,)
        The pose [rad].
    T_base_flange : ndarray, shape (4, 4)
        Flange pose at ``q`` [m].
    rpy : ndarray, shape (3,)
        Its roll, pitch, yaw [rad].
    J : ndarray, shape (6, n)
        Flange Jacobian at ``q``, base frame, rows ``[v; w]``.
    tool_xyz : tuple of float
        The tool's offset in the flange [m].
    T_flange_tool : ndarray, shape (4, 4)
        The tool [m].
    q_goal : ndarray, shape (n,)
        Seeded configuration near ``q`` whose tool pose is the IK goal [rad].
    T_base_tool_goal : ndarray, shape (4, 4)
        The IK goal [m].
    options : IKOptions
    ik : IKResult
    """

    q: FloatArray
    T_base_flange: FloatArray
    rpy: FloatArray
    J: FloatArray
    tool_xyz: tuple[float, ...]
    T_flange_tool: FloatArray
    q_goal: FloatArray
    T_base_tool_goal: FloatArray
    options: IKOptions
    ik: IKResult


def kinematics_stage(
    robot: Robot, q: ArrayLike, rng: np.random.Generator, *, tool_xyz: ArrayLike = DEMO_TOOL_XYZ
) -> KinematicsStageResult:
    """Flange pose and Jacobian at ``q``; IK for a tool at ``tool_xyz`` [m] in the flange, to
    the tool pose at a configuration drawn from ``rng`` within 0.5 rad of ``q``.

    The IK integrates with a small gain per step (``dt * gain = 0.2``), which gives a smooth
    first-order joint motion to plot.
    """
    q = np.array(q, dtype=np.float64)
    T = fk(robot, q)
    J = jacobian(robot, q)
    xyz = tuple(float(x) for x in np.asarray(tool_xyz, dtype=np.float64).reshape(3))
    T_flange_tool = transform_from_xyz_rpy(xyz)
    q_goal = np.clip(q + rng.uniform(-0.5, 0.5, robot.n), robot.q_min + 0.1, robot.q_max - 0.1)
    T_goal = fk(robot, q_goal, tool=T_flange_tool)
    options = IKOptions(dt=0.01, gain=20.0)
    res = ik(robot, T_goal, q, tool=T_flange_tool, options=options, rng=rng)
    return KinematicsStageResult(
        q, T, rpy_from_matrix(T[:3, :3]), J, xyz, T_flange_tool, q_goal, T_goal, options, res
    )


# ----------------------------------------------------------------------------- stage 2
@dataclass(frozen=True, slots=True, eq=False)
class IdentificationStageResult:
    """Stage 2: static data from the simulated controller and the identified model.

    Attributes
    ----------
    data : StaticDataset
        The configurations, ``M`` and ``g`` (metadata records the seed).
    model : IdentifiedModel
    relative_noise : float
    max_abs_error : float
        Largest ``|beta - beta_true|`` (SI of each coefficient).
    max_error_in_std : float
        Largest ``|beta - beta_true| / std``.
    seed : int
    """

    data: StaticDataset
    model: IdentifiedModel
    relative_noise: float
    max_abs_error: float
    max_error_in_std: float
    seed: int

    @property
    def n_configurations(self) -> int:
        return int(self.data.n_configurations)

    @property
    def rank(self) -> int:
        return int(self.model.fit.rank)

    @property
    def condition_number(self) -> float:
        return float(self.model.fit.condition_number)

    @property
    def relative_error_percent(self) -> float:
        return float(self.model.fit.relative_error_percent)

    @property
    def dropped_rows(self) -> list[str]:
        return list(self.model.info.dropped_rows)


def identification_stage(
    robot: Robot,
    seed: int,
    *,
    n_configurations: int = DEMO_CONFIGURATIONS,
    relative_noise: float = DEMO_RELATIVE_NOISE,
) -> IdentificationStageResult:
    """Acquire ``n_configurations`` static configurations from the simulated controller
    (relative noise ``relative_noise``) and identify the base parameters (Gaz et al. 2019,
    Sec. IV-A); the errors are taken against ``robot``'s own parameters."""
    rng_q, rng_noise = seed_streams(seed)
    controller = SimulatedController(robot, relative_noise, rng=rng_noise)
    data = acquire_static(controller, n_configurations, rng_q).with_metadata(seed=seed)
    model = identify_static(robot, data)
    err = np.abs(model.beta - model.base.beta_from_phi(robot.phi))
    return IdentificationStageResult(
        data,
        model,
        relative_noise,
        float(err.max()),
        float(np.max(err / model.fit.std)),
        seed,
    )


# ----------------------------------------------------------------------------- stage 3
@dataclass(frozen=True, slots=True, eq=False)
class FrictionStageResult:
    """Stage 3: validation on the sinusoids, friction fit, validation with friction.

    Attributes
    ----------
    truth : Robot
        The robot that played the real one.
    limits : LimitReport
        The sinusoids of Table I against the limits, before scaling.
    scale : float
        Amplitude scale that keeps the sinusoids within the limits.
    scaled_limits : LimitReport
        The scaled sinusoids (both logs) against the limits: ``ok`` when they are within.
    noise : SensorNoise
    residual : FrictionResidual
        Torque residual of the model on the fitting log.
    fit : FrictionFit
        Sigmoid friction fitted to it.
    validation : Validation
        Model without and with the fitted friction on the validation log: the 20 s of the
        sinusoids after the fitting log's (each joint's sinusoid at another phase, its
        combination with the others a motion the fit did not see).
    friction_curve_rms : ndarray, shape (n,), or None
        RMS of the fitted minus the true friction over the visited velocities [N m]
        (None: the truth has no friction).
    seed : int
    """

    truth: Robot
    limits: LimitReport
    scale: float
    scaled_limits: LimitReport
    noise: SensorNoise
    residual: FrictionResidual
    fit: FrictionFit
    validation: Validation
    friction_curve_rms: FloatArray | None
    seed: int

    @property
    def reference_friction(self) -> Friction | FrictionSum | None:
        """The truth's friction, or None."""
        return robot_friction(self.truth)

    @property
    def rms_without_friction(self) -> FloatArray:
        return self.validation.without_friction.rms

    @property
    def rms_with_friction(self) -> FloatArray:
        assert self.validation.with_friction is not None
        return self.validation.with_friction.rms

    @property
    def relative_error_percent_without(self) -> float:
        return float(self.validation.without_friction.relative_error_percent)

    @property
    def relative_error_percent_with(self) -> float:
        assert self.validation.with_friction is not None
        return float(self.validation.with_friction.relative_error_percent)


def friction_stage(
    model: IdentifiedModel, seed: int, *, truth: Robot | None = None
) -> FrictionStageResult:
    """Friction and validation from a rigid-body model (e.g. the static one).

    Simulates 40 s at 1 kHz of the velocity-mode sinusoids (Gaz et al. 2019, eq. 31,
    Table I; started centred in the joint ranges and scaled in amplitude into the limits)
    on ``truth`` (default ``model.robot``), as two 20 s logs with independent sensor
    noise: the first to fit the sigmoid friction to the model's residual, the second (the
    sinusoids 20 s on: each joint's at another phase, so the joints' states combine as
    the fit never saw) to validate the model without and with it.

    Raises
    ------
    DynidError
        ``truth`` has no link parameters to simulate with.
    """
    truth = model.robot if truth is None else truth
    if not np.any(truth.phi):
        raise DynidError(
            "the model's robot has no link parameters to simulate with (read from JSON?); "
            "pass truth=<Robot>"
        )
    rng = np.random.default_rng(seed)
    t = sample_times(2 * _SINUSOID_LOG_S, 1000.0)
    traj = sinusoid_trajectory(t, centered_start(truth))
    limits = check_limits(truth, traj)
    traj, scale = scale_into_limits(truth, traj, method="amplitude")
    scaled_limits = check_limits(truth, traj)
    half = int(np.searchsorted(traj.t, traj.t[0] + _SINUSOID_LOG_S))
    noise = SensorNoise()
    fit_log = simulate_measurement(truth, _part(traj, 0, half), rng=rng, noise=noise)
    val_log = simulate_measurement(truth, _part(traj, half, len(traj)), rng=rng, noise=noise)
    res = friction_residual(model, fit_log)
    fit = fit_sigmoid(res.dq, res.residual, dq_noise_std=res.dq_noise_std)
    val = validate_torques(model, val_log, friction=fit.friction)
    assert val.with_friction is not None
    curve = None
    true_f = robot_friction(truth)
    if true_f is not None:
        v = np.linspace(-1.0, 1.0, 801)[:, None] * np.max(np.abs(traj.dq), axis=0)
        curve = np.sqrt(np.mean((fit.friction.torques(v) - true_f.torques(v)) ** 2, axis=0))
    return FrictionStageResult(
        truth, limits, float(scale), scaled_limits, noise, res, fit, val, curve, seed
    )


#: Seconds of each of the friction stage's sinusoid logs (fitting, then validation).
_SINUSOID_LOG_S = 20.0


def _part(traj: Trajectory, a: int, b: int) -> Trajectory:
    """The samples ``a:b`` of ``traj``."""
    return Trajectory(t=traj.t[a:b], q=traj.q[a:b], dq=traj.dq[a:b], ddq=traj.ddq[a:b])


# ----------------------------------------------------------------------------- stage 4
@dataclass(frozen=True, slots=True, eq=False)
class FeasibleStageResult:
    """Stage 4: feasible link parameters and their Newton-Euler validation.

    Attributes
    ----------
    retrieval : RetrievalResult
    validation : NewtonEulerValidation
        RNEA with the feasible parameters (plus the friction) against the validation log,
        and the identified model as reference.
    max_torque_difference : float
        Largest ``|NE - identified|`` over the validation samples, friction excluded [N m].
    seed : int
    """

    retrieval: RetrievalResult
    validation: NewtonEulerValidation
    max_torque_difference: float
    seed: int

    @property
    def feasible(self) -> bool:
        return bool(self.retrieval.feasible)

    @property
    def relative_residual(self) -> float:
        return float(self.retrieval.relative_residual)

    @property
    def min_margin(self) -> dict[str, float]:
        rep = self.retrieval.report
        return {n: rep.min_margin(n) for n in rep.names}

    @property
    def total_mass(self) -> float:
        return float(np.sum(self.retrieval.mass))

    @property
    def rms_newton_euler(self) -> FloatArray:
        return self.validation.errors.rms


def _validation_log(robot: Robot, seed: int) -> TorqueLog:
    """A 10 s random Fourier trajectory at 1 kHz, simulated with sensor noise on ``robot``."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, 5]))
    series = random_fourier(robot, rng, n_harmonics=5)
    traj = series(sample_times(10.0, 1000.0))
    return simulate_measurement(robot, traj, rng=rng, noise=SensorNoise())


def feasible_stage(
    model: IdentifiedModel,
    validation_log: TorqueLog | None = None,
    friction: Any = None,
    seed: int = 0,
    *,
    truth: Robot | None = None,
    workers: int | None = None,
    progress: Progress | None = None,
) -> FeasibleStageResult:
    """Feasible link parameters from the static ``model`` (Algorithm 1 with the default
    options and bounds), validated by Newton-Euler on a trajectory the friction was not
    fitted on.

    Parameters
    ----------
    model : IdentifiedModel
        Identified static coefficients (e.g. from :func:`identification_stage`).
    validation_log : TorqueLog, optional
        Measured validation trajectory, used as it is when it has ``ddq``, else prepared
        with :func:`dynid.identification.prepare.prepare_log` (zero-phase filtered states,
        ``ddq`` differentiated, torques kept unfiltered). Default: a 10 s random Fourier
        trajectory simulated on ``truth`` with sensor noise.
    friction : Friction, array_like (n, 3) (sigmoid) or None
        Friction added to the Newton-Euler torques (e.g. the fitted sigmoid of stage 3).
    seed : int
    truth : Robot, optional
        Robot that plays the real one for the default validation log (default
        ``model.robot``; it must have link parameters).
    workers : int, optional
        Processes for the retrieval (default ``min(DEMO_WORKERS, cores)``).
    progress : callable, optional
        Receives a :class:`~dynid.feasibility.penalty.result.RetrievalProgress` per finished run.

    Raises
    ------
    DynidError
        No validation log and no link parameters to simulate one with.
    """
    if workers is None:
        workers = max(1, min(DEMO_WORKERS, os.cpu_count() or 1))
    result = retrieve(model, seed=seed, workers=workers, progress=progress)
    if validation_log is None:
        truth = model.robot if truth is None else truth
        if not np.any(truth.phi):
            raise DynidError(
                "no validation log given and the model's robot has no link parameters to "
                "simulate with; pass truth="
            )
        validation_log = _validation_log(truth, seed)
    log = (
        validation_log if validation_log.ddq is not None else prepare_log(validation_log, MEASURED)
    )
    assert log.ddq is not None
    val = validate_newton_euler(
        result.robot, log.t, log.q, log.dq, log.ddq, log.tau, friction=friction, reference=model
    )
    diff = float(np.max(np.abs(val.tau_rigid - model.torques(log.q, log.dq, log.ddq))))
    return FeasibleStageResult(result, val, diff, seed)
