"""The friction a model without friction leaves in the residual, measured on the logs.

A model that holds no friction (identified without friction terms or from static data, a
URDF without ``<dynamics friction>``, a description with its friction removed) predicts
the motors' torques without the joints' friction ``tau_f``, and the residual reads
``r = tau_ext - tau_f`` through the observer's lag: on collision-free motion ``-tau_f``,
an external torque that is not one. At speed it is fitted per joint by

.. math:: r_j = -(f_{c,j} \\operatorname{sign}\\dot q_j + f_{v,j} \\dot q_j) + o_j

(least squares over running normal equations, a block of samples at a time; without the
offset ``o_j`` for a joint that moved one way only, :data:`ONE_WAY`), on the
samples where ``|dq_j|`` exceeds :data:`SPEED` and five velocity-noise stds and its sign
has held for :data:`SETTLE` time constants ``1 / K_O`` (the lag has passed the step of
the Coulomb term at a reversal). The size reported per joint is the RMS of the fitted
``f_c sign(dq) + f_v dq`` over those samples [N m]: what the unmodelled friction adds
to the external torque estimate while the joint moves. It is *seen* where the pair
``(f_c, f_v)`` stands out of the fit's noise (a chi-square of 2 degrees of freedom over
:data:`CHI2_SEEN`, the covariance scaled for the residual's serial correlation: the
samples within ``2 / K_O`` of each other count once). Where it is not seen, the size
still bounds what the data could hide: :attr:`UnmodelledFriction.bound` (the size plus
three standard errors). A detection reads only the samples under the contact threshold;
where those are a minority of the samples at speed (:data:`MOST_FLAGGED`), they say
nothing of the friction (a residual over the threshold through most of the motion is
itself the sign of a model that misses terms), and the same fit over every sample at
speed, contacts included, is what the note gives (:attr:`UnmodelledFriction.overall`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..identification.velocity_noise import velocity_noise_std

__all__ = [
    "CHI2_SEEN",
    "MOST_FLAGGED",
    "SETTLE",
    "SPEED",
    "FrictionTally",
    "UnmodelledFriction",
    "no_friction_note",
]

#: Speed [rad/s] below which a sample is not read (near rest the Coulomb term's sign is
#: the velocity noise's).
SPEED = 0.05
#: Time constants ``1 / K_O`` the velocity's sign must have held for a sample to be read.
SETTLE = 5.0
#: Chi-square (2 degrees of freedom) above which the fitted friction is seen: 13.8, a
#: chance of 1e-3 for a model whose friction is right.
CHI2_SEEN = 13.82
#: Share of a joint's samples at speed in one direction above which its Coulomb term and an
#: offset cannot be told apart: the fit then has no offset (the size an upper bound).
ONE_WAY = 0.95
#: Samples per joint at speed below which nothing is said of it.
MIN_SAMPLES = 50
#: Share of the samples at speed over the contact threshold (left out of the fit) above
#: which the samples under it cannot judge the friction a model misses.
MOST_FLAGGED = 0.5


@dataclass(frozen=True, slots=True)
class UnmodelledFriction:
    """The friction in the residual of a model without friction, per joint.

    Attributes
    ----------
    coulomb, viscous : ndarray, shape (n,)
        ``f_c`` [N m] and ``f_v`` [N m s/rad] fitted (NaN: fewer than
        :data:`MIN_SAMPLES` samples at speed).
    size : ndarray, shape (n,)
        RMS [N m] of the fitted friction over the samples at speed (NaN as above).
    se : ndarray, shape (n,)
        Its standard error [N m] (delta method, serial correlation counted).
    seen : ndarray of bool, shape (n,)
        The friction stands out of the noise (module docstring).
    samples : ndarray of int, shape (n,)
        Samples read at speed.
    at_speed : ndarray of int, shape (n,), or None
        Samples at speed, those over the contact threshold (not read) included (None:
        every sample at speed read).
    overall : UnmodelledFriction or None
        The same fit over every sample at speed, those over the threshold included (None:
        none left out).
    """

    coulomb: NDArray[np.float64]
    viscous: NDArray[np.float64]
    size: NDArray[np.float64]
    se: NDArray[np.float64]
    seen: NDArray[np.bool_]
    samples: NDArray[np.int64]
    at_speed: NDArray[np.int64] | None = None
    overall: UnmodelledFriction | None = None

    def flagged_share(self) -> float:
        """The share of the samples at speed (every joint's pooled) over the contact
        threshold, left out of the fit (0: none)."""
        if self.at_speed is None or not np.any(self.at_speed):
            return 0.0
        return 1.0 - float(np.sum(self.samples)) / float(np.sum(self.at_speed))

    @property
    def bound(self) -> NDArray[np.float64]:
        """``size + 3 se`` [N m] (n,): the friction the data could hide where not seen."""
        out: NDArray[np.float64] = self.size + 3.0 * self.se
        return out


@dataclass(slots=True)
class FrictionTally:
    """Running normal equations of the fit of the module docstring over the blocks of
    one or more logs.

    Attributes
    ----------
    n : int
        Joints.
    gain : ndarray, shape (n,)
        ``K_O`` [1/s]: the settling time and the serial correlation.
    """

    n: int
    gain: NDArray[np.float64]
    _AtA: NDArray[np.float64] = field(init=False)
    _Atr: NDArray[np.float64] = field(init=False)
    _rr: NDArray[np.float64] = field(init=False)
    _count: NDArray[np.int64] = field(init=False)
    _dt: list[float] = field(init=False)
    _sign: NDArray[np.float64] = field(init=False)
    _since: NDArray[np.float64] = field(init=False)

    def __post_init__(self) -> None:
        n = self.n
        self.gain = np.broadcast_to(np.asarray(self.gain, dtype=np.float64), (n,)).copy()
        # [0]: the samples read (under the threshold), [1]: every sample at speed
        self._AtA, self._Atr = np.zeros((2, n, 3, 3)), np.zeros((2, n, 3))
        self._rr, self._count, self._dt = np.zeros((2, n)), np.zeros((2, n), dtype=np.int64), []
        self.new_log()

    def new_log(self) -> None:
        """Forget the last velocity signs (a new log, or a piece after a cut)."""
        self._sign = np.zeros(self.n)
        self._since = np.full(self.n, np.inf)

    def add(self, t: ArrayLike, dq: ArrayLike, r: ArrayLike, keep: ArrayLike | None = None) -> None:
        """One block of consecutive samples: times ``t`` [s] (N,), measured velocities
        ``dq`` [rad/s] and residual ``r`` [N m], each (N, n); ``keep`` (N, n) bool, the
        samples that may be read (a detection leaves out those over a threshold). Rows
        where ``r`` is not finite are left out."""
        T = np.asarray(t, dtype=np.float64)
        V, R = np.asarray(dq, dtype=np.float64), np.asarray(r, dtype=np.float64)
        if T.shape[0] < 2:
            return
        self._dt.append(float(np.median(np.diff(T))))
        ok = np.all(np.isfinite(R), axis=1)
        sigma = velocity_noise_std(V[ok]) if np.count_nonzero(ok) >= 8 else np.zeros(self.n)
        for j in range(self.n):
            s = np.sign(V[:, j])
            since = self._since_change(T, s, j)
            use = ok & (np.abs(V[:, j]) > max(SPEED, 5.0 * sigma[j]))
            use &= since >= SETTLE / self.gain[j]
            self._put(1, j, s, V[:, j], R[:, j], use)
            if keep is not None:
                use &= np.asarray(keep)[:, j]
            self._put(0, j, s, V[:, j], R[:, j], use)

    def _put(self, k: int, j: int, s: NDArray, v: NDArray, r: NDArray, use: NDArray) -> None:
        """Joint ``j``'s samples ``use`` into the normal equations ``k`` (0: read, 1: all
        at speed): velocity signs ``s``, velocities ``v`` and residual ``r``."""
        A = np.stack([-s[use], -v[use], np.ones(np.count_nonzero(use))], axis=1)
        y = r[use]
        self._AtA[k, j] += A.T @ A
        self._Atr[k, j] += A.T @ y
        self._rr[k, j] += y @ y
        self._count[k, j] += y.shape[0]

    def _since_change(self, T: NDArray, s: NDArray, j: int) -> NDArray[np.float64]:
        """Time [s] since the sign of joint ``j``'s velocity last changed, at each sample
        (carried across blocks)."""
        prev = np.concatenate([[self._sign[j]], s[:-1]])
        changed = s != prev
        idx = np.where(changed, np.arange(s.shape[0]), -1)
        last = np.maximum.accumulate(idx)
        start = T[0] - self._since[j] if np.isfinite(self._since[j]) else -np.inf
        at = np.where(last >= 0, T[np.maximum(last, 0)], start)
        out: NDArray[np.float64] = T - at
        self._sign[j] = s[-1]
        self._since[j] = out[-1] + 0.0
        return out

    def result(self) -> UnmodelledFriction | None:
        """The fit of every block added (None before any sample at speed); with samples
        over the threshold left out, the fit over all of them too (``overall``)."""
        if not np.any(self._count[1]):
            return None
        read = self._fit(0)
        if np.array_equal(self._count[0], self._count[1]):
            return read
        return replace(read, at_speed=self._count[1].copy(), overall=self._fit(1))

    def _fit(self, k: int) -> UnmodelledFriction:
        """The fit of the normal equations ``k`` (0: samples read, 1: all at speed)."""
        n = self.n
        fc, fv, size, se = (np.full(n, np.nan) for _ in range(4))
        seen = np.zeros(n, dtype=bool)
        dt = float(np.median(self._dt)) if self._dt else 0.0
        for j in range(n):
            N = int(self._count[k, j])
            if N < MIN_SAMPLES:
                continue
            G, b = self._AtA[k, j], self._Atr[k, j]
            if abs(G[0, 2]) > ONE_WAY * N:  # moved one way only: no offset told apart
                G, b = G[:2, :2], b[:2]
            x = np.linalg.lstsq(G, b, rcond=None)[0]
            s2 = max(float(self._rr[k, j] - x @ b), 0.0) / max(N - G.shape[0], 1)
            inflation = max(1.0, 2.0 / (self.gain[j] * dt)) if dt > 0 else 1.0
            cov = s2 * inflation * np.linalg.pinv(G)
            Gf, xf, cf = G[:2, :2] / N, x[:2], cov[:2, :2]
            fc[j], fv[j] = x[0], x[1]
            size[j] = np.sqrt(max(float(xf @ Gf @ xf), 0.0))
            grad = Gf @ xf / size[j] if size[j] > 0 else np.zeros(2)
            se[j] = np.sqrt(max(float(grad @ cf @ grad), 0.0))
            chi2 = float(xf @ np.linalg.lstsq(cf, xf, rcond=None)[0]) if s2 > 0 else np.inf
            seen[j] = chi2 > CHI2_SEEN
        return UnmodelledFriction(fc, fv, size, se, seen, self._count[k].copy())


def no_friction_note(found: UnmodelledFriction | None, names: Sequence[str]) -> str:
    """The note of a model that holds no friction: whether the logs' residual at speed
    shows friction it misses, how large per joint [N m], and what to do."""
    head = "the model holds no friction"
    if found is not None and (o := found.overall) is not None:
        if found.flagged_share() > MOST_FLAGGED and np.isfinite(o.size).any():
            return _mostly_flagged_note(found, o, names)
    if found is None or not np.any(np.isfinite(found.size)):
        return (
            f"{head}, and the logs never move a joint fast enough to measure what it misses: "
            "an arm's friction, if it has some, reads as an external torque while a joint "
            "moves: identify it (`dynid friction` on a log that moves) and pass it with "
            "--friction"
        )
    read = [j for j in range(len(names)) if np.isfinite(found.size[j])]
    if not np.any(found.seen):
        top = max(float(found.bound[j]) for j in read)
        return (
            f"{head}, and the logs' residual at speed shows none above its noise (at most "
            f"{top:.2g} N m RMS on any joint, on {int(np.sum(found.samples))} samples at "
            "speed): no friction to add"
        )
    seen = [j for j in read if found.seen[j]]
    sizes = ", ".join(f"{names[j]} {found.size[j]:.2g}" for j in seen)
    clear = [names[j] for j in read if not found.seen[j]]
    return (
        f"{head}, but the arm's friction is in the logs: the residual at speed holds "
        f"{sizes} N m (RMS while the joint moves)"
        + (f"; none above the noise on {', '.join(clear)}" if clear else "")
        + ". It reads as an external torque whenever those joints move, and thresholds "
        "calibrated on it grow by as much (contacts that size go unseen): identify the "
        "friction (`dynid friction` on a collision-free log) and pass it with --friction"
    )


def _mostly_flagged_note(
    found: UnmodelledFriction, overall: UnmodelledFriction, names: Sequence[str]
) -> str:
    """The note of a model without friction whose residual lies over the contact
    threshold on most samples at speed: the samples under it cannot judge; the fit over
    every sample at speed, contacts included, says how large what it misses reads."""
    joints = [j for j in range(len(names)) if np.isfinite(overall.size[j])]
    shown = [j for j in joints if overall.seen[j]] or joints
    sizes = ", ".join(f"{names[j]} {overall.size[j]:.2g}" for j in shown)
    return (
        f"the model holds no friction, and its residual lies over the contact threshold on "
        f"{100.0 * found.flagged_share():.3g} % of the samples at speed: too few under it "
        "to judge the friction it misses. Over every sample at speed, contacts included, "
        f"it reads {sizes} N m (RMS while the joint moves): the model likely misses the "
        "arm's friction (or other terms), which reads as contact whenever a joint moves; "
        "identify the friction (`dynid friction` on a collision-free log) and pass it "
        "with --friction"
    )
