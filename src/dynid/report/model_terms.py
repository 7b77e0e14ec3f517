"""The identified model's appended terms (``terms`` of identification.json) as tables.

Every term the model holds beside the base parameters gets its table: friction at the
motors, friction at the joints (a coupled drive's ``at:both`` model holds both), the
armature or rotor inertia and a joint spring. Each row is a motor (the term acts at the
motors) or a joint; each column one kind of coefficient (``fv``, ``fc``, ``Ia``, ...) with
its unit, the value ``± std`` in each cell (``in beta1`` where the coefficient is
regrouped with link inertias into that base parameter: no value of its own). Files
without ``terms`` (written before it) show the top-level ``friction`` matrix: ``fv, fc,
fo`` per joint.
"""

from __future__ import annotations

import re
from typing import Any

from ..model.units import Joints, unit_said
from .html import capitalised, cell, esc, is_number, number, section, table

__all__ = ["terms_sections"]

#: The unit of each coefficient kind (the label without its joint number and prefix).
_UNITS = {
    "fv": "N m s/rad",
    "fq": "N m s^2/rad^2",
    "fc": "N m",
    "fsp": "N m",
    "fo": "N m",
    "Ia": "kg m^2",
}
_LABEL = re.compile(r"^(?P<code>[A-Za-z_]+?)(?P<index>\d+)$")


def _heading(term: dict[str, Any]) -> str:
    name = str(term.get("name", ""))
    definition = term.get("definition") or {}
    if term.get("kind") == "linear_friction":
        where = "the motors" if definition.get("at") == "motor" else "the joints"
        parts = definition.get("parts")
        law = ": " + " + ".join(map(str, parts)) if isinstance(parts, list) and parts else ""
        return f"{capitalised(name)} at {where}{esc(law)} (value \u00b1 std)"
    if term.get("kind") == "rotor_inertia":
        return f"{capitalised(name)}: armature or rotor inertia at the motors (value \u00b1 std)"
    return f"{capitalised(name)} (value \u00b1 std)"


def _unit(code: str, joints: Joints | None = None) -> str:
    """`` [unit]`` of a coefficient kind, said per kind of ``joints`` (none: at motors)."""
    unit = _UNITS.get(code) or _UNITS.get(code[1:], "")  # "jfv": friction at the joints
    return f" [{unit_said(joints, unit)}]" if unit else ""


def _joints(doc: dict[str, Any]) -> Joints | None:
    """The joints' names and kinds of an identification record's ``robot`` (None: not
    held)."""
    robot = doc.get("robot")
    if not isinstance(robot, dict):
        return None
    names, kinds = robot.get("joint_names"), robot.get("prismatic")
    if not (isinstance(names, list) and isinstance(kinds, list) and len(names) == len(kinds)):
        return None
    return Joints(tuple(str(x) for x in names), tuple(bool(x) for x in kinds))


def _term_table(
    term: dict[str, Any],
    joint_names: list[str],
    combined: dict[str, str] | None = None,
    joints: Joints | None = None,
) -> str:
    combined = combined or {}
    labels, values = term.get("labels") or [], term.get("values") or []
    std = term.get("std") or []
    held = term.get("regrouped_in") or []
    at_motors = term.get("kind") == "rotor_inertia" or (
        (term.get("definition") or {}).get("at") == "motor"
    )
    codes: list[str] = []
    rows: dict[int, dict[str, str]] = {}
    for k, lab in enumerate(labels):
        m = _LABEL.match(str(lab))
        code, index = (m["code"], int(m["index"])) if m else (str(lab), 0)
        if code not in codes:
            codes.append(code)
        s = std[k] if k < len(std) else None
        v = values[k] if k < len(values) else None
        holder = str(held[k]) if k < len(held) and held[k] else ""
        text = cell(v) + (f" &plusmn; {number(s, 2)}" if is_number(s) else "")
        text = f"in {esc(holder)} (regrouped)" if holder else text
        text += " (combined)" if str(lab) in combined else ""
        rows.setdefault(index, {})[code] = text
    body = []
    for index in sorted(rows):
        if at_motors:
            who = f"motor {index}"
        elif 0 < index <= len(joint_names):
            who = joint_names[index - 1]
        else:
            who = f"joint {index}"
        body.append([esc(who), *(rows[index].get(c, "") for c in codes)])
    kinds = None if at_motors else joints  # a motor turns: rad
    headers = ["motor" if at_motors else "joint", *(f"{c}{_unit(c, kinds)}" for c in codes)]
    mine = [str(lab) for lab in labels if str(lab) in combined]
    note = (
        "<p>combined: holds a coefficient left out as structurally dependent on it (no "
        "data tell them apart), not its own value alone: "
        + esc("; ".join(f"{lab} holds {combined[lab]}" for lab in mine))
        + "</p>"
        if mine
        else ""
    )
    regrouped = sorted({str(h) for h in held if h}, key=lambda h: (len(h), h))
    if regrouped:
        note += (
            f"<p>regrouped: in {esc(', '.join(regrouped))}, with link inertias (see the base "
            "parameters); the data give the sum, not this coefficient alone</p>"
        )
    return table(headers, body) + note


def _classical(doc: dict[str, Any], joint_names: list[str]) -> str:
    joints = _joints(doc)
    fr = doc.get("friction")
    if not isinstance(fr, list) or not fr:
        return ""
    std = (doc.get("metadata") or {}).get("friction_std") or []
    rows = []
    for j, row in enumerate(fr):
        cells = [esc(joint_names[j] if j < len(joint_names) else f"joint {j + 1}")]
        for k, v in enumerate(row):
            s = std[3 * j + k] if 3 * j + k < len(std) else None
            cells.append(cell(v) + (f" &plusmn; {number(s, 2)}" if is_number(s) else ""))
        rows.append(cells)
    headers = ["joint", *(f"{c}{_unit(c, joints)}" for c in ("fv", "fc", "fo"))]
    return section(
        "friction",
        "Friction identified with the coefficients (value \u00b1 std)",
        table(headers, rows),
    )


def terms_sections(doc: dict[str, Any]) -> list[str]:
    """One section per appended term of the identification record ``doc`` (its ``terms``),
    or the classical friction table of a record without them; empty without either."""
    robot = doc.get("robot") or {}
    names = [str(x) for x in robot.get("joint_names") or []] if isinstance(robot, dict) else []
    terms = doc.get("terms")
    if not isinstance(terms, list) or not terms:
        classical = _classical(doc, names)
        return [classical] if classical else []
    meta = doc.get("metadata") or {}
    combined = meta.get("combined") if isinstance(meta, dict) else None
    combined = {str(k): str(v) for k, v in combined.items()} if isinstance(combined, dict) else {}
    out: list[str] = []
    for k, term in enumerate(terms):
        if not isinstance(term, dict) or not term.get("labels"):
            continue
        anchor = "friction" if k == 0 and term.get("kind") == "linear_friction" else f"term-{k}"
        table = _term_table(term, names, combined, _joints(doc))
        out.append(section(anchor, _heading(term), table))
    return out
