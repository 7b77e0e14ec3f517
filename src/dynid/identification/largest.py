"""The one regressor a group of candidate structures shares, fitted once.

:func:`fit_largest` fits the model holding every column of a group of candidates
(:func:`~dynid.identification.structure.largest_terms`; the groups:
:func:`~dynid.identification.structure.regressor_group`) with the held-out judge, so that
each candidate is judged on its own columns of the folds' normal equations. Where the data
cannot tell some columns apart, only the alike candidates are left out, one set after the
other (:data:`SMOOTH_THINNING`), each named in one note; the smooth widths left out are
judged each in a regressor of its own: alike the others near rest in the rank's eyes, they
need not predict alike (the narrowest, the expected sign of a sharp Coulomb law given the
velocity noise, against the banded sign).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, replace
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
from .one_way_friction import FRICTION_LABEL, offset_instead
from .recordings import Recordings
from .structural import held_by
from .structure import (
    STRIBECK_COARSE,
    Structure,
    largest_terms,
    regressor_group,
    width_key,
    width_text,
)

__all__ = [
    "Fitted",
    "LeftOut",
    "SMOOTH_THINNING",
    "fit_largest",
    "limits_middle",
    "recording_bands",
]

#: A regressor fitted with the held-out judge: its family (the third item of
#: :func:`~dynid.identification.structure.regressor_group`, ``smooth:W`` for a width
#: judged apart), the model, its terms (with what each stands for) and its candidates.
Fitted = tuple[str, IdentifiedModel, list[tuple[ModelTerm, Any]], list[Structure]]


def recording_bands(data: Recordings) -> dict[str, tuple[float, ...]]:
    """The standstill bands at a drive's motors and joints, as tuples."""
    return {at: tuple(float(x) for x in b) for at, b in data.bands.items()}


def limits_middle(robot: Robot) -> tuple[float, ...]:
    """The middle of each joint's limits [rad], zero for a joint without finite limits: a
    spring's rest position, whose true value the offset absorbs."""
    lo, hi = np.asarray(robot.q_min, dtype=np.float64), np.asarray(robot.q_max, dtype=np.float64)
    finite = np.isfinite(lo) & np.isfinite(hi)  # a continuous joint: -inf .. inf
    mid = np.zeros(lo.shape)
    mid[finite] = (lo[finite] + hi[finite]) / 2
    return tuple(float(x) for x in mid)


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
    unexcited: set[str] | None = None,
    left_out: list[LeftOut] | None = None,
) -> list[Fitted]:
    """The model of every candidate's columns at once, with its terms and the candidates it
    holds; when the data cannot tell its columns apart, the Stribeck laws at
    :data:`~dynid.identification.structure.STRIBECK_COARSE` only, then fewer smooth widths,
    then the classical candidates alone, and after it the smooth widths left out, each in
    a regressor of its own (a note says which were left out or judged apart; a
    :class:`LeftOut` appended to
    ``left_out`` instead when given, said once the choice is made). When not even those are
    identifiable for want of single joints' friction coefficients (a joint that never
    reverses: its Coulomb friction is an offset), those coefficients are left out of every
    candidate (:func:`_unexcited_coefficients`; ``unexcited`` gathers them over the
    groups, and a group starts without those already found) and the candidates judged
    again; those dependent at every motion are left out of this group's candidates only
    (a column set's own dependence: viscous friction at the motors and at the joints of a
    differential wrist, not at the motors alone); empty (and a note) when still none is
    identifiable."""
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
    classical = [c for c in mine if c not in shaped]
    tries.append(classical)
    what = ("with" if arm else "without") + " armature"
    place = {"both": "motors and the joints"}
    what += "".join(
        f", friction at the {place.get(a, a + 's')}" for a in {c.at for c in mine} - {""}
    )
    family = regressor_group(mine[0])[2]
    laws = _family(family)

    held: dict[str, str] = {}  # what coefficients hold of those left out as dependent

    def fit(group: list[Structure], drop: frozenset[str]) -> _Fitted:
        model, terms = _fit_group(
            robot, data, group, arm, drive, est, rtol, judge, fold_labels, drop
        )
        if held:  # the candidates' sign checks read it (a difference has no sign)
            model = replace(model, info=replace(model.info, combined=dict(held)))
        return model, terms

    found = unexcited if unexcited is not None else set()
    drop = frozenset(found)
    fitted, failed = _first_fitted(tries, drop, fit)
    if fitted is None and classical:
        more, why, structural, own = _unexcited_coefficients(classical, drop, fit)
        if more:
            drop |= more
            found |= more - own  # the data's, not this column set's own dependence
            held.update(held_by(structural, own))
            fitted, failed = _first_fitted(tries, drop, fit)
            note = f"{_unexcited_text(why, structural)}: {_left_out_text(more, own, what)}"
            notes += [] if note in notes else [note]
    if fitted is not None:
        model, terms, group, k = fitted
        out: list[Fitted] = [(family, model, terms, [c.without(drop) for c in group])]
        if k:
            out += _fit_apart(fit, [c for c in mine if c not in group], drop, family)
            apart = [c for *_, g in out[1:] for c in g]
            record = _left_out(mine, group, laws, what, failed, apart)
            if left_out is None:
                notes.append(record.note())
            else:
                left_out.append(record)
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


_Fitted = tuple[IdentifiedModel, list[tuple[ModelTerm, Any]]]
_FirstFit = tuple[IdentifiedModel, list[tuple[ModelTerm, Any]], list[Structure], int]


def _fit_group(
    robot: Robot,
    data: Recordings,
    group: list[Structure],
    arm: bool,
    drive: Drive | None,
    est: Estimator,
    rtol: float | None,
    judge: Judge,
    fold_labels: NDArray[np.intp] | None,
    drop: frozenset[str],
) -> _Fitted:
    """The model of the columns of every candidate of ``group`` (the friction coefficients
    ``drop`` left out), fitted with the held-out judge, and its terms.

    Raises
    ------
    RankDeficientError
        The data do not identify those columns.
    """
    model_drive, terms = largest_terms(
        group, arm, drive, robot.n, tuple(data.band), recording_bands(data), data.band_gain, drop,
        limits_middle(robot),
    )  # fmt: skip
    with warnings.catch_warnings():  # the candidates' fits: only the chosen one speaks
        warnings.simplefilter("ignore", DynidWarning)
        model = identify(
            robot,
            data,
            drive=model_drive,
            terms=tuple(t for t, _ in terms),
            estimator=est,
            rtol=rtol,
            judge=judge,
            fold_labels=fold_labels,
        )
    return model, terms


def _first_fitted(
    tries: list[list[Structure]],
    drop: frozenset[str],
    fit: Callable[[list[Structure], frozenset[str]], _Fitted],
) -> tuple[_FirstFit | None, list[str]]:
    """The first of ``tries`` the data identify (its model, terms, candidates and place),
    and the ranks of those before it that they do not."""
    failed: list[str] = []
    for k, group in enumerate(tries):
        if not group or (k and len(group) == len(tries[k - 1])):
            continue
        try:
            return (*fit(group, drop), group, k), failed
        except RankDeficientError as exc:
            failed.append(f"rank {exc.rank} < {exc.needed}")
    return None, failed


def _fit_apart(
    fit: Callable[[list[Structure], frozenset[str]], _Fitted],
    left: list[Structure],
    drop: frozenset[str],
    family: str,
) -> list[Fitted]:
    """The smooth candidates (not Stribeck) of ``left`` (left out of their shared
    regressor) in one regressor per width, family ``smooth:W`` (after ``family``); those
    of a width whose own columns the data cannot tell apart stay left out."""
    out: list[Fitted] = []
    smooth = [c for c in left if "smooth" in c.friction and "stribeck" not in c.friction]
    for w in sorted({c.width for c in smooth}, key=width_key):
        group = [c for c in smooth if c.width == w]
        try:
            model, terms = fit(group, drop)
        except RankDeficientError:
            continue
        key = (f"{family} " if family else "") + f"smooth:{width_text(w)}"
        out.append((key, model, terms, [c.without(drop) for c in group]))
    return out


#: At most this many rounds of single joints' coefficients left out
#: (:func:`_unexcited_coefficients`).
MAX_DROP_ROUNDS = 3


def _unexcited_coefficients(
    classical: list[Structure],
    drop: frozenset[str],
    fit: Callable[[list[Structure], frozenset[str]], _Fitted],
) -> tuple[frozenset[str], list[str], list[str], frozenset[str]]:
    """The single joints' friction coefficients (``"fc3"``) beside ``drop`` without which
    the data identify the classical candidates' columns, the combinations the data do
    not excite that named them (:attr:`~dynid.exceptions.RankDeficientError.redundant`),
    those of them no data excite (the model's columns dependent at every motion,
    :attr:`~dynid.exceptions.RankDeficientError.structural`) and the coefficients those
    name: dependent in these columns only (viscous friction at both motors of a
    differential wrist is dependent on that at its joints, not alone), so left out of
    these candidates, not of other column sets; none when other columns (the links') are
    not identifiable either."""
    more: set[str] = set()
    own: set[str] = set()
    why: list[str] = []
    structural: list[str] = []
    for _ in range(MAX_DROP_ROUNDS):
        try:
            fit(classical, drop | more)
        except RankDeficientError as exc:
            named = {offset_instead(lab, exc.combinations) for lab in exc.redundant}
            new = named - drop - more
            if not new or not all(FRICTION_LABEL.fullmatch(lab) for lab in new):
                return frozenset(), [], [], frozenset()
            more |= new
            own |= new if exc.structural else set()  # then it names the structural ones
            why += [c for c in exc.combinations if c not in exc.structural]
            structural += list(exc.structural)
            continue
        return frozenset(more), why, structural, frozenset(own)
    return frozenset(), [], [], frozenset()


def _left_out_text(more: frozenset[str], own: frozenset[str], what: str) -> str:
    """Which coefficients left out where: those the data do not excite, of every
    candidate; those dependent in one column set only (``own``), of its candidates
    (``what``: ``"without armature, friction at the motors and the joints"``)."""
    said = []
    if more - own:
        said.append(f"{', '.join(sorted(more - own, key=_order))} left out of every candidate")
    if own:
        said.append(f"{', '.join(sorted(own, key=_order))} left out of the candidates {what}")
    return "; ".join(said)


def _unexcited_text(why: list[str], structural: list[str]) -> str:
    """What left single joints' coefficients out: the model's columns dependent at every
    motion (no trajectory helps) and the combinations the data do not excite."""
    parts = []
    if structural:
        parts.append(
            f"structurally not identifiable (dependent at every motion, whatever the "
            f"trajectory): {'; '.join(structural)}"
        )
    if why:
        parts.append(f"the data do not excite {'; '.join(why)}")
    return "; ".join(parts)


def _order(label: str) -> tuple[int, str]:
    """Joint first, then the label: ``fv2 < fo2 < fv3``."""
    prefix = label.rstrip("0123456789")
    return int(label[len(prefix) :]), prefix


#: The order in which smooth widths (in bands) are left out of a regressor whose columns
#: the data cannot tell apart (:func:`_fit_largest`).
SMOOTH_THINNING = (1.0, 3.0, 0.3, 10.0, 30.0, 100.0, 300.0)


@dataclass(frozen=True, slots=True)
class LeftOut:
    """Shaped candidates of one regressor left out because the data do not tell their
    columns apart (:func:`fit_largest`); :meth:`note` says it once the choice is made.

    Attributes
    ----------
    laws : str
        The family (``"smooth"``, ``"Stribeck"``, ``"smooth-sign Stribeck"``).
    what : str
        Which regressor (``"with armature"``, ``", friction at the motors"``).
    group : tuple of (bool, str, str)
        Its :func:`~dynid.identification.structure.regressor_group`.
    widths : tuple of float
        The smooth widths [bands] left out.
    vsts : tuple of float
        The Stribeck velocities [rad/s] left out.
    from_coulomb : bool
        Every shaped candidate left out (the data do not tell them from Coulomb friction).
    failed : tuple of str
        The ranks of the regressors tried (``"rank 101 < 102"``).
    apart : tuple of float
        The smooth widths [bands] left out of the shared regressor but judged each in a
        regressor of its own (not among :attr:`widths`).
    """

    laws: str
    what: str
    group: tuple[bool, str, str]
    widths: tuple[float, ...]
    vsts: tuple[float, ...]
    from_coulomb: bool
    failed: tuple[str, ...]
    apart: tuple[float, ...] = ()

    def note(self, chosen: Structure | None = None, chosen_group: Any = None) -> str:
        """One line; a smooth ``chosen`` structure at one of :attr:`widths` judged in
        another regressor of the same armature and placement (``chosen_group``: a
        smooth-sign Stribeck law whose bumps were left out) is said to be kept, not named
        as left out."""
        ranks = f" ({'; '.join(self.failed)})"
        alone = ", ".join(f"{w:g}" for w in self.apart)
        apart = (
            f"the widths {alone} bands, too alike their neighbours near rest to share a "
            "regressor with them, judged each in a regressor of its own"
        )
        if self.from_coulomb:
            return (
                f"the {self.laws} candidates {self.what}: the data do not tell them from "
                f"Coulomb friction" + (f" in one regressor; {apart}" if self.apart else "") + ranks
            )
        kept = (
            chosen is not None
            and chosen_group is not None
            and chosen_group != self.group
            and tuple(chosen_group[:2]) == self.group[:2]
            and "smooth" in chosen.friction
            and chosen.width in self.widths
        )
        width = chosen.width if kept and chosen is not None else None
        widths = [w for w in self.widths if w != width]
        parts = [f"Stribeck velocities {', '.join(f'{v:g}' for v in self.vsts)} rad/s"]
        parts = parts if self.vsts else []
        parts += [f"widths {', '.join(f'{w:g}' for w in widths)} bands"] if widths else []
        text = f"the {self.laws} candidates {self.what}"
        if parts:
            text += (
                f" at the {' and '.join(parts)}: the data do not tell them from their "
                "neighbours (left out)"
            )
        if width is not None:
            text += (
                f"{';' if parts else ':'} the width {width:g}, chosen, was kept: judged with "
                f"the {_family(chosen_group[2])} candidates (their bumps left out)"
            )
        if self.apart:
            text += f"{';' if parts or width is not None else ':'} {apart}"
        return text + ranks


def _family(key: str) -> str:
    """The laws of a regressor's key: ``"smooth_stribeck:0.3"`` -> ``"smooth-sign
    Stribeck"``, ``""`` -> ``"smooth"``."""
    laws = "smooth-sign Stribeck" if key.startswith("smooth") else key or "smooth"
    return "Stribeck" if laws == "stribeck" else laws


def _left_out(
    mine: list[Structure],
    group: list[Structure],
    laws: str,
    what: str,
    failed: list[str],
    apart: list[Structure],
) -> LeftOut:
    """The shaped candidates of ``mine`` left out of ``group`` (those of ``apart`` judged in
    regressors of their own)."""
    vst = sorted({c.vst for c in mine if c not in group and isinstance(c.vst, float) and c.vst})
    alone = {c.width for c in apart if isinstance(c.width, float)}
    widths = sorted(
        {
            c.width
            for c in mine
            if c not in group
            and c.friction
            and "stribeck" not in c.friction
            and isinstance(c.width, float)
        }
        - {0.0}
        - alone
    )
    shaped = len(group) > len([c for c in mine if not {"smooth", "stribeck"} & set(c.friction)])
    return LeftOut(
        laws,
        what,
        regressor_group(mine[0]),
        tuple(widths),
        tuple(vst),
        not shaped,
        tuple(failed),
        tuple(sorted(alone)),
    )
