"""The paper's pipeline as library calls: one function per stage, frozen results.

``run_demo(seed=0, progress=print)`` runs everything ``dynid demo`` runs and returns a
:class:`DemoResult`; the stage functions run one stage each. Nothing here prints or writes
files: the command line renders the results and saves them.
"""

from .collision import CollisionStageResult, collision_stage
from .consistent import ConsistentSetup, ConsistentStageResult, consistent_stage
from .demo import (
    STAGE_TITLES,
    STAGES,
    DemoResult,
    Stage,
    StageFinished,
    StageKind,
    StageStarted,
    run_demo,
)
from .stages import (
    DEMO_RELATIVE_NOISE,
    DEMO_TOOL_XYZ,
    DEMO_WORKERS,
    FeasibleStageResult,
    FrictionStageResult,
    IdentificationStageResult,
    KinematicsStageResult,
    feasible_stage,
    friction_stage,
    identification_stage,
    kinematics_only,
    kinematics_stage,
)

__all__ = [
    "DEMO_RELATIVE_NOISE",
    "DEMO_TOOL_XYZ",
    "DEMO_WORKERS",
    "STAGES",
    "STAGE_TITLES",
    "CollisionStageResult",
    "ConsistentSetup",
    "ConsistentStageResult",
    "DemoResult",
    "FeasibleStageResult",
    "FrictionStageResult",
    "IdentificationStageResult",
    "KinematicsStageResult",
    "Stage",
    "StageFinished",
    "StageKind",
    "StageStarted",
    "collision_stage",
    "consistent_stage",
    "feasible_stage",
    "friction_stage",
    "identification_stage",
    "kinematics_only",
    "kinematics_stage",
    "run_demo",
]
