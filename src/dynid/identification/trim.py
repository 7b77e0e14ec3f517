"""The samples each piece of a recording keeps: the one cut-off read from the recordings'
motion and the seconds trimmed at both ends of every filtered piece.

One rule for identification (:func:`~dynid.identification.recordings.prepare_recordings`),
validation and the friction fit (:mod:`dynid.friction.recordings`), so that a model is
judged on the very samples identification prepared from the same recording:

* :func:`common_cutoff`: each recording's cut-off read from its pieces on its own time
  axis (:func:`~dynid.identification.rate.cutoff_from_motion`), the median over the
  recordings weighted by their samples;
* :func:`edge_seconds`: what :func:`~dynid.signals.edge_seconds` trims at each end of a
  piece filtered at the cut-off: half a period when the motion lies a decade below it (the
  cut-off read from the motion, or the motion read from the pieces for a cut-off given
  or recorded; :func:`~dynid.signals.lowpass` continues each end with its cubic), two
  periods otherwise and for velocities derived from positions (filtered twice);
* :func:`within_edges`: the samples a piece keeps after that trim.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .. import signals
from ..exceptions import DataError
from .log import TorqueLog
from .rate import CUTOFF_MULTIPLE, bridged, cutoff_from_motion

__all__ = ["common_cutoff", "edge_seconds", "within_edges"]


def common_cutoff(
    pieces: Sequence[TorqueLog],
    recording: Sequence[int] | None = None,
    turns: NDArray[np.bool_] | None = None,
) -> float | None:
    """The cut-off [Hz] read from the motion of the recordings
    (:func:`~dynid.identification.rate.cutoff_from_motion`): each recording's read from
    its pieces on its own time axis (:func:`~dynid.identification.rate.bridged`, the
    columns ``turns`` moved by whole turns across its gaps), the median over the
    recordings, each weighted by its samples; None when no recording holds 64 samples.

    ``recording`` gives each piece's recording (default: every piece its own, read alone).
    A recording whose cut-out stretches are longer than what was kept is read from its
    pieces of at least 64 samples, each on its own, weighted by its samples.
    """
    labels = list(range(len(pieces))) if recording is None else [int(r) for r in recording]
    found: list[float] = []
    weight: list[int] = []
    for r in dict.fromkeys(labels):
        mine = [p for p, k in zip(pieces, labels, strict=True) if k == r]
        grid = None
        if len(mine) > 1 and sum(p.n_samples for p in mine) >= 64:
            grid = bridged([p.t for p in mine], [p.q for p in mine], [p.dq for p in mine], turns)
        if grid is not None:
            dq = np.concatenate([p.dq for p in mine])
            found.append(cutoff_from_motion(grid[0], dq, grid[1]))
            weight.append(sum(p.n_samples for p in mine))
            continue
        for piece in mine:
            if piece.n_samples < 64:
                continue
            try:
                found.append(cutoff_from_motion(piece.q, piece.dq, piece.sample_rate))
            except DataError:
                if len(pieces) == 1:
                    raise
                continue
            weight.append(piece.n_samples)
    if not found:
        return None
    order = np.argsort(found)
    cum = np.cumsum(np.asarray(weight, dtype=np.float64)[order])
    return float(np.asarray(found)[order][np.searchsorted(cum, 0.5 * cum[-1])])


def edge_seconds(
    pieces: Sequence[TorqueLog],
    recording: Sequence[int],
    cutoff_hz: float | None,
    *,
    from_motion: bool = False,
    turns: NDArray[np.bool_] | None = None,
) -> float | None:
    """The seconds trimmed at each end of every piece filtered at ``cutoff_hz`` [Hz]
    (module docstring; :func:`~dynid.signals.edge_seconds`).

    Parameters
    ----------
    pieces : sequence of TorqueLog
        The pieces at the joints, before filtering.
    recording : sequence of int
        Each piece's recording.
    cutoff_hz : float or None
        The one cut-off; None: no filter, nothing trimmed (None returned).
    from_motion : bool
        The cut-off was read from these pieces' motion (:func:`common_cutoff`): the motion
        lies a decade below it. Else (given, or recorded with a model) the motion is read
        from the pieces here.
    turns : ndarray of bool, shape (n,), optional
        Columns moved by whole turns across a recording's gaps (:func:`common_cutoff`).

    Returns
    -------
    float or None
        Half a period of the cut-off when the motion lies a decade or more below it, two
        periods otherwise (a motion the pieces do not tell, velocities derived from
        positions); None without a cut-off.
    """
    if cutoff_hz is None:
        return None
    if any(p.dq_derived for p in pieces):
        return signals.edge_seconds(cutoff_hz)
    motion = cutoff_hz / CUTOFF_MULTIPLE if from_motion else _motion_hz(pieces, recording, turns)
    return signals.edge_seconds(cutoff_hz, motion)


def _motion_hz(
    pieces: Sequence[TorqueLog], recording: Sequence[int], turns: NDArray[np.bool_] | None
) -> float | None:
    """The motion's highest significant frequency [Hz] of the pieces (as a cut-off read
    from the motion reads it, :func:`common_cutoff`), None when no piece tells it."""
    try:
        found = common_cutoff(pieces, recording, turns)
    except DataError:
        return None
    return None if found is None else found / CUTOFF_MULTIPLE


def within_edges(t: NDArray[np.float64], trim_s: float) -> int:
    """Samples of ``t`` more than ``trim_s`` [s] from both of its ends (as
    :func:`~dynid.signals.trim_edges` keeps them)."""
    lo = np.searchsorted(t, t[0] + trim_s, side="left")
    hi = np.searchsorted(t, t[-1] - trim_s, side="right")
    return int(max(0, hi - lo))
