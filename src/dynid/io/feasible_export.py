"""What a robot file written of a consistent fit holds: one rule for every route.

:func:`result_export` turns a :class:`~dynid.feasibility.result.FeasibleResult` into the
robot and the :class:`~dynid.io.robot.export_options.ExportOptions` its files are written
with: the robot with the fitted model's friction and springs
(:func:`~dynid.io.feasible.fitted_robot`), the friction identified with the links (its
law, offsets included, at the joints or the motors), the drive (its rotor inertias the
identified ones: MJCF ``armature``, the TOML ``[drive]`` table; a URDF, which holds none,
says so in a warning by joint with their share of the joint's inertia), and the lines at
the top of every file (a fit that was not accepted, structurally combined coefficients,
motors of unknown torque scale, rotor inertias the structure left out). The output folder
of ``dynid retrieve`` and ``identify --consistent``
(:func:`~dynid.io.feasible_bundle.save_feasible_bundle`) and
:func:`dynid.io.export.save_robot` of a result both write through it.
"""

from __future__ import annotations

import logging
from typing import Any

from ..feasibility.result import FeasibleResult
from ..identification.structural import combined_notes
from ..model.robot import Robot
from ..progress import NOTE
from .feasible import (
    armature_left_out,
    armature_left_out_note,
    combined_coefficients,
    fitted_robot,
    rejection_caveat,
    result_rejection,
    unknown_scale_caveat,
)
from .robot.export_options import ExportOptions

__all__ = ["result_export"]

_log = logging.getLogger(__name__)


def result_export(
    result: FeasibleResult,
    *,
    unknown_scale: str | None = None,
    source: str | None = None,
    said: str = "robot file",
) -> tuple[Robot, ExportOptions]:
    """The robot and the export options of ``result``'s robot files.

    Parameters
    ----------
    result : FeasibleResult
        A retrieval or a one-step consistent fit.
    unknown_scale : str, optional
        The finding on the motors whose torque constants the data leave unknown, said at
        the top of each file.
    source : str, optional
        The file written beside that holds the friction exactly (``feasible.json``),
        named by the writers' warnings.
    said : str
        How the note of the rotor inertias left out names the files (``"robot files"``).

    Returns
    -------
    robot : Robot
        :func:`~dynid.io.feasible.fitted_robot` of ``result``.
    options : ExportOptions
        ``friction`` the result's (True: the robot's own, when it holds none), ``drive``
        the result's, ``source``, and ``caveat`` the lines at the top of the file (None:
        none).
    """
    reason = result_rejection(result)
    notes = combined_notes(combined_coefficients(result))  # not the motors' own friction alone
    caveats = ([] if reason is None else [rejection_caveat(reason)]) + list(notes[:1])
    if unknown_scale is not None:
        caveats.append(unknown_scale_caveat(unknown_scale))
    robot = fitted_robot(result)
    left = armature_left_out_note(robot.joint_names, result.drive, armature_left_out(result))
    if left is not None:  # one note for the files, and a line atop each
        _log.log(NOTE, "%s: %s", said, left)
        caveats.append(left)
    friction: Any = True if result.friction is None else result.friction
    options = ExportOptions(
        friction=friction,
        drive=result.drive,
        source=source,
        caveat="; ".join(caveats) if caveats else None,
    )
    return robot, options
