"""The friction a model without friction leaves in the observer's residual.

The note "the model holds no friction" said the same whatever the arm: it named no size
and told a user of a frictionless arm (or of a URDF, with no identification.json) to pass
a friction.json. References: a simulated Panda with known classical friction (viscous and
Coulomb), observed with its exact links and no friction; the true friction evaluated on
the true velocities of the same samples.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.observer.model import from_robot
from dynid.observer.residual import ObserverOptions, observe
from dynid.observer.unmodelled import SPEED, FrictionTally, no_friction_note
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

FV = np.linspace(0.5, 0.2, 7)  # N m s/rad
FC = np.linspace(0.8, 0.3, 7)  # N m
TRUTH = ClassicalFriction(FV, FC, np.zeros(7))


def _tally(model, log, gain=50.0):
    """The residual of ``model`` on ``log`` read by a tally a block of 1000 samples at a
    time, as observe reads it."""
    r = observe(model, log.t, log.q, log.dq, log.tau, ObserverOptions(gain=gain)).r
    tally = FrictionTally(model.n, np.array(gain))
    for a in range(0, log.t.size, 1000):
        tally.add(log.t[a : a + 1000], log.dq[a : a + 1000], r[a : a + 1000])
    return tally.result()


@pytest.fixture(scope="module")
def arm():
    """A 4 s, 1 kHz noisy log of a Panda with the friction TRUTH, and its true states."""
    panda = dynid.panda()
    rng = np.random.default_rng(5)
    traj = random_fourier(panda, rng)(sample_times(4.0, 1000.0))
    log = simulate_measurement(panda, traj, rng=rng, noise=SensorNoise(), friction=TRUTH)
    return panda, traj, log


def test_the_friction_a_model_misses_is_measured_at_its_true_size(arm):
    """The exact links without friction: every joint's friction is seen, and its size
    (RMS at speed) matches the true friction's RMS on the true velocities at speed
    within 3 standard errors and 10 %."""
    panda, traj, log = arm
    found = _tally(from_robot(panda, friction=None), log)
    assert found is not None and found.seen.all()
    moving = np.abs(traj.dq) > 2 * SPEED
    tau_f = FC * np.sign(traj.dq) + FV * traj.dq
    truth = np.sqrt([np.mean(tau_f[moving[:, j], j] ** 2) for j in range(7)])
    np.testing.assert_array_less(np.abs(found.size - truth), 3 * found.se + 0.1 * truth)
    np.testing.assert_allclose(found.coulomb, FC, atol=0.15)
    note = no_friction_note(found, panda.joint_names)
    assert note.startswith("the model holds no friction, but") and note.endswith("--friction")
    for j in range(7):
        assert f"{panda.joint_names[j]} {found.size[j]:.2g}" in note


def test_a_model_with_the_right_friction_leaves_none(arm):
    """The exact links with the true friction: the residual holds no friction on any
    joint (none seen, each size under 0.05 N m where the friction is 0.3 to 1.2 N m)."""
    panda, _, log = arm
    found = _tally(from_robot(panda, friction=TRUTH), log)
    assert found is not None and not found.seen.any()
    assert np.all(found.size < 0.05)


def test_a_frictionless_arm_gets_a_note_that_asks_nothing():
    """A frictionless arm observed without friction: the note says the residual shows
    none above its noise and asks for no friction.json."""
    panda = dynid.panda()
    rng = np.random.default_rng(6)
    traj = random_fourier(panda, rng)(sample_times(3.0, 1000.0))
    log = simulate_measurement(panda, traj, rng=rng, noise=SensorNoise(), friction=None)
    found = _tally(from_robot(panda, friction=None), log)
    note = no_friction_note(found, panda.joint_names)
    assert found is not None and not found.seen.any()
    assert "shows none above its noise" in note and "--friction" not in note


def test_a_log_at_rest_says_it_cannot_measure():
    """No sample at speed: the note says the logs cannot tell, and how to add friction."""
    note = no_friction_note(None, ["a", "b"])
    assert "never move a joint fast enough" in note and note.endswith("--friction")


def test_a_joint_moved_one_way_is_fitted_without_an_offset():
    """A joint that only turns one way: its Coulomb term and an offset are one column, so
    the fit leaves the offset out and reads the whole friction, ``fc + fv dq``, in a
    synthetic residual ``-(0.4 + 0.2 dq)`` plus white noise (its RMS within 1 %)."""
    rng = np.random.default_rng(8)
    t = np.arange(0.0, 4.0, 1e-3)
    dq = (0.5 + 0.3 * np.sin(2.0 * t))[:, None]
    r = -(0.4 + 0.2 * dq) + 0.02 * rng.standard_normal(dq.shape)
    tally = FrictionTally(1, np.array(50.0))
    tally.add(t, dq, r)
    found = tally.result()
    truth = np.sqrt(np.mean((0.4 + 0.2 * dq[t > 0.1]) ** 2))
    assert found is not None and found.seen[0]
    np.testing.assert_allclose(found.size[0], truth, rtol=0.01)


def _tally_kept(model, log, contact, gain=50.0):
    """As :func:`_tally`, reading only the samples under a contact threshold ``contact``
    [N m] (n,), as a detection does."""
    r = observe(model, log.t, log.q, log.dq, log.tau, ObserverOptions(gain=gain)).r
    tally = FrictionTally(model.n, np.array(gain))
    for a in range(0, log.t.size, 1000):
        b = a + 1000
        tally.add(log.t[a:b], log.dq[a:b], r[a:b], ~(np.abs(r[a:b]) > contact))
    return tally.result()


def test_a_residual_mostly_over_the_threshold_is_not_read_as_no_friction(arm):
    """Regression: a detection reads only the samples under the contact threshold; on a
    model missing 0.3 to 1.2 N m of friction with thresholds at 0.05 N m nearly none
    remain, and the note said "none above its noise ... no friction to add". Now it says
    they cannot judge, and gives the fit over every sample at speed, which matches the
    true friction's RMS within 3 standard errors and 10 %."""
    panda, traj, log = arm
    found = _tally_kept(from_robot(panda, friction=None), log, np.full(7, 0.05))
    assert found is not None and found.overall is not None
    assert found.flagged_share() > 0.9
    moving = np.abs(traj.dq) > 2 * SPEED
    tau_f = FC * np.sign(traj.dq) + FV * traj.dq
    truth = np.sqrt([np.mean(tau_f[moving[:, j], j] ** 2) for j in range(7)])
    o = found.overall
    np.testing.assert_array_less(np.abs(o.size - truth), 3 * o.se + 0.1 * truth)
    note = no_friction_note(found, panda.joint_names)
    assert "no friction to add" not in note and "too few under it to judge" in note
    assert "likely misses the arm's friction" in note and note.endswith("--friction")
    for j in range(7):
        assert f"{panda.joint_names[j]} {o.size[j]:.2g}" in note


def test_a_few_samples_over_the_threshold_leave_the_note_on_those_under_it(arm):
    """Thresholds above every residual of the model with the right friction: no sample
    left out, no overall fit, the note judged on the samples read (none seen)."""
    panda, _, log = arm
    found = _tally_kept(from_robot(panda, friction=TRUTH), log, np.full(7, 5.0))
    assert found is not None and found.overall is None and found.flagged_share() == 0.0
    assert "shows none above its noise" in no_friction_note(found, panda.joint_names)
