"""Identities and closed forms of the dynamics: rnea, M, g, c, S, forward dynamics."""

from __future__ import annotations

import numpy as np
import pytest

import dynid

from conftest import random_states


def test_rnea_equals_m_ddq_plus_c_plus_g(panda):
    """rnea(q, dq, ddq) == M ddq + c + g on random states."""
    q, dq, ddq = random_states(panda, 50, seed=2)
    lhs = dynid.rnea(panda, q, dq, ddq)
    rhs = np.einsum("bij,bj->bi", dynid.mass_matrix(panda, q), ddq)
    rhs += dynid.coriolis(panda, q, dq) + dynid.gravity_torques(panda, q)
    np.testing.assert_allclose(lhs, rhs, atol=1e-10)


def test_mass_matrix_is_symmetric_positive_definite(panda):
    """M(q) is symmetric with positive eigenvalues."""
    q, _, _ = random_states(panda, 50, seed=3)
    M = dynid.mass_matrix(panda, q)
    np.testing.assert_allclose(M, np.swapaxes(M, 1, 2), atol=1e-14)
    assert np.all(np.linalg.eigvalsh(M) > 0)


def test_coriolis_matrix_times_dq_is_c_and_mdot_minus_2s_is_skew(panda):
    """S dq = c and dM/dt - 2S is skew-symmetric (dM/dt by central differences)."""
    q, dq, _ = random_states(panda, 10, seed=4)
    S = dynid.coriolis_matrix(panda, q, dq)
    np.testing.assert_allclose(
        np.einsum("bij,bj->bi", S, dq), dynid.coriolis(panda, q, dq), atol=1e-10
    )
    h = 1e-6
    Mdot = (dynid.mass_matrix(panda, q + h * dq) - dynid.mass_matrix(panda, q - h * dq)) / (2 * h)
    K = Mdot - 2 * S
    np.testing.assert_allclose(K, -np.swapaxes(K, 1, 2), atol=1e-7)


def test_forward_dynamics_inverts_rnea(panda):
    """forward_dynamics(q, dq, rnea(q, dq, ddq)) == ddq."""
    q, dq, ddq = random_states(panda, 20, seed=5)
    tau = dynid.rnea(panda, q, dq, ddq)
    np.testing.assert_allclose(dynid.forward_dynamics(panda, q, dq, tau), ddq, atol=1e-9)


def test_planar_2r_matches_closed_form(planar2r):
    """M, c, g of the planar 2R arm equal the textbook closed form (Spong et al. ch. 7)."""
    l1, lc1, lc2, m1, m2, I1, I2, g0 = 0.7, 0.35, 0.25, 2.0, 1.5, 0.05, 0.03, 9.81
    rng = np.random.default_rng(6)
    for _ in range(20):
        q, dq = rng.uniform(-3, 3, 2), rng.uniform(-2, 2, 2)
        c2 = np.cos(q[1])
        d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
        d12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
        d22 = m2 * lc2**2 + I2
        hh = -m2 * l1 * lc2 * np.sin(q[1])
        c = np.array([2 * hh * dq[0] * dq[1] + hh * dq[1] ** 2, -hh * dq[0] ** 2])
        g = np.array(
            [
                (m1 * lc1 + m2 * l1) * g0 * np.cos(q[0]) + m2 * lc2 * g0 * np.cos(q[0] + q[1]),
                m2 * lc2 * g0 * np.cos(q[0] + q[1]),
            ]
        )
        np.testing.assert_allclose(
            dynid.mass_matrix(planar2r, q), [[d11, d12], [d12, d22]], atol=1e-12
        )
        np.testing.assert_allclose(dynid.coriolis(planar2r, q, dq), c, atol=1e-12)
        np.testing.assert_allclose(dynid.gravity_torques(planar2r, q), g, atol=1e-12)


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_batch_shapes_are_kept(panda, shape):
    """A (..., n) input gives a (..., n) output; (n,) gives one result, (1, n) a batch of one."""
    rng = np.random.default_rng(7)
    q = rng.uniform(-1, 1, shape + (7,))
    assert dynid.rnea(panda, q, q, q).shape == shape + (7,)
    assert dynid.mass_matrix(panda, q).shape == shape + (7, 7)
    assert dynid.coriolis_matrix(panda, q, q).shape == shape + (7, 7)
    assert dynid.fk(panda, q).shape == shape + (4, 4)
    assert dynid.jacobian(panda, q).shape == shape + (6, 7)


def test_dynamics_reject_bad_shapes_and_nan(panda):
    """Wrong joint count and NaN raise ShapeError / NonFiniteError naming the array."""
    with pytest.raises(dynid.ShapeError, match=r"q must have shape \(\.\.\., 7\)"):
        dynid.rnea(panda, np.zeros(6), np.zeros(7), np.zeros(7))
    q = np.zeros((3, 7))
    q[1, 2] = np.nan
    with pytest.raises(dynid.NonFiniteError, match=r"q must be finite.*\(1, 2\)"):
        dynid.mass_matrix(panda, q)
    with pytest.raises(dynid.ShapeError, match="broadcast"):
        dynid.rnea(panda, np.zeros((2, 7)), np.zeros((3, 7)), np.zeros(7))


def test_forward_dynamics_of_a_singular_mass_matrix_is_a_model_error():
    """A massless first link on the second joint's axis: M is singular; every path says so."""
    robot = dynid.Robot.from_mdh(
        [0.0, 0.0, 0.3], [0.0, 0.0, 0.0], [0.0, 0.0, np.pi / 2], mass=[0.0, 1.0, 1.0],
        com=[[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.0, 0.0]],
        inertia=[np.zeros((3, 3)), np.eye(3) * 0.01, np.eye(3) * 0.01],
    )  # fmt: skip
    q, dq, tau = np.random.default_rng(3).normal(size=(3, 3))
    dynid.rnea(robot, q[None], dq[None], dq[None])  # compiled kernels loaded
    for args in ((q, dq, tau), (q, dq, tau), (q[None], dq[None], tau[None])):
        with pytest.raises(dynid.ModelError, match="mass matrix is singular"):
            dynid.forward_dynamics(robot, *args)


def test_forward_dynamics_names_tau_in_its_errors(panda):
    q = np.zeros(7)
    with pytest.raises(dynid.NonFiniteError, match="tau must be finite"):
        dynid.forward_dynamics(panda, q, q, [0, 0, 0, np.nan, 0, 0, 0])
    with pytest.raises(dynid.ShapeError, match=r"tau must have shape \(\.\.\., 7\)"):
        dynid.forward_dynamics(panda, q, q, np.zeros(6))
