"""A held-out fold's fit without the torque offsets its training rows cannot tell apart.

A joint that turns one way throughout a fold's training rows (one recording of two, its
velocity keeping one sign) has a Coulomb column ``sign(dq_j)`` that is a constant there:
its torque offset's column up to the sign. The fold's least squares
(:meth:`~dynid.identification.holdout.Normals.solve`) cannot determine that direction and
splits the constant between the two coefficients as round-off falls (or by the minimum
norm), which holds for the training rows only: where the held-out recording turns the
joint the other way, the offset's share has the wrong sign. A candidate with offsets
was then judged far worse than the same without (a UR5 whose joint 1 turned one way in
one of two recordings: every ``+ offset`` candidate 25 to 37 % held out, the same
without 1.3 to 1.8 %), and since offsets are judged for every joint at once, a true
1.5 N m offset on joint 2 was left out and went into a link's centre of mass.

The fold has no evidence on that split: whatever it predicts for the joint's reversals
is a convention, not a measurement. :func:`fold_solution` resolves it with the one the
search already applies to the whole data (:mod:`~dynid.identification.one_way_friction`:
the offset left out, the Coulomb coefficient holding both): each combination the fold's
training rows do not excite, read from their normal equations at the fold's own rank
tolerance or the precision they resolve (:func:`resolved`;
:func:`~dynid.identification.solvers.unexcited_combinations`, the column
naming it :func:`~dynid.identification.solvers.unexcited_columns`, an offset in place of
a Coulomb coefficient it holds with it,
:func:`~dynid.identification.one_way_friction.offset_instead`), loses its offset in that
fold's fit. Its prediction is then the candidate's without that joint's offset: the fold
says nothing for or against it, and the other folds (those whose training rows reverse
the joint) and the other joints' offsets judge it. This keeps the candidates whole (an
offset per joint still enters or leaves with the structure) and costs nothing where the
training rows have full rank (the factorisation the fold's solve made is read). Columns
the fold does not excite that are no offsets are solved as before.

Judging offsets joint by joint after the choice instead would leave the fold's verdict on
the whole offset candidates as it was (their errors still those of the arbitrary split,
the table still saying offsets predict 20 times worse) and add a search; the cause is one
fold's undetermined direction, so it is resolved there. Rows that reverse the joint only
briefly (a few samples) do tell the two apart, poorly: their fold is judged as before.

* :data:`FOLD_RTOL`: the folds' default rank tolerance (the labels of offsets and Coulomb
  coefficients: :data:`~dynid.identification.one_way_friction.OFFSET`,
  :data:`~dynid.identification.one_way_friction.COULOMB`);
* :func:`model_labels`, :func:`kept_labels`: the labels of a model's columns (``""`` for
  the links');
* :func:`resolved`: the rank tolerance normal equations resolve;
* :func:`untold_offsets`: the offsets a fold's training rows do not tell apart;
* :func:`fold_solution`: the fold's least squares without them;
* :func:`fold_fits`: every fold's, of a model's columns.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .holdout import HeldOut, Normals
from .model import IdentifiedModel
from .one_way_friction import OFFSET, columns_left_out

__all__ = [
    "FOLD_RTOL",
    "fold_fits",
    "fold_solution",
    "kept_labels",
    "model_labels",
    "resolved",
    "untold_offsets",
]

#: The folds' rank tolerance where none is given (:meth:`Normals.solve`'s default).
FOLD_RTOL = 1e-10


def model_labels(model: IdentifiedModel) -> tuple[str, ...]:
    """The label of each column of ``model``'s fit: ``""`` for the base parameters, then
    its appended terms' (``fv1, fc1, fo1, ...``)."""
    out = [""] * model.base.rank
    for t in model.appended:
        out += t.labels
    return tuple(out)


def resolved(rtol: float, p: int) -> float:
    """The relative singular value below which normal equations of ``p`` columns do not
    resolve a direction from zero: ``rtol``, or ``sqrt(p eps)`` where that is larger (the
    scaled ``G``'s eigenvalues, the singular values squared, carry an error of about ``p
    eps`` times the largest: two columns equal on every row leave one near ``1e-17``, a
    singular value of ``6e-9``, which a rank tolerance of ``1e-10`` reads as kept)."""
    return max(rtol, math.sqrt(p * float(np.finfo(np.float64).eps)))


def untold_offsets(train: Normals, rtol: float, labels: Sequence[str]) -> NDArray[np.intp]:
    """The columns of the torque offsets (:data:`OFFSET`) that the rows of ``train``
    (``labels``: one per column, ``""`` for a column of no offset or friction) do not tell
    apart at the rank tolerance ``rtol`` of their least squares (or what their normal
    equations resolve, :func:`resolved`): each combination they do not excite names a
    column, an offset in place of a Coulomb coefficient it holds with it
    (:func:`~dynid.identification.one_way_friction.columns_left_out`); ascending, empty at
    full rank or without offsets."""
    none = np.zeros(0, dtype=np.intp)
    if len(labels) != train.p or not any(OFFSET.fullmatch(lab) for lab in labels):
        return none
    rank = train.rank(rtol, resolved(rtol, train.p))
    if rank >= train.p:
        return none
    R, scale = train.scaled_root()
    names = tuple(lab or f"column {i}" for i, lab in enumerate(labels))
    named = columns_left_out(R, scale, rank, names)[0]
    found = [i for i, lab in enumerate(names) if lab in named and OFFSET.fullmatch(lab)]
    return np.array(found, dtype=np.intp)


def fold_solution(
    train: Normals, rtol: float = FOLD_RTOL, labels: Sequence[str] = ()
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """A fold's least squares on its training normal equations ``train`` at ``rtol``
    (:meth:`~dynid.identification.holdout.Normals.solve`), the offsets its rows do not
    tell apart (:func:`untold_offsets`; ``labels``: one per column, none: no column left
    out) left out, at zero; and which columns it fitted (p,) (those left out False).
    """
    gone = untold_offsets(train, rtol, labels) if labels else np.zeros(0, dtype=np.intp)
    fitted = np.ones(train.p, dtype=bool)
    if not gone.size:
        return train.solve(rtol), fitted
    fitted[gone] = False
    x = np.zeros(train.p)
    x[fitted] = train.restricted(np.flatnonzero(fitted)).solve(rtol)
    return x, fitted


def fold_fits(
    held: HeldOut, rtol: float, labels: Sequence[str], idx: NDArray[np.intp] | None = None
) -> list[NDArray[np.float64]]:
    """Each fold's least squares on its training rows of ``held`` at ``rtol``, without the
    offsets those rows do not tell apart (:func:`fold_solution`); ``labels``: one per
    column of the model, whose columns ``idx`` ``held`` holds (None: all of them); empty,
    or not as many as the columns: every fold's plain least squares."""
    mine = tuple(labels[i] for i in idx) if labels and idx is not None else tuple(labels)
    mine = mine if len(mine) == held.whole.p else ()
    return [fold_solution(t, rtol, mine)[0] for t in held.train]


def kept_labels(model: IdentifiedModel, idx: NDArray[np.intp]) -> tuple[str, ...]:
    """The labels of ``model``'s columns ``idx`` (:func:`model_labels`); none when the
    model's labels do not match its fit's columns."""
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    labels = model_labels(model)
    return tuple(labels[i] for i in idx) if len(labels) == np.size(fit.kept) else ()
