"""Scoring detected events against labelled contacts (dynid.observer.scoring): intervals
of a 0/1 series, matching, counts; and ``dynid observe`` on simulated contacts and on a
log with a label column, whose counts equal the contacts simulated."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.exceptions import ShapeError
from dynid.observer.scoring import (
    ContactScore,
    combined,
    interval_peaks,
    label_intervals,
    labels_lead,
    lead_for,
    match_events,
    score_events,
    shifted_labels_note,
    truth_flags,
)


def test_intervals_of_a_series_are_its_runs_with_edges_and_nan():
    """Runs at the first and last sample, a one-sample run, NaN as no contact: the first
    and last sample time of each run."""
    t = np.arange(10) * 0.5
    flags = [1, 1, 0, 0, 1, np.nan, 3, 0, 0, 1]
    np.testing.assert_array_equal(
        label_intervals(t, flags), [[0.0, 0.5], [2.0, 2.0], [3.0, 3.0], [4.5, 4.5]]
    )
    assert label_intervals(t, np.zeros(10)).shape == (0, 2)
    np.testing.assert_array_equal(label_intervals(t, np.ones(10)), [[0.0, 4.5]])
    with pytest.raises(ShapeError, match="both be"):
        label_intervals(t, np.ones(9))


def test_truth_flags_and_peaks_of_true_torques():
    """Some joint over the level is contact; the peak is the largest |tau_ext| over the
    interval's samples and joints."""
    rng = np.random.default_rng(5)
    t = np.arange(8) * 0.1
    ext = np.zeros((8, 2))
    ext[2:5, 1] = [-0.5, -2.0, 0.3]
    ext[6, 0] = 0.05 + 0.01 * rng.random()
    flags = truth_flags(ext, 0.1)
    np.testing.assert_array_equal(flags, [0, 0, 1, 1, 1, 0, 0, 0])
    iv = label_intervals(t, flags)
    np.testing.assert_allclose(interval_peaks(t, ext, iv), [2.0])


def test_matching_a_miss_a_false_alarm_two_events_in_one_contact_one_over_two():
    """Contacts [1, 2], [5, 6], [8, 8.5], [8.6, 9]; events (1.05, 1.3) and (1.5, 2.05) in the
    first (one detection, delay 0.05), one at 3 (a false alarm), none near the second
    (missed), one over the last two (both detected, one delay), one starting 0.08 s
    after a contact's end (within the tolerance of 0.1 s)."""
    labels = np.array([[1.0, 2.0], [5.0, 6.0], [8.0, 8.5], [8.6, 9.0], [10.0, 10.2]])
    events = np.array([[1.05, 1.3], [1.5, 2.05], [3.0, 3.2], [8.02, 8.9], [10.28, 10.4]])
    first, false = match_events(events, labels, 0.1)
    np.testing.assert_array_equal(first, [0, -1, 3, 3, 4])
    np.testing.assert_array_equal(false, [False, False, True, False, False])
    s = score_events(events, labels, (0.0, 12.0), tolerance_s=0.1, peaks=[3, 0.7, 2, 2, 5])
    assert (s.labelled, s.detected, s.false_alarms) == (5, 4, 1)
    assert [(m.start, m.end, m.peak) for m in s.missed] == [(5.0, 6.0, 0.7)]
    np.testing.assert_allclose(s.delays, [0.05, 0.02, 0.28])
    # contact-free: 12 s less [0.98, 2.1], [4.98, 6.1], [7.98, 9.1] (two windows joined),
    # [9.98, 10.3]: the lead of 0.02 s before each contact, the tolerance after
    assert s.contact_free_s == pytest.approx(12.0 - 1.12 - 1.12 - 1.12 - 0.32)
    assert s.false_alarms_per_min == pytest.approx(60.0 / s.contact_free_s)
    assert s.delay_median == pytest.approx(0.05) and s.delay_max == pytest.approx(0.28)
    tight = score_events(events, labels, (0.0, 12.0), tolerance_s=0.05)
    # the late event a false alarm; 0.1 s apart, the last two contacts are two groups:
    # the event open over both detects the one it starts in, the other is missed
    assert (tight.detected, tight.false_alarms) == (2, 2)


def test_an_event_starting_long_before_a_contact_or_open_over_several_detects_nothing():
    """A whole-log event (0 to 15 s over contacts at 3, 7 and 11 s): a false alarm, all
    three missed, no delay; an event starting 0.01 s before a contact (within the lead of
    0.02 s) detects it with a delay of -10 ms, one starting 0.05 s before does not; an
    event from inside the first contact still open over the second detects the first only
    (the second has no onset of its own), and is no false alarm."""
    labels = np.array([[3.0, 3.3], [7.0, 7.5], [11.0, 11.2]])
    whole = score_events([[0.0, 15.0]], labels, (0.0, 15.0))
    assert (whole.labelled, whole.detected, whole.false_alarms) == (3, 0, 1)
    assert len(whole.missed) == 3 and whole.delays == () and whole.delay_median is None
    near = score_events([[2.99, 3.2], [6.95, 7.4]], labels, (0.0, 15.0), lead_s=0.02)
    assert (near.detected, near.false_alarms) == (1, 1)
    np.testing.assert_allclose(near.delays, [-0.01])
    first, false = match_events([[3.05, 7.2]], labels, 0.1, 0.02)
    np.testing.assert_array_equal(first, [0, -1, -1])
    np.testing.assert_array_equal(false, [False])
    later = score_events([[0.0, 15.0], [7.05, 7.3]], labels, (0.0, 15.0))
    assert (later.detected, later.false_alarms) == (1, 1) and later.delays == pytest.approx((0.05,))


def test_no_labels_every_event_false_and_totals_pool_logs():
    """Without contacts every event is a false alarm over the whole span; the total adds
    counts and times and pools delays."""
    a = score_events([[1.0, 1.1]], np.zeros((0, 2)), (0.0, 30.0), source="x")
    assert (a.labelled, a.detected, a.false_alarms, a.contact_free_s) == (0, 0, 1, 30.0)
    assert a.delay_median is None and a.false_alarms_per_min == pytest.approx(2.0)
    b = ContactScore("x", 0.1, 2, 1, (), 0, 10.0, (0.04,))
    total = combined([a, b])
    assert (total.labelled, total.detected, total.false_alarms) == (2, 1, 1)
    assert total.contact_free_s == 40.0 and total.delays == (0.04,)
    with pytest.raises(ValueError, match="no score"):
        combined([])
    with pytest.raises(ShapeError, match="peaks"):
        score_events([], [[0.0, 1.0]], (0.0, 2.0), peaks=[1.0, 2.0])


@pytest.fixture(scope="module")
def pushes(tmp_path_factory):
    """Thresholds from a free 3 s Panda log, and a 4 s log with three pushes at 0.8-1.1,
    1.9-2.3 and 3.0-3.2 s (tau_ext written beside it)."""
    d = tmp_path_factory.mktemp("scoring")
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "-q"]
    assert main([*sim, "--duration", "3", "--seed", "2", "--out", str(d / "free.csv")]) == 0
    hit = [
        "--contact", "link6:0,0,-15:0.8,1.1", "--contact", "flange:10,0,0:1.9,2.3",
        "--contact", "link4:0,0,-20:3,3.2",
    ]  # fmt: skip
    assert main([*sim, "--duration", "4", "--seed", "3", *hit, "--out", str(d / "hit.csv")]) == 0
    p = ["observe", "--params", "panda", "--no-figures", "-q"]
    assert main([*p, "--data", str(d / "free.csv"), "--calibrate", "--out", str(d / "cal")]) == 0
    return d


def _with_column(src, dst, name, values):
    """``src`` (a dynid CSV log) with one more column ``name`` holding ``values``."""
    lines = src.read_text().splitlines()
    head, rows = lines[:3], lines[3:]
    head[2] += f",{name}"
    dst.write_text("\n".join(head + [f"{r},{v:g}" for r, v in zip(rows, values, strict=True)]))


def test_observe_scores_a_simulated_log_against_its_true_torques(pushes, capsys):
    """dynid observe on the log of three simulated pushes: 3 labelled (tau_ext > 0.1 N m),
    3 detected, none missed, no false alarm, each within 25 ms (K_O = 50/s: a 20 ms time
    constant) of the push; the summary, events.json and the report say so."""
    d = pushes
    p = ["observe", "--params", "panda", "--no-figures"]
    th = ["--thresholds", str(d / "cal" / "thresholds.json")]
    assert main([*p, *th, "--data", str(d / "hit.csv"), "--out", str(d / "sim")]) == 0
    out = capsys.readouterr().out
    assert "3 labelled, 3 detected, 0 missed; 0 false alarm(s)" in out
    score = json.loads((d / "sim" / "events.json").read_text())["score"]
    assert (score["labelled"], score["detected"], score["missed"]) == (3, 3, 0)
    assert score["false_alarms"] == 0 and score["source"] == "tau_ext > 0.1 N m"
    assert 0.0 <= score["delay_median_ms"] <= score["delay_max_ms"] <= 25.0
    (log,) = score["logs"]
    starts = [a for a, _ in log["contacts"]]
    np.testing.assert_allclose(starts, [0.8, 1.9, 3.0], atol=2e-3)
    report = (d / "sim" / "report.html").read_text()
    assert "3 labelled, 3 detected, 0 missed; 0 false alarm(s)" in report
    assert log["contact_free_s"] == pytest.approx(
        4.0 - sum(b + 0.1 - a + log["lead_s"] for a, b in log["contacts"])
    )


@pytest.mark.parametrize("mapped", [False, True])
def test_observe_scores_against_a_label_column_by_default_name_or_mapped(pushes, capsys, mapped):
    """A 0/1 column labelling the first push and a contact that never happened
    (3.5-3.7 s), the second and third unlabelled: 2 labelled, 1 detected, the made-up
    one missed (its times, no peak), 2 false alarms; read as ``collision`` or through
    ``--columns label=touch``; the figure hatches the labels."""
    from dynid.io.torque_log import load_torque_log

    d = pushes
    t = load_torque_log(d / "hit.csv").t
    flags = ((t >= 0.8) & (t <= 1.1)) | ((t >= 3.5) & (t <= 3.7))
    name = "touch" if mapped else "collision"
    _with_column(d / "hit.csv", d / f"{name}.csv", name, flags.astype(float))
    args = ["--columns", f"label={name}"] if mapped else []
    th = ["--thresholds", str(d / "cal" / "thresholds.json")]
    out_dir = d / f"lab_{name}"
    cmd = ["observe", "--params", "panda", *th, *args, "--data", str(d / f"{name}.csv")]
    assert main([*cmd, "--out", str(out_dir)]) == 0
    out = capsys.readouterr().out
    assert "2 labelled, 1 detected, 1 missed; 2 false alarm(s)" in out
    assert "missed in" in out and "3.500 s .. 3.700 s" in out
    score = json.loads((out_dir / "events.json").read_text())["score"]
    assert score["source"] == f"column {name!r}"
    # the invented contact: no push in the true torques, read through a column map too
    # (one naming no tau_ext reads dynid's tau_ext1..n; before, a map left them unread)
    peak = 0.0
    (miss,) = score["missed_contacts"]
    assert {k: miss[k] for k in ("start", "end", "peak")} == {
        "start": 3.5,
        "end": 3.7,
        "peak": peak,
    }
    assert (out_dir / "residuals.png").stat().st_size > 0


def test_a_whole_log_event_of_an_offset_torque_is_scored_a_false_alarm(pushes, capsys):
    """The three pushes labelled, joint 2's torque offset by 10 N m (a sensor offset the
    model lacks): one event over the whole log, scored 0 detected, 3 missed, 1 false alarm
    and no delay, in the summary and in events.json (not 3 detected with a delay of
    -0.8 s)."""
    from dynid.io.torque_log import load_torque_log

    d = pushes
    t = load_torque_log(d / "hit.csv").t
    flags = ((t >= 0.8) & (t <= 1.1)) | ((t >= 1.9) & (t <= 2.3)) | ((t >= 3.0) & (t <= 3.2))
    _with_column(d / "hit.csv", d / "lab.csv", "collision", flags.astype(float))
    lines = (d / "lab.csv").read_text().splitlines()
    col = lines[2].split(",").index("tau2")
    rows = [r.split(",") for r in lines[3:]]
    for r in rows:
        r[col] = f"{float(r[col]) + 10.0:.17g}"
    (d / "offset.csv").write_text("\n".join(lines[:3] + [",".join(r) for r in rows]))
    th = ["--thresholds", str(d / "cal" / "thresholds.json")]
    cmd = ["observe", "--params", "panda", "--no-figures", *th, "--data", str(d / "offset.csv")]
    assert main([*cmd, "--out", str(d / "offset")]) == 0
    out = capsys.readouterr().out
    assert "1 event(s)" in out
    assert "3 labelled, 0 detected, 3 missed; 1 false alarm(s)" in out
    assert "delay" not in out.split("scored against")[1]
    score = json.loads((d / "offset" / "events.json").read_text())["score"]
    assert (score["detected"], score["missed"], score["false_alarms"]) == (0, 3, 1)
    assert score["delay_median_ms"] is None and score["delay_max_ms"] is None


def test_a_log_without_labels_is_not_scored(pushes, capsys):
    """A free simulated log (no tau_ext, no label column): no score printed nor written."""
    d = pushes
    p = ["observe", "--params", "panda", "--no-figures"]
    th = ["--thresholds", str(d / "cal" / "thresholds.json")]
    assert main([*p, *th, "--data", str(d / "free.csv"), "--out", str(d / "free")]) == 0
    assert "scored against" not in capsys.readouterr().out
    assert "score" not in json.loads((d / "free" / "events.json").read_text())


def test_a_mapped_label_the_log_lacks_and_a_label_unit_are_refused(pushes, capsys):
    """--columns label=NAME without that column names it; --units label=... is refused."""
    d = pushes
    p = ["observe", "--params", "panda", "--no-figures", "--thresholds"]
    p += [str(d / "cal" / "thresholds.json"), "--data", str(d / "hit.csv")]
    assert main([*p, "--columns", "label=bump", "--out", str(d / "x")]) != 0
    assert "no column 'bump' for 'label'" in capsys.readouterr().err
    assert main([*p, "--units", "label=s", "--out", str(d / "y")]) != 0
    assert "a label column has no unit" in capsys.readouterr().err


def test_labels_follow_the_log_past_rows_dropped_and_a_column_not_numbers(pushes, capsys):
    """Rows dropped for NaN (--drop-invalid): the labels matched by time give the same
    score; a ``label`` column of text is warned about and the true torques score
    instead."""
    from dynid.io.torque_log import load_torque_log

    d = pushes
    t = load_torque_log(d / "hit.csv").t
    flags = ((t >= 0.8) & (t <= 1.1)) | ((t >= 3.5) & (t <= 3.7))
    _with_column(d / "hit.csv", d / "holes.csv", "contact", flags.astype(float))
    _nan_tau1(d / "holes.csv", d / "holes.csv")
    p = ["observe", "--params", "panda", "--no-figures", "--drop-invalid", "--thresholds"]
    p += [str(d / "cal" / "thresholds.json")]
    assert main([*p, "--data", str(d / "holes.csv"), "--out", str(d / "holes")]) == 0
    assert "2 labelled, 1 detected, 1 missed; 2 false alarm(s)" in capsys.readouterr().out
    _with_column(d / "hit.csv", d / "text.csv", "label", np.zeros(t.size))
    (d / "text.csv").write_text((d / "text.csv").read_text().replace(",0\n", ",no\n"))
    assert main([*p, "--data", str(d / "text.csv"), "--out", str(d / "text")]) == 0
    captured = capsys.readouterr()
    assert "column 'label' read as no contact labels" in captured.err
    assert "(tau_ext > 0.1 N m;" in captured.out and "3 labelled, 3 detected" in captured.out


def _nan_tau1(src, dst):
    """``src`` written to ``dst`` with tau1 NaN in the rows at 0.497 and 2.697 s (outside
    the pushes)."""
    lines = src.read_text().splitlines()
    for k in (500, 2700):
        cells = lines[k].split(",")
        cells[15] = "nan"
        lines[k] = ",".join(cells)
    dst.write_text("\n".join(lines))


def test_true_torques_follow_the_log_past_rows_dropped(pushes, capsys):
    """Rows dropped for NaN (--drop-invalid) in a log scored by its true torques: tau_ext
    realigned with the rows kept by time, so the score and RMS r - tau_ext stay (they
    vanished silently when the row counts differed)."""
    from dynid.io.columns import load_joint_columns
    from dynid.io.torque_log import load_torque_log

    d = pushes
    _nan_tau1(d / "hit.csv", d / "nan.csv")
    p = ["observe", "--params", "panda", "--no-figures", "--drop-invalid", "--thresholds"]
    p += [str(d / "cal" / "thresholds.json")]
    assert main([*p, "--data", str(d / "nan.csv"), "--out", str(d / "nan")]) == 0
    out = capsys.readouterr().out
    assert "3 labelled, 3 detected, 0 missed; 0 false alarm(s)" in out
    assert "RMS r - tau_ext" in out
    score = json.loads((d / "nan" / "events.json").read_text())["score"]
    assert (score["labelled"], score["detected"]) == (3, 3)
    from dynid.workflows.observe_detect import _stored_rows

    t = load_torque_log(d / "hit.csv").t
    kept = np.delete(t, [497, 2697])  # the header's three lines before row 0
    rows = _stored_rows(t, kept)
    ext = load_joint_columns(d / "hit.csv", "tau_ext", 7)
    assert rows is not None
    np.testing.assert_array_equal(ext[rows], np.delete(ext, [497, 2697], axis=0))
    assert _stored_rows(t, kept + 1e-4) is None


def test_missed_labelled_contacts_carry_the_true_torques_peak_where_it_is_known():
    """Regression (a label column beside simulate --contact's true torques gave missed
    contacts a peak of null; a log with labelled contacts and no event failed on an empty
    argmin): with both, the contacts are the labels' and a missed one's peak is the largest
    true |tau_ext| over it; with the labels alone it is not known."""
    from dynid.workflows.observe_detect import Labels, scored

    t = np.arange(0.0, 4.0, 0.01)
    flags = ((t >= 1.0) & (t < 1.5)).astype(float)
    ext = np.zeros((t.size, 2))
    ext[(t >= 1.0) & (t < 1.5), 1] = 0.7
    with_truth = scored(t, [], Labels("column 'collision'", flags), ext)
    alone = scored(t, [], Labels("column 'collision'", flags), None)
    assert with_truth is not None and alone is not None
    assert [m.peak for m in with_truth.missed] == [0.7]
    assert [m.peak for m in alone.missed] == [None]


def test_a_push_shorter_than_the_minimum_duration_is_named_as_a_dropped_crossing(pushes, capsys):
    """Regression (max |r|/contact 1.93 on a joint and no event, with nothing saying why):
    a simulated 12 ms push of 25 N with --min-duration 0.05 is no event and the one
    labelled contact of the true torques is missed, while the summary, events.json and
    the report name the crossing the minimum duration dropped (not a contact) at the
    push, on the joint of the largest true torque, with its sign, under it (the lag), over
    its threshold and shorter than 0.05 s; with the default 0.01 s it is an event and
    nothing is dropped."""
    from dynid.io.columns import load_joint_columns

    d = pushes
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "-q", "--duration", "3"]
    push = ["--contact", "link6:0,0,-25:1.0,1.012"]
    assert main([*sim, "--seed", "3", *push, "--out", str(d / "short.csv")]) == 0
    ext = load_joint_columns(d / "short.csv", "tau_ext", 7)
    assert ext is not None
    j = int(np.argmax(np.abs(ext).max(axis=0)))  # the joint the push loads most
    p = ["observe", "--params", "panda", "--no-figures", "--data", str(d / "short.csv")]
    p += ["--thresholds", str(d / "cal" / "thresholds.json")]
    assert main([*p, "--min-duration", "0.05", "--out", str(d / "short")]) == 0
    out = capsys.readouterr().out
    doc = json.loads((d / "short" / "events.json").read_text())
    assert doc["events"] == [] and doc["score"]["missed"] == 1
    (miss,) = doc["score"]["missed_contacts"]
    drop = doc["dropped"]
    assert (drop["count"], drop["min_duration_s"]) == (1, 0.05)
    (c,) = drop["crossings"]
    assert miss["start"] <= c["start"] <= miss["end"] + 0.02 and c["duration_s"] < 0.05
    assert j + 1 in c["joints"] and c["ratio"][j] > 1.0
    true_peak = ext[np.argmax(np.abs(ext[:, j])), j]
    assert np.sign(c["peak"][j]) == np.sign(true_peak) and abs(c["peak"][j]) < abs(true_peak)
    top = c["joint"]
    assert c["ratio"][top - 1] == max(c["ratio"])
    assert "1 crossing(s) over the contact threshold dropped as shorter than --min-duration" in out
    assert f"= {c['ratio'][top - 1]:.3g} x contact" in out and "< 50 ms" in out
    report = (d / "short" / "report.html").read_text()
    assert "No event, but 1 crossing(s)" in report and "not contacts" in report
    assert '<span class="level">no event</span>' in report
    assert "every residual stayed below" not in report
    assert main([*p, "--out", str(d / "short_default")]) == 0
    doc = json.loads((d / "short_default" / "events.json").read_text())
    assert len(doc["events"]) == 1 and doc["dropped"]["count"] == 0
    assert doc["score"]["detected"] == 1 and "dropped as shorter" not in capsys.readouterr().out


def test_a_one_sample_crossing_is_said_to_last_one_sample():
    """dropped_words: a crossing of one sample (start == end) reads "one sample", not a
    span from a time to itself of 0 ms."""
    from dynid.observer.results import dropped_words

    said = dropped_words(2.01, 2.01, "joint4", -0.7, 1.26, "isolated", 0.05)
    assert said.startswith("2.010 s, joint4") and "one sample < 50 ms" in said
    assert " 0 ms" not in said and ".." not in said


def test_delays_of_look_ahead_velocities_carry_their_caveat_in_the_score_line():
    """A score whose velocities came from a zero-phase low-pass says so right after its
    delays, pooled over logs when any one of them did; a score without says nothing."""
    from dynid.observer.scoring import LOOK_AHEAD_WORDS, combined, score_words

    ev, lab = [[1.02, 1.4]], [[1.0, 1.3]]
    ahead = score_events(ev, lab, (0.0, 5.0), look_ahead=True)
    plain = score_events(ev, lab, (0.0, 5.0))
    assert score_words(ahead).endswith(f"delay median 20 ms, max 20 ms ({LOOK_AHEAD_WORDS})")
    assert score_words(plain).endswith("delay median 20 ms, max 20 ms")
    assert combined([plain, ahead]).look_ahead and not combined([plain, plain]).look_ahead
    none = score_events(np.zeros((0, 2)), lab, (0.0, 5.0), look_ahead=True)
    assert LOOK_AHEAD_WORDS not in score_words(none)  # no delay to qualify


def test_hand_labels_late_by_60_ms_count_with_the_default_tolerance_and_are_noted_without(
    pushes, capsys
):
    """Labels 60 ms late (each true contact from simulated tau_ext, shifted): with the
    default --label-tolerance 0.1 s, which a label column applies before its start too,
    3 labelled, 3 detected, no false alarm; with --label-tolerance 0.03 s the three events
    start before their labels: 3 missed, 3 false alarms, each marked false_alarm in
    events.json and the report, and a note says the labels look late by ~60 ms. Scored
    against the true torques the lead stays 0.02 s."""
    d = pushes
    p = ["observe", "--params", "panda", "--no-figures"]
    th = ["--thresholds", str(d / "cal" / "thresholds.json")]
    assert main([*p, *th, "--data", str(d / "hit.csv"), "--out", str(d / "truth")]) == 0
    capsys.readouterr()
    truth = json.loads((d / "truth" / "events.json").read_text())["score"]
    assert truth["lead_s"] == pytest.approx(0.02)
    contacts = np.array(truth["logs"][0]["contacts"])
    t = np.loadtxt(d / "hit.csv", delimiter=",", comments="#", skiprows=3)[:, 0]
    late = np.zeros(t.shape)
    for a, b in contacts:
        late[(t >= a + 0.06) & (t <= b + 0.06)] = 1.0
    _with_column(d / "hit.csv", d / "late.csv", "collision", late)
    data = ["--data", str(d / "late.csv")]
    assert main([*p, *th, *data, "--out", str(d / "late")]) == 0
    out = capsys.readouterr()
    assert "3 labelled, 3 detected, 0 missed; 0 false alarm(s)" in out.out
    assert "from 0.1 s before a contact's start" in out.out
    doc = json.loads((d / "late" / "events.json").read_text())
    assert [e["false_alarm"] for e in doc["events"]] == [False] * 3
    assert main([*p, *th, *data, "--label-tolerance", "0.03", "--out", str(d / "tight")]) == 0
    out = capsys.readouterr()
    assert "3 labelled, 0 detected, 3 missed; 3 false alarm(s)" in out.out
    (note,) = [x for x in out.err.splitlines() if "look shifted late" in x]
    lead = float(re.search(r"late by ~(\d+) ms", note).group(1))
    assert 40.0 <= lead <= 60.0  # 60 ms less each event's delay after the true start
    doc = json.loads((d / "tight" / "events.json").read_text())
    assert [e["false_alarm"] for e in doc["events"]] == [True] * 3
    (log,) = doc["score"]["logs"]
    assert [e["start"] for e in log["false_alarm_events"]] == [e["start"] for e in doc["events"]]
    page = re.sub(r"<[^>]+>", " ", (d / "tight" / "report.html").read_text())
    assert page.count("false alarm ") >= 3


def test_a_wrench_at_the_flange_that_leaves_a_link4_push_unexplained_is_warned(pushes, capsys):
    """--frame flange on pushes at link6, the flange and link4: the flange push leaves
    under 2 % of |r| unexplained by the wrench there (events.json) and is not named; the
    link4 push (at link4's origin, on joint 4's axis: joints 4-6 feel nothing of it,
    which a wrench at the flange would load) is warned, and so is the link6 push (at
    link6's origin, where joints 5 and 6's axes meet), named with joint 4, the last
    joint over its noise in them, and a --frame hint."""
    d = pushes
    p = ["observe", "--params", "panda", "--no-figures", "--frame", "flange"]
    th = ["--thresholds", str(d / "cal" / "thresholds.json")]
    assert main([*p, *th, "--data", str(d / "hit.csv"), "--out", str(d / "flange")]) == 0
    err = capsys.readouterr().err
    doc = json.loads((d / "flange" / "events.json").read_text())
    flange = next(e for e in doc["events"] if 1.85 < e["start"] < 2.0)
    elbow = next(e for e in doc["events"] if 2.95 < e["start"] < 3.1)
    assert flange["unexplained_share"] < 0.02
    (warned,) = [x for x in err.splitlines() if "does not fit" in x]
    link6 = next(e for e in doc["events"] if 0.75 < e["start"] < 0.9)
    assert f"{elbow['start']:.3f} s" in warned and f"{link6['start']:.3f} s" in warned
    assert f"{flange['start']:.3f} s" not in warned
    assert "likely on a link before flange" in warned and "try --frame link4" in warned
    assert "joint4, so on link4" in warned


def test_a_label_columns_lead_is_its_tolerance_and_late_labels_are_said():
    """lead_for: 0.02 s at 1 kHz, 3 samples at 100 Hz, the tolerance where given (a label
    column, both sides). Events at 1.00 and 2.00 s against labels 80 ms late: with the
    exact lead both are false alarms that run into a missed label, 80 ms early each (the
    note says ~80 ms and a tolerance of 0.1 s), false_events naming both; with a 0.1 s
    lead both detect."""
    t = np.arange(0.0, 5.0, 0.001)
    assert lead_for(t) == pytest.approx(0.02)
    assert lead_for(np.arange(0.0, 5.0, 0.01)) == pytest.approx(0.03)
    assert lead_for(t, 0.1) == pytest.approx(0.1)
    ev = [[1.0, 1.3], [2.0, 2.2], [4.0, 4.1]]
    lab = [[1.08, 1.3], [2.08, 2.2]]
    sc = score_events(ev, lab, (0.0, 5.0), lead_s=0.02)
    assert (sc.detected, sc.false_alarms, sc.false_events) == (0, 3, (0, 1, 2))
    np.testing.assert_allclose(sc.early, [0.08, 0.08])
    note = shifted_labels_note(sc)
    assert note is not None and "~80 ms" in note and "--label-tolerance 0.1 " in note
    wide = score_events(ev, lab, (0.0, 5.0), lead_s=0.1)
    assert (wide.detected, wide.false_events, wide.early) == (2, (2,), ())
    assert shifted_labels_note(wide) is None


def test_detections_that_lead_late_labels_get_the_note_with_the_median_lead():
    """Regression (a UR5's labels 21-58 ms late: every event started before its label,
    delay median -16 ms, said without a word): contacts at 1, 3, 5 and 7 s detected 10,
    20, 30 ms after their true onsets, labelled 40, 50, 60 ms late (leads 30 ms each)
    and a fourth 10 ms after its label: the note gives the median lead, 30 ms."""
    onsets = np.array([1.0, 3.0, 5.0, 7.0])
    late = np.array([0.04, 0.05, 0.06, 0.0])
    starts = onsets + np.array([0.01, 0.02, 0.03, 0.01])
    labels = np.column_stack([onsets + late, onsets + late + 0.3])
    sc = score_events(np.column_stack([starts, starts + 0.2]), labels, (0.0, 9.0), lead_s=0.1)
    np.testing.assert_allclose(sorted(sc.delays), [-0.03, -0.03, -0.03, 0.01], atol=1e-12)
    count, lead = labels_lead(sc)
    assert count == 3 and lead == pytest.approx(0.03)
    note = shifted_labels_note(sc)
    assert note is not None and "3 of 4 detected contacts' events start before" in note
    assert "labels look late by about 30 ms" in note


def test_a_few_events_before_their_labels_are_no_sign_of_late_labels():
    """Two of four events starting before their labels (exact labels, velocities that
    see ahead) are no majority: no note."""
    labels = np.array([[1.0, 1.3], [3.0, 3.3], [5.0, 5.3], [7.0, 7.3]])
    starts = np.array([0.99, 2.99, 5.02, 7.03])
    sc = score_events(np.column_stack([starts, starts + 0.2]), labels, (0.0, 9.0), lead_s=0.1)
    assert labels_lead(sc) is None and shifted_labels_note(sc) is None
