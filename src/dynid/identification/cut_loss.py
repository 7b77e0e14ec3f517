"""What cutting recordings at their gaps cost, said once: the pieces left out and the hint.

A recording is cut at every gap longer than the longest bridged (``--max-gap``, default
:func:`~dynid.identification.log.default_max_gap`: 2.5 median steps); each piece is
filtered on its own and trimmed at both ends, and a piece too short for that is left out
(:func:`~dynid.identification.pieces.skipped_piece`). Dropped samples with a jittery clock
make many gaps just past the limit, and the cuts then cost many samples that a slightly
longer ``--max-gap`` keeps. :func:`left_out_finding` says it in one line for every piece
left out: how many, of which recordings, the samples they held and those trimmed at the
cuts, the gaps cut at, and, when some are a few sample steps (at most
:data:`SHORT_GAP_STEPS`), the ``--max-gap`` that bridges those (:func:`bridging_gap`);
holes of seconds stay cuts, with no hint.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .._times import stamp_text
from .log import TorqueLog, default_max_gap

__all__ = ["SHORT_GAP_STEPS", "bridging_gap", "cut_gaps", "left_out_finding"]

#: A gap of at most this many median sample steps is dropped samples, which ``--max-gap``
#: may bridge; a longer one is a hole in the recording.
SHORT_GAP_STEPS = 10.0

#: Pieces left out named one by one up to this many; more are counted per recording.
_NAMED = 3


def cut_gaps(pieces: Sequence[TorqueLog]) -> NDArray[np.float64]:
    """The gaps [s] between consecutive pieces of one recording, in order (k - 1 of k)."""
    return np.array([b.t[0] - a.t[-1] for a, b in zip(pieces[:-1], pieces[1:], strict=True)])


def bridging_gap(gaps: NDArray[np.float64], step: float) -> float | None:
    """The ``--max-gap`` [s] that bridges every gap of ``gaps`` [s] at most
    :data:`SHORT_GAP_STEPS` sample steps ``step`` [s] long: the longest of them plus half a
    step, rounded up to two significant digits; None when none is that short."""
    short = gaps[gaps <= SHORT_GAP_STEPS * step]
    if not short.size or step <= 0:
        return None
    value = float(np.max(short)) + 0.5 * step
    scale = 10.0 ** (math.floor(math.log10(value)) - 1)
    return math.ceil(value / scale - 1e-9) * scale


def _trimmed_at_cuts(piece: TorqueLog, trim_s: float, first: bool, last: bool) -> int:
    """Samples of ``piece`` within ``trim_s`` of an end that is a cut (not the
    recording's own start or end)."""
    t = piece.t
    start = np.zeros(t.shape, dtype=bool) if first else t < t[0] + trim_s
    end = np.zeros(t.shape, dtype=bool) if last else t > t[-1] - trim_s
    return int(np.sum(start | end))


def left_out_finding(
    names: Sequence[str],
    pieces: Sequence[tuple[int, TorqueLog]],
    left: Sequence[tuple[int, str]],
    trim_s: float | None,
    max_gap_s: float | None,
) -> str | None:
    """One line for every piece left out (module docstring), or None when none was.

    Parameters
    ----------
    names : sequence of str
        The recordings' names.
    pieces : sequence of (int, TorqueLog)
        Every piece in order with its recording (index into ``names``).
    left : sequence of (int, str)
        The pieces left out (index into ``pieces``) and why.
    trim_s : float, optional
        Seconds trimmed at each end of a piece (None: 0).
    max_gap_s : float, optional
        The longest gap bridged as given [s] (None: the default rule).
    """
    if not left:
        return None
    out = {k for k, _ in left}
    lost = sum(pieces[k][1].n_samples for k in out)
    reasons = "; ".join(dict.fromkeys(why for _, why in left))
    if len(left) <= _NAMED:
        said = "; ".join(
            f"{names[pieces[k][0]]}: piece t = {stamp_text(pieces[k][1].t[0])}-"
            f"{stamp_text(pieces[k][1].t[-1])} s "
            f"({pieces[k][1].n_samples} samples)"
            for k, _ in left
        )
        msg = f"{said} left out: {reasons}"
    else:
        per = {names[pieces[k][0]]: 0 for k, _ in left}
        for k, _ in left:
            per[names[pieces[k][0]]] += 1
        counts = ", ".join(f"{name} {c}" for name, c in per.items())
        msg = f"{len(left)} pieces ({counts}; {lost} samples) left out: {reasons}"
    return msg + _cuts(names, pieces, out, lost, trim_s or 0.0, max_gap_s)


def _cuts(
    names: Sequence[str],
    pieces: Sequence[tuple[int, TorqueLog]],
    out: set[int],
    lost: int,
    trim_s: float,
    max_gap_s: float | None,
) -> str:
    """What the cuts cost and the ``--max-gap`` that keeps it (:func:`left_out_finding`)."""
    gaps, trimmed, steps, recorded = [], 0, [], sum(p.n_samples for _, p in pieces)
    for r in range(len(names)):
        mine = [k for k, (rr, _) in enumerate(pieces) if rr == r]
        gaps.append(cut_gaps([pieces[k][1] for k in mine]))
        for i, k in enumerate(mine):
            steps.append(np.diff(pieces[k][1].t))
            if k not in out:
                trimmed += _trimmed_at_cuts(pieces[k][1], trim_s, i == 0, i == len(mine) - 1)
    g = np.concatenate(gaps)
    if not g.size:
        return ""
    step = float(np.median(np.concatenate(steps)))
    limit = default_max_gap(step) if max_gap_s is None else float(max_gap_s)
    said = (
        f"; the recordings were cut at {g.size} gap(s) of {g.min():.3g}-{g.max():.3g} s "
        f"({g.min() / step:.2g}-{g.max() / step:.2g} sample steps of {step:.3g} s) longer "
        f"than the {limit:.3g} s bridged, which cost {lost + trimmed} of their {recorded} "
        f"samples ({lost} in the pieces left out, {trimmed} trimmed at the cuts)"
    )
    value = bridging_gap(g, step)
    if value is None:
        return said
    short = int(np.sum(g <= SHORT_GAP_STEPS * step))
    rest = "" if short == g.size else f"; the {g.size - short} longer, holes, stay cuts"
    return said + f"; hint: --max-gap {value:.2g} bridges the {short} short one(s){rest}"
