"""The fk, jacobian, ik and demo subcommands: JSON equals the library, errors are one line."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid import spatial
from dynid.cli.__main__ import main
from dynid.kinematics import IKOptions, ik


def _csv(x) -> str:
    return ",".join(repr(float(v)) for v in np.ravel(x))


def _run_json(capsys, argv):
    """Run the CLI, check exit status 0 and that stdout is exactly one JSON object."""
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    assert err == ""
    assert out.count("\n") == 1
    return json.loads(out)


def test_fk_json_equals_library(capsys):
    """fk --json prints {"T": 4x4} equal to dynid.fk with the same frame and tool."""
    rng = np.random.default_rng(41)
    robot = dynid.panda()
    q = rng.uniform(robot.q_min, robot.q_max)
    tool = [0.01, -0.02, 0.1, 0.1, -0.2, 0.3]
    argv = ["fk", f"--q={_csv(q)}", "--frame", "link6", "--tool", _csv(tool), "--json"]
    obj = _run_json(capsys, argv)
    assert set(obj) == {"T"}
    T_ref = dynid.fk(robot, q, "link6", spatial.transform_from_xyz_rpy(tool[:3], tool[3:]))
    np.testing.assert_array_equal(np.array(obj["T"]), T_ref)


@pytest.mark.parametrize(
    "argv",
    [
        ["fk", "--q=0,0,0,-1.5,0,1.5,0.7"],
        ["jacobian", "--q=0,0,0,-1.5,0,1.5,0.7"],
        ["ik", "--goal-xyz", "0.4,0.1,0.4", "--goal-rpy", "3.1416,0,0"],
    ],
    ids=["fk", "jacobian", "ik"],
)
def test_one_shot_kinematics_imports_neither_scipy_nor_numba(argv):
    """A one-shot ``dynid fk/jacobian/ik`` on the Panda loads only what it uses (start-up
    target of issue 11), and prints what the library computes."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from dynid.cli.__main__ import main\n"
        f"assert main({argv + ['--robot', 'panda', '--json']!r}) == 0\n"
        "heavy = sorted(m for m in ('scipy', 'numba', 'matplotlib') if m in sys.modules)\n"
        "assert not heavy, heavy\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    got, robot, q = json.loads(out.stdout), dynid.panda(), [0, 0, 0, -1.5, 0, 1.5, 0.7]
    if argv[0] == "fk":
        np.testing.assert_allclose(got["T"], dynid.fk(robot, q), rtol=0, atol=1e-14)
    elif argv[0] == "jacobian":
        np.testing.assert_allclose(got["J"], dynid.jacobian(robot, q), rtol=0, atol=1e-14)
    else:
        assert got["converged"]
        np.testing.assert_allclose(dynid.fk(robot, got["q"])[:3, 3], [0.4, 0.1, 0.4], atol=1e-6)


def test_fk_default_q_is_the_neutral_pose(capsys):
    """Without --q, fk uses the documented neutral pose PANDA_NEUTRAL_Q."""
    obj = _run_json(capsys, ["fk", "--json"])
    T_ref = dynid.fk(dynid.panda(), dynid.PANDA_NEUTRAL_Q)
    np.testing.assert_array_equal(np.array(obj["T"]), T_ref)


def test_jacobian_json_equals_library(capsys):
    """jacobian --json prints {"J": 6xn, "rows": [...]} equal to dynid.jacobian."""
    rng = np.random.default_rng(42)
    robot = dynid.panda()
    q = rng.uniform(robot.q_min, robot.q_max)
    obj = _run_json(capsys, ["jacobian", f"--q={_csv(q)}", "--tool", "0,0,0.1", "--json"])
    assert obj["rows"] == ["vx", "vy", "vz", "wx", "wy", "wz"]
    J_ref = dynid.jacobian(robot, q, tool=spatial.transform_from_xyz_rpy([0, 0, 0.1]))
    np.testing.assert_array_equal(np.array(obj["J"]), J_ref)


def test_ik_json_with_goal_matrix_equals_library_and_reaches_the_goal(capsys):
    """ik --goal (16 numbers) --json equals dynid.kinematics.ik and fk(q) is the goal."""
    rng = np.random.default_rng(43)
    robot = dynid.panda()
    tool = spatial.transform_from_xyz_rpy([0, 0, 0.1])
    T_goal = dynid.fk(robot, rng.uniform(robot.q_min, robot.q_max), tool=tool)
    obj = _run_json(capsys, ["ik", f"--goal={_csv(T_goal)}", "--tool", "0,0,0.1", "--json"])
    assert set(obj) == {"q", "converged", "iterations", "position_error", "orientation_error"}
    ref = ik(robot, T_goal, tool=tool, rng=np.random.default_rng(0))
    assert obj["converged"] is True and obj["iterations"] == ref.iterations
    np.testing.assert_array_equal(obj["q"], ref.q)
    assert obj["position_error"] == ref.position_error <= 1e-6
    assert obj["orientation_error"] == ref.orientation_error <= 1e-6
    np.testing.assert_allclose(dynid.fk(robot, obj["q"], tool=tool), T_goal, atol=2e-6)


def test_ik_json_with_xyz_rpy_and_q0_equals_library(capsys):
    """ik --goal-xyz/--goal-rpy/--q0/tolerances equal the library call with the same values."""
    robot = dynid.panda()
    q0 = np.array([0.2, -0.5, -0.1, -2.2, 0.1, 1.7, 0.5])
    xyz, rpy = [0.45, -0.1, 0.35], [np.pi, 0.1, -0.3]
    obj = _run_json(
        capsys,
        [
            "ik",
            "--goal-xyz",
            _csv(xyz),
            "--goal-rpy",
            _csv(rpy),
            "--q0",
            _csv(q0),
            "--position-tolerance",
            "1e-8",
            "--orientation-tolerance",
            "1e-8",
            "--json",
        ],
    )
    opts = IKOptions(position_tolerance=1e-8, orientation_tolerance=1e-8)
    ref = ik(
        robot,
        spatial.transform_from_xyz_rpy(xyz, rpy),
        q0,
        options=opts,
        rng=np.random.default_rng(0),
    )
    assert obj["converged"] and obj["position_error"] <= 1e-8
    np.testing.assert_array_equal(obj["q"], ref.q)


def test_ik_goal_xyz_without_rpy_keeps_the_start_orientation(capsys):
    """Without --goal-rpy the goal orientation is the frame's orientation at --q0."""
    robot = dynid.panda()
    obj = _run_json(capsys, ["ik", "--goal-xyz", "0.35,0.1,0.45", "--json"])
    T = dynid.fk(robot, obj["q"])
    np.testing.assert_allclose(T[:3, 3], [0.35, 0.1, 0.45], atol=1e-6)
    np.testing.assert_allclose(T[:3, :3], dynid.fk(robot, dynid.PANDA_NEUTRAL_Q)[:3, :3], atol=1e-6)


def test_ik_unreachable_goal_exits_1_with_best_result(capsys):
    """An unreachable goal prints converged false and exits with status 1."""
    code = main(["ik", "--goal-xyz", "2,0,0.3", "--max-iterations", "300", "--json"])
    out, err = capsys.readouterr()
    assert code == 1 and err == ""
    obj = json.loads(out)
    assert obj["converged"] is False and obj["position_error"] > 1.0


@pytest.mark.parametrize("command", ["fk", "jacobian", "ik"])
def test_text_output_is_a_readable_table(capsys, command):
    """Without --json, the joint names and the key quantities are printed."""
    extra = ["--goal-xyz", "0.4,0,0.4"] if command == "ik" else []
    assert main([command, *extra]) == 0
    out = capsys.readouterr().out
    assert "joint7" in out
    word = {"fk": "T_base_flange", "jacobian": "wz", "ik": "converged after"}[command]
    assert word in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["fk", "--q", "1,2"], "--q must have 7 values; got 2"),
        (["fk", "--q=nan,0,0,-1,0,1,0"], "--q must be finite"),
        (["fk", "--frame", "gripper"], "Unknown frame 'gripper'"),
        (["jacobian", "--tool", "0,0"], "--tool must have 3 values"),
        (["jacobian", "--robot", "robot.stl"], "--robot must be 'panda'"),
        (["ik"], "give the goal as either --goal"),
        (["ik", "--goal", "1,0,0,0"], "--goal must have 16 values"),
        (["ik", "--goal", "1,0,0,0,0,2,0,0,0,0,1,0,0,0,0,1"], "rotation block must be orthonormal"),
        (["ik", "--goal-xyz", "0.4,0,0.4", "--q0", "0,0,0,0,0,0,0"], "q0 must lie within"),
        (["ik", "--goal-xyz", "0.4,0,0.4", "--goal", "1"], "either --goal"),
        (["ik", "--goal-xyz", "a,b,c"], "--goal-xyz must be comma-separated numbers"),
    ],
)
def test_bad_input_exits_nonzero_with_one_stderr_line(capsys, argv, message):
    """Bad input returns a non-zero status and one 'dynid CMD: error: ...' line on stderr."""
    code = main(argv)
    out, err = capsys.readouterr()
    assert code != 0
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"dynid {argv[0]}: error: ")
    assert message in lines[0]


def test_demo_kinematics_stage_runs_headless_and_writes_a_png(tmp_path):
    """The demo's stage 1 (library) solves the IK; the CLI writes a non-empty PNG of the joint
    motion and reports convergence."""
    from dynid.cli.demo_stages import format_kinematics, save_kinematics
    from dynid.model.panda import PANDA_NEUTRAL_Q
    from dynid.pipeline import kinematics_stage

    robot = dynid.panda()
    res = kinematics_stage(robot, PANDA_NEUTRAL_Q, np.random.default_rng(3))
    text = format_kinematics(robot, res)
    out_dir = tmp_path / "demo"
    assert save_kinematics(out_dir, robot, res) == [out_dir / "ik_joint_motion.png"]
    png = out_dir / "ik_joint_motion.png"
    assert png.stat().st_size > 1000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "IK converged" in text and "flange Jacobian" in text


def test_plot_ik_path_draws_one_line_per_joint_into_given_axes():
    """plot_ik_path returns the Figure of the given axes with n lines and a time axis."""
    from matplotlib.figure import Figure

    from dynid.plots.kinematics import plot_ik_path

    rng = np.random.default_rng(44)
    path = np.cumsum(rng.normal(size=(30, 7)) * 0.01, axis=0)
    fig = plot_ik_path(path, dt=0.1)
    assert isinstance(fig, Figure)
    assert len(fig.axes[0].lines) == 7 and fig.axes[0].get_xlabel() == "time [s]"
    fig2 = Figure()
    ax = fig2.add_subplot()
    assert plot_ik_path(path, ax=ax, q_min=-np.ones(7), q_max=np.ones(7)) is fig2
    assert len(ax.lines) == 7 + 14
    with pytest.raises(dynid.ShapeError, match="path must have shape"):
        plot_ik_path(np.zeros(7))


_BAD_INERTIA_URDF = (
    '<robot name="r"><link name="a"/><link name="b"><inertial><mass value="2"/>'
    '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.09"/></inertial></link>'
    '<link name="flange"/><link name="tool0"/>'
    '<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
    '<limit lower="-3" upper="3" velocity="2" effort="10"/></joint>'
    '<joint name="f" type="fixed"><parent link="b"/><child link="flange"/>'
    '<origin xyz="0.3 0 0"/></joint>'
    '<joint name="t" type="fixed"><parent link="flange"/><child link="tool0"/>'
    '<origin xyz="0 0 0.05"/></joint></robot>'
)


def test_a_warning_given_twice_in_a_run_is_printed_once(capsys):
    """Regression: a URDF read as the robot and again as the prior (identify --consistent
    --prior) printed its triangle-inequality warning twice; a run prints each text once."""
    from dynid.cli.__main__ import _signals_and_warnings
    from dynid.cli.console import Console
    from dynid.io.robot.urdf import robot_from_urdf_string

    with _signals_and_warnings(Console("identify")):
        robot_from_urdf_string(_BAD_INERTIA_URDF)
        robot_from_urdf_string(_BAD_INERTIA_URDF, tip_link="b")  # the prior's reading
    err = capsys.readouterr().err
    assert err.count("triangle inequality") == 1
    assert "is not the tip link" not in err


def test_fk_of_a_fixed_urdf_link_named_flange_is_its_own_pose(capsys, tmp_path):
    """Regression: fk --frame flange of a URDF whose fixed link 'flange' carries the leaf
    tool0 printed tool0's pose (0.05 m off) with a warning; now flange's own, a closed form."""
    path = tmp_path / "r.urdf"
    path.write_text(_BAD_INERTIA_URDF.replace('izz="0.09"', 'izz="0.025"'))
    for frame, z in (("flange", 0.0), ("tool0", 0.05)):
        argv = ["fk", "--robot", str(path), "--q", "0.5", "--frame", frame, "--json"]
        out = _run_json(capsys, argv)
        T = np.asarray(out["T"])
        np.testing.assert_allclose(T[:3, 3], [0.3 * np.cos(0.5), 0.3 * np.sin(0.5), z], atol=1e-15)
