"""One torque log identified by the library (``identify_from_log``) and by the command
(``dynid identify``): the same preparation, the same held-out judgement on the torques as
measured, so the same structure chosen and the same parameters."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning, OptionError
from dynid.friction.model import ClassicalFriction
from dynid.identification.classical import identify_from_log
from dynid.identification.structure import Structure
from dynid.identification.verdict import FLOOR_GOOD
from dynid.io.model_json import load_model_json
from dynid.io.torque_log import load_torque_log, save_torque_log
from dynid.model.robot import Robot
from dynid.simulation.measurement import SensorNoise

from conftest import recordings, robot_data_urdf


@pytest.fixture(scope="module")
def one_log(panda, tmp_path_factory):
    """A noisy 6 s recording of an arm with viscous and Coulomb friction, saved and read
    back as the command reads it."""
    fr = ClassicalFriction(np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7), np.zeros(7))
    (log,) = recordings(panda, (81,), friction=fr, duration=6.0, noise=SensorNoise())
    path = save_torque_log(tmp_path_factory.mktemp("one") / "rec.npz", log)
    return path, load_torque_log(path)


def _command(path, out, *extra) -> object:
    args = ["identify", "--robot", "panda", "--data", str(path), "--out", str(out)]
    args += ["--no-figures", "-q"]  # (the figures are not compared)
    assert main([*args, *extra]) == 0
    return load_model_json(out / "identification.json")


def _same(lib, cli):
    np.testing.assert_allclose(cli.fit.beta, lib.fit.beta, rtol=1e-12, atol=1e-12)
    assert set(cli.terms) == set(lib.terms)
    for name, term in lib.terms.items():
        assert cli.terms[name].labels == term.labels
        np.testing.assert_allclose(cli.terms[name].values, term.values, rtol=1e-12, atol=1e-12)
    for key in ("heldout_error_percent", "training_error_percent", "noise_floor_percent"):
        assert cli.info.heldout[key] == pytest.approx(lib.info.heldout[key], rel=1e-12)


def test_library_and_command_choose_the_same_structure_on_one_log(panda, one_log, tmp_path):
    """identify_from_log's defaults are the command's: the structure and the estimator
    chosen on held-out data."""
    path, log = one_log
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        lib = identify_from_log(panda, log)
        cli = _command(path, tmp_path / "auto")
    # the truth's terms: viscous and sharp Coulomb friction (or the narrow smooth sign, its
    # expected value given the velocity noise)
    name = lib.info.selection["chosen"].partition(" - ")[0]
    assert name in ("links + viscous + coulomb", "links + viscous + smooth:0.3"), name
    assert cli.info.selection["chosen"] == lib.info.selection["chosen"]
    assert cli.info.selection["rule"] == lib.info.selection["rule"]
    _same(lib, cli)


def test_library_classical_terms_are_the_commands_classical_terms(panda, one_log, tmp_path):
    """identify_from_log's classical terms (viscous, Coulomb and offset friction) are
    ``--terms viscous,coulomb,offset``: the same parameters and held-out errors (judged on
    the torques as measured)."""
    path, log = one_log
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        lib = identify_from_log(panda, log, structure="classical")
        cli = _command(path, tmp_path / "fixed", "--terms", "viscous,coulomb,offset")
    assert lib.info.extra["terms"] == ["viscous", "coulomb", "offset"]
    _same(lib, cli)


def test_friction_false_with_terms_given_is_refused(panda, one_log):
    with pytest.raises(OptionError, match="friction=False"):
        identify_from_log(panda, one_log[1], structure=Structure(), friction=False)
    with pytest.raises(OptionError, match="friction=False applies to structure='classical'"):
        identify_from_log(panda, one_log[1], friction=False)  # the default chooses the terms
    with pytest.raises(OptionError, match="^structure must be 'auto', 'classical' or a"):
        identify_from_log(panda, one_log[1], structure=None)  # type: ignore[arg-type]


def test_default_identifies_an_armature_and_reaches_the_noise_floor():
    """A noisy log of an arm whose rotors add 7-15 % to its joints' inertia: the default
    (the structure chosen on held-out data, as the command) finds the armature and
    predicts held-out torques at the noise floor (it fitted friction alone: 4 x the
    floor)."""
    robot = Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), "base_link", "forearm_link"
    )
    fr = ClassicalFriction(np.array([3.0, 2.0, 1.0]), np.array([4.0, 3.0, 2.0]), np.zeros(3))
    armature = np.array([0.4, 0.3, 0.15])
    (log,) = recordings(
        robot, (5,), friction=fr, armature=armature, duration=4.0, fs=250.0, noise=SensorNoise()
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_from_log(robot, log)
    assert "rotor_inertia" in model.terms
    held = model.info.heldout
    assert held["heldout_error_percent"] <= FLOOR_GOOD * held["noise_floor_percent"]
