"""A residual that is one constant over a recording: that recording's torque offset.

Joint torque sensors re-zeroed at each power-up give each recording its own offset; a
model predicts a new recording with the offset it was fitted with, and the difference is a
residual constant over the whole recording. A level that changes along the motion
(friction the law misses at some speeds, a drift) is not steady: its mean over the
recording's quarters differs. :func:`recording_levels` finds, per joint, the recordings
whose residual is steady (the means of :data:`SEGMENTS` consecutive parts within
:data:`STEADY` of the whole mean) and above a practical size (:data:`NOISE_FRACTION` of the
joint's noise), and the error with those constants removed; :func:`level_clause` says one
joint's in words.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: Consecutive parts a recording's residual is split into to judge whether it is steady.
SEGMENTS = 4
#: A steady level: every part's mean within this share of the whole mean from it.
STEADY = 0.25
#: A level told as an offset: above this share of the joint's noise [N m].
NOISE_FRACTION = 0.5


@dataclass(frozen=True)
class RecordingLevels:
    """Each recording's constant residual per joint, where it is one.

    Attributes
    ----------
    joints : tuple of int
        The joints (0-based) whose residual is a steady constant over the recordings.
    levels : ndarray, shape (R, n)
        Each recording's mean residual per joint [N m] (measured less predicted).
    percent : float
        The relative RMS error [%] over every sample (every joint) as judged.
    own_percent : float
        The same with each recording's constant removed on ``joints``.
    """

    joints: tuple[int, ...]
    levels: NDArray[np.float64]
    percent: float
    own_percent: float

    def of(self, joint: int) -> tuple[float, ...] | None:
        """Joint ``joint``'s constant per recording [N m], None where it is no offset."""
        return tuple(float(x) for x in self.levels[:, joint]) if joint in self.joints else None

    def sentence(self, joint_names: Sequence[str]) -> str:
        """The error with the recordings' own offsets, in one clause."""
        per = ", ".join(
            f"{joint_names[j]} " + "/".join(f"{x:+.2g}" for x in self.levels[:, j])
            for j in self.joints
        )
        return (
            f"with the recording's own torque offsets ({per} N m off the model's) the error "
            f"is {self.own_percent:.3g} % (of {self.percent:.3g} %): torque sensors zeroed "
            "anew at each power-up give each recording its own offset, which a model cannot "
            "know beforehand"
        )


def _steady(e: NDArray[np.float64]) -> NDArray[np.bool_]:
    """(n,): whether each column of ``e`` (N, n) keeps its mean over its parts."""
    if e.shape[0] < 4 * SEGMENTS:
        return np.zeros(e.shape[1], dtype=bool)
    mean = e.mean(axis=0)
    parts = np.array([p.mean(axis=0) for p in np.array_split(e, SEGMENTS)])
    return np.all(np.abs(parts - mean) <= STEADY * np.abs(mean), axis=0)


def recording_levels(
    error: Sequence[NDArray[np.float64]],
    torques: Sequence[NDArray[np.float64]],
    recording: Sequence[int],
    noise: NDArray[np.float64],
    joints: Collection[int] | None = None,
) -> RecordingLevels | None:
    """The joints (of ``joints``; None: every one) whose residual is one steady constant
    over each recording (module docstring); None where there is none.

    Parameters
    ----------
    error : sequence of ndarray, shape (N_k, n)
        Measured less predicted torques of each piece [N m].
    torques : sequence of ndarray, shape (N_k, n)
        The measured torques of the same pieces [N m].
    recording : sequence of int
        The recording of each piece (pieces of one recording in time order).
    noise : ndarray, shape (n,)
        The joints' torque noise [N m].
    joints : collection of int, optional
        The joints (0-based) judged: those whose model holds an offset, which a recording's
        own differs from (a model without one misses the constant itself).
    """
    rec = list(recording)
    if not error or len(rec) != len(error):
        return None
    whole = [
        np.concatenate(
            [np.asarray(e, dtype=np.float64) for e, k in zip(error, rec, strict=True) if k == r]
        )
        for r in sorted(set(rec))
    ]
    levels = np.array([e.mean(axis=0) for e in whole])
    big = np.abs(levels) > NOISE_FRACTION * np.asarray(noise, dtype=np.float64)
    steady = np.array([_steady(e) for e in whole])
    offset = big.any(axis=0) & np.all(steady | ~big, axis=0)
    if joints is not None:
        offset &= np.isin(np.arange(offset.size), list(joints))
    found = tuple(int(j) for j in np.flatnonzero(offset))
    if not found:
        return None
    e2 = own2 = 0.0
    for e, lv in zip(whole, levels, strict=True):
        own = e - np.where(offset, lv, 0.0)
        e2, own2 = e2 + float(np.sum(e**2)), own2 + float(np.sum(own**2))
    t2 = float(sum(np.sum(np.asarray(t, dtype=np.float64) ** 2) for t in torques))
    if not t2 > 0:
        return None
    pct = 100 * float(np.sqrt(e2 / t2))
    return RecordingLevels(found, levels, pct, 100 * float(np.sqrt(own2 / t2)))


def level_clause(
    head: str, mean: float, rms: float, level: Sequence[float], offset: tuple[str, bool] | None
) -> str:
    """One joint's residual that is a steady constant over each recording, said as the
    recording's torque offset differing from the model's (``offset``: its label and whether
    the model holds it; None: it has none there) by ``level`` [N m] per recording."""
    model = "the model's (none there)"
    if offset is not None:
        label, held = offset
        model = f"the model's {label}" if held else f"the model's (none: {label} left out)"
    by = ", ".join(f"{x:+.2g}" for x in level)
    return (
        f"{head}{abs(mean):.2g} of {rms:.2g} N m RMS residual is one constant over the "
        f"recording: its torque offset differs from {model} by {by} N m (a sensor zeroed "
        "anew at power-up), not an effect along the motion"
    )
