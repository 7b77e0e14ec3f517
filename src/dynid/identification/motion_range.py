"""A recording that moves a joint beyond the motion the model was identified on: the hint
of a verdict.

A model identified on data in which a joint hardly moved has not identified that joint's
friction and rotor inertia (they are left out, zero) and has seen its velocity-dependent
terms only near rest; a recording that moves the joint fast is predicted by extrapolation
(a 6-joint arm identified with joint 4 held still: "poor, joint 4 at 11 x its noise: the
model misses effects the data show", with no word that it never moved). The record keeps
each joint's largest speed over the samples used (``LogInfo.speed_max``);
:func:`motion_range_hint` names the joints a recording moves more than
:data:`BEYOND` times as fast.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .verdict import Verdict, with_hint

__all__ = ["BEYOND", "motion_range_hint", "with_motion_range_hint"]

#: A joint moved more than this many times as fast as in the identification's data is
#: named.
BEYOND = 3.0


def motion_range_hint(
    speed_max: ArrayLike | None,
    dq: Sequence[NDArray[np.float64]],
    joint_names: Sequence[str],
) -> str | None:
    """The joints that the velocities ``dq`` (pieces of (N_k, n) [rad/s]) move more than
    :data:`BEYOND` times as fast as the identification's largest speeds ``speed_max``
    (n,) [rad/s], with both speeds and the hint; None when there are none or no record."""
    if speed_max is None or not dq:
        return None
    ident = np.asarray(speed_max, dtype=np.float64).ravel()
    here = np.max([np.max(np.abs(np.asarray(x)), axis=0) for x in dq if len(x)], axis=0)
    if here.shape != ident.shape:
        return None
    beyond = [int(j) for j in np.flatnonzero(here > BEYOND * ident)]
    if not beyond:
        return None
    which = ", ".join(
        f"{joint_names[j]} up to {here[j]:.3g} rad/s here, {ident[j]:.3g} in the "
        "identification's data"
        for j in beyond
    )
    return (
        f"joint(s) {which}: the model predicts their motion by extrapolation (a joint that "
        "hardly moved has its friction and rotor inertia left out); hint: identify from "
        "recordings that move every joint as this one does"
    )


def with_motion_range_hint(
    verdict: Verdict,
    speed_max: ArrayLike | None,
    dq: Sequence[NDArray[np.float64]],
    joint_names: Sequence[str],
) -> Verdict:
    """``verdict`` with :func:`motion_range_hint` appended when it is above the noise floor
    (not ``"good"``) and the hint applies; else ``verdict`` itself."""
    if verdict.level == "good":
        return verdict
    return with_hint(verdict, motion_range_hint(speed_max, dq, joint_names))
