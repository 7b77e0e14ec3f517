"""Names survive every round trip (issue 28): any link, joint or frame name a URDF can hold.

A name may hold quotes, markup characters (``< > &``, ``]]>``), spaces, tabs, non-ASCII
letters and characters beyond the Basic Multilingual Plane; it may be written in the URDF
with character references or entities of the document's DTD. Each is read, written
escaped and read back equal in URDF, MJCF, TOML and JSON (robot, feasible and bounds
files). References: ``xml.etree`` for well-formed XML and MuJoCo's own compiler for the
names it reads from the MJCF.
"""

from __future__ import annotations

import contextlib
import dataclasses
import html
import io
import json
import os
import re
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning, ModelError
from dynid.feasibility.bounds import default_bounds
from dynid.io.bounds_file import load_bounds, save_bounds
from dynid.io.feasible import load_feasible_json, save_feasible_json
from dynid.io.robot.mjcf import mjcf_from_robot
from dynid.io.robot.toml import robot_from_toml_string, save_toml, toml_from_robot
from dynid.io.robot.urdf import robot_from_urdf_string, save_urdf, tip_name, urdf_from_robot

from conftest import planar_2r

#: Characters a URDF name can hold: every XML character but the control characters a
#: robot refuses (a tab is allowed), with the troublesome ones drawn often.
_CHARS = st.characters(
    exclude_categories=("Cc", "Cs"), exclude_characters="\ufffe\uffff"
) | st.sampled_from(list("\"'<>&;]# \t\u00e9\u94fe\U0001f600"))
_NAME = st.text(_CHARS, min_size=1, max_size=10)


def _named(names: list[str]) -> dynid.Robot:
    """The planar 2R arm with links, joints, two frames and the robot renamed."""
    links, joints, frames = names[:3], names[3:5], names[5:7]
    base = planar_2r()
    r = base.with_params(base.phi)
    r = dataclasses.replace(
        r,
        name=names[7],
        link_names=tuple(links),
        joint_names=tuple(joints),
        frames={"flange": base.frames["flange"]},
    )
    T = np.eye(4)
    T[:3, 3] = (0.1, 0.2, 0.3)
    return r.with_frame(frames[0], T, parent=links[1]).with_frame(frames[1], T, parent=links[2])


def _names(r: dynid.Robot) -> tuple:
    return r.name, r.link_names, r.joint_names, sorted(r.frames)


def _char_references(urdf: str) -> str:
    """The URDF with every character of every name written as a character reference,
    decimal and hexadecimal in turn."""

    def refs(m: re.Match) -> str:
        value = html.unescape(m.group(3))
        chars = (f"&#{ord(c)};" if k % 2 else f"&#x{ord(c):x};" for k, c in enumerate(value))
        return f'{m.group(1)}="{"".join(chars)}"'

    return re.sub(r"\b(name|link)=([\"'])(.*?)\2", refs, urdf)


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.lists(_NAME, min_size=8, max_size=8, unique=True))
@example(['a "q" <b> & c', "\u00e9 \u94fe\tx", " sp ", "]]>", "&amp;", "--x--", "\U0001f600", "r"])
@example(["base", "l1", "l2", "tool_joint", "j2", "tool", "other", "r"])
def test_any_urdf_name_survives_urdf_mjcf_toml_and_json(tmp_path_factory, names):
    """Link, joint, frame and robot names read back equal from every format (issue 28); a
    frame named like a joint without its "_joint" made a URDF with a duplicated joint."""
    if "flange" in names[:3] + names[5:7] or "world" in names[1:3]:
        return  # the mounting frame's name; MuJoCo's world body (their own tests)
    r = _named(names)
    tmp = tmp_path_factory.mktemp("names")
    urdf = urdf_from_robot(r, all_frames=True)
    ET.fromstring(urdf)  # well formed
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        for text in (urdf, _char_references(urdf)):
            back = robot_from_urdf_string(text, tip_link=tip_name(r))
            assert _names(back) == _names(r)
            np.testing.assert_allclose(back.phi, r.phi, atol=1e-12)

    mjcf, _ = mjcf_from_robot(r)
    ET.fromstring(mjcf)
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_string(mjcf)
    assert [m.body(i).name for i in range(1, m.nbody)] == list(r.link_names)
    assert [m.joint(i).name for i in range(m.njnt)] == list(r.joint_names)
    assert sorted(m.site(i).name for i in range(m.nsite)) == sorted(
        k for k in r.frames if k not in r.link_names
    )

    assert _names(robot_from_toml_string(toml_from_robot(r))) == _names(r)
    save_feasible_json(tmp / "feasible.json", r)
    assert _names(load_feasible_json(tmp / "feasible.json")) == _names(r)
    for suffix in (".toml", ".json"):
        save_bounds(tmp / f"bounds{suffix}", default_bounds(r))
        assert load_bounds(tmp / f"bounds{suffix}", r).link_names == r.link_names[1:]


_DTD_URDF = """<?xml version="1.0"?>
<!DOCTYPE robot [<!ENTITY l "link"> <!ENTITY q "&#34;">]>
<robot name="r">
  <link name="base"/>
  <joint name="j&#49;" type="revolute">
    <parent link="base"/><child link="&l;1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
  </joint>
  <link name="&l;1">
    <inertial><origin xyz="0.1 0 0"/><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="j2" type="revolute">
    <parent link="&l;1"/><child link="&q;&l;2&q;"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
  </joint>
  <link name="&q;&l;2&q;">
    <inertial><origin xyz="0.2 0 0"/><mass value="2"/>
      <inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>
"""


def test_template_with_dtd_entity_link_names_exports(tmp_path):
    """A template whose link names are DTD entities (``&l;1``) exports patched; it read
    'link1' and failed with "unexpected KeyError: 'link1'" (issue 28)."""
    template = tmp_path / "entities.urdf"
    template.write_text(_DTD_URDF, encoding="utf-8")
    chain = dynid.Robot.from_urdf(template)
    assert chain.link_names == ("base", "link1", '"link2"')
    new = chain.with_params(chain.phi * 1.25)
    save_toml(tmp_path / "params.toml", new)
    out = tmp_path / "patched.urdf"
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(
            [
                *("export", "--params", str(tmp_path / "params.toml"), "--out", str(out)),
                *("--urdf-template", str(template)),
            ]
        )
    assert code == 0, err.getvalue()
    text = out.read_text(encoding="utf-8")
    assert "<!ENTITY l" in text and '<link name="&l;1">' in text  # the rest kept as written
    np.testing.assert_allclose(dynid.Robot.from_urdf(out).phi, new.phi, rtol=1e-12)


def _run_c_locale(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """``dynid ARGS`` under a C locale without UTF-8 mode or locale coercion."""
    env = dict(os.environ, LC_ALL="C", LANG="C", PYTHONUTF8="0", PYTHONCOERCECLOCALE="0")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(dynid.__file__).parents[1]), *sys.path])
    return subprocess.run(
        [sys.executable, "-m", "dynid", *args], cwd=cwd, env=env, capture_output=True, timeout=120
    )


def test_non_ascii_frame_name_under_c_locale(tmp_path):
    """A non-ASCII --frame is found under LC_ALL=C without UTF-8 mode as under UTF-8 (it
    arrived surrogate-escaped and was unknown), and a non-ASCII robot file still opens."""
    r = _named(["b\u00e4se", "l\u00efnk1", "\u94fe2", "j1", "j2", "w\u00fcrfel", "t\u00f6ol", "r"])
    urdf = tmp_path / "r\u00f6bot.urdf"
    save_urdf(urdf, r, all_frames=True)
    args = ["fk", "--robot", urdf.name, "--tip", "flange", "--q", "0.1,0.2", "--json"]
    c = _run_c_locale([*args, "--frame", "w\u00fcrfel"], tmp_path)
    assert c.returncode == 0, c.stderr.decode()
    T = np.array(json.loads(c.stdout)["T"])
    np.testing.assert_allclose(T, dynid.fk(r, np.array([0.1, 0.2]), "w\u00fcrfel"), atol=1e-12)
    c = _run_c_locale([*args, "--frame", "nicht-da-\u00fc"], tmp_path)
    assert c.returncode == 2 and b"Unknown frame 'nicht-da-\\xfc'" in c.stderr


def test_a_base_link_named_world_is_mujocos_world_body():
    """A base link named 'world' (common in URDFs) is MuJoCo's world body: the MJCF compiles
    and the names read back (it was "repeated name 'world' in body"); a moving link named
    'world' is refused naming it."""
    mujoco = pytest.importorskip("mujoco")
    r = _named(["world", "l1", "l2", "j1", "j2", "a", "b", "r"])
    m = mujoco.MjModel.from_xml_string(mjcf_from_robot(r)[0])
    assert [m.body(i).name for i in range(m.nbody)] == list(r.link_names)
    assert sorted(m.site(i).name for i in range(m.nsite)) == ["a", "b", "flange"]
    with pytest.raises(ModelError, match="link 1 of robot 'r' is named 'world'"):
        mjcf_from_robot(_named(["base", "world", "l2", "j1", "j2", "a", "b", "r"]))
