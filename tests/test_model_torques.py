"""``dynid.model_torques``: a model's whole torques, where ``dynid.rnea`` gives the links
alone (a saved model with a spring, predicted by ``rnea``, was 55 % off its log).

Reference: Pinocchio's RNEA of the same links plus the closed forms of the rotor
inertias ``I_a ddq``, the spring ``k (q - q0)`` and the classical friction
``fv dq + fc sign(dq) + fo``.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.model.drive import Drive
from dynid.model.stiffness import JointStiffness

from conftest import exact_model, pinocchio_panda_model

K = np.array([0.0, 40.0, 0.0, 0.0, 0.0, 0.0, 0.0])  # N m/rad
Q0 = np.full(7, 0.3)  # rad
FV, FC, FO = np.full(7, 0.4), np.full(7, 0.7), np.linspace(-0.5, 0.5, 7)
IA = np.linspace(0.1, 0.3, 7)  # kg m^2


def _saved_model():
    """The Panda as a saved model holds it: friction with offsets and a spring, read
    through a drive with rotor inertias."""
    robot = dynid.panda().with_friction(ClassicalFriction(FV, FC, FO))
    drive = Drive(transmission=np.eye(7), offset=np.zeros(7), rotor_inertia=IA)
    return robot.with_spring(JointStiffness(K, Q0)), drive


def test_model_torques_are_the_links_rotors_spring_and_friction():
    """Pinocchio's RNEA plus the closed forms, to 1e-10 N m; rnea alone is far off."""
    pin = pytest.importorskip("pinocchio")
    robot, drive = _saved_model()
    rng = np.random.default_rng(4)
    q, dq, ddq = (rng.uniform(-1.0, 1.0, (20, 7)) for _ in range(3))
    model = pinocchio_panda_model()
    data = model.createData()
    links = np.array([pin.rnea(model, data, a, b, c) for a, b, c in zip(q, dq, ddq, strict=True)])
    truth = links + IA * ddq + K * (q - Q0) + FV * dq + FC * np.sign(dq) + FO
    np.testing.assert_allclose(
        dynid.model_torques(robot, q, dq, ddq, drive=drive), truth, atol=1e-10
    )
    off = np.linalg.norm(dynid.rnea(robot, q, dq, ddq) - truth) / np.linalg.norm(truth)
    assert off > 0.3


def test_model_torques_keep_the_batch_shape():
    """``(n,)`` in gives ``(n,)``; batch shapes broadcast and are kept."""
    robot, drive = _saved_model()
    one = dynid.model_torques(robot, np.zeros(7), np.full(7, 0.1), np.zeros(7), drive=drive)
    assert one.shape == (7,)
    q = np.zeros((3, 1, 7))
    many = dynid.model_torques(robot, q, np.full(7, 0.1), np.zeros((2, 7)), drive=drive)
    assert many.shape == (3, 2, 7)
    np.testing.assert_allclose(many[2, 1], one, atol=1e-12)


def test_model_torques_refuse_a_wrong_model_and_shape():
    """A dict is not a model; q of another joint count is named."""
    robot, _ = _saved_model()
    with pytest.raises(dynid.WrongTypeError, match="model"):
        dynid.model_torques({}, np.zeros(7), np.zeros(7), np.zeros(7))
    with pytest.raises(dynid.ShapeError, match="q must have shape"):
        dynid.model_torques(robot, np.zeros(6), np.zeros(7), np.zeros(7))


def test_rnea_says_what_it_leaves_out_and_where_the_whole_torques_are():
    """rnea's docstring names the links alone, what it leaves out and model_torques."""
    doc = inspect.getdoc(dynid.rnea) or ""
    for said in ("robot.phi", "friction", "spring", "rotor inertias", "model_torques"):
        assert said in doc, said


def test_an_identified_model_s_torques_are_its_links():
    """An identified model of the Panda's exact coefficients, without terms beside the
    links: Pinocchio's RNEA, to 1e-8 N m."""
    pin = pytest.importorskip("pinocchio")
    panda = dynid.panda()
    model = exact_model(panda, panda)
    rng = np.random.default_rng(5)
    q, dq, ddq = (rng.uniform(-1.0, 1.0, (10, 7)) for _ in range(3))
    ref = pinocchio_panda_model()
    data = ref.createData()
    truth = np.array([pin.rnea(ref, data, a, b, c) for a, b, c in zip(q, dq, ddq, strict=True)])
    np.testing.assert_allclose(dynid.model_torques(model, q, dq, ddq), truth, atol=1e-8)
