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
4. The candidate with the lowest held-out error is kept (on a tie, the earlier of
   :data:`~dynid.friction.laws.LAWS`: the simpler) and fitted on the whole log.

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
coefficients the model holds, the others left at 0: the same structure). ``friction.json``
holds one law of the registry: when the sum predicts best it is ``chosen`` (``own``), the
kept fit is the best law of the registry and a warning says so (the model's own friction
stays in its identification file).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError, DynidWarning, OptionError
from ..identification.holdout import DEFAULT_FOLDS, block_labels
from ..model.drive import Drive
from .fit import FrictionFit, FrictionResidual, fit_friction_through, fit_law_through
from .laws import LAWS
from .laws.base import _LinearFit, bounded_lstsq
from .model import FrictionModel, FrictionSum, friction_parts

__all__ = ["FOLDS", "OWN", "CandidateScore", "FrictionSelection", "select_friction"]

#: Number of contiguous blocks of the cross-validation (the identification's default).
FOLDS = DEFAULT_FOLDS
#: Name of the candidate "the model's own friction, as it is".
OWN = "own"


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
    """

    name: str
    params: tuple[str, ...]
    train_error_percent: float
    heldout_error_percent: float


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
    """

    fit: FrictionFit
    chosen: str
    scores: tuple[CandidateScore, ...]
    folds: int
    method: str = "contiguous-block cross-validation"

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: ``folds``, ``chosen`` and one row per candidate (``model``,
        ``parameters``, ``train_error_percent``, ``heldout_error_percent``)."""
        return {
            "method": self.method,
            "folds": self.folds,
            "chosen": self.chosen,
            "candidates": [
                {
                    "model": s.name,
                    "parameters": list(s.params),
                    "train_error_percent": s.train_error_percent,
                    "heldout_error_percent": s.heldout_error_percent,
                }
                for s in self.scores
            ],
        }

    def table(self) -> str:
        """The candidates as a text table, the kept one marked with ``*``."""
        rows = [f"  {'friction law':<12} {'parameters':<32} {'train [%]':>10} {'held-out [%]':>13}"]
        for s in self.scores:
            mark = "*" if s.name == self.chosen else " "
            rows.append(
                f"{mark} {s.name:<12} {', '.join(s.params) or '-':<32} "
                f"{s.train_error_percent:>10.3f} {s.heldout_error_percent:>13.3f}"
            )
        return "\n".join(rows)


def _heldout_torques(
    res: FrictionResidual, drive: Drive | None, name: str, labels: NDArray[np.intp]
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
                name, res.dq[keep], res.residual[keep], drive, dq_noise_std=noise, warn=False
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
) -> FrictionSelection:
    """Fit the candidate laws and keep the one with the lowest held-out error.

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
        Joints that never move (their friction is zero).
    """
    compared = [name for name, law in LAWS.items() if law.compared]
    if own_fitted_here and isinstance(own, FrictionModel) and own.kind in LAWS:
        compared = [*dict.fromkeys(compared + [own.kind])]  # the own law, refitted as the rest
    names = compared if candidates is None else list(candidates)
    unknown = [c for c in names if c not in LAWS]
    if unknown:
        raise OptionError(f"--friction-model must be one of {', '.join(LAWS)}; got {unknown[0]!r}")
    labels, folds, method = _folds(res, folds)
    r = res.residual
    scale = float(np.linalg.norm(res.log.tau)) or 1.0

    def err(tf: NDArray[np.float64]) -> float:
        return 100.0 * float(np.linalg.norm(r - tf)) / scale

    fits: dict[str, FrictionFit] = {}
    scores: list[CandidateScore] = []
    own_score: CandidateScore | None = None
    last = False  # the own friction judged by a refit goes last: a tie goes to a law
    if own is not None:
        tf = own.torques(res.dq)
        if isinstance(own, FrictionModel):
            fits[OWN] = _own_fit(own, res)
        last = own_fitted_here  # judged by its own structure refitted on the other blocks
        held = err(_heldout_own(res, own, labels) if last else tf)
        own_score = CandidateScore(OWN, own.names, err(tf), held)
        if not last:  # new data to the model: its prediction is held out as it is
            scores.append(own_score)
    for name in names:
        with warnings.catch_warnings():
            if name != names[-1]:  # one warning about still joints is enough
                warnings.simplefilter("ignore", DynidWarning)
            fits[name] = fit_friction_through(res, drive, name)
        train = err(fits[name].friction.torques(res.dq))
        held = err(_heldout_torques(res, drive, name, labels))
        scores.append(CandidateScore(name, LAWS[name].params, train, held))
    if own_score is not None and last:
        scores.append(own_score)
    best = min(scores, key=lambda s: s.heldout_error_percent)  # first of the lowest: simpler
    if best.name == OWN and isinstance(own, FrictionSum):
        kept = min((s for s in scores if s.name != OWN), key=lambda s: s.heldout_error_percent)
        warnings.warn(
            f"the model's own friction ({own.kind}) predicts the held-out data best "
            f"({best.heldout_error_percent:.3g} % against {kept.heldout_error_percent:.3g} % "
            f"for {kept.name}); friction.json holds one law of the registry, {kept.name}: "
            "keep the model's own friction from its identification file",
            DynidWarning,
            stacklevel=2,
        )
        return FrictionSelection(fits[kept.name], OWN, tuple(scores), folds, method)
    return FrictionSelection(fits[best.name], best.name, tuple(scores), folds, method)


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


def _own_fit(own: FrictionModel, res: FrictionResidual) -> FrictionFit:
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
