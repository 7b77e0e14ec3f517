"""Classical identification from the torque log of an exciting trajectory (Gaz et al. 2019).

Sec. IV-B of the paper:

.. math:: \\tau_k = Y_b(q_k, \\dot q_k, \\ddot q_k)\\, \\beta + F(\\dot q_k)\\, f,
          \\qquad f_j = (f_{v,j}, f_{c,j}, f_{o,j})

stacked over samples ``k`` and solved by ordinary least squares
(:func:`~dynid.identification.least_squares.fit_least_squares`, the same estimator and
statistics as the static route). ``Y_b`` is the torque regressor reduced to the base
parameters of ``base_parameters(robot, kind="torque")``; ``F`` holds the classical
friction of each joint (eq. 24), ``fv dq_j + fc sign(dq_j) + fo`` in the row of joint
``j`` only. Columns are ordered ``beta1 .. beta_r`` then ``fv1, fc1, fo1, fv2, ...``;
rows sample-major (row ``k n + j`` is sample ``k``, joint ``j``).

Pipeline: :func:`~dynid.identification.prepare.prepare_log` (resample if needed, zero-phase
low-pass of ``q``, ``dq``, ``tau``, ``ddq`` from the filtered ``dq``, trim the edges), then
**decimation**: after the low-pass at ``cutoff_hz`` the signals hold nothing above a few
times the cutoff, so keeping every ``k``-th sample with ``fs / k >= 10 cutoff_hz`` loses no
information and divides the cost of the regressor and of the least squares by ``k``
(the "parallel filtering and decimation" of Gautier, Khalil and coworkers). The
statistics then also assume less correlated residuals. ``decimate=1`` keeps every sample.
By default the cut-off and the decimation are read from the log
(:mod:`dynid.identification.rate`: 10 times the motion's highest significant frequency,
and at least 10 % of the samples kept).
Gaz et al. report a condition number of 122 and a relative error of 1.4 % for this route
on the real Panda.

A single log is one recording of :func:`~dynid.identification.selection.identify_recordings`
(:func:`identify_from_log`): prepared, judged on held-out data (the torques as measured)
and, by default (``structure="auto"``, ``estimator="auto"``), its terms and its estimator
chosen exactly as ``dynid identify`` chooses them on the log's file; with
``structure="classical"`` the terms above (:func:`classical_structure`).
"""

from __future__ import annotations

from typing import Literal

import numpy as np

from ..exceptions import OptionError, WrongTypeError
from ..model.drive import Drive
from ..model.robot import Robot, checked_robot
from ..regressors.base import BaseParameters
from ..regressors.terms import friction_labels
from .estimators import Estimator, EstimatorName
from .holdout import DEFAULT_FOLDS
from .least_squares import StdMethod
from .log import TorqueLog, checked_log
from .log_rows import (
    friction_regressor,
    log_blocks,
    parallel_filtered,
    still_columns,
    term_regressor,
)
from .model import IdentifiedModel
from .prepared_log import PreparedLog, prepare_torque_log
from .selection import identify_recordings
from .structure import Structure

__all__ = [
    "PreparedLog",
    "log_blocks",
    "parallel_filtered",
    "still_columns",
    "auto_decimation",
    "classical_structure",
    "friction_labels",
    "friction_regressor",
    "identify_from_log",
    "prepare_torque_log",
    "term_regressor",
]

_ = friction_labels  # re-exported: the labels of friction_regressor

#: The parts of the classical friction, eq. 24 of Gaz et al. 2019.
_CLASSICAL = ("viscous", "coulomb", "offset")


def auto_decimation(fs: float, cutoff_hz: float | None) -> int:
    """Largest ``k`` with ``fs / k >= 10 cutoff_hz`` (1 without filtering)."""
    if cutoff_hz is None:
        return 1
    return max(1, int(np.floor(fs / (10.0 * cutoff_hz))))


def classical_structure(drive: Drive | None = None, friction: bool = True) -> Structure:
    """The terms of the classical route (module docstring): the drive's rotor inertias where
    it identifies them and, with ``friction``, the classical friction ``fv, fc, fo`` per joint
    (motor) where the drive says (``dynid identify --terms viscous,coulomb,offset``, with
    ``armature`` before them for a drive whose rotor inertias are identified)."""
    armature = drive is not None and drive.identifies_rotor_inertia
    return Structure(armature=armature, friction=_CLASSICAL if friction else ())


def _one_log(log: object) -> TorqueLog:
    """``log`` when it is one :class:`TorqueLog`; a list of them named with the function
    that takes several (:func:`~dynid.identification.log.checked_log` otherwise)."""
    if isinstance(log, list | tuple):
        raise WrongTypeError(
            f"log: expected a TorqueLog, got a {type(log).__name__} of {len(log)}; several "
            "recordings go to dynid.workflows.identify.identify_logs, which keeps each apart"
        )
    return checked_log(log)


def identify_from_log(
    robot: Robot,
    log: TorqueLog,
    *,
    structure: Structure | Literal["auto", "classical"] = "auto",
    cutoff_hz: float | Literal["auto"] | None = "auto",
    trim_s: float | None = None,
    max_gap_s: float | None = None,
    decimate: int | None = None,
    max_std_percent: float | None = None,
    friction: bool = True,
    base: BaseParameters | None = None,
    rtol: float | None = None,
    drive: Drive | None = None,
    estimator: EstimatorName | Estimator | Literal["auto"] = "auto",
    std: StdMethod = "hac",
    folds: int = DEFAULT_FOLDS,
    validate_on: TorqueLog | None = None,
) -> IdentifiedModel:
    """Identify base parameters (and the model's terms) from a torque log: the log as the one
    recording of :func:`~dynid.identification.selection.identify_recordings` (prepared,
    fitted and judged on held-out data as ``dynid identify`` does on the log's file).

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity; its inertial parameters are not used.
    log : TorqueLog
        Measured ``t``, ``q``, ``dq``, ``tau`` (``ddq`` optional) of an exciting trajectory.
    structure : Structure, "auto" or "classical"
        The terms beside the links: ``"auto"`` (default) chosen on held-out data
        (:func:`~dynid.identification.selection.select_structure`: rotor inertias,
        friction laws and their parts), as ``dynid identify`` chooses them without
        ``--terms``; ``"classical"`` those of :func:`classical_structure` (``friction``
        says whether with the classical friction), ``dynid identify --terms
        viscous,coulomb,offset``; or the terms given.
    cutoff_hz : float, "auto" or None
        Zero-phase low-pass cutoff [Hz] (:func:`~dynid.identification.prepare.prepare_log`);
        ``"auto"`` (default) reads it from the motion
        (:func:`~dynid.identification.trim.common_cutoff`); None for noise-free data
        (then ``ddq`` of the log is used if present, else differentiated).
    trim_s, max_gap_s, decimate, max_std_percent, rtol, drive, std, folds
        As :func:`~dynid.identification.selection.identify_recordings` (``folds``: the
        contiguous time blocks of the held-out judgement).
    estimator : {"auto", "ols", "wls", "irls"} or Estimator
        ``"auto"`` (default): ordinary or weighted least squares chosen on the held-out
        folds, as ``dynid identify`` chooses (:mod:`~dynid.identification.estimator_choice`).
    friction : bool
        With ``structure="classical"``: identify ``fv, fc, fo`` per joint together with
        the base parameters. False with another structure is refused.
    base : BaseParameters, optional
        Base parameters to use with a structure given or the classical one; default
        ``base_parameters(robot, kind="torque")`` of its terms.
    validate_on : TorqueLog, optional
        A separate recording (same joints, read the same way) that the held-out error is
        measured on instead of the blocks.

    Returns
    -------
    IdentifiedModel
        ``fit`` holds the ``r`` base parameters (with the statistics of the whole fit:
        condition number, relative error, sigma); the terms (``rotor_inertia``,
        ``friction`` of the law chosen; ``friction`` with ``fv, fc, fo`` per joint with
        ``"classical"``); ``info`` the preparation (``info.log``), the held-out errors on
        the torques as measured (``info.heldout``), the structure chosen
        (``info.selection``, with ``"auto"``); ``holdout`` the folds' normal equations.

    Raises
    ------
    WrongTypeError
        ``robot`` not a Robot, ``log`` not a TorqueLog (a list of logs:
        :func:`~dynid.workflows.identify.identify_logs` takes several).
    ShapeError
        ``log.n != robot.n``.
    DataError
        From the preparation of the log (gaps, too short, bad cutoff).
    OptionError
        ``friction=False`` with a structure other than ``"classical"``; ``base`` with
        ``structure="auto"``; an armature asked with known rotor inertias; a
        ``structure`` that is none of the above.
    RankDeficientError
        The trajectory does not excite every base parameter (and friction column); the
        message names the nearly dependent columns.

    Warns
    -----
    DynidWarning
        Ill-conditioned regressor or coefficients above 1000 % std
        (:func:`~dynid.identification.least_squares.conditioning_advice`); identified
        friction that is not dissipative.
    """
    robot, log = checked_robot(robot), _one_log(log)
    if not isinstance(structure, Structure) and structure not in ("auto", "classical"):
        raise OptionError(
            f"must be 'auto', 'classical' or a Structure; got {structure!r}", field="structure"
        )
    if structure != "classical" and not friction:
        raise OptionError(
            "friction=False applies to structure='classical'; give the terms (a Structure)"
        )
    return identify_recordings(
        robot,
        [log],
        structure=classical_structure(drive, friction) if structure == "classical" else structure,
        cutoff_hz=cutoff_hz,
        trim_s=trim_s,
        max_gap_s=max_gap_s,
        decimate=decimate,
        drive=drive,
        estimator=estimator,
        std=std,
        max_std_percent=max_std_percent,
        rtol=rtol,
        folds=folds,
        validate_on=validate_on,
        base=base,
    )
