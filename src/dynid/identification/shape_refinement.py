"""A friction law's shape refined between the grid's points on held-out data.

The structure search judges the shapes of the laws at grids about 1.5 to 3.3 x apart: the
Stribeck bump ``exp(-(dq / v_st)^2)`` at the velocities of
:data:`~dynid.identification.structure.STRIBECK_VELOCITIES`, the smooth Coulomb
``tanh(dq / w)`` at the widths of :data:`~dynid.identification.structure.SMOOTH_WIDTHS`.
A true shape between two of them is taken at the nearer, and the coefficients that share
its columns make up for the difference: a simulated cobot whose bump sits at 0.08 rad/s,
chosen at 0.1, had its Stribeck peak on joint 4 at 0.42 N m against 0.5 (0.48 at the
truth); a smooth Coulomb at 18 bands, judged at 10 and 30, took a Stribeck bump below
zero to round the sign. Given the shape the law is linear, so each shape is one more fit
of the same columns; :func:`refined_shape` searches its logarithm between the grid
neighbours of the chosen shape by successive parabolic interpolation (Brent's step
without its golden fallback but where the parabola is not convex) on the held-out error
the grid was judged on, starting from the grid's own scores, so that a few fits (at most
:data:`MAX_FITS`) reach the minimum within :data:`TOLERANCE`. Never the training error: a
wider bump or a narrower sign always fits the training data at least as well.

A smooth width's error is V-shaped in the width's logarithm (a simulated UR5 judged on two
recordings: 7.1 at 10 bands, 10.8 at 30, about 1.1 at the true 17.5): the parabola through
the three grid points put its vertex back at 10, and the search stopped there. With
``probe`` (the smooth width's search) a golden-section step toward the lower neighbour is
taken instead, and the parabolas from there reached 18.3.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator, Mapping

__all__ = ["MAX_FITS", "TOLERANCE", "refined_shape", "shape_search"]

#: The fits at new shapes at most.
MAX_FITS = 3
#: The search stops where the next shape is within this share of one judged [1].
TOLERANCE = 0.01
_GOLDEN = 0.381966  # (3 - sqrt(5)) / 2


def refined_shape(
    scores: Mapping[float, float],
    start: float,
    judged: Callable[[float], float | None],
    max_fits: int = MAX_FITS,
    probe: bool = False,
) -> tuple[float, ...]:
    """The shapes tried between the grid neighbours of ``start``, in the order tried.

    Parameters
    ----------
    scores : mapping of float to float
        The grid's shapes (Stribeck velocities [rad/s], smooth widths [bands]) and their
        held-out errors [%] (the structure without its coefficients left out, each at
        that shape).
    start : float
        The chosen shape, one of ``scores``.
    judged : callable
        The held-out error [%] of the same structure at a new shape (one fit); None
        where it cannot be judged (the search stops).
    max_fits : int
        Calls of ``judged`` at most.
    probe : bool
        Where the parabola's vertex is a shape judged already, a golden-section step from
        the best shape toward its neighbour of lower error (:func:`_toward_lower`) instead
        of stopping: for an error V-shaped in the shape's logarithm (a smooth Coulomb's
        width), whose parabola through three points puts its vertex back at the best.

    Returns
    -------
    tuple of float
        The shapes ``judged`` was called at, each rounded to three significant digits
        (the name it is written under: ``stribeck:0.0823``, ``smooth:18.4``); empty when
        ``start`` has no grid neighbour or the parabola points at a shape judged already
        (without ``probe``).
    """
    tried: list[float] = []
    search = shape_search(scores, start, max_fits, probe)
    try:
        v = next(search)
        while True:
            tried.append(v)
            v = search.send(judged(v))
    except StopIteration:
        pass
    return tuple(tried)


def shape_search(
    scores: Mapping[float, float],
    start: float,
    max_fits: int = MAX_FITS,
    probe: bool = False,
) -> Generator[float, float | None, None]:
    """:func:`refined_shape`'s search as a generator: it yields each shape to judge and is
    sent its held-out error [%] (None: it cannot be judged, the search stops), so that the
    searches of several joints' shapes advance together, each round's shapes judged in
    one fit (:mod:`~dynid.identification.stribeck_joints`). Parameters as
    :func:`refined_shape`."""
    grid = sorted(scores)
    if start not in scores or len(grid) < 2:
        return
    k = grid.index(start)
    lo, hi = math.log(grid[max(k - 1, 0)]), math.log(grid[min(k + 1, len(grid) - 1)])
    points = {math.log(v): s for v, s in scores.items() if lo <= math.log(v) <= hi}
    for _ in range(max_fits):
        v = _rounded(_next(points))
        x = math.log(v)
        if not lo < x < hi or _near(x, points):  # the parabola ends there
            if not probe:
                return
            v = _rounded(_toward_lower(points))
            x = math.log(v)
            if not lo < x < hi or _near(x, points):
                return
        s = yield v
        if s is None or not math.isfinite(s):
            return
        points[x] = s


def _rounded(x: float) -> float:
    """The shape of logarithm ``x``, rounded to three significant digits."""
    return float(f"{math.exp(x):.3g}")


def _near(x: float, points: Mapping[float, float]) -> bool:
    """Whether the logarithm ``x`` is within :data:`TOLERANCE` of one judged."""
    return min(abs(x - p) for p in points) < TOLERANCE


def _toward_lower(points: Mapping[float, float]) -> float:
    """A golden-section step from the best point toward its neighbour of lower error
    (the only one where there is one): where the parabola points back at a shape judged
    already, its vertex says nothing of a minimum whose sides differ in slope (a
    smooth width's error, V-shaped in its logarithm, was not refined: 10 bands judged
    again for a minimum at 17.5), and the minimum lies toward the lower side."""
    b = min(points, key=lambda x: points[x])
    sides = [
        x
        for x in (
            max((x for x in points if x < b), default=None),
            min((x for x in points if x > b), default=None),
        )
        if x is not None
    ]
    if not sides:
        return b
    side = min(sides, key=lambda x: points[x])
    return b + _GOLDEN * (side - b)


def _next(points: Mapping[float, float]) -> float:
    """The next logarithm of the shape to judge: the vertex of the parabola through the best point
    and its nearest neighbours each side, or a golden-section step into the wider side
    where there is one neighbour or the parabola is not convex."""
    b = min(points, key=lambda x: points[x])
    left = max((x for x in points if x < b), default=None)
    right = min((x for x in points if x > b), default=None)
    if left is not None and right is not None:
        fl, fb, fr = points[left], points[b], points[right]
        num = (b - left) ** 2 * (fb - fr) - (b - right) ** 2 * (fb - fl)
        den = (b - left) * (fb - fr) - (b - right) * (fb - fl)
        if den < 0:  # convex: the vertex lies between the neighbours
            return b - 0.5 * num / den
    far = max((x for x in (left, right) if x is not None), key=lambda x: abs(x - b), default=b)
    return b + _GOLDEN * (far - b)
