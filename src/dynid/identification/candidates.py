"""The candidates of the model's structure judged on held-out data, and the recordings
that hold what no candidate models.

A :class:`Candidate` is a structure with its training and held-out errors (every fold's
too); a :class:`Selection` the candidates judged, the one kept and, with several
recordings, the chosen one's held-out error on each. A recording that holds torques no
candidate models (contacts, a payload) spoils the fit of every fold it is trained in, so
that every recording's held-out error rises and the structure collapses to the links;
:func:`recording_oddness` finds it by comparing its held-out error with the others' when
it is left out of their fits too, and :func:`without_recordings` gives the folds without
it.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .dissipation import Violation
from .fold_offsets import fold_fits, fold_solution, model_labels
from .holdout import HeldOut
from .model import IdentifiedModel
from .structural import mixed_sign
from .structure import ERROR_FLOOR_PERCENT, Structure

__all__ = [
    "ADMISSIBLE_STD_PERCENT",
    "DETERMINED_STD_PERCENT",
    "ODD_FLOOR_PERCENT",
    "OUTLIER_RATIO",
    "RELATIVE_TIE",
    "RULE",
    "Candidate",
    "admissible",
    "Selection",
    "candidate_judged",
    "cut_record",
    "heldout_of",
    "loose_pushing",
    "paired_fold_se",
    "paired_se",
    "recording_oddness",
    "relative_stds",
    "std_inflation",
    "within_best",
    "without_recordings",
]


#: A coefficient whose relative standard deviation [%] in the fit that holds it is at most
#: this (``|t| >= 5``) is determined by the data and never left out for predicting no
#: better (:meth:`Candidate.determined`). Of a coefficient whose true value is zero,
#: ``|t|`` reaches 5 with probability 6e-7 when its standard deviation holds (the HAC one
#: of the filtered log's coloured residual, :func:`std_inflation`), and still only 1 % if
#: that were half the true one; a smaller threshold would keep spurious terms where the
#: standard deviation is understated (the classical one, 1.5 to 3 times too small on a
#: low-passed log). A wrist armature that the held-out torques hardly miss (0.05 N m at
#: 8 rad/s^2) but that the fit determines to 3 % is kept: ``M(q)`` of the wrist would be
#: 30 to 70 % too small without it.
DETERMINED_STD_PERCENT = 20.0
#: An armature (a rotor's inertia: at least zero, and on every motor-driven joint) fitted
#: above zero is determined at a relative standard deviation [%] of at most this (``t >=
#: 3``; :func:`admissible`). The sign is a second check a spurious term must pass: of a
#: true zero, a value above zero at 3 standard deviations has probability 1.3e-3
#: (one-sided), and still 7 % if the standard deviation were half the true one, where a
#: term so loose costs ``M(q)`` at most its own small value; leaving a real one out costs
#: all of it. A Kinova Jaco2's wrist armatures (0.03, 0.02, 0.02 kg m^2) fitted at 30 %,
#: 46 % and 23 % were left out at 20 %, the wrist's ``M_jj`` 53 %, 31 % and 76 % low.
#: Friction coefficients stay at :data:`DETERMINED_STD_PERCENT`: a Panda without Coulomb
#: friction (viscous alone, two 4 s recordings) had two of seven Coulomb coefficients
#: fitted above zero at 28 and 31 % (the residual of a low-passed log is coloured and
#: their standard deviations understated), which the sign would have kept. An offset
#: (either sign) or a Stribeck bump has no sign to check either.
ADMISSIBLE_STD_PERCENT = 100.0 / 3.0
#: How the structure is chosen (:func:`paired_se`, :data:`DETERMINED_STD_PERCENT`,
#: :data:`ADMISSIBLE_STD_PERCENT`).
RULE = (
    "simplest within one standard error of the lowest held-out error (each joint in units "
    "of its own noise), paired over the folds; a coefficient determined to 20 % kept (an "
    "armature above zero to 33 %, 3 std); "
    "friction below zero not determined to 20 % left out"
)
#: Held-out errors closer than this fraction of the lowest one count as equal: a model
#: that predicts 1 % better (relative) is not worth a term.
RELATIVE_TIE = 0.01


@dataclass(frozen=True, slots=True)
class Candidate:
    """A structure judged on held-out data.

    Attributes
    ----------
    structure : Structure
    n_params : int
        Parameters fitted (base parameters and terms; columns the data cannot excite not
        counted).
    train_error_percent : float
        Relative error [%] of the fit on all data, on those data.
    heldout_error_percent : float
        Pooled relative error [%] of the folds' fits on their held-out rows.
    heldout_se_percent : float
        Standard error [%] of the held-out error over the folds (0 for one fold).
    se_vs_best_percent : float
        Standard error [%] of its held-out error's difference from the lowest one, paired
        over the folds (:func:`paired_se`); set once every candidate is judged (0 before,
        and for the best).
    fold_errors_percent : tuple of float
        Relative held-out error [%] of every fold judged (each recording left out, when
        the folds are recordings).
    unphysical : tuple of Violation
        Where its friction is not dissipative within the velocity limits.
    left_out : tuple of str
        A per-joint structure's coefficients left out from the candidate its search
        started at, every one (``fv1 .. fv7`` too when the name no longer holds
        ``viscous``).
    whitened_error_percent : float or None
        The held-out error [%] with every joint's torques in units of its own noise
        (:attr:`~.holdout.HeldOut.whitened`): what the choice reads (:attr:`score`); None
        when the noise is not known.
    fold_whitened_percent : tuple of float
        The same per fold.
    negative_bump : tuple of str
        The Stribeck coefficients (``fsp1``) fitted below zero on all data: static friction
        below the Coulomb level, no Stribeck effect but a correction of the sign's shape
        (a smooth Coulomb narrower or wider than the data's); the candidate is skipped, and
        the search falls back to the law without the bump on those joints.
    part_scores : tuple of float
        The whitened held-out error [%] of every contiguous time block of the held-out
        recordings (:attr:`~.holdout.HeldOut.parts`, each predicted by the fit of its fold),
        which :func:`paired_se` pairs; empty: the folds are paired.
    relative_std : tuple of (str, float)
        Each coefficient it holds that a per-joint structure may leave out (``Ia5``,
        ``fv3``) and its relative standard deviation [%] in its fit on all data (as the
        identified model's: HAC, :func:`std_inflation`; ``inf`` at a coefficient of 0).
    loose_pushing : tuple of (str, float, float)
        Its friction coefficients that push the arm by themselves and that the data do
        not determine (:func:`loose_pushing`): each one's label, value in its fit on all
        data and relative standard deviation [%]; the choice leaves them out.
    admissible : tuple of str
        The labels of :attr:`relative_std` whose sign physics fixes and whose fit on all
        data puts them above zero (:func:`admissible`): determined at
        :data:`ADMISSIBLE_STD_PERCENT`.
    """

    structure: Structure
    n_params: int
    train_error_percent: float
    heldout_error_percent: float
    heldout_se_percent: float
    fold_errors_percent: tuple[float, ...] = ()
    se_vs_best_percent: float = 0.0
    unphysical: tuple[Violation, ...] = ()
    left_out: tuple[str, ...] = ()
    whitened_error_percent: float | None = None
    fold_whitened_percent: tuple[float, ...] = ()
    relative_std: tuple[tuple[str, float], ...] = ()
    negative_bump: tuple[str, ...] = ()
    part_scores: tuple[float, ...] = ()
    loose_pushing: tuple[tuple[str, float, float], ...] = ()
    admissible: tuple[str, ...] = ()

    @property
    def skipped(self) -> bool:
        """Whether the choice skips it: friction not dissipative (:attr:`unphysical`) or
        a Stribeck bump below zero (:attr:`negative_bump`)."""
        return bool(self.unphysical or self.negative_bump)

    def determined(self) -> dict[str, float]:
        """The coefficients of :attr:`relative_std` that the data determine (at most
        :data:`DETERMINED_STD_PERCENT`; :data:`ADMISSIBLE_STD_PERCENT` for those of
        :attr:`admissible`) and their relative standard deviations [%]; none when the fit
        is exact (training error at round-off, :data:`~.structure.ERROR_FLOOR_PERCENT`),
        where a standard deviation is round-off too."""
        if self.train_error_percent <= ERROR_FLOOR_PERCENT:
            return {}
        signed = frozenset(self.admissible)
        return {
            lab: r
            for lab, r in self.relative_std
            if r <= (ADMISSIBLE_STD_PERCENT if lab in signed else DETERMINED_STD_PERCENT)
        }

    @property
    def score(self) -> float:
        """What the choice compares: the held-out error of the torques in units of each
        joint's noise when known, else the held-out error [%]."""
        w = self.whitened_error_percent
        return self.heldout_error_percent if w is None else w

    @property
    def fold_scores(self) -> tuple[float, ...]:
        """:attr:`score` per fold."""
        return self.fold_whitened_percent or self.fold_errors_percent

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "name": self.structure.name,
            "terms": list(self.structure.terms),
            "n_params": self.n_params,
            "train_error_percent": self.train_error_percent,
            "heldout_error_percent": self.heldout_error_percent,
            "heldout_se_percent": self.heldout_se_percent,
            "heldout_se_vs_best_percent": self.se_vs_best_percent,
            "heldout_per_fold_percent": list(self.fold_errors_percent),
            "not_dissipative": [str(v) for v in self.unphysical],
            "negative_bump": list(self.negative_bump),
            "left_out": list(self.left_out),
            "heldout_whitened_percent": self.whitened_error_percent,
        }


def paired_se(c: Candidate, best: Candidate) -> float:
    """Standard error [%] of ``c``'s held-out error minus ``best``'s, paired over the
    folds both were judged on.

    Every candidate is judged on the same folds, and the folds differ far more among
    themselves (one recording is harder to predict than another) than two candidates do
    on one fold; the spread of each candidate's fold errors (``heldout_se_percent``) would
    call a consistently worse candidate as good as the best. The one-standard-error rule
    reads the spread of the differences instead. 0 for one fold (the folds of two
    candidates always match: the same held-out data). Of fewer recordings than
    ``--folds``, paired over the contiguous time blocks of each held-out recording
    (:attr:`Candidate.part_scores`): two recordings' folds give the difference's spread
    one degree of freedom, a tie or a gap by the luck of two numbers."""
    if c.part_scores and len(c.part_scores) == len(best.part_scores):
        return paired_fold_se(c.part_scores, best.part_scores)
    return paired_fold_se(c.fold_scores, best.fold_scores)


def within_best(c: Candidate, best: Candidate) -> bool:
    """Whether ``c`` predicts as well as ``best``: its held-out error (:attr:`Candidate.score`)
    above the lowest by at most one standard error of the difference, paired over the
    folds (:func:`paired_se`), or by less than :data:`RELATIVE_TIE` of the lowest (or
    :data:`~.structure.ERROR_FLOOR_PERCENT`)."""
    low = best.score
    tie = max(paired_se(c, best), RELATIVE_TIE * low, ERROR_FLOOR_PERCENT)
    return c.score <= low + tie


def paired_fold_se(a: Sequence[float], b: Sequence[float]) -> float:
    """Standard error [%] of the mean of ``a - b`` over the folds (the fold errors [%] of
    two candidates judged on the same folds, :func:`paired_se`); 0 for fewer than two
    folds or folds that do not match."""
    if len(a) < 2 or len(a) != len(b):
        return 0.0
    d = np.subtract(a, b)
    return float(np.std(d, ddof=1) / math.sqrt(d.size))


@dataclass(frozen=True, slots=True)
class Selection:
    """The candidates judged and the structure kept (module docstring).

    Attributes
    ----------
    candidates : tuple of Candidate
    chosen : Structure
    validation : str
        How the data were held out.
    rule : str
        How the structure was chosen.
    notes : tuple of str
        Candidates that could not be fitted, and why.
    per_recording : tuple of (str, float)
        With several recordings: each recording's name and the chosen structure's
        held-out error [%] on it (fitted on the others).
    outlying : tuple of str
        Recordings whose held-out error is more than :data:`OUTLIER_RATIO` times the
        others' median (the others fitted without it); the structure is judged on the
        other recordings alone (the table's held-out errors), the final fit still uses
        every recording.
    determined : tuple of (str, float)
        The coefficients of the chosen structure whose absence the held-out error would
        not miss (within one standard error of the lowest) but that the data determine
        (:data:`DETERMINED_STD_PERCENT`), kept: each one's label and relative standard
        deviation [%].
    cut : tuple of (str, tuple of (float, float))
        The outlying recordings whose residual stands off in short spans, each with the
        intervals [s] cut out of it for the final fit (the spans with the filter's edge
        beside them) in place of leaving it out whole.
    spring : tuple of (str, Any)
        The spring candidate tried where the chosen structure's held-out residual names a
        joint spring (:mod:`~dynid.identification.spring_candidate`): its joints, the
        structure, its held-out error and whether it was chosen; empty when none was tried.
    differing : tuple of dict
        The recordings, not outlying, whose held-out error over their noise floor stands
        clearly above the others' (:mod:`~dynid.identification.differing_recording`):
        named in a note, fitted still; each one's record.
    """

    candidates: tuple[Candidate, ...]
    chosen: Structure
    validation: str
    rule: str = RULE
    notes: tuple[str, ...] = ()
    per_recording: tuple[tuple[str, float], ...] = ()
    outlying: tuple[str, ...] = ()
    determined: tuple[tuple[str, float], ...] = ()
    cut: tuple[tuple[str, tuple[tuple[float, float], ...]], ...] = ()
    spring: tuple[tuple[str, Any], ...] = ()
    differing: tuple[dict[str, Any], ...] = ()

    def __post_init__(self) -> None:
        # a note reached by two routes (the same regressor group tried for two armature
        # choices) is said once
        object.__setattr__(self, "notes", tuple(dict.fromkeys(self.notes)))

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (``identification.json``'s ``metadata.selection``)."""
        return {
            "rule": self.rule,
            "validation": self.validation,
            "chosen": self.chosen.name,
            "candidates": [c.as_dict() for c in self.candidates],
            "notes": list(self.notes),
            "heldout_per_recording": [
                {"file": f, "heldout_error_percent": e} for f, e in self.per_recording
            ],
            "outlying_recordings": list(self.outlying),
            "kept_determined": [
                {"coefficient": lab, "std_percent": r} for lab, r in self.determined
            ],
            "cut_out_spans": cut_record(self.cut),
            "differing_recordings": list(self.differing),
        } | ({"spring_candidate": dict(self.spring)} if self.spring else {})


def cut_record(
    cut: Sequence[tuple[str, tuple[tuple[float, float], ...]]],
) -> list[dict[str, Any]]:
    """JSON-ready spans cut out of outlying recordings (:attr:`Selection.cut`): per
    recording its ``file`` and ``intervals`` (``[t0, t1]`` [s] each, as the file holds the
    times)."""
    return [{"file": f, "intervals": [[a, b] for a, b in c]} for f, c in cut]


#: A recording whose held-out error exceeds this multiple of the other recordings' median
#: (each fitted without it) is named in a warning and left out of the structure's
#: judgement.
OUTLIER_RATIO = 3.0
#: A recording predicted within this relative error [%] is never odd, whatever the ratio:
#: exact data leave round-off errors (1e-6 %) whose ratios mean nothing, and torques no
#: candidate models large enough to spoil the others' fits (a contact, a payload) are far
#: above it.
ODD_FLOOR_PERCENT = 0.5


def candidate_judged(
    structure: Structure,
    use: NDArray[np.bool_],
    model: IdentifiedModel,
    held: HeldOut,
    rtol: float,
    check: Callable[[NDArray[np.float64], NDArray[np.float64]], tuple[Violation, ...]]
    | None = None,
    labels: Sequence[str] = (),
) -> Candidate:
    """``structure`` (the columns ``use`` of ``model``) judged on the folds ``held``;
    ``check`` (of every column's coefficients fitted on all data and their standard
    deviations, 0 where not used) says where its friction is not dissipative. With
    ``check``, each column's label (``""`` for a column never left out alone,
    :func:`~.structure.column_labels`) gives the coefficients' relative standard
    deviations (:attr:`Candidate.relative_std`). A fold whose training rows do not tell a
    joint's offset from its Coulomb friction fits without that offset
    (:func:`~.fold_offsets.fold_solution`). A coefficient that holds a difference
    of coefficients (``fv6`` holding ``fv6 - fv5``, ``model.info.combined``:
    :func:`~.structural.mixed_sign`) has no sign of its own: 0 in the dissipation
    ``check`` and not among :attr:`Candidate.loose_pushing`."""
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    use = use & np.asarray(fit.kept, dtype=bool)
    idx = np.flatnonzero(use)
    sub = held.restricted(idx)
    xs = fold_fits(sub, rtol, _labels_of(model, labels, use.size), idx)
    per_fold = [t.relative_error_percent(x) for t, x in zip(sub.test, xs, strict=True)]
    se = float(np.std(per_fold, ddof=1) / math.sqrt(len(per_fold))) if len(per_fold) > 1 else 0.0
    white = [t.relative_error_percent(x) for t, x in zip(sub.whitened, xs, strict=True)]
    parts = [t.relative_error_percent(xs[f]) for t, f in zip(sub.parts, sub.part_fold, strict=True)]
    whole, whole_std = sub.whole.solve_with_std(rtol, std=check is not None)
    unphysical: tuple[Violation, ...] = ()
    relative: tuple[tuple[str, float], ...] = ()
    negative: tuple[str, ...] = ()
    loose: tuple[tuple[str, float, float], ...] = ()
    signed: tuple[str, ...] = ()
    if check is not None:
        assert whole_std is not None  # asked for with the check
        x, sd = np.zeros(use.size), np.zeros(use.size)
        x[idx], sd[idx] = whole, whole_std * std_inflation(model, rtol)[idx]
        free = mixed_sign(model.info.combined)
        signed_labels = [lab if lab not in free else "" for lab in labels]
        alone = np.array([lab not in free for lab in labels], bool) if free and labels else None
        unphysical = check(x if alone is None else np.where(alone, x, 0.0), sd)
        relative = relative_stds(x, sd, use, labels)
        negative = negative_bumps(x, use, labels)
        loose = loose_pushing(x, sd, use, signed_labels)
        signed = admissible(x, use, labels)
    return Candidate(
        structure=structure,
        n_params=int(use.sum()),
        train_error_percent=sub.judged_whole.relative_error_percent(whole),
        heldout_error_percent=sub.heldout_error_percent(xs),
        heldout_se_percent=se,
        fold_errors_percent=tuple(per_fold),
        unphysical=unphysical,
        whitened_error_percent=sub.heldout_error_percent(xs, whitened=True) if white else None,
        fold_whitened_percent=tuple(white),
        relative_std=relative,
        negative_bump=negative,
        part_scores=tuple(parts),
        loose_pushing=loose,
        admissible=signed,
    )


def _labels_of(model: IdentifiedModel, labels: Sequence[str], p: int) -> tuple[str, ...]:
    """Each of the ``p`` columns' label: ``labels`` when given, else the model's own
    (:func:`~.fold_offsets.model_labels`); none when they do not match the columns."""
    out = tuple(labels) if labels else model_labels(model)
    return out if len(out) == p else ()


#: A Stribeck coefficient of one joint (motor): ``fsp3``, ``jfsp7``.
_BUMP = re.compile(r"j?fsp[0-9]+")


def negative_bumps(
    x: NDArray[np.float64], use: NDArray[np.bool_], labels: Sequence[str]
) -> tuple[str, ...]:
    """The labels of the Stribeck coefficients ``fsp = fs - fc`` [N m] among the columns
    ``use`` whose value in ``x`` is below zero (static friction below Coulomb)."""
    found = (lab for lab, v, u in zip(labels, x, use, strict=False) if u and v < 0)
    return tuple(dict.fromkeys(lab for lab in found if _BUMP.fullmatch(lab)))


#: A friction coefficient that dissipates by itself only when positive, of one joint
#: (motor): viscous, Coulomb (sharp or smooth) or quadratic, ``fv3``, ``fc3``, ``fq3``,
#: ``jfv7`` at a joint beside the motors.
_DISSIPATING = re.compile(r"j?f[vcq][0-9]+")


def loose_pushing(
    x: NDArray[np.float64], sd: NDArray[np.float64], use: NDArray[np.bool_], labels: Sequence[str]
) -> tuple[tuple[str, float, float], ...]:
    """The friction coefficients among the columns ``use`` (``labels``: one per column)
    that push the arm by themselves and that the data do not determine: viscous, Coulomb
    or quadratic (``fv3``, ``fc3``, ``fq3``) below zero in ``x`` on every column of theirs
    in use, none of them determined (relative standard deviation ``sd / |x|`` above
    :data:`DETERMINED_STD_PERCENT`). Each one's label, value (of its first column in use)
    and smallest relative standard deviation [%], in column order."""
    seen: dict[str, list[tuple[float, float]]] = {}
    for lab, on, xi, si in zip(labels, use, x, sd, strict=bool(labels)):
        if lab and on and _DISSIPATING.fullmatch(lab):
            r = 100.0 * float(si) / abs(float(xi)) if xi else math.inf
            seen.setdefault(lab, []).append((float(xi), r))
    return tuple(
        (lab, got[0][0], min(r for _, r in got))
        for lab, got in seen.items()
        if all(v < 0 for v, _ in got) and min(r for _, r in got) > DETERMINED_STD_PERCENT
    )


#: A coefficient whose sign physics fixes, at least zero: a rotor's inertia (``Ia3``) or a
#: dissipating friction coefficient (:data:`_DISSIPATING`).
_SIGNED = re.compile(r"Ia[0-9]+")


def admissible(
    x: NDArray[np.float64], use: NDArray[np.bool_], labels: Sequence[str]
) -> tuple[str, ...]:
    """The labels among the columns ``use`` (``labels``: one per column, ``""`` for none)
    of an armature (``Ia3`` [kg m^2]: a rotor's inertia, at least zero) whose value in
    ``x`` is above zero on every column of theirs in use; friction coefficients are not
    among them (:data:`ADMISSIBLE_STD_PERCENT`)."""
    seen: dict[str, bool] = {}
    for lab, on, xi in zip(labels, use, x, strict=bool(labels)):
        if lab and on and _SIGNED.fullmatch(lab):
            seen[lab] = seen.get(lab, True) and float(xi) > 0.0
    return tuple(lab for lab, ok in seen.items() if ok)


def relative_stds(
    x: NDArray[np.float64], sd: NDArray[np.float64], use: NDArray[np.bool_], labels: Sequence[str]
) -> tuple[tuple[str, float], ...]:
    """Each label of ``labels`` (one per column, ``""`` for none) on a column of ``use``
    and the smallest relative standard deviation [%] ``sd / |x|`` of its columns in use
    (``inf`` where ``x`` is 0)."""
    out: dict[str, float] = {}
    for lab, on, xi, si in zip(labels, use, x, sd, strict=bool(labels)):
        if lab and on:
            r = 100.0 * float(si) / abs(float(xi)) if xi else math.inf
            out[lab] = min(r, out.get(lab, math.inf))
    return tuple(out.items())


@functools.lru_cache(maxsize=8)  # one per largest model: every candidate of it reads it
def std_inflation(model: IdentifiedModel, rtol: float) -> NDArray[np.float64]:
    """Per column of ``model`` (c,): its reported standard deviation over the classical one
    from the normal equations of all its rows (its held-out folds' ``whole``; 1 where
    either is 0 or the column is not kept). A candidate's standard deviations come from
    the normal equations (``sigma^2 G^-1``, which take the residual as white); times these
    they hold for the residual as the model's own do (``std="hac"``: a filtered log's residual is
    correlated over several samples, about 2 times the classical on a 2R arm)."""
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    kept = np.flatnonzero(np.asarray(fit.kept, dtype=bool))
    out = np.ones(np.size(fit.kept))
    whole = heldout_of(model).whole.restricted(kept)
    classical = whole.std(whole.solve(rtol), rtol)
    reported = np.asarray(fit.std, dtype=np.float64)[kept]
    ok = (classical > 0) & (reported > 0)
    out[kept[ok]] = reported[ok] / classical[ok]
    out.flags.writeable = False  # shared by the candidates of the model
    return out


def heldout_of(model: IdentifiedModel) -> HeldOut:
    """The held-out folds of a candidates' model (fitted with a judge)."""
    assert model.holdout is not None  # models of the candidates are judged on held-out data
    return model.holdout


def without_recordings(model: IdentifiedModel, skip: tuple[int, ...]) -> HeldOut:
    """The held-out folds of ``model`` with the recordings ``skip`` left out of every fit
    and every judgement."""
    held = heldout_of(model)
    kept = [t for j, t in enumerate(held.test) if j not in skip]
    white = tuple(t for j, t in enumerate(held.whitened) if j not in skip)
    out = replace(HeldOut.k_fold(kept), scheme=held.scheme, noise=held.noise, whitened=white)
    return out.with_parts(*held.without_folds(skip)) if held.parts else out


def recording_oddness(use: NDArray[np.bool_], model: IdentifiedModel, rtol: float) -> list[float]:
    """Per recording (fold): its held-out error over the median held-out error of the
    other recordings when it is left out of their fits too (about 1 for recordings
    alike; large for one holding torques no candidate models, which also spoils the
    others' fits while it is among them); 0 for a recording whose held-out error is below
    :data:`ODD_FLOOR_PERCENT` (never odd)."""
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    idx = np.flatnonzero(use & np.asarray(fit.kept, dtype=bool))
    held = heldout_of(model).restricted(idx)
    labels = _labels_of(model, (), use.size)
    mine = tuple(labels[i] for i in idx) if labels else ()
    tests = held.test
    out = []
    for r, (train, test) in enumerate(zip(held.train, tests, strict=True)):
        rest = HeldOut.k_fold([t for j, t in enumerate(tests) if j != r])
        others = [
            t.relative_error_percent(x)
            for x, t in zip(fold_fits(rest, rtol, mine), rest.test, strict=True)
        ]
        med = float(np.median(others))
        e = test.relative_error_percent(fold_solution(train, rtol, mine)[0])
        if e < ODD_FLOOR_PERCENT:
            out.append(0.0)
            continue
        out.append(e / med if med > 0 else (math.inf if e > 0 else 1.0))
    return out
