"""The torque constants of a current log judged before its structure is chosen: the
structure search of ``dynid identify`` (``--terms`` not given) then runs on efforts each
motor's fitted factor corrects.

Efforts read through torque constants off by a different factor per motor leave an error
the structure search takes for other terms: on a simulated Panda logged as joint-side
currents through joint 2's constant guessed 1.4 times the true one and joint 4's 0.7
times, with joint friction and armature in the truth, the search kept no friction, and
the gains fitted with that model left 8.2 times the noise: no factor was named, the
verdict named a spring on joint 2 and joint 4's rotor inertia came out negative. The
factors are therefore judged first with the richest structure of the search (armature
where the drive's rotor inertias are identified, viscous and Coulomb friction, offsets:
the friction the truth has is present), as the held-out verdict judges them
(:func:`~dynid.friction.heldout_torques.heldout_torques`, a factor named only where it
improves the prediction of held-out data); the named ones correct the drive's torque
constants for the search, and the structure it chooses is fitted to the efforts as
logged, whose held-out verdict names the factors. Constants that are right name
nothing, and the search runs as before.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from ..exceptions import DynidError
from ..friction.heldout_torques import heldout_torques
from ..identification.drive_gains import DriveGains
from ..identification.log import TorqueLog
from ..identification.model import IdentifiedModel
from ..identification.structure import Structure
from ..model.drive import Drive

__all__ = ["CorrectedSearch", "gains_first", "richest_structure"]

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
    """

    gains: DriveGains
    drive: Drive
    searched: IdentifiedModel

    @property
    def structure(self) -> Structure:
        """The structure the search chose."""
        return Structure.parse(",".join(self.searched.info.extra.get("terms", ())))

    def note(self) -> str:
        """One sentence for the model's notes: the factors the search's efforts were
        corrected by."""
        g = self.gains
        unit = g.per
        said = ", ".join(f"{unit} {k + 1}'s by {g.factor[k]:.3g}" for k in g.named)
        return (
            "the structure was chosen on efforts corrected by the torque constants' factors "
            f"fitted with the richest structure ({','.join(richest_structure(self.drive).terms)}"
            f"): {said}; the model is fitted to the efforts as logged"
        )


def richest_structure(drive: Drive) -> Structure:
    """The search's richest classical structure for ``drive``: an armature where the
    drive's rotor inertias are identified, viscous and Coulomb friction and an offset per
    joint (motor)."""
    return Structure(
        armature=drive.identifies_rotor_inertia, friction=("viscous", "coulomb", "offset")
    )


def gains_first(
    fit: Fit,
    drive: Drive | None,
    logs: Sequence[TorqueLog],
    separate: TorqueLog | None = None,
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
    """
    if drive is None or drive.effort != "current" or drive.torque_constant is None:
        return None
    try:
        with warnings.catch_warnings():  # the richest fit's findings are not the run's
            warnings.simplefilter("ignore")
            rich = fit(richest_structure(drive), drive)
            held = heldout_torques(rich, logs[-1], separate=separate, others=logs[:-1])
    except DynidError:
        return None
    gains = None if held is None else held.gains
    if gains is None or not gains.named:
        return None
    factor = np.ones(drive.n)
    named = list(gains.named)
    factor[named] = gains.factor[named]
    corrected = dataclasses.replace(drive, torque_constant=drive.torque_constant * factor)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        searched = fit("auto", corrected)
    for w in said:  # the search's findings, but the rotor inertias of a model not kept
        if not str(w.message).startswith("the identified rotor inertia"):
            warnings.warn(w.message, w.category, stacklevel=2)
    return CorrectedSearch(gains, corrected, searched)
