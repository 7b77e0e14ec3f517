"""The held-out prediction of ``dynid identify`` (``heldout.json``, the verdict line, the
held-out figures) is made by the library from the logs the identification read: returned
by :func:`~dynid.workflows.identify.identify_files`, each data file read once.

References: exact simulated Panda logs (viscous friction, true accelerations kept), whose
torques are the rigid body's through RNEA plus the true friction; the files the command
reads, counted.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.dynamics.rnea import rnea
from dynid.exceptions import DynidWarning
from dynid.friction.heldout_torques import heldout_torques
from dynid.friction.model import ClassicalFriction
from dynid.identification.log import TorqueLog
from dynid.identification.structure import Structure
from dynid.io.torque_log import save_torque_log
from dynid.workflows import data_files as data_files_module
from dynid.workflows.identify import IdentifyOptions, identify_files

from conftest import recordings

FRICTION = ClassicalFriction(np.linspace(0.6, 0.2, 7), np.zeros(7), np.zeros(7))


@pytest.fixture(scope="module")
def logs(panda, tmp_path_factory):
    """Two exact 4 s recordings at 250 Hz (seeds 1, 2), in memory and as CSV files."""
    d = tmp_path_factory.mktemp("heldout_prediction")
    logs = recordings(panda, (1, 2), friction=FRICTION, duration=4.0, fs=250.0)
    paths = [d / f"r{k}.csv" for k in (1, 2)]
    for log, path in zip(logs, paths, strict=True):
        save_torque_log(path, log)
    return logs, paths


def _truth(robot, log: TorqueLog, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The log's rows at the instants ``t`` and the torques there [N m] through RNEA plus
    the true friction."""
    rows = np.searchsorted(log.t, t)
    assert np.array_equal(log.t[rows], t)
    return rows, rnea(robot, log.q[rows], log.dq[rows], log.ddq[rows]) + FRICTION.torques(
        log.dq[rows]
    )


def _identified(robot, data, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return identify_files(robot, data, IdentifyOptions(terms="viscous", **kw))


def test_identify_files_returns_the_prediction_of_the_last_time_block(panda, logs):
    """One exact log, 5 time blocks: identify_files (no command line) returns the
    held-out prediction; its samples are the log's in the last block (its edges trimmed
    as filtered), its measured torques the log's own, and its predicted torques RNEA
    plus the true friction there (to 1e-4 of their norm: the states' zero-phase filter
    leaves about 3e-6)."""
    (log, _), (path, _) = logs
    held = _identified(panda, path).heldout
    assert held is not None and held.block.startswith("the last of 5 time blocks")
    v = held.validation
    rows, tau = _truth(panda, log, v.log.t)
    assert v.log.t[0] > log.t[0] + 0.75 * (log.t[-1] - log.t[0]) and np.all(np.diff(rows) == 1)
    np.testing.assert_array_equal(v.log.tau, log.tau[rows])
    assert np.linalg.norm(v.tau_hat - tau) < 1e-4 * np.linalg.norm(tau)
    assert held.as_dict()["n_samples"] == v.log.t.size


def test_identify_files_returns_the_prediction_of_a_separate_log(panda, logs):
    """validate_on, a recording the fit did not see: the model itself predicts its
    samples, RNEA plus the true friction (to 1e-4 of their norm)."""
    (_, separate), (path, other) = logs
    held = _identified(panda, path, validate_on=other).heldout
    assert held is not None and held.block == "the separate log (--validate-on)"
    v = held.validation
    rows, tau = _truth(panda, separate, v.log.t)
    assert rows.size > 0.8 * separate.t.size
    np.testing.assert_array_equal(v.log.tau, separate.tau[rows])
    assert np.linalg.norm(v.tau_hat - tau) < 1e-4 * np.linalg.norm(tau)


def test_validate_of_the_separate_log_judges_the_samples_identify_held_out(panda, logs):
    """validate of the --validate-on recording with the identified model judges the same
    samples as identify's held-out prediction of it (the same ends trimmed at the same
    cut-off): the same time stamps, prediction and error."""
    from dynid.workflows.validate import ValidateOptions, validate_files

    (_, separate), (path, other) = logs
    ident = _identified(panda, path, validate_on=other)
    held = ident.heldout
    assert held is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        val = validate_files(ident.model, other, ValidateOptions())
    (part,) = val.validation.parts
    np.testing.assert_array_equal(part.log.t, held.validation.log.t)
    np.testing.assert_allclose(part.tau_hat, held.validation.tau_hat, rtol=0, atol=1e-9)
    rel = val.validation.errors.relative_error_percent
    assert abs(rel - held.validation.errors.relative_error_percent) < 1e-9 * rel


def test_identify_files_returns_the_prediction_of_every_recording(panda, logs):
    """Two recordings: each, predicted by the fit of the other, pooled one after the
    other (the verdict was the last recording's alone, while the leave-one-recording-out
    judgement printed under it pooled them all): both recordings' samples, in order on
    one increasing time axis, and their predicted torques RNEA plus the true friction at
    the prepared states (to 1e-4 of their norm)."""
    (first, last), paths = logs
    held = _identified(panda, paths).heldout
    assert held is not None
    assert held.block == "each of the 2 recordings, predicted by the fit of the other 1"
    v = held.validation
    assert v.log.t.size > 0.8 * (first.t.size + last.t.size) and np.all(np.diff(v.log.t) > 0)
    tau = rnea(panda, v.log.q, v.log.dq, v.log.ddq) + FRICTION.torques(v.log.dq)
    assert np.linalg.norm(v.tau_hat - tau) < 1e-4 * np.linalg.norm(tau)
    rows = np.searchsorted(first.t, v.log.t[:50])  # the first recording's, as it was
    np.testing.assert_array_equal(v.log.tau[:50], first.tau[rows])


@pytest.mark.parametrize("case", ["folder", "validate_on"])
def test_identify_reads_each_data_file_once(logs, tmp_path, monkeypatch, case):
    """Regression: the command read the last data file (and the --validate-on log) a
    second time for its held-out prediction (4-6 s more on a 10-minute 1 kHz log, and a
    second progress line); now every file is read once, and heldout.json is written."""
    _, (first, second) = logs
    read = data_files_module.load_torque_log
    counts: dict[str, int] = {}

    def counted(path, *args, **kw):
        counts[path.name] = counts.get(path.name, 0) + 1
        return read(path, *args, **kw)

    monkeypatch.setattr(data_files_module, "load_torque_log", counted)
    data = [str(first.parent)] if case == "folder" else [str(first), "--validate-on", str(second)]
    argv = ["identify", "--robot", "panda", "--terms", "viscous", "--no-figures", "-q"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*argv, "--data", *data, "--out", str(tmp_path / "out")]) == 0
    assert counts == {first.name: 1, second.name: 1}
    assert (tmp_path / "out" / "heldout.json").is_file()


def test_the_heldout_prediction_does_not_judge_the_torques_sign_again(panda, logs):
    """The held-out prediction is made of data identify has checked: what its fold fit's
    prediction says of the torques' sign is not said (a right-signed 2 s UR5 log read
    "anti-correlated ... sign probably opposite" from a poor fold fit). Here the log
    handed to it is the negated one, which the prediction would call opposite."""
    from dynid.identification.selection import identify_recordings

    (a, b), _ = logs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, [a, b], structure=Structure(False, ("viscous",)))
    neg = TorqueLog(b.t, b.q, b.dq, -b.tau)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DynidWarning)
        held = heldout_torques(model, neg)
    assert held is not None and held.verdict.level == "unusable"


def test_the_heldout_prediction_of_a_wrapped_motor_log_uses_its_q_start_turns(panda, tmp_path):
    """Regression: with --q-start the held-out prediction re-read the motor-side log
    without the whole turns the fit had given it (joint positions a motor turn off: a
    Panda log's held-out error read 3.6e3 % where the fit's was 61 %); now it predicts
    the log the fit took, as on the log that recorded the turns (errors equal to 1e-6)."""
    from dynid.io.drive_file import load_drive
    from dynid.simulation.measurement import SensorNoise, simulate_measurement
    from dynid.simulation.trajectories import Trajectory

    (tmp_path / "drive.toml").write_text(
        'schema = "dynid-drive/1"\nside = "motor"\ngear_ratio = 50\n'
        "coupling = [[7, 6, 15.0]]\noffset = [0.01, -0.02, 0.0, 0.03, 0.0, 0.0, 0.01]\n"
        "rotor_inertia = [0, 0, 0, 0, 0, 0, 0]\n"
    )
    drive = load_drive(tmp_path / "drive.toml", 7)
    t = np.arange(0.0, 4.0, 0.005)
    w, ph = 2 * np.pi * np.linspace(0.4, 0.9, 7), np.linspace(0.3, 2.8, 7)
    c = 0.5 * (panda.q_min + panda.q_max) + 0.3
    s, co = np.sin(w * t[:, None] + ph), np.cos(w * t[:, None] + ph)
    traj = Trajectory(t, c + 0.1 * s, 0.1 * w * co, -0.1 * w**2 * s)
    turns = simulate_measurement(
        panda, traj, rng=np.random.default_rng(0), noise=SensorNoise(), drive=drive
    )
    wrapped = TorqueLog(turns.t, np.angle(np.exp(1j * turns.q)), turns.dq, turns.tau)
    assert np.all(np.abs(turns.q[0]) > np.pi)  # every motor lost turns at the start
    save_torque_log(tmp_path / "m.csv", turns)
    save_torque_log(tmp_path / "w.csv", wrapped)
    kw = dict(drive=drive, cutoff_hz=5.0)
    q_start = tuple(float(x) for x in traj.q[0] + 0.003)
    got = _identified(panda, tmp_path / "w.csv", q_start=q_start, **kw).heldout
    want = _identified(panda, tmp_path / "m.csv", **kw).heldout
    assert got is not None and want is not None
    np.testing.assert_allclose(got.validation.errors.rms, want.validation.errors.rms, rtol=1e-6)
    assert got.as_dict()["relative_error_percent"] < 100


def test_a_heldout_prediction_it_cannot_make_is_a_warning_not_a_failure(panda, logs, tmp_path):
    """The last recording 60 samples long (too short to filter for the prediction):
    identify_files returns the model, no held-out prediction, and a warning says why."""
    (_, last), (first, _) = logs
    short = tmp_path / "short.csv"
    save_torque_log(short, last.select(slice(0, 60)))
    with pytest.warns(DynidWarning, match=r"skipped the held-out prediction .*trimming"):
        result = identify_files(panda, [first, short], IdentifyOptions(terms="viscous"))
    assert result.heldout is None and result.model.holdout is not None
