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
three standard errors).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..identification.velocity_noise import velocity_noise_std

__all__ = [
    "CHI2_SEEN",
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
    """

    coulomb: NDArray[np.float64]
    viscous: NDArray[np.float64]
    size: NDArray[np.float64]
    se: NDArray[np.float64]
    seen: NDArray[np.bool_]
    samples: NDArray[np.int64]

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
        self._AtA, self._Atr = np.zeros((n, 3, 3)), np.zeros((n, 3))
        self._rr, self._count, self._dt = np.zeros(n), np.zeros(n, dtype=np.int64), []
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
            if keep is not None:
                use &= np.asarray(keep)[:, j]
            A = np.stack([-s[use], -V[use, j], np.ones(np.count_nonzero(use))], axis=1)
            y = R[use, j]
            self._AtA[j] += A.T @ A
            self._Atr[j] += A.T @ y
            self._rr[j] += y @ y
            self._count[j] += y.shape[0]

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
        """The fit of every block added (None before any sample at speed)."""
        if not np.any(self._count):
            return None
        n = self.n
        fc, fv, size, se = (np.full(n, np.nan) for _ in range(4))
        seen = np.zeros(n, dtype=bool)
        dt = float(np.median(self._dt)) if self._dt else 0.0
        for j in range(n):
            N = int(self._count[j])
            if N < MIN_SAMPLES:
                continue
            G, b = self._AtA[j], self._Atr[j]
            if abs(G[0, 2]) > ONE_WAY * N:  # moved one way only: no offset told apart
                G, b = G[:2, :2], b[:2]
            x = np.linalg.lstsq(G, b, rcond=None)[0]
            s2 = max(float(self._rr[j] - x @ b), 0.0) / max(N - G.shape[0], 1)
            inflation = max(1.0, 2.0 / (self.gain[j] * dt)) if dt > 0 else 1.0
            cov = s2 * inflation * np.linalg.pinv(G)
            Gf, xf, cf = G[:2, :2] / N, x[:2], cov[:2, :2]
            fc[j], fv[j] = x[0], x[1]
            size[j] = np.sqrt(max(float(xf @ Gf @ xf), 0.0))
            grad = Gf @ xf / size[j] if size[j] > 0 else np.zeros(2)
            se[j] = np.sqrt(max(float(grad @ cf @ grad), 0.0))
            chi2 = float(xf @ np.linalg.lstsq(cf, xf, rcond=None)[0]) if s2 > 0 else np.inf
            seen[j] = chi2 > CHI2_SEEN
        return UnmodelledFriction(fc, fv, size, se, seen, self._count.copy())


def no_friction_note(found: UnmodelledFriction | None, names: Sequence[str]) -> str:
    """The note of a model that holds no friction: whether the logs' residual at speed
    shows friction it misses, how large per joint [N m], and what to do."""
    head = "the model holds no friction"
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
            f"{top:.2g} N m RMS on any joint): no friction to add"
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
