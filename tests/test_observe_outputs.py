"""What ``dynid observe`` writes and prints for a user: events.json names each event's log
(one log or several) and its joints by name, the largest residual is printed per log
beside the pooled one, and ``--frame`` on a log without velocities (derived, their edges
unobserved) gives the push's wrench where the residual exists and NaN elsewhere."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.simulation.contact import Contact
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times

PUSH = Contact("flange", (10.0, 0.0, 0.0), 2.0, 2.5)  # 10 N along x at the flange


def _positions_only(path, seed: int, contacts=()) -> None:
    """A 4 s Panda log of t, q, tau (no velocity column) at 1 kHz."""
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=4, w_f=2 * np.pi * 0.125)(
        uniform_times(4.0, 1000.0)
    )
    log = simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), contacts=contacts)
    n = log.q.shape[1]
    head = ",".join(["t", *(f"q{j + 1}" for j in range(n)), *(f"tau{j + 1}" for j in range(n))])
    np.savetxt(
        path, np.column_stack([log.t, log.q, log.tau]), delimiter=",", header=head, comments=""
    )


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Thresholds from a free log; detection on a pushed log alone (with the wrench at the
    flange) and on it beside another free log."""
    d = tmp_path_factory.mktemp("observe_outputs")
    _positions_only(d / "free.csv", 1)
    _positions_only(d / "other.csv", 2)
    _positions_only(d / "hit.csv", 3, (PUSH,))
    p = ["observe", "--params", "panda", "--no-figures"]
    assert main([*p, "--data", str(d / "free.csv"), "--calibrate", "--out", str(d / "cal")]) == 0
    p += ["--thresholds", str(d / "cal" / "thresholds.json")]
    one = [*p, "--frame", "flange", "--data", str(d / "hit.csv"), "--out", str(d / "one")]
    assert main(one) == 0
    assert (
        main([*p, "--data", str(d / "hit.csv"), str(d / "other.csv"), "--out", str(d / "two")]) == 0
    )
    return d


def test_events_name_their_log_and_joints_with_one_log_or_several(runs):
    """Every event of events.json has its log and its joints' names (the model's names at
    its 1-based joints), with one log as with two; the push is found within 20 ms."""
    names = list(dynid.panda().joint_names)
    for folder, logs in (("one", {"hit.csv"}), ("two", {"hit.csv", "other.csv"})):
        doc = json.loads((runs / folder / "events.json").read_text())
        assert doc["joints"] == names
        assert doc["events"] and {e["log"] for e in doc["events"]} <= logs
        for e in doc["events"]:
            assert e["joint_names"] == [names[j - 1] for j in e["joints"]]
        pushed = [e for e in doc["events"] if e["log"] == "hit.csv"]
        assert len(pushed) == 1 and 0 <= pushed[0]["start"] - PUSH.start < 0.02


def test_the_time_flagged_is_given_beside_the_event_count(runs):
    """The count alone misled as a false-alarm measure (fewer events covering more time at
    a lower threshold): events.json gives each log's duration and the time its events
    cover, the push's 0.5 s (less the observer's rise, plus its decay) on the pushed log;
    the report's headline gives the sum and its share of the time logged."""
    import re

    doc = json.loads((runs / "two" / "events.json").read_text())
    assert doc["data"] == ["hit.csv", "other.csv"]
    t_end = 4.0  # uniform_times(4.0): first to last sample
    assert doc["duration_s"] == pytest.approx([t_end, t_end], abs=1e-9)
    for log, flagged in zip(doc["data"], doc["flagged_s"], strict=True):
        covered = sum(e["end"] - e["start"] for e in doc["events"] if e["log"] == log)
        assert flagged == pytest.approx(covered, abs=1e-12)
    assert 0.4 < doc["flagged_s"][0] < 0.6
    page = (runs / "two" / "report.html").read_text()
    text = re.sub(r"<[^>]+>", "", page)
    total = sum(doc["flagged_s"])
    share = 100 * total / (2 * t_end)
    assert f"{total:.3g} s flagged ({share:.3g} % of {2 * t_end:.3g} s logged)" in text


def test_the_largest_residual_is_printed_per_log(runs, capsys):
    """With two logs the table's column says it pools them, and a line per log gives that
    log's largest |r| per joint: those of its residual table."""
    capsys.readouterr()
    th = ["--thresholds", str(runs / "cal" / "thresholds.json")]
    data = ["--data", str(runs / "hit.csv"), str(runs / "other.csv")]
    out = ["--no-figures", "--out", str(runs / "two_again")]
    assert main(["observe", "--params", "panda", *th, *data, *out]) == 0
    said = capsys.readouterr().out
    assert "max |r| all logs [N m]" in said and "max |r| per log [N m]" in said
    for name in ("hit", "other"):
        line = next(x for x in said.splitlines() if x.strip().startswith(f"{name}.csv "))
        printed = np.array([float(v) for v in line.split()[1:]])
        table = np.loadtxt(runs / "two_again" / f"residuals_{name}.csv", delimiter=",", skiprows=3)
        np.testing.assert_allclose(printed, np.nanmax(np.abs(table[:, 1:8]), axis=0), rtol=1e-3)


def test_the_wrench_of_a_log_without_velocities_is_nan_where_the_residual_is(runs):
    """--frame on a log whose velocities are derived (its edges unobserved, NaN residual):
    the wrench is NaN on exactly those rows, not flagged damped, and during the push its
    force is the 10 N the simulation applied."""
    table = np.loadtxt(runs / "one" / "residuals.csv", delimiter=",", skiprows=3)
    t, r, wrench, damped = table[:, 0], table[:, 1:8], table[:, 8:14], table[:, 14]
    unseen = np.isnan(r).any(axis=1)
    assert unseen[0] and unseen[-1] and not unseen.all()
    np.testing.assert_array_equal(np.isnan(wrench).any(axis=1), unseen)
    assert np.all(damped[unseen] == 0)
    push = (t > PUSH.start + 0.1) & (t < PUSH.end)  # after five time constants of the lag
    np.testing.assert_allclose(np.median(wrench[push, :3], axis=0), [10.0, 0.0, 0.0], atol=1.5)
