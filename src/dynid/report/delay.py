"""The torques' lag behind the positions, on the identify and validate pages.

A file's ``torque_delay`` (``validation.json``; ``identification.json``'s ``metadata``:
the record of :class:`~dynid.identification.torque_delay.TorqueDelay`, written when the
delay is named): the delay common to every joint [ms] with its standard deviation, said in
the verdict box before the residual's other hints (a lag leaves a residual that follows the
joints' velocities and accelerations, which those hints may read as friction or a
spring), and, where some joint's own delay stands clear of its standard deviation, a table
of those joints with the units and what the numbers are; a joint whose own estimate does
not stand clear (``null`` in the record) is not listed.
"""

from __future__ import annotations

from typing import Any

from ..identification.torque_delay import SIGNIFICANT, delay_decimals
from .html import esc, is_number, number, section, table

__all__ = ["delay_facts", "delay_section"]


def _record(doc: Any) -> dict[str, Any] | None:
    """The named ``torque_delay`` record of a file (top level or in ``metadata``), or None."""
    if not isinstance(doc, dict):
        return None
    rec = doc.get("torque_delay")
    if rec is None and isinstance(doc.get("metadata"), dict):
        rec = doc["metadata"].get("torque_delay")
    if not isinstance(rec, dict) or rec.get("named") is not True:
        return None
    if not (is_number(rec.get("delay_ms")) and is_number(rec.get("std_ms"))):
        return None
    return rec


def _names(doc: dict, n: int) -> list[str]:
    robot = doc.get("robot")
    names = doc.get("joint_names") or (
        robot.get("joint_names") if isinstance(robot, dict) else None
    )
    if isinstance(names, list) and len(names) == n and all(isinstance(x, str) for x in names):
        return names
    return [f"joint{j + 1}" for j in range(n)]


def delay_facts(doc: Any) -> list[str]:
    """The fact (HTML) of a named delay: the common delay [ms] with its standard deviation,
    and that the hints after it may be the lag; none without one."""
    rec = _record(doc)
    if rec is None:
        return []
    ms, sd = float(rec["delay_ms"]), float(rec["std_ms"])
    d = delay_decimals(sd)  # as the summary says it
    return [
        f"<b>The torques {'lag' if ms > 0 else 'lead'} the positions by "
        f"{abs(ms):.{d}f} ms</b> (std {sd:.{d}f} ms): the residual's other hints "
        "below may be this lag, which follows the joints' velocities and accelerations; "
        f"--torque-delay {ms:.{d}f} takes it out before filtering"
    ]


def delay_section(doc: Any) -> str:
    """The table of each joint's own delay [ms] where it stands clear, or "" (no named
    delay, or no joint's own estimate clear)."""
    rec = _record(doc)
    if rec is None:
        return ""
    assert isinstance(doc, dict)
    own, std = rec.get("joints_ms"), rec.get("joints_std_ms")
    if not (isinstance(own, list) and isinstance(std, list) and len(own) == len(std)):
        return ""
    names = _names(doc, len(own))
    rows = [
        [esc(names[j]), number(float(own[j]), 3), number(float(std[j]), 2)]
        for j in range(len(own))
        if is_number(own[j]) and is_number(std[j])
    ]
    if not rows:
        return ""
    said = (
        f"The torques' lag behind the positions [ms], read from each joint's residual alone, "
        f"for the joints whose own estimate stands {SIGNIFICANT:g} standard deviations clear; "
        f"the delay common to every joint, {number(float(rec['delay_ms']), 3)} ms (std "
        f"{number(float(rec['std_ms']), 2)} ms), is the one --torque-delay takes."
    )
    return section(
        "torque-delay",
        "Torque delay per joint",
        f"<p>{esc(said)}</p>",
        table(["joint", "delay [ms]", "std [ms]"], rows),
    )
