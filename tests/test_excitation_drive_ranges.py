"""Exciting trajectories with a drive's rotor inertias and with narrowed joint ranges.

An industrial arm's trial (gear ratios 51-141, a coupled wrist, joints turning +-2 pi):
``excite`` ignored the drive, so the torque check left out the rotor inertias reflected
through the gears (15.8 kg m^2 at the first joint) and printed an optimistic margin; and a
user could narrow the joints' ranges for the design only by editing the URDF.
"""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

import dynid
from dynid.cli.excite import parse_ranges
from dynid.dynamics.rnea import rnea
from dynid.exceptions import OptionError
from dynid.io.excitation import save_excitation_json
from dynid.io.robot.urdf import load_urdf
from dynid.model.drive import Drive
from dynid.simulation.excitation import (
    ExcitationOptions,
    _start,
    limit_margins,
    optimise_excitation,
    within_ranges,
)
from dynid.simulation.trajectories import Trajectory
from dynid.workflows.excite import ExcitationDesign

from conftest import SHORT_EXCITATION as SHORT
from conftest import SO101_URDF as SO101


def _sine(robot, amplitude=0.3, w=2.0):
    """Every joint swinging about its neutral position, 2 s at 200 Hz."""
    t = np.arange(400) / 200.0
    phase = np.arange(robot.n)
    q0 = robot.q_neutral if robot.q_neutral is not None else np.zeros(robot.n)
    q = q0 + amplitude * np.sin(w * t[:, None] + phase)
    dq = amplitude * w * np.cos(w * t[:, None] + phase)
    ddq = -amplitude * w**2 * np.sin(w * t[:, None] + phase)
    return Trajectory(t=t, q=q, dq=dq, ddq=ddq)


def _torques_closed_form(robot, tr, gears, ia, coupled):
    """Joint torques with the rotors written out: ``k_j^2 I_a,j ddq_j`` per joint, and for
    the motor ``m`` that also turns with joint ``j`` by ``c`` (``K[m, j] = c``), its
    inertia seen by both joints."""
    tau = rnea(robot, tr.q, tr.dq, tr.ddq)
    if robot.friction is not None:
        tau = tau + robot.friction.torques(tr.dq)
    ddq = np.asarray(tr.ddq)
    tau = tau + np.asarray(gears) ** 2 * np.asarray(ia) * ddq
    m, j, c = coupled  # 0-based motor, joint
    tau[:, j] += ia[m] * (c**2 * ddq[:, j] + c * gears[m] * ddq[:, m])
    tau[:, m] += ia[m] * c * gears[m] * ddq[:, j]
    return tau


def test_the_torque_margins_include_the_rotor_inertias_in_closed_form():
    """The torque margins with a geared, coupled drive of known rotor inertias are those
    of the closed form ``k^2 I_a ddq`` (plus the coupled motor's terms)."""
    panda = dynid.panda()
    gears = np.array([141.0, 121, 101, 81, 71, 51, 51])
    ia = np.array([8e-4, 8e-4, 5e-4, 3e-4, 2e-4, 1.2e-4, 1.2e-4])
    drive = Drive.from_gears(gears, [(7, 6, 25.0)], rotor_inertia=ia, friction_at="joint")
    tr = _sine(panda)
    o = ExcitationOptions()
    tau = _torques_closed_form(panda, tr, gears, ia, (6, 5, 25.0))
    want = (1 - o.torque_margin) * panda.tau_max - np.abs(tau).max(axis=0)
    got = limit_margins(panda, tr, o, drive=drive)["torque"]
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-9)
    bare = limit_margins(panda, tr, o)["torque"]
    assert bare[0] - got[0] > 10.0  # 141^2 x 8e-4 = 15.9 kg m^2 at joint 1: not negligible


def test_the_torque_margins_place_the_friction_where_the_drive_puts_it():
    """With a drive whose friction acts at the motors, the robot's friction law acts on
    the motors' velocities and reaches the joints through the gears: ``K^T f(K dq)``."""
    panda = dynid.panda()  # the sigmoid law of Gaz et al.
    K = Drive.from_gears(np.full(7, 50.0), [(7, 6, 10.0)]).transmission
    drive = Drive(transmission=K, offset=np.zeros(7), friction_at="motor")
    tr = _sine(panda)
    o = ExcitationOptions()
    tau = rnea(panda, tr.q, tr.dq, tr.ddq) + panda.friction.torques(np.asarray(tr.dq) @ K.T) @ K
    want = (1 - o.torque_margin) * panda.tau_max - np.abs(tau).max(axis=0)
    got = limit_margins(panda, tr, o, drive=drive)["torque"]
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-9)


def test_a_drive_that_identifies_its_rotors_leaves_them_out_and_says_so():
    """A drive without rotor inertias (to be identified) changes no margin, and the
    summary says the torque margins leave the rotors out."""
    panda = dynid.panda()
    drive = Drive.from_gears(np.full(7, 100.0), friction_at="joint")
    tr = _sine(panda)
    o = ExcitationOptions()
    assert limit_margins(panda, tr, o, drive=drive) == limit_margins(panda, tr, o)
    design = ExcitationDesign(SimpleNamespace(drive=drive), tr)  # type: ignore[arg-type]
    line = design.drive_line(lambda k: "--" + k)
    assert line is not None and "leave them out" in line and "--drive" in line
    assert ExcitationDesign(SimpleNamespace(drive=None), tr).drive_line() is None  # type: ignore[arg-type]


def test_range_text_names_joints_by_number_or_name():
    """``--range`` reads ``qJ=LO:HI`` items, qJ or J a number from 1 or a joint's name, and
    names a bad item, an unknown joint and a repeated one."""
    joints = ("pan", "lift", "elbow")
    assert parse_ranges("q1=-1.5:1.5, elbow=0.5:2.5", joints) == ((0, -1.5, 1.5), (2, 0.5, 2.5))
    assert parse_ranges("2=-1:0", joints) == ((1, -1.0, 0.0),)
    for text, said in [
        ("1=-1.5", "not qJ=LO:HI"),
        ("4=0:1", "no joint '4'"),
        ("wrist=0:1", "no joint 'wrist'"),
        ("1=a:1", "must be numbers"),
        ("1=0:1,pan=0:1", "given twice"),
    ]:
        with pytest.raises(OptionError, match=said):
            parse_ranges(text, joints)


def test_ranges_outside_the_limits_or_empty_are_refused():
    """A range beyond a joint's limits, reversed, or of a joint the robot lacks is an
    error naming --range."""
    panda = dynid.panda()
    with pytest.raises(OptionError, match="--range: joint 1's"):
        within_ranges(panda, ((0, -4.0, 0.0),))
    with pytest.raises(OptionError, match="--range"):
        within_ranges(panda, ((7, -1.0, 1.0),))
    with pytest.raises(OptionError, match="--range"):
        ExcitationOptions(ranges=((0, 1.0, -1.0),))


@pytest.fixture(scope="module")
def so101():
    """The SO-101's five arm joints, base to the gripper's frame."""
    return load_urdf(SO101, tip_link="gripper_frame_link", snap_angles=True)


#: The SO-101's drive for the design below: rotors that a 10 N m limit notices.
SO101_GEARS = np.array([100.0, 100.0, 100.0, 60.0, 60.0])
SO101_IA = np.array([2e-4, 2e-4, 2e-4, 1e-4, 1e-4])


@pytest.fixture(scope="module")
def so101_design(so101):
    """The SO-101 designed with the short options, its shoulder lift and elbow narrowed,
    with a geared drive of known rotor inertias (seed 0)."""
    drive = Drive.from_gears(SO101_GEARS, rotor_inertia=SO101_IA, friction_at="joint")
    ranges = ((1, -1.0, 1.0), (2, -1.2, 0.8))
    opts = ExcitationOptions(**SHORT, ranges=ranges)
    return optimise_excitation(so101, np.random.default_rng(0), opts, drive=drive)


def test_a_design_keeps_the_ranges_given(so101, so101_design):
    """The trajectory keeps each narrowed joint inside its range less the position
    margin at 1 kHz, and the others inside their limits."""
    res = so101_design
    assert res.status != "infeasible"
    q = np.asarray(res.trajectory.sample(1000.0).q)
    m = res.options.position_margin
    lo, hi = so101.q_min.copy(), so101.q_max.copy()
    lo[1], hi[1], lo[2], hi[2] = -1.0, 1.0, -1.2, 0.8
    assert np.all(q.min(axis=0) >= lo + m - 1e-9) and np.all(q.max(axis=0) <= hi - m + 1e-9)


def test_a_design_keeps_the_torques_with_the_rotors_in_closed_form(so101, so101_design):
    """The design's torques, rotors included by ``k^2 I_a ddq``, keep the torque limits
    less their margin at 1 kHz; the rotors' share is not negligible there."""
    res = so101_design
    tr = res.trajectory.sample(1000.0)
    rotor = SO101_GEARS**2 * SO101_IA * np.asarray(tr.ddq)
    tau = rnea(so101, tr.q, tr.dq, tr.ddq) + rotor
    if so101.friction is not None:
        tau = tau + so101.friction.torques(tr.dq)
    limit = (1 - res.options.torque_margin) * so101.tau_max
    assert np.all(np.abs(tau).max(axis=0) <= limit + 1e-9)
    assert np.abs(rotor).max() > 0.5  # N m: the check had something to include


def test_trajectory_json_records_the_ranges_and_the_drive(so101, so101_design, tmp_path):
    """trajectory.json records the ranges given, its limits are those kept (the robot's
    beside them), and the drive with its rotor inertias."""
    path = save_excitation_json(tmp_path / "trajectory.json", so101_design, so101, seed=0)
    d = json.loads(path.read_text())
    name = so101.joint_names[2]
    assert d["ranges"][name] == {"joint": 3, "lo_rad": -1.2, "hi_rad": 0.8}
    assert d["limits"]["q_min_rad"][2] == -1.2 and d["limits"]["q_max_rad"][1] == 1.0
    assert d["robot_limits"]["q_min_rad"] == so101.q_min.tolist()
    np.testing.assert_allclose(d["drive"]["rotor_inertia"], SO101_IA)


class _Candidates:
    """A stand-in for the optimisation's problem: each variable vector ``x`` is a
    candidate whose criterion is ``x[0]`` and whose penalty (torques, clearances) is
    ``x[1]``; full-amplitude candidates violate, those at a fraction below 0.5 are clear
    but less exciting."""

    n, L = 1, 1
    opts = SimpleNamespace(n_starts=4)

    def initial(self, raw, offset, fraction=1.0):
        return np.array([2.0 - fraction, 0.0 if fraction < 0.5 else 1.0])

    def coefficients(self, x):
        return x, None

    def penalty(self, x, _):
        return 100.0 * x[1]

    def objective(self, x):
        return x[0] + self.penalty(x, None) * 1e-3  # a violation cheaper than excitation


def test_a_start_that_must_be_reduced_is_one_clear_of_the_floor_and_itself():
    """Regression (an arm of +-2 pi joints: the optimiser's start, the best candidate by
    criterion plus penalty, went 0.44 m into the floor): when no full-amplitude candidate
    keeps the torques and clearances, a reduced one that keeps them (by the penalty the
    optimiser's constraints use) is chosen over a more exciting one that does not."""
    prob = _Candidates()
    x0 = _start(prob, np.random.default_rng(0))  # type: ignore[arg-type]
    assert prob.penalty(*prob.coefficients(x0)) == 0
    assert x0[0] == pytest.approx(2.0 - 0.4)  # the most exciting of the clear ones
