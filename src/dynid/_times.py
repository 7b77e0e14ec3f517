"""Time stamps said in messages so that a user finds them in the file.

A log's time column may hold absolute stamps (seconds or milliseconds since midnight,
since the epoch): ``8.641e+04 s`` names no row. :func:`said_time` writes the stamp as the
file holds it, converted to seconds, to the millisecond (``t = 86412.300 s``), and its
offset from the log's first sample when the log does not start at 0
(``(11.3 s into rec1.csv)``). Times are in seconds.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = ["longest_gaps", "offset_text", "said_time", "said_times", "stamp_text"]

#: Decimals of a stamp said in seconds: milliseconds, the resolution of a log's stamps
#: at up to 1 kHz.
DECIMALS = 3


def stamp_text(t: float) -> str:
    """A stamp [s] to the millisecond (``86412.300``)."""
    return f"{float(t):.{DECIMALS}f}"


def offset_text(offsets: Sequence[float], t0: float | None, name: str | None = None) -> str:
    """``11.3 s into rec1.csv`` for offsets [s] from the log's start ``t0`` [s]; empty
    when ``t0`` is None or 0 (the stamps are the offsets)."""
    if t0 is None or float(t0) == 0.0:
        return ""
    into = f"into {name}" if name else "into the log"
    said = [f"{d:.4g}" if abs(d) < 1e4 else f"{d:.0f}" for d in map(float, offsets)]
    return f"{', '.join(said)} s {into}"


def _paren(text: str) -> str:
    return f" ({text})" if text else ""


def said_time(t: float, t0: float | None = None, name: str | None = None) -> str:
    """``t = 86412.300 s (11.3 s into rec1.csv)``: a stamp [s] as in the file, and its
    offset from ``t0`` [s], the log's first stamp (none said when ``t0`` is None or 0)."""
    return f"t = {stamp_text(t)} s" + _paren(offset_text([float(t) - float(t0 or 0.0)], t0, name))


def said_times(
    times: Sequence[float] | NDArray[np.float64],
    t0: float | None = None,
    name: str | None = None,
    *,
    shown: int = 3,
) -> str:
    """``t = 86412.300, 86415.100 s and 2 more (11.3, 14.1 s into rec1.csv)``: the first
    ``shown`` stamps [s] as :func:`said_time` says one."""
    head = [float(t) for t in list(times)[:shown]]
    more = len(times) - len(head)
    rest = f" and {more} more" if more > 0 else ""
    offsets = [t - float(t0 or 0.0) for t in head]
    return f"t = {', '.join(stamp_text(t) for t in head)} s{rest}" + _paren(
        offset_text(offsets, t0, name)
    )


def longest_gaps(
    gaps: Sequence[Sequence[float]], shown: int = 4
) -> tuple[list[tuple[float, float]], str]:
    """The ``shown`` longest of a recording's ``gaps`` (``[t_before, length]`` [s] each),
    in time order, and what is said of the others: ``" and 3 more, at most 0.03 s long"``
    (empty for none): a 2 s hole among many dropped samples is never among "the others"."""
    pairs = [(float(t), float(n)) for t, n in gaps]
    keep = sorted(sorted(range(len(pairs)), key=lambda k: -pairs[k][1])[:shown])
    rest = [pairs[k][1] for k in range(len(pairs)) if k not in set(keep)]
    more = f" and {len(rest)} more, at most {max(rest):.3g} s long" if rest else ""
    return [pairs[k] for k in keep], more
