"""Several recordings and bad inputs on every command that reads them, as a new user
meets them: each case ends in one line naming the file (or is handled with a note), never a
dropped recording nor a traceback; each warning is printed once.

References: simulated Panda logs (the torques of the robot's own model plus sensor noise)
rewritten the way real files go wrong (empty, header only, NaN rows, duplicated or
decreasing stamps, extra columns, another joint count, another unit, torques of another
sign), and the closed-form relative error of a prediction of zero (100 %).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows import identify as identify_workflow
from dynid.workflows.identify import IdentifyOptions, identify_files


def _log(robot, seed, duration=5.0, rate=200.0):
    traj = random_fourier(robot, np.random.default_rng(seed))(sample_times(duration, rate))
    return simulate_measurement(robot, traj, rng=np.random.default_rng(seed + 100))


@pytest.fixture(scope="module")
def panda():
    return dynid.panda()


class _Stop(Exception):
    """Raised in place of the convex solve: the unconstrained fit is what is judged."""


def test_the_consistent_route_warns_each_finding_of_the_data_once(panda, tmp_path, monkeypatch):
    """Torques of the opposite sign: the consistent route's unconstrained fit (structure
    chosen on held-out data, then the classical friction fitted with it) prepares the log
    once, so its finding is warned once (it was warned by the selection's fit and again
    by the final one), and the friction warnings are those of the model kept."""
    log = _log(panda, 3)
    save_torque_log(tmp_path / "neg.csv", type(log)(log.t, log.q, log.dq, -log.tau))
    kept = {}

    def stop(robot, model, **kw):
        kept["model"] = model
        raise _Stop

    monkeypatch.setattr(identify_workflow, "consistent_from_identified", stop)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(_Stop):
            identify_files(panda, [tmp_path / "neg.csv"], IdentifyOptions(consistent=True))
    said = [str(w.message) for w in caught if issubclass(w.category, DynidWarning)]
    assert sum("anti-correlated" in s for s in said) == 1
    assert len(said) == len(set(said)), said
    model = kept["model"]
    assert model.info.selection is not None  # the structure was chosen, and recorded
    assert model.friction.shape == (7, 3)  # fv, fc, fo per joint: the classical friction
    # the friction warnings are of the model kept: one per joint whose kept friction
    # has a negative viscous or Coulomb coefficient (the selection's fit warned its own)
    quoted = [s for s in said if s.startswith("identified friction not dissipative")]
    named = sorted(int(s.split("(joint ")[1].split(":")[0]) for s in quoted)
    negative = np.flatnonzero(np.any(model.friction[:, :2] < 0, axis=1)) + 1
    assert named and set(named) <= set(negative.tolist()) and len(named) == len(set(named))
