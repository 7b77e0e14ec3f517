"""Stage 5 of the demo, beyond the paper: physically consistent parameters by the convex
(LMI) retrieval against the penalty method, on a robot with model error.

The truth is the given robot with every parameter scaled by up to +-20 %, plus rotor
inertia and a gravity tilt that no rigid body reproduces; its coefficients are identified
from static data as in stage 2, with the rotor inertias as model terms of a direct drive
(:mod:`dynid.model.drive`), and the methods retrieve link parameters from them with the
given robot as prior (:func:`dynid.feasibility.compare.compare_methods`): the convex method
identifies the rotor inertias too (``>= 0``), the penalty method gets the links' part.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..feasibility.compare import MethodSummary, compare_methods, perturbed_robot
from ..identification.model import IdentifiedModel
from ..identification.static import identify_static
from ..model.drive import Drive
from ..model.robot import Robot
from ..simulation.controller import SimulatedController, acquire_static
from ..simulation.unmodelled import UnmodelledEffects
from .stages import DEMO_CONFIGURATIONS, DEMO_WORKERS, Progress

__all__ = ["ConsistentSetup", "ConsistentStageResult", "consistent_stage"]


@dataclass(frozen=True, slots=True, eq=False)
class ConsistentSetup:
    """Stage 5's simulated truth, sent to ``progress`` before the retrievals start.

    Attributes
    ----------
    truth : Robot
        The published robot with every parameter scaled by up to +-20 %.
    effects : UnmodelledEffects
        Rotor inertia and gravity tilt that no rigid body reproduces.
    """

    truth: Robot
    effects: UnmodelledEffects


@dataclass(frozen=True, slots=True, eq=False)
class ConsistentStageResult:
    """Stage 5: convex (LMI) retrieval against the penalty method on data with model error.

    Attributes
    ----------
    truth : Robot
    effects : UnmodelledEffects
    model : IdentifiedModel
        Coefficients identified from the truth's static data.
    rows : tuple of MethodSummary
        ``sdp``, ``penalty``, ``penalty + prior``, in that order.
    prior_mass_error_truth : float
        Median over links 2..n of the prior's relative mass error against the truth.
    seed : int
    """

    truth: Robot
    effects: UnmodelledEffects
    model: IdentifiedModel
    rows: tuple[MethodSummary, ...]
    prior_mass_error_truth: float
    seed: int

    @property
    def notes(self) -> list[str]:
        """Notes of the convex method."""
        return list(self.rows[0].result.notes)


def consistent_stage(
    robot: Robot,
    seed: int,
    *,
    workers: int = DEMO_WORKERS,
    progress: Progress | None = None,
) -> ConsistentStageResult:
    """Convex retrieval against the penalty method (without and with a prior) on a robot
    that differs from ``robot`` (the prior) by up to 20 % per parameter, with rotor inertia
    and a gravity tilt; 1010 static configurations with 1e-4 relative noise.

    ``progress`` receives a :class:`ConsistentSetup` once the truth is drawn, then a
    :class:`~dynid.feasibility.penalty.result.RetrievalProgress` per finished penalty run.
    """
    rng = np.random.default_rng(np.random.SeedSequence([seed, 55]))
    truth = perturbed_robot(robot, rng)
    effects = UnmodelledEffects.typical(robot.n, rng)
    if progress is not None:
        progress(ConsistentSetup(truth, effects))
    ctrl = SimulatedController(truth, relative_noise=1e-4, rng=rng, effects=effects)
    data = acquire_static(ctrl, DEMO_CONFIGURATIONS, rng)
    with warnings.catch_warnings():  # the tilt puts data in the uninformative g1 row: expected
        warnings.simplefilter("ignore")
        # the controller's M holds the rotors: identified with the links (a direct drive)
        model = identify_static(robot, data, drive=Drive.identity(robot.n))
    rows = compare_methods(model, robot, truth=truth, workers=workers, seed=seed, progress=progress)
    prior_err = float(np.median(np.abs(robot.mass - truth.mass)[1:] / truth.mass[1:]))
    return ConsistentStageResult(truth, effects, model, tuple(rows), prior_err, seed)
