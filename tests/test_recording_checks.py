"""Preparation of several recordings that tells the truth (issue 26 items 2 and 5, issue 28
item 6): wraps found only where a joint can wrap and its positions jump by a turn, a time
column in milliseconds refused with its remedy, wraps taken out per piece, gap counts per
recording, and a ``--max-gap`` below the sample step refused in one line.

References: simulated Panda logs (the same motion wrapped into ``[-pi, pi]`` by
``angle(exp(i q))``, its time column multiplied by 1000), the joints' limits, and the
counts of the stretches cut out by hand.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError, DynidWarning, OptionError
from dynid.friction.recordings import prepare_pieces
from dynid.identification.log import TorqueLog
from dynid.identification.pieces import turn_limited
from dynid.identification.recordings import (
    prepare_recordings,
    recording_pieces,
    unwrapped,
    wrappable,
)
from dynid.model.drive import Drive
from dynid.progress import NOTE
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import Trajectory, random_fourier


@pytest.fixture(scope="module")
def panda():
    return dynid.panda()


def _continuous(robot, joints):
    """``robot`` with the given joints (0-based) continuous: no position limits."""
    lo, hi = np.array(robot.q_min), np.array(robot.q_max)
    lo[list(joints)], hi[list(joints)] = -np.inf, np.inf
    return dataclasses.replace(robot, q_min=lo, q_max=hi)


@pytest.fixture(scope="module")
def log(panda):
    """A 6 s, 200 Hz Panda log whose joints 1 and 7 cross +-pi (moved by a constant)."""
    traj = random_fourier(panda, np.random.default_rng(3))(sample_times(6.0, 200.0))
    g = simulate_measurement(panda, traj, rng=np.random.default_rng(4))
    q = np.array(g.q)
    for j in (0, 6):
        q[:, j] += np.pi - 0.5 * (q[:, j].min() + q[:, j].max())  # centred on +pi
    return TorqueLog(g.t, q, g.dq, g.tau)


def _wrap(log, joints):
    q = np.array(log.q)
    q[:, joints] = np.angle(np.exp(1j * q[:, joints]))
    return TorqueLog(log.t, q, log.dq, log.tau)


def test_every_revolute_joint_can_be_recorded_wrapped(panda):
    """Joint side, every revolute joint's log can hold a wrap (the Panda's limits span less
    than a turn: those are turn_limited, named when wrapped); a motor-side log's motor of
    a 50:1 gear turns over joint limits of 0.2 rad (10 rad), a 20:1 one does not (4 rad);
    an identity drive is the joint side."""
    assert np.all(wrappable(panda)) and np.all(turn_limited(panda))
    arm = _continuous(panda, [0, 6])
    np.testing.assert_array_equal(turn_limited(arm), np.arange(7) % 6 != 0)
    np.testing.assert_array_equal(wrappable(arm, Drive.identity(7)), wrappable(arm))
    narrow = dataclasses.replace(
        panda, q_min=np.full(7, -0.1), q_max=np.full(7, 0.1), q_neutral=np.zeros(7)
    )
    gears = Drive.from_gears([50, 20, 50, 20, 50, 20, 50], side="motor")
    np.testing.assert_array_equal(wrappable(narrow, gears), np.arange(7) % 2 == 0)


def test_a_time_column_in_ms_is_refused_naming_the_file_and_the_factor(panda, log):
    """t x 1000: every continuous joint was 'unwrapped' and the cut-off fell to 0.05 Hz;
    now the file, the factor 1000 and --units t=ms are named and nothing is prepared, on
    identification and on validation alike; wrap detection alone finds no wrap in smooth
    positions whose velocities disagree with their time column."""
    arm = _continuous(panda, range(7))
    ms = TorqueLog(1e3 * log.t, log.q, log.dq, log.tau)
    assert unwrapped(ms, np.ones(7, bool))[1] == ()
    with pytest.raises(DataError, match=r"ms\.csv: .*1000 times.*--units t=ms"):
        prepare_recordings(arm, [log, ms], ["good.csv", "ms.csv"], cutoff_hz=10.0)
    with pytest.raises(DataError, match=r"ms\.csv: .*--units t=ms"):
        prepare_pieces(arm, [ms], ["ms.csv"], cutoff_hz=10.0)
    us = TorqueLog(1e6 * log.t, log.q, log.dq, log.tau)
    with pytest.raises(DataError, match="--units t=us"):
        prepare_recordings(arm, [us], ["us.csv"], cutoff_hz=10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DynidWarning)
        prepare_recordings(arm, [log], ["good.csv"], cutoff_hz=10.0)  # seconds: no word


def test_validation_with_an_identity_drive_unwraps_like_identification(panda, log, caplog):
    """An armature model is stored with an identity drive: validation skipped unwrapping
    then. Joint-side pieces with the drive now come back to the motion exactly, as
    without a drive, with the joints named (in a note: the joints are continuous)."""
    arm = _continuous(panda, [0, 6])
    wrapped = _wrap(log, [0, 6])
    for drive in (None, Drive.identity(7)):
        caplog.clear()
        with caplog.at_level(NOTE), warnings.catch_warnings():
            warnings.simplefilter("error", DynidWarning)  # a note, no warning
            p = prepare_pieces(arm, [wrapped], ["w.csv"], cutoff_hz=None, drive=drive)
        assert "joint(s) 1, 7 recorded wrapped" in caplog.text
        assert p.unwrapped == (0, 6)
        back = p.logs[0].q
        np.testing.assert_allclose(back - back[0], log.q - log.q[0], atol=1e-9)


def test_recordings_wrapped_alike_are_said_once(panda, log, caplog):
    """Four recordings with joints 1 and 7 wrapped: four identical warnings, one per file;
    now one, naming the files: a note where the joints turn without end (continuous in
    the description, as the issue asks: unwrapping them is the reading), a warning where
    their limits allow less than a turn (the Panda's own)."""
    arm = _continuous(panda, [0, 6])
    wrapped = _wrap(log, [0, 6])
    names = ["r1.csv", "r2.csv", "r3.csv", "r4.csv"]
    with caplog.at_level(NOTE), warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always", DynidWarning)
        prepare_recordings(arm, [wrapped] * 4, names, cutoff_hz=10.0)
    assert not [w for w in got if "recorded wrapped" in str(w.message)]
    said = [r.getMessage() for r in caplog.records if "recorded wrapped" in r.getMessage()]
    assert said == [f"{', '.join(names)}: joint(s) 1, 7 recorded wrapped into [-pi, pi] "
                    "(jumps of a whole turn): unwrapped"], said  # fmt: skip
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always", DynidWarning)
        prepare_recordings(panda, [wrapped] * 2, names[:2], cutoff_hz=10.0)
    assert [w for w in got if "r1.csv, r2.csv: joint(s) 1, 7 recorded wrapped" in str(w.message)]


def test_a_motor_side_log_is_unwrapped_at_its_motors(panda, log):
    """A geared motor-side log wraps the motor angles: unwrapped before the drive maps
    them to the joints (mapped first, the joint angles came out wrong by 2 pi / 50); the
    whole turns each motor had at the start are lost, and the Panda's limits leave many
    counts of them at a 50:1 gear: refused naming the file and the motors (the fit was
    made with joint angles off by up to 20 turns' worth, with an "unwrapped" note)."""
    arm = _continuous(panda, [0, 6])
    drive = Drive.from_gears(np.full(7, 50.0), side="motor")
    qm = log.q * 50.0
    motor = TorqueLog(log.t, np.angle(np.exp(1j * qm)), log.dq * 50.0, log.tau / 50.0)
    pieces, motors = recording_pieces("m.csv", motor, wrappable(arm, drive))  # no limits
    assert motors == tuple(range(7))
    back = pieces[0].q / 50.0
    np.testing.assert_allclose(back - back[0], log.q - log.q[0], atol=1e-9)
    with pytest.raises(DataError, match=r"m\.csv: motor\(s\) 1, 2, .*7 recorded wrapped.*turns"):
        prepare_pieces(arm, [motor], ["m.csv"], cutoff_hz=None, drive=drive)


def _narrow_motor_log(jitter: float = 0.0, drop: tuple[int, ...] = ()):
    """A Panda whose joints move within +-0.1 rad (sinusoids of 0.08 rad), read at
    motors of 50:1 gears (encoder offsets 0.01 rad at the joints) wrapped into [-pi, pi]
    as single-turn encoders give them; the joint-side truth and the drive."""
    panda = dynid.panda()
    arm = dataclasses.replace(
        panda, q_min=np.full(7, -0.1), q_max=np.full(7, 0.1), q_neutral=np.zeros(7)
    )
    drive = Drive.from_gears(np.full(7, 50.0), side="motor", offset=np.full(7, 0.01))
    t = np.arange(0.0, 4.0, 0.005)
    t = t + jitter * np.random.default_rng(8).standard_normal(t.size)
    t = np.delete(t, list(drop))
    w = 2 * np.pi * np.linspace(0.4, 0.9, 7)
    ph = np.linspace(0.3, 2.8, 7)  # several joints start more than pi / 50 from zero
    s = np.sin(w * t[:, None] + ph)
    c = np.cos(w * t[:, None] + ph)
    traj = Trajectory(t, 0.08 * s, 0.08 * w * c, -0.08 * w**2 * s)
    true = simulate_measurement(
        arm, traj, rng=np.random.default_rng(0), noise=SensorNoise.none(), drive=drive
    )
    wrapped = TorqueLog(true.t, np.angle(np.exp(1j * true.q)), true.dq, true.tau)
    return arm, drive, traj, true, wrapped


def test_a_motor_sides_lost_turns_are_found_from_the_joint_limits():
    """The joints' limits leave one count of turns per motor: the wrapped log comes back
    to the joint positions exactly (absolute, not up to a constant), and identification
    prepares the very samples of the log recorded with multi-turn encoders."""
    arm, drive, traj, true, wrapped = _narrow_motor_log()
    assert np.any(np.abs(true.q[0]) > np.pi)  # turns lost at the start
    with pytest.warns(DynidWarning, match=r"w\.csv: motor\(s\) 1, 2, 3, 4, 5, 6, 7 recorded"):
        pieces, _ = recording_pieces(
            "w.csv", wrapped, wrappable(arm, drive), robot=arm, drive=drive
        )
    q = drive.joint_states(pieces[0].q)[0]
    np.testing.assert_allclose(q, traj.q, atol=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        a = prepare_recordings(arm, [wrapped], ["w.csv"], cutoff_hz=5.0, drive=drive)
        b = prepare_recordings(arm, [true], ["t.csv"], cutoff_hz=5.0, drive=drive)
    for x, y in zip(a.pieces, b.pieces, strict=True):
        for k in ("q", "dq", "ddq", "tau"):
            np.testing.assert_allclose(getattr(x.log, k), getattr(y.log, k), atol=1e-9)


def test_jitter_and_dropped_samples_near_wraps_make_no_false_turn():
    """Timestamps jittered by 0.2 ms and samples dropped right at motor wraps (a jump of
    more than pi between two kept samples, which the recorded velocities explain): the
    positions come back exactly, no turn added or lost."""
    _, drive, _, true, _ = _narrow_motor_log()
    wraps = np.flatnonzero(np.abs(np.diff(np.angle(np.exp(1j * true.q[:, 2])))) > np.pi)
    drop = tuple(int(k) + d for k in wraps[:3] for d in (0, 1))  # both sides of 3 wraps
    arm, drive, traj, true, wrapped = _narrow_motor_log(jitter=2e-4, drop=drop)
    back, motors = unwrapped(wrapped, wrappable(arm, drive))
    assert 2 in motors
    np.testing.assert_allclose(back.q - back.q[0], true.q - true.q[0], atol=1e-9)
    pieces, _ = recording_pieces("j.csv", wrapped, wrappable(arm, drive), robot=arm, drive=drive)
    np.testing.assert_allclose(drive.joint_states(pieces[0].q)[0], traj.q, atol=1e-9)


def test_a_wrap_inside_a_cut_out_stretch_keeps_the_other_wraps(panda, log):
    """Joint 7 wraps several times and a stretch is cut out where it also wraps: the jump
    across the cut is no wrap, every piece comes back to the motion (the joint was left
    wrapped entirely)."""
    arm = _continuous(panda, [6])
    t = log.t
    q = np.array(log.q)
    q[:, 6] = 3.0 * t + np.pi  # turns a half turn a second: wraps at every turn
    dq = np.array(log.dq)
    dq[:, 6] = 3.0
    keep = ~((t > 2.0) & (t < 3.2))  # wrap at t = 2.09 s cut out
    cut = TorqueLog(t, q, dq, log.tau).select(np.flatnonzero(keep))
    wrapped = _wrap(cut, [6])
    with pytest.warns(DynidWarning, match=r"c\.csv: joint\(s\) 7 recorded wrapped"):
        pieces, joints = recording_pieces("c.csv", wrapped, wrappable(arm))
    assert joints == (6,) and len(pieces) == 2
    for piece, rows in zip(pieces, (t[keep] <= 2.0, t[keep] >= 3.2), strict=True):
        truth = cut.q[rows, 6]
        np.testing.assert_allclose(piece.q[:, 6] - piece.q[0, 6], truth - truth[0], atol=1e-9)


def test_cleaning_is_counted_once_per_recording_and_cuts_as_cuts(panda, log):
    """Two cut-out stretches and one dropped sample: 1 gap bridged and 2 cuts, however
    many pieces (the counts were multiplied by the pieces, the cuts called bridged)."""
    t = log.t
    drop = np.ones(t.size, bool)
    drop[(t > 1.5) & (t < 2.0)] = False
    drop[(t > 4.0) & (t < 4.5)] = False
    drop[100] = False  # one lost sample: bridged
    g = TorqueLog.from_raw(t[drop], log.q[drop], log.dq[drop], log.tau[drop])
    rec = prepare_recordings(panda, [g, g], ["a.csv", "b.csv"], cutoff_hz=10.0)
    assert len(rec.pieces) == 6
    info = rec.record(0).log
    assert (info.n_gaps, info.n_cuts) == (2, 4)
    assert info.n_samples_log == 2 * g.n_samples


def test_a_max_gap_below_the_sample_step_is_refused_in_one_line(panda, log):
    """--max-gap 1 ms on a 200 Hz log ended in 't must have shape (N,) with N >= 2'."""
    with pytest.raises(OptionError, match=r"--max-gap 0\.001 s is below the sample step 0\.005"):
        prepare_recordings(panda, [log], ["a.csv"], max_gap_s=1e-3)
    with pytest.raises(OptionError, match="--max-gap"):
        prepare_pieces(panda, [log], ["a.csv"], max_gap_s=1e-3)


def test_a_sample_isolated_between_two_gaps_is_left_out_with_a_word(panda, log):
    """One sample between two cut-out stretches ended in 't must have shape (N,) with
    N >= 2'; it is left out, counted, and the rest prepared."""
    t = log.t
    keep = ~((t > 2.0) & (t < 3.0))
    keep[500] = True  # t = 2.5 s alone in the cut-out stretch
    g = log.select(np.flatnonzero(keep))
    with pytest.warns(DynidWarning, match=r"g\.csv: 1 sample\(s\) isolated between gaps"):
        rec = prepare_recordings(panda, [g], ["g.csv"], cutoff_hz=10.0)
    assert len(rec.pieces) == 2


def _sines(f_hz, duration=8.0, fs=100.0):
    """Joints moving as sines of the given frequencies [Hz] (exact velocities), 7 joints."""
    t = np.arange(int(duration * fs) + 1) / fs
    f = np.resize(np.asarray(f_hz, dtype=float), 7)
    phase = np.arange(7)
    q = 0.5 * np.sin(2 * np.pi * f * t[:, None] + phase)
    dq = 0.5 * 2 * np.pi * f * np.cos(2 * np.pi * f * t[:, None] + phase)
    return TorqueLog(t, q, dq, np.zeros_like(q))


def test_the_cut_off_of_a_log_cut_into_pieces_is_read_over_its_time_axis():
    """Sines of at most 0.5 Hz over 8 s, four 0.2 s stretches cut out: the cut-off is
    10 x 0.5 Hz up to the whole log's resolution (2 bins of 1/8 s), as for the whole log;
    read piece by piece (1.6 s each) it was 2-4 times that."""
    from dynid.identification.recordings import common_cutoff, split_at_gaps

    g = _sines([0.5, 0.3, 0.2])
    whole = common_cutoff([g])
    keep = ~np.any([(g.t > a) & (g.t < a + 0.2) for a in (1.5, 3.1, 4.7, 6.3)], axis=0)
    pieces = split_at_gaps(g.select(np.flatnonzero(keep)))
    assert len(pieces) == 5
    cut = common_cutoff(pieces, [0] * 5)
    for c in (whole, cut):
        assert 5.0 <= c <= 10 * (0.5 + 2 / 8.0)
    # two recordings of other motions: the median by samples, each read on its own axis
    slow = split_at_gaps(_sines([0.2]).select(np.flatnonzero(keep)))
    both = common_cutoff(pieces + slow + slow, [0] * 5 + [1] * 5 + [2] * 5)
    assert 2.0 <= both <= 10 * (0.2 + 2 / 8.0)


def test_pieces_of_three_samples_leave_no_numpy_warning(panda):
    """A log cut into many pieces, some of three samples: left out with a word, no
    'Mean of empty slice' from the noise estimate of a piece too short for it, and the
    samples recorded counted with them (the pieces used only were counted)."""
    g = _sines([0.5, 0.3])
    keep = np.ones(g.n_samples, bool)
    for a in range(100, 700, 100):
        keep[a : a + 10] = False
        keep[a + 13 : a + 20] = False  # leaves three samples a+10..a+12 alone
    cut = g.select(np.flatnonzero(keep))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.warns(DynidWarning, match="3 samples"):
            rec = prepare_recordings(panda, [cut], ["p.csv"])
    assert len(rec.pieces) == 7
    assert rec.record(0).log.n_samples_log == cut.n_samples  # the pieces left out too


def test_validation_cuts_and_decimates_as_the_model_was_identified(panda, log, tmp_path):
    """--max-gap 0.05 at identification bridges two 30 ms gaps (one piece); validate and
    friction re-cut at the default 20 ms rule (three pieces) and compared every sample.
    The rule is recorded in identification.json and reused, with the decimation, unless
    given: the pieces then hold the samples identification used."""
    from dynid.identification.selection import identify_recordings
    from dynid.identification.structure import Structure
    from dynid.io.model_json import load_model_json, save_model_json

    keep = np.ones(log.n_samples, bool)
    keep[300:306] = keep[800:806] = False  # 35 ms steps
    g = log.select(np.flatnonzero(keep))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, [g], structure=Structure(False, ()), max_gap_s=0.05)
    assert model.info.log.max_gap_s == 0.05 and model.info.recordings[0]["pieces"] == 1
    back = load_model_json(save_model_json(tmp_path / "identification.json", model))
    assert back.info.log.max_gap_s == 0.05
    k = back.info.log.decimate
    assert k > 1
    p = prepare_pieces(back, [g], ["g.csv"])
    every = prepare_pieces(back, [g], ["g.csv"], decimate=1)
    default = prepare_pieces(back, [g], ["g.csv"], max_gap_s=0.02, decimate=1)
    assert len(p.logs) == len(every.logs) == 1 and len(default.logs) == 3
    assert p.n_samples == -(-every.n_samples // k)
    np.testing.assert_array_equal(p.logs[0].t, every.logs[0].t[::k])


def test_a_time_column_in_ms_among_good_recordings_is_named_for_its_time(panda, log, tmp_path):
    """Mixed with a good recording, the ms file was refused as 'velocities 0.001 times
    those of the other recording: other units?'; its time column is now named."""
    from dynid.io.torque_log import save_torque_log
    from dynid.workflows.validate import validate_files

    save_torque_log(tmp_path / "good.csv", log)
    save_torque_log(tmp_path / "ms.csv", TorqueLog(1e3 * log.t, log.q, log.dq, log.tau))
    with pytest.raises(
        DataError, match=r"ms\.csv: .*time column looks like ms.*--units ms\.csv:t=ms"
    ):
        validate_files(_continuous(panda, [0, 6]), [tmp_path / "good.csv", tmp_path / "ms.csv"])


def test_a_recording_in_short_pieces_is_checked_once_and_whole(panda):
    """Pieces of 0.8 s of a Panda log: each piece's own sign check found its torques
    'anti-correlated' with gravity (a hint to flip a right sign); the recording checked
    whole says nothing, and a flipped sign is refused once, naming the file."""
    traj = random_fourier(panda, np.random.default_rng(1))(sample_times(20.0, 100.0))
    g = simulate_measurement(panda, traj, rng=np.random.default_rng(5))
    cut = g.select(np.flatnonzero((g.t % 1.0) <= 0.8))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DynidWarning)
        prepare_recordings(panda, [cut], ["c.csv"], cutoff_hz=10.0)
    assert not any("anti-correlated" in str(w.message) for w in caught)
    flipped = TorqueLog(cut.t, cut.q, cut.dq, -cut.tau)
    with pytest.raises(DataError, match=r"^f\.csv: the measured torques are anti-corr"):
        prepare_recordings(panda, [flipped], ["f.csv"], cutoff_hz=10.0)


def test_positions_only_recordings_are_said_once(panda, log, tmp_path, caplog):
    """Four recordings without velocity columns: four copies of one long warning, one per
    file; now one note (nothing is wrong with such logs), naming the files (the reader's
    own line at -v only)."""
    from dynid.io.torque_log import save_torque_log
    from dynid.workflows.recordings import read_recordings

    paths = [  # written without dq; each its own (a copy is refused)
        save_torque_log(
            tmp_path / f"r{k}.csv", TorqueLog(log.t, log.q, log.dq, log.tau + k, dq_derived=True)
        )
        for k in range(1, 5)
    ]
    with warnings.catch_warnings(record=True) as got, caplog.at_level(NOTE):
        warnings.simplefilter("always", DynidWarning)
        rec = read_recordings(paths, panda)
    assert all(g.dq_derived for g in rec.logs)
    said = [str(w.message) for w in got if "no velocity columns" in str(w.message)]
    said += [r.getMessage() for r in caplog.records if "no velocity columns" in r.getMessage()]
    assert len(said) == 1 and said[0].startswith("r1.csv, r2.csv, r3.csv, r4.csv: "), said
    assert not [w for w in got if "no velocity columns" in str(w.message)]
