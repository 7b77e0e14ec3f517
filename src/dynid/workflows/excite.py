"""Design an exciting trajectory: the entry point of ``dynid excite``, with every policy the
command applies, so that the Python API behaves as the command does.

* The obstacles: a file's (``obstacles.json``), else the floor
  (:func:`~dynid.simulation.excitation.optimise_excitation`).
* The capsule radius and the clearances not given are scaled to the arm
  (:meth:`~dynid.simulation.excitation.ExcitationOptions.sized_for`); the summary says
  which were used and why, and names the links of a violated clearance.
* The trajectory is optimised from one seed and checked, and given sampled at 1 kHz (the
  rate of the checks and of ``trajectory.csv``).
* The torques checked include a drive's known rotor inertias (reflected through its
  gears: ``k^2 I_a ddq`` on an uncoupled joint); a drive that leaves them to be identified
  is said to leave them out of the torque margins.
* A trajectory that is not admissible is a result, not an error (``admissible`` is False;
  the command writes it for inspection and exits 1).
* Limits of the cell tighter than the robot's (``max_velocity``, ``max_acceleration``,
  ``max_torque``) replace its own, never loosen them (:func:`loosened_note`); a robot
  without acceleration limits (a URDF holds none) is warned of before the design
  (:func:`unlimited_warnings`).
* The optimiser's iterations are told to :mod:`dynid.progress` within the stage
  :data:`STAGE`; the time the design took is kept (``elapsed_s``) and said.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..friction.model import own_at_motors_note
from ..io.excitation import load_obstacles
from ..model.drive import Drive
from ..model.robot import Robot, checked_robot
from ..progress import stage
from ..simulation.collision import (
    DEFAULT_OBSTACLE_CLEARANCE,
    DEFAULT_RADIUS,
    DEFAULT_SELF_CLEARANCE,
    FULL_SIZE_CHAIN,
)
from ..simulation.excitation import (
    TIGHTENED,
    UNLIMITED_ACCELERATION,
    UNLIMITED_VELOCITY,
    ExcitationOptions,
    ExcitationResult,
    design_limits,
    not_tightened,
    optimise_excitation,
)
from .options import checked_options

__all__ = [
    "EXCITE_RATE_HZ",
    "STAGE",
    "ExcitationDesign",
    "design_excitation",
    "loosened_note",
    "unlimited_warnings",
]

#: What each option of :data:`~dynid.simulation.excitation.TIGHTENED` limits.
_WHAT = {"max_velocity": "velocity", "max_acceleration": "acceleration", "max_torque": "torque"}

#: The stage the design's progress is told in (:func:`dynid.progress.stage`).
STAGE = "exciting trajectory"

#: Rate of the sampled trajectory and of its checks [Hz].
EXCITE_RATE_HZ = 1000.0


#: The limits an exciting trajectory keeps a margin from, and their units.
MARGIN_UNITS = {"position": "rad", "velocity": "rad/s", "acceleration": "rad/s^2", "torque": "N m"}


def _margin(x: float, unit: str) -> str:
    """A margin with its unit, or ``(no limit)`` where the robot gives none."""
    return f"{x:.3g} {unit}" if np.isfinite(x) else "(no limit)"


@dataclass(frozen=True, slots=True, eq=False)
class ExcitationDesign:
    """Result of :func:`design_excitation`.

    Attributes
    ----------
    result : ExcitationResult
        The optimised trajectory, its condition numbers and its margins to every limit.
    samples : Trajectory
        The trajectory sampled at :data:`EXCITE_RATE_HZ`.
    seed : int
        The seed it was optimised from.
    obstacles_file : str or None
        The obstacles file's name (None: the default floor, ``z = 0`` of the base frame).
    elapsed_s : float
        Wall-clock time the design took [s] (NaN: not measured).
    """

    result: ExcitationResult
    samples: Any
    seed: int = field(default=0)
    obstacles_file: str | None = None
    elapsed_s: float = float("nan")

    def sampled(self, fs: float = EXCITE_RATE_HZ) -> Any:
        """The trajectory (``t, q, dq, ddq``) sampled at ``fs`` [Hz] over its whole
        duration, ramps included: :attr:`samples` at :data:`EXCITE_RATE_HZ`, the rate of
        the checks; another rate (a servo bus's 50 Hz goal positions) from the same series,
        so every sample keeps the limits the checks found kept between them."""
        if fs == EXCITE_RATE_HZ:
            return self.samples
        return self.result.trajectory.sample(fs)

    @property
    def admissible(self) -> bool:
        """Whether the trajectory keeps every limit and clearance."""
        return self.result.status != "infeasible"

    def describe(self, robot: Robot, name: Callable[[str], str] = str) -> tuple[str, ...]:
        """Two lines: the condition numbers, iterations and the time taken; the smallest
        margins; a third when the optimiser did not improve on its start
        (:meth:`start_note`); which regressor the condition number is of
        (:meth:`condition_line`); the limits given (:meth:`limits_line`); then the capsule
        radius and clearances used (:meth:`sizes_line`) and each clearance the result, or
        a start that mattered, violates (:meth:`clearance_lines`). Options are named by
        ``name`` (``str``: as the Python API names them)."""
        res, m = self.result, self.result.margins
        took = f", designed in {self.elapsed_s:.3g} s" if np.isfinite(self.elapsed_s) else ""
        first = (
            f"exciting trajectory for {robot.name}: {res.trajectory.total_duration:g} s, "
            f"condition number {res.condition_number:.4g} (unscaled; start "
            f"{res.initial_condition_number:.4g}), scaled {res.scaled_condition_number:.4g}, "
            f"{res.iterations} iterations, status {res.status}{took}"
        )
        o = res.options
        kept = (
            f"position {np.rad2deg(o.position_margin):.3g} deg, velocity "
            f"{np.rad2deg(o.velocity_margin):.3g} deg/s, acceleration "
            f"{100 * o.acceleration_margin:.3g} % and torque {100 * o.torque_margin:.3g} % "
            "of the limit"
        )
        second = (
            f"smallest margins at 1 kHz beyond those kept ({kept}; 0: at a kept margin): "
            + ", ".join(
                f"{name} {_margin(min(m[name]), unit)}" for name, unit in MARGIN_UNITS.items()
            )
            + f", self-collision {m['self_collision']:.3g} m"
            + "".join(f", {k} {v:.3g} m" for k, v in m["obstacles"].items())
        )
        note = self.start_note()
        head: tuple[str, ...] = (first, second) if note is None else (first, second, note)
        head += (self.condition_line(robot),)
        limits = self.limits_line(robot, name)
        head += () if limits is None else (limits,)
        drive = self.drive_line(name)
        head += () if drive is None else (drive,)
        at_motors = own_at_motors_note(robot, self.result.drive)
        head += () if at_motors is None else (at_motors,)
        ranges = self.ranges_line(robot, name)
        head += () if ranges is None else (ranges,)
        return head + (self.sizes_line(name),) + self.clearance_lines(name)

    def condition_line(self, robot: Robot) -> str:
        """Which regressor the condition numbers are of, and why ``identify``'s on a log
        of this trajectory differs (another matrix: its columns, rows and weights)."""
        r, n = self.result.n_base, robot.n
        return (
            f"condition number of [Y_b, F]: {r} base columns, viscous, Coulomb and offset "
            f"friction per joint ({3 * n} columns), on the trajectory's exact samples at "
            "200 Hz, rows unweighted (scaled: unit column norms); identify's on a log of it is "
            "of the structure it chooses (rotors, friction laws) on the log's filtered rows, "
            "each joint's divided by its noise under wls: its unscaled number differs most by "
            "that weighting, the scaled ones less"
        )

    def limits_line(self, robot: Robot, name: Callable[[str], str] = str) -> str | None:
        """The velocity, acceleration and torque limits given tighter than the robot's
        (``max_velocity``, ``max_acceleration``, ``max_torque``), as the design kept to
        them, or None when none was given."""
        o = self.result.options
        kept = design_limits(robot, o)
        parts, flags = [], []
        for k, (field_name, unit) in TIGHTENED.items():
            joints = sorted({j for j, _ in getattr(o, k)})
            if not joints:
                continue
            flags.append(name(k))
            limit = getattr(kept, field_name)
            parts.append(f"{_WHAT[k]} {_per_joint(robot, joints, limit, unit)}")
        if not parts:
            return None
        return (
            f"limits kept ({', '.join(flags)}, the smaller of each joint's own and the one "
            f"given; the margins kept inside them): {'; '.join(parts)}"
        )

    def ranges_line(self, robot: Robot, name: Callable[[str], str] = str) -> str | None:
        """The joint ranges the design kept to instead of the limits (given by
        ``ranges``), or None."""
        ranges = self.result.options.ranges
        if not ranges:
            return None
        return f"joint ranges kept ({name('ranges')}, instead of the limits): " + ", ".join(
            f"{robot.joint_names[j]} {lo:.3g}:{hi:.3g} rad" for j, lo, hi in ranges
        )

    def drive_line(self, name: Callable[[str], str] = str) -> str | None:
        """What the torques checked hold of the drive (given by ``drive``): its known
        rotor inertias' reflected torques and their largest, or that it leaves them to be
        identified and the torque margins leave them out; None without a drive."""
        drive = self.result.drive
        if drive is None:
            return None
        if drive.rotor_inertia is None:
            return (
                f"the drive ({name('drive')}) leaves its rotor inertias to be identified: the "
                "torques checked leave them out, and the torque margins are optimistic by "
                "their reflected torques (K^T diag(I_a) K ddq)"
            )
        ddq = np.asarray(self.samples.ddq)
        tau = np.abs(drive.rotor_torques(ddq, drive.rotor_inertia)).max(axis=0)
        j = int(np.argmax(tau))
        return (
            f"the torques checked include the drive's rotor inertias ({name('drive')}; "
            f"K^T diag(I_a) K ddq, largest {tau[j]:.3g} N m at joint {j + 1})"
        )

    def sizes_line(self, name: Callable[[str], str] = str) -> str:
        """The capsule radius and clearances used, which option sets each, and why: given,
        or the defaults scaled to the arm's chain
        (:func:`~dynid.simulation.collision.collision_sizes`)."""
        res, o = self.result, self.result.options
        radii = np.atleast_1d(np.asarray(o.radii, dtype=np.float64))
        radius = f"{radii[0]:.3g}" if np.ptp(radii) == 0 else f"{radii.min():.3g}-{radii.max():.3g}"
        parts = [
            ("radii", f"capsule radius {radius} m"),
            ("self_clearance", f"self-clearance {o.self_clearance:.3g} m"),
            ("obstacle_clearance", f"obstacle clearance {o.obstacle_clearance:.3g} m"),
        ]
        text = ", ".join(
            f"{what} ({'default' if k in res.derived else 'given'}, {name(k)})" for k, what in parts
        )
        s = res.sizes
        if not res.derived or s is None:
            return text
        full = f"the defaults for a chain of {FULL_SIZE_CHAIN:g} m or longer"
        if s.scale == 1.0:
            return f"{text}; {full} (this arm's is {s.chain_length:.3g} m)"
        return (
            f"{text}; {full} ({DEFAULT_RADIUS:g}, {DEFAULT_SELF_CLEARANCE:g}, "
            f"{DEFAULT_OBSTACLE_CLEARANCE:g} m) scaled by {s.scale:.3g}: this arm's chain is "
            f"{s.chain_length:.3g} m"
        )

    def clearance_lines(self, name: Callable[[str], str] = str) -> tuple[str, ...]:
        """One line per clearance the result violates, naming the links (or the link and
        the obstacle), their distance and the options that change it; the same for the
        start when the result is not admissible or the start was not improved on."""
        res = self.result
        lines = tuple(f"clearance violated: {a.describe(name)}" for a in res.violated_clearances())
        if not self.admissible or not res.improved:
            lines += tuple(
                f"the optimiser's start violates a clearance: {a.describe(name)}"
                for a in res.violated_clearances(start=True)
            )
        return lines

    def failure(self, robot: Robot, name: Callable[[str], str] = str) -> str:
        """Why no admissible trajectory was found, in one line: what is violated, the
        obstacles' planes used and where they come from, the rest position's clearance
        when it already violates one (then no amplitude helps), and what to change."""
        res = self.result
        text = (
            f"no admissible trajectory found (violated at 1 kHz: "
            f"{', '.join(res.violations())}; files written for inspection)"
        )
        if any(k.startswith("obstacles[") for k in res.violations()):
            text += f"; {self.planes_text(robot, name)}"
        if res.rest_clearances:
            near = ", ".join(
                f"{a.link} {-a.distance:.3g} m into {a.other}"
                if a.distance < 0
                else f"{a.link} {a.distance:.3g} m from {a.other} ({a.required:.3g} m required)"
                for a in res.rest_clearances
            )
            where = (
                f"lower it with {name('obstacles')} FILE holding "
                '{"schema": "dynid-obstacles/1", "planes": [{"name": "floor", "point": '
                f'[0, 0, Z], "normal": [0, 0, 1]}}]}} (Z in m in {robot.link_names[0]}\'s '
                "frame, below the arm)"
                if self.obstacles_file is None
                else f"move the obstacles in {self.obstacles_file} ({name('obstacles')})"
            )
            return (
                f"{text}; the rest position the design starts from already violates it "
                f"({near}); hint: {where}, or narrow the joint ranges to a rest position "
                f"clear of it ({name('ranges')} q1=LO:HI,...)"
            )
        return (
            f"{text}; hint: narrower joint ranges ({name('ranges')} q1=LO:HI,...; a joint "
            "that turns +-2 pi reaches the floor and the arm itself), fewer or smaller "
            f"obstacles ({name('obstacles')}), a smaller {name('radii')}, "
            f"{name('self_clearance')} or {name('obstacle_clearance')}, more "
            f"{name('max_iter')} or another {name('seed')}"
        )

    def planes_text(self, robot: Robot, name: Callable[[str], str] = str) -> str:
        """The obstacles' planes in the base frame and where they come from."""
        obs = self.result.obstacles
        where = (
            f"the default floor (no {name('obstacles')})"
            if self.obstacles_file is None
            else f"from {self.obstacles_file} ({name('obstacles')})"
        )
        planes = ", ".join(
            f"{n}: {_plane_text(p.point, p.normal)}"
            for n, p in zip(obs.names, obs.planes, strict=False)
        )
        base = robot.link_names[0]
        return f"obstacle planes {where}, in the base frame {base}: {planes or 'none'}"

    def start_note(self) -> str | None:
        """Why the result is not better than the optimiser's start, or None when it is."""
        res = self.result
        if res.improved:
            return None
        if res.start_admissible:  # then the result is the start itself
            return (
                "the optimiser did not improve on its start: the start, admissible, is "
                "returned unchanged"
            )
        start = (
            f"the optimiser's start (condition number {res.initial_condition_number:.4g}) "
            f"violates {', '.join(res.violations(start=True))}"
        )
        if not self.admissible:
            return f"not improved: {start}, and no admissible iterate was found"
        if res.status == "reduced":
            return (
                f"not better than the start: {start}; the result is the optimiser's "
                "trajectory with its amplitudes reduced until admissible (status reduced)"
            )
        return f"not better than the start: {start}; the result is the best admissible iterate"


def design_excitation(
    robot: Robot,
    options: ExcitationOptions | None = None,
    *,
    obstacles: str | Path | None = None,
    seed: int = 0,
    progress: Callable[[int, int, float], None] | None = None,
    evaluated: Callable[[int, int], None] | None = None,
    drive: Drive | None = None,
) -> ExcitationDesign:
    """An exciting trajectory for ``robot``, optimised and checked
    (:func:`~dynid.simulation.excitation.optimise_excitation`).

    Parameters
    ----------
    robot : Robot
    options : ExcitationOptions, optional
    obstacles : str or Path, optional
        An obstacles JSON (default: the floor).
    seed : int
        Seed of the starts of the optimisation.
    progress : callable, optional
        ``progress(iteration, total, condition_number)`` after each iteration.
    evaluated : callable, optional
        ``evaluated(evaluations, budget)`` after each evaluation of the objective.
    drive : Drive, optional
        The drive train: the torques checked include its known rotor inertias.

    Returns
    -------
    ExcitationDesign

    Raises
    ------
    DataError
        An unreadable obstacles file.
    """
    checked_robot(robot)
    options = checked_options(options, ExcitationOptions)
    obs = None if obstacles is None else load_obstacles(obstacles)
    start = time.monotonic()
    with stage(STAGE):
        res = optimise_excitation(
            robot,
            np.random.default_rng(seed),
            options,
            obstacles=obs,
            progress=progress,
            evaluated=evaluated,
            drive=drive,
        )
    file = None if obstacles is None else Path(obstacles).name
    samples = res.trajectory.sample(EXCITE_RATE_HZ)
    return ExcitationDesign(res, samples, seed, file, time.monotonic() - start)


def loosened_note(
    robot: Robot, options: ExcitationOptions, name: Callable[[str], str] = str
) -> str | None:
    """One line naming the limits given above the robot's own, which the design keeps at
    the robot's (the options tighten, never loosen), or None."""
    above = not_tightened(robot, options)
    if not above:
        return None
    units = {k: unit for k, (_, unit) in TIGHTENED.items()}
    groups: dict[tuple[str, float], list[tuple[int, float]]] = {}
    for k, j, v, own in above:
        groups.setdefault((k, v), []).append((j, own))
    items = "; ".join(
        f"{name(k)} {v:g} {units[k]} on {', '.join(robot.joint_names[j] for j, _ in js)} "
        f"(own {'/'.join(f'{own:g}' for own in dict.fromkeys(o for _, o in js))})"
        for (k, v), js in groups.items()
    )
    return (
        f"limits given above the description's own, kept at its own (these options only "
        f"tighten limits; a looser one is the description's to change): {items}"
    )


def unlimited_warnings(
    robot: Robot, options: ExcitationOptions, name: Callable[[str], str] = str
) -> tuple[str, ...]:
    """One line for the velocity, and one for the acceleration, limits that neither the
    robot (a URDF holds no acceleration limit) nor ``options`` give: the design then
    bounds them only by its own :data:`UNLIMITED_VELOCITY`,
    :data:`UNLIMITED_ACCELERATION` (on its 100 Hz grid) and the torque limits."""
    kept = design_limits(robot, options)
    out = []
    for k, field_name, what, bound, unit, item in (
        ("max_velocity", "dq_max", "velocity", UNLIMITED_VELOCITY, "rad/s", "dq"),
        ("max_acceleration", "ddq_max", "acceleration", UNLIMITED_ACCELERATION, "rad/s^2", "ddq"),
    ):
        free = [j for j in range(robot.n) if not np.isfinite(getattr(kept, field_name)[j])]
        if not free:
            continue
        where = (
            "on any joint"
            if len(free) == robot.n
            else "on " + ", ".join(robot.joint_names[j] for j in free)
        )
        out.append(
            f"the description has no {what} limits {where}: the design's {what}s are bounded "
            f"only by its own {bound:g} {unit} per joint and the torque limits (an arm's or "
            f"a cell's limits may be lower); hint: {name(k)} A ({unit}, every joint) or "
            f"{name(k)} {item}1=A,{item}2=B,..."
        )
    return tuple(out)


def _per_joint(robot: Robot, joints: list[int], limit: Any, unit: str) -> str:
    """``limit`` [unit] of ``joints``: one value for them all when they share it."""
    values = [float(limit[j]) for j in joints]
    if len(set(values)) == 1:
        which = (
            "every joint"
            if len(joints) == robot.n
            else ", ".join(robot.joint_names[j] for j in joints)
        )
        return f"{values[0]:.4g} {unit} on {which}"
    return (
        ", ".join(f"{robot.joint_names[j]} {v:.4g}" for j, v in zip(joints, values, strict=True))
        + f" {unit}"
    )


def _plane_text(point: tuple[float, ...], normal: tuple[float, ...]) -> str:
    """``z = -0.8`` for a horizontal plane, else its point and normal [m]."""
    if tuple(normal) == (0.0, 0.0, 1.0):
        return f"z = {point[2]:.3g} m"
    return (
        f"point {tuple(round(x, 3) for x in point)} m, normal {tuple(round(x, 3) for x in normal)}"
    )
