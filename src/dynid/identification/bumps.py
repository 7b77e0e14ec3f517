"""The Stribeck bump on the smooth sign, at the width of the smooth law the data choose.

The grid of :func:`~dynid.identification.structure.candidate_structures` pairs the bump
``(fs - fc) tanh(dq / w) exp(-(dq / v_st)^2)`` with one narrow width only
(:data:`~dynid.identification.structure.SMOOTH_STRIBECK_WIDTHS`): the bumps of every
width are one regressor each (alike near rest, they cannot share one), and a regressor
per width would double the search's fits. A friction rounded over many bands (a smooth
Coulomb of 10 bands with a bump: 1.95 % on a new recording of a UR5's point-to-point
moves, the bump at its own width 0.70 %, the noise floor 0.38 %) needs the bump at its
own width. :func:`bump_widths` adds it to the smooth law that predicts held-out data
best, at every Stribeck velocity (the search asks only where that law predicts better
than the laws without a Coulomb term: a bump rides on Coulomb friction). Where the bump
predicts better by more than one standard error (paired over the folds), it walks the
bump's width along the grid of smooth widths each way while the held-out error keeps
falling as much: a smooth law without its bump is fitted at a width rounded to make up
for the bump (3 bands for a bump at 10), so its own width is a start, not the answer.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from .candidates import Candidate

__all__ = ["bump_widths"]


def bump_widths(
    start: Candidate,
    widths: Sequence[float],
    at_width: Callable[[float | tuple[float, ...]], list[Candidate]],
    better: Callable[[Candidate, Candidate], bool],
) -> list[Candidate]:
    """The smooth-sign Stribeck candidates judged from the smooth law ``start``: those
    at its width (one, or one per joint), and, where the best of them predicts held-out
    data better than ``start`` (``better``) and the width is one of ``widths``, those at
    the next widths of ``widths`` each way while their best predicts better than the best
    so far.

    Parameters
    ----------
    start : Candidate
        A smooth Coulomb law without a bump.
    widths : sequence of float
        The grid of smooth widths [bands], ascending.
    at_width : callable
        The smooth-sign Stribeck candidates at a width [bands] (every Stribeck velocity),
        judged on held-out data; empty where the data do not identify them.
    better : callable
        Whether the first candidate predicts held-out data better than the second beyond
        one standard error.

    Returns
    -------
    list of Candidate
        Every candidate judged, in the order judged.
    """
    out = at_width(start.structure.width)
    best = _best(out)
    w = start.structure.width
    if best is None or not better(best, start) or not isinstance(w, float) or w not in widths:
        return out
    here = list(widths).index(w)
    for step in (-1, 1):
        i = here + step
        while 0 <= i < len(widths):
            found = at_width(widths[i])
            out += found
            top = _best(found)
            if top is None or not better(top, best):
                break
            best, i = top, i + step
    return out


def _best(cands: Sequence[Candidate]) -> Candidate | None:
    """The candidate of lowest held-out error not skipped (friction dissipative, no bump
    below zero: :attr:`~.candidates.Candidate.skipped`; None when every one is)."""
    return min((c for c in cands if not c.skipped), key=lambda c: c.score, default=None)
