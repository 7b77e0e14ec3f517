"""A residual that a joint spring explains: a stiffness per joint fitted with the model.

A spring ``k_j (q_j - q0_j)`` on joint ``j`` that the rigid-body model lacks is partly
taken by the fit (the links' gravity columns and the offsets bend towards it), so the
held-out residual's slope over ``q_j`` is far below ``k_j`` (a fifth of it for a Panda
shoulder swept over 2.5 rad). :func:`residual_spring` fits the measured torques, each
joint weighed by its noise, with the model's own columns and one column ``q_j`` per joint
on the joint itself (:func:`spring_columns`) together: the coefficients of the latter are
the stiffnesses [N m/rad] the data hold beyond the model, its offsets taking the rest
position, and a tilt of the gravity vector beside them where the caller adds its columns
(a tilted base is no spring). A joint's spring is named (:attr:`ResidualSpring.named`)
when the joint's held-out residual is above its noise, the stiffness stands
:data:`SIGNIFICANT` standard deviations clear and the spring's torque over the samples
(``|k_j|`` times the RMS of ``q_j`` about its mean) is at least :data:`FOLLOWS` of the
residual above the noise: a stiffness too small to make the residual is not its cause;
and never where the residual follows the joint's velocity more than its position
(:attr:`ResidualSpring.velocity_led`, set by
:func:`~dynid.identification.residual_dependence.judged_springs`): friction the law misses
(a Stribeck bump) leaves a residual that a stiffness fitted beside the model's columns
takes a share of (0.37 N m/rad, 13 standard deviations clear, on a Panda's joint 4 whose
Stribeck term the model lacked), and it is no spring's.

A simulated Panda with a 20 N m/rad spring on joint 2: 19.92 N m/rad from one 8 s
recording, 20.19 and 19.99 from two and three (each predicted by the fit of the others);
a 20 s recording's residual alone had been read as a gravity vector tilted by 0.89 and
1.8 deg.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..regressors.spring import JointSpring
from .verdict import SYSTEMATIC_RATIO

__all__ = ["FOLLOWS", "SIGNIFICANT", "ResidualSpring", "residual_spring", "spring_columns"]

#: Smallest ratio of a stiffness's magnitude to its standard deviation.
SIGNIFICANT = 5.0
#: Smallest share of a joint's held-out residual above its noise (RMS) the spring's torque
#: must reach.
FOLLOWS = 0.5
#: Samples used at most (evenly spread).
_SAMPLES = 4_000


@dataclass(frozen=True, slots=True, eq=False)
class ResidualSpring:
    """The joint springs a residual points to.

    Attributes
    ----------
    stiffness : ndarray, shape (n,)
        Each joint's stiffness [N m/rad] fitted with the model's columns (the torque
        ``k_j (q_j - q0_j)`` added to the model's).
    std : ndarray, shape (n,)
        Their standard deviations [N m/rad] (white noise of the joints' residual after the
        fit assumed, at least their noise: a lower bound).
    torque : ndarray, shape (n,)
        Each spring's torque RMS [N m] over the samples: ``|k_j|`` times the RMS of
        ``q_j`` about its mean.
    systematic : ndarray, shape (n,)
        Each joint's residual above its noise (RMS) [N m]: of the prediction judged, the
        ``error`` of :func:`residual_spring`.
    noise : ndarray, shape (n,)
        Each joint's noise [N m].
    velocity_led : tuple of int
        The joints whose residual follows their velocity more than their position
        (:func:`~dynid.identification.residual_dependence.judged_springs`): never named,
        their residual is friction's, whatever stiffness was fitted; empty until judged.
    """

    stiffness: NDArray[np.float64]
    std: NDArray[np.float64]
    torque: NDArray[np.float64]
    systematic: NDArray[np.float64]
    noise: NDArray[np.float64]
    velocity_led: tuple[int, ...] = ()

    @property
    def named(self) -> tuple[int, ...]:
        """The joints whose spring explains their residual: the residual above the noise
        (its RMS over :data:`~dynid.identification.verdict.SYSTEMATIC_RATIO` x the
        noise), the stiffness :data:`SIGNIFICANT` standard deviations clear, its torque at
        least :data:`FOLLOWS` of the residual above the noise; none of
        :attr:`velocity_led` (a residual that follows the velocity more is friction's)."""
        z = np.abs(self.stiffness) / np.maximum(self.std, 1e-300)
        ok = (z >= SIGNIFICANT) & (self.torque >= FOLLOWS * self.systematic)
        ok &= self.systematic**2 + self.noise**2 > (SYSTEMATIC_RATIO * self.noise) ** 2
        return tuple(int(j) for j in np.flatnonzero(ok) if int(j) not in self.velocity_led)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``stiffness`` and ``std`` per joint [N m/rad], ``torque`` and
        ``systematic`` per joint [N m], ``named`` and ``velocity_led`` (the joints' indices
        from 0)."""
        return {
            "stiffness": self.stiffness.tolist(),
            "std": self.std.tolist(),
            "torque": self.torque.tolist(),
            "systematic": self.systematic.tolist(),
            "named": list(self.named),
            "velocity_led": list(self.velocity_led),
        }

    def sentence(self, joint: int) -> str:
        """Joint ``joint``'s stiffness in words: ``a spring of about 19.8 N m/rad (std
        0.3)``."""
        k, s = float(self.stiffness[joint]), float(self.std[joint])
        return f"a spring of about {k:.3g} N m/rad (std {s:.2g})"


def spring_columns(q: ArrayLike) -> NDArray[np.float64]:
    """The regressor of a linear spring on each joint: ``q_j`` on joint ``j`` (the spring
    term's own columns, :class:`~dynid.regressors.spring.JointSpring`, about ``q = 0``).

    Parameters
    ----------
    q : array_like, shape (..., n)
        Joint positions [rad].

    Returns
    -------
    ndarray, shape (..., n, n)
        [rad]: column ``j`` is ``q_j`` in row ``j``, zero elsewhere (a constant, the rest
        position, is an offset's).
    """
    q = np.asarray(q, dtype=np.float64)
    term = JointSpring(tuple(np.zeros(q.shape[-1])))  # the spring term, about q = 0
    return term.torque_columns(q, np.zeros_like(q), np.zeros_like(q))


def residual_spring(
    q: ArrayLike,
    tau: ArrayLike,
    error: ArrayLike,
    noise_rms: ArrayLike,
    columns: Callable[[NDArray[np.intp]], NDArray[np.float64]],
) -> ResidualSpring | None:
    """The stiffness per joint that explains the torques beside the model's columns
    (module docstring).

    Parameters
    ----------
    q : array_like, shape (N, n)
        Positions [rad] of the residual's samples.
    tau : array_like, shape (N, n)
        The measured torques [N m] at the samples.
    error : array_like, shape (M, n)
        Measured less predicted torques [N m] of the prediction judged (the held-out
        residual), at its own samples (a time block of the log fitted: ``M <= N``): what a
        spring must explain.
    noise_rms : array_like, shape (n,)
        Each joint's noise [N m].
    columns : callable
        ``columns(rows)``: the model's own regressor (M, n, p) at the samples ``rows``
        (M,), offsets among them (their rest positions), without a spring.

    Returns
    -------
    ResidualSpring or None
        None when the noise is not known or there are fewer samples than columns.
    """
    E = np.asarray(error, dtype=np.float64)
    s = np.asarray(noise_rms, dtype=np.float64)
    Q = np.asarray(q, dtype=np.float64)
    if E.ndim != 2 or Q.ndim != 2 or not np.all(np.isfinite(s) & (s > 0)):
        return None
    N, n = Q.shape
    rows = np.unique(np.linspace(0, N - 1, min(N, _SAMPLES)).astype(np.intp))
    Q = Q[rows]
    W = np.concatenate([np.asarray(columns(rows), dtype=np.float64), spring_columns(Q)], axis=-1)
    A = (W / s[:, None]).reshape(rows.size * n, -1)
    if A.shape[0] <= A.shape[1]:
        return None
    y = (np.asarray(tau, dtype=np.float64)[rows] / s).reshape(-1)
    x, _, rank, _ = np.linalg.lstsq(A, y, rcond=None)  # its rank matrix_rank's, one SVD
    r = y - A @ x
    dof = int(rank)
    var = max(float(r @ r) / max(r.size - dof, 1), 1.0)
    cov = np.linalg.pinv(A.T @ A)[-n:, -n:] * var
    k = np.asarray(x[-n:], dtype=np.float64)
    spread = np.sqrt(np.mean((Q - Q.mean(axis=0)) ** 2, axis=0))
    above = np.sqrt(np.maximum(np.mean(E**2, axis=0) - s**2, 0.0))
    return ResidualSpring(
        stiffness=k,
        std=np.sqrt(np.maximum(np.diag(cov), 0.0)),
        torque=np.abs(k) * spread,
        systematic=above,
        noise=s,
    )
