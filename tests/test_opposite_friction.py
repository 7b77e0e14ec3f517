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

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.friction.model import ClassicalFriction
from dynid.identification.recorded_signs import opposite_friction_among
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
    assert said is not None and said.startswith("b.csv: the torques of motor 5 read of the opp")
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
    assert said is not None and said.startswith("c.csv: the torques of joint7 read"), said
    assert "--units c.csv:tau7=-1" in said, said
