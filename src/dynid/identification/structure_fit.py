"""One structure fitted on prepared recordings: the pieces the structure search's entry
(:mod:`dynid.identification.selection`) and the handling of outlying recordings
(:mod:`dynid.identification.outlying_recordings`) share.

A :class:`~.structure.Structure`'s terms with the recordings' bands (:func:`_terms_of`),
its fit judged on held-out folds (:func:`_fitted`, a rank deficiency with the hint of the
terms that leave the unexcited coefficients out) and the recordings prepared with a
separate validation recording prepared as they are (:func:`_recordings`).
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from typing import Any

from ..exceptions import RankDeficientError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.terms import ModelTerm
from .core import identify
from .estimators import Estimator
from .judge import heldout_judge
from .largest import limits_middle, recording_bands
from .log import TorqueLog
from .model import IdentifiedModel
from .recordings import Recordings, prepare_recordings
from .structure import Structure, structure_terms


def _terms_of(
    structure: Structure,
    drive: Drive | None,
    n: int,
    data: Recordings,
    rest: tuple[float, ...] = (),
) -> tuple[Drive | None, tuple[ModelTerm, ...]]:
    """:func:`~dynid.identification.structure.structure_terms` with the recordings' bands
    (a spring about ``rest`` [rad])."""
    return structure_terms(
        structure, drive, n, tuple(data.band), recording_bands(data), data.band_gain, rest
    )


def _fitted(
    robot: Robot,
    data: Recordings,
    structure: Structure,
    drive: Drive | None,
    folds: int,
    validation: Recordings | None,
    *,
    estimator: Estimator,
    **kw: Any,
) -> tuple[IdentifiedModel, tuple[ModelTerm, ...]]:
    """``structure`` fitted on ``data`` (:func:`~.core.identify` with ``kw``), judged on
    its held-out folds (or ``validation``), and its terms; a rank deficiency with the hint
    of the terms that leave the unexcited coefficients out (:func:`_without_hint`)."""
    model_drive, terms = _terms_of(structure, drive, robot.n, data, limits_middle(robot))
    judge, _, fold_labels = heldout_judge(robot, data, estimator, folds, validation)
    try:
        model = identify(
            robot, data, drive=model_drive, terms=terms, estimator=estimator, judge=judge,
            fold_labels=fold_labels, **kw,
        )  # fmt: skip
    except RankDeficientError as exc:
        raise _without_hint(exc, structure) from exc
    return model, terms


def _without_hint(exc: RankDeficientError, structure: Structure) -> RankDeficientError:
    """``exc`` with a hint naming the terms that leave out the single joints' friction
    coefficients that name the combinations the data do not excite (``-fc3``), when those
    are all it names."""
    fewer = structure.without(exc.redundant)
    if not exc.redundant or len(fewer.drop) - len(structure.drop) < len(set(exc.redundant)):
        return exc
    labels = ", ".join(exc.redundant)
    out = copy.copy(exc)
    # structural: the core's message already says to leave one out; here is how
    how = ": " if exc.structural else f"; or leave {labels} out: "
    out.args = (
        f"{exc.args[0]}{how}--terms {','.join(fewer.terms)} "
        f"(-LABEL leaves out one joint's coefficient)",
        *exc.args[1:],
    )
    return out


def _recordings(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None,
    validate_on: TorqueLog | None,
    drive: Drive | None,
    **kw: Any,
) -> tuple[Recordings, Recordings | None]:
    """The recordings prepared (:func:`~.recordings.prepare_recordings` with ``kw``) and the
    separate recording ``validate_on`` prepared as they are (their cut-off and decimation)."""
    data = prepare_recordings(robot, logs, names, drive=drive, **kw)
    if validate_on is None:
        return data, None
    same = {**kw, "cutoff_hz": data.cutoff_hz, "decimate": data.pieces[0].decimate}
    return data, prepare_recordings(robot, [validate_on], ["validation log"], drive=drive, **same)
