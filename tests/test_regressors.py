"""Torque and static regressors and the base-parameter reduction."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import dynid
from dynid.regressors import static as static_module
from dynid.regressors.base import (
    _clean,
    base_parameters,
    base_parameters_from_regressor,
)
from dynid.regressors.static import (
    static_first_columns,
    static_labels,
    static_regressor,
    static_regressor_columns,
    static_regressor_numpy,
    static_vector,
)
from dynid.regressors.torque import torque_regressor

from conftest import pinocchio_panda_urdf, planar_2r, random_states, robot_data_urdf

#: dynid order (m, mcx, mcy, mcz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz) from Pinocchio's
#: (m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz)
PIN_TO_DYNID = np.array([0, 1, 2, 3, 4, 5, 7, 6, 8, 9])


def test_torque_regressor_times_phi_equals_rnea(panda):
    """Y(q, dq, ddq) phi == rnea for random states and random phi (linearity in phi)."""
    q, dq, ddq = random_states(panda, 30, seed=10)
    Y = torque_regressor(panda, q, dq, ddq)
    np.testing.assert_allclose(Y @ panda.phi.reshape(-1), dynid.rnea(panda, q, dq, ddq), atol=1e-10)
    phi = np.random.default_rng(11).normal(size=(7, 10))
    other = panda.with_params(phi)
    np.testing.assert_allclose(Y @ phi.reshape(-1), dynid.rnea(other, q, dq, ddq), atol=1e-10)


def test_torque_regressor_matches_pinocchio(panda):
    """The regressor equals Pinocchio's computeJointTorqueRegressor after the column permutation."""
    pin = pytest.importorskip("pinocchio")
    full = pin.buildModelFromUrdf(pinocchio_panda_urdf())
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    model.gravity.linear[:] = panda.gravity
    data = model.createData()
    q, dq, ddq = random_states(panda, 100, seed=12)
    Y = torque_regressor(panda, q, dq, ddq)
    for s in range(len(q)):
        Yp = pin.computeJointTorqueRegressor(model, data, q[s], dq[s], ddq[s])
        Yp = Yp.reshape(7, 7, 10)[:, :, PIN_TO_DYNID].reshape(7, 70)
        np.testing.assert_allclose(Y[s], Yp, atol=1e-10)


def test_static_regressor_times_phi_equals_tril_m_and_g(panda):
    """Y_s(q) phi == [tril M(q); g(q)] with rows ordered by np.tril_indices."""
    q, _, _ = random_states(panda, 30, seed=13)
    s = static_vector(dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q))
    Ys = static_regressor(panda, q)
    assert Ys.shape == (30, 35, 70)
    np.testing.assert_allclose(Ys @ panda.phi.reshape(-1), s, atol=1e-10)
    labels = static_labels(7)
    assert labels[:4] == ("M1_1", "M2_1", "M2_2", "M3_1") and labels[-1] == "g7"


def test_panda_has_43_base_parameters_and_base_regressor_reproduces_torques(panda):
    """Rank 43 (Gaz et al. 2019) from both regressors; Y_b beta == Y phi for random phi."""
    bp = base_parameters(panda)
    assert bp.rank == 43
    assert base_parameters(panda, kind="torque").rank == 43
    q, dq, ddq = random_states(panda, 40, seed=14)
    Y = torque_regressor(panda, q, dq, ddq)
    for seed in range(3):
        phi = np.random.default_rng(seed).normal(size=70)
        np.testing.assert_allclose(bp.reduce(Y) @ bp.beta_from_phi(phi), Y @ phi, atol=1e-9)


def test_base_expressions_use_exact_kinematic_constants(panda):
    """Combination coefficients are the exact products of DH lengths (d3^2 = 0.099856, ...)."""
    bp = base_parameters(panda)
    text = " ".join(bp.expressions)
    for const in ("0.099856*m3", "0.632*mc3z", "0.007744*m7", "0.768*mc5z"):
        assert const in text
    # joint 1's axis sees J1zz plus link 2's inertia about the axis it shares at q2 = 0
    # (the MDH frames of links 1 and 2 share their origin; alpha_1 = -pi/2 turns z1 into y2)
    assert "J1zz + J2yy" in bp.expressions


def test_planar_2r_base_parameters_match_closed_form():
    """Planar 2R in a vertical plane: the 6 base parameters of Khalil and Dombre.

    ZZ1R = J1zz + l1^2 m2, MX1R = mc1x + l1 m2, MY1 = mc1y, ZZ2 = J2zz, MX2 = mc2x,
    MY2 = mc2y (J about the link origins): the identified combinations span exactly these.
    """
    l1 = 0.7
    r = planar_2r(l1=l1)
    bp = base_parameters(r)
    labels = r.param_labels
    C = np.zeros((6, 20))
    idx = {name: k for k, name in enumerate(labels)}
    C[0, idx["J1zz"]], C[0, idx["m2"]] = 1.0, l1**2
    C[1, idx["mc1x"]], C[1, idx["m2"]] = 1.0, l1
    for row, name in enumerate(("mc1y", "J2zz", "mc2x", "mc2y"), start=2):
        C[row, idx[name]] = 1.0
    P = bp.projection
    assert bp.rank == 6
    assert np.linalg.matrix_rank(C) == 6
    assert np.linalg.matrix_rank(np.vstack([P, C]), tol=1e-9) == 6  # same row space
    W = static_regressor(r, np.random.default_rng(15).uniform(-3, 3, (50, 2))).reshape(-1, 20)
    assert bp.rank == np.linalg.matrix_rank(W)


def test_rank_of_rank_deficient_regressor_is_reported():
    """A regressor with duplicated columns has the rank of its distinct columns."""
    rng = np.random.default_rng(16)
    A = rng.normal(size=(50, 3))
    W = np.column_stack([A, A[:, 0] * 2.0, np.zeros(50)])
    bp = base_parameters_from_regressor(W, ("a", "b", "c", "d", "e"))
    assert bp.rank == 3
    np.testing.assert_allclose(W @ np.arange(5.0), bp.reduce(W) @ bp.beta_from_phi(np.arange(5.0)))


# ------------------------------------------------------------------ compiled static regressor
def _rpr():
    """An RPR arm with tilted gravity (a prismatic joint in the middle)."""
    return dynid.Robot.from_mdh(
        [0.0, 0.1, 0.2],
        [0.3, 0.0, 0.1],
        [0.0, np.pi / 2, -np.pi / 2],
        joint_types="RPR",
        gravity=(0.3, -1.0, -9.8),
    )


def _kernel_in_use():
    if static_module._kernel() is None:
        pytest.skip("compiled kernels disabled (DYNID_NO_NUMBA) or numba missing")


@pytest.mark.parametrize("B", [1, 127, 128, 300])
def test_static_regressor_kernel_matches_the_numpy_path(B):
    """The numba kernel equals the numpy path to rounding, for partial and full blocks."""
    _kernel_in_use()
    for robot in (dynid.panda(), _rpr(), planar_2r()):
        q, _, _ = random_states(robot, B, seed=200 + B)
        Y = static_regressor(robot, q)
        ref = static_regressor_numpy(robot, q)
        assert Y.shape == ref.shape == (B, robot.n * (robot.n + 1) // 2 + robot.n, 10 * robot.n)
        np.testing.assert_allclose(Y, ref, rtol=0, atol=1e-13 * np.abs(ref).max())
        # a subset of the columns, in any order, as written by the kernel directly
        cols = np.random.default_rng(B).permutation(10 * robot.n)[: 4 * robot.n]
        sub = static_regressor_columns(robot, q, cols)
        np.testing.assert_allclose(
            sub, ref.transpose(2, 1, 0)[cols], rtol=0, atol=1e-13 * np.abs(ref).max()
        )
    # one configuration keeps its shape; a batch of shape (2, 3) too
    robot = dynid.panda()
    q, _, _ = random_states(robot, 6, seed=210)
    assert static_regressor(robot, q[0]).shape == (35, 70)
    np.testing.assert_allclose(
        static_regressor(robot, q.reshape(2, 3, 7)).reshape(6, 35, 70),
        static_regressor_numpy(robot, q),
        atol=1e-12,
    )


def test_static_regressor_kernel_times_phi_equals_tril_m_and_g_with_a_prismatic_joint():
    """Independent of the numpy path: Y_s phi == [tril M; g] from the dynamics (RPR arm)."""
    _kernel_in_use()
    robot = _rpr()
    rng = np.random.default_rng(211)
    q = rng.uniform(-2.0, 2.0, (50, 3))
    Y = static_regressor(robot, q)
    for _ in range(3):
        other = robot.with_params(rng.normal(size=30))
        want = static_vector(dynid.mass_matrix(other, q), dynid.gravity_torques(other, q))
        np.testing.assert_allclose(Y @ other.phi.reshape(-1), want, atol=1e-12 * np.abs(want).max())


def test_static_regressor_rows_are_exactly_zero_before_their_first_column():
    """Rows (i, j) and g_i do not act on links before i: exact zeros, both paths."""
    robots = [dynid.panda(), _rpr(), planar_2r()]
    try:
        robots.append(
            dynid.Robot.from_urdf(
                robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), tip_link="tool0"
            )
        )
    except pytest.skip.Exception:
        pass
    for robot in robots:
        q, _, _ = random_states(robot, 40, seed=212)
        bp = base_parameters(robot)
        for cols in (np.arange(10 * robot.n), bp.independent):
            first = static_first_columns(robot.n, cols)
            for numpy_path in (False, True):
                Y = static_regressor_columns(robot, q, cols, numpy_path=numpy_path)
                for k, c in enumerate(first):
                    assert np.all(Y[:c, k] == 0.0)
    # the Panda's g7 and M7_j rows start at link 7's mass (column 60); M1_1 at column 0
    first = static_first_columns(7, np.arange(70))
    assert first[0] == 0 and first[21:28].tolist() == [60] * 7 and first[-1] == 60
    # no structure is claimed for columns out of order
    assert np.all(static_first_columns(7, np.array([30, 10, 50])) == 0)


def test_no_numba_environment_variable_selects_the_numpy_static_regressor():
    """DYNID_NO_NUMBA=1: numpy path, numba not imported; same regressor and base parameters."""
    code = (
        "import json, sys, numpy as np, dynid\n"
        "from dynid.regressors.static import _kernel\n"
        "r = dynid.panda(); q = np.linspace(-1, 1, 14).reshape(2, 7)\n"
        "Y = dynid.static_regressor(r, q); bp = dynid.base_parameters(r)\n"
        "assert _kernel() is None and 'numba' not in sys.modules\n"
        "print(json.dumps([Y.tolist(), list(bp.expressions)]))\n"
    )
    env = dict(os.environ, DYNID_NO_NUMBA="1")
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    Y, expressions = json.loads(out.stdout)
    robot = dynid.panda()
    q = np.linspace(-1, 1, 14).reshape(2, 7)
    np.testing.assert_allclose(Y, static_regressor(robot, q), rtol=0, atol=1e-12)
    assert tuple(expressions) == base_parameters(robot).expressions


def test_clean_rounds_to_significant_digits_and_zeroes_round_off():
    """K_d cleaning: 10 significant digits; entries below 1e-11 of the largest become +0."""
    x = np.array([[0.09985600000000012, -1e-17, 0.0], [-0.0, 0.632 + 4e-16, -2.5]])
    out = _clean(x, 10, 2.5)
    np.testing.assert_array_equal(out, [[0.099856, 0.0, 0.0], [0.0, 0.632, -2.5]])
    assert not np.signbit(out[1, 0]) and not np.signbit(out[0, 1])


def test_base_parameters_depend_on_the_structure_not_on_the_samples(panda):
    """Same independent set and expressions from other random states and from either regressor."""
    ref = base_parameters(panda)
    for seed, n in ((1, 40), (2, 500)):
        other = base_parameters(panda, n_samples=n, rng=np.random.default_rng(seed))
        assert other.expressions == ref.expressions
    assert base_parameters(panda, kind="torque").expressions == ref.expressions


def test_panda_base_parameters_read_as_in_the_paper(panda):
    """Gauss-Jordan order gives the paper's first coefficients (Gaz et al. 2019, Table III)."""
    e = base_parameters(panda).expressions
    assert e[0] == "J1zz + J2yy"  # paper #1: J2yy + J1zz
    assert e[3] == (  # paper #2: J2xx - J2yy + J3yy + d3^2 m3 + 2 d3 c3z m3 + (d3^2 + a4^2) m4..7
        "J2xx - J2yy + 0.099856*m3 + 0.632*mc3z + J3yy + 0.10666225*m4 + 0.10666225*m5"
        " + 0.10666225*m6 + 0.10666225*m7"
    )


def test_tied_columns_keep_the_first_in_parameter_order():
    """Duplicated columns: the first copy is independent, the later one maps onto it."""
    rng = np.random.default_rng(17)
    a, b = rng.normal(size=(2, 60))
    W = np.column_stack([b, a, a, 3.0 * b])
    bp = base_parameters_from_regressor(W, ("p0", "p1", "p2", "p3"))
    assert bp.rank == 2 and list(bp.independent) == [0, 1]
    assert bp.expressions == ("p0 + 3*p3", "p1 + p2")
