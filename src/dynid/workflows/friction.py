"""Fit friction to a model's torque residual on a log file: the entry point of
``dynid friction``, with every policy the command applies, so that the Python API behaves
as the command does.

* The logs (one or more files, or a folder) are read strictly with the model's joint
  count, through the column map the model's data were read with when none is given
  (:mod:`dynid.workflows.recordings`); their invalid rows dropped and their gaps bridged as
  the identification's were, unless given (:mod:`dynid.workflows.as_identified`).
* Each recording, and each piece of one cut at a gap longer than ``max_gap_s``, is
  filtered and differentiated on its own (:func:`~dynid.friction.recordings.prepare_pieces`);
  the laws are fitted on the residual of every piece together.
* The drive is the model's own, or the one given when the model has none (another one is
  refused, :func:`~dynid.friction.fit.model_drive`).
* ``law="auto"`` fits every law of the registry on held-out blocks (one recording left
  out at a time when there are several, contiguous time blocks otherwise) and keeps the
  simplest within one standard error of the best, the model's own friction a candidate
  judged on the same blocks and kept as it is (a sum at the motors and joints too)
  (:func:`~dynid.friction.select.select_friction`);
  a law's name fits that law (:func:`~dynid.friction.fit.fit_friction_through`; the
  smooth law at the width :func:`~dynid.friction.select.choose_smooth_width` chooses on
  held-out blocks among the widths ``identify`` searches).
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from ..exceptions import DynidWarning
from ..friction.dissipative import ALLOWANCE_STD, law_violations
from ..friction.fit import FrictionFit, FrictionResidual, fit_friction_through
from ..friction.laws import LAWS
from ..friction.model import FrictionSum
from ..friction.recordings import Pieces, pieces_residual, prepare_pieces, thinned
from ..friction.select import (
    WIDTH_LAWS,
    FrictionSelection,
    choose_smooth_width,
    select_friction,
    torque_noise_std,
)
from ..friction.validation import RECORDED, own_friction
from ..identification.model import IdentifiedModel, checked_model
from ..identification.spikes import SPIKES_BEFORE_FIT
from ..model.drive import Drive
from ..model.robot import Robot
from .as_identified import read_as_identified
from .data_files import ColumnSpec, in_file
from .options import (
    Cutoff,
    check_choice,
    check_cutoff,
    check_number,
    checked_options,
    library_cutoff,
    velocity_cutoff,
)
from .recordings import despiked_recordings, read_recordings

__all__ = ["FrictionFileResult", "FrictionOptions", "fit_friction_files"]


@dataclass(frozen=True, slots=True)
class FrictionOptions:
    """How :func:`fit_friction_files` fits friction to a model's torque residual.

    Attributes
    ----------
    law : str
        ``"auto"`` (the law chosen on held-out data,
        :func:`~dynid.friction.select.select_friction`) or a law of
        :data:`~dynid.friction.laws.LAWS`.
    columns : (str or None, str or None), optional
        Column names and units of another tool's files; default: those the model's data
        were read with.
    drop_invalid : bool
        Drop rows with NaN/inf or a repeated timestamp (counted) instead of failing;
        False: as the identification did (:func:`~dynid.workflows.as_identified.
        read_as_identified`, with a note), else refused.
    drive : Drive, optional
        The drive the log was recorded through, for a model without one.
    cutoff_hz : float or "none", optional
        Zero-phase low-pass cut-off of the states [Hz] (and of velocities derived from
        positions); default: the identification's recorded one (no filter if it was
        identified without), else the one read from the log's motion
        (:func:`~dynid.friction.validation.recorded_cutoff`); ``"none"``
        (:data:`~dynid.workflows.options.NO_FILTER`): no low-pass.
    max_gap_s : float, optional
        Longest gap bridged by interpolation [s]; a longer one cuts a log into pieces;
        default: the identification's recorded one (a note names it), else the default
        rule.
    torque_delay_s : float, optional
        How far the torques lag the positions [s]: each piece's states read that much
        earlier before filtering
        (:attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`); default:
        the identification's recorded one, 0 for a robot.
    q_start : tuple of float, optional
        Joint positions [rad] at the first sample of one motor-side recording whose motor
        encoders wrap every turn: the motors' whole turns are those that put the joints
        nearest them (:func:`~dynid.workflows.recordings.given_start`).

    Raises
    ------
    OptionError
        ``law`` neither ``"auto"`` nor a law of the registry; a cut-off or gap that is not
        a positive number (``field`` names it).
    """

    law: str = "auto"
    columns: ColumnSpec | None = None
    drop_invalid: bool = False
    drive: Drive | None = None
    cutoff_hz: Cutoff = None
    max_gap_s: float | None = None
    q_start: tuple[float, ...] | None = None
    torque_delay_s: float | None = None

    def __post_init__(self) -> None:
        check_choice(self, "law", ("auto", *LAWS), optional=False)
        check_cutoff(self)
        check_number(self, "max_gap_s")
        check_number(self, "torque_delay_s", low=-1.0, high=1.0)


@dataclass(frozen=True, slots=True, eq=False)
class FrictionFileResult:
    """Result of :func:`fit_friction_files`.

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
    pieces : Pieces or None
        The recordings' prepared pieces (how many pieces and samples each file gave).
    noise_std : ndarray, shape (n,), or None
        Per joint, the white-noise std [N m] of the measured torques
        (:func:`~dynid.friction.select.torque_noise_std`): what ``rms_after`` reaches for
        a correct model; None when not known.
    decimate : int
        Every ``decimate``-th measured sample of each piece was fitted (the model's
        identification's decimation; 1: every sample).
    """

    fit: FrictionFit
    residual: FrictionResidual
    selection: FrictionSelection | None
    cutoff_hz: float | None = None
    pieces: Pieces | None = None
    noise_std: NDArray[np.float64] | None = None
    decimate: int = 1

    def metadata(self, model: str) -> dict[str, Any]:
        """The keys ``friction.json`` records beside the fit: the recordings, ``model``
        (what the rigid-body model is), the cut-off, the samples, the convergence and the
        torques' noise per joint (``noise_rms`` [N m])."""
        files = [s["file"] for s in self.pieces.summary()] if self.pieces else []
        return {
            "data": ", ".join(files),
            "files": files,
            "recordings": list(self.pieces.summary()) if self.pieces else [],
            "model": model,
            "cutoff_hz": self.cutoff_hz,
            "n_samples": self.fit.n_samples,
            "decimate": self.decimate,
            "converged": [bool(x) for x in self.fit.converged],
            "noise_rms": None if self.noise_std is None else [float(x) for x in self.noise_std],
        }


def fit_friction_files(
    model: IdentifiedModel | Robot,
    data: str | Path | Sequence[str | Path],
    options: FrictionOptions | None = None,
) -> FrictionFileResult:
    """Friction fitted to the torque residual of ``model`` on the logs ``data``.

    Parameters
    ----------
    model : IdentifiedModel or Robot
        The rigid-body model (an identified model, or a robot's own link parameters).
    data : str, Path or a sequence of them
        One or more torque logs (``.csv`` or ``.npz``; a folder: its data files), or
        files of another tool read through ``options.columns``.
    options : FrictionOptions, optional

    Returns
    -------
    FrictionFileResult

    Raises
    ------
    DataError
        A bad file, another joint count, invalid rows without ``drop_invalid``, other
        columns or another drive than the model's, a recording in other units or with no
        piece long enough to filter, or no joint moving beyond its velocity noise band
        (the message starts with the file's name).
    """
    checked_model(model)
    opt = checked_options(options, FrictionOptions)
    drop, gap = read_as_identified(
        model.info.log if isinstance(model, IdentifiedModel) else None,
        opt.drop_invalid,
        opt.max_gap_s,
    )
    opt = dataclasses.replace(opt, drop_invalid=drop, max_gap_s=gap)  # as identify read them
    law, columns, drop_invalid = opt.law, opt.columns, opt.drop_invalid
    drive, cutoff_hz, max_gap_s = opt.drive, opt.cutoff_hz, opt.max_gap_s
    path = data
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    rec = read_recordings(
        path,
        robot,
        recorded=model.info.column_map if isinstance(model, IdentifiedModel) else None,
        columns=columns,
        drop_invalid=drop_invalid,
        cutoff_hz=velocity_cutoff(cutoff_hz),
        owner="the model",
        drive=(model.drive if isinstance(model, IdentifiedModel) else None) or drive,
        q_start=opt.q_start,
        max_gap_s=max_gap_s,
        reference=model.equivalent_robot if isinstance(model, IdentifiedModel) else None,
        sign_map=True,
    )
    rec, _ = despiked_recordings(rec, robot.joint_names, SPIKES_BEFORE_FIT)  # as identify

    def fit() -> FrictionFileResult:
        pieces = prepare_pieces(
            model,
            rec.logs,
            rec.names,
            cutoff_hz=library_cutoff(cutoff_hz, RECORDED),
            max_gap_s=max_gap_s,
            drive=drive,
            decimate=1,  # every sample, at its own time: the torques validate judges
            measured_samples=True,
            torque_delay_s=opt.torque_delay_s,
        )
        every = _recorded_decimation(model)
        pieces = thinned(pieces, every)  # samples, not averages
        res = pieces_residual(model, pieces)
        cut = pieces.cutoff_hz
        if law == "auto":
            # the model identified from one of these recordings: its friction is judged by
            # its law refitted on the held-out folds' training data
            here = isinstance(model, IdentifiedModel) and bool(model.info.fitted_on(rec.names))
            # where it acts (a robot's where the drive puts it); a sum judged too
            own = own_friction(model, pieces.drive)
            sel = select_friction(
                res, pieces.drive, own=own, own_fitted_here=here, dq_max=robot.dq_max
            )
            noise = torque_noise_std(res)
            return FrictionFileResult(sel.fit, res, sel, cut, pieces, noise, every)
        width = choose_smooth_width(res, pieces.drive) if law in WIDTH_LAWS else None
        chosen = fit_friction_through(res, pieces.drive, law, width=width)
        if law == "quadratic":
            _quadratic_at_bound(chosen)
        _say_not_dissipative(chosen, robot.dq_max)
        return FrictionFileResult(chosen, res, None, cut, pieces, torque_noise_std(res), every)

    result: FrictionFileResult = in_file(rec.paths[0], fit) if len(rec.paths) == 1 else fit()
    return result


def _recorded_decimation(model: Robot | IdentifiedModel) -> int:
    """The decimation a model was identified with (1: a robot, or a model of static
    data): friction is fitted on every k-th measured sample alike."""
    if isinstance(model, IdentifiedModel) and model.info.log is not None:
        return max(1, int(model.info.log.preprocessing.decimate))
    return 1


def _quadratic_at_bound(fit: FrictionFit) -> None:
    """A warning when the quadratic law's ``fq`` sits on its bound 0 on joints it was
    identified on: the friction of the data grows slower than linearly with speed (it
    saturates), which ``fq >= 0`` (dissipative at every speed) cannot follow, so the law
    is the classical one there."""
    if isinstance(fit.friction, FrictionSum):
        return
    fq = np.asarray(fit.friction.params)[:, 1]
    held = [j + 1 for j in range(fq.size) if fit.identified[j] and fq[j] == 0.0]
    if held:
        warnings.warn(
            f"quadratic friction: fq held at its bound 0 on joint(s) "
            f"{', '.join(map(str, held))}: the friction of these data grows slower than "
            "linearly with speed (it saturates), which fq >= 0 cannot follow; there the law "
            "is the classical one (a saturating law follows it: sigmoid, smooth, stribeck)",
            DynidWarning,
            stacklevel=caller_level(),
        )


def _say_not_dissipative(fit: FrictionFit, dq_max: NDArray[np.float64]) -> None:
    """A warning, one line per joint (motor), where the law asked for by name is not
    dissipative within the velocity limits, its offset aside (the selection sets such a
    law aside: :func:`~dynid.friction.dissipative.law_violations`)."""
    allowance = fit.covariance is not None
    for v in law_violations(fit.friction, dq_max, fit.covariance):
        warnings.warn(
            f"{fit.kind} friction not dissipative within the velocity limits (the offset "
            "aside"
            + (
                f", by more than {ALLOWANCE_STD:g} standard deviations of the fit"
                if allowance
                else ""
            )
            + f"): {v}; the friction pushes the arm there (--friction-model auto sets "
            "such a law aside)",
            DynidWarning,
            stacklevel=caller_level(),
        )
