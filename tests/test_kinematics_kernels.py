"""The compiled (numba) kinematics kernels against the numpy reference path and Pinocchio."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import dynid
from dynid import _compiled
from dynid.kinematics import forward as forward_module
from dynid.kinematics.forward import fk_numpy, frame_pose_in_link, link_poses_numpy
from dynid.kinematics.jacobian import jacobian_numpy

from conftest import pinocchio_panda_urdf, random_states

pytest.importorskip("numba")
from dynid.kinematics import _kernels  # noqa: E402  (after the skip: imports numba)


@pytest.fixture(autouse=True)
def _kernels_in_use():
    """The public functions must take the kernel path in this module."""
    if forward_module.kernels() is None:
        pytest.skip("compiled kernels disabled (DYNID_NO_NUMBA)")


def kernel_link_poses(robot, q):
    """The link-pose kernel called directly on (B, n) positions."""
    T = np.empty((q.shape[0], robot.n + 1, 4, 4))
    ok = _kernels.link_poses(_compiled.pack(robot), q.reshape(-1), T.reshape(-1))
    assert ok
    return T


def kernel_fk(robot, q, frame, tool=None):
    """The frame-pose kernel called directly on (B, n) positions."""
    link, T_lf = frame_pose_in_link(robot, frame, tool)
    T_lf = forward_module._readonly(T_lf)  # the type the public functions pass
    T = np.empty((q.shape[0], 4, 4))
    CF = _compiled.pack_frame(_compiled.pack(robot), link, T_lf)
    ok = _kernels.frame_pose(CF, q.reshape(-1), T.reshape(-1))
    assert ok
    return T


def kernel_jacobian(robot, q, frame, tool=None):
    """The Jacobian kernel called directly on (B, n) positions."""
    link, T_lf = frame_pose_in_link(robot, frame, tool)
    T_lf = forward_module._readonly(T_lf)  # the type the public functions pass
    J = np.empty((q.shape[0], 6, robot.n))
    CF = _compiled.pack_frame(_compiled.pack(robot), link, T_lf)
    ok = _kernels.jacobian(CF, q.reshape(-1), J.reshape(-1))
    assert ok
    return J


def tilted_rpr(seed: int) -> dynid.Robot:
    """An 'RPR' MDH arm whose joint axes are tilted away from z, with a flange offset."""
    rng = np.random.default_rng(seed)
    robot = dynid.Robot.from_mdh(
        a=[0.0, 0.3, 0.05],
        d=[0.4, 0.1, 0.2],
        alpha=[0.0, -np.pi / 2, np.pi / 2],
        theta=[0.0, 0.3, -0.2],
        joint_types="RPR",
        flange=(0.02, 0.15, 0.4, -0.3),
        name="rpr_tilted",
    )
    axes = np.array([0.0, 0.0, 1.0]) + rng.uniform(-0.6, 0.6, (3, 3))
    return robot.replace(axes=axes / np.linalg.norm(axes, axis=1)[:, None])


def tool_pose() -> np.ndarray:
    """A tool 12 cm out along a tilted axis of the flange."""
    c, s = np.cos(0.7), np.sin(0.7)
    T = np.eye(4)
    T[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
    T[:3, 3] = [0.03, -0.02, 0.12]
    return T


def pin_chain(robot: dynid.Robot, tool: np.ndarray):
    """``robot`` rebuilt joint by joint in Pinocchio (unaligned axes), with its frames."""
    pin = pytest.importorskip("pinocchio")
    model = pin.Model()
    parent = 0
    for i in range(robot.n):
        T = robot.T_parent_joint[i]
        ax = np.array(robot.axes[i])
        joint = (
            pin.JointModelPrismaticUnaligned(ax)
            if robot.prismatic[i]
            else pin.JointModelRevoluteUnaligned(ax)
        )
        parent = model.addJoint(parent, joint, pin.SE3(T[:3, :3], T[:3, 3]), f"j{i + 1}")
    fids = {}
    for name, f in robot.frames.items():
        for suffix, T in (("", f.T_link_frame), ("+tool", f.T_link_frame @ tool)):
            frame = pin.Frame(
                name + suffix, f.link, 0, pin.SE3(T[:3, :3], T[:3, 3]), pin.FrameType.OP_FRAME
            )
            fids[name + suffix] = model.addFrame(frame)
    return model, model.createData(), fids


def test_kernels_match_numpy_path_and_pinocchio_on_every_panda_link():
    """Poses and Jacobians of every Panda link: kernel == numpy path == Pinocchio (1e-12)."""
    pin = pytest.importorskip("pinocchio")
    robot = dynid.panda()
    full = pin.buildModelFromUrdf(pinocchio_panda_urdf())
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    data = model.createData()
    q, _, _ = random_states(robot, 100, seed=31)
    T_k = kernel_link_poses(robot, q)
    np.testing.assert_allclose(T_k, link_poses_numpy(robot, q), rtol=0, atol=1e-14)
    np.testing.assert_array_equal(dynid.link_poses(robot, q), T_k)
    frames = {k: f"link{k}" for k in range(1, 8)} | {8: "flange"}
    J_k = {k: kernel_jacobian(robot, q, name) for k, name in frames.items()}
    F_k = {k: kernel_fk(robot, q, name) for k, name in frames.items()}
    for k, name in frames.items():
        np.testing.assert_allclose(J_k[k], jacobian_numpy(robot, q, name), rtol=0, atol=1e-14)
        np.testing.assert_allclose(F_k[k], fk_numpy(robot, q, name), rtol=0, atol=1e-14)
        np.testing.assert_array_equal(dynid.jacobian(robot, q, name), J_k[k])
        np.testing.assert_array_equal(dynid.fk(robot, q, name), F_k[k])
    for s in range(len(q)):
        pin.forwardKinematics(model, data, q[s])
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, q[s])
        for k in frames:  # panda_link8 is dynid's flange
            fid = model.getFrameId(f"panda_link{k}")
            T_pin = data.oMf[fid].homogeneous
            if k < 8:
                np.testing.assert_allclose(T_k[s, k], T_pin, rtol=0, atol=1e-12)
            np.testing.assert_allclose(F_k[k][s], T_pin, rtol=0, atol=1e-12)
            J_pin = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(J_k[k][s], J_pin, rtol=0, atol=1e-12)


def test_kernels_match_numpy_path_and_pinocchio_on_tilted_rpr_arm_with_a_tool():
    """An 'RPR' arm with tilted axes: every frame, with and without a tool (1e-12)."""
    pin = pytest.importorskip("pinocchio")
    robot = tilted_rpr(seed=32)
    assert not np.allclose(robot.axes[:, :2], 0.0)
    tool = tool_pose()
    model, data, fids = pin_chain(robot, tool)
    q = np.random.default_rng(33).uniform(-2.0, 2.0, (100, robot.n))
    T_k = kernel_link_poses(robot, q)
    np.testing.assert_allclose(T_k, link_poses_numpy(robot, q), rtol=0, atol=1e-14)
    np.testing.assert_array_equal(dynid.link_poses(robot, q), T_k)
    cases = [(name, t) for name in robot.frames for t in (None, tool)]
    F, J = {}, {}
    for name, t in cases:
        key = name if t is None else name + "+tool"
        F[key], J[key] = kernel_fk(robot, q, name, t), kernel_jacobian(robot, q, name, t)
        np.testing.assert_allclose(F[key], fk_numpy(robot, q, name, t), rtol=0, atol=1e-14)
        np.testing.assert_allclose(J[key], jacobian_numpy(robot, q, name, t), rtol=0, atol=1e-14)
        np.testing.assert_array_equal(dynid.fk(robot, q, name, t), F[key])
        np.testing.assert_array_equal(dynid.jacobian(robot, q, name, t), J[key])
    for s in range(len(q)):
        pin.forwardKinematics(model, data, q[s])
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, q[s])
        for k in range(1, robot.n + 1):
            np.testing.assert_allclose(T_k[s, k], data.oMi[k].homogeneous, rtol=0, atol=1e-12)
        for key, fid in fids.items():
            np.testing.assert_allclose(F[key][s], data.oMf[fid].homogeneous, rtol=0, atol=1e-12)
            J_pin = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(J[key][s], J_pin, rtol=0, atol=1e-12)


def test_kernel_jacobian_matches_finite_differences_of_kernel_fk():
    """The Jacobian's columns are the central differences of the tool origin and rotation."""
    robot = tilted_rpr(seed=34)
    tool = tool_pose()
    q = np.random.default_rng(35).uniform(-2.0, 2.0, robot.n)
    J = dynid.jacobian(robot, q, tool=tool)
    h = 1e-6
    for i in range(robot.n):
        e = np.zeros(robot.n)
        e[i] = h
        Tp, Tm = dynid.fk(robot, q + e, tool=tool), dynid.fk(robot, q - e, tool=tool)
        v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ dynid.fk(robot, q, tool=tool)[:3, :3].T
        w = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
        np.testing.assert_allclose(J[:3, i], v, rtol=0, atol=1e-8)
        np.testing.assert_allclose(J[3:, i], w, rtol=0, atol=1e-8)


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_kernel_paths_keep_batch_shapes(shape):
    """(n,) gives one result, (1, n) a batch of one, (3, 2, n) a (3, 2) batch (kernel path)."""
    robot = dynid.panda()
    q = np.random.default_rng(36).uniform(-1.0, 1.0, shape + (7,))
    T = dynid.link_poses(robot, q)
    F = dynid.fk(robot, q, "link5", tool=tool_pose())
    J = dynid.jacobian(robot, q, "link5", tool=tool_pose())
    assert T.shape == shape + (8, 4, 4) and F.shape == shape + (4, 4) and J.shape == shape + (6, 7)
    np.testing.assert_allclose(T, link_poses_numpy(robot, q), rtol=0, atol=1e-14)
    np.testing.assert_allclose(F, fk_numpy(robot, q, "link5", tool_pose()), rtol=0, atol=1e-14)
    np.testing.assert_allclose(
        J, jacobian_numpy(robot, q, "link5", tool_pose()), rtol=0, atol=1e-14
    )
    flat = q.reshape(-1, 7)
    for k, row in enumerate(flat):
        idx = np.unravel_index(k, shape) if shape else ()
        np.testing.assert_array_equal(T[idx], dynid.link_poses(robot, row))
        np.testing.assert_array_equal(J[idx], dynid.jacobian(robot, row, "link5", tool_pose()))
    np.testing.assert_array_equal(J[..., 5:], 0.0)  # joints after link 5 do not move it


def test_kernel_paths_accept_lists_views_read_only_and_float32():
    """Lists, strided views, read-only and float32 arrays give the numpy path's result."""
    robot = dynid.panda()
    q, _, _ = random_states(robot, 6, seed=37)
    wide = np.repeat(q, 2, axis=1)[:, ::2]  # non-contiguous view equal to q
    ro = q.copy()
    ro.setflags(write=False)
    ref_T, ref_J = link_poses_numpy(robot, q), jacobian_numpy(robot, q)
    for qq in (q.tolist(), wide, ro, np.asfortranarray(q)):
        np.testing.assert_allclose(dynid.link_poses(robot, qq), ref_T, rtol=0, atol=1e-14)
        np.testing.assert_allclose(dynid.jacobian(robot, qq), ref_J, rtol=0, atol=1e-14)
        np.testing.assert_allclose(
            dynid.fk(robot, qq),
            ref_T[:, -1] @ robot.frame("flange").T_link_frame,
            rtol=0,
            atol=1e-14,
        )
    q32 = q[0].astype(np.float32)
    np.testing.assert_allclose(dynid.fk(robot, q32), fk_numpy(robot, q32), rtol=0, atol=1e-14)
    T = dynid.fk(robot, q)
    assert not np.shares_memory(T, q) and q.flags.writeable


def test_kernel_handles_a_frame_on_the_base():
    """A frame on link 0 does not move: constant pose, zero Jacobian."""
    robot = tilted_rpr(seed=38).with_frame("stand", tool_pose(), parent="link0")
    q = np.random.default_rng(39).uniform(-2.0, 2.0, (4, robot.n))
    np.testing.assert_array_equal(
        dynid.fk(robot, q, "stand"), np.broadcast_to(tool_pose(), (4, 4, 4))
    )
    np.testing.assert_array_equal(dynid.jacobian(robot, q, "stand"), 0.0)


def error_of(fn, *args, **kw):
    """Type and message of the exception ``fn`` raises."""
    with pytest.raises(dynid.DynidError) as info:
        fn(*args, **kw)
    return type(info.value), str(info.value)


@pytest.mark.parametrize(
    "public, reference",
    [
        (dynid.fk, fk_numpy),
        (dynid.jacobian, jacobian_numpy),
        (
            lambda r, q, *a, **k: dynid.link_poses(r, q),
            lambda r, q, *a, **k: link_poses_numpy(r, q),
        ),
    ],
)
def test_kernel_paths_raise_the_numpy_paths_errors(public, reference):
    """Wrong shapes, NaN/inf and unknown frames raise the same errors as the numpy path."""
    robot = dynid.panda()
    q, _, _ = random_states(robot, 4, seed=40)
    bad = q.copy()
    bad[2, 5] = np.inf
    nan = q[0].copy()
    nan[3] = np.nan
    for args in ((bad,), (nan,), (np.zeros(6),), (np.zeros((3, 8)),), (1.0,), ("abc",)):
        assert error_of(public, robot, *args) == error_of(reference, robot, *args)
    kind, msg = error_of(public, robot, bad)
    assert kind is dynid.NonFiniteError and msg.startswith("q must be finite")
    assert "(2, 5)" in msg
    kind, msg = error_of(public, robot, np.zeros(6))
    assert kind is dynid.ShapeError and "q must have shape (..., 7)" in msg


@pytest.mark.parametrize("fn", [dynid.fk, dynid.jacobian])
def test_kernel_paths_raise_for_unknown_frames_and_bad_tools(fn):
    """Unknown frame names and non-4x4 tools raise as documented, before q is looked at."""
    robot = dynid.panda()
    with pytest.raises(dynid.UnknownNameError, match="Unknown frame 'link9'; available"):
        fn(robot, np.zeros(7), "link9")
    with pytest.raises(dynid.UnknownNameError, match="Unknown frame"):
        fn(robot, np.full(7, np.nan), "link9")
    with pytest.raises(dynid.ShapeError, match=r"tool must have shape \(4, 4\)"):
        fn(robot, np.zeros(7), tool=np.eye(3))
    with pytest.raises(dynid.NonFiniteError, match="tool must be finite"):
        fn(robot, np.zeros(7), tool=np.full((4, 4), np.nan))


def test_no_numba_environment_variable_selects_the_kinematics_numpy_path():
    """With DYNID_NO_NUMBA=1 no kernel is loaded, numba is not imported, results agree."""
    code = (
        "import json, sys, numpy as np, dynid\n"
        "from dynid.kinematics.forward import kernels\n"
        "r = dynid.panda(); q = np.linspace(-1, 1, 7)\n"
        "T = dynid.fk(r, q); J = dynid.jacobian(r, q); L = dynid.link_poses(r, q)\n"
        "assert kernels() is None and 'numba' not in sys.modules\n"
        "print(json.dumps([T.tolist(), J.tolist(), L.tolist()]))\n"
    )
    env = dict(os.environ, DYNID_NO_NUMBA="1")
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    T, J, L = json.loads(out.stdout)
    robot = dynid.panda()
    q = np.linspace(-1, 1, 7)
    np.testing.assert_allclose(T, dynid.fk(robot, q), rtol=0, atol=1e-14)
    np.testing.assert_allclose(J, dynid.jacobian(robot, q), rtol=0, atol=1e-14)
    np.testing.assert_allclose(L, dynid.link_poses(robot, q), rtol=0, atol=1e-14)


def test_import_dynid_does_not_import_the_kinematics_kernels():
    """``import dynid`` stays light: the kinematics kernels load on the first call only."""
    code = (
        "import sys, dynid\n"
        "assert 'numba' not in sys.modules\n"
        "assert 'dynid.kinematics._kernels' not in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
