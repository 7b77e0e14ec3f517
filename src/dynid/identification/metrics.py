"""Error metrics of predicted joint torques against measured ones.

For measured ``tau`` and predicted ``tau_hat`` (N, n) [N m], with ``e = tau - tau_hat``:

* ``rms_j = sqrt(mean_k e_kj^2)`` [N m] and ``mse_j = rms_j^2`` [N^2 m^2] per joint;
* ``relative_error_percent = 100 ||e||_F / ||tau||_F`` over all joints and samples (the
  relative error of Gaz et al. 2019, eq. 22 and Sec. VI);
* ``relative_error_percent_per_joint = 100 ||e_j|| / ||tau_j||``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError

__all__ = [
    "TorqueErrors",
    "mse",
    "noise_floor_percent",
    "relative_error_percent",
    "rms",
    "torque_errors",
]


def _pair(tau: ArrayLike, tau_hat: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    a = _checks.as_array("tau", tau)
    b = _checks.as_array("tau_hat", tau_hat)
    if a.ndim != 2 or a.shape != b.shape or a.shape[0] < 1:
        raise ShapeError(
            f"tau and tau_hat must both have shape (N, n); got {a.shape} and {b.shape}"
        )
    return a, b


#: Rows per block when :func:`torque_errors` sums a long log.
_BLOCK = 65_536


def rms(tau: ArrayLike, tau_hat: ArrayLike) -> NDArray[np.float64]:
    """Root-mean-square error per joint [N m]: (N, n), (N, n) -> (n,)."""
    a, b = _pair(tau, tau_hat)
    return np.sqrt(np.mean((a - b) ** 2, axis=0))


def mse(tau: ArrayLike, tau_hat: ArrayLike) -> NDArray[np.float64]:
    """Mean squared error per joint [N^2 m^2]: (N, n), (N, n) -> (n,)."""
    a, b = _pair(tau, tau_hat)
    return np.mean((a - b) ** 2, axis=0)


def relative_error_percent(tau: ArrayLike, tau_hat: ArrayLike) -> float:
    """``100 ||tau - tau_hat||_F / ||tau||_F`` [%] over all joints and samples."""
    a, b = _pair(tau, tau_hat)
    na = float(np.linalg.norm(a))
    return 100.0 * float(np.linalg.norm(a - b)) / na if na > 0 else float("inf")


@dataclass(frozen=True, slots=True, eq=False)
class TorqueErrors:
    """Per-joint torque errors of a prediction.

    Attributes
    ----------
    rms : ndarray, shape (n,)
        [N m].
    mse : ndarray, shape (n,)
        [N^2 m^2].
    relative_error_percent : float
        Over all joints and samples [%].
    relative_error_percent_per_joint : ndarray, shape (n,)
        [%].
    n_samples : int
    """

    rms: NDArray[np.float64]
    mse: NDArray[np.float64]
    relative_error_percent: float
    relative_error_percent_per_joint: NDArray[np.float64]
    n_samples: int

    def as_dict(self) -> dict[str, object]:
        """JSON-ready dictionary (lists of floats); a relative error that is undefined (the
        measured torque of a joint, or of all, is zero throughout: infinite) is None."""
        return {
            "rms": [float(x) for x in self.rms],
            "mse": [float(x) for x in self.mse],
            "relative_error_percent": _defined(self.relative_error_percent),
            "relative_error_percent_per_joint": [
                _defined(x) for x in self.relative_error_percent_per_joint
            ],
            "n_samples": int(self.n_samples),
        }


def _defined(x: float) -> float | None:
    """``x`` as a float, or None where it is not finite (a percentage of zero)."""
    return float(x) if np.isfinite(x) else None


def torque_errors(tau: ArrayLike, tau_hat: ArrayLike) -> TorqueErrors:
    """All metrics of ``tau_hat`` against ``tau``, both (N, n) [N m].

    Errors beyond the float range are ``inf`` (no warning: the caller says what is far out).

    Raises
    ------
    ShapeError
        Shapes differ or are not (N, n).
    NonFiniteError
        NaN or inf in an input.
    """
    with np.errstate(over="ignore"):
        return _torque_errors(*_pair(tau, tau_hat))


def _torque_errors(a: NDArray[np.float64], b: NDArray[np.float64]) -> TorqueErrors:
    N = a.shape[0]
    if N <= _BLOCK:
        e2 = (a - b) ** 2
        se2, sa2 = e2.sum(axis=0), (a**2).sum(axis=0)
        m = e2.mean(axis=0)
        total = relative_error_percent(a, b)
    else:  # a long log: sums by blocks of rows, temporaries of one block only
        se2, sa2 = np.zeros(a.shape[1]), np.zeros(a.shape[1])
        for k in range(0, N, _BLOCK):
            d = a[k : k + _BLOCK] - b[k : k + _BLOCK]
            se2 += np.einsum("ij,ij->j", d, d)
            sa2 += np.einsum("ij,ij->j", a[k : k + _BLOCK], a[k : k + _BLOCK])
        m = se2 / N
        na_all = float(np.sqrt(sa2.sum()))
        total = 100.0 * float(np.sqrt(se2.sum())) / na_all if na_all > 0 else float("inf")
    na = np.sqrt(sa2)
    with np.errstate(divide="ignore", invalid="ignore"):
        per = np.where(na > 0, 100.0 * np.sqrt(se2) / na, np.inf)
    return TorqueErrors(
        rms=_checks.frozen(np.sqrt(m)),
        mse=_checks.frozen(m),
        relative_error_percent=total,
        relative_error_percent_per_joint=_checks.frozen(per),
        n_samples=a.shape[0],
    )


def noise_floor_percent(
    tau: Sequence[ArrayLike], noise_std: Sequence[ArrayLike], gains: Sequence[float]
) -> float | None:
    """The relative error [%] a perfect model leaves on filtered torques: their noise.

    .. math:: 100 \\sqrt{\\sum_p N_p g_p^2 \\sum_j \\sigma_{pj}^2} \\Big/ \\|\\tau\\|

    over pieces ``p`` of ``N_p`` samples whose raw torques held white noise of std
    ``sigma_pj`` [N m] on joint ``j`` and went through a low-pass of noise gain ``g_p``
    (:func:`~dynid.signals.lowpass_noise_gain`).

    Parameters
    ----------
    tau : sequence of array_like, shape (N_p, n)
        Each piece's filtered torques [N m], the samples used.
    noise_std : sequence of array_like, shape (n,)
        Each piece's raw noise std [N m].
    gains : sequence of float
        Each piece's noise gain.

    Returns
    -------
    float or None
        None for torques of zero norm.
    """
    noise = sum(
        np.shape(t)[0] * g * g * float(np.sum(np.square(s)))
        for t, s, g in zip(tau, noise_std, gains, strict=True)
    )
    norm = sum(float(np.sum(np.square(t))) for t in tau)
    return None if norm == 0.0 else 100.0 * float(np.sqrt(noise / norm))
