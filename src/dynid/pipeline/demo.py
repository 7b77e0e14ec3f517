"""The whole demonstration: the paper's stages 1-4 and stages 5-6 on one simulated robot.

:func:`run_demo` chains the stages of :mod:`dynid.pipeline.stages` as ``dynid demo`` does
and returns a frozen :class:`DemoResult`; ``progress`` receives a :class:`StageStarted`
before each stage, the stage's own events, and a :class:`StageFinished` with its result.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.panda import panda
from ..model.robot import Robot
from .collision import CollisionStageResult, collision_stage
from .consistent import ConsistentStageResult, consistent_stage
from .stages import (
    FeasibleStageResult,
    FrictionStageResult,
    IdentificationStageResult,
    KinematicsStageResult,
    Progress,
    feasible_stage,
    friction_stage,
    identification_stage,
    kinematics_only,
    kinematics_stage,
)

__all__ = ["STAGE_TITLES", "DemoResult", "StageFinished", "StageStarted", "run_demo"]

#: Title of each stage, by number.
STAGE_TITLES = {
    1: "kinematics",
    2: "identification from the controller's M(q) and g(q) (Gaz et al. 2019, Sec. IV-A)",
    3: "validation on sinusoids and joint friction (Gaz et al. 2019, Sec. IV-B, VI)",
    4: "feasible link parameters and Newton-Euler validation (Gaz et al. 2019, Sec. V)",
    5: "physically consistent parameters: convex (LMI) against the penalty method",
    6: "the identified model detects a collision (momentum observer)",
}


@dataclass(frozen=True, slots=True)
class StageStarted:
    """Sent to ``progress`` when stage ``number`` starts."""

    number: int
    title: str


@dataclass(frozen=True, slots=True, eq=False)
class StageFinished:
    """Sent to ``progress`` when stage ``number`` has finished, with its result."""

    number: int
    result: Any


@dataclass(frozen=True, slots=True, eq=False)
class DemoResult:
    """Every stage's result.

    ``identification.model`` is the model as identified; stages 3 and 4 used it through
    :func:`~dynid.pipeline.stages.kinematics_only` (coefficients and kinematics, as an
    identification file records them), with ``robot`` playing the real robot.
    """

    robot: Robot
    seed: int
    kinematics: KinematicsStageResult
    identification: IdentificationStageResult
    friction: FrictionStageResult
    feasible: FeasibleStageResult
    consistent: ConsistentStageResult
    collision: CollisionStageResult | None = None


def run_demo(
    robot: Robot | None = None, seed: int = 0, *, progress: Progress | None = None
) -> DemoResult:
    """Run the six stages on ``robot`` (default: the built-in Panda) with ``seed``.

    Stage 1 starts at the robot's neutral pose (the Panda's ``PANDA_NEUTRAL_Q``; the middle
    of the limits for a robot without one) and draws its IK goal from
    ``np.random.default_rng(seed)``; the other stages derive their own generators from
    ``seed``. ``robot`` plays the real robot and must have link parameters.
    """
    robot = panda() if robot is None else robot
    say: Progress = progress if progress is not None else (lambda event: None)
    q0 = 0.5 * (robot.q_min + robot.q_max) if robot.q_neutral is None else robot.q_neutral
    rng = np.random.default_rng(seed)

    def stage(number: int, compute: Callable[[], Any]) -> Any:
        say(StageStarted(number, STAGE_TITLES[number]))
        result = compute()
        say(StageFinished(number, result))
        return result

    kin = stage(1, lambda: kinematics_stage(robot, q0, rng))
    ident = stage(2, lambda: identification_stage(robot, seed))
    recorded = kinematics_only(ident.model)
    fric = stage(3, lambda: friction_stage(recorded, seed, truth=robot))
    feas = stage(
        4,
        lambda: feasible_stage(
            recorded, friction=fric.fit.friction, seed=seed, truth=robot, progress=progress
        ),
    )
    cons = stage(5, lambda: consistent_stage(robot, seed, progress=progress))
    coll = stage(6, lambda: collision_stage(recorded, fric.fit.friction, seed, truth=robot))
    return DemoResult(robot, seed, kin, ident, fric, feas, cons, coll)
