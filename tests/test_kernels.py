"""The compiled (numba) dynamics kernels against the numpy reference path and Pinocchio."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import dynid
from dynid import _compiled
from dynid.dynamics import rnea as rnea_module
from dynid.dynamics.rnea import _rnea, _rnea_numpy, rnea_numpy
from dynid.dynamics.terms import gravity_torques_numpy, mass_matrix_numpy

from conftest import pinocchio_panda_urdf, random_states

pytest.importorskip("numba")
from dynid.dynamics import _kernels  # noqa: E402  (after the skip: imports numba)
from dynid.kinematics import _chain  # noqa: E402


@pytest.fixture(autouse=True)
def _kernels_in_use():
    """The public functions must take the kernel path in this module."""
    if rnea_module.kernels() is None:
        pytest.skip("compiled kernels disabled (DYNID_NO_NUMBA)")


def kernel_rnea(robot, q, dq, ddq, gravity=None):
    """The rnea kernel called directly on (B, n) arrays."""
    g = robot.gravity if gravity is None else gravity
    tau = np.empty(q.shape)
    ok = _kernels.rnea(
        _compiled.pack(robot, gravity=g),
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
    ok = _kernels.mass_matrix(_compiled.pack(robot), q.reshape(-1), M.reshape(-1))
    assert ok
    return M


def kernel_gravity(robot, q):
    """The gravity kernel called directly on (B, n) positions."""
    tau = np.empty(q.shape)
    ok = _kernels.gravity_torques(_compiled.pack(robot), q.reshape(-1), tau.reshape(-1))
    assert ok
    return tau


def rpr_robot(seed: int) -> dynid.Robot:
    """A small MDH arm with a prismatic middle joint and random inertials (CoMs off-axis)."""
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


def test_kernels_match_numpy_path_and_pinocchio_on_random_states():
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


def test_kernels_match_numpy_path_to_rounding():
    """Kernel and numpy path agree to 1e-12 (rounding only) on the Panda, relative to |tau|."""
    robot = dynid.panda()
    q, dq, ddq = random_states(robot, 300, seed=12)
    tau_k, tau_n = kernel_rnea(robot, q, dq, ddq), rnea_numpy(robot, q, dq, ddq)
    assert np.max(np.abs(tau_k - tau_n)) <= 1e-12 * max(1.0, np.max(np.abs(tau_n)))
    M_k, M_n = kernel_mass_matrix(robot, q), mass_matrix_numpy(robot, q)
    assert np.max(np.abs(M_k - M_n)) <= 1e-12 * max(1.0, np.max(np.abs(M_n)))


def test_kernels_match_numpy_path_with_a_prismatic_joint():
    """An 'RPR' MDH arm: kernel rnea, M and g equal the numpy path's on 100 random states."""
    robot = rpr_robot(seed=13)
    rng = np.random.default_rng(14)
    q = rng.uniform(-2.0, 2.0, (100, 3))
    dq, ddq = rng.uniform(-2.0, 2.0, (100, 3)), rng.uniform(-5.0, 5.0, (100, 3))
    np.testing.assert_allclose(
        kernel_rnea(robot, q, dq, ddq), rnea_numpy(robot, q, dq, ddq), rtol=0, atol=1e-10
    )
    np.testing.assert_allclose(
        kernel_mass_matrix(robot, q), mass_matrix_numpy(robot, q), rtol=0, atol=1e-10
    )
    np.testing.assert_allclose(
        kernel_gravity(robot, q), gravity_torques_numpy(robot, q), rtol=0, atol=1e-10
    )
    # and through the public functions, including forward dynamics, c and the Christoffel symbols
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


def test_prismatic_arm_matches_pinocchio():
    """The 'RPR' arm rebuilt joint by joint in Pinocchio (RZ, PZ, RZ): same tau, M and g."""
    pin = pytest.importorskip("pinocchio")
    robot = rpr_robot(seed=13)
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


def test_kernel_rnea_with_other_parameters_and_gravity_matches_numpy_path():
    """The internal RNEA with a foreign phi (as the regressors use it) and a gravity argument."""
    robot = rpr_robot(seed=15)
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
    B = blocks * _kernels.BLOCK + extra
    q, dq, ddq = random_states(robot, B, seed=17)
    tau = dynid.rnea(robot, q, dq, ddq)
    assert tau.shape == (B, 7)
    np.testing.assert_allclose(tau, rnea_numpy(robot, q, dq, ddq), rtol=0, atol=1e-10)
    np.testing.assert_allclose(
        dynid.gravity_torques(robot, q), gravity_torques_numpy(robot, q), rtol=0, atol=1e-10
    )


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_kernel_paths_keep_batch_shapes(shape):
    """(n,) gives one result, (1, n) a batch of one, (3, 2, n) a (3, 2) batch (kernel path)."""
    robot = dynid.panda()
    rng = np.random.default_rng(18)
    q, dq, ddq = (rng.uniform(-1, 1, shape + (7,)) for _ in range(3))
    tau = dynid.rnea(robot, q, dq, ddq)
    M = dynid.mass_matrix(robot, q)
    g = dynid.gravity_torques(robot, q)
    assert tau.shape == shape + (7,) and M.shape == shape + (7, 7) and g.shape == shape + (7,)
    np.testing.assert_allclose(tau, rnea_numpy(robot, q, dq, ddq), rtol=0, atol=1e-10)
    np.testing.assert_allclose(M, mass_matrix_numpy(robot, q), rtol=0, atol=1e-10)
    np.testing.assert_allclose(g, gravity_torques_numpy(robot, q), rtol=0, atol=1e-10)


def test_kernel_paths_accept_lists_broadcasting_views_and_read_only_arrays():
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
    with pytest.raises(dynid.ShapeError, match="q must be numeric"):
        dynid.rnea(robot, "abc", dq[0], ddq[0])


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


def test_no_numba_environment_variable_selects_the_numpy_path():
    """With DYNID_NO_NUMBA=1 the kernels are not loaded, numba is not imported, results agree."""
    code = (
        "import json, sys, numpy as np, dynid\n"
        "from dynid.dynamics.rnea import kernels\n"
        "r = dynid.panda(); q = np.linspace(-1, 1, 7)\n"
        "tau = dynid.rnea(r, q, q, q); M = dynid.mass_matrix(r, q)\n"
        "assert kernels() is None and 'numba' not in sys.modules\n"
        "print(json.dumps([tau.tolist(), M.tolist()]))\n"
    )
    env = dict(os.environ, DYNID_NO_NUMBA="1")
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    tau, M = json.loads(out.stdout)
    robot = dynid.panda()
    q = np.linspace(-1, 1, 7)
    np.testing.assert_allclose(tau, dynid.rnea(robot, q, q, q), rtol=0, atol=1e-10)
    np.testing.assert_allclose(M, dynid.mass_matrix(robot, q), rtol=0, atol=1e-10)


def test_import_dynid_does_not_import_numba():
    """``import dynid`` stays light: numba is imported on the first dynamics call only."""
    code = (
        "import sys, dynid\n"
        "assert 'numba' not in sys.modules\n"
        "assert 'dynid.dynamics._kernels' not in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
