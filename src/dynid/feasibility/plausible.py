"""Links whose retrieved mass or size is implausible, said as notes by both retrieval
methods (the convex one of :mod:`dynid.feasibility.convex` and the paper's penalty method
of :mod:`dynid.feasibility.penalty`).

Feasible parameters reproduce the identified coefficients whatever the masses the data do
not give: the penalty method run on a Panda's exact coefficients put 0.158 kg in link 7
(the published 0.74 kg), under 1 % of the arm's 17.3 kg, with nothing said.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..model.inertia import inertial_from_phi
from ..model.robot import Robot
from .bounds import link_points

__all__ = ["MASS_SHARE", "implausible", "implausible_notes"]

#: A link lighter than this share of the arm's total mass is implausible.
MASS_SHARE = 0.01
#: A radius of gyration about the CoM over this multiple of the link's extent is.
GYRATION = 1.5


def implausible(
    robot: Robot, m: NDArray[np.float64], I: NDArray[np.float64]
) -> list[tuple[str, float, float] | None]:
    """Per link, what is implausible: ``("mass", m, M)`` for a link under
    :data:`MASS_SHARE` of the total mass ``M`` [kg]; ``("gyration", r_g, extent)`` for a
    radius of gyration about the CoM over :data:`GYRATION` times the link's extent [m];
    None when neither. ``m`` (n,) [kg], ``I`` (n, 3, 3) [kg m^2] about the CoMs."""
    M = float(m.sum())
    lam = np.linalg.eigvalsh(I)
    out: list[tuple[str, float, float] | None] = []
    for i in range(robot.n):
        ext = max(float(np.linalg.norm(np.ptp(link_points(robot, i), axis=0))), 0.05)
        rg = math.sqrt(max(float(lam[i].sum()), 0.0) / (2.0 * m[i])) if m[i] > 0 else math.inf
        if m[i] < MASS_SHARE * M:
            out.append(("mass", float(m[i]), M))
        elif rg > GYRATION * ext:
            out.append(("gyration", rg, ext))
        else:
            out.append(None)
    return out


def implausible_notes(
    robot: Robot,
    m: NDArray[np.float64],
    I: NDArray[np.float64],
    prior_phi: NDArray[np.float64] | None = None,
) -> list[str]:
    """One note per implausible link (:func:`implausible`), saying "the prior has it too"
    when the prior's link, ``prior_phi`` (n, 10), is implausible the same way; a light link
    the prior holds within 20 % of its mass is no finding (a UR10's wrist 3 link, 0.202 kg
    of 28 kg, is the arm's own)."""
    names = robot.link_names[1:]
    found = implausible(robot, m, I)
    held: list[tuple[str, float, float] | None] = [None] * robot.n
    if prior_phi is not None:
        pm, _, pI = inertial_from_phi(prior_phi)
        held = implausible(robot, pm, pI)
    out: list[str] = []
    for i, (odd, prior) in enumerate(zip(found, held, strict=True)):
        if odd is None:
            continue
        kind, value, of = odd
        too = prior[1] if prior is not None and prior[0] == kind else None
        if kind == "mass":
            if too is not None and abs(value - too) <= 0.2 * too:  # the description's own
                continue
            text = f"implausible: {names[i]} weighs {value:.3g} kg, under 1 % of the total"
            out.append(text + ("" if too is None else f"; the prior has it too ({too:.3g} kg)"))
            continue
        text = (
            f"implausible: {names[i]} has a radius of gyration of {value:.3g} m about its CoM, "
            f"more than 1.5 times its extent of {of:.3g} m"
        )
        why = " (rotor inertia the link absorbed, or inertia the data cannot see)"
        out.append(text + (why if too is None else f": the prior has it too ({too:.3g} m)"))
    return out
