"""The compiled kernels against the numpy reference paths and Pinocchio.

Each pair is the public function (compiled kernel: batches, and single samples through the
thin path once the kernels are loaded) and its documented numpy reference path. They must
agree to rounding (1e-12 relative to the largest entry) for batch shapes (), (1,), (3, 2) and
a batch of 300, on the Panda and on an arm with a prismatic joint and tilted axes, with a tool.
The rest checks what one table cannot: the kernels called directly against Pinocchio, block
boundaries, huge angles, the vectorised sine, frames on the base, error messages, unusual
inputs (lists, views, read-only, float32) and that numba loads only when it pays.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import dynid
from dynid import _kernels
from dynid.dynamics import rnea as rnea_module
from dynid.dynamics.rnea import _rnea, _rnea_numpy, rnea_numpy
from dynid.dynamics.terms import gravity_torques_numpy, mass_matrix_numpy
from dynid.kinematics import forward as forward_module
from dynid.kinematics.forward import fk_numpy, frame_pose_in_link, link_poses_numpy
from dynid.kinematics.jacobian import jacobian_numpy
from dynid.observer.terms import momentum_terms, momentum_terms_numpy
from dynid.regressors.static import static_regressor_numpy
from dynid.regressors.torque import torque_regressor, torque_regressor_numpy

from conftest import pinocchio_panda_urdf, random_states

pytest.importorskip("numba")
from dynid._kernels import chain as _chain  # noqa: E402  (after the skip: imports numba)
from dynid._kernels import dynamics as dyn_kernels  # noqa: E402
from dynid._kernels import kinematics as kin_kernels  # noqa: E402

TOOL = dynid.spatial.transform_from_xyz_rpy([0.02, -0.01, 0.1], [0.1, -0.2, 0.3])


@pytest.fixture(autouse=True)
def _kernels_loaded():
    """Load the kernels, so that single samples take them too (skip without numba)."""
    if rnea_module.kernels() is None or forward_module.kernels() is None:
        pytest.skip("compiled kernels disabled (DYNID_NO_NUMBA)")


def rpr_tilted() -> dynid.Robot:
    """An 'RPR' arm with a prismatic middle joint, tilted axes, off-axis CoMs, odd gravity."""
    rng = np.random.default_rng(7)
    A = rng.normal(size=(3, 3, 3))
    return dynid.Robot.from_mdh(
        a=[0.0, 0.3, 0.05],
        d=[0.4, 0.1, 0.2],
        alpha=[0.3, -np.pi / 2, np.pi / 2],
        theta=[0.0, 0.3, -0.2],
        joint_types="RPR",
        mass=rng.uniform(0.5, 3.0, 3),
        com=rng.uniform(-0.1, 0.1, (3, 3)),
        inertia=np.einsum("nij,nkj->nik", A, A) * 0.01 + np.eye(3) * 0.01,
        gravity=(0.3, -0.2, -9.81),
        flange=(0.02, 0.15, 0.4, -0.3),
        name="rpr_tilted",
    )


ROBOTS = {"panda": dynid.panda, "rpr_tilted": rpr_tilted}


def _coriolis_numpy(robot, q, dq):
    """c(q, dq): the numpy RNEA without gravity at zero acceleration."""
    return rnea_numpy(robot, q, dq, np.zeros_like(q), gravity=np.zeros(3))


def _forward_dynamics_numpy(robot, q, dq, tau):
    """M^-1 (tau - c - g) from the numpy mass matrix and RNEA, by numpy's LU solve."""
    bias = rnea_numpy(robot, q, dq, np.zeros_like(q))
    return np.linalg.solve(mass_matrix_numpy(robot, q), (tau - bias)[..., None])[..., 0]


#: name -> (public function, numpy reference, arguments built from (robot, q, dq, ddq))
PAIRS = {
    "link_poses": (dynid.link_poses, link_poses_numpy, lambda r, q, v, a: (r, q)),
    "fk": (dynid.fk, fk_numpy, lambda r, q, v, a: (r, q)),
    "fk_tool": (
        lambda r, q: dynid.fk(r, q, tool=TOOL),
        lambda r, q: fk_numpy(r, q, tool=TOOL),
        lambda r, q, v, a: (r, q),
    ),
    "jacobian": (dynid.jacobian, jacobian_numpy, lambda r, q, v, a: (r, q)),
    "jacobian_tool_link2": (
        lambda r, q: dynid.jacobian(r, q, r.link_names[2], tool=TOOL),
        lambda r, q: jacobian_numpy(r, q, r.link_names[2], tool=TOOL),
        lambda r, q, v, a: (r, q),
    ),
    "rnea": (dynid.rnea, rnea_numpy, lambda r, q, v, a: (r, q, v, a)),
    "mass_matrix": (dynid.mass_matrix, mass_matrix_numpy, lambda r, q, v, a: (r, q)),
    "gravity_torques": (
        dynid.gravity_torques,
        gravity_torques_numpy,
        lambda r, q, v, a: (r, q),
    ),
    "coriolis": (dynid.coriolis, _coriolis_numpy, lambda r, q, v, a: (r, q, v)),
    "forward_dynamics": (
        dynid.forward_dynamics,
        _forward_dynamics_numpy,
        lambda r, q, v, a: (r, q, v, a),
    ),
    "torque_regressor": (torque_regressor, torque_regressor_numpy, lambda r, q, v, a: (r, q, v, a)),
    "static_regressor": (
        dynid.static_regressor,
        static_regressor_numpy,
        lambda r, q, v, a: (r, q),
    ),
    "momentum_terms": (
        lambda r, q, v: np.concatenate(momentum_terms(r, q, v), axis=-1),
        lambda r, q, v: np.concatenate(momentum_terms_numpy(r, q, v), axis=-1),
        lambda r, q, v, a: (r, q, v),
    ),
}


@pytest.mark.parametrize(
    "shape", [(), (1,), (3, 2), (300,)], ids=["one", "batch1", "batch3x2", "batch300"]
)
@pytest.mark.parametrize("robot_name", sorted(ROBOTS))
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_kernel_equals_numpy_reference(pair, robot_name, shape):
    """The compiled path and the numpy reference agree to 1e-12 (relative), shapes kept."""
    robot = ROBOTS[robot_name]()
    rng = np.random.default_rng(abs(hash((pair, robot_name, shape))) % 2**32)
    lo = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    hi = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    q = rng.uniform(lo, hi, shape + (robot.n,))
    dq, ddq = rng.normal(size=q.shape), rng.normal(size=q.shape)
    ours, ref, make = PAIRS[pair]
    a, b = ours(*make(robot, q, dq, ddq)), ref(*make(robot, q, dq, ddq))
    assert a.shape == b.shape and a.shape[: len(shape)] == shape
    assert np.max(np.abs(a - b)) <= 1e-12 * max(1.0, np.max(np.abs(b)))
    # a second call (a single sample then takes its thin path) gives the same numbers
    np.testing.assert_allclose(ours(*make(robot, q, dq, ddq)), a, rtol=1e-13, atol=1e-13)


def test_single_sample_thin_path_takes_the_kernel_and_checks_its_input(panda):
    """A float64 (n,) vector goes to the kernel entry; NaN and bad shapes still raise."""
    q = np.linspace(-1.0, 1.0, 7)
    dynid.rnea(panda, q, q, q), dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q)
    dynid.fk(panda, q), dynid.jacobian(panda, q)
    for name in ("rnea", "mass_matrix", "gravity_torques", "frame_pose", "jacobian"):
        assert _kernels.KERNELS[name].one is not None, name
    # a strided view and a read-only vector are single samples too
    strided = np.repeat(q, 2)[::2]
    frozen = _kernels.readonly(q)
    for x in (strided, frozen):
        np.testing.assert_allclose(
            dynid.rnea(panda, x, x, x), rnea_numpy(panda, q, q, q), atol=1e-12
        )
        np.testing.assert_allclose(dynid.jacobian(panda, x), jacobian_numpy(panda, q), atol=1e-14)
    bad = q.copy()
    bad[3] = np.nan
    with pytest.raises(dynid.NonFiniteError, match="q must be finite"):
        dynid.gravity_torques(panda, bad)
    with pytest.raises(dynid.NonFiniteError):
        dynid.fk(panda, bad)
    with pytest.raises(dynid.ShapeError, match=r"q must have shape \(\.\.\., 7\)"):
        dynid.mass_matrix(panda, q[:6])


class _ArrayLookalike:
    """Has a float64 dtype and an (n,) shape, is not a numpy array (as a pandas Series)."""

    def __init__(self, x):
        self.x, self.shape, self.dtype = x, x.shape, x.dtype

    def __array__(self, dtype=None, copy=None):
        return np.asarray(self.x, dtype=dtype)


def test_single_sample_thin_path_leaves_other_inputs_to_the_general_path(panda):
    """Integers, array look-alikes and a chain too long for the stack scratch are exact."""
    q = np.linspace(-1.0, 1.0, 7)
    dynid.rnea(panda, q, q, q), dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q)
    dynid.fk(panda, q), dynid.jacobian(panda, q)  # the thin paths are live
    ints = np.arange(-3, 4)  # int64: same item size as float64, must not be read as one
    like = _ArrayLookalike(q)
    for x, ref in ((ints, ints.astype(float)), (like, q)):
        for ours, theirs in (
            (dynid.rnea(panda, x, x, x), rnea_numpy(panda, ref, ref, ref)),
            (dynid.mass_matrix(panda, x), mass_matrix_numpy(panda, ref)),
            (dynid.gravity_torques(panda, x), gravity_torques_numpy(panda, ref)),
            (dynid.fk(panda, x), fk_numpy(panda, ref)),
            (dynid.jacobian(panda, x), jacobian_numpy(panda, ref)),
        ):
            np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)
    # 100 joints: the single-sample kernels decline (their scratch lives on the stack) and
    # the batch kernels answer
    n = 100
    alpha = np.where(np.arange(n) % 2, np.pi / 2, -np.pi / 2)
    long = dynid.Robot.from_mdh(
        np.full(n, 0.05), np.full(n, 0.02), alpha, mass=np.full(n, 0.5),
        com=np.tile([0.01, 0.02, 0.03], (n, 1)), inertia=np.tile(np.eye(3) * 1e-3, (n, 1, 1)),
    )  # fmt: skip
    assert n * 21 > _chain.STACK
    x = np.random.default_rng(7).uniform(-1.0, 1.0, 100)
    np.testing.assert_allclose(
        dynid.rnea(long, x, x, x), rnea_numpy(long, x, x, x), rtol=1e-12, atol=1e-12
    )
    np.testing.assert_allclose(
        dynid.mass_matrix(long, x), mass_matrix_numpy(long, x), rtol=1e-12, atol=1e-12
    )
    np.testing.assert_allclose(
        dynid.gravity_torques(long, x), gravity_torques_numpy(long, x), rtol=1e-12, atol=1e-12
    )


@pytest.mark.parametrize("then", ["batch", "many single calls"])
def test_one_sample_call_in_a_fresh_process_does_not_load_numba(then):
    """A one-shot single sample stays on numpy; a batch or SMALL_CALLS more load the kernels."""
    code = (
        "import sys, numpy as np, dynid\n"
        "from dynid import _kernels\n"
        "r = dynid.panda(); q = np.linspace(-1, 1, 7)\n"
        "dynid.fk(r, q); dynid.rnea(r, q, q, q); dynid.jacobian(r, q)\n"
        "assert 'numba' not in sys.modules, 'numba imported by a single sample'\n"
        + (
            "dynid.fk(r, np.stack([q, q]))\n"
            if then == "batch"
            else "for _ in range(_kernels.SMALL_CALLS): dynid.gravity_torques(r, q)\n"
        )
        + "assert 'numba' in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


# --- the kernels called directly, against the numpy path and Pinocchio ---------------------


def kernel_rnea(robot, q, dq, ddq, gravity=None):
    """The rnea kernel called directly on (B, n) arrays."""
    g = robot.gravity if gravity is None else gravity
    tau = np.empty(q.shape)
    ok = dyn_kernels.rnea(
        _kernels.pack(robot, gravity=g),
        q.reshape(-1),
        dq.reshape(-1),
        ddq.reshape(-1),
        tau.reshape(-1),
    )
    assert ok
    return tau


def kernel_mass_matrix(robot, q):
    """The mass-matrix kernel called directly on (B, n) positions."""
    M = np.empty(q.shape + q.shape[-1:])
    ok = dyn_kernels.mass_matrix(_kernels.pack(robot), q.reshape(-1), M.reshape(-1))
    assert ok
    return M


def kernel_gravity(robot, q):
    """The gravity kernel called directly on (B, n) positions."""
    tau = np.empty(q.shape)
    ok = dyn_kernels.gravity_torques(_kernels.pack(robot), q.reshape(-1), tau.reshape(-1))
    assert ok
    return tau


def kernel_link_poses(robot, q):
    """The link-pose kernel called directly on (B, n) positions."""
    T = np.empty((q.shape[0], robot.n + 1, 4, 4))
    ok = kin_kernels.link_poses(_kernels.pack(robot), q.reshape(-1), T.reshape(-1))
    assert ok
    return T


def kernel_fk(robot, q, frame, tool=None):
    """The frame-pose kernel called directly on (B, n) positions."""
    link, T_lf = frame_pose_in_link(robot, frame, tool)
    T_lf = _kernels.readonly(T_lf)  # the type the public functions pass
    T = np.empty((q.shape[0], 4, 4))
    CF = _kernels.pack_frame(_kernels.pack(robot), link, T_lf)
    ok = kin_kernels.frame_pose(CF, q.reshape(-1), T.reshape(-1))
    assert ok
    return T


def kernel_jacobian(robot, q, frame, tool=None):
    """The Jacobian kernel called directly on (B, n) positions."""
    link, T_lf = frame_pose_in_link(robot, frame, tool)
    T_lf = _kernels.readonly(T_lf)  # the type the public functions pass
    J = np.empty((q.shape[0], 6, robot.n))
    CF = _kernels.pack_frame(_kernels.pack(robot), link, T_lf)
    ok = kin_kernels.jacobian(CF, q.reshape(-1), J.reshape(-1))
    assert ok
    return J


def rpr_z_axes(seed: int) -> dynid.Robot:
    """An MDH arm with a prismatic middle joint, z joint axes and random inertials off-axis."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(3, 3, 3))
    inertia = np.einsum("nij,nkj->nik", A, A) * 0.01 + np.eye(3) * 0.01  # SPD about the CoM
    return dynid.Robot.from_mdh(
        a=[0.0, 0.3, 0.05],
        d=[0.4, 0.1, 0.2],
        alpha=[0.0, -np.pi / 2, np.pi / 2],
        theta=[0.0, 0.3, -0.2],
        joint_types="RPR",
        mass=rng.uniform(0.5, 3.0, 3),
        com=rng.uniform(-0.1, 0.1, (3, 3)),
        inertia=inertia,
        gravity=(0.3, -0.2, -9.81),
        name="rpr",
    )


def rpr_unaligned_axes(seed: int) -> dynid.Robot:
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


def test_dynamics_kernels_match_numpy_path_and_pinocchio_on_random_states():
    """rnea, M and g: kernel == numpy path == Pinocchio to 1e-10 on 100 seeded Panda states."""
    pin = pytest.importorskip("pinocchio")
    robot = dynid.panda()
    full = pin.buildModelFromUrdf(pinocchio_panda_urdf())
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    model.gravity.linear[:] = robot.gravity
    for i in range(1, 8):
        model.inertias[i] = pin.Inertia(robot.mass[i - 1], robot.com[i - 1], robot.inertia[i - 1])
    data = model.createData()
    q, dq, ddq = random_states(robot, 100, seed=11)
    tau_k, M_k, g_k = (
        kernel_rnea(robot, q, dq, ddq),
        kernel_mass_matrix(robot, q),
        kernel_gravity(robot, q),
    )
    tau_n = rnea_numpy(robot, q, dq, ddq)
    M_n, g_n = mass_matrix_numpy(robot, q), gravity_torques_numpy(robot, q)
    np.testing.assert_allclose(tau_k, tau_n, rtol=0, atol=1e-10)
    np.testing.assert_allclose(M_k, M_n, rtol=0, atol=1e-10)
    np.testing.assert_allclose(g_k, g_n, rtol=0, atol=1e-10)
    np.testing.assert_allclose(dynid.rnea(robot, q, dq, ddq), tau_k, rtol=0, atol=0)
    np.testing.assert_allclose(dynid.mass_matrix(robot, q), M_k, rtol=0, atol=0)
    np.testing.assert_allclose(dynid.gravity_torques(robot, q), g_k, rtol=0, atol=0)
    for s in range(len(q)):
        np.testing.assert_allclose(
            tau_k[s], pin.rnea(model, data, q[s], dq[s], ddq[s]), rtol=0, atol=1e-10
        )
        Mp = pin.crba(model, data, q[s])
        np.testing.assert_allclose(M_k[s], np.triu(Mp) + np.triu(Mp, 1).T, rtol=0, atol=1e-10)
        np.testing.assert_allclose(
            g_k[s], pin.computeGeneralizedGravity(model, data, q[s]), rtol=0, atol=1e-10
        )


def test_prismatic_arm_matches_pinocchio():
    """The 'RPR' arm rebuilt joint by joint in Pinocchio (RZ, PZ, RZ): same tau, M and g."""
    pin = pytest.importorskip("pinocchio")
    robot = rpr_z_axes(seed=13)
    model = pin.Model()
    model.gravity.linear[:] = robot.gravity
    parent = 0
    for i in range(robot.n):
        T = robot.T_parent_joint[i]
        joint = pin.JointModelPZ() if robot.prismatic[i] else pin.JointModelRZ()
        parent = model.addJoint(parent, joint, pin.SE3(T[:3, :3], T[:3, 3]), f"j{i + 1}")
        inertia = pin.Inertia(robot.mass[i], robot.com[i], robot.inertia[i])
        model.appendBodyToJoint(parent, inertia, pin.SE3.Identity())
    data = model.createData()
    rng = np.random.default_rng(23)
    q = rng.uniform(-2.0, 2.0, (100, 3))
    dq, ddq = rng.uniform(-2.0, 2.0, (100, 3)), rng.uniform(-5.0, 5.0, (100, 3))
    tau, M, g = (
        dynid.rnea(robot, q, dq, ddq),
        dynid.mass_matrix(robot, q),
        dynid.gravity_torques(robot, q),
    )
    for s in range(len(q)):
        np.testing.assert_allclose(
            tau[s], pin.rnea(model, data, q[s], dq[s], ddq[s]), rtol=0, atol=1e-10
        )
        Mp = pin.crba(model, data, q[s])
        np.testing.assert_allclose(M[s], np.triu(Mp) + np.triu(Mp, 1).T, rtol=0, atol=1e-10)
        np.testing.assert_allclose(
            g[s], pin.computeGeneralizedGravity(model, data, q[s]), rtol=0, atol=1e-10
        )


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
    robot = rpr_unaligned_axes(seed=32)
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


# --- what the table of pairs does not reach ----------------------------------------------


def test_prismatic_arm_dynamics_identities_on_the_kernel_path():
    """An RPR arm: M is positive definite, rnea = M ddq + c + g, forward dynamics inverts it."""
    robot = rpr_z_axes(seed=13)
    rng = np.random.default_rng(14)
    q = rng.uniform(-2.0, 2.0, (100, 3))
    dq, ddq = rng.uniform(-2.0, 2.0, (100, 3)), rng.uniform(-5.0, 5.0, (100, 3))
    # through the public functions, including forward dynamics and the Coriolis term
    M = dynid.mass_matrix(robot, q)
    assert np.all(np.linalg.eigvalsh(M) > 0)
    tau = dynid.rnea(robot, q, dq, ddq)
    rhs = (
        np.einsum("bij,bj->bi", M, ddq)
        + dynid.coriolis(robot, q, dq)
        + dynid.gravity_torques(robot, q)
    )
    np.testing.assert_allclose(tau, rhs, rtol=0, atol=1e-10)
    np.testing.assert_allclose(dynid.forward_dynamics(robot, q, dq, tau), ddq, rtol=0, atol=1e-9)


def test_kernel_rnea_with_other_parameters_and_gravity_matches_numpy_path():
    """The internal RNEA with a foreign phi (as the regressors use it) and a gravity argument."""
    robot = rpr_z_axes(seed=15)
    rng = np.random.default_rng(16)
    q, dq, ddq = (rng.uniform(-2.0, 2.0, (40, 3)) for _ in range(3))
    phi = robot.phi + rng.normal(scale=0.01, size=robot.phi.shape)  # writeable, not robot.phi
    g = np.array([0.0, 9.0, -3.0])
    np.testing.assert_allclose(
        _rnea(robot, phi, q, dq, ddq, g), _rnea_numpy(robot, phi, q, dq, ddq, g), rtol=0, atol=1e-10
    )
    np.testing.assert_allclose(
        dynid.rnea(robot, q, dq, ddq, gravity=g),
        rnea_numpy(robot, q, dq, ddq, gravity=g),
        rtol=0,
        atol=1e-10,
    )


@pytest.mark.parametrize("blocks, extra", [(0, 0), (0, 1), (1, -1), (1, 0), (1, 1), (3, 5)])
def test_kernel_rnea_handles_partial_blocks(blocks, extra):
    """Sample counts below, at and above multiples of the block length match the numpy path."""
    robot = dynid.panda()
    B = blocks * dyn_kernels.BLOCK + extra
    q, dq, ddq = random_states(robot, B, seed=17)
    tau = dynid.rnea(robot, q, dq, ddq)
    assert tau.shape == (B, 7)
    np.testing.assert_allclose(tau, rnea_numpy(robot, q, dq, ddq), rtol=0, atol=1e-10)
    np.testing.assert_allclose(
        dynid.gravity_torques(robot, q), gravity_torques_numpy(robot, q), rtol=0, atol=1e-10
    )


def test_kernel_rnea_uses_the_math_library_for_huge_angles():
    """Angles beyond 1e8 rad (outside the polynomial's range) still match the numpy path."""
    robot = dynid.panda()
    q, dq, ddq = random_states(robot, 5, seed=22)
    q[2, 3] = 3.0e9
    np.testing.assert_allclose(
        dynid.rnea(robot, q, dq, ddq), rnea_numpy(robot, q, dq, ddq), rtol=0, atol=1e-10
    )
    np.testing.assert_allclose(
        dynid.mass_matrix(robot, q), mass_matrix_numpy(robot, q), rtol=0, atol=1e-10
    )


def test_sincos_matches_the_math_library():
    """The vectorisable sine and cosine are within 2.3e-16 of numpy's, up to |x| = 1e8."""
    import numba

    @numba.njit(fastmath=_chain.FASTMATH)  # as the kernels compile it
    def both(x):
        s, c = np.empty_like(x), np.empty_like(x)
        for k in range(x.size):
            s[k], c[k] = _chain.sincos(x[k])
        return s, c

    rng = np.random.default_rng(21)
    x = np.concatenate(
        [
            rng.uniform(-10.0, 10.0, 20000),
            rng.uniform(-1e8, 1e8, 20000),
            np.arange(-64, 65) * (np.pi / 4),  # octant boundaries
            [0.0, -0.0, 1e-300, -1e-300, 1e8, -1e8],
        ]
    )
    s, c = both(x)
    assert np.max(np.abs(s - np.sin(x))) <= 2.3e-16
    assert np.max(np.abs(c - np.cos(x))) <= 2.3e-16


def test_kernel_jacobian_matches_finite_differences_of_kernel_fk():
    """The Jacobian's columns are the central differences of the tool origin and rotation."""
    robot = rpr_unaligned_axes(seed=34)
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


def test_kernel_handles_a_frame_on_the_base():
    """A frame on link 0 does not move: constant pose, zero Jacobian."""
    robot = rpr_unaligned_axes(seed=38).with_frame("stand", tool_pose(), parent="link0")
    q = np.random.default_rng(39).uniform(-2.0, 2.0, (4, robot.n))
    np.testing.assert_array_equal(
        dynid.fk(robot, q, "stand"), np.broadcast_to(tool_pose(), (4, 4, 4))
    )
    np.testing.assert_array_equal(dynid.jacobian(robot, q, "stand"), 0.0)


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_batch_rows_equal_single_samples_bit_for_bit(shape):
    """Each row of a batch equals the single sample exactly; later joints do not move link 5."""
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


# --- inputs and errors --------------------------------------------------------------------


def test_dynamics_paths_accept_lists_broadcasting_views_and_read_only_arrays():
    """Lists, broadcast shapes, strided views and read-only arrays give the numpy path's result."""
    robot = dynid.panda()
    q, dq, ddq = random_states(robot, 6, seed=19)
    ref = rnea_numpy(robot, q, dq[0], ddq)
    np.testing.assert_allclose(dynid.rnea(robot, q, dq[0], ddq), ref, rtol=0, atol=1e-10)
    np.testing.assert_allclose(
        dynid.rnea(robot, q.tolist(), dq[0].tolist(), ddq), ref, rtol=0, atol=1e-10
    )
    wide = np.repeat(q, 2, axis=1)[:, ::2]  # non-contiguous view equal to q
    ro = q.copy()
    ro.setflags(write=False)
    for qq in (wide, ro, np.asfortranarray(q)):
        np.testing.assert_allclose(
            dynid.rnea(robot, qq, dq, ddq), rnea_numpy(robot, q, dq, ddq), rtol=0, atol=1e-10
        )
        np.testing.assert_allclose(
            dynid.mass_matrix(robot, qq), mass_matrix_numpy(robot, q), rtol=0, atol=1e-10
        )
    np.testing.assert_allclose(
        dynid.gravity_torques(robot, q[0].astype(np.float32)),
        gravity_torques_numpy(robot, q[0].astype(np.float32)),
        rtol=0,
        atol=1e-10,
    )
    assert not np.shares_memory(dynid.rnea(robot, q, dq, ddq), q)


def test_kinematics_paths_accept_lists_views_read_only_and_float32():
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


def test_kernel_paths_report_nan_and_bad_shapes_like_the_numpy_path():
    """NaN/inf in an input raises NonFiniteError naming it and its index; wrong n, ShapeError."""
    robot = dynid.panda()
    q, dq, ddq = random_states(robot, 4, seed=20)
    for name in ("q", "dq", "ddq"):
        args = {"q": q.copy(), "dq": dq.copy(), "ddq": ddq.copy()}
        args[name][2, 5] = np.inf
        with pytest.raises(dynid.NonFiniteError, match=rf"^{name} must be finite.*\(2, 5\)"):
            dynid.rnea(robot, args["q"], args["dq"], args["ddq"])
    bad = q.copy()
    bad[3, 0] = np.nan
    with pytest.raises(dynid.NonFiniteError, match=r"q must be finite.*\(3, 0\)"):
        dynid.mass_matrix(robot, bad)
    with pytest.raises(dynid.NonFiniteError, match=r"q must be finite.*\(3, 0\)"):
        dynid.gravity_torques(robot, bad)
    with pytest.raises(dynid.ShapeError, match=r"q must have shape \(\.\.\., 7\)"):
        dynid.gravity_torques(robot, np.zeros(6))
    with pytest.raises(dynid.ShapeError, match=r"q must have shape \(\.\.\., 7\)"):
        dynid.mass_matrix(robot, 1.0)
    with pytest.raises(
        dynid.WrongTypeError, match="^q: expected a real numeric array_like, got str$"
    ):
        dynid.rnea(robot, "abc", dq[0], ddq[0])


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


# --- DYNID_NO_NUMBA and a light import ------------------------------------------------------


def test_no_numba_environment_variable_selects_the_numpy_paths():
    """With DYNID_NO_NUMBA=1 no kernel is loaded, numba is not imported, results agree."""
    code = (
        "import json, sys, numpy as np, dynid\n"
        "from dynid.dynamics.rnea import kernels as dyn\n"
        "from dynid.kinematics.forward import kernels as kin\n"
        "r = dynid.panda(); q = np.linspace(-1, 1, 7)\n"
        "tau = dynid.rnea(r, q, q, q); M = dynid.mass_matrix(r, q)\n"
        "T = dynid.fk(r, q); J = dynid.jacobian(r, q); L = dynid.link_poses(r, q)\n"
        "assert dyn() is None and kin() is None and 'numba' not in sys.modules\n"
        "print(json.dumps([x.tolist() for x in (tau, M, T, J, L)]))\n"
    )
    env = dict(os.environ, DYNID_NO_NUMBA="1")
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    tau, M, T, J, L = json.loads(out.stdout)
    robot = dynid.panda()
    q = np.linspace(-1, 1, 7)
    np.testing.assert_allclose(tau, dynid.rnea(robot, q, q, q), rtol=0, atol=1e-10)
    np.testing.assert_allclose(M, dynid.mass_matrix(robot, q), rtol=0, atol=1e-10)
    np.testing.assert_allclose(T, dynid.fk(robot, q), rtol=0, atol=1e-14)
    np.testing.assert_allclose(J, dynid.jacobian(robot, q), rtol=0, atol=1e-14)
    np.testing.assert_allclose(L, dynid.link_poses(robot, q), rtol=0, atol=1e-14)


def test_import_dynid_does_not_import_numba_or_the_kernels():
    """``import dynid`` stays light: numba and the kernels load on the first call only."""
    code = (
        "import sys, dynid\n"
        "assert 'numba' not in sys.modules\n"
        "assert 'dynid._kernels.dynamics' not in sys.modules\n"
        "assert 'dynid._kernels.kinematics' not in sys.modules\n"
        "assert 'dynid._kernels.chain' not in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_packed_arrays_belong_to_one_robot(panda):
    """A robot derived from a used one packs its own constants: nothing stale is reused."""
    q = np.linspace(-1.0, 1.0, 7)
    for _ in range(2):  # the second call takes the thin paths
        tau, J = dynid.rnea(panda, q, q, q), dynid.jacobian(panda, q)
    assert _kernels.cached(panda) is not None
    variants = {
        "heavier": panda.with_params(panda.phi * 1.5),
        "tilted": panda.with_gravity([1.0, 0.0, -9.7]),
        "moved flange": panda.replace(
            frames={**panda.frames, "flange": dynid.Frame(7, tool_pose())}
        ),
    }
    for name, other in variants.items():
        assert _kernels.cached(other) is None, name
        for _ in range(2):
            np.testing.assert_allclose(
                dynid.rnea(other, q, q, q), rnea_numpy(other, q, q, q), rtol=1e-12, atol=1e-12
            )
            np.testing.assert_allclose(
                dynid.jacobian(other, q), jacobian_numpy(other, q), rtol=1e-12, atol=1e-12
            )
        assert not np.allclose(dynid.rnea(other, q, q, q), tau) or not np.allclose(
            dynid.jacobian(other, q), J
        ), name


class _FakeClassArray:
    """Claims to be an ndarray (``__class__``), as proxies do; numpy converts it."""

    def __init__(self, x):
        self._x, self.dtype, self.shape = x, x.dtype, x.shape

    @property  # type: ignore[misc]
    def __class__(self):
        return np.ndarray

    def __array__(self, dtype=None, copy=None):
        return np.asarray(self._x, dtype=dtype)


def test_thin_paths_refuse_what_only_looks_like_an_array(panda):
    """An object faking the ndarray class gets the general path's numbers, not an error."""
    q = np.linspace(-1.0, 1.0, 7)
    dynid.rnea(panda, q, q, q), dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q)
    dynid.fk(panda, q), dynid.jacobian(panda, q)  # the thin paths are live
    x = _FakeClassArray(q)
    for ours, theirs in (
        (dynid.rnea(panda, q, x, q), rnea_numpy(panda, q, q, q)),
        (dynid.mass_matrix(panda, x), mass_matrix_numpy(panda, q)),
        (dynid.gravity_torques(panda, x), gravity_torques_numpy(panda, q)),
        (dynid.fk(panda, x), fk_numpy(panda, q)),
        (dynid.jacobian(panda, x), jacobian_numpy(panda, q)),
    ):
        np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)


def test_a_robot_does_not_change_when_the_callers_arrays_do(panda):
    """Read-only arrays the caller owns are copied: unlocking and editing them later changes
    neither the robot nor what the kernels packed from it."""
    q = np.linspace(-1.0, 1.0, 7)
    phi, g, T = np.array(panda.phi), np.array([0.5, 0.0, -9.8]), tool_pose()
    for a in (phi, g, T):
        a.setflags(write=False)
    robot = panda.with_params(phi).with_gravity(g).with_frame("tcp", T)
    before = (dynid.rnea(robot, q, q, q), dynid.fk(robot, q, "tcp"))
    for _ in range(2):  # the second call takes the thin paths
        dynid.rnea(robot, q, q, q), dynid.fk(robot, q, "tcp")
    for a in (phi, g, T):
        a.setflags(write=True)
        a *= 2.0
    with pytest.raises(ValueError):
        robot.phi.setflags(write=True)
    np.testing.assert_array_equal(dynid.rnea(robot, q, q, q), before[0])
    np.testing.assert_array_equal(dynid.fk(robot, q, "tcp"), before[1])
    np.testing.assert_array_equal(rnea_numpy(robot, q, q, q), rnea_numpy(robot, q, q, q))
    np.testing.assert_allclose(rnea_numpy(robot, q, q, q), before[0], rtol=1e-12, atol=1e-12)


def test_a_scalar_is_not_a_joint_vector_of_a_one_joint_robot():
    """q = 0.3 for a one-joint robot raises ShapeError on every path, kernels loaded or not."""
    r1 = dynid.Robot.from_mdh([0.0], [0.0], [0.0], mass=[1.0], com=[[0.1, 0.0, 0.0]])
    z = np.zeros((2, 1))
    dynid.fk(r1, z), dynid.rnea(r1, z, z, z)  # the kernels are loaded
    for x in (0.3, np.float32(0.3), np.array(0.3, dtype=">f8"), np.array(3)):
        for f, args in (
            (dynid.fk, (x,)),
            (dynid.jacobian, (x,)),
            (dynid.rnea, (x, x, x)),
            (dynid.mass_matrix, (x,)),
            (dynid.gravity_torques, (x,)),
        ):
            with pytest.raises(dynid.ShapeError, match=r"shape \(\.\.\., 1\)"):
                f(r1, *args)


def test_a_frame_that_is_not_a_name_is_a_wrong_type(panda):
    """A frame that is not a name (a list of names) raises WrongTypeError naming ``frame``
    on every path, never a TypeError of an unhashable key."""
    q = np.zeros(7)
    dynid.fk(panda, q), dynid.jacobian(panda, q)
    for f in (dynid.fk, dynid.jacobian, fk_numpy, jacobian_numpy):
        with pytest.raises(dynid.WrongTypeError, match="^frame: expected a frame's name"):
            f(panda, q, frame=["flange"])


def test_none_is_not_an_array(panda):
    """None is refused as a missing input, not read as NaN."""
    q = np.zeros(7)
    for call in (
        lambda: dynid.rnea(panda, None, q, q),
        lambda: dynid.fk(panda, None),
        lambda: dynid.forward_dynamics(panda, q, q, None),
        lambda: dynid.ik(panda, None),
    ):
        with pytest.raises(
            dynid.WrongTypeError, match="expected a real numeric array_like, got None"
        ):
            call()


def test_packed_constants_are_dropped_with_their_robot():
    """The kernels' memo of a robot lives outside it and goes when the robot is collected.

    (The test robot lives at least until the call with ``other``: nothing else holds it,
    so its id is not reused before the check.)
    """
    import gc

    robot = dynid.panda().with_gravity([0.0, 0.0, -9.7])
    q = np.linspace(-1.0, 1.0, 7)
    tau = dynid.rnea(robot, q, q, q)
    np.testing.assert_allclose(tau, rnea_numpy(robot, q, q, q), rtol=1e-12, atol=1e-12)
    key = id(robot)
    assert _kernels.cached(robot) is not None and key in _kernels.CACHE.robots
    assert _kernels.CACHE.robot is robot  # the last robot used is held until another is
    other = dynid.panda()
    dynid.rnea(other, q, q, q)
    assert _kernels.CACHE.robot is other
    del robot
    gc.collect()
    assert key not in _kernels.CACHE.robots
    assert _kernels.cached(other) is not None


def test_every_kernel_is_registered_with_a_numpy_twin():
    """Each row of the registry names a kernel of its module and a callable numpy twin."""
    import importlib

    for name, k in _kernels.KERNELS.items():
        mod = importlib.import_module(f"dynid._kernels.{k.module}")
        for fn in (k.batch_name, k.one_name):
            assert fn is None or callable(getattr(mod, fn)), (name, fn)
        where, twin = k.twin.split(":")
        assert callable(getattr(importlib.import_module(where), twin)), name
