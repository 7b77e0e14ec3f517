"""The sign of a log's torques against the model's: its gravity torques and its whole
rigid-body torques.

The measured torques are compared with the model's gravity torques ``g(q)`` at the logged
configurations and with its whole rigid-body torques ``M ddq + c + g`` along the logged
motion (with the robot's own link parameters, when it has any): a correlation below
``-0.5`` with both on a joint that gravity loads (or, where the whole torques explain a
joint's at about their own scale, a correlation of -0.8 or below) means the torque sign is
opposite to the model's, refused by ``identify`` and ``observe`` and warned by
``validate``: on every joint judged, ``--units tau=-1``; on some, naming them and the
``--units tau2=-1`` entries that flip them alone (:func:`opposite_sign`). Each comparison
alone can be fooled: on 2 s of fast motion a Panda's elbow torques of the right sign
correlated -0.70 with its gravity torques (+0.99 with the whole torques), and a
description's poor inertias could turn the whole torques. Where the whole torques explain
other joints at their scale, a joint is called opposite only if the negated ones explain it
at about its own (least-squares factor within :data:`CONFIRMED_SLOPE`): a 60 N m/rad spring
the rigid bodies lack turned a Panda shoulder's correlation to -0.51 at a factor of -0.29,
and that is no sign to flip; nor where the torques as read are the model's plus a function
of the joint's own position and friction, far better than the negated ones
(:func:`_reads_right`: on another recording the same spring gave -0.96 at -1.17, as a
flipped sign would; the samples whose velocity is within its noise left out, where a
Coulomb friction of 80 N m steps). Where friction outweighs a loaded joint's rigid bodies
the correlations cannot see a flip: a joint whose negated torques are so explained while
its friction as read pushes is called opposite (:func:`_pushing_as_read`; of a joint gravity
does not load, only beside another found opposite). A robot's joint
spring (:attr:`~dynid.model.robot.Robot.spring`) is part of its torques at rest and in
motion. Not judged on a joint whose gravity torques span less than
:data:`GRAVITY_RANGE_SHARE` of the log's largest (a short stretch, whose torque variations
are the motion's).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..dynamics.rnea import rnea
from ..dynamics.terms import gravity_torques
from ..model.robot import Robot
from .log import TorqueLog
from .velocity_noise import MIN_MOTION, noise_band, velocity_noise_std

__all__ = [
    "CHECKED_SAMPLES",
    "flip_entries",
    "gravity_spread",
    "motion_accelerations",
    "CONFIRMED_CORRELATION",
    "CONFIRMED_SLOPE",
    "MOTION_HALF_SPAN_S",
    "MOTION_MIN_SAMPLES",
    "anticorrelated",
    "GRAVITY_RANGE_SHARE",
    "gravity_loaded",
    "opposite_sign",
    "opposite_sign_among",
    "OPPOSITE_CORRELATION",
    "sign_confirmed",
]

#: Samples the checks of a log use, evenly spaced: they are statistics.
CHECKED_SAMPLES = 4000
#: The sign and scale checks judge a joint only where its gravity torques span at least
#: this share of the log's largest gravity torque (a UR5's shoulder: 0.9 over 20 s of
#: Fourier motion, 0.14 over 0.5 s, 0.008 over 0.05 s, where the correlation was -0.95
#: on a log of the right sign).
GRAVITY_RANGE_SHARE = 0.1
#: A joint whose torques correlate below this with its gravity torques has the opposite
#: sign (gravity explains a quarter or more of their variance, with the other sign).
OPPOSITE_CORRELATION = -0.5
#: Half the span [s] of the central difference of the logged velocities that gives the
#: sign check its accelerations (:func:`opposite_sign`): a 20 Hz smoothing, whose bias
#: is 2 % of a 2 Hz motion's accelerations and which divides velocity noise by 35 at 1 kHz.
MOTION_HALF_SPAN_S = 0.025
#: Fewest samples with known accelerations for the sign check to use the whole torques.
MOTION_MIN_SAMPLES = 20
#: A joint's torque sign is confirmed by the model (:func:`sign_confirmed`) when its
#: torques correlate at least this with the whole rigid-body torques...
CONFIRMED_CORRELATION = 0.8
#: ... and the least-squares factor of those torques on them lies within this range.
CONFIRMED_SLOPE = (0.5, 2.0)


def _correlations(reference: NDArray[np.float64], tau: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per-joint correlation (n,) of ``tau`` with ``reference`` (both centred; 0 where
    either is constant)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = np.sum(reference * tau, axis=0) / np.sqrt(
            np.sum(reference**2, axis=0) * np.sum(tau**2, axis=0)
        )
    return np.where(np.isfinite(corr), corr, 0.0)


def anticorrelated(
    reference: NDArray[np.float64], tau: NDArray[np.float64], loaded: NDArray[np.bool_]
) -> tuple[int, float] | None:
    """The joint and correlation that show ``tau`` (N, n) of the opposite sign to
    ``reference`` (N, n), both with their means removed, or None.

    A sign is called opposite when more of the ``loaded`` joints correlate negatively than
    positively and at least one correlates below -0.5 (that one, the most negative, is
    returned).
    """
    corr = _correlations(reference, tau)
    neg = loaded & (corr < -0.5)
    if not np.any(neg) or np.sum(corr[loaded] < 0) <= np.sum(corr[loaded] > 0):
        return None
    j = int(np.flatnonzero(neg)[np.argmin(corr[neg])])
    return j, float(corr[j])


def _loaded(g: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The joints the gravity torques ``g`` (N, n) load (:func:`gravity_spread`)."""
    spread = np.std(g, axis=0)
    varied = np.ptp(g, axis=0) >= GRAVITY_RANGE_SHARE * float(np.max(np.abs(g)))
    out: NDArray[np.bool_] = (spread > 0.05 * max(float(spread.max()), 1e-300)) & varied
    return out & bool(np.any(spread > 0))


def gravity_spread(
    robot: Robot, q: NDArray[np.float64], tau: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]] | None:
    """The robot's gravity torques and ``tau`` with their means removed, and the joints
    gravity loads over the log (None when it loads none): those whose gravity torques vary
    by at least 5 % of the most varied joint's and span at least
    :data:`GRAVITY_RANGE_SHARE` of the largest gravity torque (on a short stretch gravity
    barely changes, and the torques' variations are the motion's, of either sign)."""
    g = _static_torques(robot, q)
    loaded = _loaded(g)
    if not np.any(loaded):
        return None
    return g - g.mean(axis=0), tau - tau.mean(axis=0), loaded


def gravity_loaded(robot: Robot, q: ArrayLike) -> NDArray[np.bool_]:
    """The joints (n,) whose torque sign the check against gravity judges at the
    configurations ``q`` (N, n) [rad] (:func:`opposite_sign`): those gravity loads enough
    over them; none for a robot without inertial parameters."""
    qq = _checks.as_array("q", q)
    if qq.ndim != 2 or qq.shape[0] < 2 or not np.any(robot.phi):
        return np.zeros(robot.n, dtype=bool)
    return _loaded(_static_torques(robot, qq[:: max(1, qq.shape[0] // CHECKED_SAMPLES)]))


def _static_torques(robot: Robot, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The torques [N m] (N, n) that hold the robot at rest at ``q`` (N, n): gravity's, and
    its joint springs' where it has them (a gravity-compensation spring opposes gravity:
    without it, a shoulder's torques read as of the opposite sign)."""
    g = gravity_torques(robot, q)
    return g if robot.spring is None else g + robot.spring.torques(q)


def flip_entries(joints: Iterable[int], file: str | None = None) -> str:
    """The ``--units`` entries that flip the torques of ``joints`` (from 0): ``tau2=-1``,
    or a file's own, ``rec2.csv:tau2=-1``."""
    at = "" if file is None else f"{file}:"
    return ",".join(f"{at}tau{k + 1}=-1" for k in joints)


def every_joint_entry(file: str | None = None) -> str:
    """The ``--units`` entry that flips the torques of every joint: ``tau=-1``, or a
    file's own, ``rec2.csv:tau=-1``."""
    return "tau=-1" if file is None else f"{file}:tau=-1"


def opposite_sign(robot: Robot, log: TorqueLog, *, file: str | None = None) -> str | None:
    """The finding that a joint-side log's torques have the opposite sign to ``robot``'s
    (anti-correlated with its gravity torques and with its whole rigid-body torques along
    the logged motion, module docstring), or None; None too for a robot without inertial
    parameters to compare with. ``file``: the hint flips that recording's columns alone
    (``rec2.csv:tau2=-1``: one recording among several whose others read right).

    ``identify`` refuses such a log: a fit of the negated torques returns negated
    masses, and friction that pushes the arm."""
    if not np.any(robot.phi):
        return None
    step = max(1, log.n_samples // CHECKED_SAMPLES)
    at = np.arange(0, log.n_samples, step)
    centred = gravity_spread(robot, log.q[at], log.tau[at])
    if centred is None:  # gravity barely varies: its means and the motion's torques tell
        loaded, corr = np.zeros(robot.n, dtype=bool), np.zeros(robot.n)
    else:
        gc, tc, loaded = centred
        corr = _correlations(gc, tc)
    right = flipped = np.zeros(robot.n, dtype=bool)
    every = corr
    off_scale = np.zeros(robot.n, dtype=bool)
    closer: dict[int, tuple[float, float]] = {}
    pushing: dict[int, float] = {}
    if (whole := _motion_torques(robot, log, at)) is not None:  # each can be fooled alone
        model, ok = whole
        every, slope = _explained(model[ok], log.tau[at][ok])
        corr = np.where(loaded, np.maximum(corr, every), every)
        right, flipped = _confirmed(every, slope), _confirmed(-every, -slope) & ~loaded
        lo, hi = CONFIRMED_SLOPE
        off_scale = right.any() & ((-slope < lo) | (-slope > hi))
        closer = _closer_negated(model[ok], log.tau[at][ok])
        pushing = _pushing_as_read(log, at, model, ok, loaded & ~right)
        flipped = flipped | np.isin(np.arange(robot.n), [*closer, *pushing])
    # where the model explains other joints at their scale, a joint whose negated model
    # torques would not explain its own at about theirs holds something the rigid bodies
    # lack (a spring, a counterbalance), not a flipped sign; nor does one whose torques as
    # read are the model's plus a function of its own position and friction
    strong = (loaded & (corr < OPPOSITE_CORRELATION) & ~off_scale) | flipped
    if strong.any() and whole is not None:
        strong &= ~_reads_right(log, at, whole[0], whole[1], strong)
    if not strong.any():
        return None
    if whole is not None:  # refused anyway: the joints gravity does not load, told at once
        pushing |= _pushing_as_read(log, at, whole[0], whole[1], ~(loaded | right | strong))
        strong = strong | np.isin(np.arange(robot.n), list(pushing))
    if right.any() or not loaded.any() or not bool(np.all(every[loaded] < 0)):
        told = whole is not None
        return _opposite(
            corr, strong, loaded | right, robot.joint_names, closer, pushing, file, told
        )
    names = robot.joint_names
    j = int(np.flatnonzero(strong)[np.argmin(corr[strong])])
    said = (
        f"the measured torques are anti-correlated with the model's torques (gravity and "
        f"motion; correlation {corr[j]:+.2f} on {names[j]})"
    )
    unjudged = np.flatnonzero(~(loaded | strong))
    if unjudged.size == 0:
        every_joint = every_joint_entry(file)
        return (
            f"{said}: the torque sign is probably opposite to the model's; hint: --units "
            f"{every_joint} reads them flipped"
        )
    seen = np.flatnonzero(loaded | strong)
    return (
        f"{said} {_judged_joints(seen, corr, names, closer, pushing)}: the torque sign is "
        "probably opposite to the model's there; the sign of "
        f"{', '.join(names[k] for k in unjudged)}, whose torques the model's do not explain "
        "(gravity barely loads them, and friction or a drive's rotor inertia outweighs their "
        "links'), is not told by this check; hint: --units "
        f"{every_joint_entry(file)} if every joint's is "
        f"opposite, --units {flip_entries(seen, file)} if these only"
    )


def opposite_sign_among(
    robot: Robot, log: TorqueLog, name: str, others: Iterable[TorqueLog]
) -> str | None:
    """:func:`opposite_sign` of the recording ``log`` named ``name``, its hint the
    recording's own entries (``rec2.csv:tau2=-1``) when one of the ``others`` (read
    lazily, only when ``log`` is found of the opposite sign) reads right: then ``--units
    tau2=-1`` would flip them too."""
    if (found := opposite_sign(robot, log)) is None:
        return None
    if any(opposite_sign(robot, x) is None for x in others):
        return opposite_sign(robot, log, file=name) or found
    return found


#: Position bins of the function of a joint's own position in :func:`_reads_right`.
SIGN_POSITION_BINS = 12
#: :func:`_reads_right` keeps a joint's sign when the torques as read leave at most this
#: share of the residual sum of squares the negated torques leave.
SIGN_RESIDUAL_SHARE = 0.5


def _sign_fits(
    log: TorqueLog,
    at: NDArray[np.intp],
    model: NDArray[np.float64],
    ok: NDArray[np.bool_],
    asked: NDArray[np.bool_],
) -> dict[int, tuple[float, float, float]]:
    """Per joint among ``asked`` (n,): the least-squares residual sums of squares
    [N^2 m^2] of the torques as read and negated, less the model's rigid-body torques
    ``model`` (at the samples ``at`` where ``ok``), on a function of the joint's own
    position (a spring, a counterbalance: linear in it plus a constant per
    :data:`SIGN_POSITION_BINS` bins of it) and friction (``fc sign(dq) + fv dq``), and the
    Coulomb coefficient ``fc`` [N m] of the torques as read. The samples whose velocity is
    within its noise band are left out: friction there is anywhere between ``-fc`` and
    ``fc``, and a Coulomb friction of 80 N m left its full step at the reversals in the
    residual, which then outweighed the rest (a right-signed UR5 shoulder called flipped).
    A joint with too few samples left is not given."""
    out: dict[int, tuple[float, float, float]] = {}
    dq = log.dq[at][ok]
    q = log.q[at][ok]
    tau = log.tau[at][ok]
    band = noise_band(velocity_noise_std(log.dq, log.t))
    for j in np.flatnonzero(asked):
        moving = np.abs(dq[:, j]) > max(band[j], MIN_MOTION)
        qj = q[moving, j]
        edges = np.quantile(qj, np.linspace(0.0, 1.0, SIGN_POSITION_BINS + 1)) if qj.size else ()
        which = np.clip(np.searchsorted(edges, qj, side="right") - 1, 0, None)
        which = np.minimum(which, SIGN_POSITION_BINS - 1)
        X = np.column_stack(
            [
                which[:, None] == np.arange(SIGN_POSITION_BINS),
                qj,
                np.sign(dq[moving, j]),
                dq[moving, j],
            ]
        ).astype(np.float64)
        if X.shape[0] <= 2 * X.shape[1]:
            continue
        left, fc = [], 0.0
        for k, y in enumerate((tau[moving, j], -tau[moving, j])):
            y = y - model[ok][moving, j]
            coef = np.linalg.lstsq(X, y, rcond=None)[0]
            left.append(float(np.sum((y - X @ coef) ** 2)))
            fc = float(coef[-2]) if k == 0 else fc
        out[int(j)] = (left[0], left[1], fc)
    return out


def _reads_right(
    log: TorqueLog,
    at: NDArray[np.intp],
    model: NDArray[np.float64],
    ok: NDArray[np.bool_],
    asked: NDArray[np.bool_],
) -> NDArray[np.bool_]:
    """The joints among ``asked`` (n,) whose torques as read, not negated, are the model's
    rigid-body torques ``model`` (at the samples ``at`` where ``ok``) plus a function of
    the joint's own position and friction (:func:`_sign_fits`): the least-squares
    residual of ``tau - model`` on those columns is at most :data:`SIGN_RESIDUAL_SHARE`
    of that of ``-tau - model``. Under a flipped sign the negated torques are the ones so
    explained, and the torques as read leave twice the rigid-body torques of every
    joint's motion. A 60 N m/rad spring on a Panda shoulder made its torques correlate
    -0.96 with gravity's at a factor of -1.17, as a flipped sign would; read as they are,
    they were its model's torques plus such a function."""
    out = np.zeros(log.n, dtype=bool)
    for j, (read, negated, _) in _sign_fits(log, at, model, ok, asked).items():
        out[j] = read <= SIGN_RESIDUAL_SHARE * negated
    return out


def _pushing_as_read(
    log: TorqueLog,
    at: NDArray[np.intp],
    model: NDArray[np.float64],
    ok: NDArray[np.bool_],
    asked: NDArray[np.bool_],
) -> dict[int, float]:
    """The joints among ``asked`` whose negated torques, not those as read, are the
    model's plus a function of their own position and friction (:func:`_sign_fits`, the
    reverse of :func:`_reads_right`) while the friction as read pushes (a negative Coulomb
    coefficient), with that coefficient [N m]: a flipped sign where friction outweighs
    the rigid bodies, which the correlations cannot see (a UR5 shoulder with 80 N m of
    Coulomb friction, flipped, correlated +0.52 with its model's torques). Asked of the
    joints gravity loads, and of the others once a joint is found opposite (the log is
    refused anyway, so every flipped joint is named at once: a simulated xArm7 logged with
    joints 2 and 5 flipped was refused naming joint 2 alone, and joint 5 only on the next
    run, by the fit's friction); alone, the sign of a joint gravity does not load is judged
    by the identification's dissipation check, which offers the structure without its
    friction as the way on (a controller's compensation)."""
    fits = _sign_fits(log, at, model, ok, asked)
    return {
        j: fc
        for j, (read, negated, fc) in fits.items()
        if negated <= SIGN_RESIDUAL_SHARE * read and fc < 0.0
    }


#: A joint's measured torques are the negated model's (:func:`_closer_negated`) when
#: their RMS distance from those is below this share of that from the model's own...
NEGATED_DISTANCE_SHARE = 0.5
#: ... and the model's torques there have at least this share of the measured torques'
#: RMS (a joint the model barely loads tells nothing).
NEGATED_MODEL_SHARE = 0.3


def _closer_negated(
    model: NDArray[np.float64], tau: NDArray[np.float64]
) -> dict[int, tuple[float, float]]:
    """The joints whose measured torques ``tau`` (N, n) [N m] lie far closer to the negated
    model's torques ``model`` (N, n) than to the model's own, means included
    (:data:`NEGATED_DISTANCE_SHARE`, :data:`NEGATED_MODEL_SHARE`), with the RMS distances
    [N m] from the negated and from the model's torques. The correlations look at the
    variations alone: a UR5 elbow logged with the opposite sign held +15 N m where the
    model's gravity held -15 N m, while its variations correlated -0.01 to -0.43 with
    the model's, and the log was fitted without a word."""
    rms = lambda x: np.sqrt(np.mean(x**2, axis=0))  # noqa: E731
    near, far, size = rms(tau + model), rms(tau - model), rms(tau)
    hit = (near < NEGATED_DISTANCE_SHARE * far) & (rms(model) >= NEGATED_MODEL_SHARE * size)
    return {int(j): (float(near[j]), float(far[j])) for j in np.flatnonzero(hit)}


def _explained(
    model: NDArray[np.float64], tau: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The correlation (n,) of the measured torques ``tau`` (N, n) with the model's
    ``model`` (N, n), both centred, and the least-squares factor of ``tau`` on ``model``."""
    m, y = _centred(model), _centred(tau)
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = np.sum(m * y, axis=0) / np.sum(m**2, axis=0)
    return _correlations(m, y), np.where(np.isfinite(slope), slope, 0.0)


def _confirmed(corr: NDArray[np.float64], slope: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The joints whose measured torques the model's explain at about their own scale
    (:data:`CONFIRMED_CORRELATION`, :data:`CONFIRMED_SLOPE`)."""
    lo, hi = CONFIRMED_SLOPE
    out: NDArray[np.bool_] = (corr >= CONFIRMED_CORRELATION) & (slope >= lo) & (slope <= hi)
    return out


def _centred(x: NDArray[np.float64]) -> NDArray[np.float64]:
    out: NDArray[np.float64] = x - x.mean(axis=0)
    return out


def motion_accelerations(
    log: TorqueLog, at: NDArray[np.intp]
) -> tuple[NDArray[np.float64], NDArray[np.bool_]] | None:
    """The accelerations (at.size, n) at the samples ``at`` of ``log`` that the checks
    against the whole rigid-body torques use, and where they are known: its logged
    accelerations, else the central difference of its velocities over
    +-:data:`MOTION_HALF_SPAN_S` (at least one and a half sample steps), known where that
    span stays inside the log and crosses no gap (a step over three median steps) and the
    states are finite. Linear in the velocities: of a log read through a drive, the
    drive's map of the recorded ones. None when fewer than :data:`MOTION_MIN_SAMPLES`
    samples are known."""
    t, dq = log.t, log.dq
    ts = t[at]
    if log.ddq is not None:
        ddq, ok = log.ddq[at], np.ones(at.size, dtype=bool)
    else:
        dt = np.diff(t)
        h = max(MOTION_HALF_SPAN_S, 1.5 * float(np.median(dt)))
        gaps = np.concatenate([[0], np.cumsum(dt > 3.0 * float(np.median(dt)))])
        lo, hi = np.searchsorted(t, ts - h), np.searchsorted(t, ts + h)
        ok = (ts - h >= t[0]) & (ts + h <= t[-1])
        ok &= gaps[np.minimum(hi, t.size - 1)] == gaps[np.maximum(lo - 1, 0)]
        ddq = np.column_stack(
            [
                (np.interp(ts + h, t, dq[:, j]) - np.interp(ts - h, t, dq[:, j])) / (2 * h)
                for j in range(log.n)
            ]
        )
    ok &= np.all(np.isfinite(ddq) & np.isfinite(log.q[at]) & np.isfinite(dq[at]), axis=1)
    if np.count_nonzero(ok) < MOTION_MIN_SAMPLES:
        return None
    return ddq, ok


def _motion_torques(
    robot: Robot, log: TorqueLog, at: NDArray[np.intp]
) -> tuple[NDArray[np.float64], NDArray[np.bool_]] | None:
    """The robot's rigid-body torques ``M ddq + c + g`` (no friction, its spring
    included) at the samples ``at`` of ``log``, at the accelerations
    :func:`motion_accelerations` gives, and where they are known (None: too few)."""
    found = motion_accelerations(log, at)
    if found is None:
        return None
    ddq, ok = found
    dq = log.dq
    model = np.zeros_like(ddq)
    model[ok] = rnea(robot, log.q[at][ok], dq[at][ok], ddq[ok])
    if robot.spring is not None:
        model[ok] += robot.spring.torques(log.q[at][ok])
    return model, ok


def sign_confirmed(robot: Robot, logs: Sequence[TorqueLog]) -> NDArray[np.bool_]:
    """The joints (n,) whose torque sign the robot's whole rigid-body torques confirm over
    the joint-side ``logs`` pooled: they explain the measured torques at about their own
    scale (correlation at least :data:`CONFIRMED_CORRELATION`, least-squares slope within
    :data:`CONFIRMED_SLOPE`). A joint gravity does not load is judged so too: friction
    that a short log's fit leaves pushing there (``fv5 = -0.09`` on 2 s of a Panda's
    motion, whose wrist torques correlate +0.99 with the model's) is no flipped sign.
    Correlation alone can be fooled where friction outweighs the rigid body (the Panda's
    last joint: -0.92 on a log of the right sign), the slope then far from 1."""
    if not np.any(robot.phi) or not logs:
        return np.zeros(robot.n, dtype=bool)
    step = max(1, sum(g.n_samples for g in logs) // CHECKED_SAMPLES)
    model, tau = [], []
    for g in logs:
        at = np.arange(0, g.n_samples, step)
        if at.size and (whole := _motion_torques(robot, g, at)) is not None:
            model.append(whole[0][whole[1]])
            tau.append(g.tau[at][whole[1]])
    if not model:
        return np.zeros(robot.n, dtype=bool)
    return _confirmed(*_explained(np.concatenate(model), np.concatenate(tau)))


def _judged_joints(
    seen: NDArray[np.intp],
    corr: NDArray[np.float64],
    names: tuple[str, ...],
    closer: dict[int, tuple[float, float]],
    pushing: dict[int, float],
) -> str:
    """Where the torques are anti-correlated with the model's: ``"on every joint judged
    (2 -0.80, 3 -0.52)"``, or, where a joint of ``seen`` (all called opposite) is not
    (correlation ``corr`` of 0 or more: told by its friction, ``closer`` or
    ``pushing``), ``"on every joint judged but 4 (...); 4: correlation +0.18, but ..."``:
    a joint of positive correlation is never listed as anti-correlated (a UR5's wrist at
    +0.18 was, under "every joint judged")."""
    agree = [int(k) for k in seen if corr[k] < 0]
    but = [int(k) for k in seen if corr[k] >= 0]
    listed = ", ".join(f"{names[k]} {corr[k]:+.2f}" for k in agree)
    if not but:
        return f"on every joint judged ({listed})"
    told = []
    for k in but:
        if k in closer:
            why = (
                f"{closer[k][0]:.3g} N m RMS from the negated model's torques against "
                f"{closer[k][1]:.3g} from the model's (means included)"
            )
        elif k in pushing:
            why = (
                f"as read its friction would push the arm (Coulomb {pushing[k]:.3g} N m), "
                "while negated its torques are the model's plus friction"
            )
        else:
            why = "its torques are told opposite with the others'"
        told.append(f"{names[k]}: correlation {corr[k]:+.2f}, but {why}")
    return (
        f"on every joint judged but {', '.join(names[k] for k in but)}"
        + (f" ({listed})" if listed else "")
        + f"; {'; '.join(told)}"
    )


def _opposite(
    corr: NDArray[np.float64],
    strong: NDArray[np.bool_],
    judged: NDArray[np.bool_],
    names: tuple[str, ...],
    closer: dict[int, tuple[float, float]] | None = None,
    pushing: dict[int, float] | None = None,
    file: str | None = None,
    dissipating: bool = False,
) -> str | None:
    """The finding of the joints ``strong`` (n,) anti-correlated with the model's torques
    (``corr``, n), or closer to its negated torques (``closer``: the RMS distances from
    the negated and from the model's, :func:`_closer_negated`; ``pushing``: the Coulomb
    coefficient [N m] of friction that pushes as read, :func:`_pushing_as_read`), while
    others the checks judge (``judged``) are not: named, with the ``--units`` entries
    that flip their columns alone (``tau2=-1``; of ``file`` alone: ``rec2.csv:tau2=-1``),
    and the joints neither check judges (``dissipating``: whose friction as read was
    asked and does not push)."""
    rest = np.flatnonzero(judged & ~strong)
    free = np.flatnonzero(~judged & ~strong)
    bad = np.flatnonzero(strong)
    which = ", ".join(names[k] for k in bad)
    near = {k: v for k, v in (closer or {}).items() if strong[k]}
    push = {k: v for k, v in (pushing or {}).items() if strong[k]}
    anti = bool(np.all(corr[bad] < OPPOSITE_CORRELATION))
    evidence = (
        f"correlation {', '.join(f'{corr[k]:+.2f}' for k in bad)}"
        if not near and not push
        else "; ".join(
            f"{names[k]}: correlation {corr[k]:+.2f}"
            + (
                f", {near[int(k)][0]:.3g} N m RMS from the negated model's torques against "
                f"{near[int(k)][1]:.3g} from the model's (means included)"
                if k in near
                else ""
            )
            + (
                f", as read its friction would push the arm (Coulomb {push[int(k)]:.3g} N m), "
                "while negated its torques are the model's plus friction"
                if k in push and k not in near
                else ""
            )
            for k in map(int, bad)
        )
    )
    return (
        f"the measured torques of {which} are "
        + ("anti-correlated with" if anti else "of the opposite sign to")
        + f" the model's torques (gravity and motion; {evidence})"
        + (
            f" while those of {', '.join(f'{names[k]} ({corr[k]:+.2f})' for k in rest)} are "
            "not (the sign differs on some joints only)"
            if rest.size
            else ""
        )
        + f": the torque sign of {which} is probably opposite to the model's"
        + (
            f" (the sign of {', '.join(names[k] for k in free)}, whose torques the model's "
            "do not explain, is not told by this check"
            + (", though their friction as read does not push the arm)" if dissipating else ")")
            if free.size
            else ""
        )
        + (
            f"; hint: --units "
            f"{every_joint_entry(file)} if every "
            f"joint's is opposite, --units {flip_entries(bad, file)} if these only"
            if rest.size == 0 and bad.size > 1
            else f"; hint: --units {flip_entries(bad, file)} reads "
            + ("it" if bad.size == 1 else "them")
            + " flipped (beside the torques' unit, if one is given)"
        )
    )
