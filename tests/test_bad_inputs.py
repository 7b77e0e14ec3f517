"""Bad inputs and faults through the command line: one line, the right exit code (issue 12).

The table ``CASES`` holds one row per case: an id, a function that writes the bad input
into the work folder (or None), the arguments, the expected exit code and a fragment of
the expected stderr (or, for exit 0, of the expected warning; "" for none). Add a row to
cover a new class of input. Every case also checks that nothing is a traceback and that
a failing command leaves no output of its own behind.
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from dynid.cli.__main__ import main

NEUTRAL = "0,-0.785,0,-2.356,0,1.571,0.785"


@pytest.fixture(scope="module")
def base(tmp_path_factory) -> Path:
    """Good inputs: noise-free static data (60 configurations), a 4 s log at 200 Hz, a
    model identified from the static data."""
    d = tmp_path_factory.mktemp("bad_inputs_base")
    sink = io.StringIO()
    with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
        assert main(["acquire-static", "--n", "60", "--seed", "3", "--out", str(d / "s.csv")]) == 0
        assert main(["acquire-static", "--n", "60", "--seed", "3", "--out", str(d / "s.npz")]) == 0
        assert (
            main(["simulate", "--duration", "4", "--rate", "200", "--out", str(d / "log.csv")]) == 0
        )
        assert main(["identify", "--data", str(d / "s.csv"), "--out", str(d / "res")]) == 0
    return d


# ------------------------------------------------------------------ input builders
def _lines(path: Path) -> list[str]:
    return path.read_text(encoding="utf-8").splitlines()


def _write(path: Path, lines: list[str], *, bom: bool = False) -> None:
    path.write_text(("\ufeff" if bom else "") + "\n".join(lines) + "\n", encoding="utf-8")


def _header_index(lines: list[str]) -> int:
    return next(i for i, s in enumerate(lines) if s and not s.startswith("#"))


def _edit_log(d: Path, name: str, edit: Callable[[list[list[str]]], None]) -> None:
    """Copy log.csv to ``name`` with ``edit`` applied to its rows of cells (header first)."""
    lines = _lines(d / "log.csv")
    h = _header_index(lines)
    rows = [s.split(",") for s in lines[h:]]
    edit(rows)
    comments = [s for s in lines[:h] if not s.startswith("# rows:")]
    _write(d / name, comments + [",".join(r) for r in rows])


def truncated_static(d: Path) -> None:
    """A static CSV cut short, as a killed writer of dynid 0.1 left it."""
    lines = _lines(d / "s.csv")
    _write(d / "bad.csv", lines[: len(lines) // 2])


def truncated_npz(d: Path) -> None:
    """An NPZ cut in half."""
    data = (d / "s.npz").read_bytes()
    (d / "bad.npz").write_bytes(data[: len(data) // 2])


def empty_npz(d: Path) -> None:
    """An empty file named .npz."""
    (d / "bad.npz").write_bytes(b"")


def npz_single_array(d: Path) -> None:
    """A single .npy array saved under an .npz name."""
    with open(d / "bad.npz", "wb") as fh:
        np.save(fh, np.zeros((3, 7)))


def npz_short_rows(d: Path) -> None:
    """An NPZ whose recorded row count is larger than its arrays."""
    with np.load(d / "s.npz") as z:
        arrays = {k: z[k] for k in z.files}
    arrays["n_rows"] = np.array(int(arrays["n_rows"]) + 5)
    np.savez(d / "bad.npz", **arrays)


def static_bom(d: Path) -> None:
    """A spreadsheet export: the static CSV with a UTF-8 byte-order mark."""
    _write(d / "bom.csv", _lines(d / "s.csv"), bom=True)


def static_xarm(d: Path) -> None:
    """Static data that record another 7-joint arm."""
    lines = [s.replace('"robot": "panda"', '"robot": "xarm7"') for s in _lines(d / "s.csv")]
    _write(d / "bad.csv", lines)


def static_other_kinematics(d: Path) -> None:
    """Static data whose recorded kinematics are not the Panda's (name removed)."""
    lines = _lines(d / "s.csv")
    k = next(i for i, s in enumerate(lines) if s.startswith("# metadata:"))
    meta = json.loads(lines[k][len("# metadata:") :])
    del meta["robot"]
    meta["kinematics"]["T_parent_joint"][3][0][3] += 0.01
    lines[k] = "# metadata: " + json.dumps(meta)
    _write(d / "bad.csv", lines)


def static_outside_limits(d: Path) -> None:
    """Noise-free data with one configuration past joint 4's upper limit (-0.0698 rad)."""
    lines = _lines(d / "s.csv")
    h = _header_index(lines)
    cells = lines[h + 1].split(",")
    q4 = float(cells[3])
    lines[h + 1] = ",".join(cells)
    assert q4 < 0
    # move the data set's first configuration: replace its row by the Panda's own values
    import dynid

    robot = dynid.panda()
    q = np.array([float(c) for c in cells[:7]])
    q[3] = 0.2
    M, g = dynid.mass_matrix(robot, q), dynid.gravity_torques(robot, q)
    i, j = np.tril_indices(7)
    row = np.concatenate([q, M[i, j], g])
    lines[h + 1] = ",".join(f"{v:.17g}" for v in row)
    _write(d / "lim.csv", lines)


def static_misfit(d: Path) -> None:
    """Noise-free data (as recorded) that no Panda model fits: g scaled by 1.05 in half the
    rows, the recorded robot name and kinematics removed."""
    lines = _lines(d / "s.csv")
    k = next(i for i, s in enumerate(lines) if s.startswith("# metadata:"))
    meta = json.loads(lines[k][len("# metadata:") :])
    del meta["robot"], meta["kinematics"]
    lines[k] = "# metadata: " + json.dumps(meta)
    h = _header_index(lines)
    for r in range(h + 1, len(lines), 2):
        cells = lines[r].split(",")
        cells[-7:] = [f"{1.05 * float(c):.17g}" for c in cells[-7:]]
        lines[r] = ",".join(cells)
    _write(d / "mis.csv", lines)


def static_huge(d: Path) -> None:
    """Static data with one entry of 1e300 (finite; the least squares overflow)."""
    lines = _lines(d / "s.csv")
    h = _header_index(lines)
    cells = lines[h + 3].split(",")
    cells[20] = "1e300"
    lines[h + 3] = ",".join(cells)
    _write(d / "bad.csv", lines)


def truncated_log(d: Path) -> None:
    """A torque log cut short (its '# rows:' line says 801)."""
    lines = _lines(d / "log.csv")
    _write(d / "bad.csv", lines[:500])


def truncated_log_npz(d: Path) -> None:
    """A torque-log NPZ whose n_rows says more than its arrays hold."""
    from dynid.io.torque_log import load_torque_log, save_torque_log

    save_torque_log(d / "log.npz", load_torque_log(d / "log.csv"))
    with np.load(d / "log.npz") as z:
        arrays = {k: z[k] for k in z.files}
    arrays["n_rows"] = np.array(900)
    np.savez(d / "bad.npz", **arrays)


def log_dup_column(d: Path) -> None:
    """A log with tau1 twice (the last one used to win)."""

    def edit(rows):
        k = rows[0].index("tau1")
        for r in rows:
            r.append(r[k])

    _edit_log(d, "bad.csv", edit)


def log_unknown_column(d: Path) -> None:
    """A log with a torque column of a joint the log does not have (tau8 of 7 joints); a
    column of no signal's name (a label) is ignored with a warning instead."""

    def edit(rows):
        rows[0].append("tau8")
        for r in rows[1:]:
            r.append("20")

    _edit_log(d, "bad.csv", edit)


def log_lone_ddq(d: Path) -> None:
    """A log with ddq1 but no ddq2..ddq7."""

    def edit(rows):
        rows[0].append("ddq1")
        for r in rows[1:]:
            r.append("0")

    _edit_log(d, "bad.csv", edit)


def log_nan_row(d: Path) -> None:
    """A log with a NaN torque in data row 10."""

    def edit(rows):
        rows[11][rows[0].index("tau3")] = "nan"

    _edit_log(d, "bad.csv", edit)


def log_repeated_stamp(d: Path) -> None:
    """A log whose data row 20 repeats row 19's timestamp."""

    def edit(rows):
        rows[21][0] = rows[20][0]

    _edit_log(d, "bad.csv", edit)


def log_huge_torque(d: Path) -> None:
    """A log with one torque of 1e308 (finite, but it overflows every statistic)."""

    def edit(rows):
        rows[300][rows[0].index("tau2")] = "1e308"

    _edit_log(d, "bad.csv", edit)


def log_at(rate: int) -> Callable[[Path], None]:
    """A builder: dynid's own simulate at ``rate`` Hz (issue 12: 50 Hz logs were refused)."""

    def make(d: Path) -> None:
        with contextlib.redirect_stdout(io.StringIO()):
            argv = [
                "simulate",
                "--duration",
                "6",
                "--rate",
                str(rate),
                "--out",
                str(d / "slow.csv"),
            ]
            assert main(argv) == 0

    make.__doc__ = f"A {rate} Hz log from dynid simulate."
    return make


def log_bom(d: Path) -> None:
    """The log with a UTF-8 byte-order mark."""
    _write(d / "bom.csv", _lines(d / "log.csv"), bom=True)


def log_gap(d: Path) -> None:
    """The log with 0.1 s of samples missing (20 rows at 200 Hz)."""
    lines = _lines(d / "log.csv")
    h = _header_index(lines)
    lines = [s for s in lines if not s.startswith("# rows:")]
    h = _header_index(lines)
    _write(d / "gap.csv", lines[: h + 300] + lines[h + 320 :])


def log_tau7_zero(d: Path) -> None:
    """A log whose joint 7 torque is recorded as 0 throughout (an unpowered joint): its
    relative error is undefined ("validation.json: ... is inf", exit 2, before)."""

    def edit(rows):
        k = rows[0].index("tau7")
        for r in rows[1:]:
            r[k] = "0"

    _edit_log(d, "zero7.csv", edit)


def log_all_nan(d: Path) -> None:
    """A log whose q3 is NaN in every row ("unexpected IndexError" with --drop-invalid)."""

    def edit(rows):
        k = rows[0].index("q3")
        for r in rows[1:]:
            r[k] = "nan"

    _edit_log(d, "allnan.csv", edit)


def _log_still(d: Path, name: str, joints: list[int]) -> None:
    """A 4 s log at 200 Hz of the Table I sinusoids with ``joints`` (0-based) held still;
    their measured velocities are only the sensor noise."""
    import dynid
    from dynid.io.torque_log import save_torque_log
    from dynid.simulation.limits import scale_into_limits
    from dynid.simulation.measurement import sample_times, simulate_measurement
    from dynid.simulation.trajectories import Trajectory, centered_start, sinusoid_trajectory

    robot = dynid.panda()
    q0 = centered_start(robot)
    traj, _ = scale_into_limits(robot, sinusoid_trajectory(sample_times(4.0, 200.0), q0))
    q, dq, ddq = traj.q.copy(), traj.dq.copy(), traj.ddq.copy()
    q[:, joints], dq[:, joints], ddq[:, joints] = q0[joints], 0.0, 0.0
    still = Trajectory(t=traj.t, q=q, dq=dq, ddq=ddq)
    save_torque_log(d / name, simulate_measurement(robot, still, rng=np.random.default_rng(20)))


def log_joint4_still(d: Path) -> None:
    """A log in which joint 4 never moves (issue 20: phi1 = -9.4e6 N m was fitted)."""
    _log_still(d, "still4.csv", [3])


def log_all_still(d: Path) -> None:
    """A log in which no joint moves."""
    _log_still(d, "still.csv", list(range(7)))


def _trajectory(d: Path) -> list[str]:
    """Lines of a trajectory.csv as excite writes it (2 s of slow sinusoids at 1 kHz)."""
    import dynid
    from dynid.io.excitation import save_trajectory_csv
    from dynid.simulation.trajectories import centered_start, sinusoid_trajectory

    robot = dynid.panda()
    t = np.linspace(0.0, 2.0, 2001)
    q0 = centered_start(robot, np.full(7, 0.2), np.full(7, 4.0))
    save_trajectory_csv(
        d / "traj.csv", sinusoid_trajectory(t, q0, np.full(7, 0.2), np.full(7, 4.0))
    )
    return _lines(d / "traj.csv")


def trajectory_dup_column(d: Path) -> None:
    """trajectory.csv with a second q1 column (joint 1 then did not move)."""
    lines = _trajectory(d)
    cells = [s.split(",") for s in lines[2:]]
    _write(d / "bad.csv", lines[:2] + [",".join(r + [r[1]]) for r in cells])


def trajectory_unknown_column(d: Path) -> None:
    """trajectory.csv with a column of no known name (it was ignored)."""
    lines = _trajectory(d)
    _write(d / "bad.csv", lines[:2] + [lines[2] + ",gripper"] + [s + ",0" for s in lines[3:]])


def trajectory_cut(d: Path) -> None:
    """trajectory.csv cut to 1,000 of its 2,004 lines (it was simulated without complaint)."""
    _write(d / "bad.csv", _trajectory(d)[:1000])


def obstacles_dup_planes(d: Path) -> None:
    """An obstacles file with 'planes' twice: the floor used to disappear."""
    (d / "obs.json").write_text(
        '{"schema": "dynid-obstacles/1", "planes": [{"name": "floor", "point": [0, 0, 0], '
        '"normal": [0, 0, 1]}], "planes": []}'
    )


def obstacles_unknown_key(d: Path) -> None:
    """An obstacles file with a misspelt key ('box' for 'boxes')."""
    (d / "obs.json").write_text(
        '{"schema": "dynid-obstacles/1", "box": [{"center": [0.5, 0, 0.1], "size": [1, 1, 1]}]}'
    )


def obstacles_deep(d: Path) -> None:
    """An obstacles file nested 10,000 deep (RecursionError)."""
    (d / "obs.json").write_text(
        '{"schema": "dynid-obstacles/1", "planes": ' + "[" * 10000 + "]" * 10000 + "}"
    )


def _two_joint(d: Path, name: str, old: str, new: str, *, prefix: str = "") -> None:
    """two.toml with ``old`` replaced by ``new`` (and ``prefix`` before it)."""
    assert old in TWO_JOINT_TOML
    (d / name).write_text(prefix + TWO_JOINT_TOML.replace(old, new, 1), encoding="utf-8")


def toml_axis_1e300(d: Path) -> None:
    """A joint axis [0, 0, 1e300]: its norm overflowed and the axis became zero silently."""
    _two_joint(d, "bad.toml", "axis = [0, 0, 1]", "axis = [0, 0, 1e300]")


def toml_int_400_digits(d: Path) -> None:
    """An axis entry that is an integer of 401 digits (OverflowError)."""
    _two_joint(d, "bad.toml", "axis = [0, 0, 1]", "axis = [0, 0, 1" + "0" * 400 + "]")


def toml_int_5000_digits(d: Path) -> None:
    """An integer of 5,001 digits (Python refuses to convert it: ValueError)."""
    _two_joint(d, "bad.toml", "axis = [0, 0, 1]", "axis = [0, 0, 1" + "0" * 5000 + "]")


def toml_deep(d: Path) -> None:
    """A TOML document nested 10,000 deep (RecursionError)."""
    _two_joint(
        d,
        "bad.toml",
        'name = "two"',
        'name = "two"',
        prefix="x = " + "[" * 10000 + "]" * 10000 + "\n",
    )


def toml_huge_mass(d: Path) -> None:
    """A link of 1e12 kg."""
    _two_joint(
        d,
        "bad.toml",
        "axis = [0, 0, 1]\n[[joints]]",
        "axis = [0, 0, 1]\n[joints.inertial]\n"
        "mass = 1e12\ncom = [0.1, 0, 0]\ninertia = [1, 0, 0, 1, 0, 1]\n[[joints]]",
    )


def toml_inertia_triangle(d: Path) -> None:
    """A link whose principal moments 0.01, 0.01, 0.05 violate a + b >= c (the URDF reader
    warned, the TOML reader said nothing)."""
    _two_joint(
        d,
        "tri.toml",
        "axis = [0, 0, 1]\n[[joints]]",
        "axis = [0, 0, 1]\n[joints.inertial]\n"
        "mass = 1.0\ncom = [0.1, 0, 0]\ninertia = [0.01, 0, 0, 0.01, 0, 0.05]\n[[joints]]",
    )


def toml_offset_1e200(d: Path) -> None:
    """A joint 1e200 m from its parent (M overflowed: "M must be finite; got nan ... hint:
    drop_invalid=True", "tau must be finite", "W must be finite")."""
    _two_joint(d, "far.toml", "origin = { xyz = [0.5, 0, 0] }", "origin = { xyz = [1e200, 0, 0] }")


def com_1e300(d: Path) -> None:
    """A centre of mass 1e300 m from its link, in TOML and URDF ("inertia must be finite;
    got nan at index (0, 0, 0)")."""
    _two_joint(
        d,
        "com.toml",
        "axis = [0, 0, 1]\n[[joints]]",
        "axis = [0, 0, 1]\n[joints.inertial]\n"
        "mass = 1.0\ncom = [1e300, 0, 0]\ninertia = [0.01, 0, 0, 0.01, 0, 0.01]\n[[joints]]",
    )
    (d / "com.urdf").write_text(
        TWO_LINK_URDF.replace("<inertial>", '<inertial><origin xyz="1e300 0 0"/>', 1)
    )


def toml_boolean_mass(d: Path) -> None:
    """A link mass written as true."""
    _two_joint(
        d,
        "bad.toml",
        "axis = [0, 0, 1]\n[[joints]]",
        "axis = [0, 0, 1]\n[joints.inertial]\n"
        "mass = true\ncom = [0.1, 0, 0]\ninertia = [1, 0, 0, 1, 0, 1]\n[[joints]]",
    )


def toml_long_name(d: Path) -> None:
    """A joint type of a million characters (the message echoed all of it)."""
    _two_joint(d, "bad.toml", 'type = "revolute"', 'type = "' + "x" * 1_000_000 + '"')


def toml_name_nul(d: Path) -> None:
    """A joint name holding a NUL: accepted, and the URDF and MJCF exports were not XML."""
    _two_joint(d, "bad.toml", 'name = "j1"', 'name = "j1\\u0000"')


def toml_name_newline(d: Path) -> None:
    """A joint name holding a line break (it broke the one-line messages that name it)."""
    _two_joint(d, "bad.toml", 'name = "j1"', 'name = "j\\n1"')


def devices(d: Path) -> None:
    """/dev/zero under every suffix dynid reads: the readers read it until memory ran out
    (the JSON, TOML and URDF readers could not even be stopped by SIGTERM)."""
    for suffix in ("csv", "npz", "json", "toml", "urdf", "bag"):
        (d / f"zero.{suffix}").symlink_to("/dev/zero")


def a_folder_as_a_file(d: Path) -> None:
    """A folder named like a log."""
    (d / "folder.csv").mkdir()


def model_boolean_rank(d: Path) -> None:
    """identification.json with ``"rank": true`` (cast to 1 and used, exit 0)."""
    doc = json.loads((d / "res" / "identification.json").read_text())
    doc["rank"] = True
    (d / "bad.json").write_text(json.dumps(doc))


def model_string_value(d: Path) -> None:
    """A coefficient's value given as a string (cast by float(), or an unexpected error)."""
    doc = json.loads((d / "res" / "identification.json").read_text())
    doc["coefficients"][0]["value"] = "0.1"
    (d / "bad.json").write_text(json.dumps(doc))


def drive_bom(d: Path) -> None:
    """A drive TOML saved with a byte-order mark (refused as "Invalid statement", while
    JSON, CSV and bounds TOML files with one were read)."""
    (d / "drive.toml").write_text('\ufeffschema = "dynid-drive/1"\n', encoding="utf-8")
    _two_joint(d, "bom.toml", "", "", prefix="\ufeff")


def drive_coupling_twice(d: Path) -> None:
    """A drive file that gives the entry (motor 1, joint 2) of K twice (one was dropped)."""
    (d / "drive.toml").write_text(
        'schema = "dynid-drive/1"\ncoupling = [[1, 2, 0.5], [1, 2, 0.7]]\n', encoding="utf-8"
    )


def static_nan_cell(d: Path) -> None:
    """Static data with a NaN cell (the hint named the Python argument, not the flag)."""
    lines = _lines(d / "s.csv")
    h = _header_index(lines)
    cells = lines[h + 3].split(",")
    cells[10] = "nan"
    lines[h + 3] = ",".join(cells)
    _write(d / "bad.csv", lines)


def bounds_total_inverted(d: Path) -> None:
    """A total mass band given max first (the message showed np.float64(20.0))."""
    (d / "bounds.json").write_text(
        '{"schema": "dynid-feasibility-bounds/1", "total_mass": [20.0, 16.0]}'
    )


def floor_only(d: Path) -> None:
    """An obstacles file with the floor only."""
    (d / "floor.json").write_text(
        '{"schema": "dynid-obstacles/1", "planes": [{"name": "floor", "point": [0, 0, 0], '
        '"normal": [0, 0, 1]}]}'
    )


def friction_as_model(d: Path) -> None:
    """A friction file given as --model (the message read "not a identified model")."""
    (d / "bad.json").write_text('{"schema": "dynid-friction/1"}')


def npz_duplicated_member(d: Path) -> None:
    """Static data whose NPZ holds ``q.npy`` twice, the second all zeros (numpy read the
    last one silently: every configuration at q = 0)."""
    import warnings

    with zipfile.ZipFile(d / "s.npz") as z, zipfile.ZipFile(d / "bad.npz", "w") as out:
        for name in z.namelist():
            out.writestr(name, z.read(name))
        buf = io.BytesIO()
        with np.load(d / "s.npz") as npz:
            np.save(buf, np.zeros_like(npz["q"]))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # zipfile warns of the duplicated name
            out.writestr("q.npy", buf.getvalue())


TWO_LINK_URDF = """<robot name="two">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
  </joint>
  <link name="l1">
    <inertial><mass value="1.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
</robot>
"""


def urdf_two_masses(d: Path) -> None:
    """A link whose <inertial> holds two <mass> elements (the second was ignored)."""
    text = TWO_LINK_URDF.replace('<mass value="1.0"/>', '<mass value="1.0"/><mass value="9.0"/>')
    (d / "bad.urdf").write_text(text)


def urdf_two_inertials(d: Path) -> None:
    """A link with two <inertial> elements (the second was ignored)."""
    i = TWO_LINK_URDF.index("<inertial>")
    j = TWO_LINK_URDF.index("</inertial>") + len("</inertial>")
    text = TWO_LINK_URDF[:j] + TWO_LINK_URDF[i:j] + TWO_LINK_URDF[j:]
    (d / "bad.urdf").write_text(text)


def urdf_mass_with_underscore(d: Path) -> None:
    """A URDF mass written "1_0" (Python's float read it as 10 kg)."""
    (d / "bad.urdf").write_text(TWO_LINK_URDF.replace('<mass value="1.0"/>', '<mass value="1_0"/>'))


def log_cell_with_underscore(d: Path) -> None:
    """A log cell "1_0" in q3 (read as a 10 rad spike, silently)."""

    def edit(rows):
        rows[8][3] = "1_0"

    _edit_log(d, "bad.csv", edit)


def static_arabic_digit(d: Path) -> None:
    """A static-data cell holding an Arabic-Indic digit one (read as 1.0, silently)."""
    lines = _lines(d / "s.csv")
    h = _header_index(lines)
    cells = lines[h + 2].split(",")
    cells[-1] = "\u0661"
    lines[h + 2] = ",".join(cells)
    _write(d / "bad.csv", lines)


def trajectory_json_duration_1e300(d: Path) -> None:
    """A trajectory.json whose Fourier part lasts 1e300 s (numpy's "Maximum allowed size")."""
    from dynid.simulation.excitation import ExcitingTrajectory

    traj = ExcitingTrajectory(
        w_f=0.5, a=np.zeros((7, 1)), b=np.zeros((7, 1)), q_start=np.zeros(7), duration=1e300
    )
    doc = {"schema": "dynid-exciting-trajectory/1", "trajectory": traj.to_dict()}
    (d / "traj.json").write_text(json.dumps(doc))


def obstacles_name_nul(d: Path) -> None:
    """An obstacle named "t" and a NUL (printed raw to the terminal; robot names refuse it)."""
    plane = {"name": "t\x00", "point": [0, 0, 0], "normal": [0, 0, 1]}
    (d / "nul.json").write_text(json.dumps({"schema": "dynid-obstacles/1", "planes": [plane]}))


def obstacles_far(d: Path) -> None:
    """A table top at z = 1e300 m and a box of 1e200 m (squared distances overflowed, the
    optimiser then reported "q must be finite")."""
    plane = {"name": "t", "point": [0, 0, 1e300], "normal": [0, 0, 1]}
    box = {"name": "b", "center": [0.5, 0, 0.1], "size": [1e200, 1e200, 1e200]}
    for name, key, item in (("far.json", "planes", plane), ("huge.json", "boxes", box)):
        (d / name).write_text(json.dumps({"schema": "dynid-obstacles/1", key: [item]}))


def trajectory_json_edited(d: Path) -> None:
    """trajectory.json files edited by hand: an unknown top-level key, harmonics "five",
    a duration that no longer matches the recorded total (each was ignored)."""
    from dynid.simulation.excitation import ExcitingTrajectory

    traj = ExcitingTrajectory(
        w_f=0.5, a=np.zeros((7, 1)), b=np.zeros((7, 1)), q_start=np.zeros(7), duration=2.0
    )
    edits = {
        "extra.json": lambda doc: doc.__setitem__("note", "x"),
        "five.json": lambda doc: doc["trajectory"].__setitem__("harmonics", "five"),
        "longer.json": lambda doc: doc["trajectory"].__setitem__("duration_s", 20.0),
    }
    for name, edit in edits.items():
        doc = {"schema": "dynid-exciting-trajectory/1", "trajectory": traj.to_dict()}
        edit(doc)
        (d / name).write_text(json.dumps(doc))


def toml_frame_named_like_a_link(d: Path) -> None:
    """A [[frames]] entry named l1 on link l2: it replaced link l1's own frame silently."""
    _two_joint(d, "bad.toml", "", "")
    with open(d / "bad.toml", "a") as fh:
        fh.write('\n[[frames]]\nname = "l1"\nparent = "l2"\n')


def bounds_boolean_mass(d: Path) -> None:
    """A bounds file with true as a mass bound (it was accepted, exit 0)."""
    (d / "bounds.json").write_text(
        '{"schema": "dynid-feasibility-bounds/1", "links": [{"name": "link1", "mass": [true, 5]}]}'
    )


def bounds_mass_1e300(d: Path) -> None:
    """A bounds file with a link mass up to 1e300 kg (Clarabel panicked: a Rust backtrace,
    exit 1, the code of "no feasible set")."""
    (d / "bounds.json").write_text(
        '{"schema": "dynid-feasibility-bounds/1", "links": [{"name": "link1", "mass": [0, 1e300]}]}'
    )


def bounds_link_twice(d: Path) -> None:
    """A bounds file that lists link1 twice (the second entry won silently) and one whose
    units say pounds (ignored: the numbers were read as kg)."""
    links = '[{"name": "link1", "mass": [1, 5]}, {"name": "link1", "mass": [2, 3]}]'
    (d / "twice.json").write_text(
        '{"schema": "dynid-feasibility-bounds/1", "links": ' + links + "}"
    )
    (d / "lb.json").write_text('{"schema": "dynid-feasibility-bounds/1", "units": {"mass": "lb"}}')


def bounds_string_mass(d: Path) -> None:
    """A bounds file (TOML) with a string where a number belongs."""
    (d / "bounds.toml").write_text(
        'schema = "dynid-feasibility-bounds/1"\n[[links]]\nname = "link1"\nmass = ["1", 5]\n'
    )


def bounds_deep(d: Path) -> None:
    """A bounds TOML nested 10,000 deep."""
    (d / "bounds.toml").write_text("x = " + "[" * 10000 + "]" * 10000 + "\n")


ONE_JOINT_TOML = """name = "one"
[[joints]]
name = "j1"
type = "revolute"
parent = "l0"
child = "l1"
axis = [0, 1, 0]
limits = { lower = -2, upper = 2, velocity = 2, acceleration = 10, effort = 50 }
[joints.inertial]
mass = 2.0
com = [0.3, 0, 0]
inertia = [0.01, 0, 0, 0.01, 0, 0.01]
"""

PRISMATIC_TOML = """name = "xz"
[[joints]]
name = "z"
type = "prismatic"
parent = "l0"
child = "l1"
axis = [0, 0, 1]
limits = { lower = 0, upper = 0.5, velocity = 0.5, acceleration = 5, effort = 200 }
[joints.inertial]
mass = 2.0
com = [0.0, 0, 0.1]
inertia = [0.01, 0, 0, 0.01, 0, 0.01]
[[joints]]
name = "x"
type = "prismatic"
parent = "l1"
child = "l2"
axis = [1, 0, 0]
limits = { lower = -0.3, upper = 0.3, velocity = 0.5, acceleration = 5, effort = 200 }
[joints.inertial]
mass = 1.0
com = [0.1, 0, 0]
inertia = [0.01, 0, 0, 0.01, 0, 0.01]
"""


def small_arms(d: Path) -> None:
    """A one-joint arm, a prismatic-only (x-z gantry) arm, and an obstacles file without
    obstacles (the gantry's slide starts at the floor)."""
    (d / "one.toml").write_text(ONE_JOINT_TOML)
    (d / "xz.toml").write_text(PRISMATIC_TOML)
    (d / "none.json").write_text('{"schema": "dynid-obstacles/1"}')


def _edit_model(d: Path, edit: Callable[[dict], None]) -> None:
    doc = json.loads((d / "res" / "identification.json").read_text())
    edit(doc)
    (d / "bad.json").write_text(json.dumps(doc))


def model_bad_index(d: Path) -> None:
    """A hand-edited identification.json with a column index of -1."""
    _edit_model(d, lambda doc: doc["base"]["independent"].__setitem__(0, -1))


def model_big_index(d: Path) -> None:
    """An identification.json with an index past the 70 standard parameters."""
    _edit_model(d, lambda doc: doc["base"]["dependent"].__setitem__(0, 70))


def model_bad_friction(d: Path) -> None:
    """An identification.json with a malformed friction block."""
    _edit_model(d, lambda doc: doc.__setitem__("friction", {"fv": 1}))


def model_nan(d: Path) -> None:
    """An identification.json with NaN (not JSON) as a value."""
    text = (d / "res" / "identification.json").read_text()
    (d / "bad.json").write_text(text.replace('"sigma": ', '"sigma": NaN, "x": ', 1))


def model_duplicate_key(d: Path) -> None:
    """An identification.json with a key twice."""
    text = (d / "res" / "identification.json").read_text()
    (d / "bad.json").write_text(text.replace('"rank": ', '"rank": 43, "rank": ', 1))


def model_unknown_keys(d: Path) -> None:
    """identification.json files edited by hand (each was read silently): an unknown key at
    the top, one in a coefficient, and "kept": "yes"."""

    def put(doc: dict, at: str, key: str, value: object) -> None:
        (doc if at == "top" else doc["coefficients"][0])[key] = value

    for name, at, key, value in (
        ("top.json", "top", "note", 1),
        ("coef.json", "coef", "note", 1),
        ("kept.json", "coef", "kept", "yes"),
    ):
        doc = json.loads((d / "res" / "identification.json").read_text())
        put(doc, at, key, value)
        (d / name).write_text(json.dumps(doc))


def model_bom(d: Path) -> None:
    """identification.json with a byte-order mark."""
    text = (d / "res" / "identification.json").read_text()
    (d / "bom.json").write_text("\ufeff" + text, encoding="utf-8")


def feasible_edited(d: Path) -> None:
    """feasible.json files edited by hand (each was exported silently): an unknown key at the
    top and in the kinematics, 'feasible': "yes", a link of 1e12 kg, a CoM at 1e300 m
    ("inertia must be finite"), a string as a joint limit, and a negative mass (kept, but
    said)."""
    from dynid.io.feasible import feasible_to_dict
    from dynid.model.panda import panda

    edits = {
        "extra.json": lambda doc: doc.__setitem__("note", 1),
        "kin.json": lambda doc: doc["kinematics"].__setitem__("note", 1),
        "yes.json": lambda doc: doc.__setitem__("feasible", "yes"),
        "heavy.json": lambda doc: doc["links"][0].__setitem__("mass", 1e12),
        "far.json": lambda doc: doc["links"][0].__setitem__("com", [1e300, 0, 0]),
        "limit.json": lambda doc: doc["kinematics"]["limits"].__setitem__("q_max", ["2.8"] * 7),
        "negative.json": lambda doc: doc["links"][0].__setitem__("mass", -1.0),
    }
    for name, edit in edits.items():
        doc = feasible_to_dict(panda())
        edit(doc)
        (d / name).write_text(json.dumps(doc))


def friction_nan(d: Path) -> None:
    """A friction.json with Infinity."""
    (d / "f.json").write_text(
        '{"schema": "dynid-friction/1", "model": "classical", "joints": '
        '[{"fv": Infinity, "fc": 0, "fo": 0}]}'
    )


def friction_edited(d: Path) -> None:
    """friction.json files edited by hand (each was read silently): an unknown key at the
    top and in a joint, true and "0.1" as fv (read as 1 and 0.1), "identified": "no"."""
    base = {"schema": "dynid-friction/1", "model": "classical"}
    joint = {"fv": 0.1, "fc": 0.2, "fo": 0.0}
    docs = {
        "top.json": base | {"note": 1, "joints": [joint] * 7},
        "joint.json": base | {"joints": [joint | {"note": 1}] * 7},
        "true.json": base | {"joints": [joint | {"fv": True}] * 7},
        "string.json": base | {"joints": [joint | {"fv": "0.1"}] * 7},
        "flag.json": base | {"joints": [joint | {"identified": "no"}] * 7},
    }
    for name, doc in docs.items():
        (d / name).write_text(json.dumps(doc))


# ------------------------------------------------------------------ the table
@dataclass(frozen=True)
class Case:
    """One bad input: how to make it, the command, the exit code, a stderr fragment."""

    id: str
    make: Callable[[Path], None] | None
    argv: tuple[str, ...]
    code: int
    fragment: str


def C(id, make, argv, code, fragment):  # noqa: N802 - short name for the table
    return Case(id, make, tuple(argv.split()), code, fragment)


OUT = "{d}/out"
# fmt: off
CASES = [
    # option values (argparse types): one line, exit 2
    C("seed-negative", None, f"acquire-static --seed -1 --out {OUT}/x.csv", 2, "--seed: must be an integer >= 0"),
    C("simulate-seed", None, f"simulate --seed -1 --out {OUT}/x.csv", 2, "--seed: must be an integer >= 0"),
    C("retrieve-seed", None, f"retrieve --model {{d}}/res/identification.json --seed -1 --out {OUT}", 2, "--seed"),
    C("ik-seed", None, "ik --goal-xyz 0.4,0.1,0.5 --seed -1", 2, "--seed"),
    C("demo-seed", None, f"demo --seed -1 --out {OUT}", 2, "--seed"),
    C("n-zero", None, f"acquire-static --n 0 --out {OUT}/x.csv", 2, "--n: must be an integer >= 1"),
    C("noise-negative", None, f"acquire-static --noise -1 --out {OUT}/x.csv", 2, "--noise: must be a finite number >= 0"),
    C("noise-nan", None, f"acquire-static --noise nan --out {OUT}/x.csv", 2, "--noise: must be a finite number"),
    C("max-std-zero", None, f"identify --data {{d}}/s.csv --max-std-percent 0 --out {OUT}", 2, "--max-std-percent: must be a finite number > 0"),
    C("rtol-one", None, f"identify --data {{d}}/s.csv --rtol 1 --out {OUT}", 2, "--rtol: must be a finite number > 0 and < 1"),
    C("runs-zero", None, f"retrieve --model {{d}}/res/identification.json --runs 0 --out {OUT}", 2, "--runs"),
    C("drop-too-much", None, f"simulate --drop 0.7 --out {OUT}/x.csv", 2, "--drop"),
    C("q-nan", None, "fk --q nan,0,0,0,0,0,0", 2, "--q must be finite"),
    C("q-count", None, "fk --q -0.1,0.2", 2, "--q must have 7 values"),
    # negative comma lists parse as values
    C("q-negative-list", None, "fk --q -0.1,-0.785,0,-2.356,0,1.571,0.785 --json", 0, ""),
    C("predict-negative-list", None, f"predict --model {{d}}/res/identification.json --q -0.1,{NEUTRAL[2:]} --dq -0.1,0,0,0,0,0,0", 0, ""),
    # files cut short: refused, not read as smaller data sets
    C("static-truncated", truncated_static, f"identify --data {{d}}/bad.csv --out {OUT}", 2, "records 60 rows but holds"),
    C("npz-truncated", truncated_npz, f"identify --data {{d}}/bad.npz --out {OUT}", 2, "bad.npz: not a readable NPZ"),
    C("npz-empty", empty_npz, f"identify --data {{d}}/bad.npz --out {OUT}", 2, "bad.npz: not a readable NPZ"),
    C("npz-single-array", npz_single_array, f"identify --data {{d}}/bad.npz --out {OUT}", 2, "bad.npz: a single array, not an NPZ archive"),
    C("log-npz-single-array", npz_single_array, f"validate --robot panda --data {{d}}/bad.npz --out {OUT}", 2, "bad.npz: a single .npy array"),
    C("npz-row-count", npz_short_rows, f"identify --data {{d}}/bad.npz --out {OUT}", 2, "records 65 rows but holds 60"),
    C("missing-file", None, f"identify --data {{d}}/nothing.csv --out {OUT}", 2, "nothing.csv"),
    C("log-truncated", truncated_log, f"validate --robot panda --data {{d}}/bad.csv --out {OUT}", 2, "bad.csv: the file records 801 rows but holds 497"),
    C("log-npz-row-count", truncated_log_npz, f"friction --robot panda --data {{d}}/bad.npz --out {OUT}", 2, "records 900 rows but holds 801"),
    # torque logs: strict columns and rows
    C("log-duplicated-column", log_dup_column, f"validate --robot panda --data {{d}}/bad.csv --out {OUT}", 2, "duplicated column(s) tau1;"),
    C("log-unknown-column", log_unknown_column, f"validate --robot panda --data {{d}}/bad.csv --out {OUT}", 2, "unknown column(s) tau8;"),
    C("log-lone-ddq", log_lone_ddq, f"identify --data {{d}}/bad.csv --out {OUT}", 2, "all of ddq1..ddq7 or none"),
    C("log-nan-row", log_nan_row, f"validate --robot panda --data {{d}}/bad.csv --out {OUT}", 2, "1 row(s) hold NaN, inf or an empty cell; first row 10"),
    C("log-nan-row-dropped", log_nan_row, f"validate --robot panda --data {{d}}/bad.csv --drop-invalid --no-figures --out {OUT}", 0, "dropped 1 row(s) of 801 holding NaN"),
    C("log-repeated-stamp", log_repeated_stamp, f"friction --robot panda --data {{d}}/bad.csv --out {OUT}", 2, "repeat the previous timestamp; first row 20"),
    C("log-repeated-stamp-dropped", log_repeated_stamp, f"validate --robot panda --data {{d}}/bad.csv --drop-invalid --no-figures --out {OUT}", 0, "dropped 1 row(s) of 801 repeating"),
    C("log-huge-torque", log_huge_torque, f"validate --robot panda --data {{d}}/bad.csv --out {OUT}", 2, "overflow"),
    C("log-bom", log_bom, f"validate --robot panda --data {{d}}/bom.csv --no-figures --out {OUT}", 0, ""),
    C("log-gap-bridged", log_gap, f"validate --robot panda --data {{d}}/gap.csv --max-gap 0.2 --no-figures --out {OUT}", 0, ""),
    C("log-gap-cut", log_gap, f"validate --robot panda --data {{d}}/gap.csv --no-figures --out {OUT}", 0, ""),  # cut into pieces
    C("log-50hz", log_at(50), f"validate --robot panda --data {{d}}/slow.csv --no-figures --out {OUT}", 0, ""),
    C("log-50hz-friction", log_at(50), f"friction --robot panda --data {{d}}/slow.csv --no-figures --out {OUT}", 0, ""),
    C("log-10hz", log_at(10), f"validate --robot panda --data {{d}}/slow.csv --no-figures --out {OUT}", 0, "the default cutoff 5 Hz is not below the Nyquist frequency of this 10 Hz log"),
    # friction is never fitted from noise (issue 20)
    C("friction-joint-still", log_joint4_still, f"friction --robot panda --data {{d}}/still4.csv --no-figures --out {OUT}", 0, "joint(s) [4] never move beyond their velocity noise band"),
    C("friction-all-still", log_all_still, f"friction --robot panda --data {{d}}/still.csv --out {OUT}", 2, "no joint moves beyond its velocity noise band"),
    C("log-wrong-robot", None, f"validate --robot {{d}}/two.toml --data {{d}}/log.csv --out {OUT}", 2, "the log has 7 joints"),
    # excite's files and obstacles: read as strictly as torque logs (issue 20)
    C("trajectory-duplicated-column", trajectory_dup_column, f"simulate --trajectory {{d}}/bad.csv --out {OUT}/x.csv", 2, "bad.csv, line 3: duplicated column(s) q1;"),
    C("trajectory-unknown-column", trajectory_unknown_column, f"simulate --trajectory {{d}}/bad.csv --out {OUT}/x.csv", 2, "unknown column(s) gripper;"),
    C("trajectory-cut", trajectory_cut, f"simulate --trajectory {{d}}/bad.csv --out {OUT}/x.csv", 2, "records 2001 rows but holds 997"),
    C("obstacles-duplicated-planes", obstacles_dup_planes, f"excite --obstacles {{d}}/obs.json --out {OUT}", 2, "obs.json: not strict JSON (duplicated key 'planes')"),
    C("obstacles-unknown-key", obstacles_unknown_key, f"excite --obstacles {{d}}/obs.json --out {OUT}", 2, "obs.json: key 'box': unknown key; allowed: boxes, planes, schema"),
    C("obstacles-nested-deep", obstacles_deep, f"excite --obstacles {{d}}/obs.json --out {OUT}", 2, "nested too deeply"),
    # robot descriptions: absurd numbers and deep nesting are one clear line (issue 20)
    C("toml-axis-1e300", toml_axis_1e300, "fk --robot {d}/bad.toml --q 0.1,0.2", 2, "bad.toml: key 'joints[0].axis': [0.0, 0.0, 1e+300] is too large to normalise (its squared length overflows a float)"),
    C("toml-integer-400-digits", toml_int_400_digits, "fk --robot {d}/bad.toml --q 0.1,0.2", 2, "bad.toml: key 'joints[0].axis[2]': expected a finite number; got an integer of about 401 digits"),
    C("toml-integer-5000-digits", toml_int_5000_digits, "fk --robot {d}/bad.toml --q 0.1,0.2", 2, "bad.toml: not valid TOML (an integer of more than 4300 digits)"),
    C("toml-nested-deep", toml_deep, "fk --robot {d}/bad.toml --q 0.1,0.2", 2, "bad.toml: not valid TOML (arrays or tables nested too deeply)"),
    C("toml-mass-1e12", toml_huge_mass, "fk --robot {d}/bad.toml --q 0.1,0.2", 2, "bad.toml: key 'joints[0].inertial.mass': expected a number in [0, 1e+06] [kg]; got 1000000000000.0"),
    C("toml-mass-true", toml_boolean_mass, "fk --robot {d}/bad.toml --q 0.1,0.2", 2, "bad.toml: key 'joints[0].inertial.mass': expected a number in [0, 1e+06] [kg]; got True"),
    C("toml-long-string", toml_long_name, "fk --robot {d}/bad.toml --q 0.1,0.2", 2, "... (1000000 characters)"),
    # bounds files: numbers only where numbers belong
    C("bounds-mass-true", bounds_boolean_mass, f"retrieve --model {{d}}/res/identification.json --bounds {{d}}/bounds.json --out {OUT}", 2, "bounds.json: key 'links[0].mass[0]': expected a number [kg]; got True"),
    C("bounds-mass-string", bounds_string_mass, f"retrieve --model {{d}}/res/identification.json --bounds {{d}}/bounds.toml --out {OUT}", 2, "bounds.toml: key 'links[0].mass[0]': expected a number [kg]; got '1'"),
    C("bounds-nested-deep", bounds_deep, f"retrieve --model {{d}}/res/identification.json --bounds {{d}}/bounds.toml --out {OUT}", 2, "bounds.toml: not valid TOML (arrays or tables nested too deeply)"),
    # one-joint and prismatic-only arms (issue 20: excite failed on a zero-size minimum)
    C("excite-one-joint", small_arms, f"excite --robot {{d}}/one.toml --duration 3 --harmonics 2 --max-iter 3 --no-figure --out {OUT}", 0, ""),
    C("excite-prismatic-only", small_arms, f"excite --robot {{d}}/xz.toml --obstacles {{d}}/none.json --duration 3 --harmonics 2 --max-iter 3 --no-figure --out {OUT}", 0, ""),
    # static data: robot consistency and BOM
    C("static-bom", static_bom, f"identify --data {{d}}/bom.csv --out {OUT}", 0, ""),
    C("static-other-robot", static_xarm, f"identify --data {{d}}/bad.csv --out {OUT}", 2, "recorded with robot 'xarm7'; the robot given is 'panda'"),
    C("static-other-kinematics", static_other_kinematics, f"identify --data {{d}}/bad.csv --out {OUT}", 2, "kinematics differ from those of robot 'panda': largest difference 0.01"),
    C("static-outside-limits", static_outside_limits, f"identify --data {{d}}/lim.csv --out {OUT}", 0, "1 of 60 configurations lie outside the joint limits"),
    C("static-misfit", static_misfit, f"identify --data {{d}}/mis.csv --out {OUT}", 0, "on data recorded with relative noise 0 (expected at most 1e-06 %): the data do not fit"),
    C("static-1e300", static_huge, f"identify --data {{d}}/bad.csv --out {OUT}", 2, "bad.csv: least squares overflowed: the data hold values up to 1e+300"),
    # model and friction JSON: validated before use
    C("model-index-minus-one", model_bad_index, "predict --model {d}/bad.json --q " + NEUTRAL, 2, "bad.json: key 'base.independent[0]': expected an index in 0..69 (the robot has 70 standard parameters); got -1"),
    C("model-index-too-big", model_big_index, "predict --model {d}/bad.json --q " + NEUTRAL, 2, "bad.json: key 'base.dependent[0]': expected an index in 0..69 (the robot has 70 standard parameters); got 70"),
    C("model-bad-friction", model_bad_friction, f"validate --model {{d}}/bad.json --data {{d}}/log.csv --out {OUT}", 2, "bad.json: key 'friction': expected a 7 x any nested list of numbers; got {'fv': 1}"),
    C("model-nan", model_nan, "predict --model {d}/bad.json --q " + NEUTRAL, 2, "NaN is not a JSON number"),
    C("model-duplicate-key", model_duplicate_key, "predict --model {d}/bad.json --q " + NEUTRAL, 2, "duplicated key 'rank'"),
    C("model-bom", model_bom, "predict --model {d}/bom.json --q " + NEUTRAL, 0, ""),
    C("friction-infinity", friction_nan, f"validate --robot panda --friction {{d}}/f.json --data {{d}}/log.csv --out {OUT}", 2, "Infinity is not a JSON number"),
    # adversary round of issue 20: names, devices, folders
    C("toml-name-nul", toml_name_nul, "export --params {d}/bad.toml --out {d}/out.urdf", 2, "joint name 'j1\\x00' holds the character '\\x00'; give a name without control characters"),
    C("toml-name-newline", toml_name_newline, "fk --robot {d}/bad.toml --q 0.1,0.2", 2, "joint name 'j\\n1' holds the character '\\n'"),
    C("device-model", devices, "predict --model {d}/zero.json --q " + NEUTRAL, 2, "zero.json: not a regular file (a device, a pipe or a socket"),
    C("device-robot-toml", devices, "fk --robot {d}/zero.toml --q 0.1,0.2", 2, "zero.toml: not a regular file"),
    C("device-robot-urdf", devices, "fk --robot {d}/zero.urdf --base a --tip b --q 0.1,0.2", 2, "zero.urdf: not a regular file"),
    C("device-log-csv", devices, f"identify --data {{d}}/zero.csv --out {OUT}", 2, "zero.csv: not a regular file"),
    C("device-log-npz", devices, f"validate --robot panda --data {{d}}/zero.npz --out {OUT}", 2, "zero.npz: not a regular file"),
    C("device-columns", devices, f"identify --data {{d}}/log.csv --columns {{d}}/zero.toml --out {OUT}", 2, "zero.toml: not a regular file"),
    C("device-drive", devices, f"identify --data {{d}}/log.csv --drive {{d}}/zero.toml --out {OUT}", 2, "zero.toml: not a regular file"),
    C("device-bounds", devices, f"retrieve --model {{d}}/res/identification.json --bounds {{d}}/zero.json --out {OUT}", 2, "zero.json: not a regular file"),
    C("device-trajectory", devices, f"simulate --trajectory {{d}}/zero.csv --out {OUT}/x.csv", 2, "zero.csv: not a regular file"),
    C("device-obstacles", devices, f"excite --obstacles {{d}}/zero.json --out {OUT}", 2, "zero.json: not a regular file"),
    C("device-template", devices, "export --params panda --urdf-template {d}/zero.urdf --out {d}/out.urdf", 2, "zero.urdf: not a regular file"),
    C("device-bag", devices, "import {d}/zero.bag --robot panda --out {d}/out.csv", 2, "zero.bag: not a regular file"),
    C("folder-as-log", a_folder_as_a_file, f"identify --data {{d}}/folder.csv --out {OUT}", 2, "folder holds no .csv or .npz"),
    C("toml-frame-named-like-a-link", toml_frame_named_like_a_link, "fk --robot {d}/bad.toml --frame l1 --q 0.1,0.2", 2, "frame 'l1' has the name of a link but another pose (on link 2)"),
    C("urdf-two-masses", urdf_two_masses, "fk --robot {d}/bad.urdf --base base --tip l1 --q 0.1", 2, "bad.urdf: <inertial> holds 2 <mass> elements; URDF allows one"),
    C("urdf-two-inertials", urdf_two_inertials, "fk --robot {d}/bad.urdf --base base --tip l1 --q 0.1", 2, "<link name='l1'> holds 2 <inertial> elements"),
    C("npz-duplicated-array", npz_duplicated_member, f"identify --data {{d}}/bad.npz --out {OUT}", 2, "bad.npz: duplicated array(s) q.npy; an array may appear once"),
    C("model-is-friction", friction_as_model, "predict --model {d}/bad.json --q " + NEUTRAL, 2, "bad.json: key 'schema': expected 'dynid-identified-model/1' (an identified model (dynid identify)); got 'dynid-friction/1'"),
    C("identify-prior-without-consistent", None, f"identify --data {{d}}/s.csv --prior panda --total-mass 16,20 --out {OUT}", 2, "--prior, --total-mass apply to --consistent only; add --consistent or leave them out"),
    C("acquire-obstacles-without-pool", floor_only, "acquire-static --n 5 --obstacles {d}/floor.json --out {d}/out.csv", 2, "--obstacles needs --pool"),
    C("bounds-total-inverted", bounds_total_inverted, f"retrieve --model {{d}}/res/identification.json --bounds {{d}}/bounds.json --out {OUT}", 2, "total_mass must be (min, max) with 0 <= min <= max; got (20, 16)"),
    C("static-nan-cell", static_nan_cell, f"identify --data {{d}}/bad.csv --out {OUT}", 2, "holds nan; hint: fix the file or pass --drop-invalid to drop such rows"),
    C("drive-bom", drive_bom, f"identify --data {{d}}/log.csv --drive {{d}}/drive.toml --terms viscous --no-figures --out {OUT}", 0, ""),  # one fit: the file is what is checked
    C("robot-toml-bom", drive_bom, "fk --robot {d}/bom.toml --q 0.1,0.2", 0, ""),
    C("model-rank-true", model_boolean_rank, "predict --model {d}/bad.json --q " + NEUTRAL, 2, "bad.json: key 'rank': expected an integer >= 0; got True"),
    C("model-value-string", model_string_value, "predict --model {d}/bad.json --q " + NEUTRAL, 2, "bad.json: key 'coefficients[0].value': expected a number; got '0.1'"),
    # numbers in files: plain ASCII decimals only (Python's float reads "1_0" and other scripts)
    C("urdf-mass-underscore", urdf_mass_with_underscore, "fk --robot {d}/bad.urdf --base base --tip l1 --q 0.1", 2, "<mass> attribute 'value' must be a number; got '1_0'"),
    C("log-cell-underscore", log_cell_with_underscore, f"validate --robot panda --data {{d}}/bad.csv --out {OUT}", 2, "bad.csv, line 10, column 'q3': not a number: '1_0'"),
    C("static-arabic-digit", static_arabic_digit, f"identify --data {{d}}/bad.csv --out {OUT}", 2, "column 'g7': '\u0661' is not a number"),
    # sizes no memory holds: one line naming the option, before numpy's own error
    C("simulate-duration-1e300", None, f"simulate --duration 1e300 --out {OUT}/x.csv", 2, "1e+300 s at 1000 Hz is 1e+303 samples, more than any memory holds"),
    C("simulate-rate-1e300", None, f"simulate --rate 1e300 --out {OUT}/x.csv", 2, "samples, more than any memory holds"),
    C("trajectory-json-duration-1e300", trajectory_json_duration_1e300, f"simulate --trajectory {{d}}/traj.json --out {OUT}/x.csv", 2, "at 1000 Hz is 1e+303 samples"),
    C("acquire-n-1e20", None, f"acquire-static --n {10**20} --out {OUT}/x.csv", 2, "configurations of 7 joints are more than any memory holds"),
    C("obstacles-point-1e300", obstacles_far, f"excite --obstacles {{d}}/far.json --out {OUT}", 2, "far.json: key 'planes[0]': plane point must be at most 1e+06 m in absolute value; got [0.0, 0.0, 1e+300]"),
    C("obstacles-box-1e200", obstacles_far, f"excite --obstacles {{d}}/huge.json --out {OUT}", 2, "huge.json: key 'boxes[0]': box size must be at most 1e+06 m"),
    C("drive-coupling-twice", drive_coupling_twice, f"identify --data {{d}}/log.csv --drive {{d}}/drive.toml --out {OUT}", 2, "drive.toml: key 'coupling[1]': expected each entry of K once; got motor 1 on joint 2 again"),
    # column maps: a quantity once, a column for one quantity only
    C("columns-one-column-two-quantities", None, f"validate --robot panda --data {{d}}/log.csv --columns tau=q{{i}} --out {OUT}", 2, "log.csv: column 'q1' is named by the templates of both 'q' and 'tau'"),
    C("static-columns-one-column-two-quantities", None, f"identify --data {{d}}/s.csv --columns g=q{{i}} --out {OUT}", 2, "s.csv: column 'q1' is named by the templates of both 'q' and 'g'"),
    C("units-given-twice", None, f"validate --robot panda --data {{d}}/log.csv --units q=deg,q=rad --out {OUT}", 2, "--units q=deg,q=rad: two units of q must be one length unit for the prismatic joints (m, mm) and one angle unit for the revolute ones; hint: --units q=mm,q=deg"),
    C("units-time-given-twice", None, f"validate --robot panda --data {{d}}/log.csv --units t=ms,t=us --out {OUT}", 2, "--units: 't' is given twice in 't=ms,t=us'"),
    C("columns-given-twice", None, f"validate --robot panda --data {{d}}/log.csv --columns q=q{{i}},q=dq{{i}} --out {OUT}", 2, "--columns: 'q' is given twice"),
    C("units-factor-underscore", None, f"validate --robot panda --data {{d}}/log.csv --units tau=1_0 --out {OUT}", 2, "unknown unit '1_0' for 'tau'"),
    C("bounds-mass-1e300", bounds_mass_1e300, f"retrieve --model {{d}}/res/identification.json --bounds {{d}}/bounds.json --out {OUT}", 2, "bounds.json: mass_max must be at most 1e+06 kg per link; got [1e+300,"),
    C("total-mass-1e300", None, f"retrieve --model {{d}}/res/identification.json --total-mass 0,1e300 --out {OUT}", 2, "total_mass max must be at most 7e+06 kg (7 links of at most 1e+06 kg); got 1e+300"),
    C("penalty-total-mass-1e300", None, f"retrieve --model {{d}}/res/identification.json --method penalty --total-mass 0,1e300 --out {OUT}", 2, "total_mass max must be at most 7e+06 kg"),
    C("bounds-link-twice", bounds_link_twice, f"retrieve --model {{d}}/res/identification.json --bounds {{d}}/twice.json --out {OUT}", 2, "twice.json: key 'links[1].name': expected each link once; got 'link1' again"),
    C("bounds-units-pounds", bounds_link_twice, f"retrieve --model {{d}}/res/identification.json --bounds {{d}}/lb.json --out {OUT}", 2, "lb.json: key 'units.mass': expected 'kg' (bounds are in SI units); got 'lb'"),
    C("trajectory-json-unknown-key", trajectory_json_edited, f"simulate --trajectory {{d}}/extra.json --out {OUT}/x.csv", 2, "extra.json: key 'note': unknown key; allowed: capsule_radii_m,"),
    C("trajectory-json-harmonics-string", trajectory_json_edited, f"simulate --trajectory {{d}}/five.json --out {OUT}/x.csv", 2, "five.json: key 'trajectory.harmonics': expected a number; got 'five'"),
    C("trajectory-json-duration-edited", trajectory_json_edited, f"simulate --trajectory {{d}}/longer.json --out {OUT}/x.csv", 2, "longer.json: key 'trajectory.total_duration_s': expected 21 (from the coefficients; the file was edited: regenerate it with dynid excite); got 3"),
    C("toml-inertia-triangle", toml_inertia_triangle, "fk --robot {d}/tri.toml --q 0.1,0.2", 0, "the inertial is physically inconsistent: principal moments 0.01, 0.01, 0.05 kg m^2 violate the triangle inequality (0.01 + 0.01 < 0.05)"),
    # feasible.json read back by export: strict keys and types, sane masses and CoMs
    C("feasible-unknown-key", feasible_edited, "export --params {d}/extra.json --out {d}/out.urdf", 2, "extra.json: key 'note': unknown key; allowed: armature_left_out, column_map, combined, conventions, drive"),
    C("feasible-kinematics-unknown-key", feasible_edited, "export --params {d}/kin.json --out {d}/out.urdf", 2, "kin.json: key 'kinematics.note': unknown key; allowed: T_parent_joint, axes"),
    C("feasible-flag-string", feasible_edited, "export --params {d}/yes.json --out {d}/out.urdf", 2, "yes.json: key 'feasible': expected true or false; got 'yes'"),
    C("feasible-mass-1e12", feasible_edited, "export --params {d}/heavy.json --out {d}/out.urdf", 2, "heavy.json: key 'links[0].mass': expected a number in [-1e+06, 1e+06] [kg]; got 1000000000000.0"),
    C("feasible-com-1e300", feasible_edited, "export --params {d}/far.json --out {d}/out.urdf", 2, "far.json: key 'links[0].com[0]': expected a number in [-10000, 10000] [m]; got 1e+300"),
    C("feasible-limit-string", feasible_edited, "export --params {d}/limit.json --out {d}/out.urdf", 2, "limit.json: key 'kinematics.limits.q_max[0]': expected a number; got '2.8'"),
    C("feasible-negative-mass", feasible_edited, "export --params {d}/negative.json --out {d}/out.urdf", 0, "negative.json: links[0] is physically inconsistent: negative mass -1.0; kept as given"),
    C("model-unknown-key", model_unknown_keys, "predict --model {d}/top.json --q " + NEUTRAL, 2, "top.json: key 'note': unknown key; allowed: base, coefficients,"),
    C("model-coefficient-unknown-key", model_unknown_keys, "predict --model {d}/coef.json --q " + NEUTRAL, 2, "coef.json: key 'coefficients[0].note': unknown key; allowed: description, expression, kept, name, std, std_percent, value, z"),
    C("model-kept-string", model_unknown_keys, "predict --model {d}/kept.json --q " + NEUTRAL, 2, "kept.json: key 'coefficients[0].kept': expected true or false; got 'yes'"),
    C("friction-unknown-key", friction_edited, f"validate --robot panda --friction {{d}}/top.json --data {{d}}/log.csv --out {OUT}", 2, "top.json: key 'note': unknown key; allowed: convention, drive"),
    C("friction-joint-unknown-key", friction_edited, f"validate --robot panda --friction {{d}}/joint.json --data {{d}}/log.csv --out {OUT}", 2, "joint.json: key 'joints[0].note': unknown key; allowed: fc, fo, fv"),
    C("friction-boolean-parameter", friction_edited, f"validate --robot panda --friction {{d}}/true.json --data {{d}}/log.csv --out {OUT}", 2, "true.json: key 'joints[0].fv': expected a number [N m s/rad]; got True"),
    C("friction-string-parameter", friction_edited, f"validate --robot panda --friction {{d}}/string.json --data {{d}}/log.csv --out {OUT}", 2, "string.json: key 'joints[0].fv': expected a number [N m s/rad]; got '0.1'"),
    C("friction-identified-string", friction_edited, f"validate --robot panda --friction {{d}}/flag.json --data {{d}}/log.csv --out {OUT}", 2, "flag.json: key 'joints[0].identified': expected true or false; got 'no'"),
    C("log-joint-torque-zero", log_tau7_zero, f"validate --robot panda --data {{d}}/zero7.csv --no-figures --out {OUT}", 0, ""),
    C("toml-offset-1e200", toml_offset_1e200, f"acquire-static --robot {{d}}/far.toml --n 5 --out {OUT}/x.csv", 2, "far.toml: key 'joints[1].origin.xyz[0]': expected a number in [-10000, 10000] [m]; got 1e+200"),
    C("excite-radius-1e300", None, f"excite --radius 1e300 --out {OUT}", 2, "capsule radius must be at most 1e+06 m in absolute value"),
    C("excite-negative-velocity-margin", None, f"excite --velocity-margin -5 --out {OUT}", 2, "velocity_margin (--velocity-margin) must be finite and >= 0; got -0.0872665"),
    C("excite-base-frequency-1e300", None, f"excite --base-frequency 1e300 --out {OUT}", 2, "the highest harmonic, 5 x 1e+300 Hz = 5e+300 Hz, must lie below 5 Hz"),
    C("payload-data-of-more-joints", small_arms, f"payload --robot {{d}}/one.toml --data {{d}}/s.csv --out {OUT}", 2, "s.csv: data for 7 joints (columns q1..q7); robot 'one' has 1"),
    C("payload-data-of-another-robot", None, f"payload --robot fr3 --data {{d}}/s.csv --out {OUT}", 2, "s.csv: the data were recorded with robot 'panda'; the robot given is 'fr3'"),
    C("toml-com-1e300", com_1e300, "fk --robot {d}/com.toml --q 0.1,0.2", 2, "com.toml: key 'joints[0].inertial.com[0]': expected a number in [-10000, 10000] [m]; got 1e+300"),
    C("urdf-com-1e300", com_1e300, "fk --robot {d}/com.urdf --base base --tip l1 --q 0.1", 2, "<inertial> origin must lie within 10000 m of the link frame"),
    C("obstacles-name-nul", obstacles_name_nul, f"excite --obstacles {{d}}/nul.json --out {OUT}", 2, "nul.json: key 'planes[0].name': expected a non-empty name without control characters; got 't\\x00' (holds '\\x00')"),
    C("log-every-row-dropped", log_all_nan, f"validate --robot panda --data {{d}}/allnan.csv --drop-invalid --out {OUT}", 2, "allnan.csv: fewer than 2 valid rows left of 801 (801 with NaN/inf)"),
    C("friction-every-row-dropped", log_all_nan, f"friction --robot panda --data {{d}}/allnan.csv --drop-invalid --out {OUT}", 2, "fewer than 2 valid rows left of 801"),
    C("payload-drop-invalid", log_all_nan, f"payload --robot panda --data {{d}}/allnan.csv --drop-invalid --out {OUT}", 2, "allnan.csv: fewer than 2 valid rows left of 801"),
    C("out-under-a-file", None, "identify --data {d}/s.csv --out {d}/s.csv/res", 2, "s.csv is a file, not a folder; choose another --out"),
    C("out-file-under-a-file", None, "export --params panda --out {d}/s.csv/robot.urdf", 2, "s.csv is a file, not a folder"),
]


# fmt: on


TWO_JOINT_TOML = """name = "two"
[[joints]]
name = "j1"
type = "revolute"
parent = "l0"
child = "l1"
axis = [0, 0, 1]
[[joints]]
name = "j2"
type = "revolute"
parent = "l1"
child = "l2"
origin = { xyz = [0.5, 0, 0] }
axis = [0, 0, 1]
"""


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input_gives_one_line_and_exit_code(case, base, tmp_path, capsys, caplog):
    """Each bad input exits with its code, one stderr line holding the fragment, no
    traceback, and a failing command leaves no output behind."""
    d = tmp_path
    for f in base.iterdir():
        (shutil.copytree if f.is_dir() else shutil.copy)(f, d / f.name)
    (d / "two.toml").write_text(TWO_JOINT_TOML)
    if case.make is not None:
        case.make(d)
    capsys.readouterr()
    argv = [a.replace("{d}", str(d)) for a in case.argv]
    code = main(argv)
    assert code == case.code, capsys.readouterr().err
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if case.code != 0:
        lines = [s for s in err.splitlines() if s.strip()]
        assert len(lines) == 1, err[:2000]
        assert case.fragment in lines[0], err[:2000]
        assert len(lines[0]) < 700, f"{len(lines[0])} characters: {lines[0][:2000]}"
        assert not (d / "out").exists(), "a failing command left output behind"
    elif case.fragment:  # a warning: printed, or logged (stderr through logging)
        assert case.fragment in err + caplog.text, err


def test_excite_without_an_admissible_trajectory_is_a_negative_result(tmp_path, capsys):
    """The arm inside a 10 m box: no admissible trajectory. Exit 1, the documented negative
    result, with the files written for inspection (it was exit 2, "error", which promises
    that no file is left behind, and the files stayed)."""
    box = {"name": "room", "center": [0, 0, 0.5], "size": [10, 10, 10]}
    obs = tmp_path / "obs.json"
    obs.write_text(json.dumps({"schema": "dynid-obstacles/1", "boxes": [box]}))
    out = tmp_path / "out"
    argv = ["excite", "--obstacles", str(obs), "--duration", "2", "--harmonics", "1"]
    assert main([*argv, "--max-iter", "1", "--no-figure", "--out", str(out)]) == 1
    err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
    assert len(err) == 1 and "no admissible trajectory found" in err[0]
    assert "error" not in err[0]
    assert {p.name for p in out.iterdir()} >= {"trajectory.csv", "trajectory.json"}


def test_an_undefined_relative_error_is_null_in_validation_json(base, tmp_path, capsys):
    """A joint whose measured torque is zero throughout has no relative error: null in
    validation.json (documented), the other joints' errors as numbers."""
    log_tau7_zero(base)
    out = tmp_path / "v"
    argv = ["validate", "--robot", "panda", "--data", str(base / "zero7.csv"), "--no-figures"]
    assert main([*argv, "--out", str(out)]) == 0
    doc = json.loads((out / "validation.json").read_text())
    per = doc["without_friction"]["relative_error_percent_per_joint"]
    assert per[6] is None and all(isinstance(x, float) for x in per[:6])


def test_unexpected_error_is_one_line_with_debug_hint(monkeypatch, capsys):
    """A bug (any exception that is not a DynidError) prints one line naming it and
    'run with --debug', exit 2; --debug shows the traceback."""
    from dynid.cli import fk

    def boom(args, console):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(fk, "run", boom)
    assert main(["fk", "--q", NEUTRAL]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "dynid fk: error: unexpected ZeroDivisionError: division by zero (run with --debug "
        "for the traceback)"
    ]
    with pytest.raises(ZeroDivisionError):
        main(["fk", "--q", NEUTRAL, "--debug"])


def test_figures_are_skipped_without_matplotlib(base, tmp_path, monkeypatch, capsys):
    """Without matplotlib, validate writes validation.json and its report, notes the skipped
    figures in one line each and exits 0."""
    import sys

    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    out = tmp_path / "val"
    assert (
        main(["validate", "--robot", "panda", "--data", str(base / "log.csv"), "--out", str(out)])
        == 0
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "note: matplotlib is not installed; skipped the figure validation_torques.png",
        "note: matplotlib is not installed; skipped the figure validation_rms.png",
    ]
    assert sorted(p.name for p in out.iterdir()) == [
        ".dynid-run.json",
        "report.html",
        "validation.json",
    ]
    page = (out / "report.html").read_text(encoding="utf-8")  # without figures, with the notes
    assert "<img" not in page and "skipped the figure validation_rms.png" in page
    # and says so in its first lines, with how to get them (issue 29)
    assert "Figures left out:</b> validation_torques.png, validation_rms.png." in page
    assert page.index("Figures left out") < page.index('id="verdict"')


def test_strict_json_out_never_writes_nan(tmp_path):
    """The JSON writer refuses NaN/inf, naming the key path, and writes nothing."""
    from dynid.exceptions import NonFiniteError
    from dynid.io.json_files import save_json

    with pytest.raises(NonFiniteError, match=r"x.json: rms\[1\] is inf"):
        save_json(tmp_path / "x.json", {"rms": [1.0, np.inf]}, schema="s/1")
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_leaves_the_old_file_when_interrupted(tmp_path):
    """An exception (Ctrl-C included) inside a write keeps the previous file and removes
    the temporary one; a new folder is removed by the failed transaction."""
    from dynid.io.atomic import open_atomic, output_transaction, write_text

    p = write_text(tmp_path / "a.txt", "old\n")
    with pytest.raises(KeyboardInterrupt), open_atomic(p) as fh:
        fh.write("new, half")
        raise KeyboardInterrupt
    assert p.read_text() == "old\n" and sorted(x.name for x in tmp_path.iterdir()) == ["a.txt"]
    with pytest.raises(RuntimeError), output_transaction():
        write_text(tmp_path / "new" / "deep" / "b.txt", "b")
        raise RuntimeError("fail after writing")
    assert sorted(x.name for x in tmp_path.iterdir()) == ["a.txt"]


def test_npz_members_are_checked(tmp_path):
    """A zip with a truncated member raises DataError, not zipfile's or numpy's errors."""
    from dynid.exceptions import DataError
    from dynid.io.static_data import load_static_npz

    with zipfile.ZipFile(tmp_path / "z.npz", "w") as z:
        z.writestr("q.npy", b"\x93NUMPY garbage")
    with pytest.raises(DataError, match="z.npz"):
        load_static_npz(tmp_path / "z.npz")


def test_exact_data_of_an_arm_with_a_prismatic_joint_give_zero_not_nan_std():
    """Noise-free static data of an RPR arm: every std is finite (0 to rounding) with the
    robust and the classical estimator, over several seeds (issue 12: NaN std, then a
    JSON error and an empty folder)."""
    import dynid
    from dynid.identification.static import identify_static
    from dynid.simulation.controller import SimulatedController, acquire_static

    rng = np.random.default_rng(1201)
    robot = dynid.Robot.from_mdh(
        [0.0, 0.1, 0.2],
        [0.3, 0.0, 0.1],
        [0.0, np.pi / 2, -np.pi / 2],
        joint_types="RPR",
        mass=[2.0, 1.5, 1.0],
        com=rng.uniform(-0.05, 0.05, (3, 3)),
        inertia=np.stack([np.diag(rng.uniform(0.01, 0.05, 3)) for _ in range(3)]),
        q_min=[-2.0, 0.0, -2.0],
        q_max=[2.0, 0.5, 2.0],
    )
    for seed in range(4):
        data = acquire_static(SimulatedController(robot, 0.0), 50, np.random.default_rng(seed))
        for est in ("robust", "classical"):
            fit = identify_static(robot, data, std=est).fit
            assert np.all(np.isfinite(fit.std)) and np.all(fit.std >= 0)
            assert np.all(np.isfinite(fit.std_percent[fit.kept]))
            assert fit.relative_error_percent < 1e-8


def test_warnings_print_as_one_line(monkeypatch, capsys):
    """A library warning during a command is one stderr line without the source line."""
    import warnings

    from dynid.cli import fk
    from dynid.exceptions import DynidWarning

    real = fk.run

    def run(args, console):
        warnings.warn("something recoverable", DynidWarning, stacklevel=2)
        return real(args, console)

    monkeypatch.setattr(fk, "run", run)
    assert main(["fk", "--q", NEUTRAL]) == 0
    err = capsys.readouterr().err
    assert err == "dynid fk: warning: something recoverable\n"


def _dynid(*args: str, **kw):
    import subprocess
    import sys

    return subprocess.Popen(
        [sys.executable, "-m", "dynid", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **kw,
    )


def _children(pid: int) -> list[int]:
    """Process ids whose parent is ``pid`` (from /proc)."""
    out = []
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            with contextlib.suppress(OSError):
                fields = (p / "stat").read_text().rsplit(")", 1)[1].split()
                if int(fields[1]) == pid:
                    out.append(int(p.name))
    return out


def _wait_for(cond, timeout: float) -> bool:
    import time

    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.05)
    return False


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc").exists(), reason="needs /proc to find worker processes")
def test_sigterm_stops_retrieve_and_its_workers_without_output(base, tmp_path):
    """SIGTERM during a parallel retrieval: exit 143 with one line, the worker processes
    are gone, and the output folder was never created (issue 12: workers leaked)."""
    import signal

    out = tmp_path / "feasible"
    proc = _dynid(
        "retrieve", "--model", str(base / "res" / "identification.json"), "--method",
        "penalty", "--runs", "4", "--workers", "2", "--seed", "0", "--out", str(out),
    )  # fmt: skip
    assert _wait_for(lambda: len(_children(proc.pid)) >= 2, 60), "workers did not start"
    workers = _children(proc.pid)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 143
    assert err.strip().splitlines()[-1] == (
        "dynid retrieve: terminated (SIGTERM); no partial output left"
    )
    assert "Traceback" not in err
    assert _wait_for(lambda: not any(Path(f"/proc/{w}").exists() for w in workers), 10)
    assert not out.exists()


@pytest.mark.slow
def test_ctrl_c_stops_a_write_without_a_partial_file(tmp_path):
    """SIGINT while acquire-static writes its file (sent once the writer's temporary file
    exists in the staging folder): exit 130, one line, no file and no temporary file left
    (issue 12: a killed write left a truncated file)."""
    import signal

    out = tmp_path / "big.csv"
    # SIGINT back to its default in the child: a shell starts background jobs (`make test &`,
    # nohup'd scripts) with SIGINT ignored, and Python then keeps it ignored (exit 0, no test)
    proc = _dynid(
        "acquire-static", "--n", "100000", "--out", str(out),
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )  # fmt: skip
    writing = ".big.csv.dynid-*/.big.csv.*.tmp.csv"
    assert _wait_for(lambda: proc.poll() is not None or any(tmp_path.glob(writing)), 120)
    assert proc.poll() is None, "the run ended before it wrote"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == 130, err
    assert err.strip().splitlines() == ["dynid acquire-static: interrupted; no partial output left"]
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_inside_code_made_by_exec_is_exit_130_not_death_by_sigint(tmp_path):
    """SIGINT while code built by ``exec`` runs (dataclasses and namedtuple make their
    methods so, as modules load): the interpreter marks such an interrupt as unhandled even
    once caught, and ``python -m dynid`` then killed itself with SIGINT as it exited, after
    its one line (status -2 instead of 130: 5 Ctrl-C in 40 in its first second)."""
    import os
    import signal
    import subprocess
    import sys

    (tmp_path / "interrupted_run.py").write_text(
        "import os, signal, sys\n"
        "from dynid.cli import acquire_static\n"
        "def run(args, console):\n"
        "    exec('os.kill(os.getpid(), signal.SIGINT)\\nfor _ in range(10**7): pass')\n"
        "acquire_static.run = run\n"
        "from dynid.cli.__main__ import main\n"
        "sys.exit(main())\n"
    )
    out = tmp_path / "out" / "s.csv"
    path = os.pathsep.join(p for p in (str(tmp_path), os.environ.get("PYTHONPATH")) if p)
    r = subprocess.run(
        [sys.executable, "-m", "interrupted_run", "acquire-static", "--n", "5", "--out", str(out)],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": path},
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert r.returncode == 130, r.stderr
    assert r.stderr.splitlines() == ["dynid acquire-static: interrupted; no partial output left"]
    assert not out.parent.exists()


@pytest.mark.parametrize("kind", ["DataError", "ValueError"])
def test_an_error_echoing_megabytes_is_one_short_line(monkeypatch, capsys, kind):
    """A message of 6 MB over many lines (a library echoing its input) prints as one line of
    at most 1000 characters that keeps its start and its hint (issue 20: 6-50 MB lines)."""
    from dynid.cli import fk
    from dynid.exceptions import DataError

    cls = DataError if kind == "DataError" else ValueError

    def run(args, console):
        raise cls("x.csv: bad header " + "col,\n" * 1_200_000 + "; hint: fix the header")

    monkeypatch.setattr(fk, "run", run)
    assert main(["fk", "--q", NEUTRAL]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and len(err) <= 1100, len(err)
    assert err.startswith("dynid fk: error: ") and "x.csv: bad header col, col," in err
    assert "characters cut" in err and "; hint: fix the header" in err


def test_non_ascii_names_under_an_ascii_locale(tmp_path):
    """LANG=C without UTF-8 mode: a robot with non-ASCII joint and link names prints them
    escaped (exit 0), and a log with a non-ASCII file name gets its friction fit and figure
    (issue 20: UnicodeEncodeError on stdout, a figure title matplotlib refused)."""
    import os
    import subprocess
    import sys

    text = ONE_JOINT_TOML.replace('"j1"', '"gelenk_\u00e4"').replace('"l1"', '"glied_\u00fc"')
    (tmp_path / "arm.toml").write_text(text, encoding="utf-8")
    env = dict(os.environ, LANG="C", LC_ALL="C", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0")
    env["PYTHONPATH"] = str(Path(__file__).resolve().parents[1] / "src")

    def dynid(*args):
        return subprocess.run([sys.executable, "-m", "dynid", *args], cwd=tmp_path, env=env,
                              capture_output=True, timeout=300)  # fmt: skip

    fk = dynid("fk", "--robot", "arm.toml", "--q", "0.1")
    assert fk.returncode == 0, fk.stderr
    assert b"gelenk_\\xe4" in fk.stdout and b"Traceback" not in fk.stderr
    log = "l\u00f6g.csv".encode()  # UTF-8 bytes, as a user's shell passes them
    sim = dynid("simulate", "--robot", "arm.toml", "--trajectory", "fourier", "--duration", "3",
                "--out", os.fsdecode(log))  # fmt: skip
    assert sim.returncode == 0, sim.stderr
    fr = dynid("friction", "--robot", "arm.toml", "--data", os.fsdecode(log), "--out", "fr")
    assert fr.returncode == 0, fr.stderr
    assert (tmp_path / "fr" / "friction.json").exists() and (
        tmp_path / "fr" / "friction.png"
    ).exists()
    bad = dynid("fk", "--robot", "arm.toml", "--q", "0.1", "--frame", "n\u00f6")
    assert bad.returncode == 2 and bad.stderr.count(b"\n") == 1, bad.stderr


def test_a_text_file_above_the_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    """JSON, TOML and URDF files are read whole: one larger than DYNID_MAX_TEXT_BYTES is
    one DataError saying how to raise the limit, and no more than the limit is read."""
    from dynid.exceptions import DataError
    from dynid.io.json_files import load_json

    p = tmp_path / "big.json"
    p.write_text('{"schema": "x", "pad": "' + "a" * 200 + '"}')
    monkeypatch.setenv("DYNID_MAX_TEXT_BYTES", "100")
    with pytest.raises(DataError, match=r"big.json: 226 bytes, above the 100 bytes .*DYNID_MAX"):
        load_json(p)
    monkeypatch.setenv("DYNID_MAX_TEXT_BYTES", "1000")
    assert load_json(p)["schema"] == "x"


@pytest.mark.parametrize(
    "command",
    ["identify", "retrieve", "friction", "validate", "payload", "excite", "export", "simulate",
     "acquire-static", "import", "demo"],
)  # fmt: skip
def test_an_empty_out_is_refused_not_read_as_the_current_folder(
    command, tmp_path, monkeypatch, capsys
):
    """``--out ""`` (an unset shell variable) was ``Path("")``, the current folder, and a run
    wrote its files there; it is an argument error (exit 2) and nothing is written."""
    monkeypatch.chdir(tmp_path)
    argv = [command, *(["bag.bag"] if command == "import" else []), "--out", ""]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "argument --out: must not be empty" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
