"""One recording among several whose torques of a joint (motor) have the opposite sign,
where the links barely load it: told by that joint's own friction and rotor, which
dissipate and are positive in the others and not there.

References: simulated recordings with known friction, rotor inertias and sensor noise
(the truth): a geared Panda with a coupled wrist logged as motor currents through a drive
file, and the joint-side Panda with friction and armature; the same recordings with one
effort column negated in one of them.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.friction.model import ClassicalFriction
from dynid.identification.recorded_signs import (
    DISAGREE_SHARE,
    opposite_friction_among,
    recording_sign_findings,
)
from dynid.identification.recordings import prepare_recordings

from conftest import GEARED_NOISE, geared_recordings, recordings


def _negated(log, column: int):
    """``log`` with the effort column ``column`` (from 0) negated."""
    sign = np.ones(log.n)
    sign[column] = -1.0
    return dataclasses.replace(log, tau=log.tau * sign)


@pytest.fixture(scope="module")
def geared():
    """Two 3 s motor-side current logs of the geared Panda with its coupled wrist (motor
    friction and rotor inertias the description lacks), and the drive they are read by."""
    return geared_recordings(dynid.panda(), (71, 72))


def test_a_motor_of_the_opposite_sign_in_one_recording_is_named_with_its_files_entry(geared):
    """Motor 5's current negated in b.csv alone: named, with b.csv's own --units entry, and
    identify's preparation refuses the pair with it; the pair as recorded names nothing,
    and both recordings negated alike are left to the checks of one recording."""
    (a, b), drive = geared
    panda = dynid.panda()
    names = ["a.csv", "b.csv"]
    assert opposite_friction_among(panda, [a, b], names, drive) is None
    said = opposite_friction_among(panda, [a, _negated(b, 4)], names, drive)
    assert said is not None and said.startswith("b.csv: the torques of motor 5 have the opp")
    assert "--units b.csv:tau5=-1 reads it flipped" in said, said
    assert opposite_friction_among(panda, [_negated(a, 4), _negated(b, 4)], names, drive) is None
    with pytest.raises(DataError, match="b.csv:tau5=-1"):
        prepare_recordings(panda, [a, _negated(b, 4)], names, drive=drive)


def test_three_clean_joint_side_recordings_name_nothing_and_a_wrist_flip_is_named():
    """The Panda with friction and armature, three recordings: none named as recorded;
    joint 7's torque (the links barely load it) negated in the last is named."""
    panda = dynid.panda()
    fr = ClassicalFriction(np.full(7, 0.3), np.full(7, 0.4), np.zeros(7))
    logs = recordings(
        panda, (81, 82, 83), friction=fr, armature=np.full(7, 0.2), duration=3.0, noise=GEARED_NOISE
    )
    names = ["a.csv", "b.csv", "c.csv"]
    assert opposite_friction_among(panda, logs, names) is None
    said = opposite_friction_among(panda, [*logs[:2], _negated(logs[2], 6)], names)
    assert said is not None and said.startswith("c.csv: the torques of joint7 have"), said
    assert "--units c.csv:tau7=-1" in said, said


def _stribeck(log):
    """A Stribeck peak (0.6 x the Coulomb friction of :func:`_pair`, 0.08 rad/s) beside the
    simulated classical friction: torques [N m] (N, 7) at the log's velocities."""
    fc = np.array([0.6, 0.7, 0.5, 0.5, 0.35, 0.3, 0.25])
    return 0.6 * fc * np.exp(-((log.dq / 0.08) ** 2)) * np.tanh(log.dq / 0.01)


@pytest.fixture(scope="module")
def pair():
    """Two noisy 3 s recordings of a Panda carrying a 1.2 kg payload its description lacks,
    with viscous, Coulomb and Stribeck friction (the FR3 trial's)."""
    truth = dynid.panda().with_tool(
        np.eye(4),
        name="gripper",
        mass=1.2,
        com=(0.01, 0.0, 0.08),
        inertia=(0.006, 0, 0, 0.007, 0, 0.003),
    )
    fv = np.array([0.25, 0.3, 0.2, 0.2, 0.12, 0.1, 0.06])
    fc = np.array([0.6, 0.7, 0.5, 0.5, 0.35, 0.3, 0.25])
    fr = ClassicalFriction(fv, fc, np.zeros(7))
    return recordings(truth, (1, 2), friction=fr, duration=3.0, noise=GEARED_NOISE, added=_stribeck)


def _check_numbers(said: str, negated: str) -> None:
    """The finding's "N times better with <negated> (residual r of that as read)": r at
    most DISAGREE_SHARE, and N its inverse rounded to two digits."""
    m = re.search(
        rf"fit \S+ recordings (\S+) times better with {negated} \(residual (\S+) of", said
    )
    assert m is not None, said
    times, left = float(m[1].replace(",", "")), float(m[2])
    assert 0 < left <= DISAGREE_SHARE, said
    assert times == pytest.approx(1 / left, rel=0.1), said


def test_two_recordings_of_opposite_sign_on_a_wrist_joint_name_the_flipped_file(pair):
    """Two recordings, joint 7's torque negated in one (no majority to compare with): the
    description's torques and dissipating friction name that file, whichever it is, and
    identify's preparation refuses with its --units entry; the clean pair (a payload the
    description lacks, Stribeck friction, noise) names nothing (joint 2 of b.csv had been
    named, its own terms taking what the description lacks)."""
    panda = dynid.panda()
    a, b = pair
    names = ["a.csv", "b.csv"]
    assert recording_sign_findings(panda, [a, b], names) == ()
    for flipped, (x, y) in (("b.csv", (a, _negated(b, 6))), ("a.csv", (_negated(a, 6), b))):
        found = recording_sign_findings(panda, [x, y], names)
        assert [f.name for f in found] == [flipped], found
        said = found[0].text
        other = "a.csv" if flipped == "b.csv" else "b.csv"
        assert said.startswith(f"the torques of joint7 have the opposite sign to those of {other}")
        assert f"--units {flipped}:tau7=-1 reads it flipped" in said, said
        _check_numbers(said, f"{flipped}'s tau7 negated")
        assert f"agree with {other} (residual " in said, said
    with pytest.raises(DataError, match=r"b\.csv:tau7=-1"):
        prepare_recordings(panda, [a, _negated(b, 6)], names)


def test_two_recordings_of_opposite_sign_the_description_cannot_tell_name_both():
    """A description without inertial parameters and joint 7 without friction (its own
    rotor inertia alone): the two recordings' disagreement on joint 7 is named with both
    files and both --units entries, and identify's preparation refuses; the pair as
    recorded names nothing."""
    truth = dynid.panda()
    fr = ClassicalFriction(np.r_[np.full(6, 0.3), 0.0], np.r_[np.full(6, 0.4), 0.0], np.zeros(7))
    a, b = recordings(
        truth, (93, 94), friction=fr, armature=np.full(7, 0.2), duration=3.0, noise=GEARED_NOISE
    )
    bare = truth.with_params(np.zeros_like(truth.phi))
    names = ["a.csv", "b.csv"]
    assert recording_sign_findings(bare, [a, b], names) == ()
    found = recording_sign_findings(bare, [a, _negated(b, 6)], names)
    assert [f.name for f in found] == ["a.csv, b.csv"], found
    said = found[0].text
    assert said.startswith("the torques of joint7 have opposite signs in a.csv and b.csv")
    assert "--units a.csv:tau7=-1 or --units b.csv:tau7=-1" in said, said
    _check_numbers(said, "either file's tau7 negated")
    with pytest.raises(DataError, match="have opposite signs in a.csv and b.csv"):
        prepare_recordings(bare, [a, _negated(b, 6)], names)
