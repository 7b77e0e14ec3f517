"""The closed-form friction torques the laws are built from: the sign outside a standstill
band, the sigmoid of Gaz et al. 2019 (eq. 25) and the classical law (eq. 24).

Sign convention (:mod:`dynid.friction.model`): ``tau_f`` is the part of the measured joint
torque spent on friction, of the sign of the velocity for a dissipative joint. Each function
evaluates on velocities of shape ``(..., n)`` and returns torques of the same shape.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks

__all__ = ["classical_friction", "coulomb_sign", "sigmoid_friction"]


def coulomb_sign(dq: ArrayLike, band: ArrayLike = 0.0) -> NDArray[np.float64]:
    """``sign(dq)`` outside the standstill band, 0 inside: (..., n).

    Parameters
    ----------
    dq : array_like, shape (..., n)
        Velocities [rad/s].
    band : array_like, shape (n,) or scalar
        Standstill band per joint [rad/s]; 0 gives the plain ``sign(dq)`` (``sign(0) = 0``).

    Returns
    -------
    ndarray, shape (..., n)
    """
    v = np.asarray(dq, dtype=np.float64)
    out: NDArray[np.float64] = np.where(
        np.abs(v) > np.asarray(band, dtype=np.float64), np.sign(v), 0.0
    )
    return out


def sigmoid_friction(
    dq: ArrayLike, phi1: ArrayLike, phi2: ArrayLike, phi3: ArrayLike
) -> NDArray[np.float64]:
    """Sigmoid friction torques (Gaz et al. 2019, eq. 25).

    Parameters
    ----------
    dq : array_like, shape (..., n)
        Joint velocities [rad/s].
    phi1, phi2, phi3 : array_like, shape (n,)
        Span [N m], steepness [s/rad] and velocity offset [rad/s] per joint (broadcast
        against ``dq``).

    Returns
    -------
    tau_f : ndarray, shape (..., n)
        Friction torques [N m], zero at ``dq = 0``.
    """
    from scipy.special import expit  # here: importing scipy.special costs 0.15 s

    dq = _checks.as_array("dq", dq)
    phi1, phi2, phi3 = (np.asarray(p, dtype=np.float64) for p in (phi1, phi2, phi3))
    return phi1 * (expit(phi2 * (dq + phi3)) - expit(phi2 * phi3))


def classical_friction(
    dq: ArrayLike, fv: ArrayLike, fc: ArrayLike, fo: ArrayLike, band: ArrayLike = 0.0
) -> NDArray[np.float64]:
    """Viscous + Coulomb + offset friction torques (Gaz et al. 2019, eq. 24).

    Parameters
    ----------
    dq : array_like, shape (..., n)
        Joint velocities [rad/s].
    fv, fc, fo : array_like, shape (n,)
        Viscous [N m s/rad], Coulomb [N m] and offset [N m] coefficients.
    band : array_like, shape (n,) or scalar
        Standstill band [rad/s] of the Coulomb term (:func:`coulomb_sign`); default 0.

    Returns
    -------
    tau_f : ndarray, shape (..., n)
        ``fv dq + fc sign(dq) + fo`` [N m].
    """
    dq = _checks.as_array("dq", dq)
    fv, fc, fo = (np.asarray(p, dtype=np.float64) for p in (fv, fc, fo))
    return fv * dq + fc * coulomb_sign(dq, band) + fo
