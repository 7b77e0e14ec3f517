"""A joint spring judged as a candidate structure where the held-out residual names one.

A spring (a gravity compensator, a cable) is no default candidate: a stiffness per joint
on every arm would cost parameters the data seldom need. After the structure search, the
held-out residual of the structure chosen is fitted with a stiffness per joint beside the
model's columns (:func:`~dynid.identification.residual_spring.residual_spring`, which
never names a joint whose residual follows its velocity more than its position: a
Stribeck bump the model lacks); for the joints it names, :func:`with_spring` runs the
search again with a spring on those joints as a fixed part of every candidate
(:func:`spring_structures`: the armature and friction choice may change with it), judged
on the same folds. Its choice is kept only by the rule every candidate is held to: the
structure without the spring predicts worse beyond one standard error of the difference,
paired over the folds (:func:`~dynid.identification.candidates.within_best`). Either way
the spring's candidates are in the table, and the selection's record says what was tried
(:attr:`~dynid.identification.candidates.Selection.spring`).

A Baxter arm with a 40 N m/rad gravity-compensation spring on its shoulder: held out
5.58 % (3.6 x the noise floor) without it, with an armature the truth lacks; the spring
chosen, 39.9 N m/rad, the armature gone and the error at the floor.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from dataclasses import replace
from typing import Any

from ..model.drive import Drive
from ..regressors.spring import SPRING_LABEL
from .candidates import Candidate, Selection, paired_se, within_best
from .structure import Structure, candidate_structures, friction_placements

__all__ = ["spring_structures", "tried_joints", "with_spring"]


def spring_structures(
    structures: Sequence[Structure], joints: Collection[int], n: int
) -> tuple[Structure, ...]:
    """Each of ``structures`` with a spring on ``joints`` (0-based, of ``n``) and on no
    other joint (their stiffnesses left out: ``-k1``)."""
    others = tuple(f"{SPRING_LABEL}{j + 1}" for j in range(n) if j not in joints)
    return tuple(replace(s, spring=True, drop=s.drop + others) for s in structures)


def tried_joints(selection: Selection) -> tuple[int, ...]:
    """The joints (0-based) of the spring ``selection`` tried (:func:`with_spring`); empty
    when it tried none."""
    return tuple(int(j) - 1 for j in dict(selection.spring).get("joints", ()))


def _chosen_candidate(selection: Selection) -> Candidate | None:
    """The candidate of ``selection``'s choice (its lowest score when judged twice)."""
    mine = [c for c in selection.candidates if c.structure == selection.chosen]
    return min(mine, key=lambda c: c.score) if mine else None


def _against_best(cands: Sequence[Candidate]) -> tuple[Candidate, ...]:
    """``cands`` with each one's standard error vs the lowest score among them."""
    best = min([c for c in cands if not c.skipped] or cands, key=lambda c: c.score)
    return tuple(replace(c, se_vs_best_percent=paired_se(c, best)) for c in cands)


def _note(record: dict[str, Any], plain: Candidate, sprung: Candidate) -> str:
    """The trial in words: the joints (from 1), the two choices' held-out errors [%] and
    the difference in standard errors."""
    se = float(record["se_vs_spring_percent"])
    gap = plain.score - sprung.score
    apart = f"{gap / se:.1f} standard errors" if se > 0 else "no standard error"
    joints = ", ".join(str(j) for j in record["joints"])
    how = "chosen" if record["chosen"] else "not chosen (within one standard error)"
    with_it, without = sprung.heldout_error_percent, plain.heldout_error_percent
    return (
        f"a spring on joint(s) {joints}, which the held-out residual of the choice without "
        f"one names, judged on the same folds: {how}; held out {with_it:.3g} % against "
        f"{without:.3g} % without it ({apart} apart)"
    )


def with_spring(
    first: Selection,
    joints: Sequence[int],
    n: int,
    drive: Drive | None,
    select: Callable[..., Selection | None],
) -> Selection:
    """``first`` (the search without a spring) judged against the search with a spring on
    ``joints`` (0-based, of ``n``; named by the held-out residual) as a fixed part of
    every default candidate (``select(candidates=...)``: the search on the same recordings and
    folds): the spring's choice where the choice without it is worse beyond one standard
    error, else ``first``; both searches' candidates in the table and the spring's record
    (module docstring)."""
    if first.chosen.spring or not joints:
        return first
    armature_ok = drive is None or drive.identifies_rotor_inertia
    default = candidate_structures(armature_ok, friction_placements(drive))
    second = select(candidates=spring_structures(default, joints, n))
    plain = _chosen_candidate(first)
    sprung = None if second is None else _chosen_candidate(second)
    record: dict[str, Any] = {"joints": [int(j) + 1 for j in joints]}
    if second is None or plain is None or sprung is None:
        return replace(first, spring=tuple((record | {"chosen": False}).items()))
    kept = not within_best(plain, sprung)
    record |= {
        "structure": sprung.structure.name,
        "heldout_error_percent": sprung.heldout_error_percent,
        "heldout_whitened_percent": sprung.whitened_error_percent,
        "without_spring_error_percent": plain.heldout_error_percent,
        "se_vs_spring_percent": paired_se(plain, sprung),
        "chosen": kept,
    }
    spring = tuple(record.items())
    note = _note(record, plain, sprung)
    if not kept:  # the spring's choice shown beside the others
        cands = _against_best([*first.candidates, sprung])
        return replace(first, candidates=cands, notes=(*first.notes, note), spring=spring)
    mine = tuple(f"with the spring: {m}" for m in second.notes if m not in first.notes)
    return replace(
        second,
        candidates=_against_best([*first.candidates, *second.candidates]),
        notes=(*first.notes, *mine, note),
        outlying=first.outlying,
        cut=first.cut,
        spring=spring,
    )
