"""Static data's gravity torques against a description's: a mass at the flange it lacks.

A controller's ``M(q)`` and ``g(q)`` (static data, Gaz et al. 2019, Sec. IV-A) are its own
model's output, holding whatever it was configured with: an arm's controller told of its
hand (0.73 kg on a Franka arm) gives the arm with the hand. The fit is exact all the same,
and silent: the hand goes into the last links' parameters, and a consistent fit pulled
towards a description without it puts it on them (about 0.5 kg more on link 7 and 0.2 kg
on link 6 of an FR3). The torque route names such a mass from the identified model's gravity
torques against the description's (:func:`~.gravity_scale.flange_mass`); here the data's
own ``g`` is set against the description's (or the prior's) at the data's configurations
(:func:`static_flange_mass`), and an identified model's gravity torques at configurations
spread over the joint limits (:func:`model_flange_mass`). A mass is named when the difference
is at least :data:`~.gravity_scale.DESCRIBED` of the description's gravity torques (the error
even a good description's masses keep) and a point mass at the last link leaves at most a
tenth of it; the sentence (:func:`flange_words`) names it with where to go next.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..dynamics.terms import gravity_torques
from ..model.robot import Robot
from .gravity_scale import DESCRIBED, flange_mass_of
from .model import IdentifiedModel
from .model_sign import gravity_loaded

__all__ = [
    "FlangeMass",
    "data_flange_note",
    "flange_words",
    "model_flange_mass",
    "model_flange_note",
    "static_flange_mass",
]

#: Configurations at which an identified model's gravity torques are judged
#: (:func:`model_flange_mass`), uniform within the joint limits, seeded.
MODEL_SAMPLES = 200


@dataclass(frozen=True)
class FlangeMass:
    """A mass at the last link that makes up the gravity torques' difference.

    Attributes
    ----------
    mass : float
        [kg].
    com : ndarray, shape (3,)
        Its position [m] in the last link's frame.
    share : float
        The difference's RMS over the description's gravity torques' [-], on the joints
        gravity loads.
    """

    mass: float
    com: NDArray[np.float64]
    share: float


def static_flange_mass(
    reference: Robot, q: NDArray[np.float64], g: NDArray[np.float64]
) -> FlangeMass | None:
    """The mass at ``reference``'s last link whose gravity torques make up the gravity
    torques ``g`` (N, n) [N m] (static data's, for ``reference``'s gravity vector) less
    ``reference``'s at the configurations ``q`` (N, n) [rad], or None: no inertial
    parameters in ``reference``, a difference below :data:`~.gravity_scale.DESCRIBED` of
    its gravity torques, or one no point mass at the last link makes up
    (:func:`~.gravity_scale.flange_mass_of`)."""
    q = np.asarray(q, dtype=np.float64)
    if not np.any(reference.phi) or q.shape[0] < 2:
        return None
    loaded = gravity_loaded(reference, q)
    gd = gravity_torques(reference, q)[:, loaded]
    diff = np.asarray(g, dtype=np.float64)[:, loaded] - gd
    size = float(np.sum(gd * gd))
    share = float(np.sqrt(np.sum(diff * diff) / size)) if size > 0 else 0.0
    if not share >= DESCRIBED:
        return None
    found = flange_mass_of(reference, q, g)
    return None if found is None else FlangeMass(found[0], found[1], share)


def model_flange_mass(
    reference: Robot, model: IdentifiedModel, samples: int = MODEL_SAMPLES
) -> FlangeMass | None:
    """:func:`static_flange_mass` of ``model``'s gravity torques against ``reference``'s
    at ``samples`` configurations drawn uniformly within the joint limits (seeded; a
    joint without limits over one turn): the gravity torques an identified model holds
    wherever it was identified."""
    lo = np.where(np.isfinite(reference.q_min), reference.q_min, -np.pi)
    hi = np.where(np.isfinite(reference.q_max), reference.q_max, np.pi)
    q = np.random.default_rng(0).uniform(lo, hi, size=(samples, reference.n))
    return static_flange_mass(reference, q, model.gravity_torques(q))


def flange_words(reference: Robot, found: FlangeMass, against: str, source: str) -> str:
    """The note of the mass ``found``: ``source``'s gravity torques (``"the data's"``)
    are ``against``'s (``"the robot description's"``, ``"the prior's"``) plus its,
    naming it, what it may be and what to do."""
    at = ", ".join(f"{v if abs(v) >= 5e-4 else 0.0:+.3f}" for v in found.com)  # no -0.000
    return (
        f"{source} gravity torques are {against} plus those of a mass of about "
        f"{found.mass:.3g} kg at ({at}) m in {reference.link_names[-1]}'s frame (the "
        f"difference {100 * found.share:.3g} % of {against}): a hand or a tool the "
        "controller's model holds and the description lacks (the built-in panda and fr3 "
        "hold none), or its last links heavier than described (gravity alone cannot tell "
        "them apart); the identified parameters carry it, and a consistent fit puts it on "
        "the last links; hint: `dynid payload` on the static data weighs it (its "
        "robot_with_payload.toml is the description carrying it: give it as --prior, or "
        "--robot), or give a description that holds the tool"
    )


def _reference(robot: Robot, prior: Robot | None) -> tuple[Robot, str]:
    """``robot`` (its kinematics and gravity vector) with ``prior``'s inertials when one
    is given, and how the note calls it."""
    if prior is None:
        return robot, "the robot description's"
    return robot.with_params(prior.phi), "the prior's"


def data_flange_note(
    robot: Robot, q: NDArray[np.float64], g: NDArray[np.float64], prior: Robot | None = None
) -> str | None:
    """The note (:func:`flange_words`) of static data's gravity torques ``g`` (N, n) [N m]
    at ``q`` (N, n) [rad] of ``robot`` against its description's, or ``prior``'s
    inertials where one is given (:func:`static_flange_mass`); None: no mass named."""
    reference, against = _reference(robot, prior)
    found = static_flange_mass(reference, q, g)
    return None if found is None else flange_words(reference, found, against, "the data's")


def model_flange_note(model: IdentifiedModel, prior: Robot | None = None) -> str | None:
    """The note (:func:`flange_words`) of the identified ``model``'s gravity torques
    against its description's, or ``prior``'s inertials where one is given
    (:func:`model_flange_mass`); None: no mass named."""
    reference, against = _reference(model.description, prior)
    found = model_flange_mass(reference, model)
    return (
        None if found is None else flange_words(reference, found, against, "the identified model's")
    )
