"""A URDF chain that runs on past the arm a log records (the Unitree Z1's gripper joint
after its six arm joints), read through a column map: the error says the log's joint
count, the chain's joint beyond it and the ``--tip`` that cuts the chain to the log's.

References: the Z1 URDF's own joints and links, read with ElementTree (not dynid); the log
is constructed (six joints' columns within the arm's limits)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from dynid.exceptions import DataError
from dynid.io.columns import parse_column_map
from dynid.io.robot.urdf import load_urdf
from dynid.workflows.data_files import read_torque_log

from conftest import robot_data_urdf


def _moving_chain(path: str) -> list[tuple[str, str, str]]:
    """(joint, parent link, child link) of the URDF's non-fixed joints, in file order."""
    root = ET.parse(path).getroot()
    return [
        (j.get("name"), j.find("parent").get("link"), j.find("child").get("link"))
        for j in root.findall("joint")
        if j.get("type") != "fixed"
    ]


def test_a_six_joint_log_for_the_z1_chain_to_its_gripper_is_told_the_tip(tmp_path):
    """Regression: a 6-joint log read with --columns for the Z1 URDF (7 moving joints, the
    last its gripper's) said only "missing column(s) q7 for 'q'"; now it says the log has 6
    joints, the chain 7, and --tip at the link before the extra joint, which reads it."""
    path = robot_data_urdf("z1_description/urdf/z1.urdf")
    chain = _moving_chain(path)
    assert len(chain) == 7
    gripper, tip = chain[-1][0], chain[5][2]  # the extra joint; the 6th joint's child link
    robot = load_urdf(path)
    assert robot.n == 7
    rng = np.random.default_rng(0)
    lo, hi = np.asarray(robot.q_min)[:6], np.asarray(robot.q_max)[:6]
    t = np.arange(200) * 1e-3
    q = lo + (hi - lo) * (0.5 + 0.3 * np.sin(2 * np.pi * t[:, None] * rng.uniform(1, 2, 6)))
    cols = {"t": t} | {f"pos{i + 1}": q[:, i] for i in range(6)}
    cols |= {f"vel{i + 1}": np.gradient(q[:, i], t) for i in range(6)}
    cols |= {f"eff{i + 1}": rng.normal(size=200) for i in range(6)}
    log = tmp_path / "six.csv"
    rows = np.column_stack([*cols.values()])
    log.write_text(",".join(cols) + "\n" + "\n".join(",".join(map(repr, r)) for r in rows.tolist()))
    cmap = parse_column_map("q=pos{i},dq=vel{i},tau=eff{i}")
    with pytest.raises(DataError) as err:
        read_torque_log(log, 7, columns=cmap, robot=robot)
    said = str(err.value)
    assert "the log has 6 joints; the robot has 7: missing column(s) pos7" in said, said
    assert f"--tip {tip} (leaves out {gripper})" in said, said
    cut = load_urdf(path, tip_link=tip)
    assert cut.n == 6 and read_torque_log(log, 6, columns=cmap, robot=cut).n == 6
