"""Torque offsets that differ between recordings: found, fitted one per recording, recorded.

Joint torque sensors re-zeroed at each power-up give each recording its own constant
torque offset per joint. One shared offset ``fo`` then leaves each recording's difference
from it in the residual, where the links and friction absorb part of it (a UR3's viscous
``fv5`` 16 % high with offsets 0.1-0.5 N m apart).

The check (:func:`recording_offsets`): the model's columns, with one constant per
recording and joint in place of the shared offsets, fitted by least squares on the
prepared recordings (rows of :meth:`~.recordings.Recordings.blocks`, the low-passed
torques [N m]); each recording's constant against the sample-weighted mean of all of them,
judged against its standard error (the residual's long-run variance, Bartlett weights over
the pieces' HAC window: the filtered residual is serially correlated) and against a
practical size (:data:`NOISE_FRACTION` of the joint's torque noise). Where it fires, the
fit (:func:`identify_with_offsets`) takes one offset per recording and joint: each
recording's torques shifted by its offset's difference from the mean and fitted again,
the structure chosen again on them. By the normal equations this is the least-squares fit
with one offset column per recording and joint (Frisch-Waugh-Lovell), and the shared
offset the model keeps for a new recording is the sample-weighted mean. The held-out
error of a recording left out (fitted on the others) is given twice: with the mean
offset (a new recording's offset is unknown) and with the recording's own.

Direct drives only (torques at the joints); a drive's logs, and recordings whose rows do
not stack in memory, are left as they are.
"""

from __future__ import annotations

import dataclasses
import re
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from .core import model_columns
from .log import TorqueLog
from .log_rows import log_blocks
from .model import IdentifiedModel
from .once_per_run import shared_run
from .recordings import Recordings, prepare_recordings
from .selection import fitted_logs, identify_recordings
from .streaming import streams

#: A recording's offset differs where it lies this many standard errors from the mean.
Z_SCORE = 4.0
#: ... and by more than this share of the joint's torque noise (white-noise std).
NOISE_FRACTION = 0.5
#: ... and by more than this share of the joint's torque RMS (logs without noise).
RMS_FRACTION = 5e-3

#: The joints whose offsets differ most named in the note (the rest in the record).
NAMED = 3

_OFFSET = re.compile(r"fo([0-9]+)")


@dataclasses.dataclass(frozen=True)
class RecordingOffsets:
    """Per recording and joint, the constant torque of a fit with one per recording.

    Attributes
    ----------
    names : tuple of str
        The recordings fitted, in order.
    joints : tuple of int
        The joints (0-based) whose offsets differ between them.
    offsets : ndarray, shape (R, n)
        Each recording's offset [N m] (joint side).
    std : ndarray, shape (R, n)
        The standard error of its difference from the mean [N m].
    mean : ndarray, shape (n,)
        The sample-weighted mean of the offsets [N m]: a new recording's, as the model
        predicts it.
    tolerance : ndarray, shape (n,)
        The practical size a difference must exceed [N m].
    samples : tuple of int
        Samples of each recording fitted (the mean's weights).
    heldout_percent : float
        Relative RMS error [%] of each recording predicted by the fit of the others with
        their mean offset, pooled (low-passed torques).
    own_percent : float
        The same with each recording's own offset (its residual's mean per joint removed).
    """

    names: tuple[str, ...]
    joints: tuple[int, ...]
    offsets: NDArray[np.float64]
    std: NDArray[np.float64]
    mean: NDArray[np.float64]
    tolerance: NDArray[np.float64]
    samples: tuple[int, ...]
    heldout_percent: float
    own_percent: float

    @property
    def differ(self) -> bool:
        """Whether some joint's offsets differ between the recordings."""
        return bool(self.joints)

    def sentence(self, joint_names: Sequence[str]) -> str:
        """One plain line: the :data:`NAMED` joints whose offsets differ most between the
        recordings (their range [N m]; every offset in :meth:`as_dict`), and the held-out
        errors."""
        rng = {j: float(np.ptp(self.offsets[:, j])) for j in self.joints}
        top = sorted(self.joints, key=lambda j: -rng[j])[:NAMED]
        per = ", ".join(
            f"{joint_names[j]} {self.offsets[:, j].min():+.2g} to {self.offsets[:, j].max():+.2g}"
            for j in top
        )
        more = len(self.joints) - len(top)
        return (
            "the torque offsets differ between recordings (sensors re-zeroed at power-up?) on "
            f"{len(self.joints)} joint(s), most on {per} N m"
            + (f" and {more} more joint(s)" if more > 0 else "")
            + " over the recordings; fitted one per recording (metadata.recording_offsets); a "
            "new recording's offset is unknown to the model (held-out error "
            f"{self.heldout_percent:.3g} %; with each held-out recording's own offset "
            f"{self.own_percent:.3g} %)"
        )

    def as_dict(self, joint_names: Sequence[str]) -> dict[str, Any]:
        """The JSON record (``metadata.recording_offsets``), with the summary's ``note``."""
        return {
            "recordings": list(self.names),
            "joints": [joint_names[j] for j in self.joints],
            "offsets": [[float(x) for x in row] for row in self.offsets],
            "std": [[float(x) for x in row] for row in self.std],
            "mean": [float(x) for x in self.mean],
            "tolerance": [float(x) for x in self.tolerance],
            "samples": list(self.samples),
            "heldout_percent": self.heldout_percent,
            "own_offset_percent": self.own_percent,
            "note": self.sentence(joint_names),
        }


@dataclasses.dataclass(frozen=True)
class _Rows:
    """One recording's rows: regressor ``W`` (rows, c), torques ``y`` [N m], the joint of
    each row, and its pieces' row counts and HAC windows."""

    W: NDArray[np.float64]
    y: NDArray[np.float64]
    joint: NDArray[np.intp]
    pieces: tuple[int, ...]
    lag: int


def _rows(
    robot: Robot, model: IdentifiedModel, data: Recordings
) -> tuple[list[_Rows], NDArray[np.intp]] | None:
    """Per recording of ``data``, the rows of ``model``'s kept columns, and each column's
    joint where it is that joint's shared offset ``fo`` (-1 for the others); None when the
    model's columns cannot be rebuilt (a drive, columns that do not match its fit) or
    their rows would not stack in memory (:func:`~.streaming.streams`, with one column per
    recording and joint more)."""
    if model.drive is not None:
        return None
    columns = model_columns(
        robot, data, terms=tuple(t.term for t in model.terms.values()), base=model.base
    )
    fit = model.joint_fit or model.fit
    extra = len(data.names) * data.n
    if len(columns.labels) != len(fit.kept) or streams(data.n_rows, len(fit.kept) + extra):
        return None
    kept = np.asarray(fit.kept, dtype=bool)
    labels = [lab for lab, k in zip(columns.labels, kept, strict=True) if k]
    fo = np.array([int(m[1]) - 1 if (m := _OFFSET.fullmatch(lab)) else -1 for lab in labels])
    parts: list[list[tuple[Any, ...]]] = [[] for _ in data.names]
    for r, p in zip(data.recording, data.pieces, strict=True):
        blocks = list(log_blocks(robot, p.log, columns, **p.filtering))
        W = np.concatenate([b.W[:, kept] for b in blocks])
        y = np.concatenate([b.y for b in blocks])
        g = np.concatenate([np.asarray(b.groups, dtype=np.intp) for b in blocks])
        parts[r].append((W, y, g, p.lag))
    out = [
        _Rows(
            np.concatenate([x[0] for x in ps]),
            np.concatenate([x[1] for x in ps]),
            np.concatenate([x[2] for x in ps]),
            tuple(len(x[1]) for x in ps),
            max(int(x[3]) for x in ps),
        )
        for ps in parts
        if ps
    ]
    return (out, fo) if len(out) == len(data.names) else None


def _design(
    rows: _Rows, r: int, n_rec: int, n: int, W_cols: NDArray[np.bool_], joints: Sequence[int]
) -> NDArray[np.float64]:
    """Recording ``r``'s design: the columns ``W_cols`` of its regressor, then one offset
    column per recording and joint of ``joints`` (ones on this recording's rows of it)."""
    D = np.zeros((len(rows.y), n_rec * len(joints)))
    for k, j in enumerate(joints):
        D[:, r * len(joints) + k] = rows.joint == j
    return np.hstack([rows.W[:, W_cols], D])


def _solve(N: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Least squares from normal equations, columns scaled to unit diagonal; columns with
    no rows (zero diagonal) get 0."""
    d = np.sqrt(np.diag(N))
    live = d > 0
    x = np.zeros(len(b))
    s = d[live]
    Ns = N[np.ix_(live, live)] / np.outer(s, s)
    x[live] = np.linalg.lstsq(Ns, b[live] / s, rcond=1e-12)[0] / s
    return x


def _long_run_se(e: NDArray[np.float64], pieces: Sequence[int], lag: int) -> float:
    """Standard error of the mean of ``e`` (one joint's residual over a recording's pieces,
    in order): Bartlett-weighted autocovariances up to ``lag`` within each piece."""
    m = len(e)
    if m < 2:
        return float("inf")
    c = e - e.mean()
    lrv = 0.0
    at = 0
    for k in pieces:
        x = c[at : at + k]
        at += k
        lrv += float(x @ x)
        for h in range(1, min(lag, k - 1) + 1):
            lrv += 2.0 * (1.0 - h / (lag + 1)) * float(x[h:] @ x[:-h])
    return float(np.sqrt(max(lrv, float(c @ c)) / m**2))


def _with_offsets(
    rows: list[_Rows], fo: NDArray[np.intp], n: int, joints: Sequence[int]
) -> tuple[NDArray[np.float64], NDArray[np.float64], list[NDArray[np.float64]]]:
    """The fit with one offset per recording for ``joints`` (their shared ``fo`` columns
    left out): the offsets (R, len(joints)) [N m], the other coefficients, and each
    recording's residual [N m]."""
    R = len(rows)
    W_cols = ~np.isin(fo, list(joints))
    X = [_design(x, r, R, n, W_cols, joints) for r, x in enumerate(rows)]
    N = np.sum([x.T @ x for x in X], axis=0)
    b = np.sum([x.T @ rw.y for x, rw in zip(X, rows, strict=True)], axis=0)
    theta = _solve(N, b)
    c = int(W_cols.sum())
    res = [rw.y - x @ theta for x, rw in zip(X, rows, strict=True)]
    return theta[c:].reshape(R, len(joints)), theta[:c], res


def _heldout(
    rows: list[_Rows], fo: NDArray[np.intp], n: int, joints: Sequence[int]
) -> tuple[float, float]:
    """Relative RMS error [%] of each recording predicted by the fit (one offset per
    recording for ``joints``) of the others with their sample-weighted mean offset, and
    with its own offset instead (its residual's mean per joint removed), pooled."""
    R = len(rows)
    W_cols = ~np.isin(fo, list(joints))
    X = [_design(x, r, R, n, W_cols, joints) for r, x in enumerate(rows)]
    NN = [x.T @ x for x in X]
    bb = [x.T @ rw.y for x, rw in zip(X, rows, strict=True)]
    c, J = int(W_cols.sum()), len(joints)
    m = np.array([len(x.y) for x in rows], dtype=np.float64)
    e2 = own2 = y2 = 0.0
    for r, rw in enumerate(rows):
        others = [s for s in range(R) if s != r]
        theta = _solve(
            np.sum([NN[s] for s in others], axis=0), np.sum([bb[s] for s in others], axis=0)
        )
        o = theta[c:].reshape(R, J)[others]
        mean = (m[others] @ o) / m[others].sum()
        pred = rw.W[:, W_cols] @ theta[:c]
        for k, j in enumerate(joints):
            pred = pred + np.where(rw.joint == j, mean[k], 0.0)
        e = rw.y - pred
        own = e.copy()
        for j in range(n):
            own[rw.joint == j] -= e[rw.joint == j].mean() if np.any(rw.joint == j) else 0.0
        e2, own2, y2 = e2 + float(e @ e), own2 + float(own @ own), y2 + float(rw.y @ rw.y)
    return 100 * float(np.sqrt(e2 / y2)), 100 * float(np.sqrt(own2 / y2))


def _noise(data: Recordings) -> NDArray[np.float64]:
    """Each joint's torque noise [N m]: the median over the pieces of their white-noise
    std (0 where no piece has one)."""
    got = [p.torque_noise_std for p in data.pieces if p.torque_noise_std is not None]
    return np.median(np.array(got), axis=0) if got else np.zeros(data.n)


def recording_offsets(
    robot: Robot, model: IdentifiedModel, data: Recordings
) -> RecordingOffsets | None:
    """Whether the torque offsets of the recordings ``data`` (those ``model`` was fitted
    on, prepared as it was) differ: module docstring. None for fewer than three
    recordings (a held-out recording needs two to fit on), or where the model's columns
    cannot be rebuilt (a drive)."""
    n = robot.n
    if len(data.names) < 3:
        return None
    got = _rows(robot, model, data)
    if got is None:
        return None
    rows, fo = got
    every = tuple(range(n))
    off, _, res = _with_offsets(rows, fo, n, every)
    m = np.array([len(x.y) // n for x in rows], dtype=np.float64)
    mean = (m @ off) / m.sum()
    se = np.array(
        [
            [_long_run_se(e[x.joint == j], [k // n for k in x.pieces], x.lag) for j in every]
            for x, e in zip(rows, res, strict=True)
        ]
    )
    rms = np.sqrt([np.mean(np.concatenate([x.y[x.joint == j] for x in rows]) ** 2) for j in every])
    tol = np.maximum(NOISE_FRACTION * _noise(data), RMS_FRACTION * rms)
    dev = np.abs(off - mean)
    joints = tuple(
        j for j in every if np.any((dev[:, j] > Z_SCORE * se[:, j]) & (dev[:, j] > tol[j]))
    )
    held, own = _heldout(rows, fo, n, joints) if joints else (float("nan"), float("nan"))
    return RecordingOffsets(
        data.names, joints, off, se, mean, tol, tuple(int(k) for k in m), held, own
    )


def shifted_logs(
    logs: Sequence[TorqueLog], which: Sequence[int], found: RecordingOffsets
) -> list[TorqueLog]:
    """``logs`` with the torques of the recordings ``which`` (the index in ``logs`` of
    each of ``found.names``) less their offset's difference from the mean on the joints
    whose offsets differ [N m]."""
    out = list(logs)
    cols = list(found.joints)
    for r, i in enumerate(which):
        tau = np.array(out[i].tau, dtype=np.float64)
        tau[:, cols] -= found.offsets[r, cols] - found.mean[cols]
        out[i] = dataclasses.replace(out[i], tau=tau)
    return out


def _prepared(
    robot: Robot,
    model: IdentifiedModel,
    logs: Sequence[TorqueLog],
    names: Sequence[str],
    which: Sequence[int],
    kw: dict[str, Any],
) -> Recordings:
    """The recordings ``model`` was fitted on (``which`` of ``logs``, their spans cut out
    as it cut them) prepared as it prepared them: its cut-off, the options ``kw`` of
    :func:`~.selection.identify_recordings` (its warnings said by the fit already)."""
    keys = ("trim_s", "max_gap_s", "decimate", "torque_delay_s")
    prep = {k: kw[k] for k in keys if kw.get(k) is not None}
    cutoff = None if model.info.log is None else model.info.log.cutoff_hz
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare_recordings(
            robot, fitted_logs(model, logs), [names[i] for i in which], cutoff_hz=cutoff, **prep
        )


def _fitted_indices(model: IdentifiedModel, count: int) -> list[int]:
    """The recordings (index into the logs) ``model`` was fitted on."""
    recs = model.info.recordings or ()
    if len(recs) != count:
        return list(range(count))
    return [i for i, r in enumerate(recs) if not r.get("left_out")]


def _recorded(
    model: IdentifiedModel, found: RecordingOffsets, which: Sequence[int]
) -> IdentifiedModel:
    """``model`` with ``found`` in its record: ``metadata.recording_offsets``, each
    fitted recording's ``torque_offset`` per joint [N m], and in ``metadata.selection``
    (``heldout_own_offsets``: those joints) that its held-out errors were read with each
    recording's own offset (the structure chosen on the recordings shifted by theirs)."""
    joints = model.robot.joint_names
    recs = [dict(r) for r in model.info.recordings or ()]
    for r, i in enumerate(which):
        if i < len(recs):
            recs[i]["torque_offset"] = {joints[j]: float(found.offsets[r, j]) for j in found.joints}
    extra = {**model.info.extra, "recording_offsets": found.as_dict(joints)}
    selection = model.info.selection
    if selection is not None:
        selection = {**selection, "heldout_own_offsets": [joints[j] for j in found.joints]}
    info = dataclasses.replace(model.info, extra=extra, recordings=tuple(recs), selection=selection)
    return dataclasses.replace(model, info=info)


@shared_run()  # the recordings prepared again as the fit prepared them: read back
def identify_with_offsets(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None = None,
    *,
    fit: Callable[..., IdentifiedModel] = identify_recordings,
    **kw: Any,
) -> IdentifiedModel:
    """``fit`` (:func:`~.selection.identify_recordings`, ``kw`` as it takes them), with one torque
    offset per recording and joint where the recordings' offsets differ (module
    docstring): the first fit's warnings said only where it is the answer.

    Applies to three or more recordings read at the joints (no ``drive``, no
    ``validate_on``) whose structure holds the offset."""
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        model = fit(robot, logs, names, **kw)
    names = list(names) if names is not None else [f"log{k + 1}" for k in range(len(logs))]
    found, which = None, _fitted_indices(model, len(logs))
    applies = kw.get("drive") is None and kw.get("validate_on") is None
    if applies and len(which) >= 3 and "offset" in model.info.extra.get("terms", ()):
        found = recording_offsets(robot, model, _prepared(robot, model, logs, names, which, kw))
    if found is None or not found.differ:
        for w in said:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return model
    refit = fit(robot, shifted_logs(logs, which, found), names, **kw)
    again_which = _fitted_indices(refit, len(logs))
    if len(again_which) >= 3:
        data = _prepared(robot, refit, logs, names, again_which, kw)
        again = recording_offsets(robot, refit, data)
        if again is not None and again.differ:
            found, which = again, again_which
    return _recorded(refit, found, which)
