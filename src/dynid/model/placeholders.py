"""Placeholder inertials: links whose mass in a description is a stand-in, not the link's.

A vendor's description often fills the links it has no data for with a stand-in
(``<mass value="0.001"/>`` and ``<inertia ixx="1e-6" .../>``) so that a simulator loads
it. A model with such a link lacks its weight, and a consistent fit that takes the
description as its prior would hold the link near the stand-in.

The rule (:func:`placeholder_links`): a moving body of the chain (with the links fixed to
it merged) is a *placeholder* when its mass is above zero and below
:data:`PLACEHOLDER_FRACTION` (1 %) of the median mass of the chain's bodies with mass
(at least two of them). A real link carries a drive, a bearing or a shell: the lightest
link of the arms of example-robot-data lies at 10 % (xArm7, UR5's last wrist) to 87 % of
their median, an order of magnitude above the rule. A massless body (no ``<inertial>``)
is no placeholder: it is said where it matters (a prior gives it the generic cylinder).
The median stands when fewer than half of the bodies are placeholders.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .robot import Robot

__all__ = ["PLACEHOLDER_FRACTION", "placeholder_links", "placeholder_words"]

#: A body's mass below this fraction of the median of the chain's masses is a stand-in.
PLACEHOLDER_FRACTION = 0.01


def placeholder_links(mass: ArrayLike) -> NDArray[np.bool_]:
    """Which bodies' masses are placeholders (module docstring).

    Parameters
    ----------
    mass : array_like, shape (n,)
        The chain's body masses [kg], link 1 first.

    Returns
    -------
    ndarray of bool, shape (n,)
        True where ``0 < mass < PLACEHOLDER_FRACTION * median(mass[mass > 0])``; all False
        when fewer than two bodies have mass.
    """
    m = np.asarray(mass, dtype=np.float64).reshape(-1)
    heavy = m[m > 0.0]
    if heavy.size < 2:
        return np.zeros(m.shape, dtype=bool)
    return (m > 0.0) & (m < PLACEHOLDER_FRACTION * float(np.median(heavy)))


def placeholder_words(robot: Robot) -> str | None:
    """The placeholder links of ``robot``'s description in words (names and masses, the
    rule's median), or None when it has none."""
    m = np.asarray(robot.phi, dtype=np.float64).reshape(robot.n, 10)[:, 0]
    found = np.flatnonzero(placeholder_links(m))
    if found.size == 0:
        return None
    each = ", ".join(f"{robot.link_names[i + 1]} ({m[i]:.3g} kg)" for i in found)
    median = float(np.median(m[m > 0.0]))
    return (
        f"placeholder inertial(s) on {each}: under {100 * PLACEHOLDER_FRACTION:g} % of the "
        f"median link mass ({median:.3g} kg), a stand-in the description gives where it "
        "has no data, not the link's mass"
    )
