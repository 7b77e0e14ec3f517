"""Motor encoders that wrap every turn on a geared, coupled arm: the whole turns the log
lost are told by the joint positions at its first sample (``--q-start``), and refused
without them when the joints' limits leave several counts.

Reference: a simulated Panda (its own limits, 50:1 gears, motor 7 coupled to joint 6)
whose multi-turn motor angles are wrapped into ``[-pi, pi]`` by ``angle(exp(i q_m))``; the
truth is the trajectory's joint positions.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError, DynidWarning, OptionError
from dynid.identification.log import TorqueLog, with_derived_velocities
from dynid.identification.pieces import with_start_turns
from dynid.identification.recordings import prepare_recordings
from dynid.io.drive_file import load_drive
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import Trajectory

DRIVE = """schema = "dynid-drive/1"
side = "motor"
gear_ratio = 50
coupling = [[7, 6, 15.0]]
offset = [0.01, -0.02, 0.0, 0.03, 0.0, 0.0, 0.01]
rotor_inertia = [0, 0, 0, 0, 0, 0, 0]
"""


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    """The Panda, its drive (file and object), the trajectory (4 s at 200 Hz, small
    sinusoids about the middle of the limits shifted by 0.3 rad), the multi-turn log and
    the wrapped one (both written as CSV)."""
    d = tmp_path_factory.mktemp("qstart")
    (d / "drive.toml").write_text(DRIVE)
    drive = load_drive(d / "drive.toml", 7)
    robot = dynid.panda()
    t = np.arange(0.0, 4.0, 0.005)
    w = 2 * np.pi * np.linspace(0.4, 0.9, 7)
    ph = np.linspace(0.3, 2.8, 7)
    c = 0.5 * (robot.q_min + robot.q_max) + 0.3
    s, co = np.sin(w * t[:, None] + ph), np.cos(w * t[:, None] + ph)
    traj = Trajectory(t, c + 0.1 * s, 0.1 * w * co, -0.1 * w**2 * s)
    true = simulate_measurement(
        robot, traj, rng=np.random.default_rng(0), noise=SensorNoise.none(), drive=drive
    )
    wrapped = TorqueLog(true.t, np.angle(np.exp(1j * true.q)), true.dq, true.tau)
    assert np.all(np.abs(true.q[0]) > np.pi)  # every motor lost turns at the start
    save_torque_log(d / "w.csv", wrapped)
    save_torque_log(d / "m.csv", true)
    return robot, drive, traj, true, wrapped, d


def test_without_q_start_the_turns_are_refused_naming_the_option(arm):
    """The Panda's limits leave dozens of counts per 50:1 motor: refused, naming the file
    and --q-start."""
    robot, drive, _, _, wrapped, _ = arm
    said = r"w\.csv: motor\(s\) 1, 2, .*7 recorded wrapped.*--q-start .*one recording"
    with pytest.raises(DataError, match=said):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DynidWarning)
            prepare_recordings(robot, [wrapped], ["w.csv"], cutoff_hz=5.0, drive=drive)


def test_with_q_start_the_joint_positions_are_the_truth(arm):
    """--q-start 4 mrad off the truth (a twentieth of a motor turn at the joint): the
    unwrapped log's joint positions equal the trajectory's to 1e-9 rad, and identification
    prepares the samples of the multi-turn log."""
    robot, drive, traj, true, wrapped, _ = arm
    q_start = traj.q[0] + 0.004 * np.cos(np.arange(7))
    with pytest.warns(DynidWarning, match=r"w\.csv: motor\(s\) 1, 2, 3, 4, 5, 6, 7 .*--q-start"):
        log = with_start_turns("w.csv", wrapped, robot, drive, q_start)
    np.testing.assert_allclose(drive.joint_states(log.q)[0], traj.q, rtol=0, atol=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        a = prepare_recordings(robot, [log], ["w.csv"], cutoff_hz=5.0, drive=drive)
        b = prepare_recordings(robot, [true], ["m.csv"], cutoff_hz=5.0, drive=drive)
    np.testing.assert_allclose(a.pieces[0].log.q, b.pieces[0].log.q, rtol=0, atol=1e-9)


def test_positions_only_the_velocities_are_those_of_the_unwrapped_angles(arm):
    """Regression: a positions-only motor-side log kept the velocities derived from its
    wrapped angles as read (a turn's jump at each wrap) once --q-start had unwrapped them,
    and validate's sign check read motor 3 of a UR10 as of the opposite sign; now they are
    those derived from the multi-turn angles (the never-wrapped log read alike)."""
    robot, drive, traj, true, wrapped, _ = arm
    derived = with_derived_velocities(wrapped)  # as a reader of a log without dq makes it
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        log = with_start_turns("w.csv", derived, robot, drive, traj.q[0])
    truth = with_derived_velocities(TorqueLog(true.t, true.q, true.dq, true.tau))
    assert log.dq_derived
    np.testing.assert_allclose(log.dq, truth.dq, rtol=0, atol=1e-9 * np.abs(truth.dq).max())


def test_q_start_midway_between_two_counts_is_refused(arm):
    """Joint 1 given half a motor turn (pi / 50 rad) off: two counts are as near, refused."""
    robot, drive, traj, _, wrapped, _ = arm
    q_start = traj.q[0].copy()
    q_start[0] += np.pi / 50
    with pytest.raises(DataError, match=r"--q-start lies .* it does not tell them"):
        with_start_turns("w.csv", wrapped, robot, drive, q_start)


def test_q_start_in_degrees_or_outside_a_joint_s_limits_is_refused_naming_it(arm):
    """The truth in degrees: refused as outside the limits, "in degrees?" (it was "0.0915
    rad from one count"); joint 2 given 0.3 rad beyond its upper limit: refused naming
    it and its limits (it only warned after the turns were set from it)."""
    robot, drive, traj, _, wrapped, _ = arm
    with pytest.raises(OptionError, match=r"outside the joint limits .*: in degrees\?") as e:
        with_start_turns("w.csv", wrapped, robot, drive, np.degrees(traj.q[0]))
    assert e.value.field == "q_start"
    beyond = traj.q[0].copy()
    beyond[1] = robot.q_max[1] + 0.3
    name, lo, hi = robot.joint_names[1], robot.q_min[1], robot.q_max[1]
    with pytest.raises(
        OptionError, match=rf"\({name} {beyond[1]:.4g} outside \[{lo:.4g}, {hi:.4g}\]\)"
    ):
        with_start_turns("w.csv", wrapped, robot, drive, beyond)


def test_validate_with_q_start_on_the_command_line(arm, capsys):
    """validate --drive --q-start on the wrapped log: the model's own torques predicted as
    on the multi-turn log (noise-free: the same errors); without --q-start exit 2 with one
    line naming it."""
    robot, _, traj, _, _, d = arm
    q = ",".join(repr(float(x)) for x in traj.q[0] + 0.003)
    common = ["validate", "--robot", "panda", "--drive", str(d / "drive.toml"), "--cutoff", "5",
              "--no-figures"]  # fmt: skip
    assert main([*common, "--data", str(d / "w.csv"), "--q-start", q, "--out", str(d / "v")]) == 0
    assert main([*common, "--data", str(d / "m.csv"), "--out", str(d / "v2")]) == 0
    got = json.loads((d / "v" / "validation.json").read_text())
    ref = json.loads((d / "v2" / "validation.json").read_text())
    assert got["relative_error_percent"] == pytest.approx(ref["relative_error_percent"], abs=1e-9)
    capsys.readouterr()
    assert main([*common, "--data", str(d / "w.csv"), "--out", str(d / "v3")]) == 2
    err = capsys.readouterr().err.strip()
    assert "--q-start" in err and "\n" not in err


DRV = "--drive {d}/drive.toml"


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (f"{DRV} --data {{d}}/w.csv --q-start 0,0", "--q-start must hold 7 finite joint positions"),
        ("--data {d}/w.csv --q-start 0,0,0,0,0,0,0", 'apply without a --drive of side = "motor"'),
        (f"{DRV} --data {{d}}/m.csv --q-start 0,0,0,0,0,0,0", "does not apply to m.csv"),
        (f"{DRV} --data {{d}}/w.csv {{d}}/m.csv --q-start 0,0,0,0,0,0,0", "one recording; got 2"),
        (f"{DRV} --data {{d}}/w.csv {{d}}/m.csv --q-start 0,0,0,0,0,0,0", "(one at a time)"),
        (f"{DRV} --data {{d}}/w.csv --q-start 0,x", "--q-start: must be comma-separated numbers"),
    ],
)
def test_q_start_where_it_does_not_apply_is_one_line(arm, capsys, args, said):
    """Refused in one line: a wrong count, no motor-side drive, a log whose motors did not
    wrap, several recordings, not numbers."""
    d = arm[-1]
    argv = ["friction", "--robot", "panda", "--out", str(d / "f"), *args.format(d=d).split()]
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert said in err and "\n" not in err, err


def test_the_library_names_the_field():
    """The Python API's error names the field (the command line its flag)."""
    robot = dynid.panda()
    log = TorqueLog(np.arange(3.0), np.zeros((3, 7)), np.zeros((3, 7)), np.zeros((3, 7)))
    with pytest.raises(OptionError, match=r"^q_start gives the whole turns") as exc:
        with_start_turns("x.csv", log, robot, None, np.zeros(7))
    assert exc.value.field == "q_start"


@pytest.mark.parametrize(
    "command",
    [
        "identify --robot panda",
        "payload --robot panda",
        "observe --params panda --calibrate",
        "validate --robot panda",
    ],
)
def test_every_command_reading_logs_through_a_drive_takes_q_start(arm, capsys, command):
    """The one option on each command: without a motor-side drive it is refused in one
    line naming it (the robot's drive is none)."""
    d = arm[-1]
    argv = [*command.split(), "--data", str(d / "w.csv"), "--out", str(d / "o")]
    capsys.readouterr()
    assert main([*argv, "--q-start", ",".join(["0"] * 7)]) == 2
    err = capsys.readouterr().err.strip()
    assert "--q-start gives the whole turns" in err and "\n" not in err, err
