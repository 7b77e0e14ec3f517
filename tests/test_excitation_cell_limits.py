"""A cell's velocity, acceleration and torque limits for ``excite``, and what it says of them.

A trial on an xArm7 in a cell (1 rad/s and 3 rad/s^2 on every joint): only --range could be
given on the command line, and ``excite`` exited 0 "status ok" with velocities of 2.38
rad/s and accelerations of 7.44 rad/s^2 (the URDF holds no acceleration limit; the only
sign was "acceleration (no limit)" among the margins). --max-velocity, --max-acceleration
and --max-torque tighten the description's limits, the margins kept inside them; a
description without acceleration limits is warned of.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.cli.common import flag
from dynid.cli.excite import parse_limits
from dynid.exceptions import OptionError
from dynid.io.robot.urdf import load_urdf
from dynid.simulation.excitation import ExcitationOptions, design_limits
from dynid.workflows.excite import loosened_note, unlimited_warnings

from conftest import SO101_URDF as SO101

JOINTS = ("pan", "lift", "elbow")
#: A design short enough for a test: 1 s and 2 harmonics of 1 Hz, two iterations.
TINY = ["--duration", "1", "--harmonics", "2", "--base-frequency", "1", "--max-iter", "2"]


@pytest.fixture(scope="module")
def so101():
    """The SO-101's five arm joints, angles snapped (no acceleration limit, 10 rad/s, 10 N m)."""
    return load_urdf(SO101, tip_link="gripper_frame_link", snap_angles=True)


def _csv(path, n):
    """``t, q, dq, ddq`` (N, n each) of a trajectory.csv, read with numpy alone."""
    a = np.loadtxt(path, delimiter=",", skiprows=3)
    return a[:, 0], a[:, 1 : 1 + n], a[:, 1 + n : 1 + 2 * n], a[:, 1 + 2 * n :]


def test_the_given_limits_hold_on_the_trajectory_csv_the_command_wrote(tmp_path, capsys):
    """Regression (xArm7 trial: 2.38 rad/s against the cell's 1.0, 7.44 rad/s^2 against
    3.0): read back, trajectory.csv keeps |dq| <= V - 10 deg/s and |ddq| <= 0.9 A on every
    joint given (closed form: the documented margins), and the torques Pinocchio computes
    from its rows keep |tau| <= 0.9 T on the joint given a torque limit."""
    pin = pytest.importorskip("pinocchio")
    out = tmp_path / "e"
    args = ["excite", "--robot", str(SO101), "--tip", "gripper_frame_link", *TINY, "--seed", "2"]
    args += ["--max-velocity", "0.8,dq2=0.6", "--max-acceleration", "3", "--max-torque", "tau2=1"]
    assert main([*args, "--no-figures", "--out", str(out)]) == 0
    text, err = capsys.readouterr()
    t, q, dq, ddq = _csv(out / "trajectory.csv", 5)
    v = np.array([0.8, 0.6, 0.8, 0.8, 0.8]) - np.deg2rad(10.0)
    assert np.all(np.abs(dq).max(axis=0) <= v + 1e-12)
    assert np.abs(ddq).max() <= 0.9 * 3.0 + 1e-12
    model = pin.buildModelFromUrdf(str(SO101))
    model.gravity.linear[:] = [0.0, 0.0, -9.80665]
    data = model.createData()
    tau = np.array([pin.rnea(model, data, *x) for x in zip(q, dq, ddq, strict=True)])
    assert np.abs(tau[:, 1]).max() <= 0.9 * 1.0 + 1e-9
    # the written limits, the summary's line, and no warning of a missing acceleration limit
    d = json.loads((out / "trajectory.json").read_text())
    np.testing.assert_array_equal(d["limits"]["dq_max_rad_s"], [0.8, 0.6, 0.8, 0.8, 0.8])
    assert d["limits"]["ddq_max_rad_s2"] == [3.0] * 5 and d["limits"]["tau_max_nm"][1] == 1.0
    assert d["robot_limits"]["dq_max_rad_s"] == [10.0] * 5
    assert d["limits_given"]["max_velocity"]["shoulder_lift"] == 0.6
    assert "acceleration 3 rad/s^2 on every joint; torque 1 N m on shoulder_lift" in text
    assert "no acceleration limits" not in err


def test_the_summary_says_how_long_the_design_took_and_what_its_condition_number_is_of(
    tmp_path, capsys
):
    """Regression (46-139 s without a word of the time): the first line ends with the
    design's time, and a line says which regressor the condition number is of (the
    Panda's 43 base columns and 3 x 7 friction columns) and that identify's is of
    another; a robot without acceleration limits is warned of on stderr."""
    out = tmp_path / "p"
    assert main(["excite", *TINY, "--no-figures", "--out", str(out)]) == 0
    text, _ = capsys.readouterr()
    first = text.splitlines()[0]
    took = float(first.rsplit("designed in ", 1)[1].removesuffix(" s"))
    assert took > 0
    assert "[Y_b, F]: 43 base columns, viscous, Coulomb and offset friction per joint" in text
    assert "(21 columns)" in text and "divided by its noise under wls" in text


def test_a_description_without_acceleration_limits_is_warned_of_in_one_line(so101):
    """The SO-101's URDF holds no acceleration limit: one line says the design then bounds
    them only by its own 10 rad/s^2 and names --max-acceleration; none once it is given,
    and one naming only the joints left when some are given."""
    (line,) = unlimited_warnings(so101, ExcitationOptions(), flag)
    assert line.startswith("the description has no acceleration limits on any joint")
    assert "bounded only by its own 10 rad/s^2" in line and "hint: --max-acceleration" in line
    assert "\n" not in line
    every = ExcitationOptions(max_acceleration=tuple((j, 3.0) for j in range(5)))
    assert unlimited_warnings(so101, every, flag) == ()
    some = ExcitationOptions(max_acceleration=((0, 3.0), (1, 3.0)))
    (line,) = unlimited_warnings(so101, some, flag)
    assert "limits on elbow_flex, wrist_flex, wrist_roll:" in line


def test_a_limit_above_the_descriptions_is_not_loosened_and_said_in_one_line(so101):
    """--max-velocity 12 on an arm of 10 rad/s keeps 10 (never loosens), tightens the
    joints given less, and one line names the option, the joints and their own limit."""
    o = ExcitationOptions(max_velocity=((0, 12.0), (1, 12.0), (2, 4.0)), max_torque=((3, 11.0),))
    kept = design_limits(so101, o)
    np.testing.assert_array_equal(kept.dq_max, [10.0, 10.0, 4.0, 10.0, 10.0])
    np.testing.assert_array_equal(kept.tau_max, so101.tau_max)
    note = loosened_note(so101, o, flag)
    assert note is not None and "\n" not in note
    assert "only tighten" in note
    assert "--max-velocity 12 rad/s on shoulder_pan, shoulder_lift (own 10)" in note
    assert "--max-torque 11 N m on wrist_flex (own 10)" in note
    assert loosened_note(so101, ExcitationOptions(max_velocity=((0, 1.0),)), flag) is None


def test_limit_text_reads_one_value_for_every_joint_or_per_joint(so101):
    """``V`` for every joint, ``dqJ=V``, ``J=V`` or a joint's name per joint, and a value
    for every joint with the items overriding it; each bad item refused by name."""
    assert parse_limits("1", JOINTS, "--max-velocity", "dq") == ((0, 1.0), (1, 1.0), (2, 1.0))
    got = parse_limits("dq2=0.8, elbow=0.5", JOINTS, "--max-velocity", "dq")
    assert got == ((1, 0.8), (2, 0.5))
    got = parse_limits("1.0,ddq3=2", JOINTS, "--max-acceleration", "ddq")
    assert got == ((0, 1.0), (1, 1.0), (2, 2.0))
    assert parse_limits("1=4", JOINTS, "--max-torque", "tau") == ((0, 4.0),)
    assert parse_limits(None, JOINTS, "--max-torque", "tau") == ()
    for text, said in [
        ("dq4=1", "no joint 'dq4'"),
        ("dq1=a", "is not a number or J=V"),
        ("1,2", "two values for every joint"),
        ("dq1=1,pan=2", "given twice"),
        (",", "no value given"),
    ]:
        with pytest.raises(OptionError, match=said):
            parse_limits(text, JOINTS, "--max-velocity", "dq")
    with pytest.raises(OptionError, match=r"max_velocity \(--max-velocity\) must .* > 0"):
        ExcitationOptions(max_velocity=((0, -1.0),))
    slow = ExcitationOptions(max_velocity=((1, 0.1),))  # below the 10 deg/s kept inside
    with pytest.raises(OptionError, match="0.1 rad/s on joint 2 leaves no motion"):
        design_limits(so101, slow)
    with pytest.raises(OptionError, match="--max-acceleration: joint 9 of a robot of 5"):
        design_limits(so101, _nine())


def _nine() -> ExcitationOptions:
    return ExcitationOptions(max_acceleration=((8, 1.0),))


def test_the_trajectory_csv_is_written_at_the_rate_given(tmp_path):
    """Regression (an SO-100 trial: a servo bus takes goal positions at 30-50 Hz, and
    trajectory.csv came at 1 kHz with no word on another rate): --rate 50 writes the rows
    at k / 50 s over the whole motion, ramps included, each equal to the 1 kHz file's row
    at the same instant (the samples the limits were checked on)."""
    args = ["excite", "--robot", str(SO101), "--tip", "gripper_frame_link", *TINY, "--seed", "2"]
    rows = {}
    for rate in ("1000", "50"):
        out = tmp_path / rate
        assert main([*args, "--rate", rate, "--no-figures", "-q", "--out", str(out)]) == 0
        rows[rate] = _csv(out / "trajectory.csv", 5)
    t, q, dq, ddq = rows["50"]
    total = rows["1000"][0][-1]
    np.testing.assert_allclose(t, np.arange(round(total * 50) + 1) / 50, atol=1e-12)
    at = np.searchsorted(rows["1000"][0], t - 1e-9)
    for got, checked in zip((q, dq, ddq), rows["1000"][1:], strict=True):
        np.testing.assert_allclose(got, checked[at], rtol=1e-9, atol=1e-12)
    assert main([*args, "--rate", "0", "--out", str(tmp_path / "z")]) == 2
