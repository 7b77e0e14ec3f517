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

Retrieval (:mod:`dynid.feasibility.retrieve`) adds the search box of every parameter
(:class:`Bounds`: mass, CoM box, inertia entries) and a band on the total mass, and users
may add constraints of their own (:class:`UserConstraint`).

Every constraint is reported with a **margin**, positive inside the feasible set, zero on
its boundary, negative outside; its unit is the constraint's (kg, m or kg m^2). A
constraint is *satisfied* when its margin is ``>= -tol * scale`` (limiting bodies such as
a thin rod, a lamina or a point mass are valid, as in Drake), except the mass, which
must be strictly positive. Identified parameters can be infeasible: they are held and
reported, never rejected (:func:`feasibility_report`, :func:`validate`).

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
from ..exceptions import OptionError, ShapeError, WrongTypeError
from ..model.inertia import (
    INERTIA_ORDER,
    inertia6_from_matrix,
    inertial_from_phi,
    matrix_from_inertia6,
)
from ..model.robot import Robot

__all__ = [
    "DECISION_FIELDS",
    "Bounds",
    "Constraint",
    "FeasibilityReport",
    "UserConstraint",
    "decision_labels",
    "default_bounds",
    "feasibility_report",
    "inertial_from_params",
    "kinematic_bounds",
    "link_params",
    "panda_bounds",
    "params_from_inertial",
    "principal_moments",
    "segment_points",
    "user_constraints",
    "validate",
]

#: Per-link decision variables, in order: mass [kg], CoM [m], inertia about the CoM [kg m^2].
DECISION_FIELDS = ("m", "cx", "cy", "cz") + tuple(f"I{ax}" for ax in INERTIA_ORDER)

#: Default relative tolerance of :func:`feasibility_report` (see the module docstring).
DEFAULT_TOL = 1e-9


def decision_labels(n: int) -> tuple[str, ...]:
    """Labels of the ``10 n`` decision variables: ``m1, c1x, c1y, c1z, I1xx, ..., I1zz, m2``..."""
    out: list[str] = []
    for i in range(1, n + 1):
        out += [f"m{i}", f"c{i}x", f"c{i}y", f"c{i}z"] + [f"I{i}{ax}" for ax in INERTIA_ORDER]
    return tuple(out)


def params_from_inertial(
    mass: ArrayLike, com: ArrayLike, inertia: ArrayLike
) -> NDArray[np.float64]:
    """Decision parameters ``p`` (n, 10) from masses (n,) [kg], CoMs (n, 3) [m] and
    inertias about the CoM (n, 3, 3) or (n, 6) [kg m^2]."""
    m = _checks.as_array("mass", mass)
    if m.ndim != 1:
        raise ShapeError(f"mass must have shape (n,); got {m.shape}")
    n = m.shape[0]
    c = _checks.as_exact("com", com, (n, 3))
    I = _checks.as_array("inertia", inertia)
    if I.shape == (n, 3, 3):
        I = inertia6_from_matrix(I)
    elif I.shape != (n, 6):
        raise ShapeError(f"inertia must have shape ({n}, 3, 3) or ({n}, 6); got {I.shape}")
    return np.concatenate([m[:, None], c, I], axis=1)


def inertial_from_params(
    p: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Masses (n,) [kg], CoMs (n, 3) [m] and inertias about the CoM (n, 3, 3) [kg m^2]
    from decision parameters ``p`` of shape (n, 10) or (10 n,)."""
    a = _checks.as_array("p", p)
    if a.ndim == 1 and a.size % 10 == 0:
        a = a.reshape(-1, 10)
    if a.ndim != 2 or a.shape[1] != 10:
        raise ShapeError(f"p must have shape (n, 10) or (10 n,); got {a.shape}")
    return a[:, 0].copy(), a[:, 1:4].copy(), matrix_from_inertia6(a[:, 4:])


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


# ---------------------------------------------------------------------------- bounds
@dataclass(frozen=True, slots=True, eq=False)
class Bounds:
    """Box bounds of the decision parameters of every link, and a total-mass band.

    Attributes
    ----------
    mass_min, mass_max : ndarray, shape (n,)
        Link mass bounds [kg], ``0 <= mass_min <= mass_max``.
    com_min, com_max : ndarray, shape (n, 3)
        Box of each CoM in its link frame [m].
    inertia_min, inertia_max : ndarray, shape (n, 6)
        Bounds of the inertia entries about the CoM, order ``xx, xy, xz, yy, yz, zz``
        [kg m^2].
    total_mass : tuple of 2 floats, or None
        Band ``(min, max)`` on the sum of the link masses [kg]; None for no band.
    link_names : tuple of str, or None
        Names of the links the bounds belong to (``robot.link_names[1:]``), for files.

    Raises
    ------
    ShapeError
        Inconsistent shapes.
    NonFiniteError
        A NaN or infinite bound (every bound must be finite: the retrieval samples
        uniformly inside the box).
    ValueError
        A lower bound above its upper bound, a negative mass bound, or a total-mass band
        with ``min > max`` or ``min < 0``.
    """

    mass_min: NDArray[np.float64]
    mass_max: NDArray[np.float64]
    com_min: NDArray[np.float64]
    com_max: NDArray[np.float64]
    inertia_min: NDArray[np.float64]
    inertia_max: NDArray[np.float64]
    total_mass: tuple[float, float] | None = None
    link_names: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 (frozen init)
        m0 = _checks.as_array("mass_min", self.mass_min)
        if m0.ndim != 1 or m0.shape[0] < 1:
            raise ShapeError(f"mass_min must have shape (n,) with n >= 1; got {m0.shape}")
        n = m0.shape[0]
        shapes = {"mass_min": (n,), "mass_max": (n,), "com_min": (n, 3), "com_max": (n, 3)}
        shapes.update({"inertia_min": (n, 6), "inertia_max": (n, 6)})
        for k, shape in shapes.items():
            put(k, _checks.frozen(_checks.as_exact(k, getattr(self, k), shape)))
        for lo, hi in (
            ("mass_min", "mass_max"),
            ("com_min", "com_max"),
            ("inertia_min", "inertia_max"),
        ):
            bad = np.argwhere(getattr(self, lo) > getattr(self, hi))
            if bad.size:
                idx = tuple(int(i) for i in bad[0])
                raise OptionError(
                    f"{lo} must not exceed {hi}; at index {idx}: "
                    f"{getattr(self, lo)[idx]} > {getattr(self, hi)[idx]}"
                )
        if np.any(self.mass_min < 0):
            raise OptionError(f"mass_min must be >= 0; got {self.mass_min.tolist()}")
        if self.total_mass is not None:
            m_lo, m_hi = (float(x) for x in self.total_mass)
            if not (math.isfinite(m_lo) and math.isfinite(m_hi)) or m_lo < 0 or m_lo > m_hi:
                raise OptionError(
                    f"total_mass must be (min, max) with 0 <= min <= max; got {self.total_mass}"
                )
            put("total_mass", (m_lo, m_hi))
        if self.link_names is not None:
            names = tuple(str(x) for x in self.link_names)
            if len(names) != n:
                raise ShapeError(f"link_names must have {n} entries; got {len(names)}")
            put("link_names", names)

    @property
    def n(self) -> int:
        """Number of links."""
        return int(self.mass_min.shape[0])

    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower bounds of the decision parameters, shape (n, 10), :data:`DECISION_FIELDS`."""
        return np.concatenate([self.mass_min[:, None], self.com_min, self.inertia_min], axis=1)

    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper bounds of the decision parameters, shape (n, 10)."""
        return np.concatenate([self.mass_max[:, None], self.com_max, self.inertia_max], axis=1)

    @classmethod
    def from_arrays(
        cls,
        lower: ArrayLike,
        upper: ArrayLike,
        total_mass: tuple[float, float] | None = None,
        link_names: Sequence[str] | None = None,
    ) -> Bounds:
        """Bounds from (n, 10) lower and upper arrays in the decision layout."""
        lo = _checks.as_array("lower", lower)
        hi = _checks.as_array("upper", upper)
        if lo.ndim != 2 or lo.shape[1] != 10 or hi.shape != lo.shape:
            raise ShapeError(f"lower and upper must have shape (n, 10); got {lo.shape}, {hi.shape}")
        return cls(
            lo[:, 0],
            hi[:, 0],
            lo[:, 1:4],
            hi[:, 1:4],
            lo[:, 4:],
            hi[:, 4:],
            total_mass=total_mass,
            link_names=None if link_names is None else tuple(link_names),
        )

    def with_total_mass(self, total_mass: tuple[float, float] | None) -> Bounds:
        """A copy with another total-mass band [kg] (None removes it)."""
        return Bounds(
            self.mass_min,
            self.mass_max,
            self.com_min,
            self.com_max,
            self.inertia_min,
            self.inertia_max,
            total_mass,
            self.link_names,
        )

    def inertia_scale(self) -> NDArray[np.float64]:
        """A size of each link's inertia [kg m^2], (n,): the largest bound of a principal
        moment, ``max(|inertia bounds of xx, yy, zz|)`` (1e-12 at least). Scales the
        inertia constraints in the retrieval."""
        diag = np.abs(
            np.concatenate([self.inertia_min, self.inertia_max], axis=1)[:, [0, 3, 5, 6, 9, 11]]
        )
        return np.maximum(diag.max(axis=1), 1e-12)


#: Bounds of the Panda used by Gaz et al. 2019 for the retrieval (marcocognetti/
#: FrankaEmikaPandaDynModel, matlab/parameters_retrieval/bounds_gM.csv): masses 0..10 kg,
#: CoM boxes from the link geometry in the MDH frames [m] (x, y, z ranges per link),
#: total mass of links 1..7 in 16..20 kg (error_fcn_gM_LMI.m).
_PANDA_COM_BOX = (
    ((-0.05, 0.05), (-0.05, 0.05), (-0.40, 0.05)),
    ((-0.05, 0.05), (-0.15, 0.05), (-0.05, 0.05)),
    ((-0.05, 0.15), (-0.05, 0.05), (-0.10, 0.05)),
    ((-0.15, 0.05), (-0.05, 0.15), (-0.05, 0.05)),
    ((-0.05, 0.05), (-0.05, 0.05), (-0.35, 0.05)),
    ((-0.05, 0.15), (-0.05, 0.05), (-0.05, 0.05)),
    ((-0.05, 0.05), (-0.05, 0.05), (0.04, 0.15)),
)
_PANDA_MASS = (0.0, 10.0)
_PANDA_TOTAL_MASS = (16.0, 20.0)
_PANDA_INERTIA_DIAG_MAX = 1.0


def panda_bounds() -> Bounds:
    """Default retrieval bounds of the Franka Emika Panda (links 1..7, MDH frames).

    * Masses ``0 .. 10`` kg per link and CoM boxes from the link geometry: the bounds of
      Gaz et al. 2019 (``bounds_gM.csv`` of their retrieval code). Every CoM of the
      published set ``p_hat`` lies inside (``c1z`` is not identifiable; its box reaches
      down to the base, ``-0.40`` m).
    * Inertia about the CoM: principal entries ``0 .. 1`` kg m^2 (as Gaz et al.; above
      the published 0.70 kg m^2 of link 1, an artefact of the unidentifiable ``I1xx``,
      ``I1yy``), products ``-0.5 .. 0.5`` kg m^2: for any body ``|I_xy| <= I_zz / 2``
      since ``|xy| <= (x^2 + y^2) / 2`` (Gaz et al. allowed -1 .. 1, which no body with
      principal entries below 1 reaches).
    * Total mass of links 1..7: ``16 .. 20`` kg (Gaz et al.; the datasheet gives about
      18 kg for the arm; the published ``p_hat`` sums to 16.06 kg).
    """
    n = len(_PANDA_COM_BOX)
    box = np.asarray(_PANDA_COM_BOX)
    d = _PANDA_INERTIA_DIAG_MAX
    i_min = np.tile([0.0, -d / 2, -d / 2, 0.0, -d / 2, 0.0], (n, 1))
    i_max = np.tile([d, d / 2, d / 2, d, d / 2, d], (n, 1))
    return Bounds(
        mass_min=np.full(n, _PANDA_MASS[0]),
        mass_max=np.full(n, _PANDA_MASS[1]),
        com_min=box[:, :, 0],
        com_max=box[:, :, 1],
        inertia_min=i_min,
        inertia_max=i_max,
        total_mass=_PANDA_TOTAL_MASS,
        link_names=tuple(f"link{i}" for i in range(1, n + 1)),
    )


#: Generic bounds (:func:`kinematic_bounds`): CoM box margin around the link's segment,
#: as a fraction of the longest segment of the robot, and its floor [m].
GENERIC_RADIUS_FRACTION = 0.25
GENERIC_RADIUS_MIN = 0.05
#: Generic mass bound: ``GENERIC_MASS_BASE + GENERIC_MASS_PER_M * L_i`` [kg], ``L_i`` the
#: link's segment length [m]: a drive (motor, gear, housing) of up to ~5 kg plus a
#: structure of up to ~40 kg/m (UR5/UR10 upper arms weigh ~20 kg/m, the Panda's ~9 kg/m).
GENERIC_MASS_BASE = 5.0
GENERIC_MASS_PER_M = 40.0


def segment_points(robot: Robot, i: int) -> NDArray[np.float64]:
    """Points that bound link ``i`` (0-based joint index) in its own frame [m], (k, 3):
    its origin, the parent link's origin (for a prismatic joint, at both ends of its finite
    travel: the link slides along its z axis), the next joint's origin (or, for the last
    link, the frames fixed to it, e.g. ``flange``)."""
    T = robot.T_parent_joint[i]
    parent = -T[:3, :3].T @ T[:3, 3]
    pts = [np.zeros(3), parent]  # own origin, parent origin in link i (at q = 0)
    if robot.prismatic[i]:
        pts += [
            parent - q * np.array([0.0, 0.0, 1.0])
            for q in (robot.q_min[i], robot.q_max[i])
            if np.isfinite(q)
        ]
    if i + 1 < robot.n:
        pts.append(robot.T_parent_joint[i + 1][:3, 3])
    pts += [f.T_link_frame[:3, 3] for f in robot.frames.values() if f.link == i + 1]
    return np.asarray(pts)


def kinematic_bounds(
    robot: Robot,
    *,
    radius: float | None = None,
    mass_max: ArrayLike | None = None,
    total_mass: tuple[float, float] | None = None,
) -> Bounds:
    """Generic bounds derived from a robot's kinematics (link lengths).

    For link ``i`` let ``S_i`` be the points that bound its segment in its own frame: the
    link origin, the parent link's origin and the next joint's origin (for the last link,
    the frames fixed to it, such as ``flange``); ``L_i`` the largest extent of ``S_i``.

    * CoM box: the bounding box of ``S_i`` grown by ``radius`` on every side (default
      ``max(0.05 m, 0.25 * max_i L_i)``; 0.1 m for the Panda).
    * Mass: ``0 .. 5 kg + 40 kg/m * L_i`` (a drive plus a structure; see
      :data:`GENERIC_MASS_PER_M`), or ``mass_max``.
    * Inertia about the CoM: a body of mass ``m`` inside a box of diagonal ``D`` has
      principal moments ``<= m D^2 / 4`` (all mass at the corners), and products
      ``|I_xy| <= I_zz / 2``; so principal entries ``0 .. m_max D^2 / 4`` and products
      within half of that.
    * Total mass: no band unless ``total_mass`` [kg] is given (kinematics say nothing
      of it).

    Parameters
    ----------
    robot : Robot
    radius : float, optional
        Margin of the CoM boxes [m].
    mass_max : float or array_like, shape (n,), optional
        Mass upper bounds [kg].
    total_mass : (float, float), optional
        Band on the total mass [kg].

    Returns
    -------
    Bounds
    """
    n = robot.n
    pts = [segment_points(robot, i) for i in range(n)]
    ext = np.array([float(np.max(np.ptp(P, axis=0))) if len(P) > 1 else 0.0 for P in pts])
    seg = np.array([float(np.max(np.linalg.norm(P, axis=1))) for P in pts])
    L = np.maximum(ext, seg)
    r = (
        max(GENERIC_RADIUS_MIN, GENERIC_RADIUS_FRACTION * float(L.max()))
        if radius is None
        else float(radius)
    )
    if r <= 0:
        raise OptionError(f"radius must be positive; got {r}")
    lo = np.array([P.min(axis=0) for P in pts]) - r
    hi = np.array([P.max(axis=0) for P in pts]) + r
    if mass_max is None:
        m_hi = GENERIC_MASS_BASE + GENERIC_MASS_PER_M * L
    else:
        m_hi = np.broadcast_to(_checks.as_array("mass_max", mass_max), (n,)).astype(float)
    D2 = np.sum((hi - lo) ** 2, axis=1)
    d = m_hi * D2 / 4.0
    z = np.zeros(n)
    i_min = np.stack([z, -d / 2, -d / 2, z, -d / 2, z], axis=1)
    i_max = np.stack([d, d / 2, d / 2, d, d / 2, d], axis=1)
    return Bounds(
        mass_min=z,
        mass_max=m_hi,
        com_min=lo,
        com_max=hi,
        inertia_min=i_min,
        inertia_max=i_max,
        total_mass=total_mass,
        link_names=robot.link_names[1:],
    )


def _same_kinematics(a: Robot, b: Robot, atol: float = 1e-9) -> bool:
    return (
        a.n == b.n
        and bool(np.all(a.prismatic == b.prismatic))
        and np.allclose(a.T_parent_joint, b.T_parent_joint, rtol=0.0, atol=atol)
        and np.allclose(a.axes, b.axes, rtol=0.0, atol=atol)
    )


def default_bounds(robot: Robot) -> Bounds:
    """Default retrieval bounds of a robot.

    :func:`panda_bounds` when the robot has the built-in Panda's kinematics (joint
    frames and axes equal to those of :func:`dynid.panda` within 1e-9; link names are
    taken from ``robot``), :func:`kinematic_bounds` otherwise.
    """
    from ..model.panda import panda

    if _same_kinematics(robot, panda()):
        b = panda_bounds()
        return Bounds(
            b.mass_min,
            b.mass_max,
            b.com_min,
            b.com_max,
            b.inertia_min,
            b.inertia_max,
            b.total_mass,
            robot.link_names[1:],
        )
    return kinematic_bounds(robot)


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


def validate(robot_or_params: Any, *, tol: float = DEFAULT_TOL) -> bool:
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
