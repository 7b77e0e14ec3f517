"""The smooth Coulomb's width chosen per joint (motor) on held-out data.

Every smooth candidate of :func:`~dynid.identification.structure.candidate_structures`
gives all joints one width, a factor of each joint's standstill band. Joints differ (a
motor behind a gear rounds its friction over another share of its noise than the next,
a bearing is sharper than a harmonic drive), and one factor for all is a compromise.
The columns of every width of the grid are in one regressor, one column per joint and
width (:func:`~dynid.identification.structure.largest_terms`), so a width per joint is
only another choice of columns: :func:`per_joint_widths` walks over the joints, tries
every width of the regressor for that joint alone, and keeps a change only where the
held-out error falls by more than one standard error of the difference (paired over the
folds, as the structure choice reads it); the joints are walked again while a change
is kept, at most :data:`MAX_SWEEPS` times.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..regressors.terms import PART_LABELS, ModelTerm
from .candidates import Candidate
from .structure import Structure

__all__ = ["MAX_SWEEPS", "per_joint_widths", "regressor_widths"]

#: The walks over the joints at most (each tries every other width on every joint).
MAX_SWEEPS = 2


def regressor_widths(terms: Sequence[tuple[ModelTerm, Any]]) -> tuple[float, ...]:
    """The smooth widths [bands] whose columns a regressor of
    :func:`~dynid.identification.structure.largest_terms` holds, ascending."""
    return tuple(sorted(what[1] for _, what in terms if what is not None and what[0] == "smooth"))


def per_joint_widths(
    start: Candidate,
    widths: Sequence[float],
    n: int,
    judged: Callable[[Structure], Candidate],
    better: Callable[[Candidate, Candidate], bool],
) -> Candidate:
    """From ``start`` (a smooth Coulomb law), each joint's width [bands] in turn set to
    the one of ``widths`` whose candidate (``judged``) predicts held-out data best, where
    ``better`` (that candidate, the one before) says it does; ``start`` itself when no
    change is kept. A joint whose smooth coefficient is left out (``fc3``) keeps its
    width; a candidate whose friction is not dissipative is taken only from one that is
    not either.

    Parameters
    ----------
    start : Candidate
        A candidate holding ``smooth``, its widths among ``widths``.
    widths : sequence of float
        The widths [bands] of the regressor its columns are in (:func:`regressor_widths`).
    n : int
        Joints (motors) of the friction.
    judged : callable
        A structure judged on the held-out folds of that regressor.
    better : callable
        Whether the first candidate predicts held-out data better than the second beyond
        one standard error.

    Returns
    -------
    Candidate
    """
    here = start
    for _ in range(MAX_SWEEPS):
        moved = False
        for j in range(n):
            if f"{PART_LABELS['smooth']}{j + 1}" in here.structure.drop:
                continue
            now = here.structure.widths(n)[j]
            trials = [judged(here.structure.with_width(j, w, n)) for w in widths if w != now]
            trials = [c for c in trials if not c.skipped or here.skipped]
            step = min(trials, key=lambda c: c.score, default=None)
            if step is not None and better(step, here):
                here, moved = step, True
        if not moved:
            break
    return here
