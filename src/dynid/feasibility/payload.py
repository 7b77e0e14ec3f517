"""Payload identification: mass, centre of mass and inertia of a load on a known arm.

A load rigidly fixed to frame ``F`` (default ``flange``, on link ``k``) adds its standard
parameters, carried into link ``k`` coordinates, to link ``k``. With ``T = T_link_F`` the
pseudo-inertia transforms as ``J_link = T J_F T^T`` (:mod:`dynid.feasibility.lmi`), a
linear map ``phi_link = A phi_F``, so the measured quantities minus the arm's own are
linear in the load's parameters ``phi_F = [m, m c, J_F]`` (about ``F``'s origin, ``F`` axes):

.. math:: y - y_{arm}(q) = Y_k(q) \\, A \\, \\phi_F \\; (+ F(\\dot q) f)

* **static M and g** (:func:`identify_payload` with a
  :class:`~dynid.identification.data.StaticDataset`): ``y = [tril M; g]`` and ``Y`` the
  static regressor (Gaz et al. 2019, eq. 20); all 10 parameters;
* **static g only** (``gravity_only=True``): ``g`` depends on ``m`` and ``m c`` only, so
  the mass and the CoM are estimated and the inertia is not (``inertia_identified`` False);
* **a torque log** (:class:`~dynid.identification.log.TorqueLog`): zero-phase filtered and
  differentiated (:func:`~dynid.identification.log.prepare_log`), decimated to about ten
  samples per cutoff period (as :func:`~dynid.identification.classical.identify_from_log`),
  ``Y`` the torque regressor, and the classical friction ``fv, fc, fo`` per joint
  estimated alongside; a joint whose measured velocity never leaves its noise band
  (:func:`~dynid.identification.sanity.moving_joints`) does not move: its velocity and
  acceleration are zero in the regressor and its ``fv, fc`` are not fitted (zero), so
  nothing is fitted from noise;
* **difference method** (``unloaded=`` data of the same kind recorded without the load):
  the arm is first identified from the unloaded data (base parameters,
  :func:`~dynid.identification.static.identify_static` or
  :func:`~dynid.identification.classical.identify_from_log`) and its identified model is
  the arm; model errors common to both recordings cancel.

Physical consistency: the least-squares estimate is kept when its pseudo-inertia is
positive definite with ``lambda_min(J) >= margin tr(J)``; otherwise the estimate closest to
it in the metric of the data, ``||R (phi - phi_ls)||`` (``W = Q R``), subject to that LMI
(Wensing, Kim, Slotine, RA-L 2018), is solved for with cvxpy and Clarabel. For ``g`` only
the constraint is ``m > 0``.

Standard deviations: the heteroscedasticity-consistent (HC1) covariance of the least
squares (relative, multiplicative sensor noise gives rows of unequal variance), carried to
mass, CoM and inertia about the CoM through the Jacobian of that map (central differences).
When the LMI is active they describe the unconstrained estimate.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..dynamics.rnea import rnea
from ..dynamics.terms import gravity_torques, mass_matrix
from ..exceptions import DataError, ModelError, RankDeficientError, ShapeError, SolverError
from ..identification.classical import auto_decimation, friction_regressor, identify_from_log
from ..identification.data import StaticDataset
from ..identification.least_squares import LeastSquaresFit, fit_least_squares
from ..identification.log import DEFAULT_CUTOFF_HZ, TorqueLog, prepare_log
from ..identification.model import IdentifiedModel
from ..identification.sanity import moving_joints
from ..identification.static import identify_static
from ..model.inertia import inertia6_from_matrix, inertial_from_phi
from ..model.robot import Robot
from ..regressors.base import RANK_FLOOR
from ..regressors.static import static_regressor_columns, static_rows, static_vector
from ..regressors.terms import friction_labels
from ..regressors.torque import torque_regressor
from .lmi import phi_from_pseudo_inertia, pseudo_inertia, pseudo_inertia_margin

__all__ = ["PayloadEstimate", "identify_payload", "link_params_from_frame", "robot_with_payload"]


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
        for the difference method).
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
        ``fv, fc, fo`` per joint estimated alongside (torque logs).
    notes : tuple of str
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


def link_params_from_frame(T_link_frame: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 10x10 matrix ``A`` with ``phi_link = A phi_F`` for a body fixed at ``T_link_F``.

    From the pseudo-inertia's transformation ``J_link = T J_F T^T``.
    """
    T = np.asarray(T_link_frame, dtype=np.float64)
    E = np.eye(10)
    return np.stack([phi_from_pseudo_inertia(T @ pseudo_inertia(E[i]) @ T.T) for i in range(10)], 1)


def _arm(arm: Robot | IdentifiedModel) -> Robot:
    return arm.equivalent_robot if isinstance(arm, IdentifiedModel) else arm


def _kinematics(arm: Robot | IdentifiedModel) -> Robot:
    return arm.robot if isinstance(arm, IdentifiedModel) else arm


def _summary(phi: NDArray[np.float64], cov: NDArray[np.float64], full: bool):
    """Mass, CoM, inertia (about CoM) and their standard deviations from phi and its cov."""

    def f(p: NDArray[np.float64]) -> NDArray[np.float64]:
        m, c, I = inertial_from_phi(p)
        return np.concatenate([[m], c, inertia6_from_matrix(I)])

    p = phi.copy()
    k = cov.shape[0]
    scale = np.maximum(np.abs(p[:k]), 1e-6 * max(float(np.max(np.abs(p[:k]))), 1e-12))
    Jac = np.empty((10, k))
    for i in range(k):
        h = 1e-6 * scale[i]
        a, b = p.copy(), p.copy()
        a[i] += h
        b[i] -= h
        Jac[:, i] = (f(a) - f(b)) / (2 * h)
    C = Jac @ cov @ Jac.T
    std = np.sqrt(np.maximum(np.diag(C), 0.0))
    m, c, I = inertial_from_phi(p)
    if not full:
        std[4:] = np.nan
        I = np.zeros((3, 3))
    return float(m), c, I, float(std[0]), std[1:4], std[4:]


def _consistent(
    phi_ls: NDArray[np.float64], R: NDArray[np.float64], margin: float
) -> tuple[NDArray[np.float64], bool]:
    """The LMI-constrained estimate closest to ``phi_ls`` in ``||R (phi - phi_ls)||``."""
    if pseudo_inertia_margin(phi_ls) >= margin:
        return phi_ls, False
    import cvxpy as cp

    from .convex.solvers import clarabel

    s = np.maximum(np.abs(phi_ls), 1e-9 * max(float(np.max(np.abs(phi_ls))), 1e-12))
    x = cp.Variable(10)  # phi = s * x, so the variables are of order one
    phi = cp.multiply(s, x)
    J = _pseudo_inertia_expr(phi)
    Rs = R * s[None, :]
    obj = cp.sum_squares(Rs @ x - R @ phi_ls)
    cons = [J - margin * cp.trace(J) * np.eye(4) >> 0]
    prob = cp.Problem(cp.Minimize(obj), cons)
    try:
        prob.solve(solver=clarabel())
    except (cp.error.SolverError, ArithmeticError, ValueError) as exc:
        raise SolverError(f"payload: the consistent estimate was not found ({exc})") from exc
    if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
        raise SolverError(f"payload: the consistent estimate was not found (status {prob.status})")
    return s * np.asarray(x.value), True


def _pseudo_inertia_expr(phi):  # noqa: ANN001, ANN202 (cvxpy expressions)
    """cvxpy expression of :func:`~dynid.feasibility.lmi.pseudo_inertia` (linear in phi)."""
    E = np.eye(10)
    return sum(phi[i] * pseudo_inertia(E[i]) for i in range(10))


def identify_payload(
    arm: Robot | IdentifiedModel,
    data: StaticDataset | TorqueLog | Sequence[TorqueLog],
    *,
    frame: str = "flange",
    gravity_only: bool = False,
    unloaded: StaticDataset | TorqueLog | None = None,
    margin: float = 1e-6,
    cutoff_hz: float | None = DEFAULT_CUTOFF_HZ,
    rtol: float | None = None,
    max_gap_s: float | None = None,
) -> PayloadEstimate:
    """Estimate the load fixed to ``frame`` from data recorded with it on a known arm.

    Parameters
    ----------
    arm : Robot or IdentifiedModel
        The arm without the load: a robot with its parameters (built-in, feasible), or an
        identified model (its equivalent robot). Ignored for its parameters when
        ``unloaded`` is given (then only its kinematics and gravity are used).
    data : StaticDataset, TorqueLog or a sequence of TorqueLog
        Recorded with the load: ``q`` (N, n) [rad], ``M`` [kg m^2], ``g`` [N m]; or a log;
        or several logs (recordings, or the pieces of one between its gaps), each filtered
        and differentiated on its own, their rows stacked.
    frame : str
        The frame the load is fixed to; its CoM and inertia are given in it.
    gravity_only : bool
        Static data: use ``g`` only (mass and CoM; the inertia is not identified).
    unloaded : StaticDataset or TorqueLog, optional
        The same kind of data without the load (difference method).
    margin : float
        LMI margin: ``lambda_min(J) >= margin tr(J)``.
    cutoff_hz : float or None
        Torque logs: zero-phase low-pass cutoff [Hz] (None: no filtering).
    rtol : float, optional
        Relative rank tolerance: of the unloaded arm's identification (None: its default,
        the rank at a clear singular-value gap) and of the load's least squares (None:
        1e-10).
    max_gap_s : float, optional
        Torque logs: longest gap bridged by interpolation [s]
        (:func:`~dynid.identification.log.prepare_log`).

    Returns
    -------
    PayloadEstimate

    Raises
    ------
    UnknownNameError
        ``frame`` is not a frame of the robot.
    ModelError
        The frame is on the base (a load there does not move).
    ShapeError
        Data of another joint count; ``unloaded`` of another kind than ``data``.
    RankDeficientError
        The data do not excite the load's parameters (configurations too alike, a load
        that never rotates, a log in which no joint moves); the message names them.
    DataError
        The least-squares estimate of the mass is not positive (no load in the data, or a
        wrong model of the arm).
    SolverError
        The constrained problem failed.
    """
    kin = _kinematics(arm)
    f = kin.frame(frame)
    if f.link == 0:
        raise ModelError(f"frame {frame!r} is on the base; a load there does not move")
    n, k = kin.n, f.link
    logs = tuple(data) if isinstance(data, Sequence) else None
    if logs is not None and not logs:
        raise DataError("no torque log given")
    items: tuple[StaticDataset | TorqueLog, ...] = logs if logs is not None else (data,)  # type: ignore[assignment]
    for one in items:
        if one.q.shape[-1] != n:
            raise ShapeError(f"data have {one.q.shape[-1]} joints; robot {kin.name!r} has {n}")
    notes: list[str] = []
    static = isinstance(data, StaticDataset)
    robot = _arm_without_load(arm, kin, unloaded, static, cutoff_hz, rtol, notes)
    A = link_params_from_frame(f.T_link_frame)
    cols = slice(10 * (k - 1), 10 * k)
    kept = None
    if isinstance(data, StaticDataset):
        W, yv, route = _static_rows(robot, data, cols, A, gravity_only, notes)
    else:
        W, yv, route, kept = _log_rows(robot, items, cols, A, cutoff_hz, notes, max_gap_s)  # type: ignore[arg-type]
    if unloaded is not None:
        route += ", difference"
    p = 4 if (static and gravity_only) else 10
    fit = _fit_load(W, yv, kept, rtol, p, static)
    est = np.asarray(fit.beta)
    cov = np.asarray(fit.covariance)[:p, :p]
    friction = None if static else est[10:].reshape(n, 3)
    phi, active, marg = _load_parameters(est[:p], W, margin, notes)
    m, c, I, sm, sc, si = _summary(phi, cov, p == 10)
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
        friction=friction,
        notes=tuple(notes),
    )


def _arm_without_load(
    arm: Robot | IdentifiedModel,
    kin: Robot,
    unloaded: StaticDataset | TorqueLog | None,
    static: bool,
    cutoff_hz: float | None,
    rtol: float | None,
    notes: list[str],
) -> Robot:
    """The arm's robot: ``arm``'s own parameters, or identified from ``unloaded``."""
    if unloaded is None:
        return _arm(arm)
    if isinstance(unloaded, StaticDataset) != static:
        raise ShapeError("unloaded must be the same kind of data as data (static or log)")
    if isinstance(unloaded, StaticDataset):
        model = identify_static(kin, unloaded, rtol=rtol)
    else:
        model = identify_from_log(kin, unloaded, cutoff_hz=cutoff_hz, rtol=rtol)
    notes.append(
        f"difference method: arm identified from the unloaded data "
        f"({model.base.rank} base parameters); the standard deviations leave out "
        "the uncertainty of that fit"
    )
    return model.equivalent_robot


def _static_rows(
    robot: Robot,
    data: StaticDataset,
    cols: slice,
    A: NDArray[np.float64],
    gravity_only: bool,
    notes: list[str],
) -> tuple[NDArray[np.float64], NDArray[np.float64], str]:
    """Regressor rows (in the load's frame parameters) and targets of static data.

    Only the load link's 10 columns of the static regressor are computed, a block of
    configurations at a time (a 50-joint arm's full regressor is 5.3 MB a configuration);
    the fit of the load takes its rows whole, ``(N rows, <= 10)``: a tenth of one link's
    share of the full regressor.
    """
    n, q = robot.n, data.q
    idx = np.arange(10 * n)[cols]
    step = max(1, (64 << 20) // (8 * static_rows(n) * 10))
    Y = np.concatenate(
        [
            static_regressor_columns(robot, q[a : a + step], idx).transpose(2, 1, 0) @ A
            for a in range(0, q.shape[0], step)
        ]
    )
    y = static_vector(data.M, data.g) - static_vector(
        mass_matrix(robot, q), gravity_torques(robot, q)
    )
    route = "static M and g"
    if gravity_only:
        rows = n * (n + 1) // 2
        Y, y = Y[:, rows:, :4], y[:, rows:]
        route = "static g"
        notes.append("g only: mass and CoM identified, the inertia is not")
    return Y.reshape(-1, Y.shape[-1]), y.reshape(-1), route


_LOAD_LABELS = ("m", "mcx", "mcy", "mcz", "Jxx", "Jxy", "Jxz", "Jyy", "Jyz", "Jzz")


def _fit_load(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    kept: NDArray[np.bool_] | None,
    rtol: float | None,
    p: int,
    static: bool,
) -> LeastSquaresFit:
    """The least squares of the load (and friction) columns.

    Without ``rtol``, every direction of the load's ``p`` parameters must be excited
    (:func:`_excited`): a load rotated about one axis only excites some of its 10
    parameters, and the noise of the measured positions would otherwise fill the others.

    Raises
    ------
    RankDeficientError
        Naming the load's parameters the data do not excite, and what would excite them.
    """
    labels = _LOAD_LABELS[:p] + friction_labels((W.shape[1] - p) // 3)
    if rtol is None:
        r, names = _excited(W, p, kept, labels)
        if r < p:
            raise _not_excited(r, p, names, static)
    try:
        return fit_least_squares(
            W, y, kept=kept, rtol=1e-10 if rtol is None else rtol, std="robust"
        )
    except RankDeficientError as exc:
        by_column = {f"column {i}": label for i, label in enumerate(labels)}
        shown = tuple(by_column.get(d, d) for d in exc.dependent)
        raise _not_excited(exc.rank, exc.needed, shown, static) from None


def _excited(
    W: NDArray[np.float64], p: int, kept: NDArray[np.bool_] | None, labels: tuple[str, ...]
) -> tuple[int, tuple[str, ...]]:
    """How many directions of the load's parameters (the first ``p`` columns) the data
    excite, and the labels of the others' large entries.

    Every column is scaled to unit norm; the load's columns are then freed of what the
    other fitted columns (friction, offsets) explain, and a direction whose singular
    value stays below :data:`~dynid.regressors.base.RANK_FLOOR` (a 1e-3 part of a unit
    column) is not excited: its estimate would be noise amplified a thousandfold.
    """
    import scipy.linalg  # as the rest of the module: scipy on first use

    cols = np.arange(W.shape[1]) if kept is None else np.flatnonzero(kept)
    other = cols[cols >= p]
    M = np.concatenate([W[:, other], W[:, :p]], axis=1)
    if M.shape[0] < M.shape[1]:
        return p, ()  # fewer rows than columns: the least squares says so
    norms = np.linalg.norm(M, axis=0)
    M /= np.where(norms > 0, norms, 1.0)
    R = scipy.linalg.qr(M, mode="r")[0]
    _, sv, Vt = np.linalg.svd(R[other.size : other.size + p, other.size :])
    r = int(np.sum(sv > RANK_FLOOR))
    null = np.abs(Vt[r:])
    names = tuple(labels[i] for i in np.flatnonzero(null.max(axis=0, initial=0.0) > 0.3))
    return r, names


def _not_excited(
    rank: int | None, needed: int | None, names: tuple[str, ...], static: bool
) -> RankDeficientError:
    hint = (
        "static data at more varied configurations (with --gravity-only: mass and CoM only)"
        if static
        else "a log that moves the joints carrying the load, its wrist included, so that "
        "the load rotates about several axes (or static data)"
    )
    return RankDeficientError(
        f"the data do not excite the load's parameters (rank {rank} of {needed}; "
        f"unexcited combinations of {', '.join(names) or '?'}); hint: {hint}",
        rank=rank,
        needed=needed,
        dependent=names,
    )


def _load_columns(
    robot: Robot,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    cols: slice,
    A: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The torque regressor's columns ``cols`` mapped by ``A``, (N, n, p), computed a block
    of samples at a time (the full regressor of one block held, 64 MB at most)."""
    n = robot.n
    step = max(1, (64 << 20) // (8 * n * 10 * n))
    parts = []
    for k in range(0, q.shape[0], step):
        b = slice(k, k + step)
        parts.append(torque_regressor(robot, q[b], dq[b], ddq[b])[..., cols] @ A)
    return np.concatenate(parts)


def _log_rows(
    robot: Robot,
    logs: Sequence[TorqueLog],
    cols: slice,
    A: NDArray[np.float64],
    cutoff_hz: float | None,
    notes: list[str],
    max_gap_s: float | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], str, NDArray[np.bool_]]:
    """Regressor rows (the load's parameters, then classical friction per joint), targets
    of torque logs, each filtered (gaps up to ``max_gap_s`` bridged) and decimated on its own,
    and the columns fitted (the viscous and Coulomb friction of joints that never leave
    their velocity noise band are not). The torque regressor is computed a block of
    samples at a time, its load link's columns kept: the rows fitted are held whole
    (``N n`` rows of ``10 + 3 n`` columns; the fit of the load needs them), not the
    ``10 n`` columns of every link."""
    still = ~moving_joints(np.concatenate([one.dq for one in logs]))
    Ws, ys = [], []
    for data in logs:
        log = prepare_log(data, cutoff_hz=cutoff_hz, max_gap_s=max_gap_s)
        ddq = log.ddq
        assert ddq is not None  # prepare_log always differentiates
        sl = slice(None, None, auto_decimation(data.sample_rate, cutoff_hz))
        # a still joint's filtered velocity is noise: it does not move
        q_, dq_, ddq_ = log.q[sl], log.dq[sl] * ~still, ddq[sl] * ~still
        Y = _load_columns(robot, q_, dq_, ddq_, cols, A)
        Y = np.concatenate([Y, friction_regressor(dq_)], axis=-1)
        Ws.append(Y.reshape(-1, Y.shape[-1]))
        ys.append((np.asarray(log.tau[sl]) - rnea(robot, q_, dq_, ddq_)).reshape(-1))
    n = logs[0].n
    kept = np.ones(Ws[0].shape[-1], dtype=bool)
    kept[10:] = ~(np.repeat(still, 3) & (np.arange(3 * n) % 3 != 2))
    notes.append("classical friction fv, fc, fo per joint estimated alongside")
    if len(logs) > 1:
        notes.append(f"{len(logs)} torque logs (recordings or pieces), each filtered on its own")
    if still.any():
        which = ", ".join(str(j + 1) for j in np.flatnonzero(still))
        notes.append(
            f"joint(s) {which} never leave their velocity noise band: taken as still, "
            "their friction fv, fc is not identifiable and is zero (not fitted from noise)"
        )
    route = "torque log" if len(logs) == 1 else f"{len(logs)} torque logs"
    return np.concatenate(Ws), np.concatenate(ys), route, kept


def _load_parameters(
    est: NDArray[np.float64], W: NDArray[np.float64], margin: float, notes: list[str]
) -> tuple[NDArray[np.float64], bool, float]:
    """The load's 10 parameters from the least-squares ``est`` (checked for a positive
    mass; 4: mass and first moments; 10: moved into the consistent set by the LMI)."""
    phi_ls = np.zeros(10)
    phi_ls[: est.size] = est
    if phi_ls[0] <= 0:  # both routes: the LMI would turn no load into 1e-22 kg, silently
        raise DataError(
            f"the estimated load mass is {phi_ls[0]:.6g} kg (not positive); "
            "is a load mounted, and is the arm's model right?"
        )
    if est.size == 4:
        return phi_ls, False, float("nan")
    import scipy.linalg  # as the rest of the module: scipy on first use

    R = scipy.linalg.qr(W[:, :10], mode="r")[0][:10]
    phi, active = _consistent(phi_ls, R, margin)
    if active:
        notes.append(
            "the least-squares estimate was not physically consistent; the LMI "
            f"(margin {margin:g}) moved it; standard deviations are the unconstrained ones"
        )
    return phi, active, float(pseudo_inertia_margin(phi))


def robot_with_payload(robot: Robot, est: PayloadEstimate, *, name: str = "payload") -> Robot:
    """The robot carrying the load: :meth:`Robot.with_tool` at the estimate's frame."""
    return robot.with_tool(np.eye(4), est.mass, est.com, est.inertia, parent=est.frame, name=name)
