"""The joint springs a held-out residual points to, on the identify and validate pages.

A file's ``springs`` (``heldout.json``; ``validation.json`` where it has one: the record of
:class:`~dynid.identification.residual_spring.ResidualSpring`): the stiffness per joint
[N m/rad] fitted with the model's columns to the measured torques, its standard deviation,
the spring's torque and the residual above the noise [N m] RMS, and the joints whose
residual the spring explains (``named``, indices from 0). Each named joint is said in the
verdict box with its stiffness and the verdict's own hint for it (the clause of the
verdict's reason that names the joint: what to add to ``--terms``); the table below it
lists every joint.
"""

from __future__ import annotations

import re
from typing import Any

from ..identification.residual_spring import FOLLOWS, SIGNIFICANT
from .html import cell, esc, is_number, number, section, table

__all__ = ["spring_facts", "springs_section"]

#: The record's per-joint lists, in the order of the table's columns after the joint.
_FIELDS = ("stiffness", "std", "torque", "systematic")


def _record(doc: Any) -> dict[str, Any] | None:
    """The file's ``springs`` record when every per-joint list is numbers of one length,
    or None."""
    rec = doc.get("springs") if isinstance(doc, dict) else None
    if not isinstance(rec, dict):
        return None
    lists = [rec.get(k) for k in _FIELDS]
    if not all(isinstance(v, list) and v and all(map(is_number, v)) for v in lists):
        return None
    if len({len(v) for v in lists}) != 1:  # type: ignore[arg-type]
        return None
    return rec


def _names(doc: dict, n: int) -> list[str]:
    names = doc.get("joint_names")
    if isinstance(names, list) and len(names) == n:
        return [str(x) for x in names]
    return [f"joint {j + 1}" for j in range(n)]


def _named(rec: dict, n: int) -> list[int]:
    named = rec.get("named")
    if not isinstance(named, list):
        return []
    return [int(j) for j in named if isinstance(j, int) and 0 <= j < n]


def _hint(doc: dict, name: str) -> str | None:
    """What to do for the spring on joint ``name``: the last parenthesis of the verdict's
    clause that names the joint's spring (``"try adding spring to --terms of dynid
    identify, with offset: the spring's rest position"``), or None when the verdict's
    reason does not name it (a joint past the joints it names)."""
    v = doc.get("verdict")
    reason = v.get("reason") if isinstance(v, dict) else None
    if not isinstance(reason, str):
        return None
    reason = re.sub(r" \(\d+ more joint\(s\) above their noise\)$", "", reason)
    for clause in reason.split("; "):
        if clause.startswith(f"{name}: ") and "spring of about" in clause:
            if clause.endswith(")") and " (" in clause:
                return clause[clause.rindex(" (") + 2 : -1]
    return None


def _explained(doc: dict, name: str) -> bool:
    """Whether the verdict's reason names joint ``name`` without a spring: its error
    listed while the reason gives another cause (a tilted base, a torque constant), which
    the summary says instead of the spring; False where the reason stops before the joint
    (``N more joint(s)``)."""
    v = doc.get("verdict")
    reason = v.get("reason") if isinstance(v, dict) else None
    return isinstance(reason, str) and re.search(rf"\b{re.escape(name)}\b", reason) is not None


def spring_facts(doc: Any) -> list[str]:
    """One fact (HTML) per joint whose residual the spring explains: its stiffness with its
    standard deviation [N m/rad] and what to do (the verdict's hint); none without a
    ``springs`` record, and none for a joint the verdict explains otherwise (it names the
    joint but no spring there: a tilted base read beside a 2 ms delay had put a spring of
    0.09 N m/rad in the report that the summary never said)."""
    rec = _record(doc)
    if rec is None:
        return []
    assert isinstance(doc, dict)
    n = len(rec["stiffness"])
    names = _names(doc, n)
    facts = []
    for j in _named(rec, n):
        hint = _hint(doc, names[j])
        if hint is None and _explained(doc, names[j]):
            continue  # the verdict names the joint with another cause (a tilt): as it says
        k, s = float(rec["stiffness"][j]), float(rec["std"][j])
        fact = (
            f"<b>A spring on {esc(names[j])}</b> outside the model: stiffness "
            f"<b>{number(k, 3)} N m/rad</b> (std {number(s, 2)} N m/rad), fitted with the "
            f"model's columns to the measured torques; its torque {number(rec['torque'][j], 3)}"
            f" N m RMS against {number(rec['systematic'][j], 3)} N m RMS of residual above "
            "the noise"
        )
        facts.append(fact + (f". What to do: {esc(hint)}" if hint else ""))
    return facts


def springs_section(doc: Any) -> str:
    """The table of the stiffness per joint (every joint, those the spring explains
    marked), or "" without a ``springs`` record."""
    rec = _record(doc)
    if rec is None:
        return ""
    assert isinstance(doc, dict)
    n = len(rec["stiffness"])
    names, named = _names(doc, n), set(_named(rec, n))
    rows = [
        [
            "&#10003; named" if j in named else "",
            esc(names[j]),
            *(cell(float(rec[k][j])) for k in _FIELDS),
        ]
        for j in range(n)
    ]
    headers = [
        "",
        "joint",
        "stiffness [N m/rad]",
        "std [N m/rad]",
        "spring's torque RMS [N m]",
        "residual above the noise RMS [N m]",
    ]
    said = (
        "A linear spring k (q - q0) on each joint, fitted with the model's own columns to the "
        "measured torques: named where the residual is above the noise, the stiffness "
        f"{SIGNIFICANT:g} standard deviations clear and its torque at least {FOLLOWS:g} x the "
        "residual above the noise."
    )
    return section(
        "springs",
        "Joint springs the residual points to",
        f"<p>{esc(said)}</p>",
        table(headers, rows, marked=[j in named for j in range(n)]),
    )
