"""What every friction law of the registry holds, and the helpers the laws share.

A law (:class:`FrictionLaw`) is a record of plain functions: its name, parameter names
and units, the torques of per-joint parameters, a per-joint fit to a torque residual,
bounds, and its MuJoCo mapping. Linear-in-parameter laws are built from their regressor
columns by :func:`linear_law` (bounded linear least squares); the others give their own
fit.

**Standstill.** A Coulomb term switches on with the sign of the velocity, and where a joint
stands still the measured velocity is encoder noise: ``sign(dq)`` of noise would put the
full Coulomb torque on at rest. Every law here uses :func:`coulomb_sign`, which is
``sign(dq)`` where ``|dq|`` exceeds the joint's standstill band ``b`` and 0 inside it, in
fitting and in evaluation alike. The band is the velocity noise band of
:func:`~dynid.identification.sanity.noise_band` (``5 sigma``, ``sigma`` the white-noise std
of the measured velocity, the band inside which a joint counts as still); a model with
``b = 0`` (a noise-free log, or a file without a band) uses the plain ``sign(dq)``
(``sign(0) = 0``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.optimize
from numpy.typing import ArrayLike, NDArray

from ...exceptions import ShapeError
from ..model import LawFriction, coulomb_sign

__all__ = [
    "FrictionLaw",
    "JointFit",
    "LawFriction",
    "MjcfTerms",
    "bounded_lstsq",
    "coulomb_sign",
    "linear_law",
]


@dataclass(frozen=True, slots=True)
class JointFit:
    """One joint's fitted parameters (k,), optimiser success and iterations."""

    params: NDArray[np.float64]
    converged: bool = True
    iterations: int = 0


@dataclass(frozen=True, slots=True)
class MjcfTerms:
    """What MuJoCo's joints hold of a law: ``damping`` [N m s/rad] and ``frictionloss``
    [N m] per joint (n,), the velocity-independent torque ``offset`` [N m] (n,) it drops
    (reported by the export), and ``dropped``: one line naming what else MJCF cannot hold
    (empty: nothing)."""

    damping: NDArray[np.float64]
    frictionloss: NDArray[np.float64]
    offset: NDArray[np.float64]
    dropped: str = ""


#: ``torques(dq (..., n), params (n, k), band (n,)) -> (..., n)`` [N m].
Torques = Callable[[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]], Any]
#: ``fit(dq (N,), residual (N,), band) -> JointFit`` for one joint.
Fit = Callable[[NDArray[np.float64], NDArray[np.float64], float], JointFit]
#: ``mjcf(params (n, k), dq_max (n,)) -> MjcfTerms``.
Mjcf = Callable[[NDArray[np.float64], NDArray[np.float64]], MjcfTerms]
#: ``make(params (n, k), band (n,) or None) -> FrictionModel``.
Make = Callable[[NDArray[np.float64], Any], Any]


@dataclass(frozen=True, slots=True)
class FrictionLaw:
    """A friction law of the registry (:mod:`dynid.friction.laws`).

    Attributes
    ----------
    name : str
        Registry name, ``friction.json``'s ``model`` and ``--friction-model``'s choice.
    params : tuple of str
        Parameter names per joint (the keys of ``friction.json``'s joints).
    units : tuple of str
        Their units.
    formula : str
        ``tau_f(dq)`` written out (``friction.json``'s ``convention``).
    torques : callable
        ``torques(dq (..., n), params (n, k), band (n,))`` [N m] (..., n).
    fit : callable
        ``fit(dq (N,), residual (N,), band)`` -> :class:`JointFit`, deterministic.
    lower, upper : tuple of float
        Bounds of each parameter in the fit.
    mjcf : callable
        ``mjcf(params (n, k), dq_max (n,))`` -> :class:`MjcfTerms`.
    make : callable, optional
        ``make(params (n, k), band)``: the law's own model class; default
        :class:`~dynid.friction.model.LawFriction`.
    """

    name: str
    params: tuple[str, ...]
    units: tuple[str, ...]
    formula: str
    torques: Torques
    fit: Fit
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    mjcf: Mjcf = field(repr=False)
    make: Make | None = field(repr=False, default=None)

    def model(self, params: ArrayLike, band: ArrayLike | None = None) -> Any:
        """The law with parameters (n, k) and standstill band (n,) [rad/s] (default 0):
        ``make(params, band)`` when the law has its own class (the classical and sigmoid
        laws, :mod:`dynid.friction.model`), else a :class:`LawFriction`."""
        if self.make is not None:
            return self.make(_as_params(self, params), band)
        p = _as_params(self, params)
        if band is None:
            return LawFriction(self, p)
        return LawFriction(self, p, np.asarray(band, dtype=np.float64))


def _as_params(law: FrictionLaw, params: ArrayLike) -> NDArray[np.float64]:
    p = np.asarray(params, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != len(law.params):
        raise ShapeError(
            f"params of the {law.name} law must have shape (n, {len(law.params)}); got {p.shape}"
        )
    return p


def _columns_fit(
    columns: Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]],
    lower: tuple[float, ...],
    upper: tuple[float, ...],
) -> Fit:
    lo, hi = np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64)

    def fit(dq: NDArray[np.float64], r: NDArray[np.float64], band: float) -> JointFit:
        A = columns(dq[:, None], np.array([band]))[:, 0, :]
        return JointFit(bounded_lstsq(A, r, lo, hi))

    return fit


def bounded_lstsq(
    A: NDArray[np.float64],
    b: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
) -> NDArray[np.float64]:
    """``argmin ||A x - b||`` with ``lower <= x <= upper`` (bounded-variable least squares,
    deterministic); (k,). Columns that are zero throughout get 0."""
    used = np.any(A != 0, axis=0)
    x = np.zeros(A.shape[1])
    if not used.any():
        return x
    lo, hi = lower[used], upper[used]
    free = np.linalg.lstsq(A[:, used], b, rcond=None)[0]
    if np.all((free >= lo) & (free <= hi)):
        x[used] = free  # the unconstrained minimum is feasible: it is the bounded one
    else:
        x[used] = scipy.optimize.lsq_linear(A[:, used], b, bounds=(lo, hi), method="bvls").x
    return x


def linear_law(
    name: str,
    params: tuple[str, ...],
    units: tuple[str, ...],
    formula: str,
    columns: Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]],
    lower: tuple[float, ...],
    upper: tuple[float, ...],
    mjcf: Mjcf,
    *,
    make: Make | None = None,
) -> FrictionLaw:
    """A law linear in its parameters, ``tau_f,j = columns(dq, band)[..., j, :] @ p_j``.

    ``columns(dq (..., n), band (n,))`` gives the regressor (..., n, k); the fit is the
    bounded linear least squares of :func:`bounded_lstsq`; ``make`` as in
    :class:`FrictionLaw`.
    """

    def torques(
        dq: NDArray[np.float64], P: NDArray[np.float64], band: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        out: NDArray[np.float64] = np.einsum("...jk,jk->...j", columns(dq, band), P)
        return out

    fit = _columns_fit(columns, lower, upper)
    return FrictionLaw(name, params, units, formula, torques, fit, lower, upper, mjcf, make)
