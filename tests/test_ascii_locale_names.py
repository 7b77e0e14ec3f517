"""Under an ASCII locale without UTF-8 mode (``LC_ALL=C PYTHONUTF8=0``) a non-ASCII
argument arrives with its UTF-8 bytes as surrogate escapes (``\\udcc3\\udcbc`` for
``\\u00fc``). Names are decoded at the parser, files keep the form that opens them, and
what the run shows or stores holds the characters, never lone surrogates. In-process, the
escaped form is passed to ``main`` as the interpreter would give it; it opens the same
file (UTF-8 with surrogateescape gives back the bytes)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid._checks import text
from dynid.cli.__main__ import main
from dynid.io.json_files import save_json
from dynid.io.model_json import save_model_json
from dynid.io.observer_files import log_labels
from dynid.io.robot.urdf import save_urdf
from dynid.workflows.prior import load_prior

from conftest import exact_model


def _escaped(name: str) -> str:
    """``name`` as an ASCII locale gives it: its UTF-8 bytes >= 0x80 as surrogates."""
    return name.encode("utf-8").decode("ascii", "surrogateescape")


ARM = """<?xml version="1.0" encoding="utf-8"?>
<robot name="bras">
  <link name="socle"/>
  <link name="épaule"><inertial><origin xyz="0 0 0.1"/><mass value="3.0"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.01"/></inertial></link>
  <link name="coude &amp; ψ"><inertial><origin xyz="0.1 0 0"/><mass value="1.0"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="socle"/><child link="épaule"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-2.8" upper="2.8" effort="80" velocity="2.5"/></joint>
  <joint name="j2" type="revolute"><parent link="épaule"/><child link="coude &amp; ψ"/>
    <origin xyz="0 0 0.2" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1.7" upper="1.7" effort="80" velocity="2.5"/></joint>
</robot>
"""


def test_the_text_of_an_escaped_name_is_its_characters():
    assert text(_escaped("choc \u00f6.csv")) == "choc \u00f6.csv"
    assert text("plain") == "plain" and text("x\ud800") == "x\ufffd"
    assert log_labels([Path(_escaped("a/choc \u00f6.csv"))]) == ["choc \u00f6.csv"]


@pytest.mark.filterwarnings("ignore::dynid.exceptions.DynidWarning")  # the URDF's flange
def test_a_prior_file_with_a_non_ascii_name(tmp_path):
    """It was refused: "robot name 'bras \\udcc3\\udcbc.urdf' holds the character ..."."""
    panda = dynid.panda()
    save_urdf(tmp_path / "bras \u00fc.urdf", panda)
    prior = load_prior(tmp_path / _escaped("bras \u00fc.urdf"), panda)
    assert prior is not None and prior.name == "bras \u00fc.urdf"
    np.testing.assert_allclose(prior.phi, panda.phi, atol=1e-12)
    model = tmp_path / "identification.json"
    save_model_json(model, exact_model(panda, panda))
    argv = ["retrieve", "--model", str(model), "--no-figures", "-q"]
    prior_arg = str(tmp_path / _escaped("bras \u00fc.urdf"))
    assert main([*argv, "--prior", prior_arg, "--out", str(tmp_path / "f")]) == 0
    raw = (tmp_path / "f" / "report.json").read_text(encoding="utf-8")
    assert json.loads(raw)["prior"]["source"] == "bras \u00fc.urdf"


def test_a_contact_at_a_non_ascii_frame(tmp_path, capsys):
    """--contact's frame is a name (it was "Unknown frame 'coude & \\udccf\\udc88'")."""
    (tmp_path / "bras.urdf").write_text(ARM, encoding="utf-8")
    contact = _escaped("coude & \u03c8") + ":0,0,-20:0.1,0.2"
    argv = ["simulate", "--robot", str(tmp_path / "bras.urdf"), "--trajectory", "fourier"]
    argv += ["--duration", "0.3", "--rate", "100", "--contact", contact]
    assert main([*argv, "--out", str(tmp_path / "c.csv")]) == 0
    out = capsys.readouterr().out
    assert "contact at coude & \u03c8" in out and "\\udc" not in out


def test_json_and_printed_names_hold_characters(tmp_path, capsys):
    path = save_json(tmp_path / "x.json", {"log": _escaped("choc \u00f6.csv")}, schema="t/1")
    assert json.loads(path.read_text(encoding="utf-8"))["log"] == "choc \u00f6.csv"
    out = tmp_path / _escaped("l\u00f6g.csv")
    argv = ["simulate", "--robot", "panda", "--duration", "0.1", "--rate", "100"]
    assert main([*argv, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "l\u00f6g.csv" in printed and "\\udc" not in printed
    assert (tmp_path / "l\u00f6g.csv").is_file()
