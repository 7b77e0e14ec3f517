"""The one regressor a group of candidate structures shares, fitted once.

:func:`fit_largest` fits the model holding every column of a group of candidates
(:func:`~dynid.identification.structure.largest_terms`; the groups:
:func:`~dynid.identification.structure.regressor_group`) with the held-out judge, so that
each candidate is judged on its own columns of the folds' normal equations. Where the data
cannot tell some columns apart, only the alike candidates are left out, one set after the
other (:data:`SMOOTH_THINNING`), each named in one note; the smooth widths left out are
judged each in a regressor of its own: alike the others near rest in
the rank's eyes, they need not predict alike (the narrowest, the expected sign of a sharp
Coulomb law given the velocity noise, against the banded sign).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DynidWarning, RankDeficientError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.terms import ModelTerm
from .core import Judge, identify
from .estimators import Estimator
from .model import IdentifiedModel
from .recordings import Recordings
from .structure import (
    STRIBECK_COARSE,
    Structure,
    largest_terms,
    regressor_group,
)

__all__ = ["SMOOTH_THINNING", "Fitted", "fit_largest", "recording_bands"]

#: A regressor fitted with the held-out judge: its family (the third item of
#: :func:`~dynid.identification.structure.regressor_group`, ``smooth:W`` for a width
#: judged apart), the model, its terms (with what each stands for) and its candidates.
Fitted = tuple[str, IdentifiedModel, list[tuple[ModelTerm, Any]], list[Structure]]


def recording_bands(data: Recordings) -> dict[str, tuple[float, ...]]:
    """The standstill bands at a drive's motors and joints, as tuples."""
    return {at: tuple(float(x) for x in b) for at, b in data.bands.items()}


def fit_largest(
    robot: Robot,
    data: Recordings,
    mine: list[Structure],
    arm: bool,
    drive: Drive | None,
    est: Estimator,
    rtol: float | None,
    judge: Judge,
    notes: list[str],
    fold_labels: NDArray[np.intp] | None = None,
) -> list[Fitted]:
    """The model of every candidate's columns at once, with its terms and the candidates
    it holds; when the data cannot tell its columns apart, the Stribeck laws at
    :data:`~dynid.identification.structure.STRIBECK_COARSE` only, then fewer smooth widths,
    then the classical candidates alone, and after it the smooth widths left out, each in
    a regressor of its own (one note says which were judged apart and which left out);
    empty (and a note) when not even the classical candidates are identifiable."""
    shaped = [c for c in mine if {"smooth", "stribeck"} & set(c.friction)]
    coarse = [c for c in mine if "stribeck" not in c.friction or c.vst in STRIBECK_COARSE]
    tries = [mine, coarse]
    # smooth widths the data cannot tell apart (velocities seldom within a few bands of
    # zero: tanh(v / w) is the sign for every narrow w): the narrow ones but the
    # narrowest left out first, then it, then the wider ones
    gone: set[float] = set()
    for w in SMOOTH_THINNING:
        gone.add(w)
        tries.append([c for c in coarse if "stribeck" in c.friction or c.width not in gone])
    tries.append([c for c in mine if c not in shaped])
    what = ("with" if arm else "without") + " armature"
    place = {"both": "motors and the joints"}
    what += "".join(
        f", friction at the {place.get(a, a + 's')}" for a in {c.at for c in mine} - {""}
    )
    family = regressor_group(mine[0])[2]
    laws = "smooth-sign Stribeck" if family.startswith("smooth") else family or "smooth"
    laws = "Stribeck" if laws == "stribeck" else laws
    failed: list[str] = []
    fit = _Fit(robot, data, arm, drive, est, rtol, judge, fold_labels)
    for k, group in enumerate(tries):
        if not group or (k and len(group) == len(tries[k - 1])):
            continue
        try:
            model, terms = fit(group)
        except RankDeficientError as exc:
            failed.append(f"rank {exc.rank} < {exc.needed}")
            continue
        out: list[Fitted] = [(family, model, terms, group)]
        if failed:
            apart = _fit_apart(fit, [c for c in mine if c not in group], family)
            out += apart
            judged = {c for *_, g in apart for c in g}
            note = _left_out_note(mine, group + list(judged), laws, what)
            if judged:
                widths = ", ".join(f"{w:g}" for w in sorted({c.width for c in judged}))
                note += (
                    f"; the widths {widths} bands judged each in a regressor of its own"
                    if note
                    else f"the {laws} candidates {what} at the widths {widths} bands: too "
                    "alike their neighbours near rest to share a regressor with them, "
                    "judged each in a regressor of its own"
                )
            notes.append(note + f" ({'; '.join(failed)})")
        return out
    if failed:
        notes.append(
            (
                f"the {laws} candidates {what}: the data do not tell them from Coulomb friction"
                if shaped and len(shaped) == len(mine)
                else f"the candidates {what}: not identifiable from these data"
            )
            + f" ({'; '.join(failed)})"
        )
    return []


@dataclass(frozen=True)
class _Fit:
    """The model of a group of candidates' columns (:func:`largest_terms`) with the
    held-out judge, on the data and options of one :func:`fit_largest`."""

    robot: Robot
    data: Recordings
    arm: bool
    drive: Drive | None
    est: Estimator
    rtol: float | None
    judge: Judge
    fold_labels: NDArray[np.intp] | None

    def __call__(
        self, group: list[Structure]
    ) -> tuple[IdentifiedModel, list[tuple[ModelTerm, Any]]]:
        """The model and its terms; raises RankDeficientError where the data cannot tell
        the group's columns apart."""
        data = self.data
        model_drive, terms = largest_terms(
            group,
            self.arm,
            self.drive,
            self.robot.n,
            tuple(data.band),
            recording_bands(data),
            data.band_gain,
        )
        with warnings.catch_warnings():  # the candidates' fits: only the chosen one speaks
            warnings.simplefilter("ignore", DynidWarning)
            model = identify(
                self.robot,
                data,
                drive=model_drive,
                terms=tuple(t for t, _ in terms),
                estimator=self.est,
                rtol=self.rtol,
                judge=self.judge,
                fold_labels=self.fold_labels,
            )
        return model, terms


def _fit_apart(fit: _Fit, left: list[Structure], family: str = "") -> list[Fitted]:
    """The smooth candidates (not Stribeck) of ``left`` (left out of their shared
    regressor) in one regressor per width, family ``smooth:W`` (after ``family``); those
    of a width whose own columns the data cannot tell apart stay left out."""
    out: list[Fitted] = []
    smooth = [c for c in left if "smooth" in c.friction and "stribeck" not in c.friction]
    for w in sorted({c.width for c in smooth}):
        group = [c for c in smooth if c.width == w]
        try:
            model, terms = fit(group)
        except RankDeficientError:
            continue
        out.append(((f"{family} " if family else "") + f"smooth:{w:g}", model, terms, group))
    return out


#: The order in which smooth widths (in bands) are left out of a regressor whose columns
#: the data cannot tell apart (:func:`_fit_largest`).
SMOOTH_THINNING = (1.0, 3.0, 0.3, 10.0, 30.0, 100.0, 300.0)


def _left_out_note(mine: list[Structure], group: list[Structure], laws: str, what: str) -> str:
    """One note naming the shaped candidates of ``mine`` left out of ``group`` ("" for
    none)."""
    vst = sorted({c.vst for c in mine if c not in group and c.vst})
    widths = sorted(
        {c.width for c in mine if c not in group and c.friction and "stribeck" not in c.friction}
        - {0.0}
    )
    if not vst and not widths:
        return ""
    if len(group) > len([c for c in mine if not {"smooth", "stribeck"} & set(c.friction)]):
        parts = [f"Stribeck velocities {', '.join(f'{v:g}' for v in vst)} rad/s"] if vst else []
        parts += [f"widths {', '.join(f'{w:g}' for w in widths)} bands"] if widths else []
        return (
            f"the {laws} candidates {what} at the {' and '.join(parts)}: the data do not "
            "tell them from their neighbours (left out)"
        )
    return f"the {laws} candidates {what}: the data do not tell them from Coulomb friction"
