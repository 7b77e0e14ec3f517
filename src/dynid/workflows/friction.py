"""Fit friction to a model's torque residual on a log file: the entry point of
``dynid friction``, with every policy the command applies, so that the Python API behaves
as the command does.

* The log is read strictly with the model's joint count, through the column map the
  model's data were read with when none is given (:mod:`dynid.workflows.data_files`).
* The drive is the model's own, or the one given when the model has none (another one is
  refused, :func:`~dynid.friction.fit.model_drive`).
* ``law="auto"`` fits every law of the registry on held-out blocks and keeps the best, the
  model's own friction a candidate too (:func:`~dynid.friction.select.select_friction`);
  a law's name fits that law (:func:`~dynid.friction.fit.fit_friction_through`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..exceptions import OptionError
from ..friction.fit import (
    FrictionFit,
    FrictionResidual,
    fit_friction_through,
    friction_residual,
    model_drive,
)
from ..friction.laws import LAWS
from ..friction.select import FrictionSelection, select_friction
from ..friction.validation import own_friction, recorded_cutoff
from ..identification.model import IdentifiedModel
from ..model.drive import Drive
from ..model.robot import Robot
from .data_files import ColumnSpec, column_map, in_file, read_torque_log, recorded_columns

__all__ = ["FrictionFileResult", "fit_friction_file"]


@dataclass(frozen=True, slots=True, eq=False)
class FrictionFileResult:
    """Result of :func:`fit_friction_file`.

    Attributes
    ----------
    fit : FrictionFit
        The friction kept (``selection.fit`` with ``law="auto"``), fitted on the whole log.
    residual : FrictionResidual
        The prepared log and the model's torque residual the friction was fitted to.
    selection : FrictionSelection or None
        Every candidate's training and held-out error (``law="auto"``), else None.
    cutoff_hz : float or None
        The low-pass cut-off the log was prepared with [Hz].
    """

    fit: FrictionFit
    residual: FrictionResidual
    selection: FrictionSelection | None
    cutoff_hz: float | None = None


def fit_friction_file(
    model: IdentifiedModel | Robot,
    path: str | Path,
    *,
    law: str = "auto",
    columns: ColumnSpec | None = None,
    drop_invalid: bool = False,
    drive: Drive | None = None,
    cutoff_hz: float | None = None,
    max_gap_s: float | None = None,
) -> FrictionFileResult:
    """Friction fitted to the torque residual of ``model`` on the log ``path``.

    Parameters
    ----------
    model : IdentifiedModel or Robot
        The rigid-body model (an identified model, or a robot's own link parameters).
    path : str or Path
        A torque log (``.csv`` or ``.npz``), or another tool's file read through
        ``columns``.
    law : str
        ``"auto"`` (the law with the lowest held-out error) or a law of
        :data:`~dynid.friction.laws.LAWS` (``--friction-model``).
    columns : (str or None, str or None), optional
        ``--columns`` and ``--units``; default: those the model's data were read with.
    drop_invalid : bool
        Drop rows with NaN/inf or a repeated timestamp (counted) instead of failing.
    drive : Drive, optional
        The drive the log was recorded through, for a model without one.
    cutoff_hz : float, optional
        Zero-phase low-pass cut-off of the states [Hz] (and of velocities derived from
        positions); default: the identification's recorded one, else the one read from the
        log's motion (:func:`~dynid.friction.validation.recorded_cutoff`).
    max_gap_s : float, optional
        Longest gap bridged by interpolation [s].

    Returns
    -------
    FrictionFileResult

    Raises
    ------
    OptionError
        ``law`` neither ``"auto"`` nor a law of the registry.
    DataError
        A bad file, another joint count, invalid rows without ``drop_invalid``, other
        columns or another drive than the model's, or no joint moving beyond its velocity
        noise band (the message starts with the file's name).
    """
    if law != "auto" and law not in LAWS:
        raise OptionError(f"--friction-model must be auto or one of {', '.join(LAWS)}; got {law!r}")
    path = Path(path)
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    recorded = model.info.column_map if isinstance(model, IdentifiedModel) else None
    names, units = recorded_columns(recorded, *(columns or (None, None)))
    log = read_torque_log(
        path,
        robot.n,
        columns=column_map(names, units, cutoff_hz=cutoff_hz),
        drop_invalid=drop_invalid,
        owner="the model",
    )
    drive = model_drive(model, drive)
    if cutoff_hz is None:
        cutoff_hz = recorded_cutoff(model, log)

    def fit() -> FrictionFileResult:
        res = friction_residual(model, log, cutoff_hz=cutoff_hz, max_gap_s=max_gap_s, drive=drive)
        if law == "auto":
            here = isinstance(model, IdentifiedModel) and path.name in {
                str(r.get("file")) for r in model.info.recordings
            }
            sel = select_friction(res, drive, own=own_friction(model), own_fitted_here=here)
            return FrictionFileResult(sel.fit, res, sel, cutoff_hz)
        return FrictionFileResult(fit_friction_through(res, drive, law), res, None, cutoff_hz)

    result: FrictionFileResult = in_file(path, fit)
    return result
