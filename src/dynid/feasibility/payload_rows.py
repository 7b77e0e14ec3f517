"""The rows of a payload fit: the load's regressor columns and what the arm leaves of the data.

The load fixed to a frame on link ``k`` adds ``Y_k A phi_F`` to the arm's torques
(:mod:`dynid.feasibility.payload`); the targets are the measured quantities minus the
arm's whole prediction (:class:`~dynid.feasibility.payload_arm.ArmModel`).

* :func:`static_load_rows`: ``[tril M; g]`` of static data;
* :func:`log_rows`: recordings prepared as identification prepares them
  (:func:`~dynid.identification.recordings.prepare_recordings`: read through the drive,
  unwrapped, cut at gaps longer than ``max_gap_s``, each piece filtered, differentiated
  and decimated on its own at one cut-off), with the classical friction ``fv, fc, fo`` per
  joint beside the load's columns: what the arm's own friction leaves (the load presses
  the bearings harder), or all of it for an arm modelled without friction. The torques
  are low-passed, which rounds the step of Coulomb friction at a velocity reversal: the
  Coulomb columns and the arm's own friction go through the same low-pass, as
  identification's rows do (:func:`~dynid.identification.log_rows.stepped_columns`);
  left sharp, they leave a residual at every reversal that the load's inertia absorbs;
* :func:`log_preparation`: the cut-off and decimation: given, else the identified model's
  recorded ones, else read from the recordings' motion as identification reads them;
* :func:`filtered_noise_rms`: the RMS the torque sensors' noise leaves in the rows after
  the low-pass, what a perfect model's residual comes to.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from ..identification.data import StaticDataset
from ..identification.log import TorqueLog, joint_side_log
from ..identification.log_rows import stepped_columns
from ..identification.model import IdentifiedModel
from ..identification.recordings import Recordings
from ..identification.structure import Structure
from ..identification.velocity_noise import moving_joints
from ..model.drive import Drive
from ..regressors.static import static_regressor_columns, static_rows, static_vector
from ..regressors.torque import torque_regressor
from ..signals import lowpass_noise_gain
from .payload_arm import ArmModel, FrictionTorques
from .payload_fit import friction_told_apart
from .payload_friction import friction_term

__all__ = [
    "AS_WELL",
    "filtered_noise_rms",
    "log_preparation",
    "log_rows",
    "own_friction_note",
    "static_load_rows",
    "still_joints",
]


def static_load_rows(
    arm: ArmModel,
    data: StaticDataset,
    cols: slice,
    A: NDArray[np.float64],
    gravity_only: bool,
    notes: list[str],
) -> tuple[NDArray[np.float64], NDArray[np.float64], str, NDArray[np.float64]]:
    """Regressor rows (in the load's frame parameters), targets (measured minus the arm's)
    and the arm's modelled rows of static data.

    Only the load link's 10 columns of the static regressor are computed, a block of
    configurations at a time (a 50-joint arm's full regressor is 5.3 MB a configuration);
    the fit of the load takes its rows whole, ``(N rows, <= 10)``.
    """
    robot = arm.robot
    n, q = robot.n, data.q
    idx = np.arange(10 * n)[cols]
    step = max(1, (64 << 20) // (8 * static_rows(n) * 10))
    Y = np.concatenate(
        [
            static_regressor_columns(robot, q[a : a + step], idx).transpose(2, 1, 0) @ A
            for a in range(0, q.shape[0], step)
        ]
    )
    own = static_vector(arm.mass_matrix(q), arm.gravity_torques(q))
    y = static_vector(data.M, data.g) - own
    route = "static M and g"
    if gravity_only:
        rows = n * (n + 1) // 2
        Y, y, own = Y[:, rows:, :4], y[:, rows:], own[:, rows:]
        route = "static g"
        notes.append("g only: mass and CoM identified, the inertia is not")
    return Y.reshape(-1, Y.shape[-1]), y.reshape(-1), route, own.reshape(-1)


def log_preparation(
    arm: IdentifiedModel | Any,
    logs: Sequence[TorqueLog],
    cutoff_hz: float | None | Literal["recorded"],
    decimate: int | None,
) -> tuple[float | None | Literal["auto"], int | None, str]:
    """The cut-off [Hz] (``"auto"``: read from the motion), the decimation (None: the
    default for the cut-off) and where they come from (``"given"``, ``"model"`` or
    ``"motion"``). The model's decimation is reused for recordings at the rate it was
    identified from (within 1 %)."""
    if not isinstance(cutoff_hz, str):
        return cutoff_hz, decimate, "given"
    info = arm.info.log if isinstance(arm, IdentifiedModel) else None
    if info is None:
        return "auto", decimate, "motion"
    own = info.preprocessing
    if decimate is None and logs:
        rate = float(np.median([log.sample_rate for log in logs]))
        if abs(rate - info.sample_rate_hz) <= 0.01 * info.sample_rate_hz:
            decimate = own.decimate
    return own.cutoff_hz, decimate, "model"


def still_joints(logs: Sequence[TorqueLog], drive: Drive | None) -> NDArray[np.bool_]:
    """Joints whose measured velocity (joint side) never leaves its noise band in any
    recording (:func:`~dynid.identification.velocity_noise.moving_joints`)."""
    return ~moving_joints(np.concatenate([joint_side_log(log, drive).dq for log in logs]))


def _load_columns(
    robot: Any,
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


@dataclass(frozen=True, slots=True, eq=False)
class _ArmFriction:
    """The arm's own friction torques as one column that steps at a reversal, for
    :func:`~dynid.identification.log_rows.stepped_columns`: low-passed whole (its smooth
    part, far below the cut-off, passes the filter all but unchanged). Joints in ``still`` (n,)
    are taken at rest, as in the load's rows."""

    friction: FrictionTorques
    still: NDArray[np.bool_]

    @property
    def labels(self) -> tuple[str, ...]:
        """The one column: the friction torque."""
        return ("tau_f",)

    @property
    def steps(self) -> NDArray[np.bool_]:
        """(1,): it steps at a reversal."""
        return np.ones(1, dtype=bool)

    def torque_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """The friction torques [N m] (B, n, 1) at joint velocities ``dq`` (B, n)."""
        return np.asarray(self.friction.torques(dq * ~self.still))[..., None]


def log_rows(
    arm: ArmModel,
    data: Recordings,
    still: NDArray[np.bool_],
    cols: slice,
    A: NDArray[np.float64],
    notes: list[str],
    friction: Structure | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], str, NDArray[np.bool_], NDArray[np.float64]]:
    """Regressor rows (the load's parameters, then the friction per joint: classical, or
    that of ``friction``, :func:`~dynid.feasibility.payload_friction.friction_term`),
    targets (measured torques minus the arm's) of prepared recordings, the columns fitted
    (a ``still`` joint's friction is not, but for its offset: its velocity is noise, taken
    as zero; nor a friction column the data do not tell from the others, the offset of a
    joint that turns one way throughout, noted:
    :func:`~dynid.feasibility.payload_fit.friction_told_apart`), and the arm's torques
    subtracted [N m] (its friction included when subtracted). The rows are held whole
    (``N n`` rows of ``10 + 3 n`` columns for the classical friction), not the ``10 n``
    columns of every link.

    The arm's own friction is kept in its torques when the rows explain the targets with
    it better than without it (a smaller least-squares residual, the same columns
    fitted): a friction law the loaded data do not follow (a robot file's published
    sigmoid on an arm with viscous friction only) would otherwise bias the load; without
    it, the classical friction fitted alongside is the arm's whole friction."""
    robot = arm.robot
    n = robot.n
    classical = friction_term(friction, data, n)
    alongside = (
        "classical friction fv, fc, fo"
        if friction is None
        else f"friction {friction.name.removeprefix('links + ')}"
    )
    own = None if arm.friction is None else _ArmFriction(arm.friction, still)
    Ws, ys, fs, taus = [], [], [], []
    for piece in data.pieces:
        log = piece.log
        assert log.ddq is not None  # prepared logs are differentiated
        q, dq, ddq = log.q, log.dq * ~still, log.ddq * ~still
        Y = _load_columns(robot, q, dq, ddq, cols, A)
        Y = np.concatenate([Y, stepped_columns(classical, log, **piece.filtering)], axis=-1)
        Ws.append(Y.reshape(-1, Y.shape[-1]))
        taus.append(np.asarray(log.tau).ravel())
        ys.append(taus[-1] - arm.torques(q, dq, ddq, with_friction=False).ravel())
        if own is not None:
            fs.append(stepped_columns(own, log, **piece.filtering).ravel())
    kept = np.ones(Ws[0].shape[-1], dtype=bool)
    kept[10:] = [not (still[_joint(lab)] and not lab.startswith("fo")) for lab in classical.labels]
    W, y = np.concatenate(Ws), np.concatenate(ys)
    kept, confounded = friction_told_apart(W, kept, classical.labels, 10)
    if fs:
        y = _with_own_friction(W[:, kept], y, np.concatenate(fs), arm, notes, alongside)
    else:
        notes.append(f"{alongside} per joint estimated alongside (the arm's model has no friction)")
    if len(data.pieces) > 1:
        notes.append(
            f"{data.source}: each recording and each piece between gaps filtered on its own"
        )
    if still.any():
        which = ", ".join(str(j + 1) for j in np.flatnonzero(still))
        notes.append(
            f"joint(s) {which} never leave their velocity noise band: taken as still, "
            "their friction fv, fc is not identifiable and is zero (not fitted from noise)"
        )
    if confounded is not None:
        notes.append(confounded)
    k = len(data.names)
    route = "torque log" if k == 1 else f"{k} torque logs"
    return W, y, route, kept, np.concatenate(taus) - y


def _joint(label: str) -> int:
    """The 0-based joint of a friction coefficient's label (``fc3``: 2)."""
    return int(label[len(label.rstrip("0123456789")) :]) - 1


def filtered_noise_rms(data: Recordings) -> float | None:
    """The RMS [N m] of the torque noise in the prepared rows: each piece's white noise per
    joint (:attr:`~dynid.identification.prepared_log.PreparedLog.torque_noise_std`, read
    from its raw torques) through the low-pass's noise gain
    (:func:`~dynid.signals.lowpass_noise_gain`), weighted by the piece's samples,

    .. math:: \\sqrt{\\sum_p N_p g_p^2 \\sum_j \\sigma_{pj}^2 \\Big/ \\Big(n \\sum_p N_p\\Big)};

    None when a piece's noise is not known."""
    total = count = 0.0
    for p in data.pieces:
        if p.torque_noise_std is None:
            return None
        g = lowpass_noise_gain(p.sample_rate_hz, p.cutoff_hz)
        total += p.log.n_samples * g * g * float(np.sum(np.square(p.torque_noise_std)))
        count += p.log.n_samples * p.n
    return float(np.sqrt(total / count)) if count else None


def _with_own_friction(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    f: NDArray[np.float64],
    arm: ArmModel,
    notes: list[str],
    alongside: str,
) -> NDArray[np.float64]:
    """The targets ``y`` [N m] less the arm's own friction ``f`` when that explains the
    rows ``W`` better (:func:`log_rows`), else ``y``; the choice noted (``alongside``:
    the friction estimated beside the load, as :func:`own_friction_note` names it)."""
    scale = np.linalg.norm(W, axis=0)
    Ws = W / np.where(scale > 0, scale, 1.0)

    def rms(t: NDArray[np.float64]) -> float:
        x = np.linalg.lstsq(Ws, t, rcond=None)[0]
        return float(np.sqrt(np.mean((t - Ws @ x) ** 2)))

    law = arm.friction.kind if arm.friction is not None else "?"
    own, bare = rms(y - f), rms(y)
    notes.append(own_friction_note(law, own, bare, alongside))
    return y - f if own <= bare else y


#: Residuals within this fraction of each other fit "as well": neither is called better.
AS_WELL = 0.01


def own_friction_note(
    law: str, own: float, bare: float, alongside: str = "classical friction fv, fc, fo"
) -> str:
    """The note of the choice :func:`log_rows` makes: the arm's own friction (of law
    ``law``) subtracted when the residual RMS [N m] with it, ``own``, is not above the one
    without it, ``bare``; else left out, "better" only when ``bare`` is lower by more
    than :data:`AS_WELL`, "as well" otherwise. The two printed with the digits that tell
    them apart; ``alongside`` names the friction estimated beside the load."""
    a, b = _apart(own, bare)
    if own <= bare:
        return (
            f"the arm's own friction ({law}) subtracted, {alongside} per "
            f"joint estimated alongside as its correction (residual RMS {a} N m; "
            f"{b} without the arm's friction)"
        )
    how = "better" if own - bare > AS_WELL * own else "as well (within 1 %) as with it"
    return (
        f"the arm's own friction ({law}) left out: the loaded data follow the "
        f"{alongside} estimated alongside {how} (residual RMS {b} N m; {a} with "
        "the arm's friction)"
    )


def _apart(x: float, y: float) -> tuple[str, str]:
    """``x`` and ``y`` printed with the fewest significant digits, 3 to 8, that tell them
    apart (the same text only when they agree to 8 digits)."""
    for d in range(3, 9):
        sx, sy = f"{x:.{d}g}", f"{y:.{d}g}"
        if sx != sy:
            break
    return sx, sy
