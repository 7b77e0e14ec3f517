"""The torques as measured at the prepared samples: what ``prepare_log`` gives with
``filter_tau=False`` on uniform stamps, the nearest measured sample's on jittered ones,
without preparing the other signals."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import dynid
from dynid.identification.log import TorqueLog
from dynid.identification.prepare import Preprocessing, measured_torques, prepare_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier


@pytest.mark.parametrize("jitter", [0.0, 2e-5], ids=["uniform", "jittered"])
def test_measured_torques_are_prepare_logs_unfiltered_ones(jitter):
    panda = dynid.panda()
    rng = np.random.default_rng(3)
    t = sample_times(3.0, 500.0) + rng.normal(0.0, jitter, 1501) * (np.arange(1501) > 0)
    t = np.sort(t)
    log = simulate_measurement(panda, random_fourier(panda, rng)(t), rng=rng)
    log = TorqueLog(log.t, log.q, log.dq, log.tau)
    prep = Preprocessing(cutoff_hz=6.0, trim_s=0.2, decimate=4)
    grid = prepare_log(log, dataclasses.replace(prep, filter_tau=False))
    # uniform: the unfiltered prepared torques; jittered: those of the measured sample
    # nearest each prepared one (brute force), not a line between two
    nearest = np.argmin(np.abs(log.t[None, :] - grid.t[:, None]), axis=1)
    want = grid.tau if jitter == 0.0 else log.tau[nearest]
    np.testing.assert_array_equal(measured_torques(log, prep), want)
