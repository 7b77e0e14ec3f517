"""Acquire static data from a simulated controller: the entry point of ``dynid
acquire-static``, with every policy the command applies, so that the Python API behaves as
the command does.

* One seed gives two independent streams: the configurations, then the noise
  (:func:`streams`); the effects outside the model come from ``[seed, 7]``.
* Random configurations within the joint limits less a margin, or (``pool``) the ``n`` of
  ``pool * n`` random collision-free ones that make the static regressor best conditioned,
  kept clear of the obstacles; obstacles without a pool are refused (random configurations
  are not checked against them).
* The data record the seed, the robot's kinematics, the effects and the pool's condition
  numbers (:meth:`~dynid.identification.static.StaticData.with_metadata`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import OptionError
from ..identification.consistency import kinematics_record
from ..model.robot import Robot, checked_robot
from ..simulation.controller import (
    DEFAULT_MARGIN,
    SimulatedController,
    acquire_static,
    acquire_static_at,
)
from .options import check_count, check_number, checked_options

__all__ = ["AcquireStaticOptions", "StaticAcquisition", "acquire_static_data", "streams"]


@dataclass(frozen=True, slots=True)
class AcquireStaticOptions:
    """How :func:`acquire_static_data` acquires static data.

    Attributes
    ----------
    n : int
        Number of configurations.
    noise : float
        Relative standard deviation of the multiplicative noise on M and g (>= 0).
    seed : int
        Seed of the configurations, the noise and the effects outside the model.
    margin : float
        Distance kept from the joint limits [rad] (>= 0).
    pool : int, optional
        Choose the ``n`` configurations from ``pool * n`` random collision-free ones
        (>= 2).
    obstacles : str or Path, optional
        With ``pool``: an obstacles JSON the chosen configurations are kept clear of.
    unmodelled : bool
        Add effects outside the rigid-body model (rotor inertia on M's diagonal, a tilt).

    Raises
    ------
    OptionError
        A value out of its range; ``obstacles`` without ``pool`` (``field`` names it).
    """

    n: int = 1010
    noise: float = 0.0
    seed: int = 0
    margin: float = DEFAULT_MARGIN
    pool: int | None = None
    obstacles: str | Path | None = None
    unmodelled: bool = False

    def __post_init__(self) -> None:
        check_count(self, "n", optional=False)
        check_count(self, "seed", low=0, optional=False)
        check_count(self, "pool", low=2)
        for name in ("noise", "margin"):
            check_number(self, name, low_open=False, optional=False)
        if self.obstacles is not None and self.pool is None:
            raise OptionError(
                "needs {pool}: only the chosen configurations are kept clear of obstacles, "
                "random ones are not checked (give {pool} 5, say)",
                field="obstacles",
                others=("pool",),
            )


@dataclass(frozen=True, slots=True, eq=False)
class StaticAcquisition:
    """Result of :func:`acquire_static_data`.

    Attributes
    ----------
    data : StaticData
        The configurations with M(q) and g(q) as the controller reads them, and their record.
    selection : StaticSelection or None
        With ``pool``: the choice and its condition numbers.
    """

    data: Any
    selection: Any | None

    def describe(self) -> str | None:
        """One line on the choice from the pool (None without one)."""
        sel = self.selection
        if sel is None:
            return None
        n = self.data.n_configurations
        return (
            f"chose {n} of {sel.pool_size} configurations: condition number "
            f"{sel.condition_number:.4g} (unscaled; {sel.pool_condition_number:.4g} for "
            f"{n} random ones of the pool), scaled {sel.scaled_condition_number:.4g}"
        )


def streams(seed: int) -> tuple[np.random.Generator, np.random.Generator]:
    """Two independent generators from one seed: configurations, then noise."""
    a, b = np.random.SeedSequence(seed).spawn(2)
    return np.random.default_rng(a), np.random.default_rng(b)


def acquire_static_data(
    robot: Robot, options: AcquireStaticOptions | None = None
) -> StaticAcquisition:
    """M(q) and g(q) of ``robot`` read from a simulated controller at static configurations.

    Parameters
    ----------
    robot : Robot
    options : AcquireStaticOptions, optional

    Returns
    -------
    StaticAcquisition

    Raises
    ------
    DataError
        An unreadable obstacles file.
    """
    checked_robot(robot)
    opt = checked_options(options, AcquireStaticOptions)
    rng_q, rng_noise = streams(opt.seed)
    effects = None
    if opt.unmodelled:
        from ..simulation.unmodelled import UnmodelledEffects

        effects = UnmodelledEffects.typical(robot.n, np.random.default_rng([opt.seed, 7]))
    controller = SimulatedController(robot, opt.noise, rng=rng_noise, effects=effects)
    record: dict[str, Any] = {"seed": opt.seed, "kinematics": kinematics_record(robot)}
    if opt.pool is None:
        data = acquire_static(controller, opt.n, rng_q, margin=opt.margin)
        return StaticAcquisition(_with_effects(data.with_metadata(**record), effects), None)
    from ..io.excitation import load_obstacles
    from ..simulation.static_selection import select_static_configurations

    obstacles = None if opt.obstacles is None else load_obstacles(opt.obstacles)
    sel = select_static_configurations(
        robot, opt.n, rng_q, pool_factor=opt.pool, margin=opt.margin, obstacles=obstacles
    )
    data = acquire_static_at(controller, sel.q, margin=opt.margin)
    data = data.with_metadata(
        **record,
        pool_factor=opt.pool,
        condition_number=sel.condition_number,
        random_condition_number=sel.pool_condition_number,
    )
    return StaticAcquisition(_with_effects(data, effects), sel)


def _with_effects(data: Any, effects: Any) -> Any:
    """``data`` recording the effects outside the model (if any)."""
    return data if effects is None else data.with_metadata(unmodelled=effects.as_dict())
