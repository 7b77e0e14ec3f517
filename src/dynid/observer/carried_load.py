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

The load is then taken out: :class:`LoadTorque` gives, block by block, its torque as the
observer sees it, ``Y(q) theta`` switched on at the pick and off at the release and
passed through the observer's ``K/(s + K)`` (the residual's own lag), and the detection
runs again on the residual minus it (the wrench estimate loses the load's wrench with
it). The pick and the release are read off the residual at the event's edges (the first
order lag crossed back to the step's time). Events of the second run that lie within
:data:`EDGE_S` of the pick or the release are the step's own rest, not contacts.

On the trial's 80 s Panda log with a 0.8 kg object held from 30.0 s to 50.24 s and 5
labelled contacts on top: 0.80 kg named, and the contacts on top detected (before: one
20 s collision, a false alarm hiding them).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.robot import Robot
from .unmodelled_load import LOAD_FRAME, load_regressor

__all__ = [
    "EDGE_S",
    "MIN_EXPLAINED",
    "MIN_INLIERS",
    "MIN_LOAD_S",
    "MIN_MOTION_RAD",
    "CarriedLoad",
    "LoadSamples",
    "LoadTorque",
    "at_load_edge",
    "carried_loads",
    "fit_carried_load",
    "load_words",
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
#: Samples kept per second of residual over the threshold for the fit (memory bound).
KEPT_RATE_HZ = 200.0


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
    theta : ndarray, shape (4,)
        ``(m, m c)`` [kg, kg m].
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


class LoadSamples:
    """The samples over the contact threshold of one log, every few (at most
    :data:`KEPT_RATE_HZ` a second), for :func:`fit_carried_load`: times [s], positions
    [rad], residual [N m] and contact threshold [N m]."""

    def __init__(self, period_s: float | None) -> None:
        self._every = max(1, round(1.0 / (KEPT_RATE_HZ * period_s))) if period_s else 1
        self._parts: list[tuple[NDArray, ...]] = []
        self._seen = 0

    def add(self, t: NDArray, q: NDArray, r: NDArray, contact: NDArray) -> None:
        """One block, each (m, ...) of the same rows."""
        with np.errstate(invalid="ignore"):
            over = np.any(np.abs(r) > contact, axis=1)
        idx = np.flatnonzero(over)
        take = idx[(self._seen + np.arange(idx.size)) % self._every == 0]
        self._seen += idx.size
        if take.size:
            self._parts.append((t[take], q[take], r[take], contact[take]))

    def within(self, start: float, end: float) -> tuple[NDArray, ...] | None:
        """The kept samples from ``start`` to ``end`` [s]; None: none."""
        if not self._parts:
            return None
        t, q, r, c = (np.concatenate([p[i] for p in self._parts]) for i in range(4))
        k = (t >= start) & (t <= end)
        return (t[k], q[k], r[k], c[k]) if k.any() else None


def _weighted_fit(
    A: NDArray, b: NDArray, keep: NDArray[np.bool_]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``theta`` (4,) of the rows ``keep`` of ``A`` (N, n, 4), ``b`` (N, n) and every
    sample's ``b - A theta`` (N, n)."""
    Ak, bk = A[keep].reshape(-1, 4), b[keep].reshape(-1)
    theta = np.linalg.lstsq(Ak, bk, rcond=None)[0]
    return theta, b - A @ theta


def fit_carried_load(
    robot: Robot,
    t: ArrayLike,
    q: ArrayLike,
    r: ArrayLike,
    contact: ArrayLike,
    gain: ArrayLike,
    span: tuple[float, float],
    log_span: tuple[float, float],
) -> CarriedLoad | None:
    """The load of an event ``span`` [s] fitted on its samples at times ``t`` (N,) [s],
    positions ``q`` (N, n) [rad], residual ``r`` (N, n) [N m] and contact threshold
    ``contact`` (N, n) [N m] (module docstring); ``gain`` the observer's K (n,) [1/s],
    ``log_span`` the log's first and last time [s]. None: no load explains it."""
    ta = np.asarray(t, dtype=np.float64)
    R, C = np.asarray(r, dtype=np.float64), np.asarray(contact, dtype=np.float64)
    qa = np.asarray(q, dtype=np.float64)
    good = np.all(np.isfinite(R), axis=1) & np.all(C > 0, axis=1)
    if span[1] - span[0] < MIN_LOAD_S or np.count_nonzero(good) < 20:
        return None
    ta, qa, R, C = ta[good], qa[good], R[good], C[good]
    A = load_regressor(robot, qa) / C[:, :, None]
    b = R / C
    keep = np.ones(ta.shape[0], dtype=bool)
    theta, left = _weighted_fit(A, b, keep)
    for _ in range(FIT_ROUNDS):
        worst = np.max(np.abs(left), axis=1)  # each sample's largest, over its threshold
        cut = max(1.0, SPREAD * float(np.median(worst[keep])))  # the load's own misfit
        inside = worst <= cut
        if inside.sum() < 20 or np.array_equal(inside, keep):
            break
        keep = inside
        theta, left = _weighted_fit(A, b, keep)
    kept = float(np.mean(keep))
    total = float(np.sum(b[keep] ** 2))
    explained = 1.0 - float(np.sum(left[keep] ** 2)) / total if total > 0 else 0.0
    moved = float(np.max(np.ptp(qa[keep], axis=0))) if keep.any() else 0.0
    mass = float(theta[0])
    if kept < MIN_INLIERS or explained < MIN_EXPLAINED or moved < MIN_MOTION_RAD or mass <= 0:
        return None
    Y = load_regressor(robot, qa[[0, -1]]) @ theta  # (2, n) the load's torque at the edges
    K = np.asarray(gain, dtype=np.float64)
    picked = _step_time(ta[0], R[0], Y[0], K, rising=True)
    released = _step_time(ta[-1], R[-1], Y[-1], K, rising=False)
    whole = span[0] - log_span[0] < MIN_LOAD_S / 2 and log_span[1] - span[1] < MIN_LOAD_S / 2
    return CarriedLoad(
        span[0], span[1], picked, released, mass, theta[1:] / mass, theta, explained, kept, whole
    )


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
) -> list[CarriedLoad]:
    """The loads of the events ``spans`` [s] of :data:`MIN_LOAD_S` or more, fitted on the
    ``samples`` kept over the threshold (:func:`fit_carried_load`)."""
    out = []
    for a, b in spans:
        if b - a < MIN_LOAD_S or (kept := samples.within(a, b)) is None:
            continue
        t, q, r, c = kept
        if (load := fit_carried_load(robot, t, q, r, c, gain, (a, b), log_span)) is not None:
            out.append(load)
    return out


class LoadTorque:
    """The loads' torque as the observer's residual carries it, a block at a time: ``Y(q)
    theta`` on from each load's pick to its release, through ``K/(s + K)`` (module
    docstring).

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

    def block(self, t: NDArray, q: NDArray) -> NDArray[np.float64]:
        """The torque to take from the residual at times ``t`` (m,) [s], positions ``q``
        (m, n) [rad]: (m, n) [N m]."""
        u = np.zeros((t.shape[0], self.robot.n))
        for load in self.loads:
            on = (
                np.ones(t.shape[0], bool)
                if load.whole
                else (t >= load.picked) & (t < load.released)
            )
            if on.any():
                u[on] += load_regressor(self.robot, q[on]) @ load.theta
        s, last = self._state, self._last
        m = t.shape[0]
        if m == 0 or (not u.any() and not s.any()):
            self._last = float(t[-1]) if m else last
            return u
        from scipy.signal import lfilter

        steps = np.diff(t if last is None else np.concatenate([[last], t]))
        dt = float(np.median(steps)) if steps.size else 0.0
        alpha = 1.0 - np.exp(-self._K * dt)  # one step of K/(s + K), per joint
        out = np.empty_like(u)
        for j in range(u.shape[1]):
            zi = [(1.0 - alpha[j]) * s[j]]
            out[:, j], _ = lfilter([alpha[j]], [1.0, alpha[j] - 1.0], u[:, j], zi=zi)
        s = out[-1].copy()
        s[np.abs(s) < 1e-12] = 0.0
        self._state, self._last = s, float(t[-1])
        return out


def at_load_edge(start: float, end: float, loads: Sequence[CarriedLoad]) -> bool:
    """An event from ``start`` to ``end`` [s] lies within :data:`EDGE_S` after a load's
    pick or release (the step's rest, not a contact)."""
    for ld in loads:
        for edge in (ld.picked, ld.released):
            if not ld.whole and start >= edge - EDGE_S and end <= edge + EDGE_S:
                return True
    return False


def load_words(load: CarriedLoad, *, identified: bool = True) -> str:
    """One line of a load: ``load: 0.80 kg at the flange from 30.01 s to 50.25 s (picked
    and released; not a contact)``, with its centre of mass; a load held through the whole
    log points to ``dynid payload``."""
    c = ", ".join(f"{x:+.3f}" for x in load.com)
    head = f"load: {load.mass:.2f} kg at the {LOAD_FRAME}"
    com = f"CoM ({c}) m in the flange's axes; detection ran again without its torque"
    if not load.whole:
        return (
            f"{head} from {load.start:.2f} s to {load.end:.2f} s (picked and released; not a "
            f"contact), {com}"
        )
    todo = "model_with_payload.json for --model" if identified else "robot_with_payload.toml"
    return (
        f"{head} held through the whole log, {load.start:.2f} s to {load.end:.2f} s (not a "
        f"contact, not the model's error), {com}: the model lacks it; identify it with dynid "
        f"payload on collision-free logs recorded with it ({todo}), then calibrate again"
    )
