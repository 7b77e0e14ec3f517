"""The convex method's entry points: from identified coefficients (two-step,
:func:`retrieve_sdp`) and from data (one step, :func:`identify_consistent`: torque logs or
static data), the drive adapter (:func:`with_drive`) and the method's registry entry
(:data:`METHOD`, :mod:`dynid.feasibility.methods`).

One step: the data's least-squares problem is the convex problem of
:mod:`dynid.feasibility.convex` with the data term taken on the data themselves: for
ordinary least squares,

.. math:: \\|W x - y\\|^2 = \\|W \\hat x - y\\|^2 + (x - \\hat x)^T W^T W (x - \\hat x),

so the normal equations ``W^T W / sigma^2`` of the unconstrained fit ``x_hat`` give the data
term exactly (up to the constant ``RSS / sigma^2``); the standard deviations the fit reports
are those of ``dynid identify`` (``std``: hac for torque logs, robust for static data),
which the data term does not depend on. Torque logs (one or several
recordings) go through the route of ``dynid identify``
(:func:`~dynid.identification.selection.identify_recordings`: each recording and each piece
between its gaps filtered, differentiated and decimated on its own, the model's structure
chosen on held-out data or given); the model keeps its terms as they are, each physical as
it declares (``nonnegative`` and ``dissipation_rows`` of :mod:`dynid.regressors.terms`,
:func:`consistent_from_identified`); static data through
:func:`~dynid.identification.static.identify_static` (``[tril M; g]``). The unconstrained
fit is returned with the result (``result.identified``) for comparison.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any, Literal

import numpy as np

from ...exceptions import OptionError, WrongTypeError
from ...friction.model import through_drive
from ...identification.data import StaticDataset
from ...identification.estimators import Estimator, EstimatorName
from ...identification.holdout import DEFAULT_FOLDS
from ...identification.least_squares import StdMethod
from ...identification.log import TorqueLog
from ...identification.model import IdentifiedModel
from ...identification.selection import identify_recordings
from ...identification.static import identify_static
from ...identification.structural import combined_notes
from ...identification.structure import Structure
from ...model.drive import Drive
from ...model.robot import Robot
from ...progress import stage
from ..bounds import Bounds
from ..determined import Determined, determined_by_data
from ..identified_terms import with_identified_terms
from ..prior import Prior
from ..prior_share import prior_share
from .data_term import DataTerm, coefficient_term
from .options import SDPOptions
from .result import ConsistentResult
from .solve import solve_consistent

__all__ = [
    "METHOD",
    "ConvexMethod",
    "consistent_from_identified",
    "identify_consistent",
    "retrieve_sdp",
    "with_drive",
]


def retrieve_sdp(
    model: IdentifiedModel,
    *,
    prior: Prior | Robot | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    options: SDPOptions | None = None,
    constraints: Sequence[Callable[..., Any]] = (),
) -> ConsistentResult:
    """Consistent link parameters from identified coefficients (two-step, convex).

    The coefficients' full covariance weighs the data term (``model.fit.covariance``);
    exact coefficients are met exactly. Parameters as in :func:`solve_consistent`; the
    result's robot carries ``model.robot``'s kinematics and friction. What the model
    identified beside the links is carried unchanged
    (:func:`~dynid.feasibility.identified_terms.with_identified_terms`): ``friction`` (its
    law, offsets included), ``rotor_inertia`` and ``drive`` (the rotor inertias retrieved
    with the links), ``spring``. :func:`dynid.io.export.save_robot` of the result (not of
    ``result.robot`` alone) writes them, or says what a format cannot hold.

    Examples
    --------
    >>> import dynid
    >>> from dynid.feasibility.convex import retrieve_sdp
    >>> robot = dynid.panda()
    >>> data = dynid.acquire_static(dynid.SimulatedController(robot), 100, np.random.default_rng(0))
    >>> res = retrieve_sdp(dynid.identify_static(robot, data), prior=robot)  # doctest: +SKIP
    """
    term = coefficient_term(model)
    res = solve_consistent(
        model.robot,
        term,
        prior=prior,
        bounds=bounds,
        total_mass=total_mass,
        options=options,
        constraints=constraints,
        kind="coefficients",
    )
    res = replace(
        res,
        rotor_inertia=_rotor_inertia(model, res.rotor_inertia),
        determined=determined_with_share(model, term, res),
    )
    res = res if model.drive is None else with_drive(res, model.drive)
    return with_identified_terms(res, model)  # friction, offsets, springs: as identified


def with_drive(res: ConsistentResult, drive: Drive) -> ConsistentResult:
    """The result with its drive, whose rotor inertias are the identified ones (known from
    then on: a simulator or a validation takes them as given), its friction at the motors
    acting through it."""
    ia = res.rotor_inertia if drive.rotor_inertia is None else drive.rotor_inertia
    if ia is not None:
        drive = dataclasses.replace(drive, rotor_inertia=ia)
    return dataclasses.replace(res, drive=drive, friction=through_drive(res.friction, drive))


def identify_consistent(
    robot: Robot,
    data: TorqueLog | Sequence[TorqueLog] | StaticDataset,
    *,
    prior: Prior | Robot | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    options: SDPOptions | None = None,
    constraints: Sequence[Callable[..., Any]] = (),
    cutoff_hz: float | Literal["auto"] | None = "auto",
    decimate: int | None = None,
    rtol: float | None = None,
    drive: Drive | None = None,
    estimator: EstimatorName | Estimator = "ols",
    folds: int = DEFAULT_FOLDS,
    validate_on: TorqueLog | None = None,
    structure: Structure | Literal["auto"] = "auto",
    max_gap_s: float | None = None,
    names: Sequence[str] | None = None,
    std: StdMethod | None = None,
) -> ConsistentResult:
    """Physically consistent link parameters (and friction) identified from data.

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity of the data.
    data : TorqueLog, sequence of TorqueLog, or StaticDataset
        A torque log of an exciting trajectory (or several recordings of one arm), or
        static ``q, M, g`` data.
    prior, bounds, total_mass, options, constraints
        As in :func:`~dynid.feasibility.convex.solve.solve_consistent`.
    cutoff_hz, decimate
        Torque logs: the classical route's filtering and decimation.
    rtol : float, optional
        Rank tolerance of the unconstrained fit; None: the identification's default (the
        rank at a clear gap of the singular values).
    drive : Drive, optional
        The drive train (:mod:`dynid.model.drive`): the log is read through it, its rotor
        inertias are identified with the links (``>= 0``) and its friction acts at the
        motors (``fv, fc >= 0``).
    estimator : {"ols", "wls", "irls"} or Estimator
        The unconstrained fit's estimator; its weighted covariance is the consistent fit's
        data term (:mod:`dynid.identification.estimators`).
    folds, validate_on
        Torque logs: the held-out judgement (contiguous time blocks of one recording, one
        recording left out at a time of several, or a separate log) that chooses the
        model's structure and the prior's weight and accepts the result
        (:mod:`dynid.feasibility.heldout`).
    structure : Structure or "auto"
        Torque logs: the terms beside the links; ``"auto"`` (default) chooses them on
        held-out data as ``dynid identify --consistent`` does
        (:func:`~dynid.identification.selection.identify_recordings`).
    max_gap_s : float, optional
        Torque logs: gaps up to this long [s] are bridged, longer ones cut a recording
        into pieces prepared on their own.
    names : sequence of str, optional
        Torque logs: one name per recording (file names), for messages and the record.
    std : {"classical", "robust", "hac"}, optional
        The unconstrained fit's standard deviations, as ``dynid identify`` reports them
        (default hac for torque logs, robust for static data); the data term is the
        residual itself whichever is chosen.

    Returns
    -------
    ConsistentResult
        ``kind`` ``"log"`` (with ``friction``, of the law of the structure, physical as its
        terms declare) or ``"static"``; ``identified`` the unconstrained identification.

    Raises
    ------
    RankDeficientError
        The data do not excite every base parameter (from the unconstrained fit).
    WrongTypeError
        ``data`` is neither a torque log nor static data.
    """
    logs = [data] if isinstance(data, TorqueLog) else data
    term: DataTerm | None = None
    if isinstance(data, StaticDataset):
        kw: dict[str, Any] = dict(rtol=rtol, drive=drive, estimator=estimator)
        residual = identify_static(robot, data, std="classical", **kw)  # sigma^2 (W^T W)^-1
        term = coefficient_term(residual)
        model = identify_static(robot, data, std=std or "robust", **kw)
        kind = "static"
    elif isinstance(logs, Sequence) and all(isinstance(g, TorqueLog) for g in logs):
        model = identify_recordings(
            robot,
            list(logs),
            names,
            structure=structure,
            cutoff_hz=cutoff_hz,
            max_gap_s=max_gap_s,
            decimate=decimate,
            drive=drive,
            estimator=estimator,
            std=std or "hac",  # the data term is the residual itself, whichever is reported
            rtol=rtol,
            folds=folds,
            validate_on=validate_on,
        )
        kind = "log"
    else:
        raise WrongTypeError(
            "data must be a TorqueLog, a sequence of them or a StaticDataset; got "
            f"{type(data).__name__}"
        )
    return consistent_from_identified(
        robot,
        model,
        term,
        kind=kind,
        prior=prior,
        bounds=bounds,
        total_mass=total_mass,
        options=options,
        constraints=constraints,
    )


def consistent_from_identified(
    robot: Robot,
    model: IdentifiedModel,
    term: DataTerm | None = None,
    *,
    kind: str = "log",
    prior: Prior | Robot | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    options: SDPOptions | None = None,
    constraints: Sequence[Callable[..., Any]] = (),
) -> ConsistentResult:
    """The one-step consistent fit of an unconstrained identification: its coefficients
    (and, from a torque log, its friction, of the law fitted) with their covariance as the data
    term, its held-out folds choosing the prior's weight and accepting the result.

    Parameters
    ----------
    robot : Robot
    model : IdentifiedModel
        The unconstrained fit (:func:`identify_consistent` makes it; several recordings:
        :func:`~dynid.identification.selection.identify_recordings`); its drive (a drive
        file's, or the direct drive of an armature) is kept.
    term : DataTerm, optional
        Default :func:`~dynid.feasibility.convex.data_term.coefficient_term` of ``model``
        (with its friction for ``kind="log"``), weighted by the fit's residual (its normal
        equations; its covariance when it kept none).
    kind : {"log", "static"}
    prior, bounds, total_mass, options, constraints
        As in :func:`~dynid.feasibility.convex.solve.solve_consistent`.
    """
    if term is None:  # a structure without friction (links, armature) has no joint fit
        term = coefficient_term(
            model,
            with_friction=kind == "log" and model.joint_fit is not None,
            weight="residual",
        )
    with stage("the consistent fit (a semidefinite program for each prior weight and fold)"):
        res = solve_consistent(
            robot,
            term,
            prior=prior,
            bounds=bounds,
            total_mass=total_mass,
            options=options,
            constraints=constraints,
            kind=kind,
        )
    res = replace(
        res,
        identified=model,
        determined=determined_with_share(model, term, res),
        rotor_inertia=_rotor_inertia(model, res.rotor_inertia),
        notes=res.notes + combined_notes(model.info.combined),
    )
    return res if model.drive is None else with_drive(res, model.drive)


def determined_with_share(
    model: IdentifiedModel, term: DataTerm, res: ConsistentResult
) -> Determined:
    """What the data of ``model`` determine (:func:`~dynid.feasibility.determined.
    determined_by_data`) with the prior's share in each value of the weighted fit ``res``
    (:func:`~dynid.feasibility.prior_share.prior_share`; left out for an exact or the
    closest fit, whose data term is no covariance, and for a term of other columns)."""
    det = determined_by_data(model)
    w = float(res.prior_weight)
    if res.fit != "weighted" or term.exact or not (math.isfinite(w) and w > 0):
        return det
    if term.P.shape[1] != len(det.labels):
        return det
    share = prior_share(term.P, term.A, res.phi, res.prior.phi, w, objective=res.options.objective)
    return det.with_share(share)


def _rotor_inertia(model: IdentifiedModel, ia: Any) -> Any:
    """The solved values of the model's terms in the base (``ia``, in order) as rotor
    inertias (n,) at the motors: each term maps its own (a masked armature: 0 for the
    rotors it does not hold); None when none is an inertia."""
    if ia is None:
        return None
    vals, start, out = np.asarray(ia, dtype=np.float64), 0, None
    for t in model.terms.values():
        if not t.term.in_base:
            continue
        k = len(t.term.labels)
        got = t.term.inertia(vals[start : start + k])
        start += k
        if got is not None:
            out = got if out is None else out + got
    return vals if start != vals.size else out


class ConvexMethod:
    """The convex method in the registry of consistent-parameter methods
    (:class:`~dynid.feasibility.methods.ConsistentMethod`): :func:`retrieve_sdp` from
    coefficients, :func:`identify_consistent` from a torque log or static data.

    One solver in this process: ``workers`` is refused, ``seed`` and ``progress`` (per
    finished run of a method with runs) have nothing to act on.
    """

    name = "sdp"
    description = "convex LMI retrieval with a prior (default)"
    options_type: type = SDPOptions
    parallel = False

    def _checked(self, options: Any, workers: int | None) -> SDPOptions | None:
        if workers is not None:
            raise OptionError(
                "workers apply to the penalty method (its runs); the convex method solves one "
                "problem in this process"
            )
        if options is not None and not isinstance(options, SDPOptions):
            raise WrongTypeError(
                f"the convex method takes SDPOptions; got {type(options).__name__}"
            )
        return options

    def from_coefficients(
        self,
        model: IdentifiedModel,
        *,
        prior: Prior | Robot | None = None,
        bounds: Bounds | None = None,
        total_mass: tuple[float, float] | None = None,
        options: SDPOptions | None = None,
        workers: int | None = None,
        seed: int | None = 0,
        progress: Callable[[Any], None] | None = None,
    ) -> ConsistentResult:
        """:func:`retrieve_sdp` (``workers`` refused: :class:`~dynid.exceptions.OptionError`)."""
        opts = self._checked(options, workers)
        return retrieve_sdp(model, prior=prior, bounds=bounds, total_mass=total_mass, options=opts)

    def from_data(
        self,
        robot: Robot,
        data: TorqueLog | StaticDataset,
        *,
        prior: Prior | Robot | None = None,
        bounds: Bounds | None = None,
        total_mass: tuple[float, float] | None = None,
        options: SDPOptions | None = None,
        workers: int | None = None,
        seed: int | None = 0,
        progress: Callable[[Any], None] | None = None,
    ) -> ConsistentResult:
        """:func:`identify_consistent` with its defaults for a torque log (the cut-off read
        from the log, ordinary least squares, held-out folds) (``workers`` refused)."""
        opts = self._checked(options, workers)
        return identify_consistent(
            robot, data, prior=prior, bounds=bounds, total_mass=total_mass, options=opts
        )


#: the convex method's entry in :data:`dynid.feasibility.methods.METHODS`
METHOD = ConvexMethod()
