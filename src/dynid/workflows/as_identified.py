"""How ``identify`` read its torque logs, applied by the commands that read logs for its
model (``validate``, ``friction``, ``observe``, ``payload``): rows with NaN/inf or a
repeated timestamp dropped (``--drop-invalid``) and the longest gap bridged
(``--max-gap``), each unless given, with one note naming what the record applies.

The identification's record is its :class:`~dynid.identification.info.LogInfo`
(``identification.json``'s metadata ``drop_invalid`` and ``max_gap_s``); a model of
static data, or a robot, has none; a ``feasible.json`` has that of the
``identification.json`` beside it (:func:`identification_beside`).
"""

from __future__ import annotations

import logging
from pathlib import Path

from ..exceptions import DataError
from ..identification.info import LogInfo
from ..identification.model import IdentifiedModel
from ..io.model_json import load_model_json
from ..model.robot import Robot
from ..progress import NOTE

__all__ = ["identification_beside", "read_as_identified"]

_log = logging.getLogger(__name__)


def read_as_identified(
    record: LogInfo | None,
    drop_invalid: bool,
    max_gap_s: float | None,
    *,
    gap_applied: bool = True,
) -> tuple[bool, float | None]:
    """``drop_invalid`` and ``max_gap_s`` [s] as given, else as ``record`` says identify
    read its logs, with one note naming the options applied from it
    (``using the identification's --drop-invalid, --max-gap 0.05 s``).

    Parameters
    ----------
    record : LogInfo or None
        The identification's record of its logs (None: a robot, static data).
    drop_invalid : bool
        Given: drop invalid rows (False: not given; the record's is applied).
    max_gap_s : float or None
        Given longest gap bridged [s] (None: the record's, else the default rule).
    gap_applied : bool
        Whether the caller applies the record's gap (True) or only says it, its
        preparation reading it from the model itself (the returned gap then still the one
        given).

    Returns
    -------
    drop_invalid : bool
    max_gap_s : float or None
        [s]; None: the default rule
        (:func:`~dynid.identification.log.default_max_gap`).
    """
    if record is None:
        return drop_invalid, max_gap_s
    said = []
    if record.drop_invalid and not drop_invalid:
        said.append("--drop-invalid")
        drop_invalid = True
    if record.max_gap_s is not None and max_gap_s is None:
        said.append(f"--max-gap {record.max_gap_s:g} s")
        max_gap_s = float(record.max_gap_s) if gap_applied else None
    if said:
        _log.log(
            NOTE,
            "using the identification's %s (as identify read its logs; "
            "identification.json's metadata)",
            ", ".join(said),
        )
    return drop_invalid, max_gap_s


def identification_beside(feasible: str | Path, robot: Robot) -> IdentifiedModel | None:
    """The model of the ``identification.json`` in the folder of ``feasible`` (``identify
    --consistent`` writes both) whose robot has ``robot``'s joints, or None (none there,
    not readable, another arm): the record of how the data the consistent parameters were
    fitted to were read and prepared."""
    path = Path(feasible).with_name("identification.json")
    if path == Path(feasible) or not path.is_file():
        return None
    try:
        mine = load_model_json(path)
    except DataError:
        return None
    return mine if mine.robot.joint_names == robot.joint_names else None
