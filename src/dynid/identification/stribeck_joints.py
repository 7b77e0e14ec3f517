"""The Stribeck velocity chosen per joint (motor) on held-out data.

The structure search judges the Stribeck law at one velocity for every joint (the grid of
:data:`~dynid.identification.structure.STRIBECK_VELOCITIES`, refined between its
neighbours: :mod:`~dynid.identification.shape_refinement`). Joints differ (a shoulder's
gearbox and a wrist's): a simulated TALOS arm with bumps at 0.08 rad/s on joints 1-2 and
0.1 on the others got 0.0955 for all, its Stribeck peaks on joints 1-2 5 % low.

:func:`per_joint_vst` judges each joint's velocity in turn, the others held at the
common one, at the grid's :data:`SIDE_STEPS` velocities each side of the common one
(further out while the lowest error is at the end, :data:`MAX_WALK`), then refines it
between the judged neighbours of the lowest by the same successive parabolic interpolation
(:func:`~.shape_refinement.shape_search`, :data:`MAX_ROUNDS` steps), all on the held-out
error (each joint's torques in units of its own noise: the whitened error the choice
reads). Given
the velocities the law is linear, and a joint's Stribeck column depends on that joint's
velocity alone: the columns of every joint's trial velocity and those of the common one
are one regressor (:func:`~.structure.vst_layers`), so each round of the joints' searches
is one fit, whatever the number of joints. A joint keeps a velocity of its own only where
it predicts held-out data better than the common one beyond one standard error of the
difference (paired, as the structure choice reads it); the velocities kept are then judged
together, and kept only where that beats the common velocity the same way.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator, Sequence

from ..regressors.terms import PART_LABELS
from .candidates import Candidate
from .shape_refinement import TOLERANCE, shape_search
from .structure import STRIBECK_VELOCITIES, Structure

__all__ = ["MAX_ROUNDS", "MAX_WALK", "SIDE_STEPS", "per_joint_vst", "vst_neighbours"]

#: The grid's velocities each side of the common one every joint is judged at first (in
#: one fit): a joint two grid steps off is bracketed without a walk.
SIDE_STEPS = 2
#: The grid's steps a joint's search walks beyond those at most (while its lowest
#: held-out error is at the end of the velocities judged), a fit each.
MAX_WALK = 1
#: The rounds of parabolic steps between the grid's velocities at most, a fit each: the
#: first vertex lands within a few % of a joint's own velocity, the second within 1-3 %.
MAX_ROUNDS = 2

_Search = Generator[float, float | None, None]


def vst_neighbours(
    vst: float, grid: Sequence[float] = STRIBECK_VELOCITIES, steps: int = SIDE_STEPS
) -> tuple[float, ...]:
    """The grid's ``steps`` velocities [rad/s] nearest ``vst`` each side, not ``vst``
    itself (fewer at the grid's ends)."""
    below = sorted(g for g in grid if math.log(vst / g) > TOLERANCE)
    above = sorted(g for g in grid if math.log(g / vst) > TOLERANCE)
    return tuple(below[-steps:] + above[:steps])


def per_joint_vst(
    start: Candidate,
    n: int,
    judged: Callable[[list[Structure], int], list[Candidate | None]],
    better: Callable[[Candidate, Candidate], bool],
) -> tuple[Candidate, list[Candidate]]:
    """From ``start`` (a Stribeck law at one velocity), a velocity per joint (module
    docstring).

    Parameters
    ----------
    start : Candidate
        The structure chosen, one Stribeck velocity [rad/s] for every joint.
    n : int
        Joints (motors) of the friction.
    judged : callable
        Structures fitted in one regressor and judged on the held-out folds, with the
        round's number (0 for the grid neighbours, -1 for the velocities kept judged
        together); their candidates in order, None for
        one the regressor could not hold.
    better : callable
        Whether the first candidate predicts held-out data better than the second beyond
        one standard error of the difference.

    Returns
    -------
    (Candidate, list of Candidate)
        The candidate reached (``start`` when no joint keeps a velocity of its own) and
        every candidate judged on the way.
    """
    s = start.structure
    if not isinstance(s.vst, float) or "stribeck" not in s.friction:
        return start, []
    v0 = s.vst
    joints = [j for j in range(n) if f"{PART_LABELS['stribeck']}{j + 1}" not in s.drop]
    side = vst_neighbours(v0)
    if not joints or not side:
        return start, []
    tried = {j: [start] for j in joints}
    every, r = _walked(s, {j: list(side) for j in joints}, tried, n, judged)
    searches = {j: _search(tried[j], j, n) for j in joints}
    every += _rounds(s, searches, tried, n, judged, r)
    kept = {j: _best(tried[j]) for j in joints}
    kept = {j: c for j, c in kept.items() if c is not start and better(c, start)}
    if not kept:
        return start, every
    if len(kept) == 1:
        return next(iter(kept.values())), every
    both = s
    for j, c in kept.items():
        both = both.with_vst(j, c.structure.vsts(n)[j], n)
    (together,) = judged([both], -1)
    if together is None:
        return start, every
    every.append(together)
    ok = not together.skipped and better(together, start)
    return (together if ok else start), every


def _walked(
    s: Structure,
    pending: dict[int, list[float]],
    tried: dict[int, list[Candidate]],
    n: int,
    judged: Callable[[list[Structure], int], list[Candidate | None]],
) -> tuple[list[Candidate], int]:
    """Each joint alone at the grid's velocities of ``pending`` (the common velocity's
    neighbours), then, while a joint's lowest held-out error is at the end of those it
    was judged at, at the grid's next velocity beyond (at most :data:`MAX_WALK` steps):
    each round's in one fit. The candidates judged (also appended to ``tried`` per joint)
    and the rounds taken."""
    out: list[Candidate] = []
    r = 0
    while pending and r <= MAX_WALK:
        pairs = [(j, v) for j, vs in pending.items() for v in vs]
        got = judged([s.with_vst(j, v, n) for j, v in pairs], r)
        for (j, _), c in zip(pairs, got, strict=True):
            out += [] if c is None else [c]
            tried[j] += [] if c is None else [c]
        pending = {j: [v] for j in pending if (v := _beyond(tried[j], j, n)) is not None}
        r += 1
    return out, r


def _beyond(tried: Sequence[Candidate], j: int, n: int) -> float | None:
    """The grid's velocity [rad/s] next beyond those joint ``j`` was judged at, on the side
    of the lowest held-out error when it is at their end (none judged beyond it); None
    where the lowest is between two judged or the grid ends."""
    scores = _scores(tried, j, n)
    if len(scores) < 2:
        return None
    best = min(scores, key=lambda v: scores[v])
    if best == min(scores):
        below = [g for g in STRIBECK_VELOCITIES if math.log(best / g) > TOLERANCE]
        return max(below) if below else None
    if best == max(scores):
        above = [g for g in STRIBECK_VELOCITIES if math.log(g / best) > TOLERANCE]
        return min(above) if above else None
    return None


def _scores(tried: Sequence[Candidate], j: int, n: int) -> dict[float, float]:
    """Joint ``j``'s Stribeck velocity [rad/s] and held-out error of each candidate of
    ``tried`` not skipped."""
    return {c.structure.vsts(n)[j]: c.score for c in tried if not c.skipped}


def _search(tried: list[Candidate], j: int, n: int) -> _Search | None:
    """Joint ``j``'s search from the scores of ``tried`` (the common velocity and the
    joint alone at grid velocities), between the judged neighbours of the lowest (also
    where the lowest is the common velocity: a joint at 0.08 rad/s beside a common
    0.0934 scored best there among the grid's 0.07 and 0.1, and its search reached
    0.0824); None when they are too few."""
    scores = _scores(tried, j, n)
    if len(scores) < 2:
        return None
    return shape_search(scores, min(scores, key=lambda v: scores[v]), MAX_ROUNDS)


def _rounds(
    s: Structure,
    searches: dict[int, _Search | None],
    tried: dict[int, list[Candidate]],
    n: int,
    judged: Callable[[list[Structure], int], list[Candidate | None]],
    first: int,
) -> list[Candidate]:
    """The joints' searches advanced together: each round, every search's next velocity
    judged in one fit (joint ``j`` at it, the others at the common one), each sent its
    score; the candidates judged, also appended to ``tried`` per joint."""
    out: list[Candidate] = []
    step = {j: next(g, None) for j, g in searches.items() if g is not None}
    for r in range(first, first + MAX_ROUNDS):
        want = {j: v for j, v in step.items() if v is not None}
        if not want:
            break
        got = judged([s.with_vst(j, v, n) for j, v in want.items()], r)
        step = {}
        for j, c in zip(want, got, strict=True):
            search = searches[j]
            assert search is not None
            step[j] = _step(search, None if c is None or c.skipped else c.score)
            out += [] if c is None else [c]
            tried[j] += [] if c is None else [c]
    return out


def _step(search: _Search, score: float | None) -> float | None:
    """The search's next shape after ``score`` (None: not judged, the search ends); None
    when it ends."""
    try:
        return search.send(score)
    except StopIteration:
        return None


def _best(tried: Sequence[Candidate]) -> Candidate:
    """The candidate of lowest held-out error, not skipped (the first where all are)."""
    mine = [c for c in tried if not c.skipped] or list(tried[:1])
    return min(mine, key=lambda c: c.score)
