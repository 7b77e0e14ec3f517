"""A cut-off too high for velocities derived from positions: the hint of a verdict.

A log without velocity columns gets its velocities, and the accelerations, from the
zero-phase filtered derivatives of its positions at the cut-off of the step that prepares
it. The positions' noise passes the first derivative with a gain that grows about as the
cut-off's 1.5th power and the second as its 2.5th: at a cut-off well above the one read from
the motion (:func:`~dynid.identification.trim.common_cutoff`) the derived accelerations'
noise becomes a share of the torque error, which the verdict would blame on effects outside
the model (an xArm7 at 100 Hz, positions only, ``--cutoff 12`` against the 5.25 Hz read
from the motion: held-out 1.39 %, 2.13 x the noise floor, against 0.64 % with the true
velocities at the same cut-off and 0.80 % at 5.25 Hz). :func:`derived_cutoff_hint` says
so, with the remedy; a verdict above the floor carries it
(:func:`with_derived_cutoff_hint`).
"""

from __future__ import annotations

from collections.abc import Sequence

from .log import TorqueLog
from .trim import common_cutoff
from .verdict import Verdict, with_hint

__all__ = ["DERIVED_CUTOFF_RATIO", "derived_cutoff_hint", "with_derived_cutoff_hint"]

#: A cut-off above this many times the one read from the motion makes velocities and
#: accelerations derived from positions noticeably noisy (the accelerations' noise about
#: 2.8 times that at the motion's cut-off).
DERIVED_CUTOFF_RATIO = 1.5


def derived_cutoff_hint(logs: Sequence[TorqueLog], cutoff_hz: float | None) -> str | None:
    """The hint for logs whose velocities were derived from their positions at
    ``cutoff_hz`` [Hz], more than :data:`DERIVED_CUTOFF_RATIO` times the cut-off read from
    their motion; None otherwise (measured velocities, no cut-off, or none read).

    Parameters
    ----------
    logs : sequence of TorqueLog
        The logs as read (``dq_derived`` says whose velocities were derived).
    cutoff_hz : float or None
        The cut-off [Hz] the logs were prepared at.
    """
    derived = [log for log in logs if log.dq_derived]
    if cutoff_hz is None or not derived:
        return None
    motion = common_cutoff(derived)
    if motion is None or not cutoff_hz > DERIVED_CUTOFF_RATIO * motion:
        return None
    return (
        f"the velocities and accelerations derived from the positions at {cutoff_hz:.3g} Hz, "
        f"{cutoff_hz / motion:.2g} times the cut-off read from the motion ({motion:.3g} Hz), "
        f"carry the positions' noise; hint: lower --cutoff (toward {motion:.3g} Hz) or log "
        "the velocities"
    )


def with_derived_cutoff_hint(
    verdict: Verdict, logs: Sequence[TorqueLog], cutoff_hz: float | None
) -> Verdict:
    """``verdict`` with :func:`derived_cutoff_hint` appended to its reason (``..., or the
    velocities ...``) when it is above the noise floor (not ``"good"``) and the hint
    applies; else ``verdict`` itself."""
    if verdict.level == "good":
        return verdict
    return with_hint(verdict, derived_cutoff_hint(logs, cutoff_hz), ", or ")
