"""A load carried at the flange over a long event: picked, held, released.

An object picked at the flange that the model lacks raises the residual by its weight's
torque ``Y(q) theta`` (:func:`~dynid.observer.unmodelled_load.load_regressor`,
``theta = (m, m c)``) from the pick to the release: over the contact threshold
throughout when it is heavy enough, one long "collision" that hides the contacts on top
of it. :func:`fit_carried_load` fits ``theta`` on the samples of such an event robustly
(weighted least squares, each joint's residual and regressor divided by its contact
threshold at the sample, then :data:`FIT_ROUNDS` rounds that leave out the samples the
fit leaves over the threshold at some joint, or over :data:`SPREAD` times the kept
samples' median misfit where that is larger: contacts on top of the load) and calls it a
load only where

* the event lasts :data:`MIN_LOAD_S` or more;
* the fit keeps :data:`MIN_INLIERS` of the event's samples and explains
  :data:`MIN_EXPLAINED` of their residual's sum of squares (a weight is a force along
  gravity in the base axes whose torque follows the configuration; a push at a fixed
  point of the arm, its force anywhere else, is not explained so);
* the arm moves over it: some joint spans :data:`MIN_MOTION_RAD` (a push held on a still
  arm reads as any weight would);
* ``m > 0`` (an arm lighter than its model is the model's error).

A load is a rigid body: on a fast motion its inertia adds to its weight's torque. Given
the log's accelerations, the fit takes the load's full dynamics at the flange, ``theta =
(m, m c, J)`` (:func:`rigid_load_regressor`, the payload's regressor of ``dynid
payload``), passed through the observer's lag (:func:`lagged_rigid_regressor`), where
the event's motion determines the inertia (:func:`inertia_determined`) and the ten
parameters leave less misfit than the weight alone; else the weight alone. On the trial
below the weight alone left 4 short events inside the window (its inertia) and read
0.81 kg, CoM z 0.046 m; the rigid load none, 0.80 kg and 0.050 m (0.05 m true).

The load is then taken out: :class:`LoadTorque` gives, block by block, its torque as the
observer sees it, ``Y theta`` switched on at the pick and off at the release and
passed through the observer's ``K/(s + K)`` (the residual's own lag), and the detection
runs again on the residual minus it (the wrench estimate loses the load's wrench with
it). The pick and the release are read off the residual at the event's edges (the first
order lag crossed back to the step's time). Events of the second run that lie within
:data:`EDGE_S` of the pick or the release are the step's own rest, not contacts.

The load's own event stays (:func:`load_events`, level ``load``): to the joint torques a
weight picked at the flange and a steady push along gravity are the same force, so it is
reported as an external force and scored as any event, never dropped (a Talos arm pushed
12 N down for 1.5 s: before, read as 1.22 kg and the push missed).

A load the model lacks held through the whole log whose torque dips under the threshold
at some poses makes several events, none spanning the log. A load is read as held
throughout (:func:`held_throughout`) where its weight also explains :data:`HELD_EXPLAINED`
of the residual under the threshold outside its event (:meth:`LoadSamples.quiet`, a
picked load none of it: its torque there only adds to the residual); it is then fitted
again over every sample of the log over the threshold and taken out from the first
sample, the log's other loads the same load at other poses (a simulated Panda whose
model lacks 0.1 kg: before, two picks over 1.44 s to 2.49 s and 2.74 s to 10.0 s, two
false alarms, 89.8 % of the log flagged).

On the trial's 80 s Panda log with a 0.8 kg object held from 30.0 s to 50.24 s and 5
labelled contacts on top: 0.80 kg named, and the contacts on top detected (before: one
20 s collision, a false alarm hiding them; its event is now of level ``load``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..feasibility.payload import link_params_from_frame
from ..model.robot import Robot
from ..regressors.torque import torque_regressor
from .events import ContactEvent
from .residual import first_order_filtered
from .unmodelled_load import LOAD_FRAME, load_regressor

__all__ = [
    "EDGE_S",
    "MIN_EXPLAINED",
    "MIN_INLIERS",
    "MIN_LOAD_S",
    "MIN_MOTION_RAD",
    "INERTIA_COND_MAX",
    "CarriedLoad",
    "LoadSamples",
    "LoadTorque",
    "at_load_edge",
    "carried_loads",
    "fit_carried_load",
    "HELD_EXPLAINED",
    "held_throughout",
    "lagged_rigid_regressor",
    "load_events",
    "NO_LOADS",
    "rigid_load_regressor",
    "samples_within",
    "load_words",
    "unread_load_words",
]

#: Shortest event read as a load [s].
MIN_LOAD_S = 1.0
#: Share of the event's samples the fit must leave under the threshold at every joint.
MIN_INLIERS = 0.5
#: Share of those samples' residual sum of squares (each joint over its threshold) the
#: fit must explain.
MIN_EXPLAINED = 0.9
#: Range of some joint over the event [rad]: configurations varied enough to tell a weight.
MIN_MOTION_RAD = 0.2
#: The misfit left out, in medians of the kept samples' misfit, where it exceeds the
#: threshold (the load's inertia on a fast motion: the fit models its weight alone).
SPREAD = 3.0
#: Rounds of the robust fit.
FIT_ROUNDS = 6
#: Time after the pick and after the release [s] whose events are the step's rest.
EDGE_S = 0.15
#: Largest condition number of the rigid-body regressor (its 10 columns each scaled to
#: unit norm, on the fit's samples) for the load's inertia to be fitted: beyond it the
#: event's motion does not determine it and the weight alone is fitted.
INERTIA_COND_MAX = 100.0
#: Samples kept per second of residual over the threshold for the fit (memory bound).
KEPT_RATE_HZ = 200.0
#: Samples kept per second of residual under the threshold, for :func:`held_throughout`.
QUIET_RATE_HZ = 20.0
#: Share of the residual under the threshold outside a load's event (each joint over its
#: threshold, sum of squares) its weight must explain for the load to be held throughout.
HELD_EXPLAINED = 0.5
#: Fewest samples under the threshold outside a load's event to judge it held throughout.
HELD_SAMPLES = 20


@dataclass(frozen=True, slots=True, eq=False)
class CarriedLoad:
    """A load at the flange over one event (module docstring).

    Attributes
    ----------
    start, end : float
        The event's first and last sample [s] (the log's clock).
    picked, released : float
        The pick and the release read off the residual's lag [s].
    mass : float
        [kg].
    com : ndarray, shape (3,)
        Centre of mass in the flange's axes [m].
    theta : ndarray, shape (4,) or (10,)
        ``(m, m c)`` [kg, kg m], the weight alone; or ``(m, m c, J)`` with the inertia
        ``Jxx, Jxy, Jxz, Jyy, Jyz, Jzz`` about the flange's origin [kg m^2], the rigid
        load (its inertia determined by the event's motion).
    explained : float
        Share (0 to 1) of the kept samples' residual the fit explains.
    kept : float
        Share (0 to 1) of the event's samples it leaves under the threshold.
    whole : bool
        The event spans the log: the load was held throughout.
    """

    start: float
    end: float
    picked: float
    released: float
    mass: float
    com: NDArray[np.float64]
    theta: NDArray[np.float64]
    explained: float
    kept: float
    whole: bool = False

    def as_dict(self) -> dict[str, object]:
        """The keys of events.json's ``loads`` (docs/file-formats.md)."""
        return {
            "start": self.start,
            "end": self.end,
            "picked": float(self.picked),
            "released": float(self.released),
            "mass": self.mass,
            "com": [float(x) for x in self.com],
            "frame": LOAD_FRAME,
            "explained": self.explained,
            "kept": self.kept,
            "whole_log": self.whole,
        }


class _Kept:
    """Every few samples of those a block marks (at most ``rate_hz`` a second)."""

    def __init__(self, period_s: float | None, rate_hz: float) -> None:
        self._every = max(1, round(1.0 / (rate_hz * period_s))) if period_s else 1
        self._parts: list[tuple[NDArray, ...]] = []
        self._seen = 0

    def add(self, mark: NDArray[np.bool_], arrays: tuple[NDArray, ...]) -> None:
        idx = np.flatnonzero(mark)
        take = idx[(self._seen + np.arange(idx.size)) % self._every == 0]
        self._seen += idx.size
        if take.size:
            self._parts.append(tuple(x[take] for x in arrays))

    def joined(self) -> tuple[NDArray, ...] | None:
        if not self._parts:
            return None
        return tuple(np.concatenate([p[i] for p in self._parts]) for i in range(4))


class LoadSamples:
    """The samples over the contact threshold of one log, every few (at most
    :data:`KEPT_RATE_HZ` a second), for :func:`fit_carried_load`, and those under it at
    every joint (at most :data:`QUIET_RATE_HZ` a second), for :func:`held_throughout`:
    times [s], positions [rad], residual [N m] and contact threshold [N m]."""

    def __init__(self, period_s: float | None) -> None:
        self._over = _Kept(period_s, KEPT_RATE_HZ)
        self._under = _Kept(period_s, QUIET_RATE_HZ)

    def add(self, t: NDArray, q: NDArray, r: NDArray, contact: NDArray) -> None:
        """One block, each (m, ...) of the same rows."""
        with np.errstate(invalid="ignore"):
            over = np.any(np.abs(r) > contact, axis=1)
            under = np.all(np.abs(r) <= contact, axis=1)
        self._over.add(over, (t, q, r, contact))
        self._under.add(under, (t, q, r, contact))

    def joined(self) -> tuple[NDArray, ...] | None:
        """The kept samples over the threshold of every block, each array joined once:
        times (K,) [s], positions (K, n) [rad], residual (K, n) [N m] and contact
        threshold (K, n) [N m] in time order; None: none kept."""
        return self._over.joined()

    def quiet(self) -> tuple[NDArray, ...] | None:
        """The kept samples under the threshold at every joint, as :meth:`joined`."""
        return self._under.joined()


def samples_within(
    kept: tuple[NDArray, ...], start: float, end: float
) -> tuple[NDArray, ...] | None:
    """The samples of ``kept`` (:meth:`LoadSamples.joined`, times in order) from
    ``start`` to ``end`` [s], both included; None: none."""
    t = kept[0]
    a, b = int(np.searchsorted(t, start, "left")), int(np.searchsorted(t, end, "right"))
    return tuple(x[a:b] for x in kept) if b > a else None


def rigid_load_regressor(
    robot: Robot, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike
) -> NDArray[np.float64]:
    """``Y(q, dq, ddq)`` (N, n, 10) [N m per parameter]: the external joint torques of a
    rigid load at the flange, ``-J^T`` (its spatial momentum rate minus its weight),
    linear in its 10 inertial parameters ``(m, m c, J)`` in the flange's axes (``c`` [m],
    ``J`` [kg m^2] about the flange's origin, the order of :func:`dynid.param_labels`).

    The torque regressor's columns of the flange's link mapped to the flange's
    parameters (:func:`~dynid.feasibility.payload.link_params_from_frame`, as ``dynid
    payload`` fits a load), negated: the joints' torque a load adds is what the residual
    reads with the opposite sign. At rest its first four columns are
    :func:`~dynid.observer.unmodelled_load.load_regressor`'s."""
    f = robot.frame(LOAD_FRAME)
    k = f.link
    qa = np.asarray(q, dtype=np.float64).reshape(-1, robot.n)
    Y = torque_regressor(
        robot,
        qa,
        np.asarray(dq, dtype=np.float64).reshape(qa.shape),
        np.asarray(ddq, dtype=np.float64).reshape(qa.shape),
    )[..., 10 * (k - 1) : 10 * k]
    return np.asarray(-(Y @ link_params_from_frame(f.T_link_frame)), dtype=np.float64)


def _lag(
    u: NDArray[np.float64], K: NDArray[np.float64], dt: float, state: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``u`` (N, n, ...) through each joint's ``K/(s + K)`` (exact for a step held over
    a sample, ``dt`` [s]) from the output ``state`` (n, ...) before the first sample."""
    a = -np.expm1(-np.asarray(K, dtype=np.float64) * dt)
    x = np.ascontiguousarray(u, dtype=np.float64).reshape(u.shape[0], u.shape[1], -1)
    zi = (1.0 - a)[:, None] * np.asarray(state, dtype=np.float64).reshape(u.shape[1], -1)
    out = np.empty_like(x)
    first_order_filtered(a, x, zi, out)
    return out.reshape(u.shape)


#: Samples of the rigid load's regressor computed at a time (the torque regressor of a
#: block held: 7 joints, 70 columns, 32 MB).
RIGID_BLOCK = 8192


def lagged_rigid_regressor(
    robot: Robot,
    motion: tuple[NDArray, NDArray, NDArray, NDArray],
    span: tuple[float, float],
    gain: ArrayLike,
    at: NDArray[np.float64],
) -> NDArray[np.float64]:
    """:func:`rigid_load_regressor` over the samples of ``motion`` (times [s], positions
    [rad], velocities [rad/s], accelerations [rad/s^2], each (N, ...)) from ``span[0]``
    to ``span[1]`` [s], passed through the observer's lag ``K/(s + K)`` (``gain`` (n,)
    [1/s]; started on the first sample's value) as the residual is, read at the times
    ``at`` (M,) [s] (the nearest sample at or after): (M, n, 10). Computed
    :data:`RIGID_BLOCK` samples at a time, the lag's state carried.

    The accelerations are a low-passed derivative of the log's velocities (the
    observer's preparation): the observer avoids them, its residual the momentum's
    difference, because their noise grows with the sampling rate and would pass straight
    into the detection at every sample; here they enter a least-squares fit of 10
    numbers over thousands of samples, then the lag ``K/(s + K)``, which averages the
    noise away (what is left is far below the contact threshold), while the inertial
    torque they carry (slow, at the motion's rate) is what the weight alone misses."""
    t, q, dq, ddq = motion
    a, b = int(np.searchsorted(t, span[0])), int(np.searchsorted(t, span[1], side="right"))
    K = np.asarray(gain, dtype=np.float64)
    steps = np.diff(t[a:b])
    dt = float(np.median(steps)) if steps.size else 0.0
    idx = a + np.clip(np.searchsorted(t[a:b], at), 0, max(b - a - 1, 0))
    out = np.zeros((idx.shape[0], robot.n, 10))
    state: NDArray[np.float64] | None = None
    for k in range(a, b, RIGID_BLOCK):
        e = min(k + RIGID_BLOCK, b)
        Y = rigid_load_regressor(robot, q[k:e], dq[k:e], ddq[k:e])
        Y = _lag(Y, K, dt, Y[0] if state is None else state)
        state = Y[-1]
        here = (idx >= k) & (idx < e)
        out[here] = Y[idx[here] - k]
    return out


def _weighted_fit(
    A: NDArray, b: NDArray, keep: NDArray[np.bool_]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``theta`` (p,) of the rows ``keep`` of ``A`` (N, n, p), ``b`` (N, n) and every
    sample's ``b - A theta`` (N, n)."""
    Ak, bk = A[keep].reshape(-1, A.shape[-1]), b[keep].reshape(-1)
    theta = np.linalg.lstsq(Ak, bk, rcond=None)[0]
    return theta, b - A @ theta


def _robust_fit(
    A: NDArray, b: NDArray
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """The robust fit of the module docstring: ``theta``, the misfit (N, n) and the
    samples kept (N,)."""
    keep = np.ones(b.shape[0], dtype=bool)
    theta, left = _weighted_fit(A, b, keep)
    for _ in range(FIT_ROUNDS):
        worst = np.max(np.abs(left), axis=1)  # each sample's largest, over its threshold
        cut = max(1.0, SPREAD * float(np.median(worst[keep])))  # the load's own misfit
        inside = worst <= cut
        if inside.sum() < 20 or np.array_equal(inside, keep):
            break
        keep = inside
        theta, left = _weighted_fit(A, b, keep)
    return theta, left, keep


def inertia_determined(A: NDArray) -> bool:
    """The rigid-body regressor ``A`` (N, n, 10), each joint over its threshold,
    determines the load's inertia: its columns scaled to unit norm have a condition
    number of :data:`INERTIA_COND_MAX` or less (the motion excites each inertial
    parameter apart from the others; beyond it their estimates' noise, not the load's
    torque, would be taken from the residual)."""
    Ak = A.reshape(-1, A.shape[-1])
    norms = np.linalg.norm(Ak, axis=0)
    if not np.all(norms > 0):
        return False
    s = np.linalg.svd(Ak / norms, compute_uv=False)
    return bool(s[-1] > 0 and s[0] / s[-1] <= INERTIA_COND_MAX)


def fit_carried_load(
    robot: Robot,
    t: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    contact: ArrayLike,
    gain: ArrayLike,
    span: tuple[float, float],
    log_span: tuple[float, float],
    rigid: ArrayLike | None = None,
) -> CarriedLoad | None:
    """The load of an event ``span`` [s] fitted on its samples at times ``t`` (N,) [s],
    positions ``q`` (N, n) [rad], residual ``r`` (N, n) [N m] and contact threshold
    ``contact`` (N, n) [N m] (module docstring); ``gain`` the observer's K (n,) [1/s],
    ``log_span`` the log's first and last time [s]; ``rigid`` (N, n, 10): the lagged
    rigid-body regressor at the samples (:func:`lagged_rigid_regressor`), fitted where
    it determines the inertia (:func:`inertia_determined`) and leaves less misfit than the
    weight alone on the samples both fits keep (a force that follows gravity without the
    inertia a mass carries, a weight hung by a spring, stays the weight's), else (or
    None) the weight alone. None: no load explains it."""
    ta = np.asarray(t, dtype=np.float64)
    R, C = np.asarray(r, dtype=np.float64), np.asarray(contact, dtype=np.float64)
    qa = np.asarray(q, dtype=np.float64)
    good = np.all(np.isfinite(R), axis=1) & np.all(C > 0, axis=1)
    if span[1] - span[0] < MIN_LOAD_S or np.count_nonzero(good) < 20:
        return None
    ta, qa, R, C = ta[good], qa[good], R[good], C[good]
    b = R / C
    A = load_regressor(robot, qa) / C[:, :, None]
    theta, left, keep = _robust_fit(A, b)
    if rigid is not None:
        A10 = np.asarray(rigid, dtype=np.float64)[good] / C[:, :, None]
        if inertia_determined(A10[keep]):
            rigid_fit = _robust_fit(A10, b)
            both = keep & rigid_fit[2]
            if np.sum(rigid_fit[1][both] ** 2) < np.sum(left[both] ** 2):
                A, (theta, left, keep) = A10, rigid_fit
    kept = float(np.mean(keep))
    total = float(np.sum(b[keep] ** 2))
    explained = 1.0 - float(np.sum(left[keep] ** 2)) / total if total > 0 else 0.0
    moved = float(np.max(np.ptp(qa[keep], axis=0))) if keep.any() else 0.0
    mass = float(theta[0])
    if kept < MIN_INLIERS or explained < MIN_EXPLAINED or moved < MIN_MOTION_RAD or mass <= 0:
        return None
    edges = (A[[0, -1]] * C[[0, -1]][:, :, None]) @ theta  # (2, n) the load's torque there
    K = np.asarray(gain, dtype=np.float64)
    picked = _step_time(ta[0], R[0], edges[0], K, rising=True)
    released = _step_time(ta[-1], R[-1], edges[1], K, rising=False)
    whole = span[0] - log_span[0] < MIN_LOAD_S / 2 and log_span[1] - span[1] < MIN_LOAD_S / 2
    return CarriedLoad(
        span[0], span[1], picked, released, mass, theta[1:4] / mass, theta, explained, kept, whole
    )


def held_throughout(
    robot: Robot,
    load: CarriedLoad,
    quiet: tuple[NDArray, ...] | None,
    over: tuple[NDArray, ...] | None = None,
) -> bool:
    """The ``load`` fitted on one event is held through the whole log (module
    docstring): its weight ``Y(q) theta[:4]`` explains :data:`HELD_EXPLAINED` or more of
    the residual outside the event widened by :data:`EDGE_S` (each joint over its
    threshold, sum of squares), on :data:`HELD_SAMPLES` samples or more: those under the
    threshold (``quiet``, :meth:`LoadSamples.quiet`) and those over it (``over``,
    :meth:`LoadSamples.joined`) that it brings under it (the others: contacts). A load
    picked and released leaves none of that residual: its torque there only adds to it.
    A load whose event spans the log is held throughout."""
    if load.whole:
        return True
    b_all, left_all = [], []
    for part, contacts_out in ((quiet, False), (over, True)):
        if part is None:
            continue
        t, q, r, c = part
        out = (t < load.start - EDGE_S) | (t > load.end + EDGE_S)
        b = r[out] / c[out]
        left = b - (load_regressor(robot, q[out]) @ load.theta[:4]) / c[out]
        if contacts_out:  # over the threshold still with the load out: a contact
            inside = np.max(np.abs(left), axis=1) <= 1.0
            b, left = b[inside], left[inside]
        b_all.append(b)
        left_all.append(left)
    if not b_all or sum(x.shape[0] for x in b_all) < HELD_SAMPLES:
        return False
    total = float(sum(np.sum(x**2) for x in b_all))
    misfit = float(sum(np.sum(x**2) for x in left_all))
    return total > 0 and 1.0 - misfit / total >= HELD_EXPLAINED


def _step_time(t: float, r: NDArray, y: NDArray, K: NDArray, *, rising: bool) -> float:
    """The time [s] of the step of torque ``y`` (n,) whose first-order lag (gains ``K``
    (n,) [1/s]) reads ``r`` (n,) at ``t``: ``r = y (1 - e^{-K (t - t0)})`` rising, ``r = y
    e^{-K (t - t0)}`` falling; the share read along ``y`` (0.02 to 0.98)."""
    yy = float(y @ y)
    if not yy > 0:
        return t
    s = float(np.clip((r @ y) / yy, 0.02, 0.98))
    k = float(np.sum(K * y * y) / yy)  # the gains weighed by the load's torque
    return t + (np.log(1.0 - s) if rising else np.log(s)) / k


def carried_loads(
    robot: Robot,
    samples: LoadSamples,
    spans: Sequence[tuple[float, float]],
    gain: ArrayLike,
    log_span: tuple[float, float],
    motion: tuple[NDArray, NDArray, NDArray, NDArray] | None = None,
) -> list[CarriedLoad]:
    """The loads of the events ``spans`` [s] of :data:`MIN_LOAD_S` or more, fitted on the
    ``samples`` kept over the threshold (:func:`fit_carried_load`); ``motion``: the log's
    times [s], positions [rad], velocities [rad/s] and accelerations [rad/s^2], each
    (N, ...), for the rigid load's inertia (:func:`lagged_rigid_regressor`); None: the
    weight alone. Where one is held throughout (:func:`held_throughout`), that load
    alone, fitted again over the whole log (``whole``)."""
    out: list[CarriedLoad] = []
    joined = samples.joined()
    if joined is None:
        return out
    for a, b in spans:
        if b - a >= MIN_LOAD_S and (ld := _fitted(robot, joined, (a, b), gain, log_span, motion)):
            out.append(ld)
    held = [ld for ld in out if held_throughout(robot, ld, samples.quiet(), joined)]
    if not held or any(ld.whole for ld in out):
        return out
    longest = max(held, key=lambda ld: ld.end - ld.start)
    every = _in_time_order(joined, samples.quiet())  # no selection by the residual's size
    again = _fitted(robot, every, log_span, gain, log_span, motion)
    return [again if again is not None else replace(longest, whole=True)]


def _in_time_order(a: tuple[NDArray, ...], b: tuple[NDArray, ...] | None) -> tuple[NDArray, ...]:
    """The samples of ``a`` and ``b`` (each as :meth:`LoadSamples.joined`) in time order."""
    if b is None:
        return a
    both = tuple(np.concatenate([x, y]) for x, y in zip(a, b, strict=True))
    order = np.argsort(both[0], kind="stable")
    return tuple(x[order] for x in both)


def _fitted(
    robot: Robot,
    joined: tuple[NDArray, ...],
    span: tuple[float, float],
    gain: ArrayLike,
    log_span: tuple[float, float],
    motion: tuple[NDArray, NDArray, NDArray, NDArray] | None,
) -> CarriedLoad | None:
    """:func:`fit_carried_load` on the samples of ``joined`` within ``span`` [s]."""
    if (kept := samples_within(joined, *span)) is None:
        return None
    t, q, r, c = kept
    rigid = None if motion is None else lagged_rigid_regressor(robot, motion, span, gain, t)
    return fit_carried_load(robot, t, q, r, c, gain, span, log_span, rigid)


class LoadTorque:
    """The loads' torque as the observer's residual carries it, a block at a time: ``Y
    theta`` (the weight's or the rigid load's regressor) on from each load's pick to its
    release, through ``K/(s + K)`` (module docstring).

    Parameters
    ----------
    robot : Robot
    loads : sequence of CarriedLoad
    gain : array_like, shape (n,)
        The observer's K [1/s].
    """

    def __init__(self, robot: Robot, loads: Sequence[CarriedLoad], gain: ArrayLike) -> None:
        self.robot, self.loads = robot, tuple(loads)
        self._K = np.asarray(gain, dtype=np.float64)
        self._state = np.zeros(robot.n)
        self._last: float | None = None

    def restart(self) -> None:
        """A new piece of the log: the lag starts again from zero (as the observer)."""
        self._state[:] = 0.0
        self._last = None

    def block(
        self, t: NDArray, q: NDArray, dq: NDArray | None = None, ddq: NDArray | None = None
    ) -> NDArray[np.float64]:
        """The torque to take from the residual at times ``t`` (m,) [s], positions ``q``
        (m, n) [rad], velocities ``dq`` [rad/s] and accelerations ``ddq`` [rad/s^2] (m, n)
        (a rigid load's inertia; None: its weight alone): (m, n) [N m]."""
        u = np.zeros((t.shape[0], self.robot.n))
        for load in self.loads:
            on = (
                np.ones(t.shape[0], bool)
                if load.whole
                else (t >= load.picked) & (t < load.released)
            )
            if on.any():
                u[on] += _load_torque(self.robot, load.theta, q[on], dq, ddq, on)
        s, last = self._state, self._last
        m = t.shape[0]
        if m == 0 or (not u.any() and not s.any()):
            self._last = float(t[-1]) if m else last
            return u
        steps = np.diff(t if last is None else np.concatenate([[last], t]))
        dt = float(np.median(steps)) if steps.size else 0.0
        out = _lag(u, self._K, dt, s)
        s = out[-1].copy()
        s[np.abs(s) < 1e-12] = 0.0
        self._state, self._last = s, float(t[-1])
        return out


def _load_torque(
    robot: Robot,
    theta: NDArray,
    q: NDArray,
    dq: NDArray | None,
    ddq: NDArray | None,
    on: NDArray[np.bool_],
) -> NDArray[np.float64]:
    """The torque [N m] (m, n) of a load ``theta`` (4 or 10, :class:`CarriedLoad`) at
    positions ``q`` (m, n); its inertial part needs the rows ``on`` of ``dq``, ``ddq``."""
    if theta.shape[0] == 4 or dq is None or ddq is None:
        return np.asarray(load_regressor(robot, q) @ theta[:4], dtype=np.float64)
    return np.asarray(rigid_load_regressor(robot, q, dq[on], ddq[on]) @ theta, dtype=np.float64)


def at_load_edge(start: float, end: float, loads: Sequence[CarriedLoad]) -> bool:
    """An event from ``start`` to ``end`` [s] lies within :data:`EDGE_S` after a load's
    pick or release (the step's rest, not a contact)."""
    for ld in loads:
        for edge in (ld.picked, ld.released):
            if not ld.whole and start >= edge - EDGE_S and end <= edge + EDGE_S:
                return True
    return False


def load_events(loads: Sequence[CarriedLoad], events: Sequence[ContactEvent]) -> list[ContactEvent]:
    """The event of each load picked and released (not held through the whole log): the
    first run's event it was fitted on (the same ``start`` and ``end`` [s], among
    ``events``), its level ``load``. A load is an external force at its pick, physically
    a weight or a steady push along gravity alike: reported, never dropped."""
    out = []
    for ld in loads:
        if ld.whole:
            continue
        for e in events:
            if e.start == ld.start and e.end == ld.end:
                out.append(replace(e, level="load"))
                break
    return out


#: How the reading of an event as a load is turned off (the command line's flag).
NO_LOADS = "--no-loads"


def load_words(load: CarriedLoad, *, identified: bool = True) -> str:
    """One line of a load: ``load: read as a load of 0.80 kg at the flange (or a steady
    push along gravity) from 30.01 s to 50.25 s, an external-force event (level load,
    scored as any event) ...``, with its centre of mass and how to turn the reading off
    (:data:`NO_LOADS`); a load held through the whole log points to ``dynid payload``."""
    c = ", ".join(f"{x:+.3f}" for x in load.com)
    head = f"load: read as a load of {load.mass:.2f} kg at the {LOAD_FRAME}"
    com = f"CoM ({c}) m in the flange's axes; detection ran again without its torque"
    off = f"{NO_LOADS} reads no event as a load"
    if not load.whole:
        return (
            f"{head} (or a steady push along gravity) from {load.start:.2f} s to "
            f"{load.end:.2f} s, picked at {load.picked:.2f} s and released at "
            f"{load.released:.2f} s: an external-force event (level load, scored as any "
            f"event), {com} for the contacts on top; {off}"
        )
    todo = "model_with_payload.json for --model" if identified else "robot_with_payload.toml"
    return (
        f"{head} held through the whole log, {load.start:.2f} s to {load.end:.2f} s (not a "
        f"contact, not the model's error), {com}: the model lacks it; identify it with dynid "
        f"payload on collision-free logs recorded with it ({todo}), then calibrate again; "
        f"{off}"
    )


def unread_load_words(load: CarriedLoad, *, identified: bool = True) -> str:
    """One line of a load that fits an event's residual in a detection with
    :data:`NO_LOADS` (not applied): its span, mass, centre of mass and the share of the
    residual it explains, and that the detection without the flag reads it as a load
    (and, held through the whole log, that ``dynid payload`` identifies it)."""
    c = ", ".join(f"{x:+.3f}" for x in load.com)
    held = (
        "held through the whole log"
        if load.whole
        else f"picked at {load.picked:.2f} s and released at {load.released:.2f} s"
    )
    todo = "model_with_payload.json for --model" if identified else "robot_with_payload.toml"
    payload = (
        f"; to add it to the model, dynid payload on collision-free logs recorded with it ({todo})"
        if load.whole
        else ""
    )
    return (
        f"{NO_LOADS}: a constant load at the {LOAD_FRAME} fits the residual of the event "
        f"{load.start:.2f} s to {load.end:.2f} s ({held}): {load.mass:.2f} kg, CoM ({c}) m "
        f"in the flange's axes, explaining {100.0 * load.explained:.3g} % of it, not the "
        "model's friction or thresholds; without "
        f"{NO_LOADS} the event is read as that load and the contacts on top of it are "
        f"detected{payload}"
    )
