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
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..dynamics.rnea import rnea
from ..dynamics.terms import coriolis, gravity_torques, mass_matrix
from ..exceptions import ModelError, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from ..model.stiffness import JointStiffness
from ..regressors.base import BaseParameters
from ..regressors.terms import FrictionValues, ModelTerm, RotorInertia
from .holdout import HeldOut
from .info import IdentificationInfo
from .least_squares import LeastSquaresFit

__all__ = ["IdentifiedModel", "IdentifiedTerm"]


@dataclass(frozen=True, slots=True, eq=False)
class IdentifiedTerm:
    """A model term (:mod:`dynid.regressors.terms`) with its identified coefficients.

    Attributes
    ----------
    term : ModelTerm
        What the coefficients are (labels, units, columns; friction or rotor inertias).
    values : ndarray, shape (p,)
        The coefficients, in the units of ``term.units`` (0 where not kept). For a term in
        the base (a rotor inertia): the equivalent standard parameters, whose regrouped
        entries are carried by their base combination (``J1zz + Ia1``) and are 0 here.
    std : ndarray, shape (p,)
        Their standard deviations (NaN for a term in the base's regrouped entries).
    kept : ndarray of bool, shape (p,)
        False for coefficients left out (a joint that never moves), pruned or regrouped.
    """

    term: ModelTerm
    values: NDArray[np.float64]
    std: NDArray[np.float64]
    kept: NDArray[np.bool_]

    def __post_init__(self) -> None:
        p = len(self.term.labels)
        for key in ("values", "std", "kept"):
            a = np.asarray(getattr(self, key), dtype=bool if key == "kept" else np.float64)
            if a.shape != (p,):
                raise ShapeError(
                    f"term {self.term.name!r}: {key} must have its {p} coefficients; got {a.shape}"
                )
            object.__setattr__(self, key, _checks.frozen(a))

    @property
    def labels(self) -> tuple[str, ...]:
        """The term's labels."""
        return self.term.labels

    @property
    def regrouped(self) -> NDArray[np.bool_]:
        """(p,): the coefficients the data give only in a base combination with link
        inertias (a term in the base: ``J1zz + J2yy + Ia1``), not on their own (no standard
        deviation of their own); what splits such a sum is a prior, not the data."""
        out: NDArray[np.bool_] = (
            np.zeros(self.kept.shape, dtype=bool)
            if not self.term.in_base
            else ~self.kept & ~np.isfinite(self.std)
        )
        return out

    @property
    def friction(self) -> FrictionValues | None:
        """The term as a friction law's parameters (None: not friction)."""
        return self.term.friction(self.values)

    @property
    def inertia(self) -> NDArray[np.float64] | None:
        """The term as rotor inertias [kg m^2] (None: not rotor inertias)."""
        return self.term.inertia(self.values)

    @property
    def stiffness(self) -> JointStiffness | None:
        """The term as joint springs (None: not a spring)."""
        return self.term.stiffness(self.values)

    def torques(self, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike) -> NDArray[np.float64]:
        """The term's joint torques [N m] (..., n) at joint states (..., n)."""
        a = [np.asarray(x, dtype=np.float64) for x in (q, dq, ddq)]
        Y = self.term.torque_columns(a[0], a[1], a[2])
        out: NDArray[np.float64] = Y @ self.values
        return out

    def with_values(self, values: ArrayLike) -> IdentifiedTerm:
        """The same term with other coefficients (p,) (a held-out fold's fit)."""
        return dataclasses.replace(self, values=np.asarray(values, dtype=np.float64))


def _terms_mapping(terms: Mapping[str, IdentifiedTerm]) -> Mapping[str, IdentifiedTerm]:
    """A read-only copy, keys checked against the terms' names."""
    for key, t in terms.items():
        if key != t.term.name:
            raise ShapeError(f"terms: key {key!r} holds the term named {t.term.name!r}")
    return _checks.frozen_mapping(dict(terms))


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
    terms : mapping of str to IdentifiedTerm
        The model terms beside the links (:mod:`dynid.regressors.terms`), by name, in the
        order stacked: those in the base (rotor inertias; their values the equivalent
        standard parameters, derived from ``fit`` here), then those appended after the
        base parameters (friction), with their coefficients. A drive that identifies
        rotor inertias over a base that holds them gets its rotor term when none is given
        (a model built by hand, an older file).
    info : IdentificationInfo
        What the identification did: route, data, rows used and dropped, estimator,
        standard deviations, filtering (:mod:`dynid.identification.info`).
    drive : Drive, optional
        The drive train the model includes (rotor inertia, friction at the motors); None
        for link-side torques of a direct drive.
    joint_fit : LeastSquaresFit, optional
        With appended terms: the fit of every column (the ``r`` base parameters, then the
        appended terms' coefficients in order), whose covariance couples both (consistent
        identification uses it); not saved to files.
    holdout : HeldOut, optional
        Classical route: the normal equations of the contiguous time blocks (or of the
        ``--validate-on`` log) over the columns of ``joint_fit`` (or ``fit``), for held-out
        judgement (:mod:`dynid.identification.holdout`); not saved to files.
    description_phi : ndarray, shape (n, 10), optional
        The link inertials of the description identified with (m [kg], mc [kg m], J
        [kg m^2] about the link origin), kept apart from ``robot`` by a model read from a
        file (whose robot holds the kinematics only): the prior a consistent fit from the
        model starts from (:attr:`description`). None: ``robot``'s own.
    recorded_covariance : ndarray, shape (c, c), optional
        With appended terms, the covariance of every coefficient (the ``r`` base
        parameters, then the appended terms' in order) as ``identification.json`` records
        it, for a model read from a file, which holds no ``joint_fit``
        (:meth:`coefficient_covariance`). None: not recorded.
    """

    robot: Robot
    base: BaseParameters
    fit: LeastSquaresFit
    terms: Mapping[str, IdentifiedTerm] = field(default_factory=dict)
    info: IdentificationInfo = field(default_factory=IdentificationInfo)
    joint_fit: LeastSquaresFit | None = None
    drive: Drive | None = None
    holdout: HeldOut | None = None
    description_phi: NDArray[np.float64] | None = None
    recorded_covariance: NDArray[np.float64] | None = None
    equivalent_robot: Robot = field(init=False)
    rotor_inertia: NDArray[np.float64] | None = field(init=False)
    _other: tuple[IdentifiedTerm, ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        phi = np.zeros(self.base.n_std)
        phi[self.base.independent] = self.fit.beta
        p = 10 * self.robot.n
        object.__setattr__(self, "equivalent_robot", self.robot.with_params(phi[:p]))
        if self.drive is not None:
            self.drive.check(self.robot.n)
        terms = dict(self.terms)
        given = [t.term for t in terms.values() if t.term.in_base]
        if not given and self.base.n_std == p + self.robot.n:
            if self.drive is None or not self.drive.identifies_rotor_inertia:
                raise ShapeError(
                    f"base parameters over {self.base.n_std} standard parameters need a drive "
                    f"that identifies rotor inertias (the robot's links have {p})"
                )
            given = [RotorInertia(self.drive)]
        if p + sum(len(t.labels) for t in given) != self.base.n_std:
            raise ShapeError(
                f"base parameters over {self.base.n_std} standard parameters need terms in the "
                f"base for those beyond the robot's links ({p})"
            )
        in_base = self._in_base(given, phi)
        appended = {k: t for k, t in terms.items() if not t.term.in_base}
        object.__setattr__(self, "terms", _terms_mapping(in_base | appended))
        ia = None
        if self.drive is not None and self.drive.rotor_inertia is not None:
            ia = np.array(self.drive.rotor_inertia)
        else:
            found = [x for x in (t.inertia for t in self.terms.values()) if x is not None]
            ia = found[0] if found else None
        object.__setattr__(self, "rotor_inertia", None if ia is None else _checks.frozen(ia))
        other = tuple(t for t in self.appended if t.friction is None)
        object.__setattr__(self, "_other", other)

    def _in_base(
        self, terms: list[ModelTerm], phi: NDArray[np.float64]
    ) -> dict[str, IdentifiedTerm]:
        """The terms in the base with their equivalent standard parameters (``phi``), the
        standard deviation and kept flag of the base parameter where one is its own."""
        ind = list(np.asarray(self.base.independent))
        out, start = {}, 10 * self.robot.n
        for t in terms:
            k = len(t.labels)
            std, kept = np.full(k, np.nan), np.zeros(k, dtype=bool)
            for i in range(k):
                if start + i in ind:
                    j = ind.index(start + i)
                    std[i], kept[i] = self.fit.std[j], bool(self.fit.kept[j])
            out[t.name] = IdentifiedTerm(t, phi[start : start + k], std, kept)
            start += k
        return out

    def regrouped_in(self, name: str) -> tuple[str, ...]:
        """Per coefficient of the term ``name``: the base parameters that hold it where it
        is regrouped with link inertias (``"beta1"`` for ``Ia1`` in ``beta1 = J1zz + ... +
        Ia1``; several joined by ``+``), ``""`` where it is not (its own base parameter,
        left out, or a term outside the base)."""
        t = self.terms[name]
        if not t.term.in_base:
            return ("",) * len(t.labels)
        start = 10 * self.robot.n
        for other in self.terms.values():
            if other.term.name == name:
                break
            if other.term.in_base:
                start += len(other.labels)
        return tuple(
            "+".join(self.base.holding(self.base.std_labels[start + i])) if regrouped else ""
            for i, regrouped in enumerate(t.regrouped)
        )

    @property
    def description(self) -> Robot:
        """``robot`` with the description's link inertials (:attr:`description_phi`, or
        its own): the default prior of a consistent fit from the model."""
        if self.description_phi is None:
            return self.robot
        return self.robot.with_params(self.description_phi)

    @property
    def appended(self) -> tuple[IdentifiedTerm, ...]:
        """The terms whose coefficients follow the base parameters (``joint_fit``'s
        columns after ``r``), in order."""
        return tuple(t for t in self.terms.values() if not t.term.in_base)

    @property
    def frictions(self) -> tuple[FrictionValues, ...]:
        """Every friction term's law and parameters, in order (a view of :attr:`terms`):
        one, or two for friction at the motors and at the joints of a coupled drive."""
        return tuple(f for f in (t.friction for t in self.terms.values()) if f is not None)

    @property
    def spring(self) -> JointStiffness | None:
        """The spring term's stiffnesses about its rest positions (a view of :attr:`terms`);
        None without one.

        Raises
        ------
        ModelError
            The model holds several spring terms.
        """
        found = [s for s in (t.stiffness for t in self.terms.values()) if s is not None]
        if len(found) > 1:
            raise ModelError(f"the model holds {len(found)} spring terms; one is expected")
        return found[0] if found else None

    @property
    def friction(self) -> FrictionValues | None:
        """The friction term's law and parameters (a read-only view of :attr:`terms`;
        ``dynid.friction.model.friction_of`` makes the friction type of it); None without
        friction.

        Raises
        ------
        ModelError
            The model holds several friction terms (:attr:`frictions`).
        """
        fr = self.frictions
        if len(fr) > 1:
            raise ModelError(
                f"the model holds {len(fr)} friction terms (at the motors and at the joints); "
                "take them all from frictions"
            )
        return fr[0] if fr else None

    def with_coefficients(self, x: ArrayLike) -> IdentifiedModel:
        """The same model with every coefficient replaced: ``x`` (c,) holds the base
        parameters then the appended terms' coefficients in order (a held-out fold's fit
        over ``joint_fit``'s columns).

        Raises
        ------
        ShapeError
            ``x`` of another length.
        """
        v = np.asarray(x, dtype=np.float64)
        r = self.base.rank
        sizes = [len(t.labels) for t in self.appended]
        if v.shape != (r + sum(sizes),):
            raise ShapeError(
                f"coefficients must be the {r} base parameters and the {sum(sizes)} of the "
                f"appended terms; got {v.shape}"
            )
        terms, c = dict(self.terms), r
        for t, k in zip(self.appended, sizes, strict=True):
            terms[t.term.name] = t.with_values(v[c : c + k])
            c += k
        fit = dataclasses.replace(self.fit, beta=_checks.frozen(v[:r]))
        return dataclasses.replace(
            self, fit=fit, terms=terms, joint_fit=None, holdout=None, recorded_covariance=None
        )

    def coefficient_covariance(self) -> NDArray[np.float64] | None:
        """The covariance (c, c) of every coefficient, in the units of each pair: the ``r``
        base parameters, then the appended terms' in order (the columns of
        :func:`~dynid.identification.log_rows.term_regressor`): ``joint_fit``'s, else the
        one a file recorded (:attr:`recorded_covariance`), else ``fit``'s where no term is
        appended; None where it is not known (a file written before it was recorded)."""
        width = self.base.rank + sum(len(t.labels) for t in self.appended)
        for fit in (self.joint_fit, self.fit):
            cov = None if fit is None else fit.covariance
            if cov is not None and np.shape(cov) == (width, width):
                return np.asarray(cov, dtype=np.float64)
        cov = self.recorded_covariance
        if cov is not None and np.shape(cov) == (width, width):
            return np.asarray(cov, dtype=np.float64)
        return None

    def links_only(self) -> IdentifiedModel:
        """The model of the links alone: base parameters that are parameters of the terms
        in the base of their own (``beta_k = Ia_k``) are removed; a rotor that regroups with
        link parameters (``J1zz + Ia1``) stays in that combination, which the links then
        carry. ``self`` when the model has no terms in the base. For methods that know only
        link parameters (the penalty method)."""
        p = 10 * self.robot.n
        if self.base.n_std == p:
            return self
        own = {lab for t in self.terms.values() if t.term.in_base for lab in t.labels}
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
            expressions=tuple(_without_symbols(base.expressions[k], own) for k in keep),
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
            terms={k: t for k, t in self.terms.items() if not t.term.in_base},
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
        """Identified ``M ddq + c + g`` [N m] (rotor inertia included) and the appended
        terms that are not friction (a spring), friction not included (it comes with
        ``dynid.friction.validation.own_friction``): (..., n)."""
        tau = rnea(self.equivalent_robot, q, dq, ddq)
        if self.rotor_inertia is not None and self.drive is not None:
            a = _checks.as_batch("ddq", ddq, (self.robot.n,))
            tau = tau + self.drive.rotor_torques(a, self.rotor_inertia)
        for t in self._other:
            tau = tau + t.torques(q, dq, ddq)
        return tau


def _without_symbols(expression: str, symbols: set[str]) -> str:
    """A base parameter's expression without its terms in ``symbols`` (``J1zz + Ia1`` ->
    ``J1zz`` for ``{"Ia1"}``; a term is ``[-][coefficient*]symbol``)."""
    terms = expression.replace(" - ", " + -").split(" + ")
    kept = [t for t in terms if t.lstrip("-").rpartition("*")[2] not in symbols]
    return " + ".join(kept).replace(" + -", " - ")


def checked_model(model: object, name: str = "model") -> IdentifiedModel | Robot:
    """``model`` when it is an :class:`IdentifiedModel` or a :class:`Robot` (its own link
    parameters): the check of an entry point's model argument.

    Raises
    ------
    WrongTypeError
        Neither (``"model: expected an IdentifiedModel (...) or a Robot, got str"``).
    """
    out: IdentifiedModel | Robot = _checks.of_type(
        name, model, (IdentifiedModel, Robot), MODEL_EXPECTED
    )
    return out


def kinematics_of(model: object, name: str = "model") -> Robot:
    """The robot of an entry point's ``model`` argument (:func:`checked_model`): an
    identified model's, or the robot itself.

    Raises
    ------
    WrongTypeError
        Neither an :class:`IdentifiedModel` nor a :class:`Robot`.
    """
    checked = checked_model(model, name)
    return checked.robot if isinstance(checked, IdentifiedModel) else checked


#: How a message says what a model argument must be.
MODEL_EXPECTED = "an IdentifiedModel (dynid.io.model_json.load_model_json(path)) or a Robot"
