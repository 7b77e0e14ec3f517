"""One-sample torque spikes in logs given to the momentum observer: replaced before it
runs, by the rule identify applies before fitting, and warned about with their count and
times; a contact of several samples is still found, at the same time.

Reference: simulated Panda logs (sensor noise) with spikes put on known rows and a push
of known time (``dynid.simulation.contact``), observed with the Panda's own parameters.
"""

from __future__ import annotations

import dataclasses
import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.io.torque_log import save_torque_log
from dynid.simulation.contact import Contact
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times
from dynid.workflows.observe import ObserveOptions, observe_files

SPIKES = 10
HEIGHT = 30.0  # N m


def _log(seed: int, contacts: tuple[Contact, ...] = ()):
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=4, w_f=2 * np.pi * 0.125)(
        uniform_times(6.0, 1000.0)
    )
    return simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), contacts=contacts)


def _spiked(log, seed: int, away: tuple[float, float] = (0.0, 0.0)):
    """``log`` with :data:`SPIKES` one-sample spikes of +-:data:`HEIGHT` on random joints,
    on rows 0.3 s or more apart and outside ``away`` (s), and their times."""
    rng = np.random.default_rng(seed)
    ok = (log.t > 0.5) & (log.t < log.t[-1] - 0.5) & ~((log.t > away[0]) & (log.t < away[1]))
    rows = np.sort(rng.choice(np.flatnonzero(ok)[::300], SPIKES, replace=False))
    tau = np.array(log.tau)
    tau[rows, rng.integers(0, log.n, SPIKES)] += HEIGHT * rng.choice([-1.0, 1.0], SPIKES)
    return dataclasses.replace(log, tau=tau), log.t[rows]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """Thresholds calibrated on a free log; a free log and a log with a 20 N push on link
    6 from 3.0 to 3.5 s, each clean and with spikes."""
    d = tmp_path_factory.mktemp("spikes")
    save_torque_log(d / "free.csv", _log(1))
    cal = ["observe", "--params", "panda", "-q", "--no-figures", "--calibrate"]
    assert main([*cal, "--data", str(d / "free.csv"), "--out", str(d / "cal")]) == 0
    free = _log(2)
    hit = _log(3, (Contact("link6", (0.0, 0.0, -20.0), 3.0, 3.5),))
    times = {}
    for name, log, away in (("free2", free, (0.0, 0.0)), ("hit", hit, (2.9, 3.7))):
        save_torque_log(d / f"{name}.csv", log)
        spiked, times[name] = _spiked(log, 7, away)
        save_torque_log(d / f"{name}_spiked.csv", spiked)
    return d, times


def _events(d, name, path=None):
    """The events of the log ``d / name`` (or ``path``) and the spike warnings."""
    opts = ObserveOptions(
        data=(path or d / name,), params="panda", thresholds=d / "cal" / "thresholds.json"
    )
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always", DynidWarning)
        (x,) = observe_files(opts).logs
    return x.events, [str(w.message) for w in got if "torque sample(s)" in str(w.message)]


def test_isolated_torque_spikes_are_no_collision_and_are_named(folder):
    """Regression (ten one-sample 30 N m spikes in a Kinova free-motion log made ten
    'collision' events, without a warning): the spiked free log has no event, as the
    clean one, and one warning gives the file, the count and the spikes' times (up to
    three per joint: here every one)."""
    d, times = folder
    assert _events(d, "free2.csv") == ([], [])
    events, said = _events(d, "free2_spiked.csv")
    assert events == [] and len(said) == 1, (events, said)
    assert said[0].startswith(f"free2_spiked.csv: {SPIKES} torque sample(s)")
    listed = {float(x) for x in re.findall(r"\d+\.\d+", said[0].split("noise:")[1])}
    assert all(any(abs(t - x) < 1e-3 for x in listed) for t in times["free2"]), said[0]
    assert "before the observer runs" in said[0]


def test_a_contact_is_found_at_the_same_time_in_a_log_with_spikes(folder):
    """A 20 N push from 3.0 s, with ten spikes elsewhere in the log: one event, starting
    where it starts in the clean log (within 10 ms of the push), no other."""
    d, _ = folder
    clean, _ = _events(d, "hit.csv")
    spiked, said = _events(d, "hit_spiked.csv")
    assert len(clean) == 1 and 3.0 <= clean[0].start < 3.01, clean
    assert [(e.start, e.level) for e in spiked] == [(clean[0].start, clean[0].level)]
    assert len(said) == 1


def test_at_a_low_rate_the_spikes_are_kept_and_said_so(folder, tmp_path):
    """At 100 Hz a short impact can be one sample: a free log at 100 Hz with ten spikes
    keeps them (they show as events, as without the rule), and the warning says they were
    kept and why."""
    d, _ = folder
    slow = _log(2).select(slice(0, None, 10))
    rng = np.random.default_rng(5)
    rows = np.sort(rng.choice(np.arange(50, slow.n_samples - 50, 30), SPIKES, replace=False))
    tau = np.array(slow.tau)
    tau[rows, rng.integers(0, slow.n, SPIKES)] += HEIGHT
    save_torque_log(tmp_path / "slow.csv", dataclasses.replace(slow, tau=tau))
    events, said = _events(d, "", tmp_path / "slow.csv")
    assert len(said) == 1 and "kept: at 100 Hz, below 500 Hz" in said[0], said
    assert events, "the spikes kept at 100 Hz"
