"""What every friction law of the registry holds, and the helpers the laws share.

A law (:class:`FrictionLaw`) is a record of plain functions: its name, parameter names
and units, the torques of per-joint parameters, a per-joint fit to a torque residual,
bounds, its MuJoCo mapping and its compiled form in the observer. :class:`Friction`, the
one friction type, is a law with its parameters, standstill band and where it acts.
Linear-in-parameter laws are built from their regressor columns by :func:`linear_law`
(bounded linear least squares); the others give their own fit.

**Standstill.** A Coulomb term switches on with the sign of the velocity, and where a joint
stands still the measured velocity is encoder noise: ``sign(dq)`` of noise would put the
full Coulomb torque on at rest. Every law here uses :func:`coulomb_sign`, which is
``sign(dq)`` where ``|dq|`` exceeds the joint's standstill band ``b`` and 0 inside it, in
fitting and in evaluation alike. The band is the velocity noise band of
:func:`~dynid.identification.velocity_noise.noise_band` (``5 sigma``, ``sigma`` the white-noise std
of the measured velocity, the band inside which a joint counts as still); a model with
``b = 0`` (a noise-free log, or a file without a band) uses the plain ``sign(dq)``
(``sign(0) = 0``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ... import _checks
from ...exceptions import ShapeError
from ...model.drive import Drive
from ..torques import coulomb_sign

__all__ = [
    "CANONICAL_COLUMNS",
    "Friction",
    "FrictionLaw",
    "JointFit",
    "MjcfTerms",
    "bounded_lstsq",
    "canonical_rows",
    "coulomb_sign",
    "linear_law",
    "odd_coulomb_viscous",
]

#: The canonical friction parameters per motor that the observer's compiled step evaluates
#: (:mod:`dynid.observer.friction`, which writes the form out):
#: ``f(v) = fv+ v+ + fv- v- + fc+ [s > 0] - fc- [s < 0] + fo + (fs - fc) exp(-(v/vst)^2) s
#: + ft tanh(v / vs) + phi1 (sigma(phi2 (v + phi3)) - sigma(phi2 phi3)) + fq v |v|``.
CANONICAL_COLUMNS = (
    "fv_pos", "fv_neg", "fc_pos", "fc_neg", "fo", "band", "fs_minus_fc", "vst", "ft", "vs",
    "phi1", "phi2", "phi3", "fq",
)  # fmt: skip


def canonical_rows(band: NDArray[np.float64], **columns: ArrayLike) -> NDArray[np.float64]:
    """Canonical rows (n, 14) with the standstill ``band`` (n,) and the named columns of
    :data:`CANONICAL_COLUMNS` set (each (n,)), the others zero."""
    b = np.asarray(band, dtype=np.float64)
    F = np.zeros((b.shape[0], len(CANONICAL_COLUMNS)))
    F[:, CANONICAL_COLUMNS.index("band")] = b
    for name, value in columns.items():
        F[:, CANONICAL_COLUMNS.index(name)] = value
    return F


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
#: ``canonical(params (n, k), band (n,)) -> (n, 14)`` (:data:`CANONICAL_COLUMNS`).
Canonical = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]


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
        ``mjcf(params (n, k), dq_max (n,))`` -> :class:`MjcfTerms`: what MuJoCo's joints
        (and URDF's ``<dynamics>``) hold of the law, and what they drop.
    canonical : callable or None
        ``canonical(params (n, k), band (n,))`` -> (n, 14): the law in the observer's
        compiled form (:data:`CANONICAL_COLUMNS`); None: the observer evaluates
        ``torques`` in Python.
    standstill : bool
        Whether the law has a standstill band (the sigmoid, smooth and zero at rest, has
        none: its band is always zero and ``friction.json`` writes none).
    band_key : str
        The name of the law's band in files (``friction.json``, ``feasible.json``, the robot
        TOML): ``standstill_band`` where the sign is off inside the band (the standstill
        band of the velocity noise), ``width`` where the sign is ``tanh(dq / width)`` (the
        smooth sign's width, a multiple of that standstill band: ``identify``'s summary
        gives both, ``band`` and ``width``).
    compared : bool
        Whether ``dynid friction`` compares it by default
        (:func:`~dynid.friction.select.select_friction`); a law it fits at a width it
        cannot choose is given by name only.
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
    canonical: Canonical | None = field(repr=False, default=None)
    standstill: bool = True
    compared: bool = True
    band_key: str = "standstill_band"

    def model(
        self, params: ArrayLike, band: ArrayLike | None = None, drive: Drive | None = None
    ) -> Friction:
        """The law with parameters (n, k), standstill band (n,) [rad/s] (default 0) and
        where it acts (``drive``, default the joints): a :class:`Friction`."""
        b = np.zeros(0) if band is None else np.asarray(band, dtype=np.float64)
        return Friction(self, np.asarray(params, dtype=np.float64), b, drive)


@dataclass(frozen=True, slots=True, eq=False)
class Friction:
    """Friction of a robot: a registry law, its parameters, standstill band and where it
    acts; arrays read-only.

    ``tau_f(dq) = f(dq)`` at the joints (``drive`` None, or a drive with
    ``friction_at="joint"``), ``tau_f(dq) = K^T f(K dq)`` at the motors of a drive
    (:mod:`dynid.model.drive`). The law's parameters read by name as attributes
    (``fr.fv``, ``fr.phi1``: column (n,) of ``params``).

    Attributes
    ----------
    law : FrictionLaw
        The registry law (:mod:`dynid.friction.laws`).
    params : ndarray, shape (n, k)
        Parameters per joint (per motor at the motors), columns ``law.params``, in the
        law's units.
    band : ndarray, shape (n,)
        Standstill band [rad/s] (:func:`coulomb_sign`); zeros when not given, and always
        for a law without one (:attr:`FrictionLaw.standstill`).
    drive : Drive or None
        Where the law acts: None (the joints) or a drive, whose ``friction_at`` says the
        motors (velocities and torques at the motor) or the joints.

    Raises
    ------
    ShapeError
        Parameters not (n, k), a band not (n,), a drive of another number of joints.
    """

    law: FrictionLaw
    params: NDArray[np.float64]
    band: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    drive: Drive | None = None

    def __post_init__(self) -> None:
        p = _checks.as_array("params", self.params)
        k = len(self.law.params)
        if p.ndim != 2 or p.shape[1] != k:
            raise ShapeError(
                f"params of the {self.law.name} law must have shape (n, {k}); got {p.shape}"
            )
        n = p.shape[0]
        no_band = np.size(self.band) == 0 or not getattr(self.law, "standstill", True)
        b = np.zeros(n) if no_band else _checks.as_exact("band", self.band, (n,))
        if self.drive is not None:
            self.drive.check(n)
        object.__setattr__(self, "params", _checks.frozen(p))
        object.__setattr__(self, "band", _checks.frozen(b))

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        """Pickle (and copy) through the constructor: the arrays come back read-only."""
        return Friction, (self.law, self.params, self.band, self.drive)

    def __getattr__(self, name: str) -> NDArray[np.float64]:
        """A parameter by name: its column (n,) of ``params``."""
        if name.startswith("_") or name in ("law", "params", "band", "drive"):
            raise AttributeError(name)  # not set yet (copying, unpickling)
        try:
            i = self.law.params.index(name)
        except (ValueError, AttributeError):
            raise AttributeError(
                f"{type(self).__name__} of the {self.law.name} law has no attribute {name!r}"
            ) from None
        return self.params[:, i]

    @property
    def kind(self) -> str:
        """The law's registry name."""
        return self.law.name

    @property
    def names(self) -> tuple[str, ...]:
        """The parameter names."""
        return self.law.params

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.params.shape[0])

    @property
    def at_motors(self) -> bool:
        """Whether the law acts at the motors of a drive (``K^T f(K dq)``)."""
        return self.drive is not None and self.drive.friction_place == "motor"

    @property
    def transmission(self) -> NDArray[np.float64]:
        """``K_f`` (n, n): motor velocities per joint velocity where the law acts (the
        identity at the joints)."""
        if self.drive is None:
            return np.eye(self.n)
        return np.array(self.drive.friction_transmission, dtype=np.float64)

    def as_array(self) -> NDArray[np.float64]:
        """The parameters (n, k) (a copy)."""
        return np.array(self.params)

    def at(self, drive: Drive | None) -> Friction:
        """The same law acting where ``drive`` says (None: at the joints)."""
        return Friction(self.law, self.params, self.band, drive)

    def placed(self, drive: Drive | None) -> Friction:
        """A friction given per joint without a drive (a ``friction.json``, a ground truth
        handed to simulation) where ``drive`` puts it: per motor (``K^T f(K dq)``,
        :meth:`at`) when its friction acts at the motors (:attr:`Drive.friction_place`,
        the place identification fits friction in), else itself. A robot description's
        own friction is placed by :func:`~dynid.friction.model.robot_friction` instead
        (the joints', unless the drive file says ``friction_at = "motor"``)."""
        if drive is None or self.drive is not None or drive.friction_place != "motor":
            return self
        return self.at(drive)

    def torques(self, dq: ArrayLike) -> NDArray[np.float64]:
        """Joint friction torques [N m] (..., n) at joint velocities ``dq`` [rad/s] (..., n)."""
        v = _checks.as_batch("dq", dq, (self.n,))
        if self.drive is None:
            out: NDArray[np.float64] = np.asarray(self.law.torques(v, self.params, self.band))
            return out
        f = np.asarray(self.law.torques(self.drive.motor_velocities(v), self.params, self.band))
        return self.drive.joint_friction(f)


#: ``columns(dq (..., n), band (n,)) -> (..., n, k)``: a linear law's regressor.
Columns = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]


@dataclass(frozen=True, slots=True)
class _LinearTorques:
    """``torques`` of a linear law (a module-level class: the law pickles)."""

    columns: Columns

    def __call__(
        self, dq: NDArray[np.float64], P: NDArray[np.float64], band: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        out: NDArray[np.float64] = np.einsum("...jk,jk->...j", self.columns(dq, band), P)
        return out


@dataclass(frozen=True, slots=True)
class _LinearFit:
    """``fit`` of a linear law: bounded linear least squares on its columns."""

    columns: Columns
    lower: tuple[float, ...]
    upper: tuple[float, ...]

    def __call__(self, dq: NDArray[np.float64], r: NDArray[np.float64], band: float) -> JointFit:
        A = self.columns(dq[:, None], np.array([band]))[:, 0, :]
        lo = np.asarray(self.lower, dtype=np.float64)
        hi = np.asarray(self.upper, dtype=np.float64)
        return JointFit(bounded_lstsq(A, r, lo, hi))


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
        import scipy.optimize  # here: a robot holding a law loads no solver

        x[used] = scipy.optimize.lsq_linear(A[:, used], b, bounds=(lo, hi), method="bvls").x
    return x


def odd_coulomb_viscous(
    torque: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    dq_max: float,
    n_points: int = 200,
) -> tuple[float, float, float, float]:
    """``fc sign(dq) + fv dq`` with ``fc, fv >= 0`` closest (least squares) to the odd part
    ``(torque(dq) - torque(-dq)) / 2`` of one joint's friction on ``n_points`` velocities
    spread evenly over ``(0, dq_max]`` [rad/s]: ``(fc [N m], fv [N m s/rad], offset, rms)``,
    ``offset`` the even part at ``dq_max`` [N m] (what the fit drops at large speed) and
    ``rms`` the fit's RMS error [N m]. ``torque`` maps velocities (k,) to torques (k,)."""
    v = np.linspace(dq_max / n_points, dq_max, n_points)
    up, down = torque(v), torque(-v)
    odd = 0.5 * (up - down)
    A = np.stack([np.ones_like(v), v], axis=1)
    x = bounded_lstsq(A, odd, np.zeros(2), np.full(2, np.inf))
    rms = float(np.sqrt(np.mean((A @ x - odd) ** 2)))
    return float(x[0]), float(x[1]), float(0.5 * (up[-1] + down[-1])), rms


def linear_law(
    name: str,
    params: tuple[str, ...],
    units: tuple[str, ...],
    formula: str,
    columns: Columns,
    lower: tuple[float, ...],
    upper: tuple[float, ...],
    mjcf: Mjcf,
    canonical: Canonical | None = None,
    torques: Torques | None = None,
) -> FrictionLaw:
    """A law linear in its parameters, ``tau_f,j = columns(dq, band)[..., j, :] @ p_j``.

    ``columns(dq (..., n), band (n,))`` gives the regressor (..., n, k); the fit is the
    bounded linear least squares of :func:`bounded_lstsq`; ``canonical`` as in
    :class:`FrictionLaw`; ``torques``, when given, the same torques in closed form (faster
    than the columns' product; default that product).
    """
    tau = _LinearTorques(columns) if torques is None else torques
    fit = _LinearFit(columns, lower, upper)
    return FrictionLaw(name, params, units, formula, tau, fit, lower, upper, mjcf, canonical)
