"""The pseudo-inertia matrix, its margin, repair and the log-det divergence.

References: the second moment of a uniform solid box (closed form), the point mass and the
thin rod (boundary cases), and the classical feasibility conditions (positive mass, positive
definite inertia, triangle inequality) checked by :mod:`dynid.feasibility.constraints`.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import ModelError
from dynid.feasibility.constraints import feasibility_report
from dynid.feasibility.lmi import (
    log_det_divergence,
    phi_from_pseudo_inertia,
    pseudo_inertia,
    pseudo_inertia_margin,
    repair_pseudo_inertia,
)


def _rotation(rng: np.random.Generator) -> np.ndarray:
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def _box(rng: np.random.Generator):
    """A uniform box: mass, CoM, rotation, dimensions and its phi."""
    m = rng.uniform(0.5, 5.0)
    c = rng.uniform(-0.3, 0.3, 3)
    R = _rotation(rng)
    a = rng.uniform(0.02, 0.4, 3)
    Ic = R @ np.diag(m / 12.0 * (np.sum(a**2) - a**2)) @ R.T
    return m, c, R, a, dynid.phi_from_inertial(m, c, Ic)


def test_pseudo_inertia_of_a_box_is_its_second_moment_about_the_origin():
    """Sigma = m (R diag(a^2/12) R^T + c c^T), h = m c, for uniform boxes."""
    rng = np.random.default_rng(0)
    for _ in range(20):
        m, c, R, a, phi = _box(rng)
        J = pseudo_inertia(phi)
        Sigma = m * (R @ np.diag(a**2 / 12.0) @ R.T + np.outer(c, c))
        np.testing.assert_allclose(J[:3, :3], Sigma, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(J[:3, 3], m * c, rtol=1e-12)
        assert J[3, 3] == pytest.approx(m)
        assert pseudo_inertia_margin(phi) > 0


def test_phi_round_trips_through_the_pseudo_inertia_for_batches():
    """phi -> J -> phi is the identity, batch shape kept."""
    rng = np.random.default_rng(1)
    phi = rng.normal(size=(3, 2, 10))
    J = pseudo_inertia(phi)
    assert J.shape == (3, 2, 4, 4)
    np.testing.assert_allclose(phi_from_pseudo_inertia(J), phi, rtol=1e-13, atol=1e-15)


def test_margin_is_zero_for_a_point_mass_and_a_thin_rod():
    """Limiting bodies lie on the boundary of the consistent set."""
    point = dynid.phi_from_inertial(2.0, [0.1, 0.2, -0.1], np.zeros((3, 3)))
    L = 0.5
    rod = dynid.phi_from_inertial(1.0, [0.0, 0.0, 0.2], np.diag([L**2 / 12, L**2 / 12, 0.0]))
    assert abs(pseudo_inertia_margin(point)) < 1e-14
    assert abs(pseudo_inertia_margin(rod)) < 1e-14


def test_negative_margin_exactly_when_a_classical_condition_fails():
    """J >= 0 iff m >= 0, I_c >= 0 and the triangle inequality (random tensors)."""
    rng = np.random.default_rng(2)
    agree = 0
    for _ in range(300):
        m = rng.uniform(0.1, 3.0)
        R = _rotation(rng)
        lam = rng.uniform(-0.02, 0.2, 3)
        Ic = R @ np.diag(lam) @ R.T
        phi = dynid.phi_from_inertial(m, rng.uniform(-0.2, 0.2, 3), Ic)
        rep = feasibility_report((np.array([m]), [phi[1:4] / m], Ic[None]), tol=0.0)
        classical = all(
            rep.min_margin(n) > 1e-12
            for n in ("mass_positive", "inertia_positive_definite", "triangle_inequality")
        )
        lmi = pseudo_inertia_margin(phi) > 1e-12
        agree += classical == lmi
    assert agree == 300


def test_repair_floors_eigenvalues_and_leaves_good_links_alone():
    """An impossible link (triangle inequality violated) is moved to the margin; a box is kept."""
    rng = np.random.default_rng(3)
    good = _box(rng)[-1]
    bad = dynid.phi_from_inertial(1.0, [0.0, 0.0, 0.1], np.diag([0.01, 0.01, 0.05]))
    assert pseudo_inertia_margin(bad) < 0
    fixed, changed = repair_pseudo_inertia(np.stack([good, bad]), 1e-3)
    assert changed.tolist() == [False, True]
    np.testing.assert_array_equal(fixed[0], good)
    assert pseudo_inertia_margin(fixed[1]) == pytest.approx(1e-3, rel=1e-9)


def test_divergence_is_zero_at_the_prior_positive_elsewhere_and_frame_invariant():
    """d(J0, J0) = 0, d > 0 for another body, and d is unchanged by a rigid motion of both."""
    rng = np.random.default_rng(4)
    J0 = pseudo_inertia(_box(rng)[-1])
    J = pseudo_inertia(_box(rng)[-1])
    assert log_det_divergence(J0, J0) == pytest.approx(0.0, abs=1e-12)
    d = float(log_det_divergence(J, J0))
    assert d > 0
    T = np.eye(4)
    T[:3, :3] = _rotation(rng)
    T[:3, 3] = rng.normal(size=3)
    # second moments move as T J T^T under a change of frame (homogeneous coordinates)
    assert float(log_det_divergence(T @ J @ T.T, T @ J0 @ T.T)) == pytest.approx(d, rel=1e-9)
    assert np.isinf(log_det_divergence(-J, J0))
    with pytest.raises(ModelError, match="J0 must be positive definite"):
        log_det_divergence(J, -J0)
