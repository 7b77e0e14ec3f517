"""What ``validate`` says the residual above the noise follows: the hints of its verdict.

In order, each judged only where the one before says nothing: a gain per motor of the
logged efforts (:func:`~dynid.friction.heldout_torques.residual_gains`; a current log's
also at the noise floor); then, above the floor, the tilt of the gravity vector, a spring
per joint, a rigid load at the flange the model lacks, and what each joint's residual
follows (its position, velocity or acceleration:
:func:`~dynid.identification.residual_dependence.with_dependence_hint`); last, a cut-off
too high for the derived states and an error at low speed. :func:`residual_hints` is the
one entry; ``dynid.workflows.validate`` judges the verdict and calls it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..friction.heldout_torques import residual_gains, residual_springs, residual_tilt
from ..friction.pooled import joined_validation
from ..friction.recordings import RecordingsValidation
from ..friction.validation import Validation
from ..identification.derived_cutoff import derived_cutoff_hint, with_derived_cutoff_hint
from ..identification.drive_gains import DriveGains
from ..identification.gravity_tilt import GravityTilt
from ..identification.log import TorqueLog
from ..identification.low_speed import with_low_speed_hint
from ..identification.model import IdentifiedModel
from ..identification.recording_level import RecordingLevels, recording_levels
from ..identification.residual_dependence import (
    dependence_hint,
    friction_left_out,
    held_terms,
    offsets_of,
    with_dependence_hint,
)
from ..identification.residual_spring import ResidualSpring
from ..identification.verdict import Verdict, with_hint
from ..model.drive import Drive
from ..model.placeholders import placeholder_words
from ..model.robot import Robot
from ..observer.residual_load import ResidualLoad, load_hint, residual_load

__all__ = ["URDF_INERTIA", "JudgedNoise", "ResidualHints", "residual_hints", "terms_held"]

#: The remedy of a residual that follows a joint's acceleration, of a robot read from a
#: URDF without a drive's rotor inertias: the file cannot hold them.
URDF_INERTIA = (
    "a URDF holds no armature: dynid's URDF export leaves it out, and warns so; validate "
    "the MJCF export (robot.xml), which holds it as armature, or give --drive a drive file "
    "with rotor_inertia"
)


@dataclass(frozen=True, slots=True)
class JudgedNoise:
    """The noise per joint [N m] (n,) of the pieces judged: the torque sensors', that of
    the states the model is evaluated at (None: not known) and all its parts (root sum of
    squares), each joint's error over it as the verdict weighed it (None: not known), and
    the part an identified model's coefficients put into its prediction (None: not
    counted)."""

    sensor: NDArray[np.float64]
    inputs: NDArray[np.float64] | None
    total: NDArray[np.float64]
    ratios: NDArray[np.float64] | None = None
    fitted: NDArray[np.float64] | None = None

    @property
    def measured(self) -> NDArray[np.float64]:
        """The noise per joint [N m] (n,) without the model's coefficients' part: what
        remains of the log's own noise once a fit to the residual (a spring, a tilt, a
        gain per motor, a load) has taken up what the model's coefficients put there as
        well as what they miss. Those fits are judged against it: counted, the
        coefficients' part would hide what they find (a torque constant 15 % off at 2 N m
        of noise, 0.4 N m of it the coefficients')."""
        if self.fitted is None:
            return self.total
        rest = np.maximum(self.total**2 - self.fitted**2, self.sensor**2)
        return np.asarray(np.sqrt(rest), dtype=np.float64)


@dataclass(frozen=True, slots=True)
class ResidualHints:
    """The verdict with its hints, and what was fitted to the residual to say them (None:
    not judged): the springs, the gains per motor, the gravity's tilt, the flange load, the
    recordings' own torque offsets."""

    verdict: Verdict
    springs: ResidualSpring | None = None
    gains: DriveGains | None = None
    tilt: GravityTilt | None = None
    load: ResidualLoad | None = None
    levels: RecordingLevels | None = None


#: The model's terms, the remedy of a residual that follows a joint's acceleration, and
#: the robot file that holds no offsets (:func:`terms_held`).
Held = tuple[frozenset[str], str | None, str | None]


def terms_held(model: IdentifiedModel | Robot, drive: Drive | None, label: str | None) -> Held:
    """The terms ``model`` holds beside the rigid bodies
    (:func:`~dynid.identification.residual_dependence.held_terms`; ``armature`` too where
    the ``drive`` placed has rotor inertias), the remedy of a residual that follows
    a joint's acceleration: :data:`URDF_INERTIA` for a robot read from a URDF (``label``
    naming it) without an armature, else None (the remedy by the terms), and ``"a URDF"``
    for such a robot, which holds no torque offsets and no friction beyond viscous and
    Coulomb (:func:`~dynid.identification.residual_dependence.cannot_hold_note`), else
    None."""
    rotors = drive is not None and drive.rotor_inertia is not None
    terms = held_terms(model) | ({"armature"} if rotors else frozenset())
    urdf = isinstance(model, Robot) and (label or "").lower().endswith(".urdf")
    inertia = URDF_INERTIA if urdf and "armature" not in terms else None
    return terms, inertia, "a URDF" if urdf else None


def residual_hints(
    model: IdentifiedModel | Robot,
    verdict: Verdict,
    val: RecordingsValidation,
    logs: Sequence[TorqueLog],
    noise: JudgedNoise,
    names: Sequence[str],
    *,
    dependence: bool = True,
    held: Held = (frozenset(), None, None),
    gains_too: bool = False,
    payload: str = "`dynid payload`",
) -> ResidualHints:
    """``verdict`` of the validation ``val`` of the recordings ``logs`` with its hints
    (module docstring). ``dependence`` False: a recording that moves beyond the
    identification's data (any residual follows the motion) or of the opposite sign,
    where only a current log's gains (``gains_too``) are judged; ``held``: the model's
    terms, which the remedies leave out, and the remedy of a residual that follows a
    joint's acceleration (:func:`terms_held`); ``payload``: the command that measures a
    load, said with one found."""
    floor = verdict.level == "good"  # a current log's constants judged at the floor too
    judged = (dependence or gains_too) and (not floor or gains_too)
    whole = joined_validation(val.parts) if judged else None
    found = _gains_said(model, verdict, whole, noise, floor)
    unsaid = found.gains is None or found.gains.sentence() is None
    if unsaid and dependence:  # said, the efforts' scale explains it: no spring, no tilt
        at = None if floor else whole  # springs, a tilt and a load: above the floor only
        said = _dependence_said(model, verdict, val, at, noise, names, held, payload)
        found = dataclasses.replace(said, gains=found.gains)
    verdict = with_derived_cutoff_hint(found.verdict, logs, val.pieces.cutoff_hz)
    high = derived_cutoff_hint(logs, val.pieces.cutoff_hz)
    if verdict.level == "good" and high is not None and noise.inputs is not None:
        # at a floor the derived states raise: a lower cut-off lowers it
        verdict = dataclasses.replace(
            verdict, reason=f"{verdict.reason}; a floor raised because {high}"
        )
    # the low-speed hint's "above the noise": the sensors' (its module docstring)
    dq = [v.log.dq for v in val.parts]
    error = [v.log.tau - v.tau_hat for v in val.parts]
    verdict = with_low_speed_hint(verdict, dq, error, noise.sensor, names)
    return dataclasses.replace(found, verdict=verdict)


def _gains_said(
    model: IdentifiedModel | Robot,
    verdict: Verdict,
    whole: Validation | None,
    noise: JudgedNoise,
    floor: bool,
) -> ResidualHints:
    """``verdict`` with the gain per motor that explains the residual of the recordings
    joined (``whole``; None: not judged), at the noise floor (``floor``) said as the
    factors and named only clear of 1 over the time blocks too
    (:attr:`~dynid.identification.drive_gains.DriveGains.floor`)."""
    gains = (
        None
        if whole is None
        else residual_gains(model, whole, noise.measured, described=floor, floor=floor)
    )
    said = None if gains is None else gains.sentence()
    if said is not None and floor:  # at the floor, the factors said
        verdict = dataclasses.replace(verdict, reason=f"{verdict.reason}; {said}")
    elif said is not None:  # the efforts' scale per motor explains it: no spring, no tilt
        verdict = with_hint(verdict, said)
    return ResidualHints(verdict, gains=gains)


def _dependence_said(
    model: IdentifiedModel | Robot,
    verdict: Verdict,
    val: RecordingsValidation,
    whole: Validation | None,
    noise: JudgedNoise,
    names: Sequence[str],
    held: Held,
    payload: str,
) -> ResidualHints:
    """``verdict`` with the tilt of the gravity vector, the springs and the flange load
    fitted on the recordings joined (``whole``; None: at the noise floor, none), and what
    each joint's residual follows (on what the load leaves, where one is named)."""
    terms, inertia, lacks = held
    offsets, left_out = offsets_of(model), friction_left_out(model)
    kinds = tuple(bool(p) for p in (model if isinstance(model, Robot) else model.robot).prismatic)
    q = [v.log.q for v in val.parts]
    dq = [v.log.dq for v in val.parts]
    t = [v.log.t for v in val.parts]  # the joints' rests told from their reversals
    error = [v.log.tau - v.tau_hat for v in val.parts]
    springs = None if whole is None else residual_springs(model, whole, noise.measured)
    tilt = None if whole is None else residual_tilt(model, whole, noise.measured, springs)
    got = [v.log.ddq for v in val.parts]
    ddq = [a for a in got if a is not None] if all(a is not None for a in got) else None
    tilted = tilt is not None and tilt.named  # a tilt named is said first, as before
    load = None if whole is None or tilted else _fitted_load(model, val, ddq, noise)
    if load is not None and load.named:  # the joints diagnosed on what it leaves
        stand_in = placeholder_words(model) if isinstance(model, Robot) else None
        verdict = with_hint(verdict, load_hint(load, payload, stand_in))
        rest = dependence_hint(
            q, dq, load.residual, noise.total, names, terms, offsets=offsets,
            left_out=left_out, ddq=ddq, inertia=inertia, lacks=lacks, prismatic=kinds, t=t,
        )  # fmt: skip
        verdict = with_hint(verdict, None if rest is None else f"what it leaves: {rest}")
        return ResidualHints(verdict, None, None, tilt, load)  # the load, not a spring
    tau = [v.log.tau for v in val.parts]
    own = None if verdict.level == "good" else _own_offsets(val, error, tau, noise.sensor, offsets)
    verdict = with_hint(verdict, None if own is None else own.sentence(names))
    levels = None if own is None else {j: own.of(j) or () for j in own.joints}
    verdict = with_dependence_hint(
        verdict, q, dq, error, noise.total, names, terms, tilt, noise.ratios, springs,
        tau, offsets, left_out, ddq, inertia, lacks, kinds, levels, t,
    )  # fmt: skip
    return ResidualHints(verdict, springs, None, tilt, load, own)


def _own_offsets(
    val: RecordingsValidation,
    error: Sequence[NDArray[np.float64]],
    tau: Sequence[NDArray[np.float64]],
    noise: NDArray[np.float64],
    offsets: Mapping[int, tuple[str, bool]],
) -> RecordingLevels | None:
    """The joints whose model holds an offset (``offsets``) and whose residual is one
    steady constant over each recording judged: the recordings' own torque offsets
    (:func:`~dynid.identification.recording_level.recording_levels`), None where there is
    none or the pieces' recordings are unknown."""
    recording = getattr(val.pieces, "recording", ())
    if len(recording) != len(error) or not offsets:
        return None
    return recording_levels(error, tau, recording, noise, tuple(offsets))


def _fitted_load(
    model: IdentifiedModel | Robot,
    val: RecordingsValidation,
    ddq: Sequence[NDArray[np.float64]] | None,
    noise: JudgedNoise,
) -> ResidualLoad | None:
    """The rigid load at the flange fitted to the residual of every piece judged
    (:func:`~dynid.observer.residual_load.residual_load`, its serial correlation over the
    pieces' cut-off at their rate); None without the accelerations."""
    if ddq is None:
        return None
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    steps = np.concatenate([np.diff(v.log.t) for v in val.parts])
    rate = 1.0 / float(np.median(steps)) if steps.size and np.median(steps) > 0 else None
    return residual_load(
        robot, [v.log.q for v in val.parts], [v.log.dq for v in val.parts], ddq,
        [v.log.tau - v.tau_hat for v in val.parts], noise.measured,
        cutoff_hz=val.pieces.cutoff_hz, rate_hz=rate,
    )  # fmt: skip
