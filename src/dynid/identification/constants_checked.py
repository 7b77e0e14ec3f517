"""What a log of motor currents told of its torque constants, as ``identify`` records it.

The held-out verdict's gains per motor (:mod:`~dynid.identification.drive_gains`) check
some motors' constants and leave others unchecked: a determined factor within
:data:`~dynid.identification.drive_gains.OFF` of 1 is not named (the description's masses
are rarely truer), so the constant it checks is known to that tolerance only; a motor whose
factor the data do not determine is not checked at all, its torques as right as the drive
file's constant. A load weighed later through the same constants (``dynid payload``)
carries their error: its mass and first moments are known to that, not to their standard
deviations. :func:`constants_record` makes the record ``identify`` writes to the model's
metadata (:data:`CONSTANTS_CHECKED`), :func:`recorded_constants` reads it back.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .drive_gains import OFF, DriveGains
from .model import IdentifiedModel

__all__ = ["CONSTANTS_CHECKED", "constants_record", "recorded_constants"]

#: The key of the record in an identification's metadata (``identification.json``).
CONSTANTS_CHECKED = "constants_checked"


def constants_record(gains: DriveGains | None) -> dict[str, Any] | None:
    """The record of what ``gains`` checked of a current log's torque constants:
    ``checked`` (the motors, from 1, whose factor the data determine, not named: known to
    ``within_percent``), ``corrected`` (from 1: named, the drive file's fix said),
    ``unchecked`` (from 1: not determined), ``within_percent`` [%] (:data:`OFF`), ``per``
    (``"motor"`` or ``"joint"``); None for a log of torques or no gains judged."""
    if gains is None or gains.effort != "current":
        return None
    determined = np.asarray(gains.determined, dtype=bool)
    corrected = {int(k) for k in gains.named}
    return {
        "checked": [int(k) + 1 for k in np.flatnonzero(determined) if int(k) not in corrected],
        "corrected": sorted(int(k) + 1 for k in corrected),
        "unchecked": [int(k) + 1 for k in np.flatnonzero(~determined)],
        "within_percent": 100 * OFF,
        "per": gains.per,
    }


def recorded_constants(model: object) -> dict[str, Any] | None:
    """The record of :func:`constants_record` in ``model``'s metadata, or None: not an
    identified model, none recorded (a log of torques, or an identification written before
    the record), or a record of another form."""
    if not isinstance(model, IdentifiedModel):
        return None
    got = model.info.extra.get(CONSTANTS_CHECKED)
    if not isinstance(got, dict):
        return None
    keys = ("checked", "unchecked", "within_percent")
    if not all(k in got for k in keys):
        return None
    return dict(got)
