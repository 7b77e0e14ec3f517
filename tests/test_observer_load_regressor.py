"""The weight of a load at the flange as the residual reads it, against Pinocchio.

The regressor ``Y(q)`` of :mod:`dynid.observer.unmodelled_load` (its batched products),
and the running normal equations of :class:`~dynid.observer.unmodelled_load.LoadTally`
over blocks: ``Y(q) (m, m c)`` is minus the gravity torques the load adds to the arm
(Pinocchio's generalized gravity with and without it), and the tally fed those torques
with noise finds the load's mass and centre of mass, and each joint's RMS of its torque.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.observer.unmodelled_load import LoadTally, load_regressor

from conftest import pinocchio_panda_model

MASS, COM = 0.9, np.array([0.02, -0.01, 0.06])  # [kg], [m] in the flange's axes
FLANGE_Z = 0.107  # the flange on link 7 [m]


def _load_torques(q: np.ndarray) -> np.ndarray:
    """Minus the gravity torques [N m] the load adds, Pinocchio's (N, 7)."""
    pin = pytest.importorskip("pinocchio")
    arm = dynid.panda()
    load = pin.Inertia(MASS, COM + [0.0, 0.0, FLANGE_Z], np.eye(3) * 1e-3)
    out = []
    for model in (pinocchio_panda_model(), pinocchio_panda_model(None, load)):
        model.gravity.linear[:] = arm.gravity
        data = model.createData()
        out.append(np.array([pin.computeGeneralizedGravity(model, data, qk) for qk in q]))
    return -(out[1] - out[0])


def test_the_load_regressor_is_the_weight_pinocchio_adds():
    """``Y(q) (m, m c)`` against Pinocchio's gravity torques, 1e-10 N m."""
    rng = np.random.default_rng(7)
    q = rng.uniform(-2.0, 2.0, (40, 7))
    theta = np.concatenate([[MASS], MASS * COM])
    got = load_regressor(dynid.panda(), q) @ theta
    np.testing.assert_allclose(got, _load_torques(q), atol=1e-10)


def test_the_tally_over_blocks_finds_the_load_and_its_level():
    """Two blocks of Pinocchio's load torques plus noise: mass, CoM and RMS per joint."""
    rng = np.random.default_rng(8)
    q = rng.uniform(-2.0, 2.0, (600, 7))
    tau = _load_torques(q)
    contact = np.full_like(tau, 10.0)  # every sample read: each |tau| under 10 N m
    r = tau + rng.normal(0.0, 1e-3, tau.shape)
    tally = LoadTally(dynid.panda())
    tally.add(q[:250], r[:250], contact[:250])
    tally.add(q[250:], r[250:], contact[250:])
    got = tally.result()
    assert np.abs(tau).max() < 10.0
    assert got is not None and got.samples == 600
    assert got.mass == pytest.approx(MASS, rel=1e-3)
    np.testing.assert_allclose(got.com, COM, atol=1e-3)
    level = np.sqrt(np.mean((tau / contact) ** 2, axis=0))
    np.testing.assert_allclose(got.level, level, rtol=1e-2, atol=1e-4)
    assert got.share > 0.99
