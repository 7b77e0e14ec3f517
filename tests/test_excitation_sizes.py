"""Capsule radius and clearances scaled to the arm, and clearances named by their links.

A hobby arm (an SO-101, links of a few centimetres) was refused by ``dynid excite`` with the
Panda's fixed 0.06 m capsules, 2 cm between links and 5 cm to the floor: infeasible by
construction, the colliding pair unnamed. The arm here is the Panda scaled down 10 x
(lengths x 0.1, masses x 1e-3, torque limits x 1e-4), whose shoulder stands 3.3 cm above
the floor.
"""

from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.io.excitation import load_trajectory
from dynid.io.robot.toml import save_toml
from dynid.kinematics.forward import link_poses
from dynid.simulation.clearance import closest_approaches
from dynid.simulation.collision import (
    Obstacles,
    Plane,
    capsule_model,
    collision_sizes,
    obstacle_distances,
    self_distances,
)
from dynid.simulation.excitation import (
    STATUSES,
    ExcitationOptions,
    ExcitingTrajectory,
    _admissible_version,
    optimise_excitation,
)
from dynid.workflows.excite import ExcitationDesign

#: The Panda's chain, base to flange, from its MDH table (link 4 is an L: 0.384 by 0.0825).
PANDA_CHAIN = 0.333 + 0.316 + 0.0825 + float(np.hypot(0.384, 0.0825)) + 0.088 + 0.107
SHORT = {"duration": 4.0, "harmonics": 3, "base_frequency": 0.25, "max_iter": 3, "n_starts": 4}
# one start, one iteration: enough where the rest position itself is in collision (the
# failure and its text are those of SHORT, at a third of its time)
AT_ONCE = {**SHORT, "max_iter": 1, "n_starts": 1}


def _scaled_panda(s: float) -> dynid.Robot:
    """The Panda with every length times ``s``, masses times s^3, first moments s^4,
    inertias s^5 and torque limits s^4 (gravity torques scale as s^4), without friction."""
    p = dynid.panda()
    T = np.array(p.T_parent_joint)
    T[:, :3, 3] *= s

    def scaled(frame):
        M = np.array(frame.T_link_frame)
        M[:3, 3] *= s
        return dataclasses.replace(frame, T_link_frame=M)

    phi = np.array(p.phi) * np.array([s**3] + [s**4] * 3 + [s**5] * 6)
    return p.replace(
        name="panda_tenth",
        T_parent_joint=T,
        phi=phi,
        tau_max=np.array(p.tau_max) * s**4,
        friction=None,
        frames={k: scaled(f) for k, f in p.frames.items()},
    )


def test_the_panda_and_fr3_keep_their_radius_and_clearances():
    """0.06 m capsules, 2 cm between links, 5 cm to obstacles, and the same pairs checked as
    before the pairs' rule counted the clearance (their chain, 1.32 m, is over 1.3 m)."""
    for robot in (dynid.panda(), dynid.fr3()):
        sizes = collision_sizes(robot)
        assert (sizes.radius, sizes.self_clearance, sizes.obstacle_clearance) == (0.06, 0.02, 0.05)
        assert sizes.scale == 1.0 and sizes.chain_length == pytest.approx(PANDA_CHAIN, abs=1e-12)
        opts = ExcitationOptions().sized_for(robot)
        assert (opts.radii, opts.self_clearance, opts.obstacle_clearance) == (0.06, 0.02, 0.05)
        caps = capsule_model(robot, clearance=0.02)
        assert np.all(caps.radii == 0.06)
        np.testing.assert_array_equal(caps.pairs, capsule_model(robot, 0.06).pairs)


def test_a_tenth_size_panda_gets_a_tenth_of_the_sizes_roughly():
    """Scale = chain / 1.3 m, from the MDH constants: 0.1 x 1.319 / 1.3 = 0.1015."""
    sizes = collision_sizes(_scaled_panda(0.1))
    scale = 0.1 * PANDA_CHAIN / 1.3
    assert sizes.scale == pytest.approx(scale, rel=1e-12)
    assert sizes.radius == pytest.approx(0.06 * scale, rel=1e-12)
    assert sizes.self_clearance == pytest.approx(0.02 * scale, rel=1e-12)
    assert sizes.obstacle_clearance == pytest.approx(0.05 * scale, rel=1e-12)


def test_the_panda_sizes_are_infeasible_by_construction_on_a_tenth_size_panda():
    """Regression (SO-101 trial): the fixed 0.06 m capsule of link 2 starts at the shoulder,
    0.0333 m above the floor, which is 0.0267 m into it in every configuration; the scaled
    ones leave it 0.0272 m clear, more than the 0.0051 m required."""
    robot = _scaled_panda(0.1)
    sizes = collision_sizes(robot)
    q = np.random.default_rng(7).uniform(robot.q_min, robot.q_max, (200, robot.n))

    def floor(r):
        return obstacle_distances(robot, q, Obstacles.floor(), capsule_model(robot, r))[:, 0]

    assert np.all(floor(0.06) <= 0.0333 - 0.06 + 1e-12)  # the shoulder is on capsule 2
    rest = obstacle_distances(
        robot, robot.q_neutral, Obstacles.floor(), capsule_model(robot, sizes.radius)
    )
    assert rest[0] == pytest.approx(0.0333 - sizes.radius, abs=1e-12)
    assert rest[0] > sizes.obstacle_clearance


def test_a_chain_of_no_length_keeps_the_defaults_and_a_slide_counts_its_stroke():
    """Regression: a one-joint arm at the base's origin got radius 0 ("radii must be
    positive"). Its sizes are the defaults (scale 1); an x-z gantry of two 0.4 m strokes at
    the origin is 0.8 m long (scale 0.8 / 1.3)."""
    one = dynid.Robot.from_mdh([0.0], [0.0], [0.0], q_min=[-1.0], q_max=[1.0])
    assert collision_sizes(one).scale == 1.0 and collision_sizes(one).radius == 0.06
    gantry = dynid.Robot.from_mdh(
        [0.0, 0.0],
        [0.0, 0.0],
        [0.0, -np.pi / 2],
        joint_types="PP",
        q_min=[0.0, 0.0],
        q_max=[0.4, 0.4],
    )
    sizes = collision_sizes(gantry)
    assert sizes.chain_length == pytest.approx(0.8, abs=1e-12)
    assert sizes.radius == pytest.approx(0.06 * 0.8 / 1.3, rel=1e-12)


@pytest.fixture(scope="module")
def tenth_panda_design():
    """The tenth-size Panda designed with the default sizes (short options), seed 0."""
    robot = _scaled_panda(0.1)
    return robot, optimise_excitation(robot, np.random.default_rng(0), ExcitationOptions(**SHORT))


def test_a_tenth_size_panda_is_designed_with_positive_margins_by_default(tenth_panda_design):
    """Admissible with the scaled sizes, checked here at 1 kHz from the capsules' own
    distances; the summary says the sizes are the defaults scaled by 0.101."""
    robot, res = tenth_panda_design
    assert res.status in ("ok", "reduced") and res.derived == (
        "radii",
        "self_clearance",
        "obstacle_clearance",
    )
    o = res.options
    assert o.radii == pytest.approx(0.06 * 0.1 * PANDA_CHAIN / 1.3, rel=1e-12)
    q = res.trajectory.sample(1000.0).q
    caps = capsule_model(robot, o.radii)
    assert self_distances(robot, q, caps).min() >= o.self_clearance
    assert obstacle_distances(robot, q, Obstacles.floor(), caps).min() >= o.obstacle_clearance
    assert res.margins["self_collision"] > 0 and res.margins["obstacles"]["floor"] > 0
    line = ExcitationDesign(res, None).describe(robot)[-1]
    assert "capsule radius 0.00609 m (default, radii)" in line, line
    assert "scaled by 0.101: this arm's chain is 0.132 m" in line, line


def _planar_3r(l1: float, l2: float, l3: float) -> dynid.Robot:
    """A horizontal planar 3R arm (axes along z), links along x."""
    return dynid.Robot.from_mdh(
        [0.0, l1, l2],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        flange=(l3, 0.0, 0.0, 0.0),
        mass=[1.0, 1.0, 1.0],
        com=np.zeros((3, 3)),
        inertia=np.stack([0.01 * np.eye(3)] * 3),
        name="planar3r",
    )


def test_closest_approaches_name_the_links_at_the_closed_form_distance():
    """Planar 3R (l1, l2, l3) = (0.3, 0.1, 0.2), radius r: folded at (0, 90, 135) deg, link 3
    crosses link 1 (at x = 0.2), a signed distance -2 r (l2 - 2 r at the other samples);
    stretched, link 3 ends at x = 0.6, X - 0.6 - r from the plane x = X. Each named with
    its time."""
    l1, l2, l3, r, X = 0.3, 0.1, 0.2, 0.03, 0.7
    robot = _planar_3r(l1, l2, l3)
    caps = capsule_model(robot, r)
    q = np.deg2rad([[0.0, 0.0, 0.0], [0.0, 45.0, 45.0], [0.0, 90.0, 135.0]])
    wall = Obstacles(planes=(Plane((X, 0.0, 0.0), (-1.0, 0.0, 0.0)),), names=("wall",))
    (pair,), (near,) = closest_approaches(
        robot, [0.0, 1.0, 2.0], q, caps, wall, self_clearance=0.05, obstacle_clearance=0.02
    )
    assert (pair.link, pair.other, pair.obstacle, pair.t) == ("link1", "link3", False, 2.0)
    assert pair.distance == pytest.approx(-2 * r, abs=1e-12)
    assert pair.margin == pytest.approx(-2 * r - 0.05, abs=1e-12)
    assert (near.link, near.other, near.obstacle, near.t) == ("link3", "wall", True, 0.0)
    assert near.distance == pytest.approx(X - (l1 + l2 + l3) - r, abs=1e-12)
    text = pair.describe()
    assert "link1 and link3 0.06 m into each other at t = 2 s, 0.05 m required (-0.11 m)" in text
    assert text.endswith("change with radii or self_clearance"), text


def _floor_distance_by_hand(robot, q, radius):
    """Lowest z of capsules 2..n (their end points: link origins and the flange) minus the
    radius, and the capsule it belongs to, from the link poses."""
    T = link_poses(robot, q)
    fl = robot.frames["flange"]
    ends = np.concatenate([T[:, :, :3, 3], (T[:, fl.link] @ fl.T_link_frame)[:, None, :3, 3]], 1)
    z = np.minimum(ends[:, 2:-1, 2], ends[:, 3:, 2])  # capsule k: ends k and k + 1
    k = int(np.argmin(z.min(axis=0)))
    return float(z.min()) - radius, robot.link_names[k + 2]


def test_an_infeasible_design_names_the_link_the_distance_and_the_options(tmp_path, capsys):
    """Regression (SO-101 trial): ``excite`` said "self_collision -0.103" with no pair and
    no option. On the tenth-size Panda with the Panda's sizes given, exit 1 names link 2 and
    the floor with the distance computed here from the link poses, and the flags."""
    robot = _scaled_panda(0.1)
    path = tmp_path / "tenth.toml"
    save_toml(path, robot)
    out = tmp_path / "e"
    args = ["excite", "--robot", str(path), "--duration", "2", "--harmonics", "2"]
    args += ["--base-frequency", "0.5", "--max-iter", "1", "--seed", "3", "--no-figure"]
    args += ["--radius", "0.06", "--obstacle-clearance", "0.05", "--out", str(out)]
    assert main(args) == 1
    text, err = capsys.readouterr()
    doc = json.loads((out / "trajectory.json").read_text())
    closest = doc["smallest_margins_at_1khz"]["closest"]
    floor = next(c for c in closest if c.get("obstacle") == "floor")
    tr = load_trajectory(out / "trajectory.json", robot.n)
    d, link = _floor_distance_by_hand(robot, tr.q, 0.06)
    assert floor["link"] == link == "link2" and floor["distance_m"] == pytest.approx(d, abs=1e-9)
    assert f"obstacles[floor] {d - 0.05:.3g} (link2)" in err, err
    line = next(x for x in text.splitlines() if x.startswith("clearance violated: link2"))
    assert f"link2 and obstacle floor {abs(d):.3g} m into each other" in line, line
    assert line.endswith("change with --radius or --obstacle-clearance or --obstacles"), line
    assert "capsule radius 0.06 m (given, --radius)" in text
    assert "self-clearance 0.00203 m (default, --self-clearance)" in text


def test_excite_help_explains_every_status(capsys):
    """Each status the design can end with has its own paragraph in ``excite --help``."""
    assert main(["excite", "--help"]) == 0
    text = capsys.readouterr().out
    for status in STATUSES:
        assert re.search(rf"^  {status} +\S", text, re.M), status


def test_a_rest_position_in_collision_is_drawn_toward_the_requested_start():
    """Regression (SO-101 trial): the optimiser's rest position had the elbow folded into
    the shoulder, and reducing the amplitudes about it never left the collision (status
    infeasible). Planar 3R resting with link 3 across link 1: the reduction draws the
    motion toward the stretched start until the links clear, checked here at 1 kHz."""
    robot = _planar_3r(0.3, 0.1, 0.2)
    opts = ExcitationOptions(duration=2.0, harmonics=1, base_frequency=0.5).sized_for(robot)
    folded = np.deg2rad([0.0, 90.0, 135.0])
    a = np.full((3, 1), 0.05)
    traj = ExcitingTrajectory(np.pi, a, np.zeros((3, 1)), folded, 2.0, 1.0)
    caps = capsule_model(robot, opts.radii, clearance=opts.self_clearance)
    reduced, margins, status = _admissible_version(
        robot, traj, opts, Obstacles(), caps, np.zeros(3)
    )
    assert status == "reduced" and margins["self_collision"] >= 0
    q = reduced.sample(1000.0).q
    assert self_distances(robot, q, caps).min() >= opts.self_clearance
    assert self_distances(robot, folded, caps).min() < 0  # the rest position it came from


def test_a_floor_through_the_rest_position_is_named_with_its_plane_and_how_to_move_it(tmp_path):
    """Regression (PR2 trial, --base torso_lift_link: the default floor z = 0 of the base
    passed through the shoulder; 'no admissible trajectory' hinted at ranges and seeds): the
    failure names the plane and where it comes from, the rest position's clearance, equal
    to the capsules' own distance there, and the file that moves it."""
    robot = _scaled_panda(0.1)
    opts = ExcitationOptions(**AT_ONCE, radii=0.06, self_clearance=0.02, obstacle_clearance=0.05)
    res = optimise_excitation(robot, np.random.default_rng(0), opts)
    assert res.status == "infeasible" and res.rest_clearances
    d = obstacle_distances(robot, res.rest, Obstacles.floor(), capsule_model(robot, 0.06))
    near = min(res.rest_clearances, key=lambda a: a.distance)
    assert near.distance == pytest.approx(float(d.min()), abs=1e-12)
    text = ExcitationDesign(res, res.trajectory.sample(100.0)).failure(robot)
    assert "the default floor (no obstacles), in the base frame" in text
    assert "floor: z = 0 m" in text and "rest position the design starts from" in text
    assert f"{near.link} {-near.distance:.3g} m into floor" in text
    assert '"point": [0, 0, Z]' in text and "max_iter" not in text
    # a floor from a file: named with its height, moved in that file
    path = tmp_path / "raised.json"
    plane = '{"name": "floor", "point": [0, 0, 0.05], "normal": [0, 0, 1]}'
    path.write_text(f'{{"schema": "dynid-obstacles/1", "planes": [{plane}]}}')
    from dynid.workflows.excite import design_excitation

    design = design_excitation(robot, ExcitationOptions(**AT_ONCE), obstacles=path)
    assert not design.admissible and design.result.rest_clearances
    text = design.failure(robot)
    assert "from raised.json (obstacles)" in text and "floor: z = 0.05 m" in text
    assert "move the obstacles in raised.json" in text
