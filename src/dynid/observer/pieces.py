"""A log as the observer may read it: pieces between its gaps, and positions that jump.

The residual integrates the measured torques from the momentum at its first sample: across
a gap (a stop of the recording longer than the gap rule ``identify`` cuts at, 2.5 median
steps by default) the momentum and the torques of the missing time are unknown, so the
observer starts again after it (:func:`pieces`; the residual is 0 at each piece's first
sample and no event spans a cut, :func:`~dynid.observer.detection.detect`'s ``restarts``).
A shorter step (a sample or two lost, a row dropped for NaN or inf) is bridged as
``identify`` bridges it: the observer's update takes any step ``T``
(:mod:`~dynid.observer.residual`), exact for an external torque constant over it, so it
carries on across the step with its actual length. Inside a piece, a
position that moves more than its recorded velocity allows over one step, beyond what the
noise and the stamps' jitter explain (samples lost under even stamps, an encoder glitch, a
re-homing), changes ``M(q)`` and ``g(q)`` at once: :func:`position_jumps` finds it
for a warning.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..identification.position_jumps import jump_steps, velocity_departure

__all__ = ["PositionJump", "pieces", "position_jumps"]


def pieces(t: ArrayLike, max_gap_s: float) -> NDArray[np.int64]:
    """First sample of every piece (K,) of the times ``t`` (N,) [s]: 0 and every sample
    after a step longer than ``max_gap_s`` [s] (the rule of
    :func:`~dynid.identification.pieces.split_at_gaps`); rows dropped where the step stays
    within it are bridged."""
    ta = _checks.as_array("t", t)
    starts = np.flatnonzero(np.diff(ta) > max_gap_s) + 1
    return np.concatenate([[0], starts]).astype(np.int64)


@dataclass(frozen=True, slots=True)
class PositionJump:
    """A position step inconsistent with the recorded velocity.

    Attributes
    ----------
    t : float
        Time of the sample after the step [s].
    joint : int
        0-based.
    size : float
        The step less what the velocity explains [rad or m].
    """

    t: float
    joint: int
    size: float


def position_jumps(
    t: ArrayLike,
    q: ArrayLike,
    dq: ArrayLike,
    starts: ArrayLike = (0,),
    jitter_s: float | None = None,
) -> list[PositionJump]:
    """Steps of ``q`` (N, n) that the velocity ``dq`` (N, n) does not explain, inside the
    pieces beginning at ``starts``: the rule of
    :func:`~dynid.identification.position_jumps.jump_steps` (a step departing from the
    recorded velocity's, ``d = q_k - q_{k-1} - T_k (dq_k + dq_{k-1}) / 2``, and from its
    neighbours', by more than
    :data:`~dynid.identification.position_jumps.JUMP_FACTOR` times the spread the noise and
    the stamps' jitter ``jitter_s`` [s] give it, and by more than
    :data:`~dynid.identification.position_jumps.JUMP_FLOOR`; None
    reads the jitter of ``t``); the first per joint and piece (of a glitch, the jump
    rather than the jump back), its size ``d``."""
    ta = _checks.as_array("t", t)
    N = ta.shape[0]
    qa, dqa = _checks.as_array("q", q), _checks.as_array("dq", dq)
    if N < 3:
        return []
    jumps = jump_steps(ta, qa, dqa, starts, jitter_s)
    bounds = np.concatenate([np.asarray(starts, dtype=np.int64), [N]])
    out = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        for j in range(qa.shape[1]):
            over = np.flatnonzero(jumps[a : b - 1, j])
            if over.size:  # the first: a glitch's jump, not its jump back
                k = a + int(over[0])
                d = velocity_departure(ta[k : k + 2], qa[k : k + 2, j], dqa[k : k + 2, j])
                out.append(PositionJump(float(ta[k + 1]), j, float(d[0])))
    return sorted(out, key=lambda x: (x.t, x.joint))
