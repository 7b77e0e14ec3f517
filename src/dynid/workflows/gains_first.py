"""The torque constants of a current log judged before its structure is chosen, when the
structure the search chose points to them: the search of ``dynid identify`` (``--terms``
not given) then runs again on efforts each motor's fitted factor corrects.

Efforts read through torque constants off by a different factor per motor leave an error
the structure search takes for other terms: on a simulated Panda logged as joint-side
currents through joint 2's constant guessed 1.4 times the true one and joint 4's 0.7
times, with joint friction and armature in the truth, the search kept no friction, and
the gains fitted with that model left 8.2 times the noise: no factor was named, the
verdict named a spring on joint 2 and joint 4's rotor inertia came out negative. The
search's model is judged first as always (its held-out verdict, whose gains per motor are
fitted above the noise floor); where those gains name a factor, the verdict's error or the
one the gains leave is more than :data:`FIRST_RATIO` times the noise, or the model holds a
rotor inertia below zero by more than its standard deviation
(:func:`reason_to_judge_first`), the factors are judged with
the richest structure of the search (armature where the drive's rotor inertias are
identified, viscous friction, the sign law the search chose or Coulomb friction, offsets:
the friction the truth has is present), as the held-out verdict judges them
(:func:`~dynid.friction.heldout_torques.heldout_torques`, a factor named only where it
improves the prediction of held-out data); the named ones correct the drive's torque
constants for a second search, whose model, fitted to the corrected efforts (its drive's
torque constants times the factors), is the one kept, and the held-out verdict names the
factors. Fitted to the efforts as logged, the structure chosen there took up in its terms
what the wrong constants leave (on the 5 s log above, joint 4's rotor inertia 1.95 kg m^2
for a true 0.2, viscous friction below zero on joints 2 and 4). Constants that are right leave
a verdict near the noise floor and gains that name nothing: the search runs once, as it did.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..exceptions import DynidError
from ..friction.heldout_torques import HeldOutTorques, heldout_torques
from ..identification.drive_gains import DriveGains
from ..identification.log import TorqueLog
from ..identification.model import IdentifiedModel
from ..identification.motor_constants import GearRatioPattern, gear_ratio_pattern
from ..identification.rotor_sign import negative_rotor_inertias, per_joint
from ..identification.structure import Structure
from ..model.drive import Drive

__all__ = [
    "FIRST_RATIO",
    "UNKNOWN_SCALE",
    "CorrectedSearch",
    "UnknownScale",
    "gains_first",
    "reason_to_judge_first",
    "richest_structure",
    "unknown_scale",
]

#: Largest ratio [-] of the chosen structure's held-out error to the noise floor, and of the
#: error its gains per motor leave fitted to the noise, before the constants are judged
#: with the richest structure (simulated Panda current logs of 3 to 20 s through their
#: true constants: verdicts at 1.0 to 1.35 times the floor, gains leaving 0.7 to 0.9;
#: joints 2 and 4 guessed 1.4 and 0.7 times: verdicts at 10 to 50 times, and gains that
#: left 8.2 times where nothing was named).
FIRST_RATIO = 2.0

#: A fit of the recordings: the structure (or ``"auto"``, chosen on held-out data) and the
#: drive they are read through.
Fit = Callable[[Structure | Literal["auto"], Drive], IdentifiedModel]


@dataclass(frozen=True, slots=True, eq=False)
class CorrectedSearch:
    """The structure search on efforts corrected by the factors judged first.

    Attributes
    ----------
    gains : DriveGains
        The factors judged with :func:`richest_structure` (:attr:`DriveGains.named`: the
        motors corrected).
    drive : Drive
        The drive the search read the logs through: each named motor's torque constant
        times its factor.
    searched : IdentifiedModel
        The search's model (its ``info.selection``: the candidates judged on the corrected
        efforts).
    why : str
        Why the constants were judged first (:func:`reason_to_judge_first`).
    said : tuple of warnings.WarningMessage
        The search's warnings (of the model kept), for the caller to say.
    rich : Structure
        The structure the factors were judged with (:func:`richest_structure`).
    pattern : GearRatioPattern, optional
        The gains follow the gear ratios (constants given at the motors on a joint-side
        log): the drive's constants are corrected by the gear ratios, every motor's, not
        by the factors.
    """

    gains: DriveGains
    drive: Drive
    searched: IdentifiedModel
    why: str = ""
    said: tuple[warnings.WarningMessage, ...] = ()
    rich: Structure = dataclasses.field(default_factory=Structure)
    pattern: GearRatioPattern | None = None

    @property
    def structure(self) -> Structure:
        """The structure the search chose."""
        return Structure.parse(",".join(self.searched.info.extra.get("terms", ())))

    def factors(self) -> str:
        """The factors named, in words: ``joint 2's by 0.713, joint 4's by 1.42``."""
        g = self.gains
        if self.pattern is not None:
            ratios = ", ".join(f"{r:.4g}" for r in self.pattern.gear_ratio)
            return f"every motor's by its gear ratio ({ratios})"
        return ", ".join(f"{g.per} {k + 1}'s by {g.factor[k]:.3g}" for k in g.named)

    def note(self) -> str:
        """One sentence for the model's notes and the summary: why the torque constants
        were judged first and the factors the search's efforts were corrected by."""
        said = self.factors()
        why = f" ({self.why})" if self.why else ""
        judged = (
            f"the torque constants were judged first{why} with the richest structure "
            f"({','.join(self.rich.terms)})"
        )
        if self.pattern is not None:
            return (
                f"{judged}: {self.pattern.sentence()}; the structure was chosen on them and "
                "the model is fitted to them (identification.json's drive holds "
                "torque_constant x gear_ratio: put it in the drive file)"
            )
        return (
            f"{judged} and the structure was chosen "
            f"on efforts corrected by their factors: {said}; the model is fitted to them (its "
            "drive's torque_constant times the factors)"
        )

    def consistent_note(self) -> str:
        """One sentence for the consistent fit's notes: the efforts it is fitted to (those
        the factors correct) and the torque constants that read them, its drive's."""
        kt = self.drive.torque_constant
        said = "" if kt is None else " ".join(f"{x:.4g}" for x in kt)
        why = f" ({self.why})" if self.why else ""
        return (
            f"the torque constants were judged first{why}: the consistent fit is fitted to "
            f"the efforts corrected by their factors, {self.factors()}, read through "
            f"torque_constant = [{said}] (its drive's), with the structure chosen on them"
        )


def richest_structure(drive: Drive, chosen: Structure | None = None) -> Structure:
    """The search's richest structure for ``drive``: an armature where the drive's rotor
    inertias are identified, viscous friction, the sign law of ``chosen`` (the structure
    the search chose: its smooth width or Stribeck velocity, its quadratic term and where
    its friction acts; Coulomb friction without one) and an offset per joint (motor).

    Judged with a sign law the data do not follow, the gains take up that law's error
    too: on a UR5 logged in currents whose friction is ``fc tanh(dq / 5 mrad/s)``,
    Coulomb friction with its standstill band left 1.35 x the noise with the gains
    fitted, too much for them to explain the error, and neither of two constants guessed
    1.3 and 0.7 times the true ones was named; with the smooth law the search chose, 1.03
    x, both named within 0.2 %."""
    laws = () if chosen is None else tuple(p for p in chosen.friction if p in _LAWS)
    if not {"coulomb", "smooth"} & set(laws):
        laws = ("coulomb", *laws)
    return Structure(
        armature=drive.identifies_rotor_inertia,
        friction=("viscous", *laws, "offset"),
        width=0.0 if chosen is None or "smooth" not in laws else chosen.width,
        vst=0.0 if chosen is None or "stribeck" not in laws else chosen.vst,
        at="" if chosen is None else chosen.at,
    )


#: The friction parts :func:`richest_structure` takes from the structure chosen.
_LAWS = ("quadratic", "coulomb", "smooth", "stribeck")


def reason_to_judge_first(model: IdentifiedModel, held: HeldOutTorques | None) -> str | None:
    """Why the torque constants of ``model``'s current log are to be judged with the
    richest structure (module docstring), in words, or None: the held-out verdict's gains
    per motor (``held.gains``) name a factor, its error or the error its gains leave
    fitted is more than :data:`FIRST_RATIO` times the noise, or a rotor inertia is below
    zero by more than its standard deviation."""
    gains = None if held is None else held.gains
    unit = "joint" if per_joint(model.drive) else "motor"
    if gains is not None and gains.named:
        which = ", ".join(str(k + 1) for k in gains.named)
        return f"the chosen structure's verdict named a factor of {unit}(s) {which}"
    ratio = None if held is None else held.verdict.ratio
    if ratio is not None and ratio > FIRST_RATIO:
        return f"the chosen structure's held-out error is {ratio:.3g} x the noise floor"
    if gains is not None and gains.ratio_fitted > FIRST_RATIO:
        return (
            f"the gains fitted with the chosen structure left {gains.ratio_fitted:.3g} x the noise"
        )
    below = [
        label
        for label, value, std in negative_rotor_inertias(model)
        if np.isfinite(std) and -value > std
    ]
    if below:
        return f"the chosen structure's rotor inertia(s) {', '.join(below)} came out negative"
    return None


def gains_first(
    fit: Fit,
    drive: Drive | None,
    logs: Sequence[TorqueLog],
    separate: TorqueLog | None = None,
    why: str = "",
    chosen: Structure | None = None,
) -> CorrectedSearch | None:
    """The structure search on efforts corrected by the factors the richest structure
    names (module docstring), or None: a drive that does not log currents, no factor
    named, or a richest fit the data refuse (the search then runs as given).

    Parameters
    ----------
    fit : callable
        ``fit(structure, drive)``: the recordings ``logs`` fitted through ``drive``.
    drive : Drive or None
        The drive file's drive (its guessed torque constants).
    logs : sequence of TorqueLog
        The recordings as the fit reads them (the last one held out, as the verdict's).
    separate : TorqueLog, optional
        The ``validate_on`` log.
    why : str, optional
        Why the constants are judged (:func:`reason_to_judge_first`), for the note.
    chosen : Structure, optional
        The structure the search chose on the efforts as logged: the richest structure
        takes its friction law (:func:`richest_structure`).
    """
    if drive is None or drive.effort != "current" or drive.torque_constant is None:
        return None
    try:
        with warnings.catch_warnings():  # the richest fit's findings are not the run's
            warnings.simplefilter("ignore")
            richest = richest_structure(drive, chosen)
            rich = fit(richest, drive)
            held = heldout_torques(rich, logs[-1], separate=separate, others=logs[:-1])
    except DynidError:
        return None
    gains = None if held is None else held.gains
    if gains is None or not gains.named:
        return None
    pattern = gear_ratio_pattern(gains, drive)
    factor = np.ones(drive.n)
    named = list(gains.named)
    factor[named] = gains.factor[named]
    if pattern is not None:  # the constants were right, at the motors: every one
        factor = pattern.gear_ratio
    corrected = dataclasses.replace(drive, torque_constant=drive.torque_constant * factor)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        searched = fit("auto", corrected)
    return CorrectedSearch(gains, corrected, searched, why, tuple(said), richest, pattern)


#: The key of ``identification.json``'s metadata and of ``feasible.json`` that names the
#: motors whose effort's scale the data leave unknown (:meth:`UnknownScale.as_dict`).
UNKNOWN_SCALE = "unknown_scale"


@dataclass(frozen=True, slots=True)
class UnknownScale:
    """The motors of a log whose torque constants (torque sensors' scales) were judged off
    on some motors and which the data leave unknown on others
    (:attr:`~dynid.identification.drive_gains.DriveGains.unknown_scale`): their joints'
    torques, and the rotor inertias and friction fitted to them, carry that unknown factor.

    Attributes
    ----------
    motors : tuple of int
        The motors (from 0).
    joints : tuple of str
        The joints they act on.
    factor : tuple of float or None
        Each motor's factor as read (None: not determined) [-].
    effort : {"current", "torque"}
        What the log holds.
    per : {"joint", "motor"}
        Whose efforts the factors scale.
    """

    motors: tuple[int, ...]
    joints: tuple[str, ...]
    factor: tuple[float | None, ...]
    effort: str = "current"
    per: str = "motor"

    def sentence(self) -> str:
        """In words, for the model's notes and the summary."""
        which = ", ".join(str(k + 1) for k in self.motors)
        read = "; ".join(
            f"{self.per} {k + 1}'s "
            + ("not determined" if f is None else f"reads {f:.3g}, not named")
            for k, f in zip(self.motors, self.factor, strict=True)
        )
        what = "torque_constant" if self.effort == "current" else "torque scale"
        return (
            f"the {what} of {self.per}(s) {which} is not known from the data ({read}; "
            "the held-out verdict says why): the torques of "
            f"{', '.join(self.joints)}, and the rotor inertias and friction fitted there, "
            "carry that unknown factor (metadata unknown_scale)"
        )

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: ``motors`` (from 1), ``joints``, ``factor`` (null: not determined),
        ``effort``, ``per`` and ``finding`` (:meth:`sentence`)."""
        return {
            "motors": [k + 1 for k in self.motors],
            "joints": list(self.joints),
            "factor": list(self.factor),
            "effort": self.effort,
            "per": self.per,
            "finding": self.sentence(),
        }


def unknown_scale(
    gains: DriveGains | None, drive: Drive | None, joint_names: Sequence[str]
) -> UnknownScale | None:
    """The motors whose effort's scale the data leave unknown where the gains judged some
    motors off (:attr:`~dynid.identification.drive_gains.DriveGains.named`, or applied by
    :func:`gains_first`): a drive file found wrong on some motors vouches for none of its
    other guesses; None otherwise (nothing named: the constants stand as given)."""
    if gains is None or not (gains.named or gains.applied):
        return None
    motors = gains.unknown_scale
    if not motors:
        return None
    K = np.eye(len(joint_names)) if drive is None else np.asarray(drive.transmission)
    acts = np.abs(K[list(motors)]) > 0
    joints = tuple(joint_names[int(j)] for j in np.flatnonzero(acts.any(axis=0)))
    factor = tuple(
        float(gains.factor[k]) if gains.determined[k] and np.isfinite(gains.factor[k]) else None
        for k in motors
    )
    return UnknownScale(motors, joints, factor, gains.effort, gains.per)
