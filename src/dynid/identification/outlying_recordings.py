"""Recordings found outlying, and the bursts of one or two: what the fit does with them.

Of three recordings or more, a recording whose held-out error under the structure (chosen
on held-out data, :mod:`dynid.identification.selection`, or given) stands far above the
others' (:data:`~.candidates.OUTLIER_RATIO` x their median, :func:`_odd_under`) holds
torques the model does not (contacts, a payload): it is named in one warning with where
its residual stands off (:func:`_residual_spans`, :mod:`dynid.identification.outlying_spans`)
and, unless kept, left out of the final fit, or those spans cut out of it where they are
short and hold nearly all of it (:func:`_cut_out`, :func:`cut_log`); the recordings are
then prepared again on their own and fitted (:func:`_without_outlying`,
:func:`_fitted_given` for a structure given). Of one or two recordings, where none can be
judged against the others, the short spans that hold the fit's own residual are cut out
the same way (:func:`_burst_cuts`, :mod:`dynid.identification.own_bursts`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from ..exceptions import DynidWarning
from ..model.drive import Drive
from ..model.robot import Robot
from ..progress import stage
from ..regressors.terms import ModelTerm
from .candidates import OUTLIER_RATIO, Selection, cut_record, heldout_of, recording_oddness
from .core import model_columns
from .fold_offsets import FOLD_RTOL, fold_fits, fold_solution, kept_labels
from .holdout import fold_errors_percent
from .input_noise import exact_to_round_off
from .log import TorqueLog, default_max_gap
from .model import IdentifiedModel
from .outlying_spans import (
    Span,
    cut_intervals,
    cut_text,
    outlying_spans,
    spans_text,
    widened_intervals,
    without_intervals,
)
from .own_bursts import own_bursts
from .recordings import Recordings
from .structure import Structure
from .structure_fit import _fitted, _recordings

#: The intervals [s] cut out of a recording (closed, ascending); none: left out whole.
_Cut = tuple[tuple[float, float], ...]


#: The outlying recordings (indices) and the intervals cut out of each (none: left out).
_Gone = dict[int, _Cut]


def _warn_outlying(
    skip: tuple[int, ...],
    per: tuple[tuple[str, float], ...],
    keep: bool | None = None,
    spans: dict[int, str] | None = None,
    given: bool = False,
    cuts: dict[int, _Cut] | None = None,
) -> None:
    """One warning naming the recordings ``skip`` left out of the judgement, their held-out
    errors with the chosen structure (``given``: the structure given) against the others'
    (``per``), where in each the residual stands off (``spans``: its text per recording,
    :func:`_outlying_where`) and what the final fit does with them (``keep``, the spans
    ``cuts`` cut out of some, :func:`_final_said`)."""
    if not skip:
        return
    odd = [per[i] for i in skip]
    rest = [e for i, (_, e) in enumerate(per) if i not in skip]
    others = f"{min(rest):.3g} %" if len(rest) == 1 else f"{min(rest):.3g} to {max(rest):.3g} %"
    errors = ", ".join(f"{e:.3g} %" for _, e in odd)
    where = [f"{per[i][0]}'s at {spans[i]}" for i in skip if spans and spans.get(i)]
    warnings.warn(
        f"{', '.join(n for n, _ in odd)}: held-out error{'s' if len(odd) > 1 else ''} "
        f"{errors} with the {'structure given' if given else 'chosen structure'}, far above "
        f"the other recordings' ({others}; metadata."
        f"{'' if given else 'selection.'}heldout_per_recording): it holds torques the model "
        "does not "
        "(contacts, a payload?)"
        + (
            f"; the residual (predicted by the fit of the others) stands off {'; '.join(where)}"
            if where
            else ""
        )
        + ("" if given else "; the structure is chosen on the other recordings")
        + _final_said(keep, skip, cuts or {}, [n for n, _ in per]),
        DynidWarning,
        stacklevel=caller_level(),
    )


def _final_said(
    keep: bool | None, skip: tuple[int, ...], cuts: dict[int, _Cut], names: Sequence[str]
) -> str:
    """``; `` and what the final fit does with the outlying recordings ``skip`` (of
    ``names``): kept or left out (``keep``, :func:`_final_fit`), or the spans ``cuts`` cut
    out of some (:func:`_cut_said`); empty where ``keep`` is not said."""
    if keep is None:
        return ""
    if keep or not cuts:
        return f"; {_final_fit(keep, len(skip))}"
    said = [_cut_said(cuts[k], names[k]) for k in skip if k in cuts]
    whole = [names[k] for k in skip if k not in cuts]
    if whole:
        said.append(f"the final fit leaves {', '.join(whole)} out (metadata.recordings[].left_out)")
    return "; " + "; ".join(said)


def _cut_said(cut: _Cut, name: str) -> str:
    """What the final fit does with an outlying recording ``name`` whose spans ``cut`` are
    cut out of it."""
    return (
        f"the final fit cuts {cut_text(cut)} out of {name} (those spans and the filter's edge "
        "beside them, the rest in pieces as at a gap) and fits the rest (--keep-outlying, "
        "keep_outlying=True, keeps it whole; metadata.recordings[].cut_out)"
    )


def _spans_said(
    found: dict[int, tuple[Span, ...]], data: Recordings, robot: Robot
) -> dict[int, str]:
    """Each recording's spans ``found`` as :func:`~.outlying_spans.spans_text` says them."""
    return {
        k: spans_text(
            f, robot.joint_names, data.starts[k] if k < len(data.starts) else None, data.names[k]
        )
        for k, f in found.items()
    }


def _cut_out(
    found: dict[int, tuple[Span, ...]], ratios: dict[int, float], data: Recordings
) -> dict[int, _Cut]:
    """The intervals [s] cut out of each outlying recording of ``data`` instead of leaving
    it out (:func:`~.outlying_spans.cut_intervals`): its spans ``found``, widened by the
    filter's edge trimmed at a piece's ends and one decimated step, where the rest of it
    (``ratios``: its held-out error over the others' median) would not be outlying; not
    those whose intervals the preparation would bridge (``data.max_gap_s``)."""
    out = {}
    for k, spans in found.items():
        edge = _cut_edges(data, k)
        if edge is None or not spans:
            continue
        if cut := cut_intervals(spans, ratios.get(k, math.inf), *edge):
            out[k] = cut
    return out


def _cut_edges(data: Recordings, k: int) -> tuple[NDArray[np.float64], float, float] | None:
    """Recording ``k``'s sample times [s] in ``data``, the widening [s] of a span cut out
    of it (the filter's edge trimmed at a piece's ends and one decimated step) and the
    longest gap [s] its preparation bridges (``data.max_gap_s``); None without pieces."""
    mine = [p for p, r in zip(data.pieces, data.recording, strict=True) if r == k]
    if not mine:
        return None
    t = np.concatenate([np.asarray(p.log.t, dtype=np.float64) for p in mine])
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    margin = max(p.trim_s for p in mine) + step
    raw = 1.0 / mine[0].sample_rate_hz
    bridged = default_max_gap(raw) if data.max_gap_s is None else float(data.max_gap_s)
    return t, margin, bridged


def cut_log(log: TorqueLog, cut: _Cut) -> TorqueLog:
    """``log`` without its samples in the intervals ``cut`` [s] (closed): pieces as at a
    gap, each filtered and trimmed at its ends as at one."""
    return log.select(np.flatnonzero(without_intervals(log.t, cut))) if cut else log


def _residual_spans(
    k: int,
    model: IdentifiedModel,
    terms: Sequence[ModelTerm],
    idx: NDArray[np.intp],
    data: Recordings,
    robot: Robot,
    rtol: float,
) -> tuple[Span, ...]:
    """Where recording ``k``'s residual stands off (:func:`~.outlying_spans.outlying_spans`):
    its torques as measured [N m] less the prediction of the columns ``idx`` of ``model``
    (fitted with ``terms`` on ``data``, judged over one fold per recording) fitted on its
    fold's training rows, the other recordings; none where none stands off or its rows do
    not match its samples."""
    held = heldout_of(model).restricted(idx)
    if held.folds != len(data.names):
        return ()
    x = fold_solution(held.train[k], rtol, kept_labels(model, idx))[0]
    columns = model_columns(robot, data, drive=model.drive, terms=tuple(terms), base=model.base)
    labels, _ = data.fold_labels()
    e, o = [], 0
    for blk in data.measured_blocks(robot, columns):
        mine = labels[o : o + blk.y.size] == k
        o += blk.y.size
        if mine.any():
            e.append(blk.y[mine] - blk.W[mine][:, idx] @ x)
    mine_pieces = [p for p, r in zip(data.pieces, data.recording, strict=True) if r == k]
    t = np.concatenate([np.asarray(p.log.t, dtype=np.float64) for p in mine_pieces])
    if o != labels.size or not e or sum(r.size for r in e) != t.size * data.n:
        return ()
    return outlying_spans(t, np.concatenate(e).reshape(t.size, data.n))


def _final_fit(keep: bool, k: int) -> str:
    """What the final fit does with ``k`` outlying recordings: kept (``keep``) or left out."""
    them = "it" if k == 1 else "them"
    if keep:
        return f"the final fit keeps {them} (--keep-outlying, keep_outlying=True)"
    return (
        f"the final fit leaves {them} out too (--keep-outlying, keep_outlying=True, keeps "
        f"{them}; metadata.recordings[].left_out)"
    )


def _per_recording_fitted(
    model: IdentifiedModel, per: tuple[tuple[str, float], ...], gone: _Gone | None = None
) -> tuple[tuple[str, float], ...]:
    """``per`` (each recording's name and held-out error [%]) with the errors of the
    recordings ``model`` was fitted on those over its own folds
    (:func:`~.holdout.fold_errors_percent` of its kept columns, as its pooled held-out
    error); the recordings ``gone`` left out of the fit whole keep theirs (those cut take
    the error of what is left of them), and
    ``per`` is returned as it is where ``model``'s folds are not one per recording."""
    held = model.holdout
    fitted = [k for k in range(len(per)) if (gone or {}).get(k, True)]
    if held is None or held.scheme != "recordings" or held.folds != len(fitted):
        return per
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    kept = np.flatnonzero(fit.kept)
    sub = held.restricted(kept)
    errors = fold_errors_percent(sub, xs=fold_fits(sub, FOLD_RTOL, kept_labels(model, kept)))
    folds = dict(zip(fitted, errors, strict=True))
    return tuple((name, folds.get(k, e)) for k, (name, e) in enumerate(per))


def _burst_cuts(
    robot: Robot,
    model: IdentifiedModel,
    terms: Sequence[ModelTerm],
    data: Recordings,
    logs: Sequence[TorqueLog],
) -> _Gone:
    """The intervals [s] cut out of each recording of ``data`` whose residual under
    ``model`` (fitted with ``terms`` on every recording, of one or two, where no recording
    can be judged against the others; none of three or more) sits in a few short spans
    (:func:`~.own_bursts.own_bursts`), widened as an outlying recording's are
    (:func:`_cut_edges`, :func:`~.outlying_spans.widened_intervals`), said in one warning
    (with the recording, the spans, their joints and peaks); empty where none is so or the
    ``logs`` (those ``data`` holds, as read) are exact to round-off.

    Regression: a 6-DoF arm's one recording with a 20 N m burst on joint 2 for 0.1 s,
    fitted whole: training error 10.97 % for a 1.12 % floor, a clean recording predicted
    at 5.15 % (its floor 1.13 %), the burst named nowhere."""
    if len(data.names) >= 3:
        return {}
    found = own_bursts(robot, model, terms, data, exact_to_round_off(logs))
    cuts: _Gone = {}
    for k, spans in found.items():
        edge = _cut_edges(data, k)
        if edge is not None and (cut := widened_intervals(spans.spans, *edge)):
            cuts[k] = cut
    if cuts:
        said = [
            f"{found[k].sentence(robot.joint_names)}; {_cut_said(c, data.names[k])}"
            for k, c in cuts.items()
        ]
        warnings.warn(
            f"{', '.join(data.names[k] for k in cuts)}: the fit's own residual (in units of "
            f"each joint's noise): {'; '.join(said)}; the structure is chosen and fitted "
            "again on the rest",
            DynidWarning,
            stacklevel=caller_level(),
        )
    return cuts


def _fitted_given(
    robot: Robot,
    logs: Sequence[TorqueLog],
    data: Recordings,
    structure: Structure,
    drive: Drive | None,
    folds: int,
    validation: Recordings | None,
    keep: bool,
    prep: dict[str, Any],
    *,
    judge: bool,
    **kw: Any,
) -> tuple[IdentifiedModel, tuple[ModelTerm, ...], Recordings, _Gone, dict[str, Any]]:
    """``structure`` fitted on ``data`` (:func:`_fitted` with ``kw``) and, given (``judge``:
    not chosen on held-out data, which judged the recordings already) of three
    recordings or more without a separate ``validation``, each recording judged under it
    as the search judges them (:func:`_odd_under`, the fit's own folds: no other
    structure fitted): one outlying is named in a warning with where its residual stands
    off (:func:`_residual_spans`) and, unless ``keep``, those spans cut out of it where
    they are short and hold nearly all of it (:func:`_cut_out`), else it is left out; the
    recordings prepared again on their own and fitted (:func:`_without_outlying`); the
    first fit's warnings said only when it is kept. Returns the model, its terms, the
    recordings it is fitted on, the outlying ones (:data:`_Gone`) and the record of the
    judgement (:func:`_given_record`; empty when not judged).

    Regression: a 6-DoF arm's three recordings, one with a 30 N m burst on joint 2 for
    0.1 s, fitted all three with ``--terms`` (training error 15.4 %, 13.4 % on a fourth
    recording for a 1.01 % floor) where the search left it out."""
    if not judge or validation is not None or len(data.names) < 3:
        with stage("the fit" if judge else "the fit of the structure chosen", rows=data.n_rows):
            model, terms = _fitted(robot, data, structure, drive, folds, validation, **kw)
        return model, terms, data, {}, {}
    with stage("the fit", rows=data.n_rows), warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        model, terms = _fitted(robot, data, structure, drive, folds, None, **kw)
    rtol = 1e-10 if kw.get("rtol") is None else float(kw["rtol"])
    skip, ratios, per = _odd_under(model, data.names, rtol)
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    idx = np.flatnonzero(np.asarray(fit.kept, dtype=bool))
    found = {k: _residual_spans(k, model, terms, idx, data, robot, rtol) for k in skip}
    if not skip or keep:
        for w in said:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        _warn_outlying(skip, per, keep, _spans_said(found, data, robot), given=True)
        return model, terms, data, {}, _given_record(per, skip, {}, data.names)
    gone = {k: () for k in skip} | _cut_out(found, ratios, data)
    model, terms, clean, gone = _without_outlying(
        robot, logs, data.names, structure, drive, folds, prep, gone, **kw
    )  # fmt: skip
    cuts = {k: c for k, c in gone.items() if c}
    _warn_outlying(skip, per, keep, _spans_said(found, data, robot), given=True, cuts=cuts)
    per = _per_recording_fitted(model, per, gone)
    return model, terms, clean, gone, _given_record(per, skip, cuts, data.names)


def _without_outlying(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str],
    structure: Structure,
    drive: Drive | None,
    folds: int,
    prep: dict[str, Any],
    gone: _Gone,
    **kw: Any,
) -> tuple[IdentifiedModel, tuple[ModelTerm, ...], Recordings, _Gone]:
    """``structure`` fitted (:func:`_fitted` with ``kw``) on the recordings ``logs`` (named
    ``names``) but those ``gone`` left out whole, the intervals ``gone`` holds cut out of
    the others (:func:`cut_log`), prepared again on their own (``prep``, as
    :func:`_chosen_without` does; their findings were said with all of them); a recording
    cut that is still outlying in that fit (:func:`_odd_under`) left out whole and the
    rest fitted again. Returns the model, its terms, the recordings fitted and ``gone`` as
    it ended."""
    while True:
        kept = [i for i in range(len(logs)) if gone.get(i, True)]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            clean, _ = _recordings(
                robot, [cut_log(logs[i], gone.get(i, ())) for i in kept],
                [names[i] for i in kept], None, drive, **prep,
            )  # fmt: skip
        with stage("the fit without the outlying recording(s)", rows=clean.n_rows):
            model, terms = _fitted(robot, clean, structure, drive, folds, None, **kw)
        still, _, _ = _odd_under(model, clean.names, kw.get("rtol") or 1e-10)
        bad = [kept[j] for j in still if gone.get(kept[j])]
        if not bad:
            return model, terms, clean, gone
        gone = {**gone, **{k: () for k in bad}}


def _given_record(
    per: tuple[tuple[str, float], ...],
    skip: tuple[int, ...],
    cuts: dict[int, _Cut],
    names: Sequence[str],
) -> dict[str, Any]:
    """The record of the recordings judged under a structure given (``metadata``'s
    ``heldout_per_recording``, ``outlying_recordings``, ``cut_out_spans``, as
    :meth:`~.candidates.Selection.as_dict` writes them): ``per``, the recordings ``skip``
    found outlying and the intervals ``cuts`` cut out of some (indices into ``names``);
    empty without ``per``."""
    if not per:
        return {}
    return {
        "heldout_per_recording": [{"file": f, "heldout_error_percent": e} for f, e in per],
        "outlying_recordings": [names[i] for i in skip],
        "cut_out_spans": cut_record([(names[k], c) for k, c in cuts.items()]),
    }


def _odd_under(
    model: IdentifiedModel, names: Sequence[str], rtol: float
) -> tuple[tuple[int, ...], dict[int, float], tuple[tuple[str, float], ...]]:
    """The recordings (indices into ``names``) outlying under ``model``'s structure, fitted
    with one fold per recording: :func:`~.candidates.recording_oddness` above
    :data:`~.candidates.OUTLIER_RATIO`, at least two others left (of three recordings or
    more), with each one's ratio; and every recording's name and held-out error [%]
    (fitted on the others). None and no errors where its folds are not one per
    recording."""
    held = model.holdout
    if held is None or held.scheme != "recordings" or held.folds != len(names):
        return (), {}, ()
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    kept = np.asarray(fit.kept, dtype=bool)
    idx = np.flatnonzero(kept)
    sub = held.restricted(idx)
    errors = fold_errors_percent(sub, xs=fold_fits(sub, rtol, kept_labels(model, idx)))
    per = tuple(zip(names, errors, strict=True))
    if len(names) < 3:
        return (), {}, per
    scores = recording_oddness(np.ones(kept.size, dtype=bool), model, rtol)
    skip = tuple(i for i, x in enumerate(scores) if x > OUTLIER_RATIO)
    if len(names) - len(skip) < 2:
        return (), {}, per
    return skip, {i: scores[i] for i in skip}, per


def _outlying(data: Recordings, selection: Selection) -> _Gone:
    """The recordings ``selection`` found outlying (indices into ``data.names``), each with
    the intervals cut out of it (none: left out whole)."""
    cut = dict(selection.cut)
    return {i: cut.get(n, ()) for i, n in enumerate(data.names) if n in selection.outlying}
