"""The sigmoid of Gaz et al. 2019 (eq. 25), zero at rest: ``phi1`` [N m] the span between
the two saturation levels, ``phi2`` [s/rad] the steepness, ``phi3`` [rad/s] the velocity
offset of the transition (:func:`~dynid.friction.model.sigmoid_friction`).

Fit, per joint: Nelder-Mead (``scipy.optimize.minimize``) on the mean squared residual in
scaled variables ``z = (phi1 / s1, ln(phi2 / s2), phi3 / s3)`` (``phi2`` stays positive),
started from a grid over ``phi2`` and ``phi3`` with ``phi1`` solved in closed form for each
grid point (the law is linear in ``phi1``); deterministic. The law is smooth and zero at
rest, so it needs no standstill band.

MuJoCo holds the odd part of the sigmoid, ``(tau_f(dq) - tau_f(-dq)) / 2``, fitted by
``fc sign(dq) + fv dq`` (bounded least squares on velocities up to ``dq_max``,
:func:`odd_part`); the even part (an offset at large speed) is dropped.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..torques import sigmoid_friction
from .base import FrictionLaw, JointFit, MjcfTerms, canonical_rows, odd_coulomb_viscous

__all__ = ["LAW", "odd_part"]

#: Nelder-Mead iteration limit per joint.
MAXITER = 4000


def _basis(dq: NDArray[np.float64], phi2: float, phi3: float) -> NDArray[np.float64]:
    from scipy.special import expit  # here: a robot holding the law loads no scipy

    out: NDArray[np.float64] = expit(phi2 * (dq + phi3)) - expit(phi2 * phi3)
    return out


def fit_joint(dq: NDArray[np.float64], r: NDArray[np.float64], band: float = 0.0) -> JointFit:
    """(phi1, phi2, phi3) of one joint's (N,) velocity [rad/s] and residual [N m]; ``band``
    is not used (the sigmoid is zero at rest)."""
    scale = float(np.sqrt(np.mean(r**2))) or 1.0
    rs = r / scale
    # start: grid over (phi2, phi3), phi1 by closed-form least squares (on a subsample)
    step = max(1, dq.size // 4000)
    dg, rg = dq[::step], rs[::step]
    best = (np.inf, 1.0, 10.0, 0.0)
    for phi2 in np.geomspace(1.0, 100.0, 15):
        for phi3 in np.linspace(-0.1, 0.1, 9):
            b = _basis(dg, phi2, phi3)
            bb = float(b @ b)
            if bb <= 0:
                continue
            a = float(b @ rg) / bb
            sse = float(np.sum((rg - a * b) ** 2))
            if sse < best[0]:
                best = (sse, a, phi2, phi3)
    _, a0, s2, p30 = best
    s1 = a0 if abs(a0) > 1e-6 else 1.0
    s3 = 0.05

    def cost(z: NDArray[np.float64]) -> float:
        e = rs - z[0] * s1 * _basis(dq, s2 * np.exp(z[1]), z[2] * s3)
        return float(np.mean(e**2))

    import scipy.optimize  # here: a robot holding the law loads no solver

    z0 = np.array([1.0, 0.0, p30 / s3])
    res = scipy.optimize.minimize(
        cost, z0, method="Nelder-Mead", options={"xatol": 1e-7, "fatol": 1e-12, "maxiter": MAXITER}
    )
    z = res.x
    phi = np.array([z[0] * s1 * scale, s2 * np.exp(z[1]), z[2] * s3])
    return JointFit(phi, bool(res.success), int(res.nit))


def odd_part(
    P: NDArray[np.float64], dq_max: NDArray[np.float64], n_points: int = 200
) -> tuple[NDArray[np.float64], ...]:
    """``fc sign(dq) + fv dq`` fitted to the odd part of sigmoids (n, 3) on ``n_points``
    velocities in ``(0, dq_max]`` (n,) [rad/s]: ``(fc, fv, offset, rms)``, each (n,), with
    ``fc, fv >= 0``, ``offset`` the even part at ``dq_max`` [N m] and ``rms`` the fit's RMS
    error [N m] (:func:`~dynid.friction.laws.base.odd_coulomb_viscous` per joint)."""
    fits = []
    for p, vmax in zip(P, dq_max, strict=True):

        def torque(v: NDArray[np.float64], p: NDArray[np.float64] = p) -> NDArray[np.float64]:
            return sigmoid_friction(v, p[0], p[1], p[2])

        fits.append(odd_coulomb_viscous(torque, float(vmax), n_points))
    out = np.array(fits, dtype=np.float64).reshape(-1, 4).T
    return out[0], out[1], out[2], out[3]


def _torques(
    dq: NDArray[np.float64], P: NDArray[np.float64], band: NDArray[np.float64]
) -> NDArray[np.float64]:
    return sigmoid_friction(dq, P[:, 0], P[:, 1], P[:, 2])


def _mjcf(P: NDArray[np.float64], dq_max: NDArray[np.float64]) -> MjcfTerms:
    fc, fv, offset, _ = odd_part(P, dq_max)
    return MjcfTerms(fv, fc, offset, "the even part of the sigmoid (an offset at large speed)")


def _canonical(P: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    return canonical_rows(np.zeros(P.shape[0]), phi1=P[:, 0], phi2=P[:, 1], phi3=P[:, 2])


LAW = FrictionLaw(
    "sigmoid",
    ("phi1", "phi2", "phi3"),
    ("N m", "s/rad", "rad/s"),
    "tau_f = phi1/(1+exp(-phi2 (dq+phi3))) - phi1/(1+exp(-phi2 phi3)) (Gaz et al. 2019, eq. 25)",
    _torques,
    fit_joint,
    (-np.inf, 0.0, -np.inf),
    (np.inf, np.inf, np.inf),
    _mjcf,
    _canonical,
    standstill=False,
)
