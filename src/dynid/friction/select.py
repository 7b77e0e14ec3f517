"""Choosing a friction law on held-out data: block cross-validation over the registry.

Fitted to the log it is judged on, a law with more parameters always looks better, and a
law can fit the identification log well and predict worse than the friction the model
already has. The selection therefore judges each candidate on samples it was not fitted
to:

1. The prepared log (:func:`~dynid.friction.fit.friction_residual`) is split into
   :data:`FOLDS` contiguous blocks of equal length (contiguous, not shuffled: neighbouring
   samples of a filtered log are correlated, and a shuffled split would leak them), the
   blocks of the identification's own held-out judgement
   (:func:`~dynid.identification.holdout.block_labels`); the residual of several
   recordings (:func:`~dynid.friction.recordings.pieces_residual`) is split by recording
   instead, one recording left out at a time, as identification does.
2. For each block, every candidate law is fitted (:func:`~dynid.friction.fit.fit_law_through`,
   so a drive's motors are fitted where its friction acts) on the other blocks and predicts
   the held-out block.
3. The held-out error of a candidate is the relative error
   ``100 ||tau - tau_model - tau_f||_F / ||tau||_F`` [%] over all held-out predictions
   (each sample is held out once; :func:`~dynid.identification.metrics.relative_error_percent`);
   the training error is that of the law fitted on the whole log, on the whole log.
4. The candidates are compared, as identification's structure selection compares its
   candidates (:mod:`dynid.identification.selection`), on the held-out error with each
   joint in units of its own torque noise (a wrist whose noise is a fortieth of the
   shoulder's is not lost in the pooled error: a coupled wrist's bearing friction missed
   by every law at the motors cost 3.12 % against 3.14 % pooled, 6 times the wrist's noise
   in validation), and the **simplest candidate within one standard error of the lowest**
   is kept (the fewest coefficients per joint; the standard error that of the difference
   of the two candidates' fold errors, :func:`~dynid.identification.candidates.paired_fold_se`,
   differences under :data:`~dynid.identification.candidates.RELATIVE_TIE` of the lowest
   counting as ties), fitted on the whole log. A Stribeck bump that predicts 0.005 points
   better than the classical law is not worth its two coefficients.
5. A law whose fit on the whole log is not dissipative within the robot's velocity limits,
   its offset aside (``f(v) v < 0`` somewhere beyond
   :data:`~dynid.friction.dissipative.ALLOWANCE_STD` standard deviations of the fit:
   friction that pushes the arm, :func:`~dynid.friction.dissipative.law_violations`, the
   check identification's structure selection applies to its candidates), is set aside:
   judged and shown, not chosen (an asymmetric law with ``fc+ = 7.86``, ``fc- = -13.8`` on
   a UR5 elbow, an offset and a Coulomb level of -2.97 N m, was kept without a word). When
   every candidate is, the choice is made among them with a warning naming where each
   pushes. The model's own friction is not judged here (identification judged it; a robot's
   is its description's).

The candidates are the laws of the registry (``none``: no extra friction, the rigid model
alone) and, when the model comes with friction of its own (an identification's classical
friction, a robot's published sigmoid; :func:`~dynid.friction.validation.own_friction`), that
friction (``own``, kept as it is when chosen). Every candidate is judged on held-out data:
``own`` predicts the log as it is when the log is new to the model, and, when the model was
identified from this very log (``own_fitted_here``), by its own law refitted on the other
blocks as the others are (its band, a smooth law's width, and the coefficients it holds:
the law it was trained with), a tie going to the registry's laws refitted on the whole log
(judged on the samples its values were fitted to, the model's friction would always win).

A model with friction at its motors and at its joints (a coupled drive's ``at:both``:
:class:`~dynid.friction.model.FrictionSum`) has no one law of the registry to refit; its
parts, linear in their coefficients, are refitted together on the other blocks (the
coefficients the model holds, the others left at 0: the same structure). Kept, it is kept
as it is, both parts (``friction.json`` holds a sum part by part).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import caller_level
from ..exceptions import DataError, DynidWarning, OptionError
from ..identification.candidates import RELATIVE_TIE, paired_fold_se
from ..identification.dissipation import Violation
from ..identification.holdout import DEFAULT_FOLDS, block_labels
from ..identification.input_noise import quantized_noise_std
from ..identification.structure import smooth_width_grid
from ..identification.verdict import NOISE_FLOOR_SHARE
from ..model.drive import Drive
from .dissipative import law_violations
from .fit import FrictionFit, FrictionResidual, fit_friction_through, fit_law_through
from .laws import LAWS
from .laws.base import _LinearFit, bounded_lstsq
from .model import FrictionModel, FrictionSum, friction_parts

__all__ = [
    "ERROR_FLOOR_PERCENT",
    "FOLDS",
    "OWN",
    "RULE",
    "CandidateScore",
    "FrictionSelection",
    "WIDTH_LAWS",
    "choose_smooth_width",
    "held_names",
    "select_friction",
    "simplest_within",
    "torque_noise_std",
]

#: Number of contiguous blocks of the cross-validation (the identification's default).
FOLDS = DEFAULT_FOLDS
#: Held-out errors [%] closer than this count as equal: the laws' folds are judged through
#: normal equations without the fit's coefficients as their origin, whose round-off on
#: exact data is near 1e-6 %.
ERROR_FLOOR_PERCENT = 1e-4
#: Laws whose band is a width chosen on held-out data among
#: :func:`~dynid.identification.structure.smooth_width_grid`, the grid ``identify``
#: searches for the same law (the smooth Coulomb ``tanh(dq / w)``).
WIDTH_LAWS = ("smooth",)
#: Name of the candidate "the model's own friction, as it is".
OWN = "own"
#: How the kept candidate is chosen (module docstring, step 4).
RULE = (
    "the simplest within one standard error of the lowest held-out error, each joint in "
    "units of its own torque noise"
)


@dataclass(frozen=True, slots=True)
class CandidateScore:
    """One candidate of the selection.

    Attributes
    ----------
    name : str
        A law of the registry, or ``"own"``.
    params : tuple of str
        Its parameter names per joint.
    train_error_percent : float
        Relative error [%] of the law fitted on the whole log, on the whole log.
    heldout_error_percent : float
        Relative error [%] on the held-out blocks, each predicted by the law fitted on the
        other blocks (module docstring).
    scaled_error_percent : float
        The held-out error [%] with each joint in units of its own torque noise: what the
        choice reads (module docstring); the held-out error when the noise is not known.
    fold_scaled_percent : tuple of float
        :attr:`scaled_error_percent` per fold.
    n_params : int
        Coefficients per joint (the model's own: those it holds, nonzero on some joint).
    unphysical : tuple of Violation
        Where the law fitted on the whole log is not dissipative within the velocity
        limits, its offset aside (:func:`~dynid.friction.dissipative.law_violations`):
        such a candidate is set aside (module docstring); empty for the model's own.
    """

    name: str
    params: tuple[str, ...]
    train_error_percent: float
    heldout_error_percent: float
    scaled_error_percent: float = float("nan")
    fold_scaled_percent: tuple[float, ...] = ()
    n_params: int = 0
    unphysical: tuple[Violation, ...] = ()


@dataclass(frozen=True, slots=True, eq=False)
class FrictionSelection:
    """Result of :func:`select_friction`.

    Attributes
    ----------
    fit : FrictionFit
        The kept candidate, fitted on the whole log (``own``: the model's friction).
    chosen : str
        Its name.
    scores : tuple of CandidateScore
        Every candidate, in registry order (``own`` first when present; last when the
        model was identified from this log).
    folds : int
        Number of blocks (recordings when one is left out at a time).
    method : str
        How the held-out blocks were made.
    own_kind : str or None
        The law of the model's own friction (``"classical"``), when it is a candidate:
        the ``own`` candidate is shown by it (:meth:`label`), as validate and the
        figure name it.
    at_motors : bool
        The registry's laws were fitted at the motors of a drive (its friction acts
        there: :func:`~dynid.friction.fit.fit_friction_through`), not at the joints.
    """

    fit: FrictionFit
    chosen: str
    scores: tuple[CandidateScore, ...]
    folds: int
    method: str = "contiguous-block cross-validation"
    rule: str = RULE
    own_kind: str | None = None
    at_motors: bool = False

    def label(self, name: str) -> str:
        """A candidate's name as shown: ``own (classical)`` for the model's own friction
        (its law named, as validate names it), else the law's name."""
        return f"{name} ({self.own_kind})" if name == OWN and self.own_kind else name

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: ``method``, ``folds``, ``rule``, ``chosen`` and one row per candidate
        (``model``, ``parameters``, ``n_params``, ``train_error_percent``,
        ``heldout_error_percent``, ``heldout_scaled_percent``,
        ``heldout_scaled_per_fold_percent``, ``not_dissipative``: one line per joint where
        its friction pushes the arm, empty when it does not) and ``set_aside``: the
        candidates not chosen for that."""
        return {
            "method": self.method,
            "folds": self.folds,
            "rule": self.rule,
            "chosen": self.chosen,
            "set_aside": [s.name for s in self.scores if s.unphysical],
            "candidates": [
                {
                    "model": s.name,
                    "parameters": list(s.params),
                    "n_params": s.n_params,
                    "train_error_percent": s.train_error_percent,
                    "heldout_error_percent": s.heldout_error_percent,
                    "heldout_scaled_percent": s.scaled_error_percent,
                    "heldout_scaled_per_fold_percent": list(s.fold_scaled_percent),
                    "not_dissipative": [str(v) for v in s.unphysical],
                }
                for s in self.scores
            ],
            "laws_at": "motors" if self.at_motors else "joints",
        }

    def table(self) -> str:
        """The candidates as a text table, the kept one marked with ``*``, those set aside
        (not dissipative) with ``x`` and a line each saying where, and the rule (with where
        the laws act, where that is a drive's motors)."""
        w = max([12, *(len(self.label(s.name)) for s in self.scores)])
        p = max([10, *(len(", ".join(s.params)) for s in self.scores)])
        rows = [
            f"  {'friction law':<{w}} {'parameters':<{p}} {'train [%]':>10} "
            f"{'held-out [%]':>13} {'by noise [%]':>13}"
        ]
        for s in self.scores:
            mark = "*" if s.name == self.chosen else ("x" if s.unphysical else " ")
            rows.append(
                f"{mark} {self.label(s.name):<{w}} {', '.join(s.params) or '-':<{p}} "
                f"{s.train_error_percent:>10.3f} {s.heldout_error_percent:>13.3f} "
                f"{s.scaled_error_percent:>13.3f}"
            )
        rows.append(
            f"kept (*): {self.rule} (by noise); {self.method}, the rigid-body model as "
            "given (not refitted per fold)"
            + (
                "; the laws fitted at the drive's motors (where its friction acts)"
                if self.at_motors
                else ""
            )
        )
        for s in self.scores:
            if s.unphysical:
                flipped = [f"tau{v.joint + 1}" for v in s.unphysical if v.everywhere]
                rows.append(
                    f"set aside (x): {self.label(s.name)}, not dissipative within the velocity "
                    f"limits (the offset aside): {'; '.join(map(str, s.unphysical))}"
                    + (
                        f" (pushing at every speed, as a torque of the opposite sign does: "
                        f"check the sign of {', '.join(flipped)})"
                        if flipped
                        else ""
                    )
                )
        return "\n".join(rows)


def _heldout_torques(
    res: FrictionResidual,
    drive: Drive | None,
    name: str,
    labels: NDArray[np.intp],
    width: float | None = None,
) -> NDArray[np.float64]:
    """Each block's friction torques (N, n) predicted by ``name`` fitted on the others; a
    block whose training blocks move no joint gets zero."""
    out = np.zeros(res.dq.shape)
    for k in range(int(labels.max()) + 1):
        b = labels == k
        keep = ~b
        noise = res.dq_noise_std
        try:
            fit = fit_law_through(
                name,
                res.dq[keep],
                res.residual[keep],
                drive,
                dq_noise_std=noise,
                warn=False,
                width=width,
            )
        except DataError:
            continue
        out[b] = fit.friction.torques(res.dq[b])
    return out


def select_friction(
    res: FrictionResidual,
    drive: Drive | None = None,
    *,
    candidates: Sequence[str] | None = None,
    own: FrictionModel | FrictionSum | None = None,
    own_fitted_here: bool = False,
    folds: int = FOLDS,
    dq_max: ArrayLike | None = None,
) -> FrictionSelection:
    """Fit the candidate laws and keep the simplest that predicts held-out data as well as
    the best (module docstring, step 4).

    Parameters
    ----------
    res : FrictionResidual
        The prepared log and the rigid-body model's residual
        (:func:`~dynid.friction.fit.friction_residual`).
    drive : Drive, optional
        The drive whose motors the friction acts at (:func:`~dynid.friction.fit.fit_law_through`).
    candidates : sequence of str, optional
        Laws of the registry to compare (default: those of :data:`~dynid.friction.laws.LAWS`
        it compares, :attr:`~dynid.friction.laws.base.FrictionLaw.compared`).
    own : FrictionModel or FrictionSum, optional
        The model's own friction, a candidate as it is (``"own"``); a sum is refitted
        part by part together (module docstring).
    own_fitted_here : bool
        The model's friction was identified from this log: it is judged by its law
        refitted on the other blocks (module docstring).
    folds : int
        Number of contiguous blocks (>= 2); not used when ``res`` holds several
        recordings (one is left out at a time).
    dq_max : array_like, shape (n,), optional
        Joint velocity limits [rad/s]: a law whose fit on the whole log is not
        dissipative within them (:func:`~dynid.friction.dissipative.law_violations`) is
        set aside (module docstring); None: no check.

    Returns
    -------
    FrictionSelection

    Raises
    ------
    OptionError
        ``folds < 2``, fewer than 10 samples per block, or an unknown candidate.
    DataError
        No joint moves beyond its velocity noise band.

    Warns
    -----
    DynidWarning
        Joints that never move (their friction is zero); every candidate set aside (the
        choice made among them, their joints and coefficients named).
    """
    compared = [name for name, law in LAWS.items() if law.compared]
    if own_fitted_here and isinstance(own, FrictionModel) and own.kind in LAWS:
        compared = [*dict.fromkeys(compared + [own.kind])]  # the own law, refitted as the rest
    names = compared if candidates is None else list(candidates)
    unknown = [c for c in names if c not in LAWS]
    if unknown:
        raise OptionError(f"--friction-model must be one of {', '.join(LAWS)}; got {unknown[0]!r}")
    labels, folds, method = _folds(res, folds)
    judge = _Judge(res, labels)
    fits: dict[str, FrictionFit] = {}
    scores: list[CandidateScore] = []
    own_score: CandidateScore | None = None
    last = False  # the own friction judged by a refit goes last
    if own is not None:
        tf = own.torques(res.dq)
        fits[OWN] = _own_fit(own, res)
        last = own_fitted_here  # judged by its own structure refitted on the other blocks
        held = _heldout_own(res, own, labels) if last else tf
        own_score = judge.score(OWN, held_names(own), _held_count(own), tf, held)
        if not last:  # new data to the model: its prediction is held out as it is
            scores.append(own_score)
    for name in names:
        width: float | None = None
        reused: NDArray[np.float64] | None = None
        if name in WIDTH_LAWS:  # the width's held-out torques, reused by the law judged
            width, best = _best_width(res, drive, labels, judge)
            reused = best if name == WIDTH_LAWS[0] else None
        with warnings.catch_warnings():
            if name != names[-1]:  # one warning about still joints is enough
                warnings.simplefilter("ignore", DynidWarning)
            fits[name] = fit_friction_through(res, drive, name, width=width)
        train = fits[name].friction.torques(res.dq)
        held = _heldout_torques(res, drive, name, labels, width) if reused is None else reused
        bad = (
            ()
            if dq_max is None
            else law_violations(fits[name].friction, dq_max, fits[name].covariance)
        )
        score = judge.score(name, LAWS[name].params, len(LAWS[name].params), train, held)
        scores.append(replace(score, unphysical=bad))
    if own_score is not None and last:
        scores.append(own_score)
    kept = simplest_within(_dissipative(scores), prefer=OWN if own is not None else None)
    own_kind = fits[OWN].kind if OWN in fits else None
    at_motors = drive is not None and drive.friction_place == "motor"
    return FrictionSelection(
        fits[kept.name],
        kept.name,
        tuple(scores),
        folds,
        method,
        own_kind=own_kind,
        at_motors=at_motors,
    )


def choose_smooth_width(
    res: FrictionResidual, drive: Drive | None = None, *, folds: int = FOLDS
) -> float:
    """The smooth Coulomb's width [standstill bands] that predicts held-out data best.

    Each factor of :func:`~dynid.identification.structure.smooth_width_grid` (the grid
    ``identify`` searches for the same law) is fitted on the training blocks and judged on
    the held-out ones as :func:`select_friction` judges laws (each joint in units of its
    torque noise); of as many coefficients, the lowest error is kept (the narrower on a
    tie), as ``identify`` keeps among its widths.

    Parameters
    ----------
    res : FrictionResidual
    drive : Drive, optional
        Where the friction acts (:func:`~dynid.friction.fit.fit_law_through`).
    folds : int
        Contiguous blocks (>= 2; a residual of several recordings leaves one out at a time).

    Returns
    -------
    float
        The factor, for :func:`~dynid.friction.fit.fit_law`'s ``width``.

    Raises
    ------
    OptionError
        ``folds < 2`` or fewer than 10 samples per block.
    """
    labels, _, _ = _folds(res, folds)
    return _best_width(res, drive, labels, _Judge(res, labels))[0]


def _best_width(
    res: FrictionResidual, drive: Drive | None, labels: NDArray[np.intp], judge: _Judge
) -> tuple[float, NDArray[np.float64]]:
    """:func:`choose_smooth_width` on the blocks ``labels``, and the held-out torques (N, n)
    [N m] of that factor (:func:`_heldout_torques`: the law's score reuses them)."""
    n = res.dq.shape[1]
    best: tuple[float, float, NDArray[np.float64]] | None = None
    for factor, _ in smooth_width_grid([0.0] * n):
        held = _heldout_torques(res, drive, WIDTH_LAWS[0], labels, factor)
        score = judge.score(WIDTH_LAWS[0], (), 0, held, held).scaled_error_percent
        if best is None or score < best[1]:
            best = (factor, score, held)
    assert best is not None  # (the grid is not empty)
    return best[0], best[2]


def _dissipative(scores: Sequence[CandidateScore]) -> list[CandidateScore]:
    """The candidates whose friction dissipates (all of them, with a warning naming
    where each pushes the arm, when none does), as identification's structure selection
    skips a candidate whose friction is not dissipative."""
    kept = [s for s in scores if not s.unphysical]
    if kept:
        return kept
    where = "; ".join(f"{s.name}: {', '.join(map(str, s.unphysical))}" for s in scores)
    warnings.warn(
        f"every friction law compared is not dissipative within the velocity limits (the "
        f"offset aside), so the one kept pushes the arm somewhere: {where}; hint: check the "
        "torque sign of those joints (--units tauJ=-1) and the model's terms",
        DynidWarning,
        stacklevel=caller_level(),
    )
    return list(scores)


def simplest_within(scores: Sequence[CandidateScore], prefer: str | None = None) -> CandidateScore:
    """The candidate with the fewest coefficients per joint among those whose held-out
    error in noise units is within one standard error of the lowest (paired over the
    folds, :func:`~dynid.identification.candidates.paired_fold_se`; differences under
    :data:`~dynid.identification.candidates.RELATIVE_TIE` of the lowest are ties); of as
    many coefficients, the lower error, then the earlier. The candidate named ``prefer``
    (the model's own friction, identified with its links) is kept when it is within (or
    ties with the one kept) and has no more coefficients than that one: a law refitted to
    tie with it is no reason to replace it (a 5-joint arm's own smooth law, 1.7 rad/s
    wide, gave way to a refitted one 0.023 rad/s wide at the same error, and new data
    were predicted worse)."""
    best = min(scores, key=lambda s: s.scaled_error_percent)
    low = best.scaled_error_percent

    def within(s: CandidateScore) -> bool:
        se = paired_fold_se(s.fold_scaled_percent, best.fold_scaled_percent)
        return s.scaled_error_percent <= low + max(se, RELATIVE_TIE * low, ERROR_FLOOR_PERCENT)

    near = [s for s in scores if within(s)]
    kept = min(near, key=lambda s: (s.n_params, s.scaled_error_percent))
    tied = kept.scaled_error_percent * (1.0 + RELATIVE_TIE)
    mine = [
        s
        for s in scores
        if s.name == prefer
        and s.n_params <= kept.n_params
        and (within(s) or s.scaled_error_percent <= tied)
    ]
    return mine[0] if mine else kept


class _Judge:
    """The errors of a candidate's friction torques on the residual ``res``: training,
    held-out, and held-out with each joint in units of its torque noise, pooled and per
    fold (``labels``)."""

    def __init__(self, res: FrictionResidual, labels: NDArray[np.intp]) -> None:
        self.r, self.labels = res.residual, labels
        self.scale = float(np.linalg.norm(res.log.tau)) or 1.0
        self.w = _inverse_noise(res)
        self.wtau = res.log.tau * self.w
        self.blocks = [labels == k for k in range(int(labels.max()) + 1)]

    def _err(self, e: NDArray[np.float64], ref: NDArray[np.float64]) -> float:
        return 100.0 * float(np.linalg.norm(e)) / (float(np.linalg.norm(ref)) or 1.0)

    def score(
        self,
        name: str,
        params: tuple[str, ...],
        n_params: int,
        train: NDArray[np.float64],
        held: NDArray[np.float64],
    ) -> CandidateScore:
        """The :class:`CandidateScore` of friction torques ``train`` (fitted on the whole
        log) and ``held`` (each block predicted by a fit on the others), both (N, n) [N m]."""
        e = (self.r - held) * self.w
        folds = tuple(self._err(e[b], self.wtau[b]) for b in self.blocks)
        return CandidateScore(
            name,
            params,
            100.0 * float(np.linalg.norm(self.r - train)) / self.scale,
            100.0 * float(np.linalg.norm(self.r - held)) / self.scale,
            self._err(e, self.wtau),
            folds,
            n_params,
        )


def torque_noise_std(res: FrictionResidual) -> NDArray[np.float64] | None:
    """Per joint, the white-noise std [N m] (n,) of the measured torques of ``res``: each
    recording's (:func:`~dynid.identification.input_noise.quantized_noise_std`, the
    sensors' noise validation judges against) pooled by samples; None when not known."""
    tau, t = res.log.tau, res.log.t
    rec = np.zeros(tau.shape[0], np.intp) if res.recording is None else res.recording
    var, count = np.zeros(tau.shape[1]), 0
    for k in np.unique(rec):
        b = rec == k
        if b.sum() >= 3:
            var += b.sum() * quantized_noise_std(tau[b], t[b]) ** 2
            count += int(b.sum())
    sigma = np.sqrt(var / max(count, 1))
    ok = count > 0 and np.all(np.isfinite(sigma)) and float(np.max(sigma)) > 0
    return np.asarray(sigma, dtype=np.float64) if ok else None


def _inverse_noise(res: FrictionResidual) -> NDArray[np.float64]:
    """Per joint, one over the torque noise std [1/(N m)] (:func:`torque_noise_std`, at
    least :data:`~dynid.identification.verdict.NOISE_FLOOR_SHARE` of the largest joint's),
    as identification weighs its held-out judgement; ones when the noise is not known."""
    sigma = torque_noise_std(res)
    if sigma is None:
        return np.ones(res.log.tau.shape[1])
    return np.asarray(1.0 / np.maximum(sigma, NOISE_FLOOR_SHARE * float(np.max(sigma))))


def held_names(own: FrictionModel | FrictionSum) -> tuple[str, ...]:
    """The coefficients a friction holds (nonzero on some joint), by name; a sum's each
    with its place (``fv@motors``, ``fc@joints``)."""
    parts = friction_parts(own)
    out: list[str] = []
    for part in parts:
        held = np.any(part.as_array() != 0, axis=0)
        at = ("@motors" if part.at_motors else "@joints") if len(parts) > 1 else ""
        out += [f"{name}{at}" for name, h in zip(part.names, held, strict=True) if h]
    return tuple(out)


def _held_count(own: FrictionModel | FrictionSum) -> int:
    """Coefficients per joint a friction holds (:func:`held_names`); a law not linear in
    its parameters counts all of its own."""
    return len(held_names(own))


def _heldout_own(
    res: FrictionResidual, own: FrictionModel | FrictionSum, labels: NDArray[np.intp]
) -> NDArray[np.float64]:
    """Each block's friction torques (N, n) predicted by the model's own friction, its
    structure refitted on the other blocks: every part (one, or a sum's) with its law,
    standstill band (a smooth law's width) and place, the coefficients ``own`` holds
    (nonzero; those the model left out stay 0) by bounded linear least squares together,
    within their laws' bounds unless the model's own value lies outside one (a part's
    torques at one coefficient set to 1 are its column; a law not linear in its
    parameters gets one gain >= 0 per row, its shape kept). The same law trains and
    judges the row: a registry law refitted at its default band is another law (a smooth
    Coulomb 0.3 rad/s wide refitted at the velocity noise, 0.0007 rad/s, was judged at
    0.455 % against its 0.348 % training error)."""
    dq = res.dq
    cols: list[NDArray[np.float64]] = []
    lo: list[float] = []
    hi: list[float] = []
    for part in friction_parts(own):
        P = part.as_array()
        units: list[tuple[NDArray[np.float64], float, float]] = []
        if isinstance(part.law.fit, _LinearFit):
            for m, i in zip(*np.nonzero(P), strict=True):
                unit = np.zeros_like(P)
                unit[m, i] = 1.0
                low = part.law.lower[i] if P[m, i] >= part.law.lower[i] else -np.inf
                high = part.law.upper[i] if P[m, i] <= part.law.upper[i] else np.inf
                units.append((unit, low, high))
        else:  # not linear in its parameters: one gain per row, its shape kept
            for m in np.flatnonzero(np.any(P != 0, axis=1)):
                unit = np.zeros_like(P)
                unit[m] = P[m]
                units.append((unit, 0.0, np.inf))
        for unit, low, high in units:
            cols.append(part.law.model(unit, part.band, part.drive).torques(dq).ravel())
            lo.append(low)
            hi.append(high)
    out = np.zeros(dq.shape)
    if not cols:
        return out
    A = np.column_stack(cols)
    rows = np.repeat(labels, dq.shape[1])
    r = res.residual.ravel()
    for k in range(int(labels.max()) + 1):
        b = rows == k
        x = bounded_lstsq(A[~b], r[~b], np.array(lo), np.array(hi))
        out.reshape(-1)[b] = A[b] @ x
    return out


def _folds(res: FrictionResidual, folds: int) -> tuple[NDArray[np.intp], int, str]:
    """Each sample's held-out block, the number of blocks and how they were made."""
    rec = res.recording
    if rec is not None and np.unique(rec).size > 1:
        _, labels = np.unique(rec, return_inverse=True)
        k = int(labels.max()) + 1
        return labels.astype(np.intp), k, f"leave one recording out ({k} recordings)"
    return block_labels(res.dq.shape[0], folds), folds, "contiguous-block cross-validation"


def _own_fit(own: FrictionModel | FrictionSum, res: FrictionResidual) -> FrictionFit:
    n = res.dq.shape[1]
    after = res.residual - own.torques(res.dq)
    return FrictionFit(
        friction=own,
        rms_before=np.sqrt(np.mean(res.residual**2, axis=0)),
        rms_after=np.sqrt(np.mean(after**2, axis=0)),
        converged=np.ones(n, bool),
        iterations=np.zeros(n, int),
        n_samples=res.dq.shape[0],
        identified=np.ones(n, bool),
    )
