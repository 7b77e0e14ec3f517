"""Columns of a log recorded reversed: several joints at once, and a motor-side log's motors.

References: simulated Panda recordings with known friction, rotor inertias and sensor
noise (the truth), the same recordings with chosen columns negated; a geared Panda with
a coupled wrist (motor 7 turns with joint 6) whose log holds motor positions and currents
through a drive file's transmission and torque constants.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.friction.model import ClassicalFriction
from dynid.identification.log import TorqueLog
from dynid.identification.model_sign import opposite_sign
from dynid.identification.recorded_signs import reversed_joint
from dynid.identification.recordings import prepare_recordings
from dynid.io.columns import load_mapped_torque_log, parse_column_map
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive

from conftest import GEARED_NOISE, geared_recordings, recordings


def _negated(log: TorqueLog, motion: list[int], torque: list[int]) -> TorqueLog:
    """``log`` with the position and velocity columns ``motion`` and the effort columns
    ``torque`` (from 0) negated, as a sensor mounted the other way records them."""
    m, t = np.ones(log.n), np.ones(log.n)
    m[motion], t[torque] = -1.0, -1.0
    return TorqueLog(log.t, log.q * m, log.dq * m, log.tau * t)


def _geared(seed: int) -> tuple[TorqueLog, Drive]:
    """A 3 s motor-side current log of the geared Panda with its coupled wrist, and the
    drive file's drive it is read through (:func:`conftest.geared_recordings`)."""
    (log,), drive = geared_recordings(dynid.panda(), (seed,))
    return log, drive


def test_two_joints_recorded_reversed_are_named_with_one_hint(panda, tmp_path):
    """A Panda log with joints 2 and 5 recorded reversed (position, velocity and torque):
    both are named, one --units hint lists both, and the log read back through that hint
    is the log as recorded the right way (not questioned); the clean log names nothing."""
    fr = ClassicalFriction(np.full(7, 0.3), np.full(7, 0.4), np.zeros(7))
    kw = dict(friction=fr, armature=np.full(7, 0.2), duration=3.0, noise=GEARED_NOISE)
    (right,) = recordings(panda, (91,), **kw)
    assert reversed_joint(panda, right) is None
    rev = _negated(right, [1, 4], [1, 4])
    said = reversed_joint(panda, rev)
    assert said is not None and said.startswith("joint2, joint5 look recorded reversed"), said
    hint = "--units q2=-1,tau2=-1,q5=-1,tau5=-1 reads them so"
    assert hint in said, said
    save_torque_log(tmp_path / "rev.csv", rev)
    entries = hint.split()[1] + ",dq2=-1,dq5=-1"
    back = load_mapped_torque_log(tmp_path / "rev.csv", parse_column_map(units=entries)).log
    np.testing.assert_allclose(back.q, right.q, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(back.tau, right.tau, rtol=1e-12, atol=1e-12)
    assert reversed_joint(panda, back) is None


@pytest.mark.parametrize("motors", [[5], [2, 5]])
def test_a_motor_recorded_reversed_is_named_in_the_logs_columns(panda, motors):
    """A motor-side log of currents of a geared Panda with a coupled wrist, motor 6 (which
    with the coupling moves joints 6 and 7) or motors 3 and 6 recorded reversed: the
    motors are named, the hint in the log's own columns (q6=-1,tau6=-1); identify's
    preparation refuses the log with it. The clean log names nothing, and every current
    negated is left to the sign check, which says so."""
    log, drive = _geared(92)
    assert reversed_joint(panda, log, drive) is None
    rev = _negated(log, motors, motors)
    said = reversed_joint(panda, rev, drive)
    names = ", ".join(f"motor {k + 1}" for k in motors)
    assert said is not None and said.startswith(f"{names} look"), said
    cols = ",".join(f"q{k + 1}=-1,tau{k + 1}=-1" for k in motors)
    assert f"--units {cols} reads" in said and "motor-side log" in said, said
    with pytest.raises(DataError, match=f"{names} looks? recorded reversed"):
        prepare_recordings(panda, [rev], ["rev.csv"], drive=drive)
    negated = _negated(log, [], list(range(7)))
    assert reversed_joint(panda, negated, drive) is None
    joint_side = dynid.identification.log.joint_side_log(negated, drive)
    assert opposite_sign(panda, joint_side) is not None


def test_a_motors_encoder_reversed_alone_is_told_from_its_current(panda):
    """Motor 3's encoder reversed alone (position and velocity, its current as recorded)
    on the geared arm: named as its position only, the hint q3=-1 without tau3."""
    log, drive = _geared(93)
    said = reversed_joint(panda, _negated(log, [2], []), drive)
    assert said is not None and said.startswith(
        "motor 3 looks recorded reversed: its position has the opp"
    )
    assert "--units q3=-1 reads it so" in said, said
