"""The library's route from a torque log to robot files: ``retrieve_sdp`` carries what the
model identified beside the links (friction with its offsets, rotor inertias, the drive),
and ``save_robot`` of the result writes it, or says what a format cannot hold, as ``dynid
retrieve``'s output folder does. Checked by Pinocchio and MuJoCo reading the files, against
the simulated arm's truth."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pinocchio as pin
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.feasibility import retrieve_sdp
from dynid.friction.model import ClassicalFriction
from dynid.identification.structure import Structure
from dynid.io.export import save_robot
from dynid.io.feasible_bundle import save_feasible_bundle

from conftest import mujoco_inverse, recordings, robot_data_urdf

#: The UR5's shoulder and elbow (its wrist and tool lumped into the forearm, as Pinocchio
#: locks them), with rotor inertias [kg m^2] of the size of the links' and classical
#: friction [N m s/rad, N m, N m] at the joints.
IA = np.array([0.4, 0.3, 0.15])
FV = np.array([3.0, 2.0, 1.0])
FC = np.array([4.0, 3.0, 2.0])
FO = np.array([0.3, -0.2, 0.1])
WRIST = ("wrist_1_joint", "wrist_2_joint", "wrist_3_joint")


def _pinocchio_arm(gravity):
    """Pinocchio's model of the true arm: the UR5 with its wrist locked at zero, under
    ``gravity`` (3,) [m/s^2]."""
    full = pin.buildModelFromUrdf(robot_data_urdf("ur_description/urdf/ur5_robot.urdf"))
    locked = [full.getJointId(name) for name in WRIST]
    arm = pin.buildReducedModel(full, locked, pin.neutral(full))
    arm.gravity.linear = np.asarray(gravity)
    return arm


def _mass_matrices(model, q):
    """Pinocchio's joint-space inertia M(q) (N, n, n) of ``model`` at each ``q`` (N, n)."""
    data = model.createData()
    out = np.array([pin.crba(model, data, s) for s in q])
    return np.triu(out) + np.transpose(np.triu(out, 1), (0, 2, 1))


@pytest.fixture(scope="module")
def retrieved():
    """An exact log of the arm with armature and friction, identified with both, and its
    links retrieved with the true description as prior."""
    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    robot = dynid.Robot.from_urdf(path, "base_link", "forearm_link")
    fr = ClassicalFriction(FV, FC, FO)
    (log,) = recordings(robot, (5,), friction=fr, armature=IA, duration=2.0, fs=100.0)
    terms = Structure(armature=True, friction=("viscous", "coulomb", "offset"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)  # a short log: weak coefficients
        model = dynid.identify_from_log(robot, log, cutoff_hz=None, structure=terms)
    return robot, model, retrieve_sdp(model, prior=robot)


def test_retrieve_sdp_carries_the_identified_friction_and_offsets(retrieved):
    """The two-step retrieval's result holds the model's friction (it was None: the
    library route lost what the command's route kept), equal to the simulated truth."""
    _, _, res = retrieved
    assert res.friction is not None
    np.testing.assert_allclose(res.friction.params, np.c_[FV, FC, FO], rtol=1e-6, atol=1e-6)
    assert res.drive is not None and res.determined is not None


def test_saved_urdf_holds_the_friction_and_names_the_armature_it_cannot_hold(retrieved, tmp_path):
    """save_robot(path, result): Pinocchio reads the true friction from <dynamics>; the
    warning's armature per joint, added to Pinocchio's M(q) of the file, gives the
    model's own M(q) with its armature and the true arm's (links + rotors)."""
    robot, model, res = retrieved
    with pytest.warns(DynidWarning) as said:
        path = save_robot(tmp_path / "arm.urdf", res)
    text = " ".join(str(w.message) for w in said)
    assert "leaves out the armature" in text and "the offsets fo" in text
    named = re.search(r"armature per joint \[kg m\^2\]: (.*?), the inertia", text)
    assert named is not None
    arm = np.array([float(v) for v in re.findall(r"_joint ([0-9.e+-]+) \(", named.group(1))])
    written = pin.buildModelFromUrdf(str(path))
    np.testing.assert_allclose(written.damping, FV, rtol=1e-6)
    np.testing.assert_allclose(written.friction, FC, rtol=1e-6)
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (50, 3))
    m_file = _mass_matrices(written, q)
    m_true = _mass_matrices(_pinocchio_arm(robot.gravity), q) + np.diag(IA)
    own = model.mass_matrix(q)
    np.testing.assert_allclose(arm, IA, rtol=2e-3)  # as printed, 4 digits
    assert np.linalg.norm(m_file - own) > 0.05 * np.linalg.norm(own)  # the armature's share
    np.testing.assert_allclose(m_file + np.diag(arm), own, atol=2e-3 * np.abs(own).max())
    np.testing.assert_allclose(m_file + np.diag(IA), m_true, atol=1e-5 * np.abs(own).max())


def test_saved_mjcf_holds_the_armature_and_the_friction(retrieved, tmp_path):
    """save_robot(path.xml, result): MuJoCo's inverse dynamics of the file is the true
    arm's links and rotors (Pinocchio's RNEA plus IA ddq), its damping and dry friction
    the true ones."""
    mujoco = pytest.importorskip("mujoco")
    robot, _, res = retrieved
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)  # mj_inverse's friction near reversals
        path = save_robot(tmp_path / "arm.xml", res)
    mj = mujoco.MjModel.from_xml_path(str(path))
    np.testing.assert_allclose(mj.dof_armature, IA, rtol=1e-4)  # split by the retrieval
    np.testing.assert_allclose(mj.dof_damping, FV, rtol=1e-6)
    np.testing.assert_allclose(mj.dof_frictionloss, FC, rtol=1e-6)
    mj.dof_damping[:] = mj.dof_frictionloss[:] = 0.0  # the rigid body and rotors alone
    rng = np.random.default_rng(4)
    q, dq, ddq = rng.uniform(-2.0, 2.0, (3, 20, 3))
    arm = _pinocchio_arm(robot.gravity)
    data = arm.createData()
    truth = np.array([pin.rnea(arm, data, *s) for s in zip(q, dq, ddq, strict=True)]) + IA * ddq
    got = mujoco_inverse(mj, q, dq, ddq)
    np.testing.assert_allclose(got, truth, atol=1e-5 * np.abs(truth).max())


def test_save_robot_of_a_result_writes_what_the_output_folder_writes(retrieved, tmp_path):
    """One path: the URDF of save_robot(result) is the output folder's robot.urdf (the
    command's), but for the folder's note of the files written beside it."""
    _, _, res = retrieved
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        save_feasible_bundle(tmp_path, res)
        alone = save_robot(tmp_path / "alone.urdf", res)
    folder = pin.buildModelFromUrdf(str(tmp_path / "robot.urdf"))
    single = pin.buildModelFromUrdf(str(alone))
    np.testing.assert_array_equal(single.damping, folder.damping)
    np.testing.assert_array_equal(single.friction, folder.friction)
    for a, b in zip(single.inertias, folder.inertias, strict=True):
        np.testing.assert_array_equal(a.toDynamicParameters(), b.toDynamicParameters())
