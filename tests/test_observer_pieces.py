"""The observer on logs that stop, jump or hold NaN: cut at gaps (the observer starts
again, no event spans a cut, never an event invented from a gap), rows dropped for NaN
bridged as ``identify`` bridges them, invalid rows refused unless dropped, position jumps
warned about, a long standstill quiet; through the library and ``dynid observe``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.typing import NDArray

import dynid
from dynid.cli.__main__ import main
from dynid.identification.log import TorqueLog
from dynid.io.torque_log import load_torque_log, save_torque_log
from dynid.observer.detection import Thresholds, detect
from dynid.observer.pieces import pieces, position_jumps
from dynid.observer.residual import ObserverOptions
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import Trajectory, random_fourier, uniform_times


def test_pieces_start_after_every_step_longer_than_the_gap_rule():
    """A 0.5 s stop cuts; a 2 ms step (a row dropped) is bridged, cut only under a 1.5 ms rule."""
    t = np.array([0.0, 0.001, 0.002, 0.5, 0.501, 0.502, 0.504, 0.505])
    assert pieces(t, 0.02).tolist() == [0, 3]
    assert pieces(t, 0.0015).tolist() == [0, 3, 6]
    assert pieces(t, 1.0).tolist() == [0]


def test_position_jumps_find_a_step_the_velocity_does_not_explain():
    """q = sin(t) recorded with its derivative: no jump; 0.05 rad added from t = 1 s on
    joint 2: found there, of that size; a long standstill (q constant, dq = 0): none."""
    t = np.arange(0.0, 2.0, 1e-3)
    q = np.stack([np.sin(t), np.cos(2 * t)], axis=1)
    dq = np.stack([np.cos(t), -2 * np.sin(2 * t)], axis=1)
    assert position_jumps(t, q, dq) == []
    q2 = q.copy()
    q2[t >= 1.0, 1] += 0.05
    (jump,) = position_jumps(t, q2, dq)
    assert (
        jump.joint == 1
        and jump.t == pytest.approx(1.0)
        and jump.size == pytest.approx(0.05, abs=1e-5)
    )
    assert position_jumps(t, q2, dq, starts=(0, int(np.argmax(t >= 1.0)))) == []  # a cut there
    assert position_jumps(t, np.ones_like(q), np.zeros_like(dq)) == []


def test_an_encoder_glitch_is_named_at_its_jump_not_at_its_jump_back():
    """One sample read 0.05 rad off (at t = 1 s) and the next a little short of the way
    back: the glitch is at t = 1 s, of +0.05, though the step back is the larger."""
    t = np.arange(0.0, 2.0, 1e-3)
    q = np.sin(t)[:, None]
    dq = np.cos(t)[:, None]
    k = int(np.argmax(t >= 1.0))
    q[k] += 0.05
    q[k + 1] -= 0.002
    (jump,) = position_jumps(t, q, dq)
    assert jump.t == pytest.approx(1.0) and jump.size == pytest.approx(0.05, abs=1e-5)


def test_log_labels_tell_logs_of_one_name_apart_by_their_folders():
    """A file name when it is unique; the folder too for two free.csv."""
    from dynid.io.observer_files import log_labels

    paths = ["x/a/free.csv", "x/b/free.csv", "x/a/hit.csv"]
    assert log_labels(paths) == ["a/free.csv", "b/free.csv", "hit.csv"]
    assert log_labels(["a/b/c.csv", "d/b/c.csv"]) == ["a/b/c.csv", "d/b/c.csv"]


def test_no_event_spans_a_restart():
    t = np.arange(10) * 1e-3
    r = np.zeros((10, 1))
    r[3:7] = 2.0
    th = Thresholds(np.ones(1), np.full(1, 3.0), 1.5, 1.0, 3.0, ObserverOptions(), 1)
    raw = {"min_duration_s": 0.0}  # events of a few samples
    assert [(e.start, e.end) for e in detect(t, r, th, **raw)] == [(0.003, 0.006)]
    cut = detect(t, r, th, restarts=[0, 5], **raw)
    assert [(e.start, e.end) for e in cut] == [(0.003, 0.004), (0.005, 0.006)]


def _log(seed: int, duration: float = 6.0) -> TorqueLog:
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=4, w_f=2 * np.pi * 0.125)(
        uniform_times(duration, 1000.0)
    )
    return simulate_measurement(robot, traj, rng=rng, noise=SensorNoise())


def _rows(log: TorqueLog, keep) -> TorqueLog:
    return TorqueLog(log.t[keep], log.q[keep], log.dq[keep], log.tau[keep])


def _standstill_log(seed: int) -> TorqueLog:
    """Rest, a smooth move, 3 s of standstill holding gravity, a move back."""
    robot = dynid.panda()
    t = uniform_times(7.0, 1000.0)
    q0, dqmax = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8]), np.full(7, 0.4)

    def smooth(x):  # 0 -> 1 with zero rate and curvature at both ends
        x = np.clip(x, 0.0, 1.0)
        return (
            x**3 * (10 - 15 * x + 6 * x**2),
            30 * x**2 * (1 - x) ** 2,
            60 * x * (1 - x) * (1 - 2 * x),
        )

    up, dup, ddup = smooth(t / 2.0)
    dn, ddn, dddn = smooth((t - 5.0) / 2.0)
    s, ds, dds = up - dn, dup / 2.0 - ddn / 2.0, ddup / 4.0 - dddn / 4.0
    traj = Trajectory(t, q0 + s[:, None] * dqmax, ds[:, None] * dqmax, dds[:, None] * dqmax)
    return simulate_measurement(robot, traj, rng=np.random.default_rng(seed), noise=SensorNoise())


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("pieces")
    free = _log(1)
    save_torque_log(d / "free.csv", free)
    cal = ["observe", "--params", "panda", "-q", "--no-figures"]
    assert main([*cal, "--data", str(d / "free.csv"), "--calibrate", "--out", str(d / "cal")]) == 0
    other = _log(2)
    gap = (other.t < 2.0) | (other.t >= 3.0)  # the recording stopped for 1 s, the arm moved on
    save_torque_log(d / "gap.csv", _rows(other, gap))
    save_torque_log(d / "still.csv", _standstill_log(3))
    return d


def _observe(d, name, *extra):
    th = ["--thresholds", str(d / "cal" / "thresholds.json")]
    args = ["observe", "--params", "panda", *th, "--no-figures", "--data", str(d / name)]
    rc = main([*args, "--out", str(d / f"obs_{name}"), "--force", *extra])
    events = None
    if rc == 0:
        events = json.loads((d / f"obs_{name}" / "events.json").read_text())["events"]
    return rc, events


def test_a_gap_cuts_the_log_and_invents_no_event(folder, capsys):
    """Integrated across the 1 s gap (--max-gap 2) the residual makes a collision of it;
    cut there (default), no event and one warning naming the file and the restart time."""
    rc, events = _observe(folder, "gap.csv", "--max-gap", "2")
    assert rc == 0 and len(events) >= 1 and events[0]["start"] == pytest.approx(3.0)
    capsys.readouterr()
    rc, events = _observe(folder, "gap.csv")
    assert rc == 0 and events == []
    (line,) = [x for x in capsys.readouterr().err.splitlines() if "warning" in x]
    assert "gap.csv: cut at gaps longer than 0.02 s" in line and "at t = 3.000 s" in line


def _with_nan(src, dst, rows) -> None:
    """``src`` with a NaN written into column 9 of each data row of ``rows`` (0-based)."""
    text = src.read_text().splitlines()
    head = sum(1 for line in text if not line[:1].isdigit() and not line[:1] == "-")
    for row in rows:
        cells = text[head + row].split(",")
        cells[9] = "nan"
        text[head + row] = ",".join(cells)
    dst.write_text("\n".join(text) + "\n")


def test_nan_rows_are_refused_naming_the_row_or_dropped_and_bridged(folder, capsys, caplog):
    """Two NaN rows: refused naming the first; dropped (--drop-invalid), counted, and the
    2 ms steps they leave bridged as identify bridges them: no cut, no event."""
    d = folder
    _with_nan(d / "free.csv", d / "nan.csv", (1500, 4000))
    rc, _ = _observe(d, "nan.csv")
    err = capsys.readouterr().err
    assert rc != 0 and "nan.csv" in err and "row 1500" in err and "--drop-invalid" in err
    rc, events = _observe(d, "nan.csv", "--drop-invalid")
    assert rc == 0 and events == []
    err = capsys.readouterr().err
    assert "dropped 2 row(s)" in caplog.text and "row 4000" in caplog.text  # counted
    assert "cut at" not in err and "starts again" not in err


def _pushed_log(seed: int) -> tuple[TorqueLog, NDArray[np.float64]]:
    """A 6 s Panda log at 1 kHz with pushes of 20 N on link 6 over [2.0, 2.4) s and
    [4.0, 4.5) s, and the true external joint torques."""
    from dynid.simulation.contact import Contact, contact_torques

    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=4, w_f=2 * np.pi * 0.125)(
        uniform_times(6.0, 1000.0)
    )
    pushes = (
        Contact("link6", (0.0, 0.0, -20.0), 2.0, 2.4),
        Contact("link6", (0.0, 20.0, 0.0), 4.0, 4.5),
    )
    log = simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), contacts=pushes)
    return log, contact_torques(robot, pushes, traj.t, traj.q)


def test_a_nan_row_inside_a_push_is_bridged_and_a_long_run_of_them_cuts(folder, capsys):
    """Two pushes (truth): two events unbroken; with a NaN row dropped inside the first push,
    still two, and the residual across the bridged 2 ms step within the observer's noise
    (its std on free motion) of the unbroken log's; 30 NaN rows dropped (a 31 ms step,
    over the 20 ms rule) cut the log with a warning naming the restart, still two events."""
    d = folder
    log, ext = _pushed_log(5)
    assert np.abs(ext[(log.t >= 2.0) & (log.t < 2.4)]).max() > 5.0  # the residual must see it
    save_torque_log(d / "push.csv", log)
    _with_nan(d / "push.csv", d / "push_nan.csv", (2200,))
    _with_nan(d / "push.csv", d / "push_run.csv", range(3000, 3030))
    capsys.readouterr()
    found = {}
    for name in ("push.csv", "push_nan.csv", "push_run.csv"):
        rc, events = _observe(d, name, "--drop-invalid")
        assert rc == 0
        found[name] = [(e["start"], e["end"]) for e in events]
        cuts = [x for x in capsys.readouterr().err.splitlines() if "cut at" in x]
        assert len(cuts) == (name == "push_run.csv"), cuts
    for name, spans in found.items():  # one event per push, each inside its push
        assert len(spans) == 2, (name, spans)
        assert 1.99 < spans[0][0] < 2.4 and 3.99 < spans[1][0] < 4.5
    assert (
        "push_run.csv: cut at gaps longer than 0.02 s (some where rows were dropped for "
        "NaN/inf): the observer starts again at t = 3.030 s"
    ) in cuts[0]
    whole = np.loadtxt(d / "obs_push.csv" / "residuals.csv", delimiter=",", skiprows=3)
    holed = np.loadtxt(d / "obs_push_nan.csv" / "residuals.csv", delimiter=",", skiprows=3)
    keep = np.round(whole[:, 0], 6) != 2.2
    assert holed[:, 0] == pytest.approx(whole[keep, 0])
    free = (whole[:, 0] < 1.9) | ((whole[:, 0] > 2.6) & (whole[:, 0] < 3.9))
    noise = np.std(whole[free, 1:], axis=0)  # the observer's on free motion
    near = np.abs(holed[:, 0] - 2.2) < 0.1  # across the bridged step and the lag after it
    gap = np.abs(holed[near, 1:] - whole[keep][near, 1:]).max(axis=0)
    assert np.all(gap < noise), (gap, noise)  # the dropped sample's torque noise, K_O T of it
    at = np.argmin(np.abs(whole[:, 0] - 2.2))
    assert np.abs(whole[at, 1:]).max() > 20 * noise.max()  # a restart there would show


def test_a_position_jump_is_warned_about(folder, capsys):
    d = folder
    log = _log(2)
    q = np.array(log.q)
    q[log.t >= 4.0, 1] += 0.05  # an encoder glitch on joint 2
    save_torque_log(d / "jump.csv", TorqueLog(log.t, q, log.dq, log.tau))
    assert _observe(d, "jump.csv")[0] == 0
    err = capsys.readouterr().err
    assert (
        "jump.csv: position jumps more than the recorded velocity explains (joint 2 by +0.05" in err
    )
    assert "at t = 4.000 s" in err


def test_samples_lost_in_one_short_step_cut_the_log_and_invent_no_event(folder, capsys):
    """0.3 s of rows lost while the arm moves, the time stamps after shifted so that the
    step there is 2 ms (one sample missing: under the default --max-gap of 20 ms): the
    positions jump; cut there, no event and one warning naming the jump as samples lost
    (it was taken for a gap bridged by --max-gap and made a collision of the jump)."""
    d = folder
    log = _log(2)
    keep = (log.t < 2.0) | (log.t >= 2.3)
    lost = _rows(log, keep)
    t = np.where(lost.t >= 2.3, lost.t - 0.3 + 1e-3, lost.t)
    jump = np.abs(lost.q[t >= 2.0][0] - lost.q[t < 2.0][-1]).max()
    assert jump > 0.05 and np.diff(t).max() == pytest.approx(2e-3)
    save_torque_log(d / "lost.csv", TorqueLog(t, lost.q, lost.dq, lost.tau))
    rc, events = _observe(d, "lost.csv")
    assert rc == 0 and events == []
    (line,) = [x for x in capsys.readouterr().err.splitlines() if "warning" in x]
    assert "lost.csv: position jumps more than the recorded velocity explains" in line
    assert "samples lost without a gap in the time stamps" in line


def test_a_long_standstill_raises_nothing(folder, capsys):
    rc, events = _observe(folder, "still.csv")
    assert rc == 0 and events == []
    assert "warning" not in capsys.readouterr().err


def test_the_library_runs_the_observer_again_on_each_piece(folder):
    """observe_files: the piece after the gap starts at its first sample with r = 0, as a
    fresh observer on that piece alone gives (the state of the first piece forgotten)."""
    from dynid.observer import from_robot, observe
    from dynid.workflows.observe import ObserveOptions, observe_files

    d = folder
    opts = ObserveOptions(
        data=(d / "gap.csv",), params="panda", thresholds=d / "cal" / "thresholds.json"
    )
    with pytest.warns(UserWarning, match="cut at gaps"):
        (x,) = observe_files(opts).logs
    k = int(np.argmax(x.t >= 3.0))
    assert x.restarts == (0, k) and not np.any(x.r[k])
    log = _rows(_log(2), slice(None))
    after = log.t >= 3.0
    alone = observe(
        from_robot(dynid.panda()), log.t[after], log.q[after], log.dq[after], log.tau[after]
    )
    assert x.r[k:] == pytest.approx(np.asarray(alone.r), abs=1e-9)


def _positions_only(path, log: TorqueLog) -> None:
    """A CSV of t, q, tau (no velocity column)."""
    n = log.q.shape[1]
    head = ",".join(["t", *(f"q{j + 1}" for j in range(n)), *(f"tau{j + 1}" for j in range(n))])
    np.savetxt(
        path, np.column_stack([log.t, log.q, log.tau]), delimiter=",", header=head, comments=""
    )


def test_positions_only_logs_get_velocities_per_piece_and_unobserved_edges(folder, capsys):
    """A log without velocities, cut by a 1 s gap: derived across the gap, the velocities
    made collisions of its edges (24 N m); derived per piece, with the low-pass's
    transient at each piece's ends left unobserved (NaN), no event on free motion, while a
    20 N push inside a piece is still found where it starts."""
    from dynid.simulation.contact import Contact

    d = folder
    _positions_only(d / "free_q.csv", _log(1))
    other = _log(2)
    _positions_only(d / "gap_q.csv", _rows(other, (other.t < 2.0) | (other.t >= 3.0)))
    robot = dynid.panda()
    rng = np.random.default_rng(4)
    traj = random_fourier(robot, rng, n_harmonics=4, w_f=2 * np.pi * 0.125)(
        uniform_times(6.0, 1000.0)
    )
    push = Contact("link6", (0.0, 0.0, -20.0), 4.0, 4.5)
    hit = simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), contacts=(push,))
    _positions_only(d / "hit_q.csv", _rows(hit, (hit.t < 2.0) | (hit.t >= 2.5)))
    cal = ["observe", "--params", "panda", "--no-figures", "--force"]
    args = [*cal, "--data", str(d / "free_q.csv"), "--calibrate", "--out", str(d / "cal_q")]
    assert main(args) == 0
    assert "velocities derived from the positions of each piece" in capsys.readouterr().err
    th = ["--thresholds", str(d / "cal_q" / "thresholds.json")]
    for name, want in (("gap_q.csv", []), ("hit_q.csv", [4.0])):
        out = d / f"obs_{name}"
        assert main([*cal, *th, "--data", str(d / name), "--out", str(out)]) == 0
        events = json.loads((out / "events.json").read_text())["events"]
        assert [round(e["start"], 1) for e in events] == want, events
        r = np.loadtxt(out / "residuals.csv", delimiter=",", skiprows=3)  # t, r1 .. r7
        unseen = np.isnan(r[:, 1])
        assert unseen[0] and unseen[-1] and 0.05 < unseen.mean() < 0.5  # the pieces' edges


def test_a_nan_row_in_a_log_of_positions_leaves_no_more_unobserved(tmp_path):
    """Positions only, a NaN row dropped at 3 s: one piece, velocities derived across the
    bridged step, only the log's two ends unobserved, as without the row (a restart left
    2 x 0.1 s more unobserved); the derived velocities within 0.1 s of the row within
    0.1 % of the motion's range of those of the unbroken log (2.4e-4 rad/s measured)."""
    from dynid.observer import from_robot
    from dynid.workflows.observe_logs import prepared_log

    log = _log(6)
    _positions_only(tmp_path / "q.csv", log)
    _with_nan(tmp_path / "q.csv", tmp_path / "q_nan.csv", (3000,))
    model = from_robot(dynid.panda())
    preps = {}
    for name in ("q.csv", "q_nan.csv"):
        read = load_torque_log(tmp_path / name, drop_invalid=True)
        with pytest.warns(UserWarning, match="velocities derived") as seen:
            preps[name] = prepared_log(tmp_path / name, read, model, None)
        assert not [w for w in seen if "cut at" in str(w.message)]
    whole, holed = preps["q.csv"], preps["q_nan.csv"]
    assert len(holed.spans) == 1 and holed.spans[0][1] - holed.spans[0][0] == (
        whole.spans[0][1] - whole.spans[0][0] - 1
    )
    keep = np.round(whole.log.t, 6) != 3.0
    near = np.abs(holed.log.t - 3.0) < 0.1
    span = np.ptp(log.dq, axis=0)
    assert np.abs(holed.dq[near] - whole.dq[keep][near]).max(axis=0) == pytest.approx(
        0.0, abs=1e-3 * span.max()
    )
