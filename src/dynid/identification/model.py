"""The identified Lagrangian model: base parameters ``beta`` valid for a robot's kinematics.

.. math:: \\hat\\tau(q, \\dot q, \\ddot q) = Y_b(q, \\dot q, \\ddot q) \\hat\\beta
          \\quad \\text{(Gaz et al. 2019, eq. 23)}

The model is evaluated through an *equivalent robot*: standard parameters equal to
``beta`` at the independent columns and 0 elsewhere map to ``beta`` by the base
projection, so RNEA, ``M``, ``g`` and ``c`` of that (generally non-physical) parameter set
are exactly those of the identified model.

With a drive (:mod:`dynid.model.drive`) whose rotor inertias are identified, the standard
parameters continue after the links' ``10 n`` with ``Ia1 .. Ia_n`` and the equivalent model
adds ``K^T diag(I_a) K`` of its rotor entries to ``M`` (known rotor inertias are added as
given); ``g`` and ``c`` are those of the links.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..dynamics.rnea import rnea
from ..dynamics.terms import coriolis, gravity_torques, mass_matrix
from ..exceptions import ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters
from ..regressors.terms import FRICTION_PARTS, LinearFriction
from .holdout import HeldOut
from .info import IdentificationInfo
from .least_squares import LeastSquaresFit

__all__ = ["IdentifiedModel"]


@dataclass(frozen=True, slots=True, eq=False)
class IdentifiedModel:
    """Identified base parameters with the kinematics they are valid for.

    Attributes
    ----------
    robot : Robot
        Kinematics (and gravity) the coefficients belong to; its inertial parameters
        are not used.
    base : BaseParameters
        Labels, expressions and the map from standard parameters.
    fit : LeastSquaresFit
        Estimates ``fit.beta`` and statistics.
    friction : ndarray, shape (n, 3), optional
        Linear friction ``fv [N m s/rad], fc [N m], fo [N m]`` per joint, identified with
        the classical route; None otherwise.
    info : IdentificationInfo
        What the identification did: route, data, rows used and dropped, estimator,
        standard deviations, filtering (:mod:`dynid.identification.info`).
    drive : Drive, optional
        The drive train the model includes (rotor inertia, friction at the motors); None
        for link-side torques of a direct drive.
    joint_fit : LeastSquaresFit, optional
        Classical route with friction: the fit of every column (the ``r`` base parameters,
        then ``fv, fc, fo`` per joint), whose covariance couples both (consistent
        identification uses it); not saved to files.
    holdout : HeldOut, optional
        Classical route: the normal equations of the contiguous time blocks (or of the
        ``--validate-on`` log) over the columns of ``joint_fit`` (or ``fit``), for held-out
        judgement (:mod:`dynid.identification.holdout`); not saved to files.
    """

    robot: Robot
    base: BaseParameters
    fit: LeastSquaresFit
    friction: NDArray[np.float64] | None = None
    info: IdentificationInfo = field(default_factory=IdentificationInfo)
    joint_fit: LeastSquaresFit | None = None
    drive: Drive | None = None
    holdout: HeldOut | None = None
    equivalent_robot: Robot = field(init=False)
    rotor_inertia: NDArray[np.float64] | None = field(init=False)

    def __post_init__(self) -> None:
        phi = np.zeros(self.base.n_std)
        phi[self.base.independent] = self.fit.beta
        p = 10 * self.robot.n
        object.__setattr__(self, "equivalent_robot", self.robot.with_params(phi[:p]))
        ia = None
        if self.drive is not None:
            self.drive.check(self.robot.n)
            if self.drive.rotor_inertia is not None:
                ia = np.array(self.drive.rotor_inertia)
            elif self.base.n_std == p + self.robot.n:
                ia = phi[p:]
        elif self.base.n_std != p:
            raise ShapeError(
                f"base parameters over {self.base.n_std} standard parameters need a drive "
                f"(the robot's links have {p})"
            )
        object.__setattr__(self, "rotor_inertia", None if ia is None else _checks.frozen(ia))

    def friction_from(self, values: ArrayLike) -> NDArray[np.float64]:
        """The friction coefficients ``values`` (p,) of this model's friction columns
        (``info.friction.labels``, e.g. a held-out fold's fit) as the parameters (n, k) of
        its law, as ``friction`` holds them.

        Raises
        ------
        ShapeError
            The model has no friction columns, or ``values`` another length.
        """
        fr = self.info.friction
        x = np.asarray(values, dtype=np.float64)
        if fr is None or self.friction is None or x.shape != (len(fr.labels),):
            raise ShapeError(
                f"friction values must have the {0 if fr is None else len(fr.labels)} "
                f"coefficients of the model's friction columns; got {x.shape}"
            )
        n = self.friction.shape[0]
        part = {"fv": "viscous", "fc": "smooth" if fr.law == "smooth" else "coulomb"}
        part |= {"fq": "quadratic", "fsp": "stribeck", "fo": "offset"}
        held = []  # (part, joint) of each label: "fo3" -> ("offset", 2)
        for lab in fr.labels:
            prefix = lab.rstrip("0123456789")
            held.append((part[prefix], int(lab[len(prefix) :]) - 1))
        parts = tuple(p for p in FRICTION_PARTS if any(h[0] == p for h in held))
        mask = tuple((p, j) in held for j in range(n) for p in parts)
        term = LinearFriction(
            Drive.identity(n),
            parts=parts,
            width=fr.band if fr.law == "smooth" else (),
            vst=float(np.max(self.friction[:, 3])) if fr.law == "stribeck" else 0.0,
            mask=() if all(mask) else mask,
        )
        return term.as_array(x)

    def links_only(self) -> IdentifiedModel:
        """The model of the links alone: base parameters that are rotor inertias of their own
        (``beta_k = Ia_k``) are removed; a rotor that regroups with link parameters
        (``J1zz + Ia1``) stays in that combination, which the links then carry. ``self`` when
        the model has no rotor parameters. For methods that know only link parameters (the
        penalty method)."""
        p = 10 * self.robot.n
        if self.base.n_std == p:
            return self
        base, fit = self.base, self.fit
        keep = np.flatnonzero(np.asarray(base.independent) < p)
        dep = np.asarray(base.dependent)
        dcols = np.flatnonzero(dep < p)
        sub = BaseParameters(
            std_labels=base.std_labels[:p],
            independent=_checks.frozen(np.asarray(base.independent)[keep]),
            dependent=_checks.frozen(dep[dcols]),
            K_d=_checks.frozen(np.asarray(base.K_d)[np.ix_(keep, dcols)]),
            rank=int(keep.size),
            rtol=base.rtol,
            labels=tuple(base.labels[k] for k in keep),
            expressions=tuple(_without_rotor_terms(base.expressions[k]) for k in keep),
            gap=base.gap,
        )
        cov = None if fit.covariance is None else np.asarray(fit.covariance)[np.ix_(keep, keep)]
        sub_fit = dataclasses.replace(
            fit,
            beta=fit.beta[keep],
            std=fit.std[keep],
            std_percent=fit.std_percent[keep],
            kept=fit.kept[keep],
            rank=int(np.sum(fit.kept[keep])),
            covariance=cov,
        )
        return IdentifiedModel(
            robot=self.robot,
            base=sub,
            fit=sub_fit,
            friction=self.friction,
            info=self.info,
        )

    @property
    def beta(self) -> NDArray[np.float64]:
        """Identified base parameters (r,)."""
        return self.fit.beta

    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]:
        """Identified ``M(q)`` (rotor inertia included): (..., n) -> (..., n, n) [kg m^2]."""
        M = mass_matrix(self.equivalent_robot, q)
        if self.rotor_inertia is not None and self.drive is not None:
            M = M + self.drive.rotor_mass_matrix(self.rotor_inertia)
        return M

    def gravity_torques(self, q: ArrayLike) -> NDArray[np.float64]:
        """Identified ``g(q)`` [N m]: (..., n) -> (..., n)."""
        return gravity_torques(self.equivalent_robot, q)

    def coriolis(self, q: ArrayLike, dq: ArrayLike) -> NDArray[np.float64]:
        """Identified ``c(q, dq)`` [N m]: (..., n) -> (..., n)."""
        return coriolis(self.equivalent_robot, q, dq)

    def torques(self, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike) -> NDArray[np.float64]:
        """Identified ``M ddq + c + g`` [N m] (rotor inertia included), friction not
        included: (..., n)."""
        tau = rnea(self.equivalent_robot, q, dq, ddq)
        if self.rotor_inertia is not None and self.drive is not None:
            a = _checks.as_batch("ddq", ddq, (self.robot.n,))
            tau = tau + self.drive.rotor_torques(a, self.rotor_inertia)
        return tau


def _without_rotor_terms(expression: str) -> str:
    """A base parameter's expression without its ``Ia`` terms (``J1zz + Ia1`` -> ``J1zz``)."""
    terms = expression.replace(" - ", " + -").split(" + ")
    kept = [t for t in terms if not re.fullmatch(r"-?([0-9.e+-]+\*)?Ia\d+", t)]
    return " + ".join(kept).replace(" + -", " - ")
