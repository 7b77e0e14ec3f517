"""The positions and velocities a model was identified on, and a recording that leaves them.

A model identified where a joint moved only over part of its range has fitted its
parameters there: a parameter that the positions seen cannot tell from another (a torque
offset from a centre of mass when ``cos(q)`` hardly changed) is right only in combination,
and a recording at other poses is predicted by extrapolation. The record keeps each joint's
range of positions and of velocities over the samples used (``LogInfo.position_range``,
``LogInfo.velocity_range``: :func:`motion_ranges`); :func:`outside_training` finds the
joints a recording takes outside them, how far and for what share of its samples, and
:meth:`OutsideTraining.sentence` says them in one line. A recording lies *clearly* outside
on a joint (:meth:`OutsideTraining.clear`) when at least :data:`CLEAR_SHARE` of its samples
are outside, by up to at least :data:`CLEAR_SPAN` of the training's span (and
:data:`CLEAR_LEAST` in the joint's unit): a residual there is the model's extrapolation
before any cause it points to.

Units: positions [rad] (a prismatic joint's [m]), velocities [rad/s] ([m/s]), at the joints.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "endless_joints",
    "CLEAR_LEAST",
    "CLEAR_SHARE",
    "CLEAR_SPAN",
    "HEDGE_CLAUSE",
    "OUTSIDE_CLAUSE",
    "SPEED_TOLERANCE",
    "TOLERANCE",
    "OutsideTraining",
    "motion_ranges",
    "outside_training",
]

#: A sample is outside a joint's training range when beyond it by more than this share of
#: the range's span (and :data:`TOLERANCE_LEAST`): noise and filtering at the range's ends;
#: a velocity by :data:`SPEED_TOLERANCE` (a recording's peaks seldom match).
TOLERANCE = 0.02
SPEED_TOLERANCE = 0.25
#: The least margin [rad, rad/s; m, m/s] beyond a range that counts (a joint held still).
TOLERANCE_LEAST = 0.01
#: A joint clearly outside: at least this share of the recording's samples outside ...
CLEAR_SHARE = 0.2
#: ... by up to at least this share of the training's span ...
CLEAR_SPAN = 0.2
#: ... and at least this far [rad or m] (positions; velocities the same in rad/s or m/s).
CLEAR_LEAST = 0.05

#: How the clause of a recording outside the training's motion begins
#: (:meth:`OutsideTraining.sentence`; the report cuts the verdict's reason at it).
OUTSIDE_CLAUSE = "outside the identification's motion: "
#: How the clause begins that puts the extrapolation before the verdict's cause
#: (:meth:`OutsideTraining.hedge`).
HEDGE_CLAUSE = "the model extrapolates there first: "

Ranges = tuple[tuple[float, float], ...]


def motion_ranges(pieces: Sequence[ArrayLike]) -> Ranges:
    """Each joint's ``(lowest, highest)`` over the samples of ``pieces`` ((N_k, n) each,
    positions [rad] or velocities [rad/s]); pieces without samples are skipped.

    Raises
    ------
    ValueError
        No piece holds a sample.
    """
    arrays = [np.asarray(p, dtype=np.float64) for p in pieces]
    arrays = [a for a in arrays if a.ndim == 2 and a.shape[0]]
    if not arrays:
        raise ValueError("no samples to take the ranges of")
    lo = np.min([a.min(axis=0) for a in arrays], axis=0)
    hi = np.max([a.max(axis=0) for a in arrays], axis=0)
    return tuple((float(a), float(b)) for a, b in zip(lo, hi, strict=True))


@dataclass(frozen=True)
class Outside:
    """One joint's samples outside one training range.

    Attributes
    ----------
    joint : int
        The joint (0-based).
    kind : str
        ``"position"`` or ``"velocity"``.
    here : (float, float)
        The recording's lowest and highest value [rad or rad/s].
    training : (float, float)
        The training's range.
    beyond : float
        How far the recording goes outside the range at most (> 0).
    share : float
        The share of the recording's samples outside, 0 to 1.
    """

    joint: int
    kind: str
    here: tuple[float, float]
    training: tuple[float, float]
    beyond: float
    share: float

    @property
    def clear(self) -> bool:
        """Clearly outside (module docstring)."""
        span = self.training[1] - self.training[0]
        far = max(CLEAR_SPAN * span, CLEAR_LEAST)
        return self.share >= CLEAR_SHARE and self.beyond >= far


@dataclass(frozen=True)
class OutsideTraining:
    """The joints a recording takes outside the training's positions and velocities.

    Attributes
    ----------
    found : tuple of Outside
        Per joint and kind, positions first.
    """

    found: tuple[Outside, ...]

    def clear(self, kind: str = "position") -> tuple[int, ...]:
        """The joints (0-based) clearly outside the training's ranges of ``kind``."""
        return tuple(sorted({o.joint for o in self.found if o.kind == kind and o.clear}))

    def sentence(self, joint_names: Sequence[str], units: Sequence[str] | None = None) -> str:
        """The joints outside, in one line: ``"outside the identification's motion: joint_2
        at 1.42..2 rad (trained 2.63..3.61; 100 % of samples outside, up to 1.2 rad
        beyond)"``; ``units`` per joint (position unit; default rad)."""
        parts = []
        for o in self.found:
            unit = "rad" if units is None else units[o.joint]
            unit = unit if o.kind == "position" else f"{unit}/s"
            parts.append(
                f"{joint_names[o.joint]} at {o.here[0]:.3g}..{o.here[1]:.3g} {unit} (trained "
                f"{o.training[0]:.3g}..{o.training[1]:.3g}; {100 * o.share:.3g} % of samples "
                f"outside, up to {o.beyond:.2g} {unit} beyond)"
            )
        return OUTSIDE_CLAUSE + "; ".join(parts)

    def concerned(self, joints: set[int]) -> tuple[int, ...]:
        """Of ``joints`` (0-based: those the residual concerns), those clearly outside the
        training's poses."""
        return tuple(sorted(set(self.clear("position")) & joints))

    @staticmethod
    def hedge(joints: Sequence[int], causes: Sequence[str], joint_names: Sequence[str]) -> str:
        """The clause that puts the extrapolation before the ``causes`` (in words; none:
        what the residual follows) the residual of ``joints`` would be given."""
        which = ", ".join(joint_names[j] for j in joints)
        cause = " or ".join(causes) if causes else "what it follows along the motion"
        return (
            f"{HEDGE_CLAUSE}the recording lies clearly outside the "
            f"identification's poses on {which}, so {cause} is not confirmed as the "
            "residual's cause; hint: validate on a recording within those poses, or identify "
            "from recordings that cover these poses too"
        )

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: per joint outside, ``joint`` (from 1), ``kind``, ``here``,
        ``training``, ``beyond``, ``share_percent`` and ``clear``."""
        return {
            "joints": [
                {
                    "joint": o.joint + 1,
                    "kind": o.kind,
                    "here": list(o.here),
                    "training": list(o.training),
                    "beyond": o.beyond,
                    "share_percent": 100 * o.share,
                    "clear": o.clear,
                }
                for o in self.found
            ]
        }


def _outside(
    kind: str,
    training: Ranges,
    values: Sequence[NDArray[np.float64]],
    turns: NDArray[np.bool_] | None = None,
) -> list[Outside]:
    """The joints whose ``values`` (pieces of (N_k, n)) leave ``training``'s ranges; of the
    joints ``turns`` (positions of joints that turn without end), the angles modulo a turn
    (:func:`_same_turn`)."""
    arrays = [np.asarray(v, dtype=np.float64) for v in values if len(v)]
    if not arrays:
        return []
    x = np.concatenate(arrays)
    if x.ndim != 2 or x.shape[1] != len(training):
        return []
    lo, hi = np.array(training).T
    if turns is not None and kind == "position":
        x = _same_turn(x, lo, hi, np.asarray(turns, dtype=bool))
    share = TOLERANCE if kind == "position" else SPEED_TOLERANCE
    margin = np.maximum(share * (hi - lo), TOLERANCE_LEAST)
    below, above = lo - margin - x, x - hi - margin
    out = []
    for j in range(x.shape[1]):
        outside = (below[:, j] > 0) | (above[:, j] > 0)
        if not outside.any():
            continue
        beyond = float(max(lo[j] - x[:, j].min(), x[:, j].max() - hi[j]))
        out.append(
            Outside(
                j,
                kind,
                (float(x[:, j].min()), float(x[:, j].max())),
                (float(lo[j]), float(hi[j])),
                beyond,
                float(np.mean(outside)),
            )
        )
    return out


def _same_turn(
    x: NDArray[np.float64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    turns: NDArray[np.bool_],
) -> NDArray[np.float64]:
    """Positions ``x`` (N, n) [rad] with the joints ``turns`` (n,) read as the angle, a
    whole number of turns away, nearest the middle of their training range ``lo..hi``
    (n,); one whose training covered a turn or more is inside it at every angle (a
    continuous joint trained over 2.5 turns was called outside at 1.68..16.9 rad for
    2.45..17.9)."""
    out = x.copy()
    turn = 2 * np.pi
    for j in np.flatnonzero(turns):
        if hi[j] - lo[j] >= turn:
            out[:, j] = np.clip(x[:, j], lo[j], hi[j])
        else:
            mid = 0.5 * (lo[j] + hi[j])
            out[:, j] = x[:, j] - turn * np.round((x[:, j] - mid) / turn)
    return out


def outside_training(
    position_range: Ranges | None,
    velocity_range: Ranges | None,
    q: Sequence[NDArray[np.float64]],
    dq: Sequence[NDArray[np.float64]],
    turns: ArrayLike | None = None,
) -> OutsideTraining | None:
    """The joints whose positions ``q`` or velocities ``dq`` (pieces of (N_k, n) [rad],
    [rad/s]) leave the training's ranges (``position_range``, ``velocity_range``: (n, 2)
    each, None: not recorded) by more than the tolerance (module docstring); None when
    none does or nothing is recorded. ``turns`` (n,) bool: the joints that turn without
    end (:func:`endless_joints`), whose positions are compared modulo a turn."""
    found: list[Outside] = []
    ends = None if turns is None else np.asarray(turns, dtype=bool)
    if position_range is not None:
        found += _outside("position", position_range, q, ends)
    if velocity_range is not None:
        found += _outside("velocity", velocity_range, dq)
    found.sort(key=lambda o: (o.joint, o.kind != "position"))
    return OutsideTraining(tuple(found)) if found else None


def endless_joints(q_min: ArrayLike, q_max: ArrayLike, prismatic: ArrayLike) -> NDArray[np.bool_]:
    """The revolute joints whose limits ``q_min..q_max`` [rad] (n,) span a turn or more
    (a continuous joint: infinite limits), of the ``prismatic`` (n,) flags: their angle
    is the same a turn away."""
    span = np.asarray(q_max, dtype=np.float64) - np.asarray(q_min, dtype=np.float64)
    return ~np.asarray(prismatic, dtype=bool) & (span >= 2 * np.pi * (1.0 - 1e-9))
