"""A URDF written without a template keeps every joint's name, the fixed joints of the
tool frames included (they came back as ``<child>_joint``); the names are read from the
source file with ElementTree, not through dynid."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from dynid.cli.__main__ import main
from dynid.io.robot.urdf import load_urdf
from dynid.io.robot_json import robot_from_dict, robot_to_dict

#: A two-joint arm whose tool hangs off the last link through two fixed joints in series,
#: with names no rule derives from their child links.
ARM = """<?xml version="1.0" encoding="utf-8"?>
<robot name="bras">
  <link name="socle &amp; &lt;0&gt;"/>
  <link name="épaule"><inertial><origin xyz="0 0 0.1"/><mass value="3.0"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <link name="coude &amp; ψ"><inertial><origin xyz="0.1 0 0"/><mass value="1.0"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="outil Ω"/>
  <link name="tcp"/>
  <joint name="j1 &quot;a&quot;" type="revolute">
    <parent link="socle &amp; &lt;0&gt;"/><child link="épaule"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.8" upper="2.8" effort="80" velocity="2.5"/></joint>
  <joint name="j2 ω" type="revolute">
    <parent link="épaule"/><child link="coude &amp; ψ"/>
    <origin xyz="0 0 0.2" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1.7" upper="1.7" effort="80" velocity="2.5"/></joint>
  <joint name="tool joint ☃" type="fixed">
    <parent link="coude &amp; ψ"/><child link="outil Ω"/><origin xyz="0.2 0 0"/></joint>
  <joint name="pointe" type="fixed">
    <parent link="outil Ω"/><child link="tcp"/><origin xyz="0 0 0.05"/></joint>
</robot>
"""


def _joints(path: Path) -> dict[str, str]:
    """Joint name -> type, as the file holds them."""
    return {j.get("name"): j.get("type") for j in ET.parse(path).getroot().iter("joint")}


def test_a_urdf_export_keeps_the_fixed_joints_names(tmp_path):
    src = tmp_path / "bras.urdf"
    src.write_text(ARM, encoding="utf-8")
    out = tmp_path / "out.urdf"
    assert main(["export", "--params", str(src), "--out", str(out), "--all-frames", "-q"]) == 0
    assert _joints(out) == _joints(src)


def test_the_fixed_joints_names_survive_the_json_record(tmp_path):
    src = tmp_path / "bras.urdf"
    src.write_text(ARM, encoding="utf-8")
    robot = load_urdf(src)
    back = robot_from_dict(robot_to_dict(robot))
    assert back.frames["tcp"].joint == "pointe"
    assert back.frames["outil Ω"].joint == "tool joint ☃"
    assert back.frames["flange"].joint == robot.frames["flange"].joint
