"""The files of a retrieval or a consistent fit: ``feasible.json``, ``robot.urdf``,
``robot.xml`` (MJCF), ``robot.toml`` and ``report.json`` in one folder.

Written alike by ``dynid retrieve``, ``dynid identify --consistent`` and the demo's
feasible stage. The robots carry the friction of the fitted model
(:func:`~dynid.io.feasible.fitted_robot`): the one a one-step fit identified with the links
(the law of its structure, at the joints or, with a drive whose friction acts there, at the
motors, or both), none when it fitted a torque log without friction, else the input robot's.
Rotor inertias the identified structure left out while it kept others are 0 in the robot
files: one note names their joints, and each file says so at its top
(:func:`~dynid.io.feasible.armature_left_out_note`).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..feasibility.result import FeasibleResult
from ..identification.structural import combined_notes
from ..progress import NOTE
from .export import ROBOT_FORMATS, ExportOptions, save_robot_files
from .feasible import (
    armature_left_out,
    armature_left_out_note,
    combined_coefficients,
    fitted_robot,
    rejection_caveat,
    result_rejection,
    save_feasible_json,
    unknown_scale_caveat,
)
from .report_json import save_report_json

__all__ = ["FEASIBLE_BUNDLE", "save_feasible_bundle"]

_log = logging.getLogger(__name__)

#: The files :func:`save_feasible_bundle` writes, in order: feasible.json, one robot file
#: per export format (:data:`~dynid.io.export.ROBOT_FORMATS`: robot.urdf, robot.xml,
#: robot.toml), report.json.
FEASIBLE_BUNDLE = (
    "feasible.json",
    *(f"robot{f.suffixes[0]}" for f in ROBOT_FORMATS.values()),
    "report.json",
)


def save_feasible_bundle(
    folder: str | Path,
    result: FeasibleResult,
    *,
    column_map: Mapping[str, Any] | None = None,
    unknown_scale: Mapping[str, Any] | None = None,
    **report_extra: Any,
) -> list[Path]:
    """Write :data:`FEASIBLE_BUNDLE` for ``result`` into ``folder``.

    Parameters
    ----------
    folder : str or Path
        An existing folder.
    result : FeasibleResult
        A retrieval (penalty method, :class:`~dynid.feasibility.penalty.result.RetrievalResult`)
        or a convex retrieval / one-step consistent fit
        (:class:`~dynid.feasibility.convex.result.ConsistentResult`).
    column_map : mapping, optional
        How the fit's data were read (``identification.json``'s ``column_map``), recorded
        in ``feasible.json``.
    unknown_scale : mapping, optional
        The motors whose torque constants the data leave unknown
        (:meth:`~dynid.workflows.gains_first.UnknownScale.as_dict`), recorded in
        ``feasible.json`` and said at the top of the robot files.
    **report_extra
        Extra keys of ``report.json`` (``source``, ``seed``), JSON values.

    Returns
    -------
    list of Path
        The files, in the order of :data:`FEASIBLE_BUNDLE`.

    Raises
    ------
    NonFiniteError
        A NaN or infinite number in a JSON file (named).
    """
    folder = Path(folder)
    recorded = {"column_map": column_map, "unknown_scale": unknown_scale}
    files = [save_feasible_json(folder / "feasible.json", result, **recorded)]
    friction: Any = True if result.friction is None else result.friction
    reason = result_rejection(result)
    notes = combined_notes(combined_coefficients(result))  # not the motors' own friction alone
    caveats = ([] if reason is None else [rejection_caveat(reason)]) + list(notes[:1])
    if unknown_scale is not None:
        caveats.append(unknown_scale_caveat(str(unknown_scale.get("finding", ""))))
    robot = fitted_robot(result)
    left = armature_left_out_note(robot.joint_names, result.drive, armature_left_out(result))
    if left is not None:  # one note for the three robot files, and a line atop each
        _log.log(NOTE, "robot files: %s", left)
        caveats.append(left)
    options = ExportOptions(
        friction=friction,
        drive=result.drive,
        source=files[0].name,
        caveat="; ".join(caveats) if caveats else None,
    )
    files += save_robot_files(folder, robot, options)
    files.append(save_report_json(folder / "report.json", result, **report_extra))
    return files
