"""Robots read from MJCF (``--robot FILE.xml``) through MuJoCo's compiler.

Reference: MuJoCo's own inverse dynamics (``mj_inverse``, Coulomb friction off) of the same
file at random states: ``M ddq + bias + damping dq`` with the armature in ``M`` equals
dynid's rigid-body torques of the robot read, plus its rotor inertias ``Ia ddq`` and its
viscous friction ``fv dq``.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError
from dynid.io.drive_file import drive_of_robot_file
from dynid.io.robot.mjcf import save_mjcf
from dynid.io.robot_file import load_robot
from dynid.model.drive import Drive

mujoco = pytest.importorskip("mujoco")

#: Not written by dynid: degrees, euler angles, a joint away from its body's origin, a
#: principal inertia turned by a quaternion, a massive body fixed to a link, a prismatic
#: joint, a site, limits on some joints only, an actuator with a gear.
HAND_WRITTEN = """<mujoco model="hand">
  <compiler angle="degree"/>
  <option gravity="0 0.5 -9.81"/>
  <worldbody>
    <body name="base" pos="0 0 0">
      <body name="l1" pos="0 0 0.3" euler="0 0 30">
        <joint name="j1" type="hinge" axis="0 0 1" range="-170 170" damping="0.3"
               armature="0.2"/>
        <inertial pos="0.01 0 0.1" mass="3" diaginertia="0.03 0.02 0.01"
                  quat="0.9 0.1 0.3 0.2"/>
        <body name="l2" pos="0 0.05 0.25" euler="90 0 0">
          <joint name="j2" type="hinge" axis="0 1 0.2" pos="0 0 0.05" frictionloss="0.7"/>
          <inertial pos="0.2 0 0" mass="2" diaginertia="0.01 0.05 0.05"/>
          <body name="bracket" pos="0.4 0 0" euler="0 45 0">
            <inertial pos="0 0 0.02" mass="0.5" diaginertia="0.001 0.002 0.003"/>
            <site name="flange" pos="0 0 0.04"/>
          </body>
          <body name="l3" pos="0.4 0 0">
            <joint name="j3" type="slide" axis="1 0 0" range="-0.1 0.2" damping="2"/>
            <inertial pos="0.05 0.01 0" mass="1" diaginertia="0.002 0.003 0.004"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="j1" gear="50" ctrlrange="-2 2"/>
  </actuator>
</mujoco>
"""


def _mujoco_torques(path, q, dq, ddq):
    """``mj_inverse`` at each state, constraints (joint limits, frictionloss) off."""
    m = mujoco.MjModel.from_xml_path(str(path))
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    d = mujoco.MjData(m)
    out = np.empty_like(q)
    for k in range(q.shape[0]):
        d.qpos[:], d.qvel[:], d.qacc[:] = q[k], dq[k], ddq[k]
        mujoco.mj_inverse(m, d)
        out[k] = d.qfrc_inverse
    return out


def _dynid_torques(path, q, dq, ddq):
    """dynid's rigid-body torques of the robot read, plus Ia ddq and fv dq."""
    robot = load_robot(path)
    drive = drive_of_robot_file(path, robot.n)
    tau = np.asarray(dynid.rnea(robot.with_friction(None), q, dq, ddq))
    if drive is not None:
        tau = tau + drive.rotor_inertia * ddq
    if robot.friction is not None:
        tau = tau + np.asarray(robot.friction.params)[:, 0] * dq  # fv
    return robot, tau


def _states(n, seed=0):
    rng = np.random.default_rng(seed)
    return (0.8 * rng.standard_normal((20, n)) for _ in range(3))


def test_a_hand_written_mjcf_gives_mujocos_inverse_dynamics(tmp_path):
    path = tmp_path / "hand.xml"
    path.write_text(HAND_WRITTEN)
    q, dq, ddq = _states(3)
    q[:, 2] *= 0.1  # the slide within reach
    robot, tau = _dynid_torques(path, q, dq, ddq)
    np.testing.assert_allclose(tau, _mujoco_torques(path, q, dq, ddq), atol=1e-9, rtol=1e-9)
    assert robot.joint_names == ("j1", "j2", "j3") and robot.link_names[0] == "base"
    np.testing.assert_allclose(robot.q_min, [-np.radians(170), -np.inf, -0.1])
    np.testing.assert_allclose(robot.tau_max, [100.0, np.inf, np.inf])  # 2 x gear 50
    np.testing.assert_allclose(robot.gravity, [0.0, 0.5, -9.81])
    fr = np.asarray(robot.friction.params)  # classical: fv, fc, fo
    np.testing.assert_allclose(fr, [[0.3, 0.0, 0.0], [0.0, 0.7, 0.0], [2.0, 0.0, 0.0]])
    assert robot.frames["flange"].link == 2 and robot.frames["bracket"].link == 2
    # the site in the world at q = 0 where MuJoCo puts it
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    T = dynid.fk(robot, np.zeros(3), frame="flange")
    np.testing.assert_allclose(np.asarray(T)[:3, 3], d.site_xpos[0], atol=1e-12)


def test_the_mjcf_export_reads_back_to_the_same_dynamics(tmp_path):
    """The Panda with rotor inertias, exported: MuJoCo and dynid's reading agree, and the
    reading is the Panda's own rigid body."""
    panda = dynid.panda()
    ia = np.linspace(0.1, 0.4, 7)
    drive = Drive(transmission=np.eye(7), offset=np.zeros(7), rotor_inertia=ia)
    path = save_mjcf(tmp_path / "panda.xml", panda, friction=False, drive=drive)
    q, dq, ddq = _states(7, seed=1)
    robot, tau = _dynid_torques(path, q, dq, ddq)
    np.testing.assert_allclose(tau, _mujoco_torques(path, q, dq, ddq), atol=1e-8, rtol=1e-9)
    np.testing.assert_allclose(drive_of_robot_file(path, 7).rotor_inertia, ia)
    rigid = np.asarray(dynid.rnea(panda.with_friction(None), q, dq, ddq))
    np.testing.assert_allclose(tau - ia * ddq, rigid, atol=1e-8)


def test_validate_takes_the_mjcf_export(tmp_path, capsys):
    """`validate --robot` read an MJCF as a refusal ('must be ... .urdf, .toml or
    .json'); now it validates it: its rigid body (and rotor inertias) as the TOML export
    of the same robot (its friction is MJCF's approximation of the Panda's sigmoid)."""
    log = tmp_path / "log.csv"
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "--duration", "4"]
    assert main([*sim, "--seed", "3", "-q", "--out", str(log)]) == 0
    xml, toml = tmp_path / "p.xml", tmp_path / "p.toml"
    for f in (xml, toml):
        assert main(["export", "--params", "panda", "--out", str(f), "-q"]) == 0
    rigid = {}
    for f in (xml, toml):
        out = tmp_path / f"v_{f.suffix[1:]}"
        assert main(["validate", "--robot", str(f), "--data", str(log), "--out", str(out)]) in (
            0,
            1,
        )
        said = capsys.readouterr().out
        assert "relative error" in said
        rows = [
            x.split()
            for x in said.splitlines()
            if x.startswith("joint") and x.split()[0][5:].isdigit()
        ]
        rigid[f.suffix] = np.array([float(r[1]) for r in rows])  # RMS without friction
    assert rigid[".xml"].shape == (7,)
    np.testing.assert_allclose(rigid[".xml"], rigid[".toml"], rtol=1e-3)


def test_an_mjcf_that_is_not_a_serial_chain_is_refused_in_one_line(tmp_path):
    path = tmp_path / "free.xml"
    path.write_text(
        '<mujoco><worldbody><body name="b"><freejoint name="f"/>'
        '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></worldbody></mujoco>'
    )
    with pytest.raises(DataError, match=r"free\.xml.*joint\(s\) f: only hinge and slide"):
        load_robot(path)
