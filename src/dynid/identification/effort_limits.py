"""Logged torques beyond the description's effort limits.

A URDF's ``<limit effort=...>`` (a TOML's ``effort``, an MJCF's ``actuatorfrcrange``) is
what ``dynid excite`` keeps a trajectory's torques within and what an exported model
carries. A log whose torques run well past it says one of two things: the description's
limits are not this arm's (a placeholder, another variant's), or the torques' scale is off
(a unit, a torque constant, a gear ratio). Neither changes a fit, which uses no limit; both
are worth a line: a simulated TALOS arm logged at 1.7 x its URDF's effort on two joints
said nothing of it. :func:`effort_limit_finding` names the joints, their peaks and limits.

The peak is a high quantile of ``|tau|`` (:data:`PEAK_QUANTILE`), not the maximum: a
single spike (a sensor's, removed before fitting) is not the arm's torque.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from ..model.units import joint_unit

__all__ = ["LIMIT_SHARE", "PEAK_QUANTILE", "effort_limit_finding", "peak_efforts"]

#: A joint's peak is named where it exceeds its effort limit by this factor [1].
LIMIT_SHARE = 1.2
#: The quantile of ``|tau|`` taken as a joint's peak [1].
PEAK_QUANTILE = 0.999


def peak_efforts(taus: Sequence[NDArray[np.float64]]) -> NDArray[np.float64]:
    """Each joint's peak ``|tau|`` over every recording, shape (n,) [N m or N]: the
    :data:`PEAK_QUANTILE` quantile of the finite samples (NaN for a joint without any)."""
    stacked = np.abs(np.concatenate([np.asarray(t, dtype=float) for t in taus], axis=0))
    peaks = np.full(stacked.shape[1], np.nan)
    for j in range(stacked.shape[1]):
        col = stacked[:, j][np.isfinite(stacked[:, j])]
        if col.size:
            peaks[j] = float(np.quantile(col, PEAK_QUANTILE))
    return peaks


def effort_limit_finding(robot: Robot, taus: Sequence[NDArray[np.float64]]) -> str | None:
    """One line naming the joints whose logged (joint-side) torques exceed
    :data:`LIMIT_SHARE` times the robot's finite effort limit ``tau_max``, with each
    joint's peak, limit and ratio; None where no joint does (or none has a limit).

    Parameters
    ----------
    robot : Robot
        The model whose ``tau_max`` [N m or N per joint kind] the torques are held against.
    taus : sequence of ndarray, each shape (N_k, n)
        The recordings' joint-side torques [N m or N].
    """
    if not taus:
        return None
    peaks = peak_efforts(taus)
    limits = np.asarray(robot.tau_max, dtype=float)
    usable = np.isfinite(limits) & (limits > 0) & np.isfinite(peaks)
    # peak / share > limit: a placeholder limit near the float's largest (an export's
    # "no limit") never overflows
    over = np.flatnonzero(usable & (np.where(usable, peaks, 0.0) / LIMIT_SHARE > limits))
    if over.size == 0:
        return None
    units = [joint_unit("N m", bool(robot.prismatic[j])) for j in over]
    said = ", ".join(
        f"{robot.joint_names[j]} (peak {peaks[j]:.4g} {u}, limit {limits[j]:.4g} {u}: "
        f"{peaks[j] / limits[j]:.2g} x)"
        for j, u in zip(over, units, strict=True)
    )
    return (
        f"the logged torques exceed the description's effort limits on {said}: its limits "
        "are not this arm's (a placeholder, another variant's), or the torques' scale is "
        "off (a unit, a torque constant, a gear ratio); the fit uses no limit, but excite "
        "keeps its trajectories within them and exported models carry them"
    )
