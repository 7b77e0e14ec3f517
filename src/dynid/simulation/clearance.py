"""The closest approaches of an arm's links to each other and to obstacles along a motion.

A link is its capsule (:mod:`dynid.simulation.collision`: capsule ``k`` belongs to link
``k``, 0 = the base), named by ``robot.link_names``. For each motion the closest pair of
non-adjacent links is one :class:`Approach`, and the closest link to each obstacle another;
each says its signed distance [m], the clearance required, when it happens and which
options change it (as the Python API names them: ``radii``, ``self_clearance``,
``obstacle_clearance``, ``obstacles``; the command line gives their flags).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.robot import Robot
from .collision import (
    CapsuleModel,
    Obstacles,
    capsule_segments,
    obstacle_capsule_distances,
    self_distances,
)

__all__ = ["Approach", "closest_approaches"]


@dataclass(frozen=True, slots=True)
class Approach:
    """The closest approach of a link to another link or to an obstacle along a motion.

    Attributes
    ----------
    link : str
        The link (the first of a pair).
    other : str
        The other link, or the obstacle's name.
    obstacle : bool
        Whether ``other`` is an obstacle.
    distance : float
        Smallest signed distance of the capsules' surfaces [m] (negative: penetrating).
    required : float
        The clearance required [m].
    t : float
        When the distance is smallest [s].
    """

    link: str
    other: str
    obstacle: bool
    distance: float
    required: float
    t: float

    @property
    def margin(self) -> float:
        """``distance - required`` [m]; negative when the clearance is violated."""
        return self.distance - self.required

    @property
    def options(self) -> tuple[str, ...]:
        """The options that change the distance or the clearance required."""
        if self.obstacle:
            return ("radii", "obstacle_clearance", "obstacles")
        return ("radii", "self_clearance")

    def describe(self, name: Callable[[str], str] = str) -> str:
        """One line: the pair, the distance, when, the clearance and the options that change
        it, each named by ``name`` (``str``: as the Python API names them)."""
        pair = f"{self.link} and {'obstacle ' if self.obstacle else ''}{self.other}"
        gap = "apart" if self.distance >= 0 else "into each other"
        return (
            f"{pair} {abs(self.distance):.3g} m {gap} at t = {self.t:.3g} s, "
            f"{self.required:.3g} m required ({self.margin:.3g} m); "
            f"change with {' or '.join(name(o) for o in self.options)}"
        )


def closest_approaches(
    robot: Robot,
    t: ArrayLike,
    q: ArrayLike,
    caps: CapsuleModel,
    obstacles: Obstacles,
    *,
    self_clearance: float,
    obstacle_clearance: float,
    segments: NDArray[np.float64] | None = None,
) -> tuple[tuple[Approach, ...], tuple[Approach, ...]]:
    """The closest pair of non-adjacent links, and the closest link to each obstacle.

    Parameters
    ----------
    robot : Robot
    t : array_like, shape (N,)
        Times of the samples [s].
    q : array_like, shape (N, n)
        Joint positions [rad].
    caps : CapsuleModel
    obstacles : Obstacles
    self_clearance, obstacle_clearance : float
        The clearances required [m].
    segments : ndarray, shape (N, n + 1, 2, 3), optional
        :func:`~dynid.simulation.collision.capsule_segments` of ``q``.

    Returns
    -------
    self_pair : tuple of Approach
        The closest pair (empty when no pair is checked).
    to_obstacles : tuple of Approach
        One per obstacle, in the order of ``obstacles.names`` (empty for a one-joint arm).
    """
    tt = np.asarray(t, dtype=np.float64)
    seg = capsule_segments(robot, q) if segments is None else segments
    names = robot.link_names
    pair: tuple[Approach, ...] = ()
    if caps.pairs.size:
        d = self_distances(robot, q, caps, segments=seg)  # (N, k)
        s, k = np.unravel_index(int(np.argmin(d)), d.shape)
        i, j = caps.pairs[k]
        pair = (Approach(names[i], names[j], False, float(d[s, k]), self_clearance, float(tt[s])),)
    found: list[Approach] = []
    if len(obstacles) and seg.shape[-3] > 2:
        d = obstacle_capsule_distances(robot, q, obstacles, caps, segments=seg)  # (N, c, m)
        for m, obstacle in enumerate(obstacles.names):
            s, c = np.unravel_index(int(np.argmin(d[..., m])), d.shape[:2])
            found.append(
                Approach(
                    names[c + 2],
                    obstacle,
                    True,
                    float(d[s, c, m]),
                    obstacle_clearance,
                    float(tt[s]),
                )
            )
    return pair, tuple(found)
