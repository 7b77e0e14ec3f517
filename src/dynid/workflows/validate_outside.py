"""A recording outside the poses and motion a model was identified on: what ``validate``
says of it, and the causes its verdict then does not assert.

The identification's record keeps each joint's range of positions and velocities
(:mod:`~dynid.identification.training_range`). A recording that leaves them is said in one
clause of the verdict (the joints, how far, the share of samples). Where the verdict would
name a cause of the residual (the recording's own torque offsets, a tilted gravity vector,
a spring, a load at the flange, what a joint's residual follows) while the recording lies
clearly outside the training's poses on the joints that residual concerns (those above
their noise, and those the cause names), the model's extrapolation there is the first
explanation: the verdict is said without the cause, which it names as not confirmed (a
Kinova arm identified with joint 2 within 2.6..3.7 rad, its offset left out and taken up
by ``mc2x``, validated at 1.4..2.0 rad: "sensors zeroed anew at each power-up", and with
the consistent model "gravity vector looks tilted 0.28 deg", both wrong).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from ..friction.recordings import RecordingsValidation
from ..identification.info import LogInfo
from ..identification.model import IdentifiedModel
from ..identification.training_range import OutsideTraining, outside_training
from ..identification.verdict import SYSTEMATIC_RATIO, Verdict
from ..model.robot import Robot
from .validate_hints import JudgedNoise, ResidualHints

__all__ = ["outside_said", "training_record"]


def training_record(model: IdentifiedModel | Robot) -> LogInfo | None:
    """The record of the torque logs ``model`` was identified on (None: a robot, static
    data)."""
    return model.info.log if isinstance(model, IdentifiedModel) else None


def _causes(hints: ResidualHints, names: Sequence[str]) -> tuple[list[str], set[int]]:
    """The causes ``hints`` name in words, and the joints (0-based) they name."""
    said: list[str] = []
    joints: set[int] = set()
    if hints.levels is not None:
        joints |= set(hints.levels.joints)
        which = ", ".join(names[j] for j in hints.levels.joints)
        said.append(f"the recording's own torque offset ({which})")
    if hints.tilt is not None and hints.tilt.named:  # with its angles: a candidate still
        ax, ay = np.degrees(hints.tilt.angle)
        said.append(
            f"a tilted gravity vector (tilted by about {ax:.2g} deg about x and {ay:.2g} deg "
            f"about y, {100 * min(hints.tilt.explained, 1.0):.0f} % of the residual above the "
            "noise)"
        )
    named = () if hints.springs is None else tuple(hints.springs.named)
    if named:
        joints |= set(named)
        said.append("a joint spring (" + ", ".join(names[j] for j in named) + ")")
    if hints.load is not None and hints.load.named:
        said.append("a load at the flange")
    return said, joints


def _concerned(hints: ResidualHints, noise: JudgedNoise, cause_joints: set[int]) -> set[int]:
    """The joints the residual concerns: those above their noise as the verdict weighed
    them (:data:`~dynid.identification.verdict.SYSTEMATIC_RATIO`), and those a cause
    names."""
    above: set[int] = set()
    if noise.ratios is not None:
        above = {int(j) for j in np.flatnonzero(np.asarray(noise.ratios) >= SYSTEMATIC_RATIO)}
    return above | cause_joints


def _appended(verdict: Verdict, clause: str) -> Verdict:
    """``verdict`` with ``clause`` appended to its reason at any level."""
    return dataclasses.replace(verdict, reason=f"{verdict.reason}; {clause}")


def outside_said(
    record: LogInfo | None,
    hints: ResidualHints,
    without_causes: Callable[[], ResidualHints],
    val: RecordingsValidation,
    noise: JudgedNoise,
    names: Sequence[str],
    units: Sequence[str] | None = None,
    turns: NDArray[np.bool_] | None = None,
) -> tuple[ResidualHints, OutsideTraining | None]:
    """``hints`` with the joints the recordings ``val`` take outside the training's ranges
    of ``record`` said in their verdict (module docstring), and those joints; where the
    recording lies clearly outside the training's poses on joints the residual concerns
    and the verdict names a cause, the hints ``without_causes`` (the residual not
    diagnosed) with the cause said as not confirmed. ``units``: each joint's position unit
    (default rad); ``turns``: the joints that turn without end, compared modulo a turn
    (:func:`~dynid.identification.training_range.endless_joints`)."""
    if record is None:
        return hints, None
    q = [v.log.q for v in val.parts]
    dq = [v.log.dq for v in val.parts]
    outside = outside_training(record.position_range, record.velocity_range, q, dq, turns)
    if outside is None:
        return hints, None
    line = outside.sentence(names, units)
    said, cause_joints = _causes(hints, names)
    clear = outside.concerned(_concerned(hints, noise, cause_joints))
    if clear and hints.verdict.level != "good":
        plain = without_causes()
        if plain.verdict.reason != hints.verdict.reason or said:  # a cause was said
            verdict = _appended(_appended(plain.verdict, line), outside.hedge(clear, said, names))
            return dataclasses.replace(plain, verdict=verdict), outside
    return dataclasses.replace(hints, verdict=_appended(hints.verdict, line)), outside
