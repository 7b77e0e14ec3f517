"""What a torque log's header holds when a signal's columns are missing: the columns it
does not use, and the ``--columns`` map that would read them.

Other tools name a joint signal's columns their own way: ROS ``sensor_msgs/JointState``
(``position``, ``velocity``, ``effort``), a vendor's ``torque``. Such a family, one column
per joint numbered ``1..n`` (``{i}``) or ``0..n-1`` (``{i0}``), is offered as the map that
reads it (``--columns 'tau=effort{i}'``), never read by itself: a JointState's ``effort``
is whatever its driver puts there, a joint torque on one arm and a motor current on
another, and a wrong column silently read is a wrong answer.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

__all__ = ["ALIASES", "column_hint", "joint_families", "position_count"]

#: Names other tools give a torque log's joint signals (lower case, without separators),
#: by dynid's name of the signal.
ALIASES: dict[str, tuple[str, ...]] = {
    "q": ("position", "pos", "jointposition", "q"),
    "dq": ("velocity", "vel", "jointvelocity", "qd", "qdot", "dq"),
    "tau": ("effort", "torque", "jointtorque", "jointeffort", "tau", "taumeasured", "tauj"),
}
#: How many unused columns a message names (families count as one).
SHOWN = 6


def joint_families(names: Sequence[str], n: int) -> dict[str, list[str]]:
    """The families of one column per joint in ``names``: ``--columns`` template ->
    its columns in joint order (``effort{i}`` -> ``effort1..effortn``, ``effort_{i0}`` ->
    ``effort_0..effort_{n-1}``); only families of exactly ``n`` columns."""
    found: dict[str, dict[int, str]] = {}
    for c in names:
        m = re.fullmatch(r"(.*?\D)?(\d+)", c)
        if m is not None:
            found.setdefault(m.group(1) or "", {})[int(m.group(2))] = c
    out = {}
    for prefix, cols in found.items():
        for first, field in ((1, "{i}"), (0, "{i0}")):
            if sorted(cols) == list(range(first, first + n)):
                out[prefix + field] = [cols[first + j] for j in range(n)]
    return out


def column_hint(
    names: Sequence[str],
    n: int,
    missing: Sequence[str],
    used: set[str],
    optional: Sequence[str] = (),
) -> str:
    """``; present but unused: ...; hint: ...`` for a header that lacks the columns of the
    signals ``missing`` (``"tau"``, ``"dq"``) of an ``n``-joint log.

    Parameters
    ----------
    names : sequence of str
        The header.
    n : int
        The joint count (from ``q1..qn``).
    missing : sequence of str
        The signals without their columns, dynid's names.
    used : set of str
        The columns the log reads.
    optional : sequence of str
        Signals the log may lack (the velocities of a positions-only log), mapped too when
        a family of their names is there.

    Returns
    -------
    str
        The unused columns (:data:`SHOWN` at most, a family as ``effort1..effort7``) and
        the ``--columns`` map of the families whose names are those of :data:`ALIASES`
        for a missing signal (one each; every missing signal found); else how to name or
        map the columns.
    """
    unused = [c for c in names if c not in used and not re.fullmatch(r"tau_ext\d*", c)]
    families = {t: cols for t, cols in joint_families(unused, n).items()}
    in_family = {c for cols in families.values() for c in cols}
    shown = [f"{cols[0]}..{cols[-1]}" for cols in families.values()]
    shown += [c for c in unused if c not in in_family]
    text = ""
    if shown:
        more = len(shown) - SHOWN
        text = f"; present but unused: {', '.join(shown[:SHOWN])}" + (
            f" and {more} more" if more > 0 else ""
        )
    if not missing:
        return text
    found = {}
    for signal in (*missing, *optional):
        fits = [t for t in families if _root(t) in ALIASES.get(signal, ())]
        if len(fits) == 1:
            found[signal] = fits[0]
    if all(s in found for s in missing):
        spec = ",".join(f"{s}={found[s]}" for s in ("q", "dq", "tau") if s in found)
        caveat = (
            " (check that they hold joint torques in N m: motor currents need --units "
            "tau=A and a --drive whose effort is current)"
            if "tau" in found
            else ""
        )
        spans = ", ".join(f"{s}1..{s}{n}" for s in ("q", "dq", "tau") if s in found)
        return f"{text}; hint: --columns '{spec}' reads them{caveat}, or name them {spans}"
    spans = ", ".join(f"{s}1..{s}{n}" for s in missing)
    return (
        f"{text}; hint: name the columns {spans} (the torque-log format of the docs), or "
        f"map yours with --columns ('tau=effort{{i}}': {{i}} counts joints from 1, {{i0}} "
        "from 0)"
    )


def position_count(names: Sequence[str]) -> int:
    """The joint count of a header without ``q1..qn`` read from a family of positions by
    another name (``position_0..position_6``: 7), 0 when there is none or several."""
    found: dict[str, set[int]] = {}
    for c in names:
        m = re.fullmatch(r"(.*?\D)?(\d+)", c)
        if m is not None and _root((m.group(1) or "") + "{") in ALIASES["q"]:
            found.setdefault(m.group(1) or "", set()).add(int(m.group(2)))
    counts = {len(k) for k in found.values() if k in ({*range(len(k))}, {*range(1, len(k) + 1)})}
    return counts.pop() if len(counts) == 1 else 0


def _root(template: str) -> str:
    """A family's name without its joint field and separators, lower case
    (``Effort_{i0}`` -> ``effort``)."""
    return re.sub(r"[^a-z]", "", template.split("{")[0].lower())
