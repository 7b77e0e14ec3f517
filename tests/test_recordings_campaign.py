"""Several recordings and bad inputs on every command that reads them, as a new user
meets them: each case ends in one line naming the file (or is handled with a note), never a
dropped recording nor a traceback; each warning is printed once.

References: simulated Panda logs (the torques of the robot's own model plus sensor noise)
rewritten the way real files go wrong (empty, header only, NaN rows, duplicated or
decreasing stamps, extra columns, another joint count, another unit, torques of another
sign), and the closed-form relative error of a prediction of zero (100 %).
"""

from __future__ import annotations

import json
import logging
import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError, DynidWarning
from dynid.feasibility.convex import fit as convex_fit
from dynid.identification.verdict import judge_prediction
from dynid.io.torque_log import load_torque_log, save_torque_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows import identify as identify_module
from dynid.workflows.data_files import data_files
from dynid.workflows.identify import IdentifyOptions, identify_files
from dynid.workflows.observe import ObserveOptions, observe_files
from dynid.workflows.validate import validate_files

NOISE = 0.05  # N m, the simulated torque sensor noise (SensorNoise's default)


def _log(robot, seed, duration=5.0, rate=200.0):
    traj = random_fourier(robot, np.random.default_rng(seed))(sample_times(duration, rate))
    return simulate_measurement(robot, traj, rng=np.random.default_rng(seed + 100))


@pytest.fixture(scope="module")
def panda():
    return dynid.panda()


class _Stop(Exception):
    """Raised in place of the convex solve: the unconstrained fit is what is judged."""


def test_the_consistent_route_warns_each_finding_of_the_data_once(panda, tmp_path, monkeypatch):
    """Torques in mN m read as N m (said with --units tau=Nm: not refused): the consistent
    route's unconstrained fit (structure chosen on held-out data and fitted as chosen)
    prepares the log once, so its finding is warned once (it was warned by the selection's
    fit and again by the final one), and the friction warnings are those of the model
    kept."""
    log = _log(panda, 3)
    save_torque_log(tmp_path / "neg.csv", type(log)(log.t, log.q, log.dq, 1e3 * log.tau))
    kept = {}

    def stop(robot, model, *args, **kw):
        kept["model"] = model
        raise _Stop

    monkeypatch.setattr(convex_fit, "consistent_from_identified", stop)
    monkeypatch.setattr(identify_module, "consistent_from_identified", stop)  # where called
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(_Stop):
            opt = IdentifyOptions(consistent=True, columns=(None, "tau=Nm"))
            identify_files(panda, [tmp_path / "neg.csv"], opt)
    said = [str(w.message) for w in caught if issubclass(w.category, DynidWarning)]
    assert sum("times the model's gravity torques" in s for s in said) == 1
    assert len(said) == len(set(said)), said
    model = kept["model"]
    assert model.info.selection is not None  # the structure was chosen, and recorded
    terms = model.info.extra["terms"]  # the structure chosen, fitted as it was chosen
    name = " + ".join(["links", *(t for t in terms if t[:1] != "-")])
    assert model.info.selection["chosen"] == name + "".join(
        f" - {t[1:]}" for t in terms if t[:1] == "-"
    )
    # the friction warnings are of the model kept: one per joint whose kept friction
    # has a negative viscous or Coulomb coefficient (the selection's fit warned its own)
    quoted = [s for s in said if s.startswith("identified friction not dissipative")]
    named = sorted(int(s.split("(joint ")[1].split(":")[0]) for s in quoted)
    if model.friction is None:  # no friction candidate was dissipative: none kept, none warned
        assert not named
        return
    negative = np.flatnonzero(np.any(model.friction.params[:, :2] < 0, axis=1)) + 1
    assert set(named) <= set(negative.tolist()) and len(named) == len(set(named))
    # (a negative coefficient within its standard deviation of dissipative friction is not
    # warned: a smooth Coulomb of 662 N m beside fv5 = -256 N m s/rad at 2.61 rad/s)


# --- validate: a verdict a person can act on, and its exit status ----------------------


@pytest.mark.parametrize(
    "error, floor, opposite, level, label",
    [
        (0.44, 0.33, False, "good", "at the noise floor"),  # 1.33 x the floor
        (1.2, 0.3, False, "fair", "usable"),  # 4 x the floor, but 1.2 %: usable
        (20.0, 6.0, False, "poor", "poor"),  # 3.33 x the floor and above 15 %
        (16.0, 6.0, False, "fair", "usable"),  # 2.67 x the floor, though above 15 %
        (4.0, None, False, "good", "good"),  # no floor: below 5 %
        (10.0, None, False, "fair", "usable"),
        (49.0, None, False, "poor", "poor"),
        (50.0, 0.5, False, "unusable", "unusable"),
        (136.0, 0.4, False, "unusable", "unusable"),
        (0.5, 0.4, True, "unusable", "unusable"),  # the opposite sign, whatever the error
    ],
)
def test_the_verdict_levels(error, floor, opposite, level, label):
    """The four levels at the thresholds the module documents (1.5 and 3 x the noise
    floor; 5, 15 and 50 %; the opposite sign)."""
    v = judge_prediction(error, floor, opposite_sign=opposite)
    assert (v.level, v.label) == (level, label)
    assert v.unusable == (level == "unusable")
    if floor:
        assert v.ratio == pytest.approx(error / floor)


@pytest.fixture(scope="module")
def logs(panda, tmp_path_factory):
    """Two recordings of the Panda (its own model and friction, sensor noise 0.05 N m)."""
    d = tmp_path_factory.mktemp("campaign")
    for s in (1, 2):
        save_torque_log(d / f"rec{s}.csv", _log(panda, s))
    return d


@pytest.fixture(scope="module")
def rec1_model(logs, tmp_path_factory):
    """The folder of identify's model of rec1.csv (the tests that judge other recordings
    with it share one identification)."""
    model = tmp_path_factory.mktemp("model")
    argv = ["identify", "--robot", "panda", "--no-figures", "--out", str(model), "--data"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*argv, str(logs / "rec1.csv")]) == 0
    return model


def test_validate_of_the_true_robot_is_at_the_noise_floor(panda, logs):
    """The robot that made the logs: at the noise floor, and the noise read from the
    measured torques is the simulated sensor's (0.05 N m); the ratio, weighed sample by
    sample against a noise the states' part makes vary, is within 5 % of error over floor."""
    res = validate_files(panda, [logs / "rec1.csv", logs / "rec2.csv"])
    np.testing.assert_allclose(res.noise_rms, NOISE, rtol=0.1)
    assert res.verdict.level == "good" and res.verdict.label == "at the noise floor"
    assert res.verdict.ratio == pytest.approx(
        res.validation.errors.relative_error_percent / res.noise_floor_percent, rel=0.05
    )
    meta = res.metadata()
    assert meta["verdict"]["level"] == "good" and meta["noise_floor_percent"] > 0


def _swapped(src, dst, other):
    """``src``'s positions and velocities with the torques of ``other``: a log the model
    cannot explain (another arm's torques, recorded over another motion)."""
    a, b = load_torque_log(src), load_torque_log(other)
    k = min(a.n_samples, b.n_samples)
    save_torque_log(dst, type(a)(a.t[:k], a.q[:k], a.dq[:k], b.tau[:k][:, ::-1]))
    return dst


def test_validate_of_a_log_the_model_cannot_explain_says_so_and_exits_1(
    panda, logs, tmp_path, capsys
):
    """Torques the model does not explain at all (another arm's; or of the opposite sign):
    the verdict says 'unusable' and why, the files are written, the exit status is 1 (it
    was 0 with no verdict); beside a good recording the bad one is named."""
    bad = _swapped(logs / "rec1.csv", tmp_path / "other_arm.csv", logs / "rec2.csv")
    log = load_torque_log(logs / "rec2.csv")
    save_torque_log(tmp_path / "neg.csv", type(log)(log.t, log.q, log.dq, -log.tau))
    for data, why in (
        ([bad], "does not explain the torques"),
        ([tmp_path / "neg.csv"], "anti-correlated"),
        ([logs / "rec1.csv", bad], "other_arm.csv: "),
    ):
        out = tmp_path / f"v{len(data)}{data[-1].stem}"
        argv = ["validate", "--robot", "panda", "--no-figures", "--out", str(out), "--data"]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DynidWarning)
            code = main([*argv, *map(str, data)])
        said = capsys.readouterr().out.splitlines()
        assert code == 1
        assert said[-1] == f"report: {out / 'report.html'}"  # the page, after the verdict
        assert said[-2].startswith("verdict: unusable: ") and why in said[-2], said[-2]
        doc = json.loads((out / "validation.json").read_text())
        assert doc["verdict"]["level"] == "unusable"
    argv = ["validate", "--robot", "panda", "--no-figures", "--out", str(tmp_path / "ok")]
    assert main([*argv, "--data", str(logs / "rec1.csv")]) == 0
    assert capsys.readouterr().out.splitlines()[-2].startswith("verdict: at the noise floor: ")


def test_validate_refuses_another_joint_count_in_one_line_naming_the_file(
    panda, logs, tmp_path, capsys
):
    """A six-joint log for the seven-joint Panda, alone or beside a good one: exit 2, one
    line on stderr naming the file, no output folder."""
    log = load_torque_log(logs / "rec2.csv")
    six = type(log)(log.t, log.q[:, :6], log.dq[:, :6], log.tau[:, :6])
    save_torque_log(tmp_path / "six.csv", six)
    for data in ([tmp_path / "six.csv"], [logs / "rec1.csv", tmp_path / "six.csv"]):
        out = tmp_path / "v"
        argv = ["validate", "--robot", "panda", "--out", str(out), "--data", *map(str, data)]
        assert main(argv) == 2
        err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
        assert len(err) == 1 and "six.csv: the log has 6 joints; " in err[0], err
        assert not out.exists()


def test_a_chain_with_a_joint_below_the_logs_is_told_to_start_later(panda, logs, tmp_path):
    """Regression: a log of an arm read with a chain that holds one more joint below it
    (a torso lift under a TIAGo arm) was told to end the chain earlier (--tip), which
    misreads every joint. The Panda's joints 2..7 as a 6-joint log against the chain of
    joints 2..7 and against joints 1..6: the hint says --base panda_link1 first, the
    share of positions within each cut's limits beside it; the log of joints 1..6 is told
    --tip link6 first."""
    from dynid.workflows.data_files import read_torque_log

    log = load_torque_log(logs / "rec2.csv")
    for cols, first, second in (
        (slice(1, 7), "--base link1", "--tip link6"),
        (slice(0, 6), "--tip link6", "--base link1"),
    ):
        six = type(log)(log.t, log.q[:, cols], log.dq[:, cols], log.tau[:, cols])
        path = save_torque_log(tmp_path / "six.csv", six)
        with pytest.raises(DataError) as err:
            read_torque_log(path, 7, robot=panda)
        said = str(err.value)
        assert first in said and second in said, said
        assert said.index(first) < said.index(second), said
        shares = [float(x) for x in re.findall(r"\(([\d.]+) %", said)]
        assert len(shares) == 2 and shares[0] >= shares[1], said


# --- the campaign: a bad recording beside a good one, on every command -------------------


def _rewritten(log, path, *, q=1.0, tau=1.0):
    """``log`` with its positions and velocities times ``q`` (degrees: 180 / pi) and its
    torques times ``tau`` (mN m: 1000)."""
    save_torque_log(path, type(log)(log.t, q * log.q, q * log.dq, tau * log.tau))
    return path


def test_identify_refuses_a_recording_in_other_units_naming_it(panda, logs, tmp_path, capsys):
    """A recording in mN m beside one in N m: identify refused it in no way (it warned
    that the torques were 1000 times the model's, naming no file) and fitted both; now one
    line names it, as validate, friction and payload do."""
    mnm = _rewritten(load_torque_log(logs / "rec2.csv"), tmp_path / "mnm.csv", tau=1000.0)
    argv = ["identify", "--robot", "panda", "--out", str(tmp_path / "i"), "--data"]
    assert main([*argv, str(logs / "rec1.csv"), str(mnm)]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
    assert len(err) == 1 and "error: mnm.csv: its torques (RMS) are 1" in err[0], err


def test_torques_in_mNm_read_as_Nm_are_refused_on_every_command(
    panda, logs, rec1_model, tmp_path, capsys
):
    """A recording in mN m without --units: identify fitted a model 1000 times too heavy,
    with a warning only, and reported it at the noise floor; now identify, validate,
    friction and observe each refuse it in one line with the hint --units tau=mNm, as a
    flipped sign or degrees, and --units tau=Nm (the unit said) reads it as it is."""
    model = rec1_model
    mnm = _rewritten(load_torque_log(logs / "rec2.csv"), tmp_path / "mnm.csv", tau=1000.0)
    given = ["--model", str(model / "identification.json")]
    runs = {
        "identify": ["identify", "--robot", "panda", "--terms", "viscous,coulomb"],
        "validate": ["validate", *given],
        "friction": ["friction", *given],
        "observe": ["observe", *given, "--calibrate"],
    }
    capsys.readouterr()
    for name, run in runs.items():
        out = ["--no-figures", "--out", str(tmp_path / name), "--data", str(mnm)]
        assert main([*run, *out]) == 2, name
        err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
        assert len(err) == 1 and re.search(
            r"error: mnm.csv: the measured torques are 1(\.\d+)?e\+03 times .*--units tau=mNm",
            err[0],
        ), err
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        out = ["--no-figures", "--out", str(tmp_path / "said"), "--data", str(mnm)]
        assert main([*runs["validate"], *out, "--units", "tau=Nm", "-q"]) == 1  # unusable
        assert main([*runs["validate"], *out, "--units", "tau=mNm", "-q"]) == 0


def test_identify_names_the_recording_its_findings_are_about(panda, logs, tmp_path):
    """Findings of the data (torques of the opposite sign, positions in degrees) on one of
    several recordings name it, once (the finding was said without a file, as if of all)."""
    neg = _rewritten(load_torque_log(logs / "rec2.csv"), tmp_path / "neg.csv", tau=-1.0)
    with pytest.raises(DataError) as refused:  # a fit would negate the masses
        identify_files(panda, [logs / "rec1.csv", neg])
    assert str(refused.value).startswith("neg.csv: the measured torques are anti-correlated")


def test_observe_checks_its_recordings_as_the_other_commands(
    panda, logs, rec1_model, tmp_path, capsys
):
    """observe calibrated its thresholds on a recording in mN m or in degrees beside good
    ones without a word (thresholds 1000 times too large); now each is refused, naming the
    file."""
    model = rec1_model
    log = load_torque_log(logs / "rec2.csv")
    mnm = _rewritten(log, tmp_path / "mnm.csv", tau=1000.0)
    deg = _rewritten(log, tmp_path / "deg.csv", q=180.0 / np.pi)
    run = ["observe", "--model", str(model / "identification.json"), "--calibrate"]
    run += ["--no-figures", "--out", str(tmp_path / "o"), "--data", str(logs / "rec1.csv")]
    capsys.readouterr()
    assert main([*run, str(mnm)]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
    assert len(err) == 1 and "error: mnm.csv: its torques (RMS) are 1" in err[0], err
    with pytest.raises(DataError, match="deg.csv: its positions and velocities look like deg"):
        observe_files(
            ObserveOptions(
                data=(logs / "rec1.csv", deg),
                model=model / "identification.json",
                calibrate=True,
            )
        )


def test_a_recording_too_short_to_filter_names_its_cut_off_readably(panda, logs, tmp_path):
    """A recording of ten samples: refused naming the file and the cut-off in a few digits
    (it printed 'at 11.24718820294926 Hz')."""
    log = load_torque_log(logs / "rec2.csv")
    save_torque_log(tmp_path / "short.csv", log.select(np.arange(10)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        with pytest.raises(DataError, match=r"short.csv: no piece long enough to filter") as e:
            identify_files(panda, [logs / "rec1.csv", tmp_path / "short.csv"])
    assert re.search(r"at \d+(\.\d{1,3})? Hz", str(e.value)), e.value


def test_extra_columns_are_noted_once_per_read(panda, logs, tmp_path, caplog):
    """A log with extra columns (a temperature, a label): used, the columns named in one
    note (the label, which observe scores against, not warned about); identify read it
    again for its held-out figures and said it twice (its structure given: the search
    reads no file)."""
    text = (logs / "rec1.csv").read_text().splitlines()
    h = next(i for i, s in enumerate(text) if s.startswith("t,"))
    rows = [s + f",{20 + 0.01 * k:.2f},x" for k, s in enumerate(text[h + 1 :])]
    body = [s for s in text[:h] if not s.startswith("# rows")] + [text[h] + ",temp,label"]
    (tmp_path / "extra.csv").write_text("\n".join(body + rows) + "\n")
    argv = ["identify", "--robot", "panda", "--terms", "viscous,coulomb"]
    argv += ["--out", str(tmp_path / "i"), "--data"]
    with warnings.catch_warnings(), caplog.at_level(logging.WARNING, logger="dynid"):
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*argv, str(tmp_path / "extra.csv")]) == 0
    notes = [r.getMessage() for r in caplog.records if "not torque-log signals" in r.getMessage()]
    assert notes == ["extra.csv: column(s) temp are not torque-log signals: ignored as data"]


def test_a_folder_names_the_files_it_leaves_out(logs, tmp_path, caplog):
    """A folder given to --data stands for its .csv and .npz files; a recording saved as
    .txt beside them was left out without a word, now in one note naming it."""
    d = tmp_path / "folder"
    (d / "sub").mkdir(parents=True)
    for name in ("a.csv", "b.txt"):
        (d / name).write_text((logs / "rec1.csv").read_text())
    (d / ".hidden").write_text("")
    with caplog.at_level(logging.WARNING, logger="dynid"):
        assert data_files(d) == [d / "a.csv"]
    notes = [r.getMessage() for r in caplog.records]
    assert notes == ["folder: 1 file(s) neither .csv nor .npz left out: b.txt"]


def test_one_recording_given_twice_is_refused_however_it_is_named(logs, tmp_path, monkeypatch):
    """The same file named two ways (relative and absolute), or a copy under another name:
    used twice, it counted double in the fit and judged itself when one recording was left
    out; now refused naming it."""
    monkeypatch.chdir(logs)
    with pytest.raises(DataError, match="rec1.csv: data file given twice"):
        data_files(["rec1.csv", logs / "rec1.csv"])
    (tmp_path / "copy.csv").write_bytes((logs / "rec1.csv").read_bytes())
    with pytest.raises(DataError, match="copy.csv: the same content as rec1.csv"):
        data_files([logs / "rec1.csv", logs / "rec2.csv", tmp_path / "copy.csv"])
    assert data_files([logs / "rec1.csv", logs / "rec2.csv"]) == [
        logs / "rec1.csv",
        logs / "rec2.csv",
    ]


def test_validate_on_one_of_the_recordings_fitted_is_refused(panda, logs, tmp_path, capsys):
    """--validate-on a recording the fit also saw (the same file, or a copy): its held-out
    error was the training error and chose the structure on it; now one line names the
    option and the file."""
    (tmp_path / "copy.csv").write_bytes((logs / "rec1.csv").read_bytes())
    argv = ["identify", "--robot", "panda", "--out", str(tmp_path / "i"), "--data"]
    for other in (logs / "rec1.csv", tmp_path / "copy.csv"):
        assert main([*argv, str(logs / "rec1.csv"), "--validate-on", str(other)]) == 2
        err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
        assert len(err) == 1, err
        assert f"error: --validate-on {other.name} is one of the recordings fitted" in err[0]


@pytest.mark.parametrize(
    ("factor", "said"),
    [
        (1e3, "rec2_bad.csv: its torques (RMS) are"),
        (-1.0, "rec2_bad.csv: the measured torques are anti-correlated"),
    ],
    ids=["mNm", "opposite sign"],
)
def test_the_held_out_log_is_checked_like_the_recordings(
    panda, logs, tmp_path, capsys, factor, said
):
    """identify --validate-on a log in mN m read as N m was judged (held-out error 99.9 %,
    exit 0, the unit only warned) and one of the opposite sign was refused as "validation
    log"; now both are refused as a recording fitted would be, one line naming the file."""
    log = load_torque_log(logs / "rec2.csv")
    save_torque_log(tmp_path / "rec2_bad.csv", type(log)(log.t, log.q, log.dq, factor * log.tau))
    argv = ["identify", "--robot", "panda", "--out", str(tmp_path / "i"), "--data"]
    argv += [str(logs / "rec1.csv"), "--validate-on", str(tmp_path / "rec2_bad.csv")]
    assert main(argv) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
    assert len(err) == 1 and said in err[0], err
    assert not (tmp_path / "i").exists()


def test_a_stretch_lost_without_a_gap_in_the_stamps_makes_no_event(logs, tmp_path, capsys):
    """The observer on a log whose logger lost 0.2 s of samples but stamped on evenly (the
    positions jump): it reported a 'collision' on every joint at the jump; now it starts
    again there, with a warning naming the file and the time, and finds no event."""
    log = load_torque_log(logs / "rec2.csv")
    keep = np.ones(log.n_samples, bool)
    keep[400:440] = False  # 2.0-2.2 s lost
    g = log.select(keep)
    save_torque_log(tmp_path / "lost.csv", type(g)(log.t[: g.n_samples], g.q, g.dq, g.tau))
    p = ["observe", "--params", "panda", "--no-figures"]
    cal = tmp_path / "cal"
    assert main([*p, "--calibrate", "--data", str(logs / "rec1.csv"), "--out", str(cal)]) == 0
    out = tmp_path / "det"
    th = ["--thresholds", str(cal / "thresholds.json")]
    capsys.readouterr()
    with warnings.catch_warnings():
        warnings.simplefilter("default", DynidWarning)
        assert main([*p, *th, "--data", str(tmp_path / "lost.csv"), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "lost.csv: position jumps more than the recorded velocity explains" in err
    assert "at t = 2.000 s" in err and "the observer starts again after each jump" in err
    assert json.loads((out / "events.json").read_text())["events"] == []
