"""Physical feasibility of link inertial parameters, with margins, and the parameter bounds.

Each link ``i`` of a robot carries a mass ``m_i`` [kg], a centre of mass ``c_i`` [m] in the
link frame and an inertia tensor ``I_i`` [kg m^2] **about the CoM**, in link-frame axes
(:mod:`dynid.model.inertia` holds the same body as the standard parameters ``phi``, with
``J`` about the link origin). The body is physically realisable (Gaz et al. 2019,
Sec. V, eqs. 14-16; Traversaro et al. 2016; Drake's ``IsPhysicallyValid``) when

* ``m_i > 0``;
* ``I_i`` is positive definite: its smallest principal moment ``lambda_min(I_i) > 0``;
* the principal moments satisfy the triangle inequality (eq. 16)

  .. math:: \\frac{\\mathrm{tr}(I_i)}{2} - \\lambda_{max}(I_i) > 0

  (equivalently ``lambda_1 + lambda_2 > lambda_3``; it implies positive definiteness).

Retrieval (:mod:`dynid.feasibility.penalty`) adds the search box of every parameter
(:class:`~dynid.feasibility.bounds.Bounds`: mass, CoM box, inertia entries) and a band on
the total mass, and users may add constraints of their own (:class:`UserConstraint`).

Every constraint is reported with a **margin**, positive inside the feasible set, zero on
its boundary, negative outside; its unit is the constraint's (kg, m or kg m^2). A
constraint is *satisfied* when its margin is ``>= -tol * scale`` (limiting bodies such as
a thin rod, a lamina or a point mass are valid, as in Drake), except the mass, which
must be strictly positive. Identified parameters can be infeasible: they are held and
reported, never rejected (:func:`feasibility_report`, :func:`is_physically_valid`).

Decision-variable layout (the parameters the retrieval searches, per link, link-major)::

    p_i = [m, cx, cy, cz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz]     (inertia about the CoM)

named by :func:`decision_labels` (``m1, c1x, ..., I1xx, ...``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError, WrongTypeError
from ..model.inertia import (
    inertial_from_phi,
    matrix_from_inertia6,
    params_from_inertial,
)
from ..model.robot import Robot
from .bounds import Bounds

__all__ = [
    "Constraint",
    "FeasibilityReport",
    "UserConstraint",
    "feasibility_report",
    "link_params",
    "principal_moments",
    "user_constraints",
    "is_physically_valid",
]


#: Default relative tolerance of :func:`feasibility_report` (see the module docstring).
DEFAULT_TOL = 1e-9


def link_params(robot_or_params: Any) -> NDArray[np.float64]:
    """Decision parameters ``p`` (n, 10) of a robot or a parameter set.

    Parameters
    ----------
    robot_or_params : Robot, array_like or tuple
        A :class:`~dynid.model.robot.Robot` (its ``phi``); standard parameters ``phi``
        of shape (n, 10) or (10 n,) (inertia about the link origin); or a tuple
        ``(mass (n,), com (n, 3), inertia about the CoM (n, 3, 3) or (n, 6))``. Any object
        with a ``robot`` attribute (a retrieval result) gives its robot's parameters.

    Returns
    -------
    p : ndarray, shape (n, 10)
        ``[m, cx, cy, cz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz]`` per link, inertia about the CoM.
        A link of zero mass has its CoM at the origin.
    """
    obj = robot_or_params
    if not isinstance(obj, Robot) and isinstance(getattr(obj, "robot", None), Robot):
        obj = obj.robot
    if isinstance(obj, Robot):
        phi = obj.phi
    elif isinstance(obj, tuple) and len(obj) == 3:
        return params_from_inertial(*obj)
    else:
        phi = _checks.as_array("phi", obj)
        if phi.ndim == 1 and phi.size % 10 == 0:
            phi = phi.reshape(-1, 10)
        if phi.ndim != 2 or phi.shape[1] != 10:
            raise ShapeError(f"phi must have shape (n, 10) or (10 n,); got {phi.shape}")
    m, c, I = inertial_from_phi(phi)
    return params_from_inertial(m, c, I)


# ---------------------------------------------------------------------- user constraints
@dataclass(frozen=True, slots=True, eq=False)
class UserConstraint:
    """A constraint of the user's on the link parameters.

    Attributes
    ----------
    name : str
        Name in reports.
    violation : callable
        ``violation(p) -> float``: ``p`` the decision parameters, shape (n, 10)
        (:data:`DECISION_FIELDS` per link, inertia about the CoM); returns how far the
        constraint is violated, ``>= 0``, and 0 when it holds (a distance, in a unit of
        the user's choice: it is added to the penalty as it is, see
        :mod:`dynid.feasibility.penalty`). It must be a pure function; to run the
        retrieval in several processes it must also pickle (a module-level function, or
        an instance of a module-level class).
    link : int or None
        The link (1-based) it concerns, for reports.
    """

    name: str
    violation: Callable[[NDArray[np.float64]], float]
    link: int | None = None


def user_constraints(extra: Sequence[Any]) -> tuple[UserConstraint, ...]:
    """Normalise ``extra``: UserConstraint items, callables (named after ``__name__``) or
    ``(name, callable)`` pairs."""
    out = []
    for k, e in enumerate(extra):
        if isinstance(e, UserConstraint):
            out.append(e)
        elif isinstance(e, tuple) and len(e) == 2 and callable(e[1]):
            out.append(UserConstraint(str(e[0]), e[1]))
        elif callable(e):
            name = getattr(e, "__name__", None) or type(e).__name__
            out.append(UserConstraint(str(name) if name != "<lambda>" else f"user{k + 1}", e))
        else:
            raise WrongTypeError(
                f"extra[{k}] must be a UserConstraint, a callable p -> violation or a "
                f"(name, callable) pair; got {type(e).__name__}"
            )
    return tuple(out)


# ---------------------------------------------------------------------------- report
@dataclass(frozen=True, slots=True)
class Constraint:
    """One evaluated constraint.

    Attributes
    ----------
    name : str
        ``mass_positive``, ``inertia_positive_definite``, ``triangle_inequality``,
        ``mass_in_bounds``, ``com_in_box``, ``inertia_in_bounds``, ``total_mass_min``,
        ``total_mass_max``, a user constraint's name, or ``data_fit`` (added by the
        retrieval: the data are reproduced within a relative tolerance).
    link : int or None
        Link (1-based), or None for a constraint on the whole robot.
    margin : float
        Signed distance to the constraint's boundary, positive inside [``unit``].
    unit : str
    satisfied : bool
    """

    name: str
    link: int | None
    margin: float
    unit: str
    satisfied: bool


@dataclass(frozen=True, slots=True)
class FeasibilityReport:
    """Every constraint with its margin (:func:`feasibility_report`).

    Attributes
    ----------
    constraints : tuple of Constraint
        Per link in link order (physical constraints, then bounds), then the robot-wide
        ones (total mass), then the user's.
    tol : float
        Relative tolerance used for ``satisfied``.
    """

    constraints: tuple[Constraint, ...]
    tol: float = DEFAULT_TOL

    @property
    def ok(self) -> bool:
        """True when every constraint is satisfied."""
        return all(c.satisfied for c in self.constraints)

    @property
    def violated(self) -> tuple[Constraint, ...]:
        """The constraints not satisfied."""
        return tuple(c for c in self.constraints if not c.satisfied)

    def select(self, name: str) -> tuple[Constraint, ...]:
        """The constraints called ``name``."""
        return tuple(c for c in self.constraints if c.name == name)

    def min_margin(self, name: str | None = None) -> float:
        """Smallest margin, over all constraints or those called ``name`` (inf if none).

        Margins of different constraints have different units; compare within a name.
        """
        ms = [c.margin for c in self.constraints if name is None or c.name == name]
        return float(min(ms)) if ms else math.inf

    @property
    def names(self) -> tuple[str, ...]:
        """Distinct constraint names, in order of first appearance."""
        return tuple(dict.fromkeys(c.name for c in self.constraints))

    def __str__(self) -> str:
        bad = self.violated
        if not bad:
            return f"feasible: {len(self.constraints)} constraints satisfied"
        parts = [
            f"{c.name}" + (f" (link {c.link})" if c.link else "") + f" by {-c.margin:.3g} {c.unit}"
            for c in bad
        ]
        return (
            f"infeasible: {len(bad)} of {len(self.constraints)} constraints violated: "
            + "; ".join(parts)
        )


def principal_moments(inertia: ArrayLike) -> NDArray[np.float64]:
    """Principal moments [kg m^2], ascending, of inertia tensors (..., 3, 3) -> (..., 3)."""
    I = _checks.as_batch("inertia", inertia, (3, 3))
    return np.asarray(np.linalg.eigvalsh(0.5 * (I + np.swapaxes(I, -1, -2))), dtype=np.float64)


def feasibility_report(
    robot_or_params: Any,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    extra: Sequence[Any] = (),
    *,
    tol: float = DEFAULT_TOL,
) -> FeasibilityReport:
    """Evaluate every feasibility constraint of a parameter set, with its margin.

    .. math::
        m_i > 0, \\quad \\lambda_{min}(I_i) > 0, \\quad
        \\frac{\\mathrm{tr}(I_i)}{2} - \\lambda_{max}(I_i) > 0 \\quad \\text{(eq. 16)}

    plus, when given, the box of every parameter and the total-mass band, and the user's
    constraints.

    Parameters
    ----------
    robot_or_params : Robot, array_like or tuple
        See :func:`link_params`.
    bounds : Bounds, optional
        Adds ``mass_in_bounds`` [kg], ``com_in_box`` [m] and ``inertia_in_bounds``
        [kg m^2] per link (margin: the smallest distance to a face of the box), and its
        total-mass band.
    total_mass : (float, float), optional
        Band ``(min, max)`` on the total mass [kg]; overrides ``bounds.total_mass``.
    extra : sequence
        User constraints (see :func:`user_constraints`); margin ``-violation(p)``.
    tol : float
        Relative tolerance: a margin ``>= -tol * scale`` counts as satisfied, ``scale``
        being ``tr(I_i)`` for the inertia constraints, the box width for bounds, the band
        for the total mass and 0 for the mass and the user's constraints.

    Returns
    -------
    FeasibilityReport

    Raises
    ------
    ShapeError
        Parameters or bounds of the wrong shape (or bounds for another number of links).

    Examples
    --------
    >>> import dynid
    >>> from dynid.feasibility.constraints import feasibility_report
    >>> feasibility_report(dynid.panda()).ok
    True
    """
    p = link_params(robot_or_params)
    n = p.shape[0]
    m, c = p[:, 0], p[:, 1:4]
    I = matrix_from_inertia6(p[:, 4:])
    lam = principal_moments(I)
    trace = lam.sum(axis=1)
    out: list[Constraint] = []

    def add(
        name: str, link: int | None, margin: float, unit: str, scale: float, strict: bool = False
    ) -> None:
        ok = margin > 0.0 if strict else margin >= -tol * scale
        out.append(Constraint(name, link, float(margin), unit, bool(ok)))

    if bounds is not None and bounds.n != n:
        raise ShapeError(f"bounds are for {bounds.n} links; the parameters have {n}")
    for i in range(n):
        s_I = float(abs(trace[i]))
        add("mass_positive", i + 1, m[i], "kg", 0.0, strict=True)
        add("inertia_positive_definite", i + 1, lam[i, 0], "kg m^2", s_I)
        add("triangle_inequality", i + 1, 0.5 * trace[i] - lam[i, 2], "kg m^2", s_I)
        if bounds is not None:
            w = bounds.mass_max[i] - bounds.mass_min[i]
            add(
                "mass_in_bounds",
                i + 1,
                min(m[i] - bounds.mass_min[i], bounds.mass_max[i] - m[i]),
                "kg",
                w,
            )
            wc = bounds.com_max[i] - bounds.com_min[i]
            mc = np.minimum(c[i] - bounds.com_min[i], bounds.com_max[i] - c[i])
            add("com_in_box", i + 1, float(mc.min()), "m", float(wc.max()))
            wi = bounds.inertia_max[i] - bounds.inertia_min[i]
            mi = np.minimum(p[i, 4:] - bounds.inertia_min[i], bounds.inertia_max[i] - p[i, 4:])
            add("inertia_in_bounds", i + 1, float(mi.min()), "kg m^2", float(wi.max()))
    band = (
        total_mass
        if total_mass is not None
        else (bounds.total_mass if bounds is not None else None)
    )
    if band is not None:
        lo, hi = (float(x) for x in band)
        M = float(m.sum())
        add("total_mass_min", None, M - lo, "kg", hi - lo)
        add("total_mass_max", None, hi - M, "kg", hi - lo)
    for uc in user_constraints(extra):
        v = float(uc.violation(p.copy()))
        add(uc.name, uc.link, -v, "user", 0.0)
    return FeasibilityReport(tuple(out), tol)


def is_physically_valid(robot_or_params: Any, *, tol: float = DEFAULT_TOL) -> bool:
    """Whether every link is physically valid (Drake's ``IsPhysicallyValid``).

    True when every link has ``m > 0``, a positive semi-definite inertia about its CoM and
    principal moments satisfying the triangle inequality, within ``tol`` (relative to
    ``tr(I)``; see :func:`feasibility_report`). Bounds are not checked.

    Parameters
    ----------
    robot_or_params : Robot, array_like or tuple
        See :func:`link_params`.
    tol : float
    """
    return feasibility_report(robot_or_params, tol=tol).ok
