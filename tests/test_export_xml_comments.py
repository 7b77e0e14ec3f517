"""The comments of the MJCF and URDF exports read naturally and stay valid XML: a flag
reads as the option it is ("option out r.toml"), never "- -out" (a comment holds no
"--"), and MuJoCo compiles the file."""

from __future__ import annotations

import re
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.io.robot.export_options import xml_comment
from dynid.io.robot.mjcf import save_mjcf
from dynid.io.robot.urdf import save_urdf
from dynid.model.drive import Drive
from dynid.model.robot import Robot

from conftest import robot_data_urdf

CAVEAT = "not accepted: run --consistent -- or give --allow-rejected---to write it"


def _ur5_from_urdf() -> Robot:
    """UR5 of example-robot-data (skipped when not installed)."""
    return Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), "base_link", "tool0"
    )


def _comments(text: str) -> list[str]:
    return re.findall(r"<!--(.*?)-->", text, flags=re.S)


def test_mjcf_comments_name_options_and_mujoco_compiles_the_file(tmp_path):
    """A coupled drive's MJCF (notes naming --out r.toml) with a caveat holding flags and
    dashes: no comment holds "--", the flags read "option out", and MuJoCo reads it."""
    mujoco = pytest.importorskip("mujoco")
    robot = _ur5_from_urdf()
    drive = Drive.from_gears([101.0] * 6, [(6, 5, 30.0)], rotor_inertia=np.full(6, 2e-5))
    fr = ClassicalFriction(np.full(6, 1e-3), np.full(6, 1e-2), np.zeros(6)).at(drive)
    kept = "a TOML export (--out r.toml) holds it exactly"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        path = save_mjcf(
            tmp_path / "r.xml", robot, friction=fr, drive=drive, kept=kept, caveat=CAVEAT
        )
    text = path.read_text()
    said = _comments(text)
    assert len(said) == 2 and not any("--" in c for c in said), said
    assert "option out r.toml" in said[1] and "- -" not in text
    assert (
        said[0].strip()
        == "not accepted: run option consistent - or give option allow-rejected - to write it"
    )
    ET.fromstring(text.split("\n", 1)[1])  # (the declaration apart) well-formed
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.nv == robot.n


def test_urdf_comments_are_valid_xml_too(tmp_path):
    """The URDF export's caveat comment: no "--", the flags as options, well-formed."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        path = save_urdf(tmp_path / "r.urdf", _ur5_from_urdf(), caveat=CAVEAT)
    said = _comments(path.read_text())
    assert said and not any("--" in c for c in said), said
    ET.parse(path)


@pytest.mark.parametrize("text", ["a -- b", "ends in -", "--x", "a --- b", "q=-1 --units"])
def test_xml_comment_never_holds_a_double_hyphen(text):
    """Any text makes a comment XML accepts: no "--" inside, no "-" before its end."""
    c = xml_comment(text)
    inner = c[len("<!--") : -len("-->")]
    assert "--" not in inner and not inner.endswith("-")
    ET.fromstring(f"<r>{c}</r>")
