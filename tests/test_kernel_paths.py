"""The compiled kernels against the numpy reference paths, every public pair once (issue 11).

Each pair is the public function (compiled kernel: batches, and single samples through the
thin path once the kernels are loaded) and its documented numpy reference path. They must
agree to rounding (1e-12 relative to the largest entry) for batch shapes (), (1,), (3, 2),
on the Panda and on an arm with a prismatic joint and tilted axes, with a tool.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import dynid
from dynid import _compiled
from dynid.dynamics import rnea as rnea_module
from dynid.dynamics.rnea import rnea_numpy
from dynid.dynamics.terms import gravity_torques_numpy, mass_matrix_numpy
from dynid.kinematics import forward as forward_module
from dynid.kinematics.forward import fk_numpy, link_poses_numpy
from dynid.kinematics.jacobian import jacobian_numpy
from dynid.regressors.static import static_regressor_numpy
from dynid.regressors.torque import torque_regressor, torque_regressor_numpy

pytest.importorskip("numba")

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
    "torque_regressor": (torque_regressor, torque_regressor_numpy, lambda r, q, v, a: (r, q, v, a)),
    "static_regressor": (
        dynid.static_regressor,
        static_regressor_numpy,
        lambda r, q, v, a: (r, q),
    ),
}


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)], ids=["one", "batch1", "batch3x2"])
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


def test_single_sample_thin_path_takes_the_kernel_and_checks_its_input(panda):
    """A float64 (n,) vector goes to the kernel entry; NaN and bad shapes still raise."""
    q = np.linspace(-1.0, 1.0, 7)
    dynid.rnea(panda, q, q, q), dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q)
    dynid.fk(panda, q), dynid.jacobian(panda, q)
    assert {"rnea", "mass_matrix", "gravity_torques"} <= set(rnea_module._ONE)
    assert {"frame_pose", "jacobian"} <= set(forward_module._ONE)
    # a strided view and a read-only vector are single samples too
    strided = np.repeat(q, 2)[::2]
    frozen = _compiled.readonly(q)
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


@pytest.mark.parametrize("then", ["batch", "many single calls"])
def test_one_sample_call_in_a_fresh_process_does_not_load_numba(then):
    """A one-shot single sample stays on numpy; a batch or SMALL_CALLS more load the kernels."""
    code = (
        "import sys, numpy as np, dynid\n"
        "from dynid import _compiled\n"
        "r = dynid.panda(); q = np.linspace(-1, 1, 7)\n"
        "dynid.fk(r, q); dynid.rnea(r, q, q, q); dynid.jacobian(r, q)\n"
        "assert 'numba' not in sys.modules, 'numba imported by a single sample'\n"
        + (
            "dynid.fk(r, np.stack([q, q]))\n"
            if then == "batch"
            else "for _ in range(_compiled.SMALL_CALLS): dynid.gravity_torques(r, q)\n"
        )
        + "assert 'numba' in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
