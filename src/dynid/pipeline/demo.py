"""The whole demonstration: the paper's stages 1-4 and stages 5-6 on one simulated robot.

:func:`run_demo` chains the stages of :mod:`dynid.pipeline.stages` as ``dynid demo`` does
and returns a frozen :class:`DemoResult`; ``progress`` receives a :class:`StageStarted`
before each stage, the stage's own events, and a :class:`StageFinished` with its result.
Each event carries its :class:`Stage`, which says what the stage is (``kind``, also the
:class:`DemoResult` field holding its result): a renderer picks what to show by that, never
by the stage's place in the order.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

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

__all__ = [
    "STAGES",
    "STAGE_TITLES",
    "DemoResult",
    "Stage",
    "StageFinished",
    "StageKind",
    "StageStarted",
    "run_demo",
]

#: What a stage of the demo is (and the :class:`DemoResult` field holding its result).
StageKind = Literal[
    "kinematics", "identification", "friction", "feasible", "consistent", "collision"
]


@dataclass(frozen=True, slots=True)
class Stage:
    """One stage of the demo: what it is (``kind``), its place in the run (``number``,
    from 1, for the printed heading) and its title."""

    kind: StageKind
    number: int
    title: str


#: The demo's stages in the order :func:`run_demo` runs them.
STAGES = (
    Stage("kinematics", 1, "kinematics"),
    Stage(
        "identification",
        2,
        "identification from the controller's M(q) and g(q) (Gaz et al. 2019, Sec. IV-A)",
    ),
    Stage(
        "friction", 3, "validation on sinusoids and joint friction (Gaz et al. 2019, Sec. IV-B, VI)"
    ),
    Stage(
        "feasible",
        4,
        "feasible link parameters and Newton-Euler validation (Gaz et al. 2019, Sec. V)",
    ),
    Stage(
        "consistent", 5, "physically consistent parameters: convex (LMI) against the penalty method"
    ),
    Stage("collision", 6, "the identified model detects a collision (momentum observer)"),
)
_STAGE = {s.kind: s for s in STAGES}
#: Title of each stage, by number.
STAGE_TITLES = {s.number: s.title for s in STAGES}


@dataclass(frozen=True, slots=True)
class StageStarted:
    """Sent to ``progress`` when ``stage`` starts."""

    stage: Stage

    @property
    def number(self) -> int:
        """The stage's place in the run (from 1)."""
        return self.stage.number

    @property
    def title(self) -> str:
        """The stage's title."""
        return self.stage.title


@dataclass(frozen=True, slots=True, eq=False)
class StageFinished:
    """Sent to ``progress`` when ``stage`` has finished, with its result (the
    :class:`DemoResult` field named ``stage.kind``)."""

    stage: Stage
    result: Any

    @property
    def number(self) -> int:
        """The stage's place in the run (from 1)."""
        return self.stage.number


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

    def stage(kind: StageKind, compute: Callable[[], Any]) -> Any:
        say(StageStarted(_STAGE[kind]))
        result = compute()
        say(StageFinished(_STAGE[kind], result))
        return result

    kin = stage("kinematics", lambda: kinematics_stage(robot, q0, rng))
    ident = stage("identification", lambda: identification_stage(robot, seed))
    recorded = kinematics_only(ident.model)
    fric = stage("friction", lambda: friction_stage(recorded, seed, truth=robot))
    feas = stage(
        "feasible",
        lambda: feasible_stage(
            recorded, friction=fric.fit.friction, seed=seed, truth=robot, progress=progress
        ),
    )
    cons = stage("consistent", lambda: consistent_stage(robot, seed, progress=progress))
    coll = stage(
        "collision", lambda: collision_stage(recorded, fric.fit.friction, seed, truth=robot)
    )
    return DemoResult(robot, seed, kin, ident, fric, feas, cons, coll)
