"""The warnings of the URDF and MJCF exports name, as holding what the format drops (the
friction's offsets, the rotor inertias), only files that exist: those written beside it by
the same run and the file the robot was read from; the other formats are offered as the
``--out`` that writes them. A single ``dynid export --out baxter_patched.urdf`` named
``baxter_patched.xml`` and ``baxter_patched.toml`` as holding them. The reference is the
folder on disk."""

from __future__ import annotations

import json
import re

import numpy as np

import dynid
from dynid.friction.laws import law_named
from dynid.friction.model import ClassicalFriction
from dynid.io.export import save_robot_files
from dynid.io.feasible import save_feasible_json
from dynid.io.law_friction import law_record
from dynid.io.robot.export_options import ExportOptions
from dynid.io.robot_file import load_robot
from dynid.model.drive import Drive
from dynid.workflows.export import export_robot, save_export

from conftest import said_warnings

#: A 7-joint drive with rotor inertias [kg m^2], joint side.
DRIVE = Drive.from_gears([1.0] * 7, rotor_inertia=np.full(7, 0.1), side="joint")


def _feasible(path):
    """The Panda as feasible.json with classical friction with offsets (which URDF and MJCF
    drop) and a drive with rotor inertias (which URDF drops)."""
    save_feasible_json(path, dynid.panda())
    doc = json.loads(path.read_text())
    fv, fc, fo = np.full(7, 0.5), np.full(7, 1.0), np.linspace(-0.3, 0.3, 7)
    doc["linear_friction"] = law_record(ClassicalFriction(fv, fc, fo))
    doc["drive"] = DRIVE.as_dict()
    path.write_text(json.dumps(doc))
    return path


def _named(line: str) -> list[str]:
    """The files a warning names in parentheses (``(robot.xml)``)."""
    return re.findall(r"\(([\w.]+\.(?:xml|toml|urdf|json))\)", line)


def test_a_single_export_names_only_files_that_exist(tmp_path):
    """Regression: one URDF export named X.xml and X.toml as holding the rotor inertias and
    the friction though neither was written; now every file it names exists (feasible.json,
    read), and the MJCF and TOML exports are offered by name, each "not written" (no flag:
    the Python caller gives a path)."""
    params = _feasible(tmp_path / "feasible.json")
    lines = []
    for out in ("one.urdf", "one.xml"):
        lines += said_warnings(
            lambda p, o: save_export(o, export_robot(p, o)), params, tmp_path / out
        )[1]
    assert len(lines) == 3, lines  # URDF: friction, rotors; MJCF: friction
    for line in lines:
        assert all((tmp_path / name).exists() for name in _named(line)), line
    assert "feasible.json holds it exactly" in lines[0]
    assert "a TOML export (one.toml, not written) would hold it exactly" in lines[0]
    assert "an MJCF export (one.xml, not written) would hold them as armature" in lines[1]
    assert "a TOML export (one.toml, not written) as its [drive] table" in lines[1]
    assert "feasible.json holds it exactly" in lines[2] and "(one.toml, not written)" in lines[2]


def test_an_output_folder_names_the_files_written_beside_each_other(tmp_path):
    """robot.urdf and robot.xml of one folder name robot.xml, robot.toml and feasible.json
    as holding what they drop, each of them there; nothing is offered as not written."""
    params = _feasible(tmp_path / "feasible.json")
    robot = load_robot(params)
    opts = ExportOptions(friction=robot.friction, drive=DRIVE, source="feasible.json")
    _, lines = said_warnings(save_robot_files, tmp_path, robot, opts)
    assert len(lines) == 3 and not any("not written" in x for x in lines), lines
    for line in lines:
        assert _named(line) and all((tmp_path / n).exists() for n in _named(line)), line
    assert "the TOML export (robot.toml) and feasible.json hold it exactly" in lines[0]
    assert "the MJCF export (robot.xml) holds them as armature" in lines[1]


def test_a_robot_toml_is_named_as_the_file_that_holds_its_own_friction(tmp_path):
    """A URDF exported from a robot TOML names that TOML as holding the friction and offers
    no other TOML."""
    params = _feasible(tmp_path / "feasible.json")
    toml = tmp_path / "arm.toml"
    said_warnings(lambda: save_export(toml, export_robot(params, toml)))
    out = tmp_path / "arm2.urdf"
    lines = said_warnings(lambda: save_export(out, export_robot(toml, out)))[1]
    assert "arm.toml holds it exactly" in lines[0] and "TOML export" not in lines[0], lines


def test_a_friction_urdf_cannot_hold_is_said_in_one_sentence(tmp_path):
    """Regression (the URDF and MJCF warnings of a smooth Stribeck law repeated "smooth_stribeck
    friction:" per item, MJCF's read "without smooth_stribeck friction: the Stribeck peak",
    and ended "; feasible.json holds it exactly; not written: a TOML export ..."): how the
    law is written, what is left out and where it is kept, each said once."""
    params = _feasible(tmp_path / "feasible.json")
    doc = json.loads(params.read_text())
    law = law_named("smooth_stribeck").model(
        np.column_stack(
            [
                np.full(7, 0.2),
                np.full(7, 0.5),
                np.full(7, 0.8),
                np.full(7, 0.08),
                np.linspace(-0.3, 0.8, 7),
            ]
        ),  # fmt: skip
        np.full(7, 0.01),
    )
    doc["linear_friction"] = law_record(law)
    params.write_text(json.dumps(doc))
    lines = []
    for out in ("s.urdf", "s.xml"):
        lines += said_warnings(
            lambda p, o: save_export(o, export_robot(p, o)), params, tmp_path / out
        )[1]
    said = [x for x in lines if "smooth_stribeck" in x]
    assert len(said) == 2, lines
    for line, written in zip(
        said,
        ("as the nonnegative viscous and Coulomb friction closest", "with its rounding"),
        strict=True,
    ):
        assert line.count("smooth_stribeck friction") == 1, line
        assert "friction without smooth_stribeck" not in line and "; not written:" not in line
        assert f", written {written}" in line
        assert ", without the Stribeck peak fs - fc at low speed (no per-joint term)" in line
        assert " and the offsets fo (up to +0.8 N m at joint 7); feasible.json holds it " in line
        kept = "exactly, and a TOML export (s.toml, not written) would hold it exactly"
        assert line.endswith(kept) or f"{kept}; mj_inverse's friction " in line, line


def test_armature_shares_of_an_unlimited_joint_are_read_at_zero_without_a_warning():
    """A continuous joint (no limits) takes its inertia at q = 0 and raises no floating
    point warning: the shares equal armature over the mass matrix's diagonal at the
    middle of the limited joints' ranges and 0 for the unlimited one."""
    import warnings

    from dynid.dynamics.terms import mass_matrix
    from dynid.io.robot.urdf import armature_shares

    panda = dynid.panda()
    q_min, q_max = panda.q_min.copy(), panda.q_max.copy()
    q_min[6], q_max[6] = -np.inf, np.inf
    robot = panda.replace(q_min=q_min, q_max=q_max)
    armature = np.full(7, 0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        shares = armature_shares(robot, armature)
    mid = np.r_[0.5 * (q_min[:6] + q_max[:6]), 0.0]
    np.testing.assert_allclose(shares, armature / np.diagonal(mass_matrix(panda, mid)), rtol=1e-12)
