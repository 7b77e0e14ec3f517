"""An export of a model whose structure left some rotor inertias out and kept others says,
in one note and at the top of the file, which joints are written with armature 0 because
the data did not determine it.

References: a simulated Panda whose rotor inertias are known (joint 7's is 0, the structure
given leaves it out); MuJoCo's compiled model of the exported MJCF (``dof_armature``).
"""

from __future__ import annotations

import json
import logging
import warnings

import mujoco
import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.io.feasible import armature_left_out_note
from dynid.io.feasible_bundle import save_feasible_bundle
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.workflows.export import export_robot, save_export
from dynid.workflows.identify import IdentifyOptions, identify_files

from conftest import recordings

#: Rotor inertias [kg m^2] of the simulation: joint 7 has none.
TRUTH = np.array([0.3, 0.25, 0.2, 0.15, 0.1, 0.05, 0.0])


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """``identify --consistent --terms armature,viscous,-Ia7`` of an exact Panda log with
    the rotors of :data:`TRUTH`: feasible.json and the robot files."""
    robot = dynid.panda()
    (log,) = recordings(
        robot,
        (5,),
        friction=ClassicalFriction(np.full(7, 0.2), np.zeros(7), np.zeros(7)),
        duration=3.0,
        fs=100.0,
        armature=TRUTH,
    )
    out = tmp_path_factory.mktemp("left_out")
    path = save_torque_log(out / "log.csv", log)
    opt = IdentifyOptions(terms="armature,viscous,-Ia7", consistent=True, prior="panda")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        result = identify_files(robot, path, opt)
    assert result.consistent is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        save_feasible_bundle(out, result.consistent)
    return out


def test_the_mjcf_export_names_the_joint_written_with_armature_zero(folder, caplog):
    """Regression: the export wrote ``armature="0"`` at a joint whose rotor inertia the
    structure left out, beside the identified ones, without a word. Now one note and the
    file's first comment name joint7; MuJoCo reads armature 0 there and the
    simulated rotors at the others."""
    doc = json.loads((folder / "feasible.json").read_text())
    assert doc["armature_left_out"] == ["Ia7"]
    out = folder / "arm.xml"
    with caplog.at_level(logging.INFO), warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        save_export(out, export_robot(folder / "feasible.json", out))
    said = [
        r.getMessage() for r in caplog.records if "armature (rotor inertia) 0" in r.getMessage()
    ]
    assert len(said) == 1 and "0 at joint7:" in said[0], said
    assert "left Ia7 out, which the data did not determine" in said[0]
    assert "joint6" not in said[0]
    head = out.read_text().splitlines()[1]
    assert head.startswith("<!-- armature (rotor inertia) 0 at joint7"), head
    armature = mujoco.MjModel.from_xml_path(str(out)).dof_armature
    assert armature[6] == 0.0
    np.testing.assert_allclose(armature[:6], TRUTH[:6], rtol=0.05)


def test_each_robot_file_of_the_bundle_says_it_at_its_top(folder):
    """robot.urdf, robot.xml and robot.toml of the identification's folder each say it in
    their first comment."""
    for name, line in (("robot.urdf", 1), ("robot.xml", 1), ("robot.toml", 0)):
        head = (folder / name).read_text().splitlines()[line]
        assert "armature (rotor inertia) 0 at joint7: " in head, (name, head)


def test_nothing_is_said_without_a_rotor_left_out_or_where_another_turns_the_joint():
    """No rotor left out: no note. A coupled wrist whose motor 7 also turns joint 6 and is
    left out: joint 7 is named (armature 0), joint 6 not (motor 6's rotor is there)."""
    names = [f"j{k}" for k in range(1, 8)]
    direct = Drive.identity(7)
    assert armature_left_out_note(names, direct, ()) is None
    K = np.eye(7)
    K[6, 5] = 0.4  # motor 7 turns with joint 6 too
    coupled = Drive(K, np.zeros(7), rotor_inertia=np.array([1, 1, 1, 1, 1, 1, 0.0]) * 1e-3)
    note = armature_left_out_note(names, coupled, ("Ia7",))
    assert note is not None and "0 at j7:" in note and "j6" not in note, note
