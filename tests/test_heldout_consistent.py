"""The consistent fit judged on held-out data (k-fold over contiguous time blocks), through
the API; through the command in test_heldout_consistent_command.py (a file of its own so
that the test workers share the two long fits).

References: the simulated truth (masses, rotor inertias) and the bounds computed here from
the prior.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import dynid
from dynid.feasibility.bounds import default_bounds
from dynid.feasibility.convex import identify_consistent
from dynid.identification.structure import Structure
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.simulation.unmodelled import UnmodelledEffects

from conftest import perturbed_robot

pytestmark = pytest.mark.filterwarnings("ignore::dynid.DynidWarning")


@pytest.mark.slow
def test_consistent_fit_with_rotors_offsets_outliers_and_noise_is_judged_held_out():
    """Held-out error within the tolerance of least squares', masses closer to the truth
    than the prior's, no link on its mass bound; rotor inertias >= 0."""
    robot = dynid.panda()
    rng = np.random.default_rng(1)
    truth = perturbed_robot(robot, rng)
    eff = dataclasses.replace(UnmodelledEffects.typical(7, rng), gravity_tilt=0.0)
    traj = random_fourier(robot, rng, n_harmonics=5)(sample_times(20.0, 1000.0))
    log = simulate_measurement(truth, traj, rng=rng, noise=SensorNoise(), effects=eff)
    tau = np.array(log.tau)
    k = rng.choice(tau.shape[0], tau.shape[0] // 500, replace=False)  # 0.2 % spikes of 30 N m
    tau[k, rng.integers(0, 7, k.size)] += rng.choice([-1.0, 1.0], k.size) * 30.0
    log = dynid.TorqueLog(t=log.t, q=log.q, dq=log.dq, tau=tau)
    given = Structure.parse("armature,viscous,coulomb,offset")  # classical friction, rotors
    res = identify_consistent(
        robot, log, prior=robot, drive=Drive.identity(7), estimator="irls", structure=given
    )
    j = res.heldout
    assert j is not None and j.scheme == "blocks" and j.folds == 5
    assert j.heldout_percent <= (1 + j.tolerance) * j.ls_heldout_percent
    assert j.tolerance == 0.05 and j.accepted and res.feasible
    mt = truth.mass
    ours = np.median(np.abs(res.mass - mt) / mt)
    prior = np.median(np.abs(robot.mass - mt) / mt)
    assert ours < prior
    b = default_bounds(robot)
    lo = np.maximum(b.mass_min, robot.mass / 3.0)  # the prior's factor-3 box in the bounds
    hi = np.minimum(b.mass_max, robot.mass * 3.0)
    gap = np.minimum(res.mass - lo, hi - res.mass)
    assert np.all(gap > 1e-3 * (hi - lo))
    assert not any("mass" in s and "link" in s for s in res.on_bound)
    assert res.rotor_inertia is not None and np.all(res.rotor_inertia >= 0)
