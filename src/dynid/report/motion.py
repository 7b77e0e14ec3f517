"""Where a model is judged on motion it was not identified on, as the report says it.

``validate`` (and identify's held-out prediction of a ``--validate-on`` log) records the
joints a recording takes outside the positions and velocities of the training
(``outside_training`` of ``validation.json`` or ``heldout.json``:
:meth:`~dynid.identification.training_range.OutsideTraining.as_dict`), and says them in
its verdict's reason, followed, where the recording lies clearly outside the training's
poses, by the clause that puts the model's extrapolation before the cause the verdict
would otherwise name (:meth:`~dynid.identification.training_range.OutsideTraining.hedge`).
Both are appended to the reason's long sentence; the page takes them out of it and says
each as a fact of its own, titled, beside a table of the joints.

``observe`` records the logs that move a joint more than 3 times as fast as the model's
identification data (``beyond_identification`` of ``events.json``, and of
``thresholds.json``'s ``calibration``): said as a fact of the verdict with both speeds.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..identification.training_range import HEDGE_CLAUSE, OUTSIDE_CLAUSE
from .html import cell, esc, is_number, section, table

__all__ = [
    "HEDGE",
    "OUTSIDE",
    "beyond_fact",
    "outside_facts",
    "outside_section",
    "split_reason",
]

#: How the clause of a recording outside the training's motion begins, and the clause that
#: puts the extrapolation before the verdict's cause (the verdict's own words).
OUTSIDE, HEDGE = OUTSIDE_CLAUSE, HEDGE_CLAUSE


def split_reason(reason: str) -> tuple[str, str | None, str | None]:
    """A verdict's ``reason`` cut into the part before the outside clause, the clause's
    joints (after :data:`OUTSIDE`) and the hedge (after :data:`HEDGE`); the two last None
    where the reason holds none."""
    at = reason.find("; " + OUTSIDE)
    if at < 0:
        return reason, None, None
    head, tail = reason[:at], reason[at + 2 + len(OUTSIDE) :]
    cut = tail.find("; " + HEDGE)
    if cut < 0:
        return head, tail, None
    return head, tail[:cut], tail[cut + 2 + len(HEDGE) :]


def _records(doc: Any) -> list[dict[str, Any]]:
    """The joints of ``doc``'s ``outside_training`` (each a record with numbers)."""
    got = doc.get("outside_training") if isinstance(doc, dict) else None
    joints = got.get("joints") if isinstance(got, dict) else None
    if not isinstance(joints, list):
        return []
    return [
        j
        for j in joints
        if isinstance(j, dict)
        and is_number(j.get("joint"))
        and all(isinstance(j.get(k), list) and len(j[k]) == 2 for k in ("here", "training"))
    ]


def _name(names: Sequence[str], joint: Any) -> str:
    k = int(joint) - 1
    return names[k] if 0 <= k < len(names) else f"joint {int(joint)}"


def outside_facts(doc: Any, names: Sequence[str], said: str | None, hedge: str | None) -> list[str]:
    """The facts (HTML) of a recording outside the training's motion: the joints, each
    with the recording's range and the training's, the share of samples outside and how
    far (from ``doc``'s ``outside_training``; the verdict's clause ``said`` in a file
    without it), and ``hedge`` (the verdict's words that the cause it would name is not
    confirmed) where given; empty where neither names any."""
    found = _records(doc)
    if not found:
        head = [] if said is None else [f"<b>Outside the identification's motion</b>: {esc(said)}"]
        return head + ([f"<b>Cause not confirmed</b>: {esc(HEDGE + hedge)}"] if hedge else [])
    parts = []
    for j in found:
        unit = "rad" if j.get("kind") == "position" else "rad/s"
        (a, b), (c, d) = j["here"], j["training"]
        share, far = j.get("share_percent"), j.get("beyond")
        parts.append(
            f"{_name(names, j['joint'])} {esc(j.get('kind', ''))} {a:.3g}..{b:.3g} {unit} "
            f"(trained {c:.3g}..{d:.3g}"
            + (f"; {share:.3g} % of samples outside" if is_number(share) else "")
            + (f", up to {far:.2g} {unit} beyond" if is_number(far) else "")
            + ")"
        )
    out = [
        "<b>Outside the identification's motion</b>: " + esc("; ".join(parts)) + " (the model "
        'extrapolates there; per joint: <a href="#outside">table below</a>)'
    ]
    if hedge:
        out.append(f"<b>Cause not confirmed</b>: {esc(HEDGE + hedge)}")
    return out


def outside_section(doc: Any, names: Sequence[str]) -> str:
    """The titled table of the joints outside the training's motion (``doc``'s
    ``outside_training``): kind, the recording's range, the training's, how far beyond,
    the share of samples outside and whether clearly so; empty where none."""
    found = _records(doc)
    if not found:
        return ""
    rows = [
        [
            esc(_name(names, j["joint"])),
            esc(j.get("kind", "")),
            f"{cell(j['here'][0])} .. {cell(j['here'][1])}",
            f"{cell(j['training'][0])} .. {cell(j['training'][1])}",
            cell(j.get("beyond")),
            cell(j.get("share_percent")),
            cell(j.get("clear")),
        ]
        for j in found
    ]
    heads = [
        "joint", "kind", "recording [rad, rad/s]", "training [rad, rad/s]",
        "beyond the training, at most [rad, rad/s]", "samples outside [%]", "clearly outside",
    ]  # fmt: skip
    said = (
        "<p>The joints the recording takes outside the positions and velocities the model "
        "was identified on (m and m/s for a prismatic joint): there the model extrapolates, "
        "and its error says little about its terms.</p>"
    )
    return section("outside", "Outside the identification's motion", said, table(heads, rows))


def beyond_fact(doc: Any, notes: Sequence[str]) -> str | None:
    """A fact (HTML) of the logs moved more than 3 times as fast as the model's
    identification data (``doc``'s ``beyond_identification``, or its ``calibration``'s):
    per log, each joint's largest speed there and the identification's [rad/s], and what
    it means; None where the file names none, or where a note of the run already says each
    of its logs with the identification's speeds."""
    got = doc.get("beyond_identification") if isinstance(doc, dict) else None
    if got is None and isinstance(doc, dict) and isinstance(doc.get("calibration"), dict):
        got = doc["calibration"].get("beyond_identification")
    rows = [
        x
        for x in got or ()
        if isinstance(x, dict) and is_number(x.get("speed")) and is_number(x.get("identified"))
    ]
    if not rows:
        return None
    logs = list(dict.fromkeys(str(x.get("log", "?")) for x in rows))
    if all(any(f"{log}: " in n and "identification's data" in n for n in notes) for log in logs):
        return None  # a note of the run names them with both speeds
    said = "; ".join(
        f"{log}: "
        + ", ".join(
            f"{x.get('joint', '?')} up to {x['speed']:.3g} rad/s ({x['identified']:.3g} in "
            "the identification's data)"
            for x in rows
            if str(x.get("log", "?")) == log
        )
        for log in logs
    )
    calibrating = "beyond_identification" not in doc
    means = (
        "the thresholds hold the model's error at those speeds"
        if calibrating
        else "the model extrapolates there, and events there may be its error, not contacts"
    )
    return (
        "<b>Motion beyond the identification's data</b> (over 3 x as fast): "
        f"{esc(said)}: {esc(means)}"
    )
