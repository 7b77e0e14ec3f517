"""Joint-origin angles of a URDF written rounded near multiples of pi/2.

CAD exports and hand-written URDFs often give a right angle as ``rpy="1.5708 0 0"`` or a
half turn as ``3.1416``: 4e-6 and 7e-6 rad off. The kinematics are then no longer exactly
those of the arm: dependencies between inertial parameters that the exact angles create
become near-dependencies, acting through the rounding only, and a fit can give a link's
first moment of -14,760 kg m with a small standard deviation. The regressor's column-scaled
condition number does not show it; the unscaled one does.

:class:`AngleRounding` collects, while a URDF is read, every ``rpy`` component within
:data:`ROUNDED_BAND` rad of a multiple of pi/2 but not equal to it to :data:`EXACT` rad,
and snaps such components (all those within the band) to the multiple when asked.
:func:`rounding_message` is the one-line report of angles read as written: the joints, how
far off, the leftovers they put in the base-parameter expressions (a coefficient of about
the offset, ``-7.3e-06*mc3y``, that the exact angles do not give) and the unscaled
condition numbers of the structural regressor with the angles as written and snapped; the
reader warns with it when the rounding multiplies the condition number by more than
:data:`HARMFUL_FACTOR`, and gives it as a note (shown without ``-v``) otherwise.
:func:`snapped_message` is the note of angles snapped.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ...model.robot import Robot
from ...regressors.base import base_parameters
from ...regressors.torque import torque_regressor

__all__ = [
    "EXACT",
    "HARMFUL_FACTOR",
    "ROUNDED_BAND",
    "AngleRounding",
    "rounding_message",
    "snapped_message",
    "structural_condition",
]

#: An ``rpy`` component this close to a multiple of pi/2 [rad] is taken as meant to be it.
ROUNDED_BAND = 1e-3
#: ... and it is reported as rounded when it is farther than this from it [rad] (an angle
#: written to 10 significant digits or more is exact for identification).
EXACT = 1e-9

_QUARTER = np.pi / 2


@dataclass
class AngleRounding:
    """Rounded ``rpy`` angles found while reading (``found``: joint -> largest offset
    [rad]), snapped to the multiple of pi/2 when ``snap``."""

    snap: bool = False
    found: dict[str, float] = field(default_factory=dict)

    def rpy(self, joint: str, rpy: NDArray[np.float64]) -> NDArray[np.float64]:
        """``rpy`` (3,) of ``joint``'s origin: recorded when rounded; snapped when asked."""
        exact = np.round(rpy / _QUARTER) * _QUARTER
        off = np.abs(rpy - exact)
        near = off <= ROUNDED_BAND
        rounded = near & (off > EXACT)
        if rounded.any():
            self.found[joint] = max(self.found.get(joint, 0.0), float(off[rounded].max()))
        return np.where(near, exact, rpy) if self.snap else rpy


#: Rank tolerance of :func:`structural_condition`: every direction above round-off, as a
#: fit's rank decision sees it (:data:`dynid.identification.core.DEFAULT_FIT_RTOL`).
_FIT_RTOL = 1e-10


def structural_condition(robot: Robot, n_samples: int = 64) -> float:
    """Unscaled condition number of the structural regressor of ``robot``: the torque
    regressor over ``n_samples`` random states (seeded, as
    :func:`~dynid.regressors.base.base_parameters` draws them) of the combinations above
    round-off (rank at ``rtol=1e-10``). Exact angles leave only the true base parameters;
    rounded ones add the near-dependencies they create, at the size of the rounding."""
    base = base_parameters(robot, kind="torque", n_samples=n_samples, rtol=_FIT_RTOL)
    rng = np.random.default_rng(0)
    lo = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    hi = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    q = rng.uniform(lo, hi, (n_samples, robot.n))
    dq = rng.uniform(-2, 2, q.shape)
    ddq = rng.uniform(-5, 5, q.shape)
    W = base.reduce(torque_regressor(robot, q, dq, ddq)).reshape(-1, base.rank)
    s = np.linalg.svd(W, compute_uv=False)
    return float(s[0] / s[-1]) if s.size and s[-1] > 0 else float("inf")


#: The rounding matters (a warning, not a note) when it multiplies the structural
#: regressor's unscaled condition number by more than this.
HARMFUL_FACTOR = 10.0


def rounding_message(
    source: str, found: dict[str, float], as_written: Robot, snapped: Robot
) -> tuple[str, bool]:
    """One line naming the joints whose angles are rounded (those of one offset together)
    and read as written, with the condition numbers, the leftovers the rounding puts in
    the base-parameter expressions (said only where the rounding matters) and the option
    that snaps them; and whether the rounding matters (the condition number
    as written over :data:`HARMFUL_FACTOR` times the snapped one)."""
    c_written, c_snapped = structural_condition(as_written), structural_condition(snapped)
    harmful = not c_written <= HARMFUL_FACTOR * c_snapped
    size = max(found.values())
    if not harmful:
        return (
            f"{_named(source, found)}, read as written (harmless here: the structural "
            f"regressor's unscaled condition number is {c_written:.3g} as written, "
            f"{c_snapped:.3g} with the angles snapped); --snap-angles snaps them"
        ), harmful
    return (
        f"{_named(source, found)}, read as written: the base-parameter expressions may "
        f"hold coefficients near {size:.2g} (the sine of the rounding; the exact angles give "
        f"none) and the structural regressor's unscaled condition number is {c_written:.3g} "
        f"as written, {c_snapped:.3g} with the angles snapped; hint: --snap-angles "
        "(snap_angles=True) snaps them to the multiples of pi/2"
    ), harmful


def snapped_message(source: str, found: dict[str, float]) -> str:
    """One line naming the joints whose rounded angles were snapped to multiples of pi/2."""
    return f"{_named(source, found)}, snapped to the multiples (--snap-angles)"


def _named(source: str, found: dict[str, float]) -> str:
    """The opening both messages share: the file and the joints with their offsets."""
    by_off: dict[str, list[str]] = {}
    for j, off in found.items():
        by_off.setdefault(f"{off:.2g}", []).append(j)
    names = ", ".join(f"{', '.join(js)} ({off} rad off)" for off, js in by_off.items())
    return f"{source}: joint origin angles rounded near multiples of pi/2 on {names}"
