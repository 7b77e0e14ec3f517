"""Friction laws and their placement chosen with the links on exact data: the Stribeck and
quadratic laws, friction at the joints or at the motors of a coupled drive, coefficients
left out joint by joint (the rest of the structure's choice in test_structure.py; a file
of its own so that the test workers share the structure tests).

References: simulated arms whose torques hold a known friction law (registry laws with
given parameters, at the joints or through a known coupling); exact data against round-off.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from test_structure import VISCOUS

from dynid.friction.laws import LAWS
from dynid.friction.model import ClassicalFriction, LawFriction
from dynid.friction.validation import own_friction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.model.drive import Drive

from conftest import recordings

#: seconds of each exact recording: enough for the links, the law and the per-joint
#: coefficients to come back at round-off (the coupled drive's placement needs 4 s: on
#: 3 s logs joint 7's friction at the joint and at the motor tie)
DURATION = 3.0


def test_stribeck_friction_is_identified_with_the_links_and_its_velocity_chosen(panda):
    """Exact data of an arm with Stribeck friction (v_st = 0.05 rad/s): the Stribeck law at
    0.05 rad/s is chosen among the candidates' velocities and its parameters come back."""
    P = np.column_stack([VISCOUS, np.full(7, 0.4), np.full(7, 0.9), np.full(7, 0.05), np.zeros(7)])
    fr = LawFriction(LAWS["stribeck"], P)
    logs = recordings(panda, (61, 62), friction=fr, duration=DURATION)
    model = identify_recordings(panda, logs, cutoff_hz=None)
    # the offsets, zero in the truth, are left out joint by joint
    assert model.info.selection["chosen"] == "links + viscous + coulomb + stribeck:0.05"
    assert model.friction.law == "stribeck"
    np.testing.assert_allclose(model.friction.params, P, atol=1e-7)
    assert model.fit.relative_error_percent < 1e-7
    # the model's own friction is the registry's Stribeck law with these parameters
    v = np.linspace(-1.0, 1.0, 41)[:, None] * np.ones(7)
    np.testing.assert_allclose(own_friction(model).torques(v), fr.torques(v), atol=1e-7)


def test_quadratic_viscous_friction_is_identified_with_the_links(panda):
    """Exact data of an arm whose viscous friction grows with speed (fq dq |dq|): the
    quadratic law is chosen and its parameters come back; validate and the observer
    evaluate it as that law."""
    P = np.column_stack([VISCOUS, np.full(7, 0.2), np.full(7, 0.3), np.zeros(7)])
    fr = LawFriction(LAWS["quadratic"], P)
    logs = recordings(panda, (81, 82), friction=fr, duration=DURATION)
    model = identify_recordings(panda, logs, cutoff_hz=None)
    assert model.info.selection["chosen"] == "links + viscous + quadratic + coulomb"
    assert model.friction.law == "quadratic"
    np.testing.assert_allclose(model.friction.params, P, atol=1e-7)
    v = np.linspace(-2.0, 2.0, 41)[:, None] * np.ones(7)
    np.testing.assert_allclose(own_friction(model).torques(v), fr.torques(v), atol=1e-7)


@pytest.mark.parametrize("truth", ["joint", "motor"])
def test_friction_of_a_coupled_drive_is_placed_where_the_data_say(panda, truth):
    """A coupled drive (motor 7 turns with joints 6 and 7): friction acting at the joints,
    ``f(dq)``, and at the motors, ``K^T f(K dq)``, are different models. Exact data of
    either: the default identification judges both placements and keeps the true one, whose
    parameters come back; the drive file's own placement (the motors) does not decide."""
    truth_drive = Drive.from_gears(np.ones(7), [(7, 6, 0.8)], rotor_inertia=np.zeros(7))
    truth_drive = dataclasses.replace(truth_drive, friction_at=truth)
    fr = ClassicalFriction(VISCOUS, np.linspace(0.6, 0.2, 7), np.zeros(7))
    logs = recordings(panda, (91, 92), friction=fr, drive=truth_drive, duration=4.0)
    given = Drive.from_gears(np.ones(7), [(7, 6, 0.8)], rotor_inertia=np.zeros(7))
    assert given.friction_place == "motor"
    model = identify_recordings(panda, logs, cutoff_hz=None, drive=given)
    sel = model.info.selection
    names = [c["name"] for c in sel["candidates"]]
    assert "links + viscous + at:joint" in names and "links + viscous + at:motor" in names
    judged = [c for c in sel["candidates"] if not c.get("left_out")]  # the per-joint aside
    assert len(judged) == 74  # 35 per placement, 5 at both, the model without friction once
    assert sel["chosen"] == f"links + viscous + coulomb + at:{truth}", sel["chosen"]
    assert model.drive.friction_place == truth
    np.testing.assert_allclose(model.friction.params[:, :2], fr.as_array()[:, :2], atol=1e-7)
    assert model.fit.relative_error_percent < 1e-7
    # the model's own friction acts where it was placed
    v = np.random.default_rng(5).uniform(-1, 1, (20, 7))
    ref = fr.torques(v) if truth == "joint" else fr.torques(v @ given.transmission.T)
    ref = ref if truth == "joint" else ref @ given.transmission
    np.testing.assert_allclose(own_friction(model).torques(v), ref, atol=1e-7)


def test_friction_structure_is_chosen_per_joint(panda):
    """Exact data of an arm whose joints differ: Coulomb friction on joints 1-3 only, a
    torque offset on joint 2 only. The structure chosen holds exactly those coefficients
    (the others left out joint by joint), they come back to 1e-7, and `--terms` names the
    same structure."""
    fc = np.array([0.6, 0.5, 0.4, 0.0, 0.0, 0.0, 0.0])
    fo = np.array([0.0, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0])
    fr = ClassicalFriction(VISCOUS, fc, fo)
    logs = recordings(panda, (71, 72), friction=fr, duration=DURATION)
    model = identify_recordings(panda, logs, cutoff_hz=None)
    want = (
        "links + viscous + coulomb + offset"
        " - fc4 - fc5 - fc6 - fc7 - fo1 - fo3 - fo4 - fo5 - fo6 - fo7"
    )
    chosen = Structure.parse(model.info.selection["chosen"])
    # an armature whose every own rotor is left out holds only the rotors of joints 1-2,
    # which regroup with the links' parameters: the same columns as no armature
    own = {f"Ia{j}" for j in range(3, 8)}
    if chosen.armature and own <= set(chosen.drop):
        drop = tuple(d for d in chosen.drop if d not in own)
        chosen = dataclasses.replace(chosen, armature=False, drop=drop)
    assert chosen == Structure.parse(want), chosen
    assert model.terms["friction"].labels == (
        "fv1", "fc1", "fv2", "fc2", "fo2", "fv3", "fc3", "fv4", "fv5", "fv6", "fv7"
    )  # fmt: skip
    np.testing.assert_allclose(model.friction.params, fr.as_array(), atol=1e-7)
    assert model.fit.relative_error_percent < 1e-7
    v = np.linspace(-1.0, 1.0, 41)[:, None] * np.ones(7)
    np.testing.assert_allclose(own_friction(model).torques(v), fr.torques(v), atol=1e-7)
    # the friction columns' coefficients read back as the law's table
    refit = model.with_coefficients(model.joint_fit.beta)
    np.testing.assert_array_equal(refit.friction.params, model.friction.params)
    # the same structure given by hand
    given = identify_recordings(panda, logs, cutoff_hz=None, structure=Structure.parse(want))
    np.testing.assert_allclose(given.friction.params, model.friction.params, atol=1e-9)
