"""An error that sits at low speed: the hint of a verdict.

Friction changes fastest near zero velocity: a Coulomb law steps there, a Stribeck law
peaks, a joint standing still holds any torque within its static friction. The velocities a
model is evaluated at are measured with noise and low-passed, which blurs where a sharp
step falls: on point-to-point motion with rests, the true arm and friction law predict a
new recording at 8 times the torque noise (a UR5, sharp Coulomb friction of 1-4 N m,
velocities with 1e-3 rad/s of noise), all of the excess within ~50 ms of each start and
stop, while the moving samples are at the noise. A verdict that blames "effects outside the
model" sends the user after terms the model already has. :func:`low_speed_hint` says where
the error sits and how far the model is from the noise elsewhere;
:func:`with_low_speed_hint` appends it to a verdict above the noise floor.

"Low speed" is a joint's velocity under :data:`LOW_SPEED_SHARE` of its RMS over the
prepared samples (standstill, reversals, the edges of a move); the error "above the noise"
of a joint is its squared torque error less its sensor noise's variance, summed over the
samples.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .verdict import FLOOR_FAIR, FLOOR_GOOD, Verdict, with_hint

__all__ = ["LOW_SPEED_SHARE", "MOSTLY", "low_speed_hint", "with_low_speed_hint"]

#: A joint's velocity is low under this share of its RMS over the prepared samples.
LOW_SPEED_SHARE = 0.05
#: The hint is given when at least this share of the error above the noise sits at low
#: speed.
MOSTLY = 0.5


def low_speed_hint(
    dq: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    noise_rms: NDArray[np.float64],
    joint_names: Sequence[str],
) -> str | None:
    """Where most of a prediction's error above the noise sits at low speed and the moving
    samples are within :data:`~dynid.identification.verdict.FLOOR_FAIR` times the noise,
    the sentence that says so (the share, the joints, the moving samples' error against
    the noise); None otherwise (an error also while moving: the model misses more than
    friction near zero velocity).

    Parameters
    ----------
    dq : sequence of ndarray, each (N_k, n)
        The velocities the model was evaluated at [rad/s], one array per piece.
    error : sequence of ndarray, each (N_k, n)
        Measured less predicted torques at the same samples [N m].
    noise_rms : ndarray, shape (n,)
        The sensors' noise per joint [N m].
    joint_names : sequence of str
    """
    v = np.concatenate([np.asarray(x, dtype=np.float64) for x in dq])
    e2 = np.concatenate([np.asarray(x, dtype=np.float64) for x in error]) ** 2
    var = np.asarray(noise_rms, dtype=np.float64) ** 2
    if v.shape[0] < 2 or not np.all(np.isfinite(var)) or not np.all(var > 0):
        return None
    slow = np.abs(v) < LOW_SPEED_SHARE * np.sqrt(np.mean(v**2, axis=0))
    excess = e2 - var
    total = np.sum(excess, axis=0)
    at_slow = np.sum(np.where(slow, excess, 0.0), axis=0)
    loud = np.sqrt(np.mean(e2, axis=0)) > FLOOR_GOOD * np.sqrt(var)  # joints above the noise
    if not np.any(loud) or not np.sum(total[loud]) > 0:
        return None
    share = float(np.sum(at_slow[loud]) / np.sum(total[loud]))
    if share < MOSTLY:
        return None
    which = [int(j) for j in np.flatnonzero(loud) if at_slow[j] >= MOSTLY * total[j]] or [
        int(np.flatnonzero(loud)[np.argmax(at_slow[loud])])
    ]
    where = (
        "every joint"
        if len(which) == len(joint_names)
        else "joint(s) " + ", ".join(joint_names[j] for j in which)
    )
    moving = ~slow[:, loud]
    elsewhere = np.sqrt(
        np.sum(np.where(moving, e2[:, loud], 0.0)) / np.sum(np.where(moving, var[loud], 0.0))
    )
    if elsewhere > FLOOR_FAIR:  # the model misses effects while the joints move too
        return None
    return (
        f"at low speed: {100 * min(share, 1.0):.0f} % of the error above the noise sits "
        f"where |dq| is under {100 * LOW_SPEED_SHARE:g} % of its RMS (standstill, reversals, "
        f"{100 * float(np.mean(slow[:, loud])):.0f} % of the samples) on {where}, the "
        f"moving samples at {elsewhere:.3g} x the noise: friction near zero velocity, "
        "whose step the velocities' noise and low-pass blur (the law's shape there, a "
        "standstill band or a Stribeck term can move it; the noise bounds it)"
    )


def with_low_speed_hint(
    verdict: Verdict,
    dq: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    noise_rms: NDArray[np.float64],
    joint_names: Sequence[str],
) -> Verdict:
    """``verdict`` with :func:`low_speed_hint` appended to its reason when it is above the
    noise floor (not ``"good"``) and the hint applies; else ``verdict`` itself."""
    if verdict.level == "good":
        return verdict
    return with_hint(verdict, low_speed_hint(dq, error, noise_rms, joint_names), ", ")
