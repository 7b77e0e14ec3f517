"""A model identified through a wrong torque constant (one factor on every inertial
parameter) against the robot description: named with the factor; a description whose
masses are off joint by joint, or a factor near 1, is not.

References: models holding a known robot's exact gravity coefficients (the factor is the
one applied to its parameters); models fitted to simulated noisy Panda logs whose truth is
known: the torques of the description's arm times 0.9 on every joint (a sensor scale), or
of an arm whose link masses are 7 to 16 % off the description's, each link its own factor
(the truth's gravity torques over the description's per joint, computed from both arms).
"""

from __future__ import annotations

import dataclasses
import logging
import warnings
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.dynamics.terms import gravity_torques
from dynid.exceptions import DynidWarning
from dynid.identification.gravity_scale import (
    gravity_masses_words,
    gravity_ratios,
    gravity_scale_factor,
    gravity_scale_finding,
)
from dynid.identification.motor_constants import SharedGearRatio
from dynid.identification.selection import identify_recordings
from dynid.io.robot.urdf import load_urdf
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.identify import IdentifyOptions, identify_logs, parsed_terms

from conftest import exact_model, perturbed_robot, recordings, said_warnings

#: Each Panda link's inertials (mass, first moments, inertia) in the simulated truth over
#: the description's: 7 to 16 % off, a factor per link (the joints' gravity factors 1.09 to
#: 1.14, within 5 % of their mean: a uniform factor as the spread alone judged it).
MASS_FACTORS = np.array([1.07, 0.93, 0.86, 1.07, 1.16, 1.16, 1.16])
NOISE = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)


@pytest.fixture(scope="module")
def q():
    """Configurations of a Panda spread over its range."""
    robot = dynid.panda()
    return np.random.default_rng(4).uniform(robot.q_min, robot.q_max, (400, 7))


def test_one_factor_on_every_parameter_is_named_with_the_torque_constant(q):
    """Parameters scaled by 0.83 (a torque constant guessed 1 for 1.2 N m/A): the ratio
    0.83 on every loaded joint, and the drive's torque constant to multiply by 1.2."""
    robot = dynid.panda()
    model = exact_model(robot, robot.with_params(0.83 * robot.phi))
    r, c, loaded = gravity_ratios(robot, model, q)
    np.testing.assert_allclose(r[loaded], 0.83, rtol=1e-9)
    drive = Drive(np.eye(7), np.zeros(7), effort="current", torque_constant=np.ones(7))
    said = gravity_scale_finding(robot, model, [q], drive)
    assert said is not None and "0.83 times the robot description's" in said
    assert "torque_constant" in said and "(1.2 times the 1 the currents were read through)" in said
    plain = gravity_scale_finding(robot, model, [q])
    assert plain is not None and "units='tau=1.2'" in plain and "currents" not in plain
    # currents read as torques (3 times the model's): the drive of currents is named too,
    # its torque constants one per motor (a single --units factor fits one joint at most)
    currents = exact_model(robot, robot.with_params(1 / 3 * robot.phi))
    said = gravity_scale_finding(robot, currents, [q])
    assert said is not None and "units='tau=3'" in said
    assert 'effort = "current"' in said and "torque_constant" in said


def test_masses_off_joint_by_joint_or_a_factor_near_one_say_nothing(q):
    """A description 20 % off per parameter at random, or every parameter 5 % off: None;
    the exact model: None."""
    robot = dynid.panda()
    other = perturbed_robot(robot, np.random.default_rng(3), spread=0.2)
    assert gravity_scale_finding(robot, exact_model(robot, other), [q]) is None
    near = exact_model(robot, robot.with_params(0.95 * robot.phi))
    assert gravity_scale_finding(robot, near, [q]) is None
    assert gravity_scale_finding(robot, exact_model(robot, robot), [q]) is None


def test_one_factor_near_a_shared_gear_ratio_names_constants_given_at_the_motors(q):
    """A joint-side drive of gear ratio 100 on every joint whose model came out 1/90 of
    the description (constants given at the motors, the masses 10 % off): the finding says
    the constants look given at the motors and what a joint-side log wants; with gear
    ratio 1, or a factor far from the gear ratio, it does not."""
    robot = dynid.panda()
    model = exact_model(robot, robot.with_params(robot.phi / 90.0))
    geared = Drive(100.0 * np.eye(7), np.zeros(7), effort="current", torque_constant=np.ones(7))
    said = gravity_scale_finding(robot, model, [q], geared)
    assert said is not None and "(90 times the 1 the currents were read through)" in said
    assert "near the gear ratio, 100: torque_constant looks given at the motors" in said
    plain = Drive(np.eye(7), np.zeros(7), effort="current", torque_constant=np.ones(7))
    assert "given at the motors" not in (gravity_scale_finding(robot, model, [q], plain) or "")
    far = exact_model(robot, robot.with_params(robot.phi / 2.0))
    assert "given at the motors" not in (gravity_scale_finding(robot, far, [q], geared) or "x")


def _logged(truth, scale=1.0):
    """A noisy 3 s log of the arm ``truth`` (500 Hz), its torques times ``scale``."""
    (log,) = recordings(truth, [1], friction=None, duration=3.0, noise=NOISE)
    return dataclasses.replace(log, tau=scale * log.tau)


def _fitted(robot, log):
    """The model of ``robot`` fitted to ``log`` with offsets (the truth holds no friction),
    its warnings of the short log's poorly determined parameters aside."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return identify_recordings(robot, [log], structure=parsed_terms("offset"))


def _true_ratios(robot, truth, q):
    """The truth's gravity torques over the description's per joint (least squares)."""
    gd, gt = gravity_torques(robot, q), gravity_torques(truth, q)
    return np.sum(gd * gt, axis=0) / np.sum(gd * gd, axis=0)


def test_masses_off_per_link_give_a_note_and_no_torque_scale():
    """Regression: a description whose link masses are 7 to 16 % off the arm's (a factor
    per link) made the joints' factors 1.09 to 1.14, which were called one sensor scale
    with the hint --units tau=0.887, corrupting right torques; now their standard
    deviations (from the fit's covariance, each joint's true factor within 4 of them) say
    they differ: no finding, a note that the description's masses are off."""
    robot = dynid.panda()
    truth = robot.with_params(robot.phi * MASS_FACTORS[:, None])
    log = _logged(truth)
    model = _fitted(robot, log)
    found = gravity_scale_factor(robot, model, [log.q])
    assert found is not None and not found.one_factor
    js = found.joints
    true = _true_ratios(robot, truth, log.q)[js]
    assert np.ptp(true) > 0.04 and np.all(np.abs(found.ratios[js] - true) < 4 * found.ratio_std[js])
    assert gravity_scale_finding(robot, model, [log.q]) is None
    said = gravity_masses_words(robot, found)
    assert "link masses look off" in said and "needs no change" in said
    assert "--units" not in said and "torque_constant" not in said


def test_torques_scaled_on_every_joint_keep_the_sensor_scale_hint():
    """The same motion of the description's own arm, its torques logged 0.9 times the true
    ones on every joint: one factor, 0.9 within 3 of its standard deviation, and the hint
    --units tau=1.11."""
    robot = dynid.panda()
    log = _logged(robot, 0.9)
    model = _fitted(robot, log)
    found = gravity_scale_factor(robot, model, [log.q])
    assert found is not None and found.one_factor
    assert abs(found.factor - 0.9) < 3 * found.factor_std
    said = gravity_scale_finding(robot, model, [log.q])
    assert said is not None and "units='tau=1.11'" in said and "0.902 (std 0.0016)" in said


def test_identify_notes_masses_off_and_records_no_scale(caplog):
    """identify of the log whose description's masses are off: no warning of a scale, no
    gravity_scale in the metadata (payload would doubt right torques), the note in the
    summary's notes and the model's."""
    robot = dynid.panda()
    log = _logged(robot.with_params(robot.phi * MASS_FACTORS[:, None]))
    with caplog.at_level(logging.INFO, logger="dynid"):
        got, said = said_warnings(identify_logs, robot, log, IdentifyOptions(terms="offset"))
    assert not any("gravity torques" in w for w in said), said
    assert "gravity_scale" not in got.model.info.extra
    notes = [n for n in got.model.info.notes if "link masses look off" in n]
    assert len(notes) == 1 and notes[0] in caplog.text


def test_a_hand_the_description_lacks_is_named_as_a_mass_at_the_flange():
    """A Panda carrying a 0.73 kg hand the built-in description lacks (the truth: the
    description with the hand added to link 7, as the Franka Hand rides the flange): the
    joints' factors differ, and the note names the mass at the flange that makes up the
    difference, the hand's mass and centre of mass to round-off on exact torques; the last
    links heavier than described read as such a mass too (said as the other reading), the
    last links lighter name none (noisy logs)."""
    robot = dynid.panda()
    hand = robot.with_tool(
        np.eye(4), mass=0.73, com=(0.0, 0.0, 0.06),
        inertia=(0.0025, 0.0, 0.0, 0.0025, 0.0, 0.0017), name="hand",
    )  # fmt: skip
    (log,) = recordings(hand, [1], friction=None, duration=3.0)  # exact torques
    found = gravity_scale_factor(robot, _fitted(robot, log), [log.q])
    assert found is not None and not found.one_factor and found.flange is not None
    m, c = found.flange
    flange_com = (hand.phi[6, 1:4] - robot.phi[6, 1:4]) / 0.73  # in link 7's frame
    assert m == pytest.approx(0.73, rel=1e-9) and np.allclose(c, flange_com, atol=1e-9)
    assert f"a mass of about {m:.3g} kg" in gravity_masses_words(robot, found)
    heavier = _logged(robot.with_params(robot.phi * MASS_FACTORS[:, None]))  # links 5-7 too
    said = gravity_masses_words(
        robot, gravity_scale_factor(robot, _fitted(robot, heavier), [heavier.q])
    )
    assert "a mass of about" in said and "or its last links heavier" in said
    lighter = np.array([1.2, 1.2, 1.2, 1.0, 0.8, 0.8, 0.8])  # the last links lighter
    off = _logged(robot.with_params(robot.phi * lighter[:, None]))
    other = gravity_scale_factor(robot, _fitted(robot, off), [off.q])
    assert other is not None and not other.one_factor and other.flange is None
    assert "mass of" not in gravity_masses_words(robot, other)


#: The SO-101 arm of the test data (five joints, 0.47 kg of links) and each link's
#: inertials in the simulated truth over its description's: 15 % off at most, a factor
#: per link.
SO101 = Path(__file__).parent / "data" / "so101_arm.urdf"
SO_MASSES = np.array([1.07, 0.86, 1.14, 1.07, 1.01])
#: The truth's torque constant [N m/A at the joint] of its servo currents.
SO_KT = 0.704


@pytest.fixture(scope="module")
def so101():
    """The SO-101 description and the truth: its links :data:`SO_MASSES` off."""
    robot = load_urdf(SO101, tip_link="gripper_frame_link", snap_angles=True)
    return robot, robot.with_params(robot.phi * SO_MASSES[:, None])


def _so_identified(robot, arm, kt, scale=1.0):
    """identify of an exact 2 s log of ``arm``'s currents (its torques over
    :data:`SO_KT`, times ``scale``) read through the torque constant ``kt`` on every
    joint: the result, its warnings, the held-out gains' line of the torque constants and
    the log's positions."""
    (log,) = recordings(arm, [1], friction=None, duration=2.0)
    currents = dataclasses.replace(log, tau=scale * log.tau / SO_KT)
    drive = Drive(np.eye(5), np.zeros(5), effort="current", torque_constant=np.full(5, kt))
    options = IdentifyOptions(terms="offset", drive=drive)
    got, said = said_warnings(identify_logs, robot, currents, options)
    gains = got.heldout.gains if got.heldout is not None else None
    return got, said, None if gains is None else gains.constants_words(), log.q


def test_a_wrong_torque_constant_beside_masses_off_is_named_first_with_its_fix(so101):
    """Regression (an SO-100 trial): currents read through a torque constant 2.45 times
    the true one, the description's link masses up to 15 % off: the joints' factors
    differ by the masses' error beyond their tiny uncertainty, and the whole factor was
    called the masses' (the model "right as it is and needs no change", a 0.54 kg mass at
    the gripper of a 0.47 kg arm; the torque constants' line "no change to the drive
    file"). Now it is the torque constants', named first: 2.45 times the masses' own
    factors (the truth's gravity torques over the description's, from both arms), the fix
    the constants times its inverse, within the masses' error of the true constant, and no
    mass named."""
    robot, truth = so101
    got, said, line, q = _so_identified(robot, truth, 2.45 * SO_KT)
    masses = _true_ratios(robot, truth, q)[gravity_ratios(robot, got.model, q)[2]]
    factor = got.model.info.extra["gravity_scale"]["factor"]
    assert 2.45 * masses.min() <= factor <= 2.45 * masses.max()
    common = got.heldout.gains.common
    kt = 2.45 * SO_KT * common
    assert abs(kt / SO_KT - 1) <= np.max(np.abs(1 - 1 / masses))
    (found,) = [w for w in said if "gravity torques" in w]
    fix = f"torque_constant = [{', '.join([f'{kt:.4g}'] * 5)}]"
    assert found.startswith(
        f"the torque constants look off by one factor on every motor: put {fix} "
        f"({common:.3g} times the {2.45 * SO_KT:.4g} the currents were read through)"
    )
    assert "needs no change" not in found and "a mass of about" not in found
    assert not any("needs no change" in n for n in got.model.info.notes)
    assert line is not None and "no change to the drive file" not in line
    assert "share one factor" in line and "unless a load the description lacks" in line


def test_the_warning_and_the_constants_line_give_one_fix_nearer_the_truth(so101):
    """Regression (an SO-100 trial): one torque-constant factor was named twice with two
    numbers, the gravity warning's (the gravity torques' ratio, 0.421) and the constants
    line's (the held-out gains' common factor, 0.415; the truth 0.408). Both now give the
    same corrected constants, the gains' (fitted with every motor's currents at once),
    which lie nearer the true constant than the gravity torques' ratio gives them; the
    line names the factor once (no "times the true one" beside "multiply by")."""
    robot, truth = so101
    got, said, line, _ = _so_identified(robot, truth, 2.45 * SO_KT)
    (found,) = [w for w in said if "gravity torques" in w]
    kt_line = line.split("torque_constant = [")[1].split("]")[0]
    kt_warn = found.split("torque_constant = [")[1].split("]")[0]
    assert kt_line == kt_warn, (line, found)
    kt = np.array([float(v) for v in kt_warn.split(", ")])
    by_gravity = 2.45 * SO_KT / got.model.info.extra["gravity_scale"]["factor"]
    assert np.all(np.abs(kt - SO_KT) < abs(by_gravity - SO_KT)), (kt, by_gravity)
    assert "times the true one" not in line and "multiply" not in line
    assert len(found) < 600 and len(line) < 700


def test_currents_in_ma_read_as_amperes_name_the_unit(so101):
    """The same arm's currents logged in mA and read as A through the true constant: the
    factor 1000 times the masses' is named as the unit, with --units tau=mA."""
    robot, truth = so101
    said = _so_identified(robot, truth, SO_KT, scale=1000.0)[1]
    (found,) = [w for w in said if "identified gravity torques" in w]
    assert found.startswith("the currents read") and "currents in mA read as A" in found
    assert "units='tau=mA'" in found and "needs no change" not in found


def test_a_load_the_description_lacks_is_still_named_as_a_mass(so101):
    """The arm carrying 0.1 kg at its gripper, its currents read through the true
    constant: its factors differ by the load's levers (1.9 to 2.3), and the note names a
    mass at the flange within the masses' error of 0.1 kg, no torque constant."""
    robot, truth = so101
    arm = truth.with_tool(np.eye(4), mass=0.1, com=(0.0, 0.0, 0.03))
    got, said, _, _ = _so_identified(robot, arm, SO_KT)
    assert not any("gravity torques" in w for w in said), said
    assert "gravity_scale" not in got.model.info.extra
    (note,) = [n for n in got.model.info.notes if "link masses look off" in n]
    m = float(note.split("a mass of about ")[1].split(" kg")[0])
    assert 0.085 <= m <= 0.115


def test_a_shared_gear_ratio_names_a_remaining_factor_beyond_the_masses():
    """Constants given at the motors over gear ratio 345: a remaining factor of the fitted
    model's gravity torques within 20 % of 1 is the masses' error, one of 2.34 to 2.47 is
    not called so; the torques as logged over the gravity torques (friction and the rotors'
    inertia in them) are not called the masses' error."""
    far = SharedGearRatio(345.0, np.ones(2), np.array([2.34, 2.47])).sentence()
    assert "times 2.34 to 2.47 (beyond the description's masses' error" in far
    near = SharedGearRatio(345.0, np.array([1.1, 1.14]), np.array([0.95, 1.05])).sentence()
    said = "times 0.950 to 1.05 (the fitted model's gravity torques over the description's: "
    assert said + "the masses' error)" in near, near
    raw = SharedGearRatio(345.0, np.array([1.1, 1.14])).sentence()
    assert "times 1.10 to 1.14 (the currents as logged: friction and the rotors' inertia" in raw
