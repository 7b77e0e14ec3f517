"""Validation of a dynamic model, with or without friction, against measured torques.

* :func:`validate_torques`: a model (identified, a robot through RNEA, or a callable) on a
  recorded log, prepared as for the friction fit (below).
* :func:`validate_newton_euler`: RNEA with a parameter set (the retrieved physically
  consistent ones, Gaz et al. 2019 Fig. 5) plus friction on states given as they are,
  optionally against an identified model on the same states.

The prediction is ``tau_hat = M ddq + c + g (+ tau_f(dq))`` from a rigid-body model (an
:class:`~dynid.identification.model.IdentifiedModel`, a :class:`~dynid.model.robot.Robot`
through RNEA, or a callable; see :data:`~dynid.friction.fit.TorqueModel`) and an optional
friction model (:mod:`dynid.friction.model`). The log is prepared as for the friction fit
(states low-pass filtered with zero phase, ``ddq`` from the filtered ``dq``, edges trimmed,
measured torques kept unfiltered by default), and the per-joint RMS, MSE and relative
error of :mod:`dynid.identification.metrics` are computed without and with friction
(Gaz et al. 2019, Sec. VI, Fig. 3 and Table II). With unfiltered torques the RMS of a
correct model equals the sensor noise.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from .._checks import caller_level
from ..dynamics.rnea import rnea
from ..exceptions import DynidWarning, OptionError, ShapeError, WrongTypeError
from ..identification.input_noise import exact_to_round_off
from ..identification.log import DEFAULT_CUTOFF_HZ, TorqueLog, checked_log, joint_side_log
from ..identification.metrics import TorqueErrors, torque_errors
from ..identification.model import IdentifiedModel, checked_model
from ..identification.model_sign import anticorrelated
from ..identification.prepare import (
    Preprocessing,
    at_measured_samples,
    prepare_log,
    prepared_blocks,
    resamples,
)
from ..identification.recordings import common_cutoff
from ..identification.trim import edge_seconds
from ..model.drive import Drive
from ..model.robot import Robot
from ..progress import report
from .fit import TorqueModel, model_drive, torques_through
from .model import (
    Friction,
    FrictionModel,
    FrictionSum,
    combined,
    friction_words,
    robot_friction,
)

__all__ = [
    "KEPT_SAMPLES",
    "RECORDED",
    "NewtonEulerValidation",
    "Validation",
    "errors_from_sums",
    "own_friction",
    "holds_cutoff",
    "model_torques",
    "recorded_cutoff",
    "validate_newton_euler",
    "validate_torques",
    "validated",
    "validated_log",
]


def own_friction(
    model: TorqueModel, drive: Drive | None = None
) -> FrictionModel | FrictionSum | None:
    """The friction that comes with a model, acting where it acts: an IdentifiedModel's
    friction terms (each its law, band and place; a
    :class:`~dynid.friction.model.FrictionSum` of friction at the motors and at the
    joints), a Robot's own where ``drive`` puts it
    (:func:`~dynid.friction.model.robot_friction`), or None.

    Parameters
    ----------
    model : TorqueModel
        An identified model, a robot or a callable (which has none).
    drive : Drive, optional
        The drive the robot's torques are read through: with its friction at the motors a
        robot's per-joint law acts per motor (``K^T f(K dq)``), as simulation puts it. An
        identified model's terms already hold their place; a drive given with one must be
        the one it was identified with.

    Raises
    ------
    DataError
        ``drive`` differs from the one the identified model was identified with.
    """
    if isinstance(model, IdentifiedModel):
        model_drive(model, drive)  # another drive than the model's is refused
        return combined(model.frictions)
    if isinstance(model, Robot):
        return robot_friction(model, drive)
    return None


def model_torques(
    model: IdentifiedModel | Robot,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    drive: Drive | None = None,
) -> NDArray[np.float64]:
    """A model's whole joint torques [N m] (N for a prismatic joint): what ``validate``
    and ``identify`` predict, where :func:`~dynid.dynamics.rnea.rnea` gives the links alone.

    .. math:: \\tau = M(q) \\ddot q + c(q, \\dot q) + g(q) + K^T \\mathrm{diag}(I_a) K
              \\ddot q + k (q - q_0) + \\tau_f(\\dot q)

    the links' inverse dynamics, the rotor inertias ``I_a`` through the transmission ``K``
    (an identified model's, or ``drive``'s known ``rotor_inertia`` for a robot), a joint
    spring (:attr:`~dynid.model.robot.Robot.spring`, an identified model's ``spring``
    term) and the model's own friction with its offsets, acting where it acts
    (:func:`own_friction`: at the motors of a drive, ``K^T f(K dq)``).

    Parameters
    ----------
    model : IdentifiedModel or Robot
        An identified model (``identification.json``), or a robot with its own friction
        and spring (a ``feasible.json``, robot TOML, URDF or MJCF read back).
    q, dq, ddq : array_like, shape (..., n)
        Joint positions [rad], velocities [rad/s], accelerations [rad/s^2] (m, m/s, m/s^2
        for prismatic joints), at the joints. Batch shapes broadcast.
    drive : Drive, optional
        The drive a robot's torques are read through (its rotor inertias and where its
        friction acts); an identified model's own when None (another one is refused).

    Returns
    -------
    tau : ndarray, shape (..., n)
        Joint torques [N m].

    Raises
    ------
    WrongTypeError
        ``model`` is neither an identified model nor a robot.
    ShapeError
        An input does not end in ``n`` or the batch shapes do not broadcast.
    DataError
        ``drive`` differs from the one the identified model was identified with.
    """
    model = checked_model(model)
    n = model.robot.n if isinstance(model, IdentifiedModel) else model.n
    arrays = [_checks.as_batch(k, x, (n,)) for k, x in (("q", q), ("dq", dq), ("ddq", ddq))]
    try:
        a, b, c = np.broadcast_arrays(*arrays)
    except ValueError as exc:
        shapes = ", ".join(str(x.shape) for x in arrays)
        raise ShapeError(f"q, dq, ddq: batch shapes do not broadcast; got {shapes}") from exc
    shape = a.shape
    a, b, c = (np.ascontiguousarray(x.reshape(-1, n)) for x in (a, b, c))
    d = drive if isinstance(model, Robot) else model_drive(model, drive)
    tau = np.array(torques_through(model, d, a, b, c), dtype=np.float64)
    friction = own_friction(model, drive)
    if friction is not None:
        tau = tau + friction.torques(b)
    return tau.reshape(shape)


@dataclass(frozen=True, slots=True, eq=False)
class Validation:
    """Predicted against measured torques on a prepared log.

    Attributes
    ----------
    log : TorqueLog
        Prepared log (filtered states, ``ddq``, trimmed); of a log longer than
        :data:`KEPT_SAMPLES`, every ``step``-th prepared sample (the errors are over every
        sample).
    tau_model : ndarray, shape (N, n)
        Rigid-body prediction [N m] at the samples of ``log``.
    tau_friction : ndarray, shape (N, n), or None
        Friction prediction [N m] at the samples of ``log``.
    without_friction : TorqueErrors
        Errors of ``tau_model`` over every prepared sample.
    with_friction : TorqueErrors or None
        Errors of ``tau_model + tau_friction`` over every prepared sample.
    friction : FrictionModel or None
    step : int
        ``log`` holds every ``step``-th prepared sample (1: all of them).
    tau_ss : ndarray, shape (n,), or None
        Sum over every prepared sample of the squared measured torques [N^2 m^2] (when
        ``step`` > 1: the errors of several logs are pooled from it).
    """

    log: TorqueLog
    tau_model: NDArray[np.float64]
    tau_friction: NDArray[np.float64] | None
    without_friction: TorqueErrors
    with_friction: TorqueErrors | None
    friction: FrictionModel | FrictionSum | None
    step: int = 1
    tau_ss: NDArray[np.float64] | None = None

    @property
    def tau_hat(self) -> NDArray[np.float64]:
        """The full prediction [N m] (N, n), friction included when given."""
        if self.tau_friction is None:
            return self.tau_model
        return self.tau_model + self.tau_friction

    @property
    def errors(self) -> TorqueErrors:
        """Errors of the full prediction (with friction when given)."""
        return self.with_friction if self.with_friction is not None else self.without_friction

    @property
    def added(self) -> str:
        """What ``friction`` adds, in words (:func:`~dynid.friction.model.friction_words`:
        offsets are not friction)."""
        return friction_words(self.friction)

    def as_dict(self) -> dict[str, object]:
        """JSON-ready summary: ``rms``, ``mse``, ``relative_error_percent`` of the full
        prediction, plus ``without_friction`` (and ``with_friction``) blocks and
        ``friction_terms`` (:attr:`added`: the blocks' "friction" may be offsets)."""
        out: dict[str, object] = dict(self.errors.as_dict())
        out["friction_model"] = None if self.friction is None else self.friction.kind
        out["friction_terms"] = self.added
        out["without_friction"] = self.without_friction.as_dict()
        if self.with_friction is not None:
            out["with_friction"] = self.with_friction.as_dict()
        return out


#: ``cutoff_hz`` of :func:`validate_torques`: the cut-off the model was identified with.
RECORDED: Literal["recorded"] = "recorded"


def recorded_cutoff(
    model: TorqueModel,
    log: TorqueLog | Sequence[TorqueLog] | None = None,
    recording: Sequence[int] | None = None,
) -> float | None:
    """The low-pass cut-off [Hz] an identified model's torque log was prepared with
    (``info.log.cutoff_hz`` of the classical route); for another model the one
    identification would read from ``log``'s motion
    (:func:`~dynid.identification.recordings.common_cutoff`: pieces of one recording,
    as ``recording`` says, read together on its time axis; the median over the
    recordings, each weighted by its samples), so that every
    model is judged on the samples prepared the same way; the library default without a
    log long enough to read it from. A model fitted unfiltered for its logs being exact
    to round-off (``cutoff_source`` ``"exact"``) holds no cut-off for other logs: none
    for exact ones, else the one read from their motion."""
    logs = [] if log is None else [log] if isinstance(log, TorqueLog) else list(log)
    if (
        isinstance(model, IdentifiedModel)
        and model.info.log is not None
        and holds_cutoff(model, logs)
    ):
        return model.info.log.cutoff_hz
    cut = common_cutoff(logs, recording)
    return DEFAULT_CUTOFF_HZ if cut is None else cut


def holds_cutoff(model: TorqueModel, logs: Sequence[TorqueLog]) -> bool:
    """Whether ``model`` holds the cut-off ``logs`` are prepared with: an identified
    model's record, unless it was fitted unfiltered for its logs being exact to round-off
    (``cutoff_source`` ``"exact"``) while ``logs`` are not exact."""
    if not (isinstance(model, IdentifiedModel) and model.info.log is not None):
        return False
    return model.info.log.cutoff_source != "exact" or exact_to_round_off(logs)


def validate_torques(
    model: TorqueModel,
    log: TorqueLog,
    *,
    friction: FrictionModel | FrictionSum | None = None,
    cutoff_hz: float | None | Literal["recorded"] = RECORDED,
    trim_s: float | None = None,
    filter_tau: bool = False,
    max_gap_s: float | None = None,
    drive: Drive | None = None,
    torque_delay_s: float | None = None,
) -> Validation:
    """Compare a model's torques with a measured log, without and with friction.

    Parameters
    ----------
    model : TorqueModel
        Rigid-body model (IdentifiedModel, Robot or callable ``f(q, dq, ddq)``).
    log : TorqueLog
        Measured log (e.g. the validation sinusoids, Gaz et al. 2019 eq. 31).
    friction : FrictionModel, optional
        Friction added to the prediction as it is (e.g. a fitted sigmoid, or the model's
        own where the drive puts it: :func:`own_friction` ``(model, drive)``).
    cutoff_hz, trim_s, filter_tau, max_gap_s
        Preparation of the log (:func:`~dynid.friction.fit.friction_residual`);
        ``cutoff_hz="recorded"`` (default): the cut-off an identified model was identified
        with, else the one read from the log's motion (:func:`recorded_cutoff`);
        ``trim_s`` None (default): the seconds identification trims at each end of a
        piece filtered at that cut-off, read from this log's motion
        (:func:`~dynid.identification.trim.edge_seconds`), as ``validate`` trims a
        recording, so that identify's held-out error and validate's of the same recording
        are over the same samples.
    drive : Drive, optional
        The drive the log was recorded through (motor side, currents); default: an
        identified model's own (:func:`model_drive`). Its known rotor inertias are added to
        a robot's torques (an identified model holds its own). Errors are in joint torques.
    torque_delay_s : float, optional
        How far the log's torques lag its positions [s]
        (:attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`); None
        (default): an identified model's recorded delay, else 0.

    Returns
    -------
    Validation

    Raises
    ------
    ShapeError
        The friction model's joint count differs from the log's.
    DataError
        From the preparation of the log; a drive other than the model's.
    """
    checked_log(log)
    if friction is not None and friction.n != log.n:
        raise ShapeError(f"friction model has {friction.n} joints; the log has {log.n}")
    d = model_drive(model, drive)
    jlog = joint_side_log(log, d)
    cut = recorded_cutoff(model, jlog) if isinstance(cutoff_hz, str) else cutoff_hz
    if trim_s is None and cut is not None:  # identification's rule on this log's motion
        trim_s = edge_seconds([jlog], [0], cut)
    del log  # a long log's raw signals are freed here when the caller holds no other reference
    if torque_delay_s is None:
        own = model.info.log if isinstance(model, IdentifiedModel) else None
        torque_delay_s = 0.0 if own is None else own.torque_delay_s
    prep = Preprocessing(
        cutoff_hz=cut,
        trim_s=trim_s,
        max_gap_s=max_gap_s,
        filter_tau=filter_tau,
        torque_delay_s=float(torque_delay_s),
    )
    return validated_log(model, jlog, friction, d, prep)


#: Prepared samples a :class:`Validation` keeps (for its figures): of a longer log it keeps
#: every k-th sample, the errors being summed over every sample block by block, so that
#: neither the prepared log nor the predictions are ever held whole.
KEPT_SAMPLES = 1 << 17


def validated_log(
    model: TorqueModel,
    jlog: TorqueLog,
    friction: FrictionModel | FrictionSum | None,
    drive: Drive | None,
    prep: Preprocessing,
) -> Validation:
    """:func:`validated` on the joint-side log ``jlog`` prepared as ``prep`` says
    (:func:`~dynid.identification.prepare.prepare_log`), on the log's own samples where
    the preparation resamples it and leaves the torques as measured
    (:func:`~dynid.identification.prepare.at_measured_samples`); a log longer than
    :data:`KEPT_SAMPLES` is prepared and predicted a block at a time
    (:func:`~dynid.identification.prepare.prepared_blocks`): the errors over every sample, the
    Validation keeping every k-th sample (``step``).

    Raises
    ------
    DataError
        From the preparation of the log.
    ShapeError
        The friction model's joint count differs from the log's.
    """
    step = -(-jlog.n_samples // KEPT_SAMPLES)
    own = not prep.filter_tau and prep.decimate == 1 and resamples(jlog, prep)
    if step <= 1:
        p = prepare_log(jlog, prep)
        if own:  # judged on the measured samples, not on a grid between them
            p = next(at_measured_samples([p], jlog), p)
        return validated(model, p, friction, drive)
    if friction is not None and friction.n != jlog.n:
        raise ShapeError(f"friction model has {friction.n} joints; the log has {jlog.n}")
    blocks = prepared_blocks(jlog, prep)
    if own:
        blocks = at_measured_samples(blocks, jlog)
    return _validated_blocks(model, blocks, friction, drive, step)


def _validated_blocks(
    model: TorqueModel,
    blocks: Iterator[TorqueLog],
    friction: FrictionModel | FrictionSum | None,
    drive: Drive | None,
    step: int,
) -> Validation:
    """:func:`validated` over consecutive prepared blocks: the errors summed over every
    sample, every ``step``-th sample (counted over all blocks) kept."""
    n = 0
    sums: dict[str, NDArray[np.float64]] = {}
    kept: dict[str, list[NDArray[np.float64]]] = {}
    N = 0
    for p in blocks:
        assert p.ddq is not None  # prepare_log always fills ddq
        report(f"predicting the torques: {N + p.n_samples:,} samples")
        if not sums:
            n = p.n
            sums = {k: np.zeros(n) for k in ("tau", "model", "sum")}
        tau_model = np.array(torques_through(model, drive, p.q, p.dq, p.ddq))
        _checks.finite("tau_model", tau_model)
        with np.errstate(over="ignore"):
            e = p.tau - tau_model
            sums["tau"] += np.einsum("ij,ij->j", p.tau, p.tau)
            sums["model"] += np.einsum("ij,ij->j", e, e)
            tf = None
            if friction is not None:
                tf = friction.torques(p.dq)
                e -= tf
                sums["sum"] += np.einsum("ij,ij->j", e, e)
        rows = slice((-N) % step, None, step)
        for name, x in (
            ("t", p.t),
            ("q", p.q),
            ("dq", p.dq),
            ("tau", p.tau),
            ("ddq", p.ddq),
            ("tau_model", tau_model),
            ("tau_friction", tf),
        ):
            if x is not None:
                kept.setdefault(name, []).append(np.array(x[rows]))
        N += p.n_samples
    joined = {k: np.concatenate(v) for k, v in kept.items()}
    log = TorqueLog(joined["t"], joined["q"], joined["dq"], joined["tau"], joined["ddq"])
    tf_all = joined.get("tau_friction")
    _warn_opposite_sign(log.tau, joined["tau_model"] + (0.0 if tf_all is None else tf_all))
    return Validation(
        log=log,
        tau_model=_checks.frozen(joined["tau_model"]),
        tau_friction=_checks.frozen(joined["tau_friction"]) if friction is not None else None,
        without_friction=errors_from_sums(sums["model"], sums["tau"], N),
        with_friction=(
            errors_from_sums(sums["sum"], sums["tau"], N) if friction is not None else None
        ),
        friction=friction,
        step=step,
        tau_ss=_checks.frozen(sums["tau"]),
    )


def validated(
    model: TorqueModel,
    p: TorqueLog,
    friction: FrictionModel | FrictionSum | None,
    drive: Drive | None,
) -> Validation:
    """The :class:`Validation` of ``model`` (and ``friction``) on a prepared joint-side log
    ``p`` (with ``ddq``) read through ``drive`` (its known rotors added to a robot's),
    ``friction`` added as it is (a robot's own placed by :func:`own_friction`).

    Raises
    ------
    ShapeError
        The friction model's joint count differs from the log's.
    """
    if friction is not None and friction.n != p.n:
        raise ShapeError(f"friction model has {friction.n} joints; the log has {p.n}")
    assert p.ddq is not None  # prepare_log always fills ddq
    tau_model = torques_through(model, drive, p.q, p.dq, p.ddq)  # a robot's: with rotors
    without = torque_errors(p.tau, tau_model)
    tf = with_ = None
    if friction is not None:
        tf = np.empty(p.dq.shape)
        for b in _blocks(p.n_samples):
            tf[b] = friction.torques(p.dq[b])
        with_ = _errors_of_sum(p.tau, tau_model, tf)
    _warn_opposite_sign(p.tau, tau_model if tf is None else tau_model + tf)
    return Validation(
        log=p,
        tau_model=tau_model,
        tau_friction=tf,
        without_friction=without,
        with_friction=with_,
        friction=friction,
    )


def _warn_opposite_sign(tau: NDArray[np.float64], tau_model: NDArray[np.float64]) -> None:
    """A :class:`DynidWarning` when the measured torques (N, n) [N m] have the opposite sign
    to the model's whole prediction (friction included: a geared drive's friction at the
    motors can outweigh the rigid body's torques, which then read as anti-correlated with
    a log the model predicts to 0.45 %) on most joints (a log recorded with another sign convention
    than the model's; the errors are then about 200 %)."""
    step = max(1, tau.shape[0] // 20_000)
    m, t = tau_model[::step], tau[::step]
    if not (np.all(np.isfinite(m)) and np.all(np.abs(m) < 1e150)):
        return  # a prediction that overflows: the caller names its source, not a sign
    mc, tc = m - m.mean(axis=0), t - t.mean(axis=0)
    spread = np.std(m, axis=0)
    found = anticorrelated(mc, tc, spread > 0.05 * max(float(spread.max(initial=0.0)), 1e-300))
    if found is not None:
        j, c = found
        warnings.warn(
            f"the measured torques are anti-correlated with the model's (correlation {c:+.2f} "
            f"on joint {j + 1}): the log's torque sign is probably opposite to the one the "
            "model was identified with; hint: a log recorded as the identification's was, or "
            "its torque columns negated",
            DynidWarning,
            stacklevel=caller_level(),
        )


#: Samples per block of the predictions of a long log (temporaries of one block only).
BLOCK_SAMPLES = 65_536


def _blocks(N: int) -> list[slice]:
    """Slices of :data:`BLOCK_SAMPLES` samples covering ``N``."""
    return [slice(a, a + BLOCK_SAMPLES) for a in range(0, N, BLOCK_SAMPLES)]


def _errors_of_sum(
    tau: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]
) -> TorqueErrors:
    """:func:`~dynid.identification.metrics.torque_errors` of ``a + b`` against ``tau``
    (N, n), without a full-length ``a + b``: a long log is summed block by block."""
    N = tau.shape[0]
    if N <= BLOCK_SAMPLES:
        with np.errstate(over="ignore"):  # beyond the float range: inf, said by the caller
            return torque_errors(tau, a + b)
    n = tau.shape[1]
    se2, sa2 = np.zeros(n), np.zeros(n)
    for k in _blocks(N):
        hat = a[k] + b[k]
        _checks.finite("tau_hat", hat)
        d = tau[k] - hat
        with np.errstate(over="ignore"):
            se2 += np.einsum("ij,ij->j", d, d)
            sa2 += np.einsum("ij,ij->j", tau[k], tau[k])
    return errors_from_sums(se2, sa2, N)


def errors_from_sums(se2: NDArray[np.float64], sa2: NDArray[np.float64], N: int) -> TorqueErrors:
    """:class:`~dynid.identification.metrics.TorqueErrors` from the per-joint sums (n,)
    over ``N`` samples of the squared errors ``se2`` [N^2 m^2] and of the squared measured
    torques ``sa2``: ``RMS_j = sqrt(se2_j / N)``, relative error
    ``100 sqrt(sum se2) / sqrt(sum sa2)`` [%] (infinite where the torques are all zero)."""
    m = se2 / N
    na_all = float(np.sqrt(sa2.sum()))
    na = np.sqrt(sa2)
    with np.errstate(divide="ignore", invalid="ignore"):
        per = np.where(na > 0, 100.0 * np.sqrt(se2) / na, np.inf)
    return TorqueErrors(
        rms=_checks.frozen(np.sqrt(m)),
        mse=_checks.frozen(m),
        relative_error_percent=100.0 * float(np.sqrt(se2.sum())) / na_all
        if na_all > 0
        else float("inf"),
        relative_error_percent_per_joint=_checks.frozen(per),
        n_samples=int(N),
    )


@dataclass(frozen=True, slots=True, eq=False)
class NewtonEulerValidation:
    """Predicted against measured torques on a validation trajectory.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Sample times [s].
    tau : ndarray, shape (N, n)
        Measured torques [N m].
    tau_rigid : ndarray, shape (N, n)
        RNEA torques with the feasible parameters [N m], friction excluded.
    tau_friction : ndarray, shape (N, n), or None
        Friction torques [N m] (None without a friction model).
    tau_reference : ndarray, shape (N, n), or None
        Identified model's torques ``Y_b beta`` (+ the same friction) [N m], if given.
    errors : TorqueErrors
        Of ``tau_model`` (rigid + friction) against ``tau``: per-joint ``rms`` [N m], ...
    errors_rigid : TorqueErrors
        Of ``tau_rigid`` alone.
    errors_reference : TorqueErrors or None
        Of ``tau_reference``.
    joint_names : tuple of str
    friction_kind : str or None
        ``"sigmoid"``, ``"classical"`` or None.
    """

    t: NDArray[np.float64]
    tau: NDArray[np.float64]
    tau_rigid: NDArray[np.float64]
    tau_friction: NDArray[np.float64] | None
    tau_reference: NDArray[np.float64] | None
    errors: TorqueErrors
    errors_rigid: TorqueErrors
    errors_reference: TorqueErrors | None
    joint_names: tuple[str, ...]
    friction_kind: str | None

    @property
    def tau_model(self) -> NDArray[np.float64]:
        """Full prediction, RNEA plus friction [N m] (N, n)."""
        return self.tau_rigid if self.tau_friction is None else self.tau_rigid + self.tau_friction

    @property
    def rms(self) -> NDArray[np.float64]:
        """Per-joint RMS error of the full prediction [N m] (n,)."""
        return self.errors.rms

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary (floats and lists)."""
        out: dict[str, Any] = {
            "joint_names": list(self.joint_names),
            "friction_model": self.friction_kind,
            "newton_euler": self.errors.as_dict(),
            "newton_euler_no_friction": self.errors_rigid.as_dict(),
            "units": {"rms": "N m", "mse": "N^2 m^2", "relative_error_percent": "%"},
        }
        if self.errors_reference is not None:
            out["identified_model"] = self.errors_reference.as_dict()
        return out


def _friction_model(robot: Robot, friction: Any) -> FrictionModel | FrictionSum | None:
    if isinstance(friction, str):
        if friction != "robot":
            raise OptionError(
                f"must be 'robot', None or a Friction; got {friction!r}", field="friction"
            )
        return robot_friction(robot)
    if friction is not None and not isinstance(friction, Friction):
        raise WrongTypeError(
            f"friction must be 'robot', None or a Friction, not a {type(friction).__name__} "
            "(sigmoid parameters (n, 3): dynid.SigmoidFriction.from_array(P))"
        )
    model = friction
    if model is not None and model.n != robot.n:
        raise ShapeError(f"friction model has {model.n} joints; robot {robot.name!r} has {robot.n}")
    return model


def validate_newton_euler(
    robot: Robot,
    t: ArrayLike,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    tau: ArrayLike,
    *,
    friction: Any = "robot",
    reference: IdentifiedModel | None = None,
) -> NewtonEulerValidation:
    """Compare Newton-Euler torques of a parameter set (plus friction) with measurements.

    .. math:: \\hat\\tau_k = \\mathrm{RNEA}(q_k, \\dot q_k, \\ddot q_k) + \\tau_f(\\dot q_k),
              \\quad \\mathrm{RMS}_j = \\sqrt{\\tfrac{1}{N}
              \\textstyle\\sum_k (\\tau_{kj} - \\hat\\tau_{kj})^2}

    Parameters
    ----------
    robot : Robot
        Kinematics, gravity and the (feasible) link parameters, e.g.
        ``RetrievalResult.robot``.
    t : array_like, shape (N,)
        Sample times [s].
    q, dq, ddq : array_like, shape (N, n)
        Joint positions [rad], velocities [rad/s], accelerations [rad/s^2].
    tau : array_like, shape (N, n)
        Measured joint torques [N m] (friction included).
    friction : "robot", None or Friction
        ``"robot"`` (default) uses ``robot.friction`` (none if the robot has none).
    reference : IdentifiedModel, optional
        An identified model evaluated on the same states (with the same friction), for
        comparison.

    Returns
    -------
    NewtonEulerValidation

    Raises
    ------
    ShapeError
        Shapes disagree (``t`` (N,), the others (N, n)) or the friction model has another
        joint count.
    NonFiniteError
        NaN or inf in an input.
    """
    n = robot.n
    t = _checks.as_array("t", t)
    if t.ndim != 1:
        raise ShapeError(f"t must have shape (N,); got {t.shape}")
    N = t.shape[0]
    arrs = [
        _checks.as_exact(k, v, (N, n))
        for k, v in (("q", q), ("dq", dq), ("ddq", ddq), ("tau", tau))
    ]
    q, dq, ddq, tau = arrs
    fr = _friction_model(robot, friction)
    tau_rigid = rnea(robot, q, dq, ddq)
    tau_f = None if fr is None else fr.torques(dq)
    full = tau_rigid if tau_f is None else tau_rigid + tau_f
    tau_ref = errs_ref = None
    if reference is not None:
        if reference.robot.n != n:
            raise ShapeError(f"reference model has {reference.robot.n} joints; robot has {n}")
        tau_ref = reference.torques(q, dq, ddq)
        if tau_f is not None:
            tau_ref = tau_ref + tau_f
        errs_ref = torque_errors(tau, tau_ref)
    return NewtonEulerValidation(
        t=_checks.frozen(t),
        tau=_checks.frozen(tau),
        tau_rigid=_checks.frozen(tau_rigid),
        tau_friction=None if tau_f is None else _checks.frozen(tau_f),
        tau_reference=None if tau_ref is None else _checks.frozen(tau_ref),
        errors=torque_errors(tau, full),
        errors_rigid=torque_errors(tau, tau_rigid),
        errors_reference=errs_ref,
        joint_names=robot.joint_names,
        friction_kind=None if fr is None else fr.kind,
    )
