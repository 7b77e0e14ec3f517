"""One recording among several whose torque of a coupled wrist's motor has the opposite
sign: the motor's torque reaches two joints, so no joint's torque is negated, and friction
at the joint no motor turns alone is no motor's friction.

References: simulated recordings with known terms (the truth): the coupled-wrist tutorial's
six-axis arm, logged on the motor side through its drive (gear ratio 50 at motor 6, which
turns joint 5 too), with the description's sigmoid friction at the joints (as ``dynid
simulate`` puts it), the rotors' inertia and sensor noise; the same recordings with one
motor's torque column negated in one of them, the flipped file and motor known.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.friction.model import ClassicalFriction
from dynid.identification.recorded_signs import recording_sign_findings
from dynid.identification.recordings import prepare_recordings
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

PI = np.pi
NAMES = ["a.csv", "b.csv", "c.csv"]


def _arm() -> dynid.Robot:
    """The coupled-wrist tutorial's six-axis arm, with its sigmoid friction per joint."""
    return dynid.Robot.from_mdh(
        a=[0.0, 0.26, 0.68, 0.035, 0.0, 0.0],
        d=[0.675, 0.0, 0.0, 0.67, 0.0, 0.0],
        alpha=[0.0, -PI / 2, 0.0, -PI / 2, PI / 2, -PI / 2],
        flange=(0.0, 0.158, 0.0, 0.0),
        mass=[40.0, 35.0, 20.0, 10.0, 4.0, 1.0],
        com=[
            [0.0, -0.05, -0.15],
            [0.34, 0.0, 0.05],
            [0.0, 0.0, 0.02],
            [0.0, -0.25, 0.0],
            [0.0, 0.0, 0.01],
            [0.0, 0.0, 0.02],
        ],
        inertia=[
            [1.2, 0.0, 0.0, 1.1, 0.0, 0.8],
            [0.4, 0.0, 0.0, 1.6, 0.0, 1.5],
            [0.3, 0.0, 0.0, 0.3, 0.0, 0.1],
            [0.25, 0.0, 0.0, 0.05, 0.0, 0.25],
            [0.01, 0.0, 0.0, 0.01, 0.0, 0.008],
            [0.002, 0.0, 0.0, 0.002, 0.0, 0.003],
        ],
        q_min=[-2.9, -2.4, -2.0, -3.0, -2.0, -3.0],
        q_max=[2.9, 0.6, 2.6, 3.0, 2.0, 3.0],
        dq_max=[2.7, 2.7, 2.9, 5.0, 5.0, 7.0],
        ddq_max=[8.0, 8.0, 8.0, 15.0, 15.0, 20.0],
        tau_max=[1200.0, 1200.0, 700.0, 150.0, 150.0, 80.0],
        friction=dynid.SigmoidFriction.from_array([[8.0, 30.0, 0.0]] * 3 + [[2.0, 30.0, 0.0]] * 3),
        name="industrial",
    )


def _drive() -> Drive:
    """The tutorial's drive file: motor-side torques, motor 6 turning with joint 5."""
    return Drive.from_gears(
        [120.0, 120.0, 100.0, 70.0, 70.0, 50.0],
        [(6, 5, 50.0)],
        side="motor",
        offset=np.array([0.01, -0.02, 0.015, 0.0, 0.03, -0.01]),
        rotor_inertia=np.array([1.5e-4, 1.5e-4, 1.0e-4, 3.0e-5, 3.0e-5, 2.0e-5]),
    )


def _logs(robot: dynid.Robot, seeds, friction="robot"):
    """Noisy 3 s motor-side logs at 200 Hz of ``robot`` through :func:`_drive`."""
    t = sample_times(3.0, 200.0)
    return [
        simulate_measurement(
            robot,
            random_fourier(robot, np.random.default_rng(s))(t),
            rng=np.random.default_rng(s + 100),
            noise=SensorNoise(tau_std=0.05, q_std=1e-4, dq_std=1e-3),
            drive=_drive(),
            friction=friction,
        )
        for s in seeds
    ]


def _negated(log, column: int):
    """``log`` with the effort column ``column`` (from 0) negated."""
    sign = np.ones(log.n)
    sign[column] = -1.0
    return dataclasses.replace(log, tau=log.tau * sign)


@pytest.fixture(scope="module")
def wrist():
    """Three recordings of the arm, its friction at the joints (the description's)."""
    return _logs(_arm(), (1, 2, 3))


@pytest.mark.parametrize("motor", [5, 6])
@pytest.mark.parametrize("flipped", [0, 1])
def test_a_wrist_motor_negated_in_one_of_two_recordings_names_that_file(wrist, motor, flipped):
    """Motor 5 or 6 (both turn joint 5) negated in a.csv or in b.csv: that file and motor
    are named with the file's own --units entry, the clean file never (motor 6 had been
    fitted without a word: the joint friction no motor turns alone hid its sign)."""
    logs = list(wrist[:2])
    logs[flipped] = _negated(logs[flipped], motor - 1)
    found = recording_sign_findings(_arm(), logs, NAMES[:2], _drive())
    name, other = NAMES[flipped], NAMES[1 - flipped]
    assert [f.name for f in found] == [name], found
    said = found[0].text
    head = f"the torques of motor {motor} have the opposite sign to those of {other}"
    assert said.startswith(head), said
    assert f"--units {name}:tau{motor}=-1 reads it flipped" in said, said
    assert "a coupled wrist" in said, said


@pytest.mark.parametrize("motor", [5, 6])
def test_a_wrist_motor_negated_in_one_of_three_recordings_names_that_file(wrist, motor):
    """Motor 5 or 6 negated in c.csv of three: c.csv named against a.csv and b.csv."""
    logs = [*wrist[:2], _negated(wrist[2], motor - 1)]
    found = recording_sign_findings(_arm(), logs, NAMES, _drive())
    assert [f.name for f in found] == ["c.csv"], found
    said = found[0].text
    head = f"the torques of motor {motor} have the opposite sign to those of a.csv, b.csv"
    assert said.startswith(head), said
    assert f"--units c.csv:tau{motor}=-1 reads it flipped" in said, said


def test_clean_wrist_recordings_name_nothing_and_the_other_joints_are_named_as_before(wrist):
    """Two and three clean recordings (noise, joint friction, rotors) name nothing; motor 2
    or 4 (one joint each) negated in b.csv is named by the check against the model's
    torques, with b.csv's own entry, as before."""
    robot, drive = _arm(), _drive()
    assert recording_sign_findings(robot, wrist[:2], NAMES[:2], drive) == ()
    assert recording_sign_findings(robot, wrist, NAMES, drive) == ()
    for k in (2, 4):
        pair = [wrist[0], _negated(wrist[1], k - 1)]
        found = recording_sign_findings(robot, pair, NAMES[:2], drive)
        assert [f.name for f in found] == ["b.csv"], found
        assert f"--units b.csv:tau{k}=-1" in found[0].text, found[0].text


def test_identify_refuses_two_recordings_with_a_wrist_motor_negated_in_one(wrist):
    """identify's preparation refuses the trial's pair (motor 6 negated in b.csv) with
    b.csv's own --units entry, before any fit."""
    with pytest.raises(DataError, match=r"b\.csv:tau6=-1"):
        prepare_recordings(_arm(), [wrist[0], _negated(wrist[1], 5)], NAMES[:2], drive=_drive())


def test_a_wrist_disagreement_nothing_tells_names_both_files():
    """A description without inertial parameters and a wrist without friction (its rotors
    alone): motor 5 negated in b.csv is named as a disagreement of a.csv and b.csv with
    both --units entries, never a.csv alone; the pair as recorded names nothing."""
    truth = _arm()
    zero = np.zeros(6)
    fr = ClassicalFriction(np.r_[np.full(4, 2e-3), 0, 0], np.r_[np.full(4, 4e-2), 0, 0], zero)
    a, b = _logs(truth, (11, 12), friction=fr)
    bare = truth.with_params(np.zeros_like(truth.phi))
    assert recording_sign_findings(bare, [a, b], NAMES[:2], _drive()) == ()
    found = recording_sign_findings(bare, [a, _negated(b, 4)], NAMES[:2], _drive())
    assert [f.name for f in found] == ["a.csv, b.csv"], found
    said = found[0].text
    assert said.startswith("the torques of motor 5 have opposite signs in a.csv and b.csv"), said
    assert "--units a.csv:tau5=-1 or --units b.csv:tau5=-1" in said, said


def test_a_differential_wrist_motor_negated_in_one_of_two_recordings_names_that_file():
    """A differential wrist (motors 5 and 6 each turn joints 5 and 6, whose viscous friction
    the motors' spans): the clean pair names nothing, motor 6 negated in a.csv is named."""
    K = np.diag([120.0, 120.0, 100.0, 70.0, 50.0, -50.0])
    K[4, 5] = K[5, 4] = 50.0
    drive = dataclasses.replace(_drive(), transmission=K)
    robot = _arm()
    t = sample_times(3.0, 200.0)
    a, b = (
        simulate_measurement(
            robot,
            random_fourier(robot, np.random.default_rng(s))(t),
            rng=np.random.default_rng(s + 100),
            noise=SensorNoise(tau_std=0.05, q_std=1e-4, dq_std=1e-3),
            drive=drive,
        )
        for s in (21, 22)
    )
    assert recording_sign_findings(robot, [a, b], NAMES[:2], drive) == ()
    found = recording_sign_findings(robot, [_negated(a, 5), b], NAMES[:2], drive)
    assert [f.name for f in found] == ["a.csv"], found
    assert "--units a.csv:tau6=-1 reads it flipped" in found[0].text, found[0].text
