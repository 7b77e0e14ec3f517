"""The files of a retrieval or a consistent fit: ``feasible.json``, ``robot.urdf``,
``robot.xml`` (MJCF), ``robot.toml`` and ``report.json`` in one folder.

Written alike by ``dynid retrieve``, ``dynid identify --consistent`` and the demo's
feasible stage. The robots carry the friction of the fitted model
(:func:`~dynid.io.feasible.fitted_robot`): the one a one-step fit identified with the links
(the law of its structure, at the joints or, with a drive whose friction acts there, at the
motors, or both), none when it fitted a torque log without friction, else the input robot's.
Rotor inertias the identified structure left out while it kept others are 0 in the robot
files: one note names their joints, and each file says so at its top
(:func:`~dynid.io.feasible.armature_left_out_note`). The robot files are written by the
rule :func:`dynid.io.export.save_robot` of the result follows too
(:func:`~dynid.io.feasible_export.result_export`).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..feasibility.result import FeasibleResult
from .export import ROBOT_FORMATS, save_robot_files
from .feasible import save_feasible_json
from .feasible_export import result_export
from .report_json import save_report_json

__all__ = ["FEASIBLE_BUNDLE", "save_feasible_bundle"]

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
    finding = None if unknown_scale is None else str(unknown_scale.get("finding", ""))
    robot, options = result_export(
        result, unknown_scale=finding, source=files[0].name, said="robot files"
    )
    files += save_robot_files(folder, robot, options)
    files.append(save_report_json(folder / "report.json", result, **report_extra))
    return files
