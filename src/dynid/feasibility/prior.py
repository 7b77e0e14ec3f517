"""Prior link parameters for consistent identification: checked, repaired, or made up.

A prior is a complete set of standard parameters (10 per link, :mod:`dynid.model.inertia`)
that the convex retrieval (:mod:`dynid.feasibility.convex`) is pulled towards in the
directions the data cannot see. It comes from

* a robot description with inertials (:func:`prior_from_robot`): the built-in Panda, a
  URDF from CAD, a TOML file, a feasible set retrieved earlier; or
* the kinematics alone (:func:`generic_prior`): each link a solid cylinder of radius
  :data:`GENERIC_RADIUS_FRACTION` of its length (at least :data:`GENERIC_RADIUS_MIN`)
  along the segment that bounds it (from the parent's origin or its own to the next
  joint's origin, or to the frames fixed to the last link); masses in proportion to
  ``GENERIC_LINK_MASS_BASE + GENERIC_LINK_MASS_PER_M * length``, scaled to the nearer end
  of the total-mass band when their total lies outside it.

Without a prior given, :func:`default_prior` takes the robot's own description's
inertials when it has them (the best prior a user usually has: a generic guess put 13.4 kg
on a 10.8 kg 7-joint arm, 3.7 times its last link's mass, where the data could not tell),
the generic one when it has none.

Every prior is checked before use: a link whose pseudo-inertia is not positive definite
with the margin ``lambda_min(J) >= margin tr(J)`` gets the eigenvalues of ``J`` floored to
it (:func:`~dynid.feasibility.lmi.repair_pseudo_inertia`), and a total mass outside the
band is reported. A link that violates a physical condition (``lambda_min(J) < 0``: a CAD
inertia breaking the triangle inequality, a negative principal moment; a mass at or below
zero, which gets the generic cylinder) is *repaired* (:attr:`Prior.repaired`); a
link whose mass is a description's placeholder (:mod:`dynid.model.placeholders`: above
zero, under 1 % of the median link mass) gets the generic cylinder too, one note naming
them all (:attr:`Prior.placeholders`); the links given the cylinder
(:attr:`Prior.guessed`) have their masses bounded as the generic prior's are, by the
bounds alone, not by a factor of the guess
(:func:`~dynid.feasibility.convex.problem.mass_bounds`); a
physically valid link only within the margin is *held at the margin*
(:attr:`Prior.held`: a Unitree Z1's link05 at ``0.000199 tr(J)`` against ``0.0002``).
Nothing is changed silently: :attr:`Prior.notes` says what was done, one line each.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import ModelError
from ..model.inertia import phi_from_inertial
from ..model.placeholders import placeholder_links, placeholder_words
from ..model.robot import Robot
from .bounds import segment_points
from .lmi import pseudo_inertia, pseudo_inertia_margin, repair_pseudo_inertia

__all__ = [
    "DEFAULT_PRIOR_MARGIN",
    "GENERIC_SOURCE",
    "Prior",
    "default_prior",
    "generic_prior",
    "prior_from_robot",
    "prior_scales",
]

#: A prior's links are held at or repaired up to ``lambda_min(J) >= DEFAULT_PRIOR_MARGIN
#: tr(J)`` (the published Panda's links lie between 1.3e-6 and 1.3e-3: links 2, 3, 5 and 6
#: are held at it).
DEFAULT_PRIOR_MARGIN = 2e-4
#: Generic cylinder: radius as a fraction of the link's length, and its floor [m].
GENERIC_RADIUS_FRACTION = 0.2
GENERIC_RADIUS_MIN = 0.04
#: Generic masses (before scaling to a band): a drive plus a structure [kg, kg/m].
#: The name of the generic prior (:func:`generic_prior`), in reports and as a robot's.
GENERIC_SOURCE = "generic (a solid cylinder per link)"
GENERIC_LINK_MASS_BASE = 1.0
GENERIC_LINK_MASS_PER_M = 10.0
#: Shortest generic cylinder [m] (links whose frames coincide with the next joint's).
GENERIC_LENGTH_MIN = 0.05


@dataclass(frozen=True, slots=True, eq=False)
class Prior:
    """Prior standard parameters of every link, checked.

    Attributes
    ----------
    phi : ndarray, shape (n, 10)
        Standard parameters (m, m c, J about the link origin), every link strictly
        consistent with the margin.
    source : str
        Where it came from (``"panda"``, a file name, :data:`GENERIC_SOURCE`).
    repaired : tuple of int
        Links (1-based) whose parameters violated a physical condition and were repaired
        (``lambda_min(J) < 0``, a mass at or below zero).
    notes : tuple of str
        One line per repair or warning (also the total mass against the band).
    held : tuple of int
        Links (1-based) physically valid (``lambda_min(J) >= 0``) but within the margin,
        their eigenvalues floored to ``margin tr(J)``: held at the margin, not repaired.
    placeholders : tuple of int
        Links (1-based) whose mass was a description's placeholder
        (:mod:`dynid.model.placeholders`), given the generic cylinder.
    guessed : tuple of int
        Links (1-based) given the generic cylinder in place of the description's (massless
        or a placeholder): a guess, which bounds no mass.
    """

    phi: NDArray[np.float64]
    source: str
    repaired: tuple[int, ...] = ()
    notes: tuple[str, ...] = ()
    held: tuple[int, ...] = ()
    placeholders: tuple[int, ...] = ()
    guessed: tuple[int, ...] = ()

    @property
    def n(self) -> int:
        """Number of links."""
        return int(self.phi.shape[0])

    @property
    def pseudo_inertia(self) -> NDArray[np.float64]:
        """``J0`` of every link, (n, 4, 4)."""
        return pseudo_inertia(self.phi)

    @property
    def generic(self) -> bool:
        """Whether this is the generic prior (a guess from the kinematics, however given:
        ``--prior generic`` or the default for a description without inertials)."""
        return self.source == GENERIC_SOURCE

    @property
    def mass(self) -> NDArray[np.float64]:
        """Prior link masses [kg], (n,)."""
        return self.phi[:, 0].copy()


def prior_scales(phi0: NDArray[np.float64]) -> NDArray[np.float64]:
    """Size of every standard parameter of a prior (10 n,): ``m0``, ``m0 L`` for the first
    moments and ``m0 L^2`` for the inertia entries, ``L = sqrt(max |J_o| / m0)`` the link's
    radius of gyration about its origin [kg, kg m, kg m^2]; 1e-12 at least."""
    p0 = np.asarray(phi0, dtype=np.float64).reshape(-1, 10)
    m0 = np.maximum(p0[:, 0], 1e-9)
    j0 = np.maximum(np.abs(p0[:, 4:]).max(axis=1), 1e-12)
    L = np.sqrt(j0 / m0)
    s = np.concatenate(
        [m0[:, None], np.repeat((m0 * L)[:, None], 3, 1), np.repeat(j0[:, None], 6, 1)], axis=1
    )
    return np.maximum(s, 1e-12).reshape(-1)


def _segment(robot: Robot, i: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """End points [m] in link ``i``'s frame (0-based): the two farthest apart of the points
    that bound it (:func:`~dynid.feasibility.bounds.segment_points`)."""
    P = segment_points(robot, i)
    d = np.linalg.norm(P[:, None] - P[None], axis=-1)
    a, b = np.unravel_index(int(np.argmax(d)), d.shape)
    return P[a], P[b]


def _cylinder(mass: float, a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Standard parameters of a solid cylinder of ``mass`` along a..b (link frame)."""
    axis = b - a
    L = float(np.linalg.norm(axis))
    if L < GENERIC_LENGTH_MIN:
        mid = 0.5 * (a + b)
        axis = np.array([0.0, 0.0, 1.0])
        L = GENERIC_LENGTH_MIN
        a, b = mid - 0.5 * L * axis, mid + 0.5 * L * axis
    u = (b - a) / np.linalg.norm(b - a)
    r = max(GENERIC_RADIUS_MIN, GENERIC_RADIUS_FRACTION * L)
    ax, tr = 0.5 * mass * r**2, mass * (3 * r**2 + L**2) / 12.0
    Ic = tr * np.eye(3) + (ax - tr) * np.outer(u, u)
    return phi_from_inertial(mass, 0.5 * (a + b), Ic)


def _lengths(robot: Robot) -> NDArray[np.float64]:
    return np.array(
        [float(np.linalg.norm(np.subtract(*_segment(robot, i)))) for i in range(robot.n)]
    )


def generic_prior(robot: Robot, total_mass: tuple[float, float] | None = None) -> Prior:
    """A prior from the kinematics alone: one solid cylinder per link (module docstring).

    Parameters
    ----------
    robot : Robot
    total_mass : (float, float), optional
        Band on the total mass [kg]: when the cylinders' total lies outside, the masses are
        scaled to the band's nearer end (a loose band, such as ``0..1e5``, leaves them as
        they are: the prior does not depend on how wide the band is drawn).
    """
    L = np.maximum(_lengths(robot), GENERIC_LENGTH_MIN)
    m = GENERIC_LINK_MASS_BASE + GENERIC_LINK_MASS_PER_M * L
    notes = [
        f"generic prior: solid cylinders along the links, masses {GENERIC_LINK_MASS_BASE:g} kg "
        f"+ {GENERIC_LINK_MASS_PER_M:g} kg/m"
    ]
    if total_mass is not None:  # a total outside the band is scaled to its nearer end
        lo, hi = (float(x) for x in total_mass)
        total = float(m.sum())
        target = min(max(total, lo), hi)
        if target > 0 and target != total:
            m = m * (target / total)
            notes[0] += f", scaled to {target:g} kg in all"
    phi = np.stack([_cylinder(float(m[i]), *_segment(robot, i)) for i in range(robot.n)])
    return Prior(phi=phi, source=GENERIC_SOURCE, notes=tuple(notes))


def prior_from_robot(
    robot: Robot,
    *,
    source: str | None = None,
    margin: float = DEFAULT_PRIOR_MARGIN,
    total_mass: tuple[float, float] | None = None,
) -> Prior:
    """The link parameters of ``robot`` as a prior, checked and repaired where needed.

    Parameters
    ----------
    robot : Robot
        A robot with link inertials (``robot.phi``); its joint spring, when it has one,
        is not part of a prior (a note says so).
    source : str, optional
        Name in reports (default ``robot.name``).
    margin : float
        Links with ``lambda_min(J) < margin tr(J)`` are repaired (module docstring).
    total_mass : (float, float), optional
        Band [kg]; a prior whose total mass lies outside is reported in ``notes``.

    Raises
    ------
    ModelError
        ``robot`` has no link inertials at all (every parameter zero).
    """
    phi = np.array(robot.phi, dtype=np.float64).reshape(robot.n, 10)
    name = robot.name if source is None else source
    if not np.any(phi):
        raise ModelError(
            f"prior {name!r} has no link inertials (every mass and inertia is zero); give a "
            "description with <inertial> elements, or no prior for the generic one"
        )
    notes: list[str] = []
    repaired: list[int] = []
    massless = phi[:, 0] <= 0
    stand_in = placeholder_links(phi[:, 0])
    if np.any(massless | stand_in):
        cyl = generic_prior(robot).phi
        for i in np.flatnonzero(massless):
            notes.append(
                f"prior {name}: link {i + 1} ({robot.link_names[i + 1]}) has mass "
                f"{phi[i, 0]:g} kg; replaced by the generic cylinder of {cyl[i, 0]:.3g} kg"
            )
            repaired.append(int(i) + 1)
        if np.any(stand_in):
            cyls = ", ".join(f"{cyl[i, 0]:.3g}" for i in np.flatnonzero(stand_in))
            notes.append(
                f"prior {name}: {placeholder_words(robot)}; replaced by the generic cylinder "
                f"({cyls} kg), their masses bounded by the links' lengths alone, not by a "
                "factor of the stand-in's (as a link without a description is)"
            )
        phi[massless | stand_in] = cyl[massless | stand_in]
    before = pseudo_inertia_margin(phi)
    phi, changed = repair_pseudo_inertia(phi, margin)
    violated = changed & (before < 0) & ~massless & ~stand_in
    held = changed & ~violated & ~massless & ~stand_in
    notes += _margin_notes(robot, name, margin, before, violated, held)
    repaired += [int(i) + 1 for i in np.flatnonzero(violated)]
    if total_mass is not None:
        M = float(phi[:, 0].sum())
        lo, hi = (float(x) for x in total_mass)
        if not lo <= M <= hi:
            notes.append(
                f"prior {name}: total mass {M:.3f} kg lies outside the band {lo:g}..{hi:g} kg"
            )
    if robot.spring is not None:  # a prior is of the links: the fit never reads it
        k = ", ".join(f"{x:.3g}" for x in robot.spring.k)
        notes.append(
            f"prior {name}: its joint spring (k = {k} N m/rad) is not used; a prior holds the "
            "links' inertials only, and the stiffnesses come from the data (spring in --terms)"
        )
    return Prior(
        phi=phi,
        source=name,
        repaired=tuple(sorted(set(repaired))),
        notes=tuple(notes),
        held=tuple(int(i) + 1 for i in np.flatnonzero(held)),
        placeholders=tuple(int(i) + 1 for i in np.flatnonzero(stand_in)),
        guessed=tuple(int(i) + 1 for i in np.flatnonzero(massless | stand_in)),
    )


def _margin_notes(
    robot: Robot,
    name: str,
    margin: float,
    before: NDArray[np.float64],
    violated: NDArray[np.bool_],
    held: NDArray[np.bool_],
) -> list[str]:
    """The lines saying which links' pseudo-inertia eigenvalues were floored to ``margin
    tr(J)``: those that ``violated`` physical consistency (``lambda_min(J) < 0``,
    repaired) and those ``held`` at the margin (valid, ``0 <= lambda_min(J) / tr(J) <
    margin``), each with its ``before`` ratio (n,)."""

    def links(mask: NDArray[np.bool_]) -> str:
        idx = np.flatnonzero(mask)
        return ", ".join(f"{i + 1} ({robot.link_names[i + 1]}: {before[i]:.3g})" for i in idx)

    notes = []
    if np.any(violated):
        notes.append(
            f"prior {name}: link(s) {links(violated)} not physically consistent "
            "(lambda_min(J)/tr(J) below 0: the triangle inequality or a principal moment "
            f"broken); repaired: their pseudo-inertia eigenvalues floored to {margin:g} tr(J)"
        )
    if np.any(held):
        notes.append(
            f"prior {name}: link(s) {links(held)} physically valid, lambda_min(J)/tr(J) "
            f"within the margin {margin:g}; held at the margin: their pseudo-inertia "
            f"eigenvalues floored to it (a change of at most "
            f"{float(np.max(margin - before[held])):.2g} tr(J))"
        )
    return notes


def default_prior(robot: Robot, total_mass: tuple[float, float] | None = None) -> Prior:
    """The prior of a consistent fit given none: the link inertials of ``robot``'s own
    description (checked and repaired as :func:`prior_from_robot` does, each repair a note;
    source ``"description"``), or :func:`generic_prior` when it has none (every mass and
    inertia zero, a kinematic description).

    Parameters
    ----------
    robot : Robot
        The robot identified, with or without link inertials.
    total_mass : (float, float), optional
        Band [kg]: the generic prior's masses are scaled into it; a description's total
        mass outside it is a note.
    """
    phi = np.asarray(robot.phi, dtype=np.float64)
    if not np.any(phi):
        pr = generic_prior(robot, total_mass)
        note = f"the robot's description ({robot.name}) has no link inertials: " + pr.notes[0]
        return Prior(pr.phi, pr.source, pr.repaired, (note, *pr.notes[1:]))
    pr = prior_from_robot(robot, source="description", total_mass=total_mass)
    note = (
        f"prior: the link inertials of the robot's description ({robot.name}), total mass "
        f"{float(pr.phi[:, 0].sum()):.4g} kg"
        + (f"; link(s) {', '.join(map(str, pr.repaired))} repaired" if pr.repaired else "")
        + (f"; link(s) {', '.join(map(str, pr.held))} held at the margin" if pr.held else "")
        + (
            f"; link(s) {', '.join(map(str, pr.placeholders))} placeholders, the generic "
            "cylinder in their place"
            if pr.placeholders
            else ""
        )
        + " (--prior names another)"
    )
    return dataclasses.replace(pr, notes=(note, *pr.notes))
