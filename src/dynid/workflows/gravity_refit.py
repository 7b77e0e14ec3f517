"""The gravity vector a held-out verdict reads, fitted: ``dynid identify`` identifies again
with it when the verdict names a tilted base.

A robot whose base is mounted off level (or whose description's base frame is not aligned
with gravity) loads its joints with gravity torques the description's level gravity vector
does not give; the fit takes what it can of them into its own terms and bends them. The
held-out verdict names such a tilt (:mod:`~dynid.identification.gravity_tilt`: the two
first-order tilt columns of the description's links, with the model's columns projected
out) and the gravity vector the data read as. :func:`refit_gravity` then identifies again
(the same search: the structure chosen on held-out data, or the one given) with the
robot's gravity set to that vector, again while the new model's verdict still names a tilt
(the columns being first order; at most :data:`MAX_REFITS` times), and keeps the model whose
held-out error (the verdict's, on the same held-out data and folds) is lowest: its robot
carries the gravity fitted (``identification.json``'s robot records it, so that
``validate``, ``observe`` and ``export`` of that file use it), a note says it, and the
model's metadata hold it (``gravity_fitted``: :meth:`FittedGravity.as_dict`).

A simulated Panda tilted 0.3 deg about x, with friction, offsets and rotor inertias, three
5 s recordings: the level description's fit left 0.65 % held out (noise floor 0.35 %) and
bent the offsets (fo1 +0.107 +- 0.011 N m for a true +0.2, fo3 left out for +0.1); the
gravity fitted reads 0.30 deg about x and the refit is at the floor. A level arm's verdict
names no tilt: it is fitted once, as before, its results unchanged.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import numpy as np
from numpy.typing import NDArray

from ..friction.heldout_torques import HeldOutTorques
from ..identification.model import IdentifiedModel
from ..model.robot import Robot

__all__ = ["MAX_REFITS", "FittedGravity", "Refitted", "refit_gravity", "tilt_rotation"]

#: Most identifications again with the gravity vector read (the tilt columns are first
#: order: a 0.3 deg tilt is read to about 1e-3 of itself by the first).
MAX_REFITS = 3

_T = TypeVar("_T")


@dataclass(frozen=True, slots=True, eq=False)
class FittedGravity:
    """The gravity vector a model was identified with in place of the description's.

    Attributes
    ----------
    gravity : ndarray, shape (3,)
        The gravity vector fitted [m/s^2], base frame.
    described : ndarray, shape (3,)
        The description's gravity vector [m/s^2], base frame.
    level_percent : float
        The held-out error [%] of the model identified with ``described``.
    fitted_percent : float
        The held-out error [%] of the model identified with ``gravity`` (the same held-out
        data, judged as the verdict judges).
    floor_percent : float
        The noise floor [%] of the held-out torques (of the model kept).
    refits : int
        Identifications made again with a gravity vector read (1 to :data:`MAX_REFITS`).
    """

    gravity: NDArray[np.float64]
    described: NDArray[np.float64]
    level_percent: float
    fitted_percent: float
    floor_percent: float
    refits: int

    @property
    def rotation(self) -> NDArray[np.float64]:
        """The rotation vector [rad] (base frame) turning ``described`` into ``gravity``:
        its x and y components are the tilt about the base's x and y axes."""
        return tilt_rotation(self.described, self.gravity)

    @property
    def angle(self) -> NDArray[np.float64]:
        """The tilt [rad] about the base's x and y axes (:attr:`rotation`'s components)."""
        return self.rotation[:2]

    def note(self) -> str:
        """The finding in one sentence, with the angles [deg], both held-out errors and
        where a user gives the gravity vector."""
        ax, ay = np.degrees(self.angle)
        g = ",".join(f"{x:.6g}" for x in self.gravity)
        shown = g.replace(",", ", ")
        return (
            f"gravity vector fitted: the base reads tilted {ax:.2f} deg about x and {ay:.2f} "
            f"deg about y, gravity = [{shown}] m/s^2 in the base frame (the robot's in "
            "identification.json); the description's level gravity left a held-out error of "
            f"{self.level_percent:.3g} %, the fitted one {self.fitted_percent:.3g} % (noise "
            f"floor {self.floor_percent:.3g} %); give it as --gravity={g} "
            "(or a robot TOML's gravity) to identify with it from the start"
        )

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (``identification.json``'s ``gravity_fitted``): ``gravity`` and
        ``described`` [m/s^2, base frame], ``angle_deg`` about base x and y [deg],
        ``level_percent``, ``fitted_percent``, ``floor_percent`` [%], ``refits`` and the
        ``note``."""
        return {
            "gravity": self.gravity.tolist(),
            "described": self.described.tolist(),
            "angle_deg": np.degrees(self.angle).tolist(),
            "level_percent": float(self.level_percent),
            "fitted_percent": float(self.fitted_percent),
            "floor_percent": float(self.floor_percent),
            "refits": int(self.refits),
            "note": self.note(),
        }


@dataclass(frozen=True, slots=True, eq=False)
class Refitted(Generic[_T]):
    """What :func:`refit_gravity` keeps.

    Attributes
    ----------
    robot : Robot
        The robot identified with (the description's, or with the gravity fitted).
    searched : tuple
        The search's ``(model, held-out prediction, extra)`` of ``robot``.
    gravity : FittedGravity or None
        None: the description's gravity kept (no tilt named, or no refit better held out).
    said : list of warnings.WarningMessage
        The warnings of the search kept (said by the caller).
    """

    robot: Robot
    searched: tuple[IdentifiedModel, HeldOutTorques | None, _T]
    gravity: FittedGravity | None
    said: list[warnings.WarningMessage]


def tilt_rotation(
    described: NDArray[np.float64], gravity: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The rotation vector [rad] (3,), base frame, of the smallest rotation turning the
    gravity vector ``described`` (3,) into ``gravity`` (3,) [m/s^2]: its x and y components
    are the tilt about the base's x and y axes; zeros for parallel vectors."""
    a, b = np.asarray(described, dtype=np.float64), np.asarray(gravity, dtype=np.float64)
    axis = np.cross(a, b)
    s = float(np.linalg.norm(axis))
    if s == 0.0:
        return np.zeros(3)
    angle = float(np.arctan2(s, float(np.dot(a, b))))
    out: NDArray[np.float64] = axis / s * angle
    return out


def _error(held: HeldOutTorques | None) -> float:
    """The held-out relative error [%] (inf without a prediction)."""
    return np.inf if held is None else float(held.validation.errors.relative_error_percent)


def _tilted(held: HeldOutTorques | None) -> bool:
    return held is not None and held.tilt is not None and held.tilt.named


def refit_gravity(
    robot: Robot,
    search: Callable[[Robot], tuple[IdentifiedModel, HeldOutTorques | None, _T]],
) -> Refitted[_T]:
    """``search(robot)``, and where its held-out verdict names a tilt of the gravity vector,
    ``search`` again with ``robot``'s gravity set to the vector the data read as, while the
    verdict names one (at most :data:`MAX_REFITS` times, stopping when the held-out error
    does not fall); the model of the lowest held-out error kept (module docstring).

    Parameters
    ----------
    robot : Robot
        The description (its gravity vector [m/s^2], base frame).
    search : callable
        ``search(robot)``: the identification's model, its held-out prediction and
        anything else, of a robot (the same logs, options and folds each time).

    Returns
    -------
    Refitted
        Of a verdict naming no tilt, ``search(robot)`` itself with ``gravity`` None (the
        search made once: results as before).
    """
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        first = search(robot)
    kept = Refitted(robot, first, None, list(said))
    held = first[1]
    level = _error(held)
    best, current = level, robot
    for k in range(1, MAX_REFITS + 1):
        if held is None or held.tilt is None or not _tilted(held):
            break
        current = current.with_gravity(held.tilt.gravity)
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            again = search(current)
        held = again[1]
        if held is None or not _error(held) < best:
            break
        best = _error(held)
        fitted = FittedGravity(
            np.array(current.gravity), np.array(robot.gravity), level, best,
            held.noise_floor_percent, k,
        )  # fmt: skip
        kept = Refitted(current, again, fitted, list(said))
    return kept
