"""A residual that a tilted gravity vector explains: the base mounted off level.

A robot whose true gravity vector is rotated by a small angle ``a`` about the base's x
axis from the description's ``g0`` loads its joints with
``g(q; R_x(a) g0) = g(q; g0) + a g(q; e_x x g0) + O(a^2)``: the gravity torques are linear
in the gravity vector, so the derivative with respect to the tilt is the gravity torques
of the description's links under the gravity ``e_x x g0`` (:func:`tilt_columns`, two
columns: about x and about y; [N m/rad]). The fit absorbs the part of those columns its
own regressor spans (a tilt moves the base parameters); what remains in the residual is
the part orthogonal to it. :func:`gravity_tilt` fits the measured torques, each joint
weighed by its noise, with the tilt columns and the model's own columns together (by the
Frisch-Waugh-Lovell theorem: on the tilt columns with the model's projected out): the
estimated angles, their standard deviations, and the share of the residual the model's
columns leave alone, above the noise, that the tilt explains. The tilt is named
(:attr:`GravityTilt.named`) when it explains at least :data:`EXPLAINS` of that part, the
angles standing :data:`SIGNIFICANT` standard deviations clear, and the residual's
per-joint diagnosis
(:mod:`~dynid.identification.residual_dependence`) then reads what the tilt leaves.

A Panda whose base is tilted 0.3 deg about x, identified with the level description: the
held-out residual of 1.5 x the noise floor was read as a spring on joint 1; the tilt
columns give 0.30 deg about x and explain most of it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..dynamics.terms import gravity_torques
from ..model.robot import Robot
from ..spatial import matrix_from_angle_axis
from .solvers import tall_r

__all__ = ["EXPLAINS", "SIGNIFICANT", "GravityTilt", "gravity_tilt", "tilt_columns"]

#: Smallest share of the residual's variance above the noise the tilt must explain.
EXPLAINS = 0.5
#: Smallest ratio of the tilt angle's magnitude to its standard deviation.
SIGNIFICANT = 5.0
#: Samples used at most (evenly spread).
_SAMPLES = 4_000


@dataclass(frozen=True, slots=True, eq=False)
class GravityTilt:
    """The tilt of the gravity vector a residual points to.

    Attributes
    ----------
    angle : ndarray, shape (2,)
        The rotation [rad] of the gravity vector about the base's x and y axes.
    std : ndarray, shape (2,)
        Their standard deviations [rad] (white noise of the joints' noise assumed: a
        lower bound).
    explained : float
        The share of the residual's variance above the noise the tilt explains (each joint
        weighed by its noise), 0 to 1 (more: the tilt explains noise too).
    rest : ndarray, shape (M, n)
        What the tilt leaves of the residual [N m] at the samples ``rows``: with the
        model's columns, the residual of the model's and the tilt's columns fitted jointly
        there.
    rows : ndarray of int, shape (M,)
        The residual's samples the tilt was estimated on (at most 4000, evenly spread).
    gravity : ndarray, shape (3,)
        The gravity vector [m/s^2] (base frame) the data read as: the description's rotated
        by ``angle`` (the rotation vector ``(ax, ay, 0)``), what a description's
        ``gravity`` would hold for them.
    """

    angle: NDArray[np.float64]
    std: NDArray[np.float64]
    explained: float
    rest: NDArray[np.float64]
    rows: NDArray[np.intp]
    gravity: NDArray[np.float64]

    @property
    def named(self) -> bool:
        """Whether the tilt explains the residual: at least :data:`EXPLAINS` of its part
        above the noise, the angle :data:`SIGNIFICANT` standard deviations clear."""
        z = float(np.linalg.norm(self.angle / np.maximum(self.std, 1e-300)))
        return self.explained >= EXPLAINS and z >= SIGNIFICANT

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``angle_deg`` and ``std_deg`` about base x and y [deg],
        ``explained`` (share of the residual above the noise), ``named`` and the
        ``gravity`` vector the data read as [m/s^2, base frame]."""
        return {
            "angle_deg": np.degrees(self.angle).tolist(),
            "std_deg": np.degrees(self.std).tolist(),
            "explained": float(self.explained),
            "named": bool(self.named),
            "gravity": self.gravity.tolist(),
        }

    def sentence(self) -> str:
        """The finding in words, with the angles [deg] and what to check."""
        ax, ay = np.degrees(self.angle)
        return (
            f"the gravity vector (base mounting) looks tilted by about {ax:.2g} deg about x "
            f"and {ay:.2g} deg about y (it explains {100 * min(self.explained, 1.0):.0f} % of "
            "the residual above the noise): check the robot's gravity vector / base "
            "orientation (the description's gravity or the base's mounting), not the "
            "model's terms; the data read as gravity = "
            f"[{', '.join(f'{x:.4g}' for x in self.gravity)}] m/s^2 in the base frame"
        )


def tilt_columns(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """The derivative of the gravity torques with respect to a rotation of the gravity
    vector about the base's x and y axes, at zero rotation.

    ``d g(q; R_e(a) g0) / da = g(q; e x g0)`` (``g`` linear in the gravity vector).

    Parameters
    ----------
    robot : Robot
        Its links' parameters and gravity vector ``g0`` [m/s^2] (base frame).
    q : array_like, shape (..., n)
        Joint positions [rad].

    Returns
    -------
    ndarray, shape (..., n, 2)
        [N m/rad]: about x, then about y.
    """
    g0 = np.asarray(robot.gravity, dtype=np.float64)
    cols = [gravity_torques(robot.with_gravity(np.cross(e, g0)), q) for e in np.eye(3)[:2]]
    return np.stack(cols, axis=-1)


def gravity_tilt(
    robot: Robot,
    q: ArrayLike,
    error: ArrayLike,
    noise_rms: ArrayLike,
    tau: ArrayLike | None = None,
    columns: Callable[[NDArray[np.intp]], NDArray[np.float64]] | None = None,
) -> GravityTilt | None:
    """The tilt of the gravity vector that explains ``error`` best (module docstring).

    Parameters
    ----------
    robot : Robot
        The description the model was identified with (its links and gravity).
    q : array_like, shape (N, n)
        Positions [rad] of the residual's samples.
    error : array_like, shape (N, n)
        Measured less predicted torques [N m].
    noise_rms : array_like, shape (n,)
        Each joint's noise [N m].
    tau : array_like, shape (N, n), optional
        The measured torques [N m] at the samples: with ``columns``, the angles are those
        of the model's columns and the tilt's fitted to them jointly (a held-out
        prediction's residual holds its own fit's error, which the tilt would take).
    columns : callable, optional
        ``columns(rows)``: the model's own regressor (M, n, p) at the samples ``rows``
        (M,), projected out of the tilt columns (the part of a tilt the fit absorbs).

    Returns
    -------
    GravityTilt or None
        None when the tilt columns vanish, the noise is not known, or no joint's residual
        is above its noise.
    """
    E = np.asarray(error, dtype=np.float64)
    s = np.asarray(noise_rms, dtype=np.float64)
    if E.ndim != 2 or E.shape[0] < 2 or not np.all(np.isfinite(s) & (s > 0)):
        return None
    N, n = E.shape
    rows = np.unique(np.linspace(0, N - 1, min(N, _SAMPLES)).astype(np.intp))
    G = tilt_columns(robot, np.asarray(q, dtype=np.float64)[rows])
    r, dof = E[rows], 0
    if columns is not None and tau is not None:  # refitted with the model's columns
        W = np.asarray(columns(rows), dtype=np.float64)
        Ww = (W / s[:, None]).reshape(rows.size * n, -1)
        Gw = (G / s[:, None]).reshape(-1, 2)
        T = np.asarray(tau, dtype=np.float64)[rows]
        tw = (T / s).reshape(-1)
        # one factorisation for the tilt's columns, the torques and the rank (lstsq's
        # default rcond is matrix_rank's tolerance): a third of three (one weight per row)
        both, rank = _least_squares(Ww, np.column_stack([Gw, tw]))
        G = G - W @ both[:, :2]
        r = T - W @ both[:, 2]
        dof = int(rank)
    Gw = (G / s[:, None]).reshape(-1, 2)
    rw = (r / s).reshape(-1)
    above = float(np.mean(rw**2)) - (1.0 - dof / rw.size)
    if above <= 0.0 or float(np.linalg.norm(Gw)) == 0.0:
        return None
    theta, *_ = np.linalg.lstsq(Gw, rw, rcond=1e-10)
    fitted = Gw @ theta
    rest = float(np.mean((rw - fitted) ** 2))
    cov = np.linalg.pinv(Gw.T @ Gw) * max(rest, 1.0)
    explained = float(np.mean(fitted**2)) / above
    return GravityTilt(
        angle=np.asarray(theta, dtype=np.float64),
        std=np.sqrt(np.maximum(np.diag(cov), 0.0)),
        explained=explained,
        rest=r - G @ theta,
        rows=rows,
        gravity=matrix_from_angle_axis([theta[0], theta[1], 0.0]) @ np.asarray(robot.gravity),
    )


def _least_squares(
    A: NDArray[np.float64], B: NDArray[np.float64]
) -> tuple[NDArray[np.float64], int]:
    """``lstsq(A, B, rcond=None)`` (p, q) of ``A`` (m, p), ``B`` (m, q), and ``A``'s rank
    at its default tolerance (``eps max(m, p)`` of the largest singular value); of a tall
    ``A`` from the triangular factor ``[[R, C], [0, D]]`` of ``[A B]`` (blocked QR,
    :func:`~dynid.identification.solvers.tall_r`) as ``lstsq(R, C)`` at that tolerance:
    ``R`` holds ``A``'s singular values, the same solution to round-off in half the time
    (a Panda's 4,000 samples and 75 columns: 0.11 s against 0.05 s)."""
    m, p = A.shape
    if m < 4 * (p + B.shape[1]):
        x, _, rank, _ = np.linalg.lstsq(A, B, rcond=None)
        return np.asarray(x, dtype=np.float64), int(rank)
    T = tall_r(A, np.ones(p), B)
    rcond = float(np.finfo(np.float64).eps) * max(m, p)
    x, _, rank, _ = np.linalg.lstsq(T[:p, :p], T[:p, p:], rcond=rcond)
    return np.asarray(x, dtype=np.float64), int(rank)
