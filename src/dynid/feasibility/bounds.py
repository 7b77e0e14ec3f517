"""Bounds of the link parameters for the retrieval, and the generic ones from the kinematics.

:class:`Bounds` boxes every link's decision parameters (mass [kg], CoM in the link frame [m],
inertia entries about the CoM [kg m^2], :data:`~dynid.model.inertia.DECISION_FIELDS`)
and bands the total mass. :func:`panda_bounds` are Gaz et al.'s for the Panda (their numbers
live with the Panda, :mod:`dynid.model.panda`); :func:`kinematic_bounds` derives generic ones
from the link lengths; :func:`default_bounds` picks between them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError, ShapeError
from ..model.panda import (
    PANDA_RETRIEVAL_COM_BOX,
    PANDA_RETRIEVAL_INERTIA_DIAG_MAX,
    PANDA_RETRIEVAL_MASS,
    PANDA_RETRIEVAL_TOTAL_MASS,
)
from ..model.robot import MAX_LINK_MASS, Robot

__all__ = [
    "GENERIC_MASS_BASE",
    "GENERIC_MASS_PER_M",
    "GENERIC_RADIUS_FRACTION",
    "GENERIC_RADIUS_MIN",
    "Bounds",
    "default_bounds",
    "kinematic_bounds",
    "link_points",
    "panda_bounds",
    "segment_points",
]


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
    mass_guessed : tuple of bool, or None
        Per link, True where the mass bounds are the generic guess from the link's length
        (:func:`kinematic_bounds`): a prior's masses, better knowledge, bound that link's
        mass instead where they lie above it (the consistent fit). None: none guessed.

    Raises
    ------
    ShapeError
        Inconsistent shapes.
    NonFiniteError
        A NaN or infinite bound (every bound must be finite: the retrieval samples
        uniformly inside the box).
    ValueError
        A lower bound above its upper bound, a negative mass bound or one above
        :data:`~dynid.model.robot.MAX_LINK_MASS`, or a total-mass band with ``min > max``,
        ``min < 0`` or ``max`` above ``n MAX_LINK_MASS``.
    """

    mass_min: NDArray[np.float64]
    mass_max: NDArray[np.float64]
    com_min: NDArray[np.float64]
    com_max: NDArray[np.float64]
    inertia_min: NDArray[np.float64]
    inertia_max: NDArray[np.float64]
    total_mass: tuple[float, float] | None = None
    link_names: tuple[str, ...] | None = None
    mass_guessed: tuple[bool, ...] | None = None

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
        if np.any(self.mass_max > MAX_LINK_MASS):
            raise OptionError(
                f"mass_max must be at most {MAX_LINK_MASS:g} kg per link; got "
                f"{self.mass_max.tolist()}"
            )
        if self.total_mass is not None:
            m_lo, m_hi = (float(x) for x in self.total_mass)
            if not (math.isfinite(m_lo) and math.isfinite(m_hi)) or m_lo < 0 or m_lo > m_hi:
                raise OptionError(
                    f"total_mass must be (min, max) with 0 <= min <= max; got ({m_lo:g}, {m_hi:g})"
                )
            if m_hi > n * MAX_LINK_MASS:
                raise OptionError(
                    f"total_mass max must be at most {n * MAX_LINK_MASS:g} kg ({n} links of at "
                    f"most {MAX_LINK_MASS:g} kg); got {m_hi:g}"
                )
            put("total_mass", (m_lo, m_hi))
        if self.mass_guessed is not None:
            guessed = tuple(bool(x) for x in self.mass_guessed)
            if len(guessed) != n:
                raise ShapeError(f"mass_guessed must have {n} entries; got {len(guessed)}")
            put("mass_guessed", guessed)
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
        mass_guessed: Sequence[bool] | None = None,
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
            mass_guessed=None if mass_guessed is None else tuple(mass_guessed),
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
            self.mass_guessed,
        )

    def inertia_scale(self) -> NDArray[np.float64]:
        """A size of each link's inertia [kg m^2], (n,): the largest bound of a principal
        moment, ``max(|inertia bounds of xx, yy, zz|)`` (1e-12 at least). Scales the
        inertia constraints in the retrieval."""
        diag = np.abs(
            np.concatenate([self.inertia_min, self.inertia_max], axis=1)[:, [0, 3, 5, 6, 9, 11]]
        )
        return np.maximum(diag.max(axis=1), 1e-12)


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
    n = len(PANDA_RETRIEVAL_COM_BOX)
    box = np.asarray(PANDA_RETRIEVAL_COM_BOX)
    d = PANDA_RETRIEVAL_INERTIA_DIAG_MAX
    i_min = np.tile([0.0, -d / 2, -d / 2, 0.0, -d / 2, 0.0], (n, 1))
    i_max = np.tile([d, d / 2, d / 2, d, d / 2, d], (n, 1))
    return Bounds(
        mass_min=np.full(n, PANDA_RETRIEVAL_MASS[0]),
        mass_max=np.full(n, PANDA_RETRIEVAL_MASS[1]),
        com_min=box[:, :, 0],
        com_max=box[:, :, 1],
        inertia_min=i_min,
        inertia_max=i_max,
        total_mass=PANDA_RETRIEVAL_TOTAL_MASS,
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


def link_points(robot: Robot, i: int) -> NDArray[np.float64]:
    """:func:`segment_points` of link ``i`` with its centre of mass when it has a mass."""
    pts = segment_points(robot, i)
    if robot.mass[i] > 0:
        pts = np.vstack([pts, robot.com[i]])
    return pts


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
    the frames fixed to it, such as ``flange``), and the link's own centre of mass when the
    robot has one (a link whose mass lies beyond its joints' offsets, a pendulum's bob);
    ``L_i`` the largest extent of ``S_i`` (from the origin too).

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
    pts = [link_points(robot, i) for i in range(n)]
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
        mass_guessed=(mass_max is None,) * n,
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
