"""Payload identification: mass, centre of mass and inertia of a load on a known arm.

A load rigidly fixed to frame ``F`` (default ``flange``, on link ``k``) adds its standard
parameters, carried into link ``k`` coordinates, to link ``k``. With ``T = T_link_F`` the
pseudo-inertia transforms as ``J_link = T J_F T^T`` (:mod:`dynid.feasibility.lmi`), a
linear map ``phi_link = A phi_F``, so the measured quantities minus the arm's own are
linear in the load's parameters ``phi_F = [m, m c, J_F]`` (about ``F``'s origin, ``F`` axes):

.. math:: y - y_{arm}(q) = Y_k(q) \\, A \\, \\phi_F \\; (+ F(\\dot q) f)

``y_arm`` is the arm's whole model (:mod:`dynid.feasibility.payload_arm`): an identified
model's own prediction with its armature or rotor inertias and its friction as identified,
or a robot's links with its drive's known rotor inertias and its own friction.

* **static M and g** (:func:`identify_payload` with a
  :class:`~dynid.identification.data.StaticDataset`): ``y = [tril M; g]`` and ``Y`` the
  static regressor (Gaz et al. 2019, eq. 20); all 10 parameters;
* **static g only** (``gravity_only=True``): ``g`` depends on ``m`` and ``m c`` only, so
  the mass and the CoM are estimated and the inertia is not (``inertia_identified`` False);
* **torque logs** (one or more :class:`~dynid.identification.log.TorqueLog`): prepared as
  identification prepares them (:mod:`dynid.feasibility.payload_rows`: through the drive,
  each recording and each piece between gaps on its own; an identified model's recorded
  cut-off and decimation by default), ``Y`` the torque regressor, and friction per joint
  estimated alongside (what the arm's own friction leaves): the classical ``fv, fc, fo``,
  or, when that leaves more than :data:`~dynid.identification.verdict.FLOOR_FAIR` times
  the torque noise, the friction identification chooses on held-out data from the same
  recordings (:mod:`dynid.feasibility.payload_friction`), or the one ``terms`` gives;
  the Coulomb columns and the arm's own friction low-passed as the torques were
  (parallel filtering, as identification's rows); a joint whose measured velocity never
  leaves its noise band (:func:`~dynid.identification.velocity_noise.moving_joints`) does not
  move: its velocity and acceleration are zero in the regressor and its ``fv, fc`` are
  not fitted (zero);
* **difference method** (``unloaded=`` data of the same kind recorded without the load):
  the arm is first identified from the unloaded data with identification's structure
  selection, or the structure of the identified model given
  (:func:`~dynid.feasibility.payload_arm.unloaded_arm`), at the loaded data's cut-off and
  decimation; model errors common to both recordings cancel (when the unloaded data
  repeat the loaded motion; the recordings an identified model given was identified from
  give that model again, which a note says).

Physical consistency: the least-squares estimate is kept when its pseudo-inertia is
positive definite with ``lambda_min(J) >= margin tr(J)``; otherwise the estimate closest to
it in the metric of the data, ``||R (phi - phi_ls)||`` (``W = Q R``), subject to that LMI
(Wensing, Kim, Slotine, RA-L 2018), is solved for with cvxpy and Clarabel. For ``g`` only
the constraint is ``m > 0``.

Standard deviations: the heteroscedasticity-consistent (HC1) covariance of the least
squares (relative, multiplicative sensor noise gives rows of unequal variance), carried to
mass, CoM and inertia about the CoM through the Jacobian of that map (central differences).
Torque logs: widened for the filtered rows' serial correlation (Newey-West) and, each
parameter's variance, to the estimate's spread over held-out time blocks where that is
larger (:func:`~dynid.feasibility.payload_fit.block_jackknife_covariance`): an error of
the arm's model that varies along the motion moves the estimate, which the residual does
not show. When the LMI is active they describe the unconstrained estimate, and the
inertia, set by the bound, is not determined.

Doubts (:attr:`PayloadEstimate.doubts`, each also a :class:`~dynid.exceptions.DynidWarning`):
a mass less than :data:`MIN_MASS_SIGMAS` standard deviations above zero (no load the data
can tell from none: unloaded data, or a load too light for them), or a CoM farther from
the frame than the arm is long (no load the arm carries reaches past its own base; such
a CoM is the first moment ``m c`` divided by a mass near zero), or torques of another
scale than the arm description's (:mod:`dynid.feasibility.payload_scale`: a robot or
feasible parameters, whose links do not come from these sensors; the factor and the load's
mass divided by it in :attr:`PayloadEstimate.torque_scale`, and in the error when the
least-squares mass is not positive). A doubtful estimate is not a load to hand to a
controller. An inertia whose elements the data do not determine
(:attr:`PayloadEstimate.undetermined`, :mod:`dynid.feasibility.payload_doubts`) is doubted
on its own (:attr:`PayloadEstimate.inertia_doubts`): the mass and CoM are handed on, the
inertia is not. The fit's residual is compared with its noise floor, the torque noise
left after the low-pass (:attr:`PayloadEstimate.noise_rms`) and the states' noise through
the arm's model (:mod:`dynid.feasibility.payload_floor`: recorded velocities' noise
through a steep friction law), each sample against its own noise as ``validate`` and
``identify`` weigh it (:attr:`PayloadEstimate.floor_rms`): above
:data:`~dynid.identification.verdict.FLOOR_FAIR` times it, the torques the arm's model
leaves go into the mass and CoM too (an unmodelled spring at 74 x the noise read a 1.5 kg
load as 1.04 kg), so the whole load is a doubt
(:func:`~dynid.feasibility.payload_doubts.misfit_doubts`), its inertia not determined, and
the standard deviations are raised to the largest change an unmodelled torque as large
as the misfit can make (:func:`~dynid.feasibility.payload_fit.misfit_covariance`). With
recordings of the same motion without the load, the residual judged is the loaded fit's
less the unloaded arm's at matched states, against the noise of both
(:mod:`dynid.feasibility.payload_difference`, :attr:`PayloadEstimate.judged`): an arm's
misfit common to both cancels, a load that moved does not.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, Literal, cast

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from ..exceptions import (
    DataError,
    DynidWarning,
    ModelError,
    ShapeError,
)
from ..friction.fit import model_drive
from ..identification.constants_checked import recorded_constants
from ..identification.data import StaticDataset
from ..identification.gravity_scale import recorded_scale
from ..identification.log import TorqueLog
from ..identification.model import IdentifiedModel
from ..identification.recordings import Recordings, prepare_recordings
from ..identification.structure import Structure
from ..identification.verdict import FLOOR_FAIR
from ..model.drive import Drive
from ..model.inertia import INERTIA_ORDER
from ..model.robot import Robot
from .lmi import phi_from_pseudo_inertia, pseudo_inertia
from .payload_arm import (
    ArmFriction,
    ArmModel,
    arm_model,
    holds_the_load,
    model_structure,
    parameter_spread,
    unloaded_arm,
)
from .payload_difference import (
    JudgedResidual,
    arm_residual,
    judged_residual,
    loaded_floor_rms,
    piece_states,
)
from .payload_doubts import (
    doubts_about,
    inertia_doubts,
    misfit_doubts,
    model_scale_doubts,
    undetermined_inertia,
)
from .payload_fit import (
    HELD_OUT_BLOCKS,
    block_jackknife_covariance,
    fit_load,
    held_out_widening,
    load_parameters,
    misfit_covariance,
    serial_correlation_factor,
    summary,
)
from .payload_floor import floor_ratio, sensor_variances, states_noise_var
from .payload_friction import (
    CLASSICAL_NAME,
    chosen_friction,
    classical_parts,
    friction_structure,
    friction_term,
    rows_residual,
    rows_rms,
)
from .payload_rows import (
    filtered_noise_rms,
    log_preparation,
    log_rows,
    static_load_rows,
    still_joints,
)
from .payload_scale import TorqueScale, constants_note, scale_doubts, torque_scale

__all__ = [
    "PayloadEstimate",
    "identify_payload",
    "link_params_from_frame",
    "model_with_payload",
    "robot_with_payload",
]


#: The rows of :func:`~dynid.feasibility.payload_scale.torque_scale`: the targets (the
#: measured rows minus the description's), the description's rows, the other columns
#: (the load's ``p`` first), the columns fitted and ``p`` (0: the data without the load).
_ScaleRows = tuple[
    NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_] | None, int
]


#: The arm's residual on the recordings without the load, for the difference
#: (:func:`~dynid.feasibility.payload_difference.judged_residual`): the loaded samples'
#: states, the unloaded samples' states, their pieces, the arm's residual on them [N m]
#: and what the torque noise leaves in it [N m].
_Unloaded = tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.int64],
    NDArray[np.float64],
    float | None,
]


#: The noise floor of prepared recordings (:mod:`~dynid.feasibility.payload_floor`): per
#: piece its torques [N m] (N_p, n), its torque noise variance after the low-pass
#: [N^2 m^2] (n,) (None: not read) and the states' noise variance through the arm's model
#: at each sample [N^2 m^2] (N_p, n).
_Floor = tuple[
    list[NDArray[np.float64]], list[NDArray[np.float64] | None], list[NDArray[np.float64]]
]


#: What a torque log's load fit is judged and widened by: the arm's residual without the
#: load (:data:`_Unloaded`), the noise floor (:data:`_Floor`) and the covariance the
#: identified arm's base parameters put into the load's parameters (p, p), each None
#: when not known.
_Judging = tuple[_Unloaded | None, _Floor | None, NDArray[np.float64] | None]


@dataclass(frozen=True, slots=True, eq=False)
class PayloadEstimate:
    """A load's inertial parameters in its frame, with standard deviations.

    Attributes
    ----------
    frame : str
        The frame ``F`` the load is fixed to.
    link : int
        The link carrying ``F``.
    phi : ndarray, shape (10,)
        Standard parameters in ``F``: ``m, m c, J`` about ``F``'s origin, ``F`` axes [SI].
    mass : float
        [kg].
    com : ndarray, shape (3,)
        CoM in ``F`` [m].
    inertia : ndarray, shape (3, 3)
        Inertia about the CoM in ``F`` axes [kg m^2] (zeros when not identified).
    std_mass : float
    std_com : ndarray, shape (3,)
    std_inertia : ndarray, shape (6,)
        Standard deviations of ``xx xy xz yy yz zz`` (NaN when not identified).
    covariance : ndarray, shape (p, p)
        Covariance of the estimated entries of ``phi`` (``p`` = 10, or 4 for ``g`` only).
    route : str
        ``"static M and g"``, ``"static g"`` or ``"torque log"`` (``", difference"`` appended
        for the difference method, unless the arm identified from the unloaded data is the
        identified model given: then a note says so).
    inertia_identified : bool
    constraint_active : bool
        The LMI changed the least-squares estimate.
    margin : float
        ``lambda_min(J) / tr(J)`` of the result (``nan`` for ``g`` only).
    rank : int
    condition_number : float
    residual_rms : float
        RMS of the fit's residual [SI of the rows].
    n_rows : int
    friction : ndarray, shape (n, 3), or None
        ``fv, fc, fo`` per joint estimated alongside (torque logs): the friction beyond
        the arm's own model's (zero where :attr:`friction_terms` holds none; a smooth
        Coulomb's coefficient is its ``fc``).
    friction_terms : str
        Torque logs: the friction estimated alongside, as ``dynid identify`` names a
        structure (``"viscous + coulomb + offset"``: the classical, with the plain sign);
        empty for static data.
    friction_labels : tuple of str
        Torque logs: the labels of its coefficients (``fv1, fc1, fsp1, fo1, ...``).
    notes : tuple of str
    doubts : tuple of str
        Why the estimate is not a load to trust (module docstring), a residual judged
        (:attr:`judged`) more than :data:`~dynid.identification.verdict.FLOOR_FAIR` times
        its noise among them; empty when none.
    undetermined : tuple of str
        The inertia's elements the data do not determine (``"Ixx"`` .. ``"Izz"``,
        :func:`~dynid.feasibility.payload_doubts.undetermined_inertia`); empty when every
        one is or the inertia was not identified.
    inertia_doubts : tuple of str
        Why the inertia is not to be trusted (naming :attr:`undetermined`); empty when none.
    noise_rms : float or None
        Torque logs: the RMS [N m] the torque sensors' noise alone leaves in the rows
        after the low-pass (each piece's white noise per joint through the filter's noise
        gain): with the states' noise through the arm's model (:attr:`floor_rms`), the
        :attr:`residual_rms` of a perfect model. None for static data, or when a
        recording's noise could not be read.
    judged : JudgedResidual or None
        The residual the load's doubt was judged on, with its ratio to the noise (the
        torques' and the states' through the arm's model, each sample against its own:
        :mod:`dynid.feasibility.payload_floor`;
        :mod:`dynid.feasibility.payload_difference`): the fit's, or with recordings
        without the load of the same motion the loaded fit's residual less the unloaded
        arm's at matched states (an arm's misfit common to both cancels); None for
        static data.
    torque_scale : TorqueScale or None
        The factor between the measured torques and the arm description's, with the load's
        mass at the description's scale (:mod:`dynid.feasibility.payload_scale`); None for
        an identified model (its scale was fitted to the same sensors) or a description
        without inertial parameters.
    scale_unchecked : str
        Why the torques' scale was not compared with a robot's description (its drive's
        rotor inertias to be identified, no inertial parameters); empty when it was, or
        the arm is an identified model.
    constants_checked : mapping or None
        A load weighed from motor currents: the torque constants' error its mass and first
        moments carry, ``finding`` (the note's sentence) and, of an identified arm's record
        (:func:`~dynid.identification.constants_checked.constants_record`), ``checked``,
        ``corrected``, ``unchecked`` (the motors, from 1), ``within_percent`` [%] and
        ``per``; None for a log of torques.
    preprocessing : mapping
        Torque logs: ``cutoff_hz`` [Hz], ``cutoff_source`` (``"given"``, ``"model"``: the
        identification's, ``"motion"``: read from the recordings), ``decimate``,
        ``max_gap_s`` [s] (None: the default rule) and ``sample_rate_hz`` of the raw
        recordings; empty for static data. The standard deviations of filtered rows are
        widened for their serial correlation
        (:func:`~dynid.feasibility.payload_fit.serial_correlation_factor`).
    recordings : tuple of mapping
        Torque logs: per recording ``file``, ``pieces``, ``samples`` and ``duration_s``.
    skipped : tuple of str
        One line per piece left out (too short to filter).
    """

    frame: str
    link: int
    phi: NDArray[np.float64]
    mass: float
    com: NDArray[np.float64]
    inertia: NDArray[np.float64]
    std_mass: float
    std_com: NDArray[np.float64]
    std_inertia: NDArray[np.float64]
    covariance: NDArray[np.float64]
    route: str
    inertia_identified: bool
    constraint_active: bool
    margin: float
    rank: int
    condition_number: float
    residual_rms: float
    n_rows: int
    friction: NDArray[np.float64] | None
    notes: tuple[str, ...]
    doubts: tuple[str, ...] = ()
    preprocessing: Mapping[str, Any] = field(default_factory=dict)
    recordings: tuple[Mapping[str, Any], ...] = ()
    skipped: tuple[str, ...] = ()
    undetermined: tuple[str, ...] = ()
    inertia_doubts: tuple[str, ...] = ()
    noise_rms: float | None = None
    torque_scale: TorqueScale | None = None
    judged: JudgedResidual | None = None
    friction_terms: str = ""
    friction_labels: tuple[str, ...] = ()
    scale_unchecked: str = ""
    constants_checked: Mapping[str, Any] | None = None

    @property
    def plausible(self) -> bool:
        """No doubt about the estimate, its inertia included (:attr:`doubts` and
        :attr:`inertia_doubts` empty)."""
        return not self.doubts and not self.inertia_doubts

    @property
    def inertia_determined(self) -> bool:
        """The inertia was identified and the data determine each of its elements."""
        return self.inertia_identified and not self.undetermined

    @property
    def floor_rms(self) -> float | None:
        """Torque logs: the noise floor of the loaded rows [N m], :attr:`noise_rms` and
        the states' noise through the arm's model (:mod:`dynid.feasibility.payload_floor`),
        root sum of squares; :attr:`noise_rms` when the states' noise is not known."""
        return loaded_floor_rms(self.noise_rms, self.judged)


def link_params_from_frame(T_link_frame: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 10x10 matrix ``A`` with ``phi_link = A phi_F`` for a body fixed at ``T_link_F``.

    From the pseudo-inertia's transformation ``J_link = T J_F T^T``.
    """
    T = np.asarray(T_link_frame, dtype=np.float64)
    E = np.eye(10)
    return np.stack([phi_from_pseudo_inertia(T @ pseudo_inertia(E[i]) @ T.T) for i in range(10)], 1)


def identify_payload(
    arm: Robot | IdentifiedModel | ArmModel,
    data: StaticDataset | TorqueLog | Sequence[TorqueLog],
    *,
    names: Sequence[str] | None = None,
    frame: str = "flange",
    gravity_only: bool = False,
    unloaded: StaticDataset | TorqueLog | Sequence[TorqueLog] | None = None,
    unloaded_names: Sequence[str] | None = None,
    structure: Structure | Literal["auto"] | None = None,
    drive: Drive | None = None,
    friction: ArmFriction = "own",
    terms: Structure | Literal["auto"] | None = "auto",
    margin: float = 1e-6,
    cutoff_hz: float | None | Literal["recorded"] = "recorded",
    decimate: int | None = None,
    rtol: float | None = None,
    max_gap_s: float | None = None,
) -> PayloadEstimate:
    """Estimate the load fixed to ``frame`` from data recorded with it on a known arm.

    Parameters
    ----------
    arm : Robot, IdentifiedModel or ArmModel
        The arm without the load, its whole model
        (:func:`~dynid.feasibility.payload_arm.arm_model`); only its kinematics, gravity
        and drive when ``unloaded`` is given.
    data : StaticDataset, TorqueLog or a sequence of TorqueLog
        Recorded with the load: ``q`` (N, n) [rad], ``M`` [kg m^2], ``g`` [N m]; or one or
        more recordings (on the drive's side), every piece between gaps on its own.
    names, unloaded_names : sequence of str, optional
        The recordings' names (file names), for messages and the record.
    frame : str
        The frame the load is fixed to; its CoM and inertia are given in it.
    gravity_only : bool
        Static data: use ``g`` only (mass and CoM; the inertia is not identified).
    unloaded : StaticDataset, TorqueLog or a sequence of TorqueLog, optional
        The same kind of data without the load (difference method).
    structure : Structure or "auto", optional
        Difference method on recordings: the terms of the arm identified from
        ``unloaded``; default: an identified model's own, else chosen on held-out data.
    drive, friction
        As :func:`~dynid.feasibility.payload_arm.arm_model`.
    terms : Structure, "auto" or None
        Torque logs: the friction beside the load (:mod:`.payload_friction`): None the
        classical, a structure's friction parts, or ``"auto"`` (default).
    margin : float
        LMI margin: ``lambda_min(J) >= margin tr(J)``.
    cutoff_hz : float, None or "recorded"
        Torque logs: zero-phase low-pass cut-off [Hz] (None: no filtering); ``"recorded"``
        (default): an identified model's (with its decimation), else the one read from
        the recordings' motion as identification reads it.
    decimate : int, optional
        Torque logs: keep every ``decimate``-th sample (default: the model's for
        recordings at its rate, else about ten samples per cut-off period).
    rtol : float, optional
        Relative rank tolerance of the unloaded arm's identification and of the load's
        least squares (None: their defaults; every direction of the load excited).
    max_gap_s : float, optional
        Torque logs: longest gap bridged [s]; a longer one cuts a log.

    Returns
    -------
    PayloadEstimate

    Raises
    ------
    UnknownNameError
        ``frame`` is not a frame of the robot.
    ModelError
        The frame is on the base; a robot whose drive's rotor inertias are unknown.
    ShapeError
        Data of another joint count; ``unloaded`` of another kind than ``data``.
    RankDeficientError
        The data do not excite the load's parameters (named: a load that never rotates).
    DataError
        The least-squares mass is not positive (no load, or a wrong model of the arm, or
        torques of another scale than the arm description's: then named with the load's
        mass over the factor; a fit over 3 x the torque noise: named with the ratio); a
        drive other than the model's; a recording without a piece long enough to filter;
        without ``unloaded``, one an identified ``arm`` was identified from (it holds the load).
    SolverError
        The constrained problem failed.

    Each of :attr:`PayloadEstimate.doubts` and :attr:`PayloadEstimate.inertia_doubts` is
    also a :class:`DynidWarning`.
    """
    inner = arm.model if isinstance(arm, ArmModel) else arm
    kin = inner.robot if isinstance(inner, IdentifiedModel) else inner
    d = arm.drive if isinstance(arm, ArmModel) else model_drive(inner, drive)
    f = kin.frame(frame)
    if f.link == 0:
        raise ModelError(f"frame {frame!r} is on the base; a load there does not move")
    static, items, base = _checked_items(data, unloaded, kin)
    notes: list[str] = []
    A, cols = link_params_from_frame(f.T_link_frame), slice(10 * (f.link - 1), 10 * f.link)
    kept: NDArray[np.bool_] | None = None
    record: dict[str, Any] = {}
    judging: _Judging = (None, None, None)  # torque logs: what judges the load's fit
    described, unchecked = _description(arm, d, friction)
    if isinstance(data, StaticDataset):
        empty = None if base is None else cast(StaticDataset, base[0])
        W, yv, route, differenced, scale = _static_route(
            arm, data, empty, d, friction, rtol, cols, A, gravity_only, notes, described
        )
    else:
        opt = dict(structure=structure, drive=d, friction=friction, cutoff_hz=cutoff_hz)
        opt |= dict(decimate=decimate, max_gap_s=max_gap_s, rtol=rtol, terms=terms)
        logs = cast(list[TorqueLog], list(items))
        without = None if base is None else cast(list[TorqueLog], list(base))
        W, yv, route, kept, record, differenced, scale, judging = _log_route(
            arm, logs, names, without, unloaded_names, cols, A, notes, opt, described
        )
    fit = (W, yv, kept, 4 if (static and gravity_only) else 10, static, rtol, margin)
    route += ", difference" if differenced else ""
    scaled = None if described is None else scale
    recorded = (recorded_scale(inner), recorded_constants(inner), unchecked)  # the load's too
    return _estimate(
        *fit, kin, frame, route, notes, record, differenced, scaled, d, *judging, recorded
    )


#: One data set: static data or one recording.
_Data = StaticDataset | TorqueLog


def _checked_items(
    data: StaticDataset | TorqueLog | Sequence[TorqueLog],
    unloaded: StaticDataset | TorqueLog | Sequence[TorqueLog] | None,
    kin: Robot,
) -> tuple[
    bool, tuple[StaticDataset | TorqueLog, ...], tuple[StaticDataset | TorqueLog, ...] | None
]:
    """Whether ``data`` are static, its data sets and ``unloaded``'s (None), checked: the
    robot's joint count, and the same kind of data for both (a ShapeError otherwise)."""
    static = isinstance(data, StaticDataset)
    items = _items(data, "data")
    for one in items:
        if one.q.shape[-1] != kin.n:
            raise ShapeError(f"data have {one.q.shape[-1]} joints; robot {kin.name!r} has {kin.n}")
    base = None if unloaded is None else _items(unloaded, "unloaded")
    if base is not None and isinstance(unloaded, StaticDataset) != static:
        raise ShapeError("unloaded must be the same kind of data as data (static or log)")
    return static, items, base


def _static_route(
    arm: Robot | IdentifiedModel | ArmModel,
    data: StaticDataset,
    base: StaticDataset | None,
    drive: Drive | None,
    friction: ArmFriction,
    rtol: float | None,
    cols: slice,
    A: NDArray[np.float64],
    gravity_only: bool,
    notes: list[str],
    described: ArmModel | None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], str, bool, _ScaleRows]:
    """The rows of static data with the arm given or identified from ``base``
    (:func:`~dynid.feasibility.payload_rows.static_load_rows`), whether the difference
    method changed the arm, and the rows of the torques' scale against the arm's
    ``described`` model (on ``base`` when given)."""
    inner = arm.model if isinstance(arm, ArmModel) else arm
    if base is None:
        the_arm, differenced = arm_model(arm, drive=drive, friction=friction), False
    else:
        kin = inner.robot if isinstance(inner, IdentifiedModel) else inner
        the_arm, note = unloaded_arm(kin, base, rtol=rtol, drive=drive)
        differenced = _difference_said(inner, the_arm, note, notes)
    W, yv, route, own = static_load_rows(the_arm, data, cols, A, gravity_only, notes)
    scale: _ScaleRows = (yv, own, W, None, W.shape[1])
    if base is not None and described is not None:  # on the data without the load
        _, y0, _, own0 = static_load_rows(described, base, cols, A, gravity_only, [])
        scale = (y0, own0, np.zeros((y0.size, 0)), None, 0)
    return W, yv, route, differenced, scale


def _description(
    arm: Robot | IdentifiedModel | ArmModel, drive: Drive | None, friction: ArmFriction
) -> tuple[ArmModel | None, str]:
    """The arm's description as a whole model (:func:`~dynid.feasibility.payload_arm.arm_model`)
    when its links do not come from the data's sensors: a robot with inertial parameters
    and known rotor inertias; None for an identified model (its scale was fitted to the
    same sensors). Beside it, why a robot's description cannot be compared with the
    torques (:attr:`PayloadEstimate.scale_unchecked`; empty: it can, or it is no robot)."""
    inner = arm.model if isinstance(arm, ArmModel) else arm
    if not isinstance(inner, Robot):
        return None, ""
    if not np.any(inner.phi):
        return None, "the arm's description has no inertial parameters"
    try:
        return arm_model(arm, drive=drive, friction=friction), ""
    except ModelError:  # rotor inertias to identify: the description's torques unknown
        return None, (
            'the drive\'s rotor inertias are to be identified (rotor_inertia = "identify"), '
            "so the description's torques at the motors are not known: the measured "
            "torques have no model to be compared with; hint: give the rotor inertias in "
            "the drive file (rotor_inertia = [...]), or weigh a load of known mass "
            "(--known-mass)"
        )


def _estimate(
    W: NDArray[np.float64],
    yv: NDArray[np.float64],
    kept: NDArray[np.bool_] | None,
    p: int,
    static: bool,
    rtol: float | None,
    margin: float,
    kin: Robot,
    frame: str,
    route: str,
    notes: list[str],
    record: dict[str, Any],
    difference: bool,
    scale_rows: _ScaleRows | None,
    drive: Drive | None,
    against: _Unloaded | None = None,
    floor: _Floor | None = None,
    spread: NDArray[np.float64] | None = None,
    arm_records: tuple[tuple[float, str] | None, Mapping[str, Any] | None, str] = (None, None, ""),
) -> PayloadEstimate:
    """The load's estimate from its rows: least squares, consistency, doubts (warned);
    ``difference``: the arm was identified from unloaded data (its hint differs);
    ``scale_rows``: the rows of the torques' scale against the arm's description (None:
    no description, or one identified from these sensors), ``drive`` for its hint;
    ``against``: the arm's residual on recordings without the load, the misfit then
    judged on the difference at matched states (:func:`_judged`); ``floor``: the noises
    the residual is judged against (None: the torque noise alone); ``spread``: the
    covariance the identified arm's parameters put into the load's, added (None: none);
    ``arm_records``: the identified arm's recorded gravity scale
    (:func:`~dynid.feasibility.payload_doubts.model_scale_doubts`), why a robot's
    description was not compared with the torques (:attr:`PayloadEstimate.scale_unchecked`)
    and what its identification's data checked of the drive's torque constants
    (:func:`~dynid.identification.constants_checked.recorded_constants`), which the load's
    mass and first moments carry (:func:`~dynid.feasibility.payload_scale.constants_note`)."""
    n, k = kin.n, kin.frame(frame).link
    recorded, checked, unchecked = arm_records
    fit = fit_load(W, yv, kept, rtol, p, static)
    est = np.asarray(fit.beta)
    cols = np.ones(W.shape[1], bool) if kept is None else kept
    noise = record.get("noise_rms")
    resid = yv - W[:, cols] @ est[cols]
    judged, judged_rows = _judged(fit.residual_rms, resid, noise, n, static, against, notes, floor)
    misfit = () if judged is None else misfit_doubts(judged, difference=difference)
    prep = record.get("preprocessing") or {}
    cov, per_period = _serial_widening(np.asarray(fit.covariance)[:p, :p], resid, n, prep, notes)
    if not static:  # static configurations are exchangeable: their blocks spread alike
        cov = _held_out_spread(cov, W[:, cols], yv, n, notes)
    if spread is not None:  # the arm's own error: the same all along the recordings
        cov = _with_arm_spread(cov, spread, notes)
    sm_noise = float(np.sqrt(cov[0, 0]))  # whether there is a load: the misfit says its own
    floor_rms = loaded_floor_rms(noise, judged)  # the torques' scale's fit holds it too
    if misfit and judged is not None and judged.floor_rms:  # the residual does not see them
        cov = _misfit_spread(cov, W[:, cols], judged_rows, judged.floor_rms, notes)
    m_ls, sm_ls = float(est[0]), float(np.sqrt(cov[0, 0]))
    scale = None
    if scale_rows is not None:
        y_s, arm_s, W_s, kept_s, p_s = scale_rows
        scale = torque_scale(
            y_s,
            arm_s,
            W_s,
            kept_s,
            n,
            p=p_s,
            lags=per_period,
            held_out=not static,
            load=(m_ls, sm_ls),
        )
    try:
        phi, active, marg = load_parameters(est[:p], sm_ls, W, margin, notes)
    except DataError as exc:  # a mass not positive: the torques' scale or misfit may say why
        said = scale_doubts(scale, m_ls, drive, floor_rms) or misfit
        if not said:
            raise
        raise DataError(f"{exc}; {said[0]}") from None
    m, c, I, sm, sc, si = summary(phi, cov, p == 10)
    if (constants := constants_note(drive, m, sm, checked)) is not None:
        notes.append(constants)
    doubts = misfit + doubts_about(kin, frame, m, sm_noise, c, misfit=bool(misfit))
    doubts += scale_doubts(scale, m, drive, floor_rms) + model_scale_doubts(recorded, m)
    by_std = undetermined_inertia(I, si) if p == 10 and not doubts else ()
    at_bound = active and p == 10 and not doubts  # the bound, not the data, set it
    every = tuple(f"I{name}" for name in INERTIA_ORDER)
    # torques the arm's model leaves: the inertia takes them first
    undetermined = every if at_bound or (misfit and p == 10) else by_std
    about_inertia = inertia_doubts(by_std, I, si, at_bound=at_bound, margin=margin)
    for line in doubts + about_inertia:
        warnings.warn(line, DynidWarning, stacklevel=caller_level())
    return PayloadEstimate(
        frame=frame,
        link=k,
        phi=phi,
        mass=m,
        com=c,
        inertia=I,
        std_mass=sm,
        std_com=sc,
        std_inertia=si,
        covariance=cov,
        route=route,
        inertia_identified=p == 10,
        constraint_active=active,
        margin=marg,
        rank=fit.rank,
        condition_number=fit.condition_number,
        residual_rms=fit.residual_rms,
        n_rows=fit.n_rows,
        friction=None if static else classical_parts(est[10:], record["friction_labels"], n),
        notes=tuple(notes),
        doubts=doubts,
        undetermined=undetermined,
        inertia_doubts=about_inertia,
        torque_scale=scale,
        scale_unchecked=unchecked,
        judged=judged,
        constants_checked=None if constants is None else {**(checked or {}), "finding": constants},
        **record,
    )


def _judged(
    residual_rms: float,
    resid: NDArray[np.float64],
    noise: float | None,
    n: int,
    static: bool,
    against: _Unloaded | None,
    notes: list[str],
    floor: _Floor | None = None,
) -> tuple[JudgedResidual | None, NDArray[np.float64]]:
    """The residual the load's doubt is judged on and its rows
    (:func:`~dynid.feasibility.payload_difference.judged_residual`): the fit's
    (``residual_rms`` [N m], ``resid`` its rows, ``noise`` [N m] the torque noise after the
    low-pass), judged against ``floor`` (:func:`_floor_ratio`: with the states' noise
    through the arm's model), or the difference from the unloaded arm's residual
    ``against`` at matched states (against both recordings' noises; the states' of the
    unloaded samples taken as the loaded ones'), with a note; None for static data."""
    if static:
        return None, resid
    ratio, states = _floor_ratio(floor, resid, n)
    if against is None:
        return JudgedResidual("fit", residual_rms, noise, 0.0, states, ratio), resid
    x1, x0, labels0, r0, noise0 = against
    judged, rows = judged_residual(resid.reshape(-1, n), noise, x1, x0, labels0, r0, noise0)
    if judged.kind == "fit":
        notes.append(
            f"the loaded and unloaded motions do not match ({100 * judged.matched:.0f} % of "
            "the loaded samples within reach of the unloaded trajectory): the fit's residual "
            "is judged, the arm's model errors do not cancel"
        )
        return JudgedResidual("fit", residual_rms, noise, judged.matched, states, ratio), resid
    both = None if states is None else float(np.sqrt(2.0) * states)
    return replace(judged, states_rms=both), rows


def _floor_ratio(
    floor: _Floor | None, resid: NDArray[np.float64], n: int
) -> tuple[float | None, float | None]:
    """The fit's residual ``resid`` (N n,) [N m] over the noise ``floor`` (each sample
    weighed against its own noise:
    :func:`~dynid.feasibility.payload_floor.floor_ratio`) and the RMS of the states' noise
    through the arm's model [N m]; (None, None) without a floor."""
    if floor is None:
        return None, None
    tau, sensor, states = floor
    cuts = np.cumsum([t.shape[0] for t in tau])[:-1]
    pieces = np.split(resid.reshape(-1, n), cuts)
    return floor_ratio(tau, pieces, sensor, states)


def _serial_widening(
    cov: NDArray[np.float64],
    resid: NDArray[np.float64],
    n: int,
    prep: Mapping[str, Any],
    notes: list[str],
) -> tuple[NDArray[np.float64], int | None]:
    """``cov`` widened for the serial correlation of the residual ``resid`` (``n`` rows a
    sample; :func:`~dynid.feasibility.payload_fit.serial_correlation_factor`) over a
    cut-off period of filtered rows (``prep``: the record's preprocessing), and the
    samples per cut-off period (None: unfiltered rows, ``cov`` as it is)."""
    if not prep.get("cutoff_hz"):
        return cov, None
    rate = prep["sample_rate_hz"] / prep["decimate"]
    per_period = int(np.ceil(rate / prep["cutoff_hz"]))
    factor, lags = serial_correlation_factor(resid, n, per_period)
    notes.append(
        f"standard deviations widened x{np.sqrt(factor):.3g} for the serial correlation "
        f"of the filtered samples (Newey-West, {lags} lags)"
    )
    return cov * factor, per_period


def _with_arm_spread(
    cov: NDArray[np.float64], spread: NDArray[np.float64], notes: list[str]
) -> NDArray[np.float64]:
    """``cov`` (the load's ``p`` parameters) plus ``spread`` (p, p), the covariance the
    identified arm's base parameters put into them
    (:func:`~dynid.feasibility.payload_arm.parameter_spread`), with a note of the mass's
    widening."""
    out = cov + spread
    widen = np.sqrt(out[0, 0] / cov[0, 0]) if cov[0, 0] > 0 else 1.0
    notes.append(
        f"standard deviations include the identified arm's base parameters' uncertainty "
        f"(their covariance carried through the load's fit: the mass's x{widen:.3g}), an "
        "error the same all along the recordings that no residual shows; the friction's "
        "own uncertainty is not saved with the model and not included"
    )
    return out


def _misfit_spread(
    cov: NDArray[np.float64],
    W: NDArray[np.float64],
    resid: NDArray[np.float64],
    noise_rms: float,
    notes: list[str],
) -> NDArray[np.float64]:
    """``cov`` (the load's ``p`` parameters) with each variance raised, where that is
    larger (:func:`~dynid.feasibility.payload_fit.held_out_widening`, the correlations
    kept), to the squared largest change an unmodelled torque as large as the fit's
    misfit over the noise ``noise_rms`` [N m] can make
    (:func:`~dynid.feasibility.payload_fit.misfit_covariance`; ``W`` the fitted columns,
    ``resid`` the judged residual's rows, spread over ``W``'s), with a note."""
    bound = misfit_covariance(W, resid, noise_rms, cov.shape[0], rows=W.shape[0])
    widened, widen = held_out_widening(cov, bound)
    notes.append(
        f"standard deviations widened up to x{widen.max():.3g} (the mass's x{widen[0]:.3g}) "
        "to the largest change an unmodelled torque as large as the fit's misfit makes "
        f"(the fit leaves more than {FLOOR_FAIR:g} x the torque noise): a rough bound, not "
        "a noise's standard deviation"
    )
    return widened


def _held_out_spread(
    cov: NDArray[np.float64],
    W: NDArray[np.float64],
    yv: NDArray[np.float64],
    n: int,
    notes: list[str],
) -> NDArray[np.float64]:
    """``cov`` (the load's ``p`` parameters) with each variance raised to the spread of the
    estimate over :data:`~dynid.feasibility.payload_fit.HELD_OUT_BLOCKS` held-out time
    blocks (``n`` rows a sample) where that is larger
    (:func:`~dynid.feasibility.payload_fit.block_jackknife_covariance`; the correlations
    kept), and a note when it widened a standard deviation by more than
    10 %: an error of the arm's model that varies along the motion, which the residual's
    covariance does not see. Each block's fit need determine the load's parameters only
    (``W``'s first ``p`` columns): a friction direction that block alone excites (a joint
    reversing there only) is taken out of them, not blamed on the load."""
    jack = block_jackknife_covariance(W, yv, n, wanted=cov.shape[0])
    if jack is None:
        notes.append(
            "the standard deviations were not checked on held-out time blocks (a block alone "
            "excites some direction of the load, or the log is too short)"
        )
        return cov
    widened, widen = held_out_widening(cov, jack)
    if widen.max() > 1.1:
        notes.append(
            f"standard deviations widened up to x{widen.max():.3g} to the spread of the "
            f"estimate over {HELD_OUT_BLOCKS} held-out time blocks (block jackknife): the "
            "fit's errors vary along the motion (the arm's model), more than the residual's "
            "covariance says"
        )
    return widened


def _log_route(
    arm: Robot | IdentifiedModel | ArmModel,
    logs: list[TorqueLog],
    names: Sequence[str] | None,
    base: Sequence[TorqueLog] | None,
    base_names: Sequence[str] | None,
    cols: slice,
    A: NDArray[np.float64],
    notes: list[str],
    opt: dict[str, Any],
    described: ArmModel | None,
) -> tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    str,
    NDArray[np.bool_],
    dict[str, Any],
    bool,
    _ScaleRows,
    _Judging,
]:
    """The rows of recordings (:func:`~dynid.feasibility.payload_rows.log_rows`) with the
    arm given or identified from ``base``; the preprocessing, recordings and pieces left out, for
    the record (:class:`PayloadEstimate`'s fields); whether the arm identified from ``base`` differs
    from the one given (the difference method changed it); the rows of the torques' scale against
    the arm's ``described`` model (on ``base`` when given: :func:`_base_scale`); what judges and
    widens the fit (:data:`_Judging`): the arm's residual on ``base`` (:func:`_arm_on_base`, None
    without it), the noise floor of the loaded recordings (:data:`_Floor`, None when the states'
    noise is not known); the covariance the identified arm's base parameters put into the load's
    (:func:`~dynid.feasibility.payload_arm.parameter_spread`, None for a robot description).
    ``opt``: the options of :func:`identify_payload`."""
    inner = arm.model if isinstance(arm, ArmModel) else arm
    kin = inner.robot if isinstance(inner, IdentifiedModel) else inner
    d, opt = opt["drive"], {**opt, "torque_delay_s": _recorded_delay(inner)}
    cut, dec, source = log_preparation(inner, logs, opt["cutoff_hz"], opt["decimate"])
    gap, lag = opt["max_gap_s"], opt["torque_delay_s"]
    rec = prepare_recordings(
        kin, logs, names, cutoff_hz=cut, max_gap_s=gap, decimate=dec, drive=d, torque_delay_s=lag
    )
    used = max(p.decimate for p in rec.pieces)
    prep = {"cutoff_hz": rec.cutoff_hz, "cutoff_source": source, "decimate": used}
    prep |= {"max_gap_s": gap, "sample_rate_hz": rec.pieces[0].sample_rate_hz}
    prep |= {"torque_delay_s": lag} if lag else {}
    if base is None:
        if isinstance(inner, IdentifiedModel) and (why := holds_the_load(inner, rec.summary())):
            raise DataError(why)
        the_arm, differenced = arm_model(arm, drive=d, friction=opt["friction"]), False
    else:
        structure = opt["structure"]
        if structure is None:
            own = model_structure(inner) if isinstance(inner, IdentifiedModel) else None
            structure = "auto" if own is None else own
        the_arm, note = unloaded_arm(
            kin,
            base,
            base_names,
            structure=structure,
            cutoff_hz=rec.cutoff_hz,
            decimate=used,
            max_gap_s=gap,
            drive=d,
            rtol=opt["rtol"],
            torque_delay_s=lag,
        )
        differenced = _difference_said(inner, the_arm, note, notes)
    still = still_joints(logs, d)
    states = states_noise_var(the_arm, rec, logs, d, still)
    floor = None if states is None else _floor_of(rec, states)
    fr, rows = _friction_rows(the_arm, rec, still, cols, A, notes, opt["terms"], d, floor)
    W, yv, route, kept, modelled = rows
    scale: _ScaleRows = (yv, modelled, W, kept, 10)
    against = None
    if base is not None:
        rec0 = _prepared_base(kin, base, base_names, rec.cutoff_hz, used, opt)
        against = _arm_on_base(the_arm, rec0, rec, still, cols, A, fr)
        if described is not None:
            scale = _base_scale(described, rec0, base, cols, A, d, fr)
    record: dict[str, Any] = {"preprocessing": prep, "recordings": rec.summary()}
    name = CLASSICAL_NAME if fr is None else fr.name.removeprefix("links + ")
    record |= {"friction_terms": name, "friction_labels": friction_term(fr, rec, kin.n).labels}
    record |= {"skipped": rec.skipped, "noise_rms": filtered_noise_rms(rec)}
    spread = parameter_spread(the_arm, [p.log for p in rec.pieces], still, W[:, kept], 10)
    return W, yv, route, kept, record, differenced, scale, (against, floor, spread)


def _floor_of(rec: Recordings, states: list[NDArray[np.float64]]) -> _Floor:
    """The noise floor (:data:`_Floor`) of the prepared recordings ``rec`` with the states'
    noise variance ``states`` through the arm's model."""
    return [p.log.tau for p in rec.pieces], sensor_variances(rec), states


def _friction_rows(
    arm: ArmModel,
    rec: Recordings,
    still: NDArray[np.bool_],
    cols: slice,
    A: NDArray[np.float64],
    notes: list[str],
    terms: Structure | Literal["auto"] | None,
    drive: Drive | None,
    floor: _Floor | None = None,
) -> tuple[Structure | None, tuple[Any, ...]]:
    """The friction beside the load (None: classical) and the rows of
    :func:`~dynid.feasibility.payload_rows.log_rows` with it: ``terms`` given, or
    (``"auto"``) the classical unless it leaves more than
    :data:`~dynid.identification.verdict.FLOOR_FAIR` times the noise (``floor``: the
    torques' and the states' through the arm's model, :func:`_floor_ratio`; None: the
    torques' alone) and the friction ``dynid identify`` chooses on these recordings
    (:func:`~dynid.feasibility.payload_friction.chosen_friction`) leaves less; the choice
    noted."""
    start = len(notes)
    given = friction_structure(terms) if isinstance(terms, Structure) else None
    rows = log_rows(arm, rec, still, cols, A, notes, given)
    noise = filtered_noise_rms(rec)
    if terms != "auto" or not noise:
        return given, rows
    n = arm.robot.n
    first_rows = rows_residual(rows[0], rows[1], rows[3])
    first = _floor_ratio(floor, first_rows, n)[0] or rows_rms(rows[0], rows[1], rows[3]) / noise
    if first <= FLOOR_FAIR or (chosen := chosen_friction(arm.robot, rec, drive)) is None:
        return None, rows
    mine: list[str] = []
    other = log_rows(arm, rec, still, cols, A, mine, chosen)
    other_rows = rows_residual(other[0], other[1], other[3])
    second = _floor_ratio(floor, other_rows, n)[0] or rows_rms(other[0], other[1], other[3]) / noise
    name = chosen.name.removeprefix("links + ")
    said = (
        f"the classical friction fv, fc, fo beside the load leaves {first:.3g} x the "
        f"noise; the friction dynid identify chooses on held-out data from these "
        f"recordings, {name}, leaves {second:.3g} x"
    )
    if second >= first:
        notes.append(f"{said}: the classical kept")
        return None, rows
    notes[start:] = [*mine, f"{said}: estimated beside the load instead (--terms gives one)"]
    return chosen, other


def _recorded_delay(arm: Any) -> float:
    """The torques' lag behind the positions [s] an identified ``arm`` was identified with
    (:attr:`~dynid.identification.info.LogInfo.torque_delay_s`): the loaded recordings are
    prepared with it too; 0 for a robot or a model of static data."""
    log = arm.info.log if isinstance(arm, IdentifiedModel) else None
    return 0.0 if log is None else float(log.torque_delay_s)


def _prepared_base(
    kin: Robot,
    base: Sequence[TorqueLog],
    base_names: Sequence[str] | None,
    cutoff_hz: float | None,
    decimate: int,
    opt: dict[str, Any],
) -> Recordings:
    """The recordings without the load prepared as the loaded ones (their preparation's
    warnings said once already, by :func:`~dynid.feasibility.payload_arm.unloaded_arm`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return prepare_recordings(
            kin,
            list(base),
            base_names,
            cutoff_hz=cutoff_hz,
            max_gap_s=opt["max_gap_s"],
            decimate=decimate,
            drive=opt["drive"],
            torque_delay_s=opt["torque_delay_s"],
        )


def _arm_on_base(
    arm: ArmModel,
    rec0: Recordings,
    rec: Recordings,
    still: NDArray[np.bool_],
    cols: slice,
    A: NDArray[np.float64],
    friction: Structure | None = None,
) -> _Unloaded:
    """The arm's residual on the prepared recordings without the load ``rec0``
    (:func:`~dynid.feasibility.payload_difference.arm_residual`: the friction
    ``friction`` fitted as beside the load, None: classical), the states of the loaded
    ``rec`` and unloaded samples (``still`` joints zeroed in both), the unloaded samples'
    pieces and the noise the torques leave in that residual."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        W0, y0, _, kept0, _ = log_rows(arm, rec0, still, cols, A, [], friction)
    x1, _ = piece_states(rec.pieces, still)
    x0, labels0 = piece_states(rec0.pieces, still)
    r0 = arm_residual(W0, y0, kept0, arm.robot.n)
    return x1, x0, labels0, r0, filtered_noise_rms(rec0)


def _base_scale(
    described: ArmModel,
    rec0: Recordings,
    base: Sequence[TorqueLog],
    cols: slice,
    A: NDArray[np.float64],
    drive: Drive | None,
    friction: Structure | None = None,
) -> _ScaleRows:
    """The rows of the torques' scale on the recordings without the load ``rec0``
    (:func:`_prepared_base`; ``base`` as read): the description's torques (its whole
    model, ``described``) and the friction ``friction`` per joint (None: classical)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        still = still_joints(base, drive)
        W, y, _, kept, own = log_rows(described, rec0, still, cols, A, [], friction)
    return y, own, W[:, 10:], kept[10:], 0


def _difference_said(
    given: Robot | IdentifiedModel, arm: ArmModel, note: str, notes: list[str]
) -> bool:
    """Whether the arm identified from the unloaded data differs from the identified model
    given (its coefficients to 1e-9), with ``note`` (how it was identified) appended to
    ``notes`` when it does, else a note that the difference method changed nothing (as
    when the unloaded recordings are the ones the model was identified from)."""
    same = False
    if isinstance(given, IdentifiedModel) and isinstance(arm.model, IdentifiedModel):
        a, b = np.asarray(given.fit.beta), np.asarray(arm.model.fit.beta)
        same = a.shape == b.shape and bool(np.allclose(a, b, rtol=1e-9, atol=0.0))
    notes.append(
        "difference method: the arm identified from the --unloaded data is the --model's own "
        "(the same recordings, structure and preprocessing it was identified from), so the "
        "result is the one without --unloaded; the difference method cancels the arm's model "
        "errors only with a recording of the loaded motion repeated without the load"
        if same
        else note
    )
    return not same


def _items(
    data: StaticDataset | TorqueLog | Sequence[TorqueLog], what: str
) -> tuple[StaticDataset | TorqueLog, ...]:
    """``data`` as a tuple of data sets (one static data set, or the recordings)."""
    if isinstance(data, StaticDataset | TorqueLog):
        return (data,)
    out = tuple(data)
    if not out:
        raise DataError(f"no torque log given ({what})")
    return out


def robot_with_payload(robot: Robot, est: PayloadEstimate, *, name: str = "payload") -> Robot:
    """The robot carrying the load: :meth:`Robot.with_tool` at the estimate's frame."""
    return robot.with_tool(np.eye(4), est.mass, est.com, est.inertia, parent=est.frame, name=name)


def model_with_payload(model: IdentifiedModel, est: PayloadEstimate) -> IdentifiedModel:
    """The identified model carrying the load: its base parameters ``beta + P dphi``, with
    ``dphi`` the load's standard parameters on the link of the estimate's frame
    (:func:`robot_with_payload`) and ``P`` the model's base-parameter map
    (:attr:`~dynid.regressors.base.BaseParameters.projection`); its friction, rotor
    inertias, offsets, drive and recorded preprocessing as they are. The standard
    deviations stay the arm's (the load's are the estimate's). Its description (the link
    inertials the checks against the description and a consistent fit's prior read,
    :attr:`~dynid.identification.model.IdentifiedModel.description`) carries the load too:
    without it, validating the loaded model on the loaded arm read the load as torque
    constants 1.34 x off (a simulated xArm's currents, true factor 1).

    A base-parameter model has no links of its own to add the load to: its
    ``equivalent_robot`` puts each combination on one parameter (masses of 0 holding first
    moments), which no robot description holds.
    """
    kin = model.robot
    loaded = robot_with_payload(kin, est)
    dphi = (np.asarray(loaded.phi) - np.asarray(kin.phi)).reshape(-1)
    P = model.base.projection[:, : dphi.size]
    beta = np.asarray(model.fit.beta) + P @ dphi
    rest = [np.asarray(t.values) for t in model.appended]
    loaded_model = model.with_coefficients(np.concatenate([beta, *rest]))
    described = np.asarray(model.description.phi).reshape(-1) + dphi
    return replace(loaded_model, description_phi=described.reshape(kin.n, 10))
