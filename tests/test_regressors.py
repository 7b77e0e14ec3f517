"""Torque and static regressors and the base-parameter reduction."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from conftest import pinocchio_panda_urdf, planar_2r, random_states
from dynid.regressors.base import base_parameters, base_parameters_from_regressor
from dynid.regressors.static import static_labels, static_regressor, static_vector
from dynid.regressors.torque import torque_regressor

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
    assert "J2yy + J1zz" in bp.expressions or "J1zz" in text


def test_planar_2r_base_parameters_match_closed_form():
    """Planar 2R in a vertical plane: 6 base parameters (Khalil and Dombre, ZZ1R, MX1R, MY1, ZZ2, MX2, MY2)."""
    r = planar_2r()
    bp = base_parameters(r)
    W = static_regressor(r, np.random.default_rng(15).uniform(-3, 3, (50, 2))).reshape(-1, 20)
    assert bp.rank == np.linalg.matrix_rank(W)
    assert bp.rank == 6


def test_rank_of_rank_deficient_regressor_is_reported():
    """A regressor with duplicated columns has the rank of its distinct columns."""
    rng = np.random.default_rng(16)
    A = rng.normal(size=(50, 3))
    W = np.column_stack([A, A[:, 0] * 2.0, np.zeros(50)])
    bp = base_parameters_from_regressor(W, ("a", "b", "c", "d", "e"))
    assert bp.rank == 3
    np.testing.assert_allclose(W @ np.arange(5.0), bp.reduce(W) @ bp.beta_from_phi(np.arange(5.0)))
