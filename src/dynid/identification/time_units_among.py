"""Recordings whose time columns are in different units, read in one run.

One recording logged in milliseconds among recordings in seconds (a logger changed
between sessions) is told apart by its velocities
(:func:`~dynid.identification.unit_mix.time_unit_read`); ``--units t=ms`` would read the
others wrong. :func:`time_units_hint` writes the ``--units`` that reads each in its own:
the unit most of them are in for every file (``t=ms``; nothing for seconds) and a file's
own entry for each of the others (``rec4.csv:t=ms``), in place of the time entries given.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence

from .angle_time_units import units_with

__all__ = ["time_units_hint", "time_units_said"]


def time_units_hint(names: Sequence[str], units: Sequence[str], text: str | None) -> str | None:
    """The ``--units`` text that reads every recording's time column in its own unit, or
    None when they are all in one.

    Parameters
    ----------
    names : sequence of str
        The recordings' file names, as ``--data`` gives them (without their folder).
    units : sequence of str
        The ``--units t=`` spelling of each one's time unit (``s``, ``ms``, ``us``, ``ns``).
    text : str, optional
        The ``--units`` given: its other entries kept, its time entries (``t=``,
        ``FILE:t=``) replaced.

    Returns
    -------
    str or None
        ``"rec4.csv:t=ms"`` for one file in ms among files in s; ``"t=ms,rec1.csv:t=s"``
        for one in s among files in ms (a tie: seconds for every file).
    """
    if len(set(units)) < 2:
        return None
    counts = Counter(units)
    most = max(counts.values())
    top = [u for u in dict.fromkeys(units) if counts[u] == most]
    every = "s" if "s" in top else top[0]
    kept = [
        p.strip()
        for p in (text or "").split(",")
        if p.strip() and p.partition("=")[0].strip().rpartition(":")[2].strip() != "t"
    ]
    out = ",".join(kept)
    if every != "s":
        out = units_with(out, {"t": every})
    own = [(f"{n}:t", u) for n, u in zip(names, units, strict=True) if u != every]
    return units_with(out, own)


def time_units_said(names: Sequence[str], units: Sequence[str]) -> str:
    """``rec4.csv in ms, rec1.csv, rec2.csv, rec3.csv in s``: the recordings grouped by
    the unit of their time column, the fewest first."""
    groups: dict[str, list[str]] = {}
    for n, u in zip(names, units, strict=True):
        groups.setdefault(u, []).append(n)
    order = sorted(groups, key=lambda u: len(groups[u]))
    return ", ".join(
        f"{', '.join(groups[u][:4])}{', ...' if len(groups[u]) > 4 else ''} in {u}" for u in order
    )
