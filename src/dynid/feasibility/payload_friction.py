"""The friction a payload fit estimates beside the load, chosen as identification chooses it.

The loaded data hold the arm's friction beside the load's torques; what the arm's own
model leaves of it is estimated alongside (:func:`~dynid.feasibility.payload_rows.log_rows`).
By default that is the classical ``fv, fc, fo`` per joint (Gaz et al. 2019, eq. 24).
A friction of another shape (a smooth Coulomb's rounding, a Stribeck bump at low speed)
left to it is a misfit the load's mass and CoM take in, and the fit's residual says so
(:func:`~dynid.feasibility.payload_doubts.misfit_doubts`). :func:`chosen_friction` then
chooses the friction the way ``dynid identify`` does, with the same machinery
(:func:`~dynid.identification.selection.select_structure`: the laws of
:data:`~dynid.regressors.terms.FRICTION_PARTS`, their widths and Stribeck velocities judged
on held-out recordings or time blocks) on the loaded recordings with the links'
parameters free: the load is a change of the last links' parameters, which those hold,
so the friction chosen is the data's whatever the load. Only its friction parts are
kept (every joint holding every part, and an offset: the choice of single joints'
coefficients was made with free links); the armature and a spring belong to the arm's
model (``dynid identify``, then ``--model``).

* :func:`friction_term`: the friction columns of a structure at the joints, with the
  recordings' standstill bands (the classical law with the plain sign for None);
* :func:`friction_structure`: a structure given as the friction beside the load;
* :func:`chosen_friction`: the structure chosen on held-out data, with its note;
* :func:`rows_rms`: the least-squares residual RMS of rows, to compare two frictions.
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DynidWarning, OptionError
from ..identification.largest import recording_bands
from ..identification.recordings import Recordings
from ..identification.selection import select_structure
from ..identification.structure import Structure, structure_terms
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.terms import LinearFriction

__all__ = [
    "CLASSICAL_NAME",
    "chosen_friction",
    "classical_parts",
    "friction_structure",
    "friction_term",
    "rows_residual",
    "rows_rms",
]

#: The name of the default friction beside the load (no standstill band).
CLASSICAL_NAME = "viscous + coulomb + offset"


def friction_structure(structure: Structure) -> Structure:
    """``structure`` as the friction beside the load: its friction parts with an offset,
    at the joints, on every joint.

    Raises
    ------
    OptionError
        ``structure`` holds an armature or a spring (the arm's model's terms).
    """
    if structure.armature or structure.spring:
        raise OptionError(
            ": the friction beside the load holds friction parts only; an armature or a "
            "spring belongs to the arm's model (dynid identify on data without the load, "
            "then --model)",
            field="terms",
        )
    parts = tuple(dict.fromkeys((*structure.friction, "offset")))
    return replace(structure, friction=parts, at="", drop=())


def friction_term(structure: Structure | None, data: Recordings, n: int) -> LinearFriction:
    """The friction columns beside the load: the classical ``fv, fc, fo`` per joint with
    the plain sign (``structure`` None), or ``structure``'s
    (:func:`friction_structure`) at the joints, its Coulomb band and smooth width from the
    recordings' standstill bands as identification sets them
    (:func:`~dynid.identification.structure.structure_terms`)."""
    if structure is None:
        return LinearFriction(Drive.identity(n))
    s = friction_structure(structure)
    bands = recording_bands(data)
    _, terms = structure_terms(s, None, n, tuple(data.band), bands, data.band_gain)
    return next(t for t in terms if isinstance(t, LinearFriction))


def chosen_friction(robot: Robot, data: Recordings, drive: Drive | None) -> Structure | None:
    """The friction structure ``dynid identify`` chooses on the loaded recordings ``data``
    (prepared; ``robot``'s links free, the drive ``drive``), as the friction beside the
    load (:func:`friction_structure`); None when the data are too short to judge on held-out
    data or the choice holds no friction. The selection's own warnings (a recording unlike
    the others) are left to ``dynid identify``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        selection = select_structure(robot, data, drive=drive)
    if selection is None or not selection.chosen.friction:
        return None
    return friction_structure(replace(selection.chosen, armature=False, spring=False, drop=()))


def rows_rms(
    W: NDArray[np.float64], y: NDArray[np.float64], kept: NDArray[np.bool_] | None = None
) -> float:
    """RMS [units of ``y``] of the least-squares residual of ``y`` (N,) on the columns
    ``kept`` of ``W`` (N, p), the columns scaled to unit norm."""
    return float(np.sqrt(np.mean(rows_residual(W, y, kept) ** 2)))


def rows_residual(
    W: NDArray[np.float64], y: NDArray[np.float64], kept: NDArray[np.bool_] | None = None
) -> NDArray[np.float64]:
    """The least-squares residual (N,) [units of ``y``] of ``y`` (N,) on the columns
    ``kept`` of ``W`` (N, p), the columns scaled to unit norm."""
    Wk = W if kept is None else W[:, kept]
    scale = np.linalg.norm(Wk, axis=0)
    Ws = Wk / np.where(scale > 0, scale, 1.0)
    x = np.linalg.lstsq(Ws, y, rcond=None)[0]
    return np.asarray(y - Ws @ x, dtype=np.float64)


def classical_parts(
    values: NDArray[np.float64], labels: tuple[str, ...], n: int
) -> NDArray[np.float64]:
    """``fv, fc, fo`` per joint (n, 3) of friction coefficients ``values`` labelled
    ``labels`` (``fv1, fc1, fsp1, fo1, ...``; a smooth Coulomb's ``fc`` is its
    coefficient); zero where not held."""
    out = np.zeros((n, 3))
    where = {"fv": 0, "fc": 1, "fo": 2}
    for v, lab in zip(values, labels, strict=True):
        prefix = lab.rstrip("0123456789")
        if prefix in where:
            out[int(lab[len(prefix) :]) - 1, where[prefix]] = v
    return out
