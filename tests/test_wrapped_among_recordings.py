"""A joint recorded wrapped into [-pi, pi] in one of several recordings: every check
across recordings reads the positions the preparation unwraps (the units check took the
jump, spread over many samples by the reader's derivative filter, for velocities 0.0169
times the others' and refused every multi-file run); on a joint whose limits do not allow
a whole turn the jumps are named a wrap, with their times, never degrees."""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError, DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification.recordings import prepare_recordings
from dynid.io.torque_log import load_torque_log
from dynid.observer.model import from_robot
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.identify import IdentifyOptions, identify_files
from dynid.workflows.observe_logs import prepared_log
from dynid.workflows.recordings import read_recordings

FRICTION = ClassicalFriction(np.linspace(0.6, 0.2, 7), np.zeros(7), np.zeros(7))
WIDE = 3.6  # joint 7's limits [rad], widened so that the log's motion is allowed


def _wide(panda: dynid.Robot) -> dynid.Robot:
    q_min, q_max = np.array(panda.q_min), np.array(panda.q_max)
    q_min[6], q_max[6] = -WIDE, WIDE
    return dataclasses.replace(panda, q_min=q_min, q_max=q_max)


def _save(path: Path, t: np.ndarray, q: np.ndarray, tau: np.ndarray) -> Path:
    """A positions-only CSV, every digit kept (a whole turn apart is 2 pi exactly)."""
    n = q.shape[1]
    head = ",".join(["t", *(f"q{j + 1}" for j in range(n)), *(f"tau{j + 1}" for j in range(n))])
    np.savetxt(
        path, np.column_stack([t, q, tau]), delimiter=",", header=head, comments="", fmt="%.17g"
    )
    return path


@pytest.fixture(scope="module")
def files(panda, tmp_path_factory):
    """Three 5 s recordings at 100 Hz of the Panda (joint 7 widened), positions and noisy
    torques (RNEA plus viscous friction); in b.csv joint 7 moves about 3.0 rad across pi
    and is written wrapped into [-pi, pi], in b_by_hand.csv as it moved."""
    d = tmp_path_factory.mktemp("wrapped_among_recordings")
    wide = _wide(panda)
    t = sample_times(5.0, 100.0)
    out = {}
    for seed, name in ((11, "a"), (12, "b"), (13, "c")):
        q0 = np.array(wide.q_neutral, dtype=float)
        if name == "b":
            q0[6] = 3.0
        traj = random_fourier(wide, np.random.default_rng(seed), q0=q0)(t)
        log = simulate_measurement(
            wide,
            traj,
            rng=np.random.default_rng(seed + 100),
            friction=FRICTION,
            noise=SensorNoise(q_std=0.0, dq_std=0.0, tau_std=0.02),
        )
        out[name] = _save(d / f"{name}.csv", log.t, log.q, log.tau)
        if name == "b":
            assert np.ptp(log.q[:, 6]) < 2.0 and log.q[:, 6].min() < np.pi < log.q[:, 6].max()
            out["b_by_hand"] = out["b"].rename(d / "b_by_hand.csv")
            q = np.array(log.q)
            q[:, 6] = np.mod(q[:, 6] + np.pi, 2 * np.pi) - np.pi
            out["b"] = _save(d / "b.csv", log.t, q, log.tau)
    return out


def test_a_wrapped_recording_among_others_identifies_as_unwrapped_by_hand(panda, files):
    """Three recordings, joint 7 of one wrapped: identified (it was refused: 'velocities
    ... other units'), the base parameters and the held-out error equal to 1e-9 those of
    the same recordings with that joint unwrapped by hand."""
    wide = _wide(panda)
    opt = IdentifyOptions(terms="viscous")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        wrapped = identify_files(wide, [files["a"], files["b"], files["c"]], opt)
        by_hand = identify_files(wide, [files["a"], files["b_by_hand"], files["c"]], opt)
    x, y = wrapped.model.fit.beta, by_hand.model.fit.beta
    assert x.shape == y.shape and np.max(np.abs(x - y)) <= 1e-9 * np.max(np.abs(y))
    e = [r.model.info.heldout["heldout_error_percent"] for r in (wrapped, by_hand)]
    assert 0 < e[1] < 5 and abs(e[0] - e[1]) <= 1e-9 * e[1]


def test_a_wrap_on_a_joint_limited_to_less_than_a_turn_is_named_a_wrap(panda, files):
    """The built-in Panda (joint 7 within +-2.897 rad) and the wrapped log: read without
    'in degrees' (the jumps of 2 pi in one sample are a wrap), and the preparation names
    joint7, the times of its jumps and its limits, which do not allow the motion."""
    rec = read_recordings(files["b"], panda)  # was: joint7 'in degrees ... x pi/180'
    log = rec.logs[0]
    jumps = log.t[1:][np.abs(np.diff(log.q[:, 6])) > np.pi]
    assert jumps.size >= 1
    with pytest.warns(DynidWarning) as said:
        prepare_recordings(panda, [log], ["b.csv"])
    text = " ".join(str(w.message) for w in said)
    assert "joint7 jumps a whole turn at t = " + f"{jumps[0]:.3f}" in text
    assert "do not allow a whole turn" in text and "x pi/180" not in text


def test_a_wrap_within_limits_across_pi_is_unwrapped_without_blame(panda, files):
    """Regression: a joint of limits [-0.5, 4.7] (less than a turn, across pi) moving about
    3.0 rad was logged wrapped, and its jumps at pi were called a whole turn its limits do
    not allow ("the log or the robot description is wrong"); it crossed pi within them.
    The wrap is said and unwrapped, without the blame."""
    q_min, q_max = np.array(panda.q_min), np.array(panda.q_max)
    q_min[6], q_max[6] = -0.5, 4.7
    across = dataclasses.replace(panda, q_min=q_min, q_max=q_max)
    log = read_recordings(files["b"], across).logs[0]
    with pytest.warns(DynidWarning) as said:
        prepare_recordings(across, [log], ["b.csv"])
    text = " ".join(str(w.message) for w in said)
    assert "recorded wrapped into [-pi, pi]" in text, text
    assert "do not allow a whole turn" not in text and "is wrong" not in text, text


def test_a_joint_in_degrees_is_still_named_degrees(panda, files, tmp_path):
    """a.csv with joint 7 written in degrees (57 times the radians, no jump):
    refused naming degrees and the conversion, as before."""
    log = load_torque_log(files["a"])
    q = np.array(log.q)
    q[:, 6] = np.degrees(q[:, 6])
    deg = _save(tmp_path / "deg.csv", log.t, q, log.tau)
    with pytest.raises(DataError, match=r"joint7.*degrees.*pi/180"):
        read_recordings(deg, panda)


def test_observe_names_a_wrap_on_a_turn_limited_joint_as_the_fit_does(panda, files):
    """The observer's preparation of the wrapped log names joint7's jumps and limits in the
    same words as identify's (one finding), and unwraps it as the log moved (up to the
    whole turn it starts in)."""
    rec = read_recordings(files["b"], panda)
    with pytest.warns(DynidWarning) as said:
        prep = prepared_log(Path("b.csv"), rec.logs[0], from_robot(panda), None)
    text = " ".join(str(w.message) for w in said)
    assert "b.csv: joint(s) 7 recorded wrapped" in text and "do not allow a whole turn" in text
    by_hand = read_recordings(files["b_by_hand"], panda).logs[0]
    d = prep.log.q - by_hand.q
    turns = np.round(d[0] / (2 * np.pi))
    assert np.max(np.abs(d - 2 * np.pi * turns)) < 1e-12
