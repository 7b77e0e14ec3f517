"""A payload log in which one joint turns one way throughout.

Reference: a simulated Panda carrying a known load, with classical friction and sensor
noise, whose joint 7 turns one way only (its Coulomb friction and a torque offset are then
one column); the load's mass and CoM against the truth given to the simulation.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import RankDeficientError
from dynid.feasibility.payload import identify_payload
from dynid.feasibility.payload_fit import fit_load
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import Trajectory, random_fourier, uniform_times

MASS = 0.9
COM = np.array([0.01, -0.02, 0.07])
INERTIA = np.diag([0.003, 0.004, 0.002])
NOISE = 0.02  # N m
ONE_WAY = 6  # joint 7 (0-based): its velocity stays positive
FRICTION = dynid.ClassicalFriction(np.full(7, 0.2), np.linspace(0.6, 0.3, 7), np.zeros(7))


def _one_way(traj: Trajectory, joints: list[int]) -> Trajectory:
    """``traj`` with ``joints`` turning one way only (``dq = 0.4 + 0.2 cos(2 t)`` rad/s)."""
    t = traj.t
    q, dq, ddq = (np.array(a) for a in (traj.q, traj.dq, traj.ddq))
    for j in joints:
        q[:, j] = -1.0 + 0.4 * t + 0.1 * np.sin(2 * t)
        dq[:, j] = 0.4 + 0.2 * np.cos(2 * t)
        ddq[:, j] = -0.4 * np.sin(2 * t)
    return Trajectory(t, q, dq, ddq)


def _loaded_log(traj: Trajectory, seed: int):
    """The frictionless Panda (the arm's model) and a log of it carrying the load along
    ``traj`` with :data:`FRICTION` and noise."""
    arm = dynid.panda().with_friction(None)
    loaded = arm.with_tool(np.eye(4), MASS, COM, INERTIA, name="load")
    noise = SensorNoise(tau_std=NOISE)
    log = simulate_measurement(
        loaded, traj, rng=np.random.default_rng(seed), noise=noise, friction=FRICTION
    )
    return arm, log


def test_a_joint_that_turns_one_way_does_not_withhold_the_load():
    """Regression (a continuous joint turning one way the whole recording made its
    Coulomb column its offset's, and the fit was refused as "the data do not excite the
    load's parameters (... unexcited combinations of fc4, fo4)"): the joint's offset is
    left out, one note names the joint, and the load is found to the truth."""
    arm = dynid.panda()
    traj = random_fourier(arm, np.random.default_rng(5), q0=dynid.PANDA_NEUTRAL_Q)(
        uniform_times(6.0, 250.0)
    )
    arm, log = _loaded_log(_one_way(traj, [ONE_WAY]), 6)
    assert np.all(log.dq[:, ONE_WAY] > 0)
    est = identify_payload(arm, log, terms=None)
    said = [n for n in est.notes if "turn one way" in n]
    assert len(said) == 1 and said[0].startswith("joint(s) 7 turn one way"), est.notes
    assert "fo7 left out" in said[0], said
    assert abs(est.mass - MASS) < 0.01 * MASS, est.mass
    assert np.max(np.abs(est.com - COM)) < 2e-3, est.com
    # the Coulomb coefficient holds the joint's constant friction torque
    assert est.friction[ONE_WAY, 2] == 0.0
    assert abs(est.friction[ONE_WAY, 1] - FRICTION.fc[ONE_WAY]) < 0.05


def test_a_load_the_data_do_not_excite_is_still_named_beside_a_one_way_joint():
    """Only joint 1 moves, and one way: its Coulomb friction and offset are one column
    (left out, not blamed on the load), and the load, rotated about one axis, is still
    refused as the load's: its unexcited parameters and the hint to move the wrist."""
    t = uniform_times(6.0, 250.0)
    q = np.tile(dynid.PANDA_NEUTRAL_Q, (t.size, 1))
    still = Trajectory(t, q, np.zeros_like(q), np.zeros_like(q))
    arm, log = _loaded_log(_one_way(still, [0]), 7)
    with pytest.raises(RankDeficientError, match=r"load's parameters \(rank [0-9] of 10; .*wrist"):
        identify_payload(arm, log, terms=None)


def test_friction_columns_alone_not_told_apart_are_not_blamed_on_the_load():
    """The least squares given a Coulomb column equal to its offset (the load's columns
    excited) names the friction columns, not the load's parameters."""
    rng = np.random.default_rng(3)
    W = np.concatenate([rng.normal(size=(400, 10)), rng.normal(size=(400, 1))], axis=1)
    W = np.concatenate([W, np.ones((400, 2))], axis=1)  # fv1, then fc1 == fo1
    y = W @ rng.normal(size=13)
    with pytest.raises(RankDeficientError, match=r"friction coefficients .*fc1, fo1") as e:
        fit_load(W, y, None, None, 10, False)
    assert "load's parameters (rank" not in str(e.value)
