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
identified from this very log (``own_fitted_here``), by its law refitted on the other blocks
as the others are, a tie going to the registry's law refitted on the whole log (judged on
the samples its values were fitted to, the model's friction would always win).
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
from .model import FrictionModel

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
    own: FrictionModel | None = None,
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
        Laws of the registry to compare (default: all, :data:`~dynid.friction.laws.LAWS`).
    own : FrictionModel, optional
        The model's own friction, a candidate as it is (``"own"``).
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
    names = list(LAWS) if candidates is None else list(candidates)
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
    if own is not None:
        tf = own.torques(res.dq)
        fits[OWN] = _own_fit(own, res)
        law = own.kind if own_fitted_here and own.kind in LAWS else None
        held = err(tf) if law is None else err(_heldout_torques(res, drive, law, labels))
        own_score = CandidateScore(OWN, own.names, err(tf), held)
        if law is None:  # new data to the model: its prediction is held out as it is
            scores.append(own_score)
    for name in names:
        with warnings.catch_warnings():
            if name != names[-1]:  # one warning about still joints is enough
                warnings.simplefilter("ignore", DynidWarning)
            fits[name] = fit_friction_through(res, drive, name)
        train = err(fits[name].friction.torques(res.dq))
        held = err(_heldout_torques(res, drive, name, labels))
        scores.append(CandidateScore(name, LAWS[name].params, train, held))
    if own is not None and own_fitted_here and own.kind in LAWS:
        scores.append(own_score)  # last: a tie goes to its law refitted on the whole log
    best = min(scores, key=lambda s: s.heldout_error_percent)  # first of the lowest: simpler
    return FrictionSelection(fits[best.name], best.name, tuple(scores), folds, method)


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
