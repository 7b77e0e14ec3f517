"""A simulated robot controller that answers ``M(q)`` and ``g(q)`` queries at rest.

Stand-in for the model library of the Panda's controller (libfranka's ``Model::mass`` and
``Model::gravity``), which Gaz et al. 2019 (Sec. IV-A) queried at 1010 static
configurations to identify the dynamic coefficients without moving the robot. The
simulated controller evaluates the inertia matrix and the gravity torques of a
ground-truth :class:`~dynid.model.robot.Robot` (by default the built-in Panda with the
published parameters), for that robot's gravity vector, optionally with noise.

Noise model (relative, multiplicative): every entry is multiplied by ``1 + eps z`` with
``eps = relative_noise`` and ``z`` standard normal, independent across entries and
configurations, except that ``M[i, j]`` and ``M[j, i]`` share their ``z`` so ``M`` stays
symmetric:

.. math:: \\tilde M_{ij} = M_{ij} (1 + \\epsilon z_{ij}), \\; z_{ij} = z_{ji}; \\qquad
          \\tilde g_i = g_i (1 + \\epsilon z_i)

A zero entry stays zero (``g1`` of the Panda stays at round-off level). Noise is drawn from the
controller's ``rng``, so the readings of a controller depend on the order of the queries;
two controllers built with equal seeds give equal readings for equal queries.

:func:`sample_configurations` draws configurations uniformly within the joint limits and
:func:`acquire_static` runs the acquisition into a
:class:`~dynid.identification.data.StaticDataset`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..dynamics.terms import gravity_torques, mass_matrix
from ..exceptions import LimitError, OptionError
from ..identification.data import StaticDataset
from ..model.panda import panda
from ..model.robot import Robot, checked_robot
from .trajectories import MAX_SAMPLES
from .unmodelled import UnmodelledEffects

__all__ = [
    "SimulatedController",
    "sample_configurations",
    "acquire_static",
    "acquire_static_at",
    "DEFAULT_MARGIN",
]

_log = logging.getLogger(__name__)

#: Default distance kept from each joint limit when sampling [rad] (or [m]).
DEFAULT_MARGIN = 0.05


@dataclass(frozen=True, slots=True, eq=False)
class SimulatedController:
    """Inertia matrices and gravity torques of a ground-truth robot, optionally noisy.

    Attributes
    ----------
    robot : Robot
        Ground truth: kinematics, standard parameters and gravity vector (default: the
        built-in Panda, :func:`dynid.panda`).
    relative_noise : float
        Relative standard deviation ``eps`` of the multiplicative noise (0: exact
        readings); see the module docstring.
    rng : numpy.random.Generator, optional
        Source of the noise; default ``np.random.default_rng(0)`` (reproducible).
    effects : UnmodelledEffects, optional
        Rotor inertia added to ``M`` and a tilted gravity in ``g`` (effects outside the
        rigid-body model, :mod:`dynid.simulation.unmodelled`); None: a rigid body.

    Raises
    ------
    ValueError
        ``relative_noise`` negative or not finite.
    """

    robot: Robot = field(default_factory=panda)
    relative_noise: float = 0.0
    rng: np.random.Generator | None = None
    effects: UnmodelledEffects | None = None

    def __post_init__(self) -> None:
        if self.effects is not None:
            self.effects.check(self.robot)
        eps = float(self.relative_noise)
        if not np.isfinite(eps) or eps < 0:
            raise OptionError(f"relative_noise must be finite and >= 0; got {self.relative_noise}")
        object.__setattr__(self, "relative_noise", eps)
        if self.rng is None:
            object.__setattr__(self, "rng", np.random.default_rng(0))

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.robot.n

    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]:
        """Reading of ``M(q)``: (..., n) -> (..., n, n) [kg m^2], symmetric."""
        M = mass_matrix(self.robot, q)
        if self.effects is not None:
            M = M + self.effects.mass_matrix_term()
        if self.relative_noise == 0.0:
            return M
        assert self.rng is not None  # set in __post_init__
        z = self.rng.standard_normal(M.shape)
        z = np.tril(z) + np.swapaxes(np.tril(z, -1), -1, -2)  # z_ij = z_ji
        return M * (1.0 + self.relative_noise * z)

    def gravity_torques(self, q: ArrayLike) -> NDArray[np.float64]:
        """Reading of ``g(q)``: (..., n) -> (..., n) [N m]."""
        truth = self.robot if self.effects is None else self.effects.true_robot(self.robot)
        g = gravity_torques(truth, q)
        if self.relative_noise == 0.0:
            return g
        assert self.rng is not None
        return g * (1.0 + self.relative_noise * self.rng.standard_normal(g.shape))

    def read(self, q: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(M(q), g(q))`` readings at the same configurations; shapes as the two methods."""
        return self.mass_matrix(q), self.gravity_torques(q)


def sample_configurations(
    robot: Robot,
    n: int,
    rng: np.random.Generator | None = None,
    *,
    margin: float = DEFAULT_MARGIN,
) -> NDArray[np.float64]:
    """Configurations drawn uniformly within the joint limits, away from them by ``margin``.

    Parameters
    ----------
    robot : Robot
    n : int
        Number of configurations (>= 1).
    rng : numpy.random.Generator, optional
        Default ``np.random.default_rng(0)`` (reproducible).
    margin : float
        Distance kept from each limit [rad or m]; joints without limits are sampled in
        ``[-pi, pi]``.

    Returns
    -------
    q : ndarray, shape (n, robot.n)
        Joint positions [rad or m].

    Raises
    ------
    ValueError
        ``n < 1``, ``n robot.n`` above :data:`~dynid.simulation.trajectories.MAX_SAMPLES`
        or ``margin < 0``.
    LimitError
        A joint's range is not wider than ``2 margin``.
    """
    checked_robot(robot)
    if int(n) != n or n < 1:
        raise OptionError(f"n must be a positive integer; got {n}")
    if n * robot.n > MAX_SAMPLES:
        raise OptionError(
            f"n = {n} configurations of {robot.n} joints are more than any memory holds "
            f"(at most {MAX_SAMPLES:.3g} values); give a smaller n"
        )
    if not np.isfinite(margin) or margin < 0:
        raise OptionError(f"margin must be finite and >= 0; got {margin}")
    rng = np.random.default_rng(0) if rng is None else rng
    lo = np.where(np.isfinite(robot.q_min), robot.q_min + margin, -np.pi)
    hi = np.where(np.isfinite(robot.q_max), robot.q_max - margin, np.pi)
    bad = np.flatnonzero(~(lo < hi))
    if bad.size:
        k = int(bad[0])
        raise LimitError(
            f"joint {robot.joint_names[k]} has range [{robot.q_min[k]}, {robot.q_max[k]}], not "
            f"wider than twice the margin {margin}; hint: use a smaller margin"
        )
    return rng.uniform(lo, hi, (int(n), robot.n))


def acquire_static(
    controller: SimulatedController,
    n: int = 1010,
    rng: np.random.Generator | None = None,
    *,
    margin: float = DEFAULT_MARGIN,
) -> StaticDataset:
    """Query a controller at ``n`` random static configurations (Gaz et al. 2019, Sec. IV-A).

    Parameters
    ----------
    controller : SimulatedController
    n : int
        Number of configurations (the paper used 1010).
    rng : numpy.random.Generator, optional
        Source of the configurations (the noise comes from the controller's own rng);
        default ``np.random.default_rng(0)``.
    margin : float
        Distance kept from the joint limits [rad], as in :func:`sample_configurations`.

    Returns
    -------
    StaticDataset
        ``q`` (n, dof) [rad], ``M`` (n, dof, dof) [kg m^2], ``g`` (n, dof) [N m]; metadata
        records the source, the robot name, the noise level and the margin.
    """
    controller = _checks.of_type(
        "controller",
        controller,
        SimulatedController,
        "a SimulatedController (SimulatedController(robot))",
    )
    q = sample_configurations(controller.robot, n, rng, margin=margin)
    return acquire_static_at(controller, q, margin=margin)


def acquire_static_at(
    controller: SimulatedController, q: ArrayLike, *, margin: float | None = None
) -> StaticDataset:
    """Query a controller at given static configurations ``q`` (N, dof) [rad].

    ``margin`` is recorded in the metadata only (e.g. the one the configurations were
    drawn with, :func:`dynid.simulation.static_selection.select_static_configurations`).
    """
    controller = _checks.of_type(
        "controller",
        controller,
        SimulatedController,
        "a SimulatedController (SimulatedController(robot))",
    )
    q = _checks.as_batch("q", q, (controller.robot.n,)).reshape(-1, controller.robot.n)
    _log.info("acquiring M(q) and g(q) at %d configurations", len(q))
    M, g = controller.read(q)
    meta = {
        "source": "simulated controller",
        "robot": controller.robot.name,
        "relative_noise": controller.relative_noise,
        "margin": margin,
    }
    return StaticDataset(q, M, g, meta)
