"""dynid observe end to end: calibrate on a collision-free log, detect simulated contacts
(dynid simulate --contact), with an identified model and with a consistent robot."""

from __future__ import annotations

import html
import json
import logging
import re
import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.io.observer_files import load_thresholds

from conftest import TWO_LEAVES


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """A model identified from a 12 s log, a free log and a log with two contacts. The
    model's structure is fixed to the one identify's search chooses on that log (the same
    coefficients, the search's record aside): the observer is the case, not the search."""
    d = tmp_path_factory.mktemp("observe")
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "-q"]
    assert main([*sim, "--duration", "12", "--seed", "1", "--out", str(d / "ident.csv")]) == 0
    assert (
        main(
            [
                "identify",
                "--robot",
                "panda",
                "--data",
                str(d / "ident.csv"),
                "--out",
                str(d / "id"),
                "--no-figures",  # (identify's figures are not read)
                "--terms",
                "viscous,smooth:300,stribeck:0.2,offset,-fsp1,-fv3,-fsp4,-fv5,-fv6",
                "-q",
            ]
        )
        == 0
    )
    assert main([*sim, "--duration", "6", "--seed", "2", "--out", str(d / "free.csv")]) == 0
    hit = [
        "--contact", "link6:0,0,-15:2,2.5", "--contact", "flange:10,0,0,0,0,1:4,4.3",
    ]  # fmt: skip
    assert main([*sim, "--duration", "6", "--seed", "3", *hit, "--out", str(d / "hit.csv")]) == 0
    return d


def _main_said(argv: list[str], spy: str | None = None) -> tuple[int, str, str, list]:
    """``main(argv)``'s exit code, what it printed on stdout and stderr, and the results
    the function ``spy`` (a dotted name the command calls) returned, for a module-scoped
    fixture (capsys is the test's)."""
    import contextlib
    import io

    out, err, seen = io.StringIO(), io.StringIO(), []
    with contextlib.ExitStack() as stack:
        if spy is not None:
            module, name = spy.rsplit(".", 1)
            real = getattr(__import__(module, fromlist=[name]), name)

            def recorded(*a, **k):
                seen.append(real(*a, **k))
                return seen[-1]

            stack.enter_context(pytest.MonkeyPatch.context()).setattr(spy, recorded)
        stack.enter_context(contextlib.redirect_stdout(out))
        stack.enter_context(contextlib.redirect_stderr(err))
        code = main(argv)
    return code, out.getvalue(), err.getvalue(), seen


@pytest.fixture(scope="module")
def calibrated(logs):
    """The identified model calibrated on the free log with its figures (``cal``): what
    it printed (the tests that read this calibration share one run)."""
    model = ["--model", str(logs / "id" / "identification.json")]
    cmd = ["observe", *model, "--data", str(logs / "free.csv"), "--calibrate"]
    code, out, _, _ = _main_said([*cmd, "--out", str(logs / "cal")])
    assert code == 0
    return out


@pytest.fixture(scope="module")
def calibrated_without_velocities(logs):
    """The identified model calibrated with its figures on the free log without its
    velocity columns (``cal_q``): the exit code, what it printed on stdout and stderr and
    the result of the observe_files call the command made (its series kept for the
    figure)."""
    _without_velocities(logs / "free.csv", logs / "free_q.csv")
    model = logs / "id" / "identification.json"
    cmd = ["observe", "--model", str(model), "--data", str(logs / "free_q.csv"), "--calibrate"]
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", ".*velocities derived", UserWarning)
        said = _main_said([*cmd, "--out", str(logs / "cal_q")], "dynid.cli.observe.observe_files")
    code, out, err, (result,) = said
    return code, out, err, result


@pytest.fixture(scope="module")
def panda_thresholds(logs):
    """thresholds.json of the robot's own parameters and friction (``--params panda``)
    calibrated on the free log without figures (the tests that detect with them share one
    run)."""
    out = logs / "calp"
    cal = ["observe", "--params", "panda", "-q", "--no-figures", "--calibrate"]
    assert main([*cal, "--data", str(logs / "free.csv"), "--out", str(out)]) == 0
    return out / "thresholds.json"


def test_observe_calibrates_then_finds_both_simulated_contacts(logs, calibrated, capsys):
    """thresholds.json from the free log (with the model's uncertainty), then events.json
    (dynid-events/1) with the two contacts at their times, residuals.csv with the wrench at
    the flange, residuals.png, report.html."""
    d = logs
    model = ["--model", str(d / "id" / "identification.json")]
    th = load_thresholds(d / "cal" / "thresholds.json")
    assert th.uses_uncertainty and th.n == 7 and np.all(th.collision == 2 * th.contact)
    out = d / "obs"
    args = ["--thresholds", str(d / "cal" / "thresholds.json"), "--frame", "flange"]
    assert main(["observe", *model, *args, "--data", str(d / "hit.csv"), "--out", str(out)]) == 0
    doc = json.loads((out / "events.json").read_text())
    assert doc["schema"] == "dynid-events/1"
    starts = [e["start"] for e in doc["events"]]
    assert len(starts) == 2 and 2.0 <= starts[0] < 2.1 and 4.0 <= starts[1] < 4.1
    for e in doc["events"]:
        assert len(e["peak"]) == 7 and e["level"] in ("contact", "collision")
        assert set(e["joints"]) <= set(range(1, 8)) and e["end"] >= e["start"]
    lines = (out / "residuals.csv").read_text().splitlines()
    assert lines[2].startswith("t,r1,") and lines[2].endswith("fx,fy,fz,mx,my,mz,damped")
    table = np.loadtxt(out / "residuals.csv", delimiter=",", comments="#", skiprows=3)
    during = (table[:, 0] > 4.2) & (table[:, 0] < 4.3)
    assert np.median(table[during, 8]) == pytest.approx(10.0, abs=1.0)  # fx of the push
    assert (out / "residuals.png").stat().st_size > 10_000
    assert "residuals.png" in (out / "report.html").read_text()
    said = capsys.readouterr()
    assert "2 event(s)" in said.out
    # the true external torques simulate wrote: compared with, not called ignored
    assert "RMS r - tau_ext [N m]" in said.out and "ground truth" in said.out


def test_observe_with_a_consistent_robot_raises_no_event_on_a_free_log(logs, panda_thresholds):
    """--params panda (the robot's own parameters and friction): thresholds from one free
    log, no event on the same motion's log with other noise."""
    d = logs
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "-q", "--duration", "6"]
    assert main([*sim, "--seed", "2", "--noise", "0.06", "--out", str(d / "free2.csv")]) == 0
    p = ["observe", "--params", "panda", "-q"]
    assert load_thresholds(panda_thresholds).k_sigma is None
    th = ["--thresholds", str(panda_thresholds)]
    assert main([*p, *th, "--data", str(d / "free2.csv"), "--out", str(d / "obsp")]) == 0
    assert json.loads((d / "obsp" / "events.json").read_text())["events"] == []


def test_observe_refuses_thresholds_of_another_joint_count(logs, calibrated, capsys):
    """Thresholds of 7 joints with a 7-joint model pass; edited to 6 joints they are refused
    with a message naming the file."""
    d = logs
    doc = json.loads((d / "cal" / "thresholds.json").read_text())
    for k in ("contact", "collision"):
        doc[k] = doc[k][:6]
    doc["observer"]["gain"] = doc["observer"]["gain"][:6]
    doc["uncertainty"]["noise"] = doc["uncertainty"]["noise"][:6]
    for k in ("level", "rests"):  # the standstill margin at rest, calibrated per joint
        doc["rule"]["rest_margin"][k] = doc["rule"]["rest_margin"][k][:6]
    (d / "six.json").write_text(json.dumps(doc))
    args = ["observe", "--params", "panda", "--thresholds", str(d / "six.json")]
    assert main([*args, "--data", str(d / "hit.csv"), "--out", str(d / "bad")]) == 2
    assert "thresholds for 6 joints" in capsys.readouterr().err


def test_observe_params_urdf_with_two_leaves_takes_the_chain_of_tip(tmp_path, capsys):
    """--params URDF with two leaves: refused naming --tip without it; with --tip the
    chain's two joints (a log of that chain calibrates, a push on it is found); --tip with
    --model or a built-in robot is refused in one line."""
    urdf = tmp_path / "two.urdf"
    urdf.write_text(TWO_LEAVES)
    sim = ["simulate", "--robot", str(urdf), "--tip", "lower", "--trajectory", "fourier", "-q"]
    sim += ["--duration", "4", "--no-friction"]
    assert main([*sim, "--seed", "1", "--out", str(tmp_path / "free.csv")]) == 0
    hit = ["--contact", "lower:0,0,0,0,0,5:2,2.3"]  # 5 N m about the shoulder
    assert main([*sim, "--seed", "2", *hit, "--out", str(tmp_path / "hit.csv")]) == 0
    obs = ["observe", "--params", str(urdf), "-q", "--no-figures"]
    cal = [*obs, "--data", str(tmp_path / "free.csv"), "--calibrate"]
    assert main([*cal, "--out", str(tmp_path / "c0")]) != 0
    err = capsys.readouterr().err
    assert "several leaf links" in err and "--tip" in err
    assert main([*cal, "--tip", "lower", "--out", str(tmp_path / "cal")]) == 0
    assert load_thresholds(tmp_path / "cal" / "thresholds.json").n == 2
    th = ["--thresholds", str(tmp_path / "cal" / "thresholds.json"), "--tip", "lower"]
    assert main([*obs, *th, "--data", str(tmp_path / "hit.csv"), "--out", str(tmp_path / "o")]) == 0
    events = json.loads((tmp_path / "o" / "events.json").read_text())["events"]
    assert len(events) == 1 and 2.0 <= events[0]["start"] < 2.1
    capsys.readouterr()
    other = ["observe", "--params", "panda", "--tip", "link7", *cal[4:]]
    assert main([*other, "--out", str(tmp_path / "c1")]) != 0
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "--base/--tip/--snap-angles read the chain of a --params URDF" in line


@pytest.mark.parametrize(
    "extra, flag",
    [
        (["--gain", "80"], "--gain"),
        (["--discretisation", "euler"], "--discretisation"),
        (["--rule", "rectangle"], "--rule"),
        (["--margin", "2"], "--margin"),
        (["--quantile", "0.99"], "--quantile"),
        (["--collision-factor", "3"], "--collision-factor"),
        (["--k-sigma", "4"], "--k-sigma"),
        (["--no-uncertainty"], "--no-uncertainty"),
        (["--no-standstill-margin"], "--no-standstill-margin"),
    ],
)
def test_observe_thresholds_refuses_each_calibration_option_in_one_line(
    tmp_path, capsys, extra, flag
):
    """With --thresholds the file fixes the calibration: each of its options is refused,
    named by its flag, rather than silently ignored."""
    args = ["observe", "--params", "panda", "--thresholds", str(tmp_path / "t.json")]
    assert main([*args, *extra, "--data", str(tmp_path / "x.csv"), "--out", str(tmp_path)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert f"{flag} is a calibration option; t.json fixes it" in line


@pytest.mark.parametrize(
    "extra, flag",
    [
        (["--frame", "flange"], "--frame"),
        (["--merge", "1"], "--merge"),
        (["--min-duration", "0"], "--min-duration"),
    ],
)
def test_observe_calibrate_refuses_the_detection_options(tmp_path, capsys, extra, flag):
    """--frame, --merge and --min-duration act on detection only: refused when
    calibrating."""
    args = ["observe", "--params", "panda", "--calibrate", *extra]
    assert main([*args, "--data", str(tmp_path / "x.csv"), "--out", str(tmp_path)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert f"error: {flag} applies when detecting" in line


def test_observe_takes_folders_and_names_logs_of_one_name_by_their_folder(logs, capsys):
    """--data FOLDER stands for its logs, as on identify; two logs named log.csv in folders
    a and b are told apart: events.json's log, the residual files and the printed events."""
    import shutil

    d = logs
    for sub, src in (("c", "free.csv"), ("a", "hit.csv"), ("b", "free.csv")):
        (d / sub).mkdir()
        shutil.copy(d / src, d / sub / "log.csv")
    p = ["observe", "--params", "panda", "--no-figures"]
    assert main([*p, "--data", str(d / "c"), "--calibrate", "--out", str(d / "calc")]) == 0
    th = ["--thresholds", str(d / "calc" / "thresholds.json")]
    capsys.readouterr()
    out = d / "obsab"
    assert main([*p, *th, "--data", str(d / "a"), str(d / "b"), "--out", str(out)]) == 0
    doc = json.loads((out / "events.json").read_text())
    assert len(doc["events"]) == 2 and {e["log"] for e in doc["events"]} == {"a/log.csv"}
    assert (out / "residuals_a_log.csv").exists() and (out / "residuals_b_log.csv").exists()
    assert capsys.readouterr().out.count("  a/log.csv: ") == 2


def test_calibrating_an_identified_model_in_blocks_keeps_no_series(logs, monkeypatch):
    """An identified model with its covariance, the log a block of 700 samples at a time
    (the std filtered in blocks of 8192, cut again) without its series: the thresholds,
    noise floor included, are the rule on the whole log's residual, std and margin
    (residual_std and standstill_series of the whole log at once)."""
    import numpy as np

    from dynid.identification.log import joint_side_log
    from dynid.io.torque_log import load_torque_log
    from dynid.observer import observe
    from dynid.observer.detection import residual_std, standstill_series
    from dynid.workflows.observe import ObserveOptions, load_observer_model, observe_files

    monkeypatch.setattr("dynid.workflows.observe_logs.OBSERVE_BLOCK", 700)
    path = logs / "id" / "identification.json"
    opts = ObserveOptions(data=(logs / "free.csv",), model=path, calibrate=True, keep_series=False)
    lean = observe_files(opts)
    assert lean.logs[0].r is None and lean.thresholds.uses_uncertainty
    model, _ = load_observer_model(path, None)
    log = joint_side_log(load_torque_log(logs / "free.csv"), model.drive)
    o = lean.thresholds.options
    r = observe(model, log.t, log.q, log.dq, log.tau, o).r
    s = residual_std(model, log.t, log.q, log.dq, o)
    A = np.clip(np.abs(r) - standstill_series(model, log.t, log.dq, o), 0.0, None)
    np.testing.assert_allclose(lean.thresholds.contact, 1.5 * A.max(axis=0), rtol=1e-9)
    noise = 1.5 * np.clip(A - 3.0 * s, 0.0, None).max(axis=0)
    np.testing.assert_allclose(lean.thresholds.noise, noise, rtol=1e-9, atol=1e-12)


def _without_velocities(src, dst, columns: int = 15) -> None:
    """``src``'s log with its velocity columns left out (t, q, tau; tau_ext too if it has
    them: ``columns`` 22)."""
    lines = [x for x in src.read_text().splitlines() if not x.startswith("#")]
    head = lines[0].split(",")
    keep = [i for i, h in enumerate(head) if not h.startswith("dq")]
    assert len(keep) == columns, head
    dst.write_text("\n".join(",".join(x.split(",")[i] for i in keep) for x in lines) + "\n")


@pytest.mark.filterwarnings("ignore:.*velocities derived:UserWarning")
def test_calibrating_on_a_log_without_velocities_draws_its_figure(
    logs, calibrated_without_velocities
):
    """A log without velocity columns (the edges of its derived velocities not observed:
    NaN residual, NaN std) calibrated with an identified model's uncertainty and the
    figure: the command succeeds, writes thresholds.json and the figure, whose thresholds
    are NaN where the residual is (the std there was refused: exit 2, no file)."""
    from dynid.observer.thresholds import threshold_series

    code, _, err, result = calibrated_without_velocities
    out = logs / "cal_q"
    assert code == 0
    assert (out / "thresholds.json").exists() and (out / "residuals.png").stat().st_size > 10_000
    assert "skipped" not in err
    x = result.logs[0]  # the series the command computed (and drew)
    unseen = np.isnan(x.r).any(axis=1)
    assert unseen[0] and unseen[-1] and not unseen.all()
    th = load_thresholds(out / "thresholds.json")
    c, k = threshold_series(th, x.r.shape[0], x.std, x.standstill)
    np.testing.assert_array_equal(np.isnan(c).any(axis=1), unseen)
    np.testing.assert_array_equal(np.isnan(k).any(axis=1), unseen)
    # where observed: k sigma + nu plus the standstill margin
    s = unseen
    want = th.k_sigma * x.std[~s] + th.noise + (x.standstill[~s] if th.standstill else 0.0)
    np.testing.assert_allclose(c[~s], want, rtol=1e-12)


def test_a_calibration_figure_that_fails_costs_no_data_file(logs, capsys, monkeypatch):
    """What the figure computes (its thresholds at every sample) raises: a one-line note,
    exit 0, thresholds.json written (the error escaped the figure: exit 2, no file)."""

    def broken(*a, **k):
        raise RuntimeError("the plot is broken")

    monkeypatch.setattr("dynid.cli.figures.threshold_series", broken)
    model = ["--model", str(logs / "id" / "identification.json")]
    out = logs / "cal_broken"
    cmd = ["observe", *model, "--data", str(logs / "free.csv"), "--calibrate", "--out", str(out)]
    assert main(cmd) == 0
    assert (out / "thresholds.json").exists() and not (out / "residuals.png").exists()
    err = capsys.readouterr().err
    assert "note: skipped the figure residuals.png: RuntimeError: the plot is broken" in err


def test_observe_says_when_the_model_holds_no_friction(logs, tmp_path, capsys):
    """A model without friction (the robot's without its friction) leaves the joints'
    friction in the residual: observe says so in one line naming --friction (the README's
    recipe ran a model identified from static data on logs with friction and said nothing);
    the robot's own friction gets no such line."""
    from dynid import panda
    from dynid.io.robot.toml import save_toml

    save_toml(tmp_path / "bare.toml", panda().with_friction(None))
    cal = ["observe", "--data", str(logs / "free.csv"), "--calibrate", "--no-figures"]
    assert main([*cal, "--params", str(tmp_path / "bare.toml"), "--out", str(tmp_path / "a")]) == 0
    (line,) = [x for x in capsys.readouterr().err.splitlines() if "no friction" in x]
    assert "note: the model holds no friction" in line and "--friction" in line
    assert main([*cal, "--params", "panda", "--out", str(tmp_path / "b")]) == 0
    assert "no friction" not in capsys.readouterr().err


def test_calibration_says_when_velocity_noise_times_the_gain_sets_the_thresholds(
    logs, calibrated_without_velocities, capsys
):
    """Regression: the docs said a larger --gain detects sooner, while on noisy velocities
    the thresholds grow with it (a Panda's joint 1: 0.72, 1.79, 5.6 N m at gains 20, 50,
    150). Calibrated at gains 20 and 100 on one free log, the joints the printout names
    have thresholds that grow about fivefold; a log without velocities (derived, smooth)
    names none."""
    model = ["--model", str(logs / "id" / "identification.json"), "--no-figures"]
    cal = ["observe", *model, "--data", str(logs / "free.csv"), "--calibrate"]
    contact, named = {}, {}
    for gain in (20, 100):
        out = logs / f"cal_gain{gain}"
        assert main([*cal, "--gain", str(gain), "--out", str(out)]) == 0
        contact[gain] = load_thresholds(out / "thresholds.json").contact
        said = [x for x in capsys.readouterr().out.splitlines() if "velocity noise x gain" in x]
        assert len(said) <= 1
        named[gain] = [j for j in range(7) if said and f"joint{j + 1}" in said[0].split(" the")[0]]
    assert named[100] and set(named[20]) <= set(named[100]), named
    ratio = contact[100][named[100]] / contact[20][named[100]]
    assert np.all(ratio > 3.0), ratio  # in proportion to the gain (5) where noise sets it
    code, said_derived, _, _ = calibrated_without_velocities  # the same free log
    assert code == 0 and "velocity noise x gain" not in said_derived


def _answer(page: str) -> str:
    """The report's first screen: its answer box."""
    i = page.index('id="verdict"')
    return page[i : page.index("</section>", i)]


@pytest.mark.filterwarnings("ignore:.*of each piece:UserWarning")
def test_delays_of_derived_velocities_carry_their_caveat_beside_them(
    logs, panda_thresholds, tmp_path, capsys, caplog
):
    """A log without velocity columns: the delays come from a zero-phase low-pass that sees
    ahead, and the printed score line, events.json's score and the report's delay sentence
    say so beside the delay; the same log with its recorded velocities says nothing of it.
    The report's note on the log keeps the file name's case (it wrote 'Hit_q.csv'), and
    events.json's samples and duration_s are one-entry lists for the one log, equal to the
    file's rows and first-to-last time."""
    from dynid.observer.scoring import LOOK_AHEAD_WORDS

    d = logs
    _without_velocities(d / "hit.csv", tmp_path / "hit_q.csv", columns=22)
    p = ["observe", "--params", "panda", "--no-figures"]
    th = ["--thresholds", str(panda_thresholds)]
    said = {}
    for name in ("hit_q.csv", "hit.csv"):
        src = tmp_path / name if name == "hit_q.csv" else d / name
        capsys.readouterr()
        with caplog.at_level(logging.INFO, logger="dynid"):  # the notes the report records
            assert main([*p, *th, "--data", str(src), "--out", str(tmp_path / name[:-4])]) == 0
        (line,) = [x for x in capsys.readouterr().out.splitlines() if "delay median" in x]
        doc = json.loads((tmp_path / name[:-4] / "events.json").read_text())
        page = (tmp_path / name[:-4] / "report.html").read_text()
        said[name] = (line, doc, _answer(page))
    line, doc, answer = said["hit_q.csv"]
    assert doc["score"]["detected"] == 2 and doc["score"]["delays_look_ahead"] is True
    assert line.endswith(f"max {doc['score']['delay_max_ms']:.0f} ms ({LOOK_AHEAD_WORDS})")
    (fact,) = [x for x in answer.split("<li>") if "delay median" in x]
    assert html.escape(f" ms ({LOOK_AHEAD_WORDS}).", quote=True) in fact
    text = re.sub(r"<[^>]+>", "", answer)
    assert "Note: hit_q.csv: no velocity columns" in text and "Hit_q" not in text
    rows = [x for x in (tmp_path / "hit_q.csv").read_text().splitlines()[1:] if x]
    t = np.array([float(x.split(",")[0]) for x in rows])
    assert doc["data"] == ["hit_q.csv"] and doc["samples"] == [len(rows)]
    assert doc["duration_s"] == pytest.approx([t[-1] - t[0]], rel=1e-12)
    line, doc, answer = said["hit.csv"]
    assert doc["score"]["detected"] == 2 and doc["score"]["delays_look_ahead"] is False
    assert "zero-phase" not in line and "zero-phase" not in answer


def test_the_calibration_gives_one_collision_level_while_moving_and_names_the_base(
    logs, calibrated
):
    """With the model's uncertainty the collision level while moving is collision_factor x
    (noise + k sigma_max), one number in thresholds.json, the printout and the report's
    table (not 2 x detectable there and the fixed collision elsewhere); the fixed levels
    beside it are named the base, without the uncertainty."""
    from dynid.report.html import number

    out, printed = logs / "cal", calibrated
    doc = json.loads((out / "thresholds.json").read_text())
    cal, rule, unc = doc["calibration"], doc["rule"], doc["uncertainty"]
    moving = np.array(unc["noise"]) + unc["k_sigma"] * np.array(cal["sigma_max"])
    np.testing.assert_allclose(cal["detectable"], moving, rtol=1e-12)
    collision = rule["collision_factor"] * moving
    np.testing.assert_allclose(cal["collision_moving"], collision, rtol=1e-12)
    assert not np.allclose(collision, doc["collision"])  # two quantities, told apart
    said = ", ".join(f"{v:.3g}" for v in collision)
    assert f"collision level while moving: {said} N m" in printed
    assert "it replaces the fixed level and may lie below it" in printed
    head = next(x for x in printed.splitlines() if "contact, moving [N m]" in x)
    assert "contact --no-uncertainty [N m]" in head and "base" not in head
    row = next(x for x in printed.splitlines() if x.startswith(doc["joints"][0] + " "))
    assert f"{moving[0]:.4g}" in row or f"{moving[0]:.4f}" in row
    page = (out / "report.html").read_text()
    box = page[page.index('<table class="calibration">') :]
    box = box[: box.index("</table>")]
    heads = re.findall(r"<th>([^<]*)</th>", box)
    rows = [re.findall(r"<td>([^<]*)</td>", r) for r in re.findall(r"<tr><td>.*?</tr>", box)]
    col = {h: [r[k] for r in rows] for k, h in enumerate(heads)}
    assert col["collision level, moving [N m]"] == [number(x) for x in collision]
    assert col["contact level, moving (smallest torque detected) [N m]"] == [
        number(x) for x in moving
    ]
    assert col["contact --no-uncertainty (fixed, not applied here) [N m]"] == [
        number(x) for x in doc["contact"]
    ]
    assert col["collision --no-uncertainty (fixed, not applied here) [N m]"] == [
        number(x) for x in doc["collision"]
    ]


def test_the_friction_recipe_carries_the_robot_and_log_options_given():
    """Regression: the command the no-friction note prints left out the user's --tip (a
    UR5 URDF with several leaves then failed, "pass --tip"); parsed by dynid friction's own
    parser it holds every robot and log option observe was given, as given."""
    import shlex

    from dynid.cli.__main__ import build_parser
    from dynid.cli.observe import _friction_recipe

    parser = build_parser()
    given = ["observe", "--params", "my arm.urdf", "--base", "base_link", "--tip", "tool0"]
    given += ["--snap-angles", "--drive", "d.toml", "--columns", "tau=effort{i}"]
    given += ["--units", "q=deg", "--q-start", "0.5,-1", "--max-gap", "0.05"]
    given += ["--torque-delay", "3", "--drop-invalid", "--calibrate", "--data", "free"]
    recipe = _friction_recipe(parser.parse_args([*given, "--out", "o"]))
    command = recipe.removeprefix(" (").split(";")[0]
    words = shlex.split(command)
    assert words[:2] == ["dynid", "friction"]
    fr = parser.parse_args(words[1:])
    assert (fr.robot, fr.base, fr.tip, fr.snap_angles) == (
        "my arm.urdf",
        "base_link",
        "tool0",
        True,
    )
    assert (str(fr.drive), fr.columns, fr.units) == ("d.toml", "tau=effort{i}", "q=deg")
    assert fr.q_start == (0.5, -1.0) and fr.max_gap == 0.05 and fr.drop_invalid
    assert fr.torque_delay == pytest.approx(3e-3) and [str(d) for d in fr.data] == ["free"]
    model = ["observe", "--model", "id.json", "--calibrate", "--data", "a.csv", "--out", "o"]
    fr = parser.parse_args(
        shlex.split(_friction_recipe(parser.parse_args(model))[2:].split(";")[0])[1:]
    )
    assert str(fr.model) == "id.json" and fr.robot is None and fr.tip is None


def test_a_detection_flagging_most_of_the_log_says_the_model_is_off(
    logs, panda_thresholds, tmp_path, capsys
):
    """Regression: a model 3 N m of Coulomb friction off the arm's (thresholds of the
    exact model) raised events over most of the log with no word that this is the
    model's error; now a note says what share the events cover and to check the model."""
    from dynid import panda
    from dynid.friction.model import ClassicalFriction
    from dynid.io.robot.toml import save_toml

    wrong = ClassicalFriction(np.zeros(7), np.full(7, 3.0), np.zeros(7))
    save_toml(tmp_path / "off.toml", panda().with_friction(wrong))
    p = ["observe", "--no-figures", "--data", str(logs / "free.csv")]
    th = ["--thresholds", str(panda_thresholds)]
    capsys.readouterr()
    assert (
        main([*p, "--params", str(tmp_path / "off.toml"), *th, "--out", str(tmp_path / "d")]) == 0
    )
    doc = json.loads((tmp_path / "d" / "events.json").read_text())
    share = 100.0 * sum(doc["flagged_s"]) / sum(doc["duration_s"])
    (line,) = [x for x in capsys.readouterr().err.splitlines() if "events cover" in x]
    assert share > 50.0 and f"events cover {share:.3g} % of the logs" in line
    assert "the model's error" in line and "dynid validate" in line


def test_a_wrench_damped_near_a_singular_configuration_is_said_per_event(tmp_path, capsys):
    """Regression: with --frame, a push near the stretched-elbow singularity had its
    wrench damped on most samples and only the CSV's damped column said so. Two pushes on
    a simulated Panda whose elbow stretches (q4 = -0.1) then bends (q4 = -1.2): the first
    event's share of damped samples, equal to the residual table's damped column over its
    span, is said in the summary, events.json and the report; the second's is 0."""
    from dynid.io.excitation import save_trajectory_csv
    from dynid.simulation.trajectories import Trajectory

    t = np.arange(0.0, 2.0, 1e-3)
    w = np.pi
    q = np.tile([0.0, 0.3, 0.0, 0.0, 0.0, 1.5, 0.8], (t.size, 1))
    dq, ddq = np.zeros_like(q), np.zeros_like(q)
    for j, a, c in ((0, 0.3, 0.0), (3, 0.55, -0.65)):  # joint 1 sways, the elbow bends
        q[:, j] = c + a * np.sin(w * t + (np.pi / 2 if j == 3 else 0.0))
        dq[:, j] = a * w * np.cos(w * t + (np.pi / 2 if j == 3 else 0.0))
        ddq[:, j] = -a * w * w * np.sin(w * t + (np.pi / 2 if j == 3 else 0.0))
    save_trajectory_csv(tmp_path / "traj.csv", Trajectory(t, q, dq, ddq))
    sim = ["simulate", "--robot", "panda", "--trajectory", str(tmp_path / "traj.csv"), "-q"]
    assert main([*sim, "--seed", "1", "--out", str(tmp_path / "free.csv")]) == 0
    hit = ["--contact", "flange:0,0,-15:0.1,0.35", "--contact", "flange:0,0,-15:0.9,1.15"]
    assert main([*sim, "--seed", "2", *hit, "--out", str(tmp_path / "hit.csv")]) == 0
    p = ["observe", "--params", "panda", "--no-figures"]
    cal = ["--data", str(tmp_path / "free.csv"), "--calibrate", "-q"]
    assert main([*p, *cal, "--out", str(tmp_path / "cal")]) == 0
    th = ["--thresholds", str(tmp_path / "cal" / "thresholds.json"), "--frame", "flange"]
    capsys.readouterr()
    assert main([*p, *th, "--data", str(tmp_path / "hit.csv"), "--out", str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    events = json.loads((tmp_path / "o" / "events.json").read_text())["events"]
    table = np.loadtxt(tmp_path / "o" / "residuals.csv", delimiter=",", comments="#", skiprows=3)
    assert len(events) == 2
    for e in events:
        span = (table[:, 0] >= e["start"]) & (table[:, 0] <= e["end"])
        assert e["damped_share"] == pytest.approx(np.mean(table[span, -1]), abs=1e-12)
    first, second = (e["damped_share"] for e in events)
    assert first > 0.5 and second == 0.0
    assert f"wrench damped on {100 * first:.3g} %" in out and out.count("damped on") == 1
    assert "the wrench there is unreliable" in out
    page = html.unescape((tmp_path / "o" / "report.html").read_text())
    assert f"event 1 {100 * first:.3g} %" in page and "the wrench there is unreliable" in page


@pytest.mark.filterwarnings("ignore:.*calibrated with:UserWarning")
def test_the_trust_verdict_tells_a_model_that_fits_from_one_that_misfits(
    logs, panda_thresholds, tmp_path, capsys
):
    """The first line of the summary, events.json's trust and the report's headline say
    how far to trust the events. The arm's own model on the log with two pushes: good, the
    residual outside the events near the calibration's level. The same arm with 50 g at
    the flange that the model holds and the arm does not: poor, the level over the
    calibration's, and its rate of false alarms the one counted here from the simulated
    contacts' known times (link6 2-2.5 s, flange 4-4.3 s)."""
    from dynid import panda
    from dynid.io.robot.toml import save_toml

    robot = panda()
    mass = np.array(robot.mass, dtype=float)
    mass[6] += 0.05
    save_toml(tmp_path / "misfit.toml", robot.with_inertials(mass, robot.com, robot.inertia))
    recorded = json.loads(panda_thresholds.read_text())["calibration"]["residual_level"]
    got = {}
    for name, params in (("fits", "panda"), ("misfit", str(tmp_path / "misfit.toml"))):
        capsys.readouterr()
        cmd = ["observe", "--params", params, "--no-figures", "--data", str(logs / "hit.csv")]
        out = tmp_path / name
        assert main([*cmd, "--thresholds", str(panda_thresholds), "--out", str(out)]) == 0
        first = capsys.readouterr().out.splitlines()[0]
        doc = json.loads((out / "events.json").read_text())
        got[name] = (first, doc, (out / "report.html").read_text())
    for name, level in (("fits", "good"), ("misfit", "poor")):
        first, doc, page = got[name]
        trust = doc["trust"]
        assert trust["level"] == level and first == trust["summary"]
        assert first.startswith(f"trust: {level} - outside events the residual sits at")
        assert trust["calibration_level"] == pytest.approx(recorded)
        assert f'<section class="verdict {level}" id="verdict">' in page
        assert f"trust {level}</span> Outside events the residual sits at" in _answer(page)
    fits, misfit = got["fits"][1]["trust"], got["misfit"][1]["trust"]
    assert fits["quiet_level"] <= 1.2 * recorded and fits["false_alarms"] == 0
    assert misfit["quiet_level"] > 1.4 * recorded
    # the false alarms from the known contacts: an event starting outside every
    # [start - 0.02 s, end + 0.1 s] (the score's lead and tolerance) detects none
    doc = got["misfit"][1]
    windows = [(2.0 - 0.02, 2.5 + 0.1), (4.0 - 0.02, 4.3 + 0.1)]
    false = [e for e in doc["events"] if not any(a <= e["start"] <= b for a, b in windows)]
    free = doc["duration_s"][0] - sum(b - a for a, b in windows)
    assert misfit["false_alarms"] == len(false) >= 1
    assert misfit["false_alarms_per_min"] == pytest.approx(60.0 * len(false) / free, rel=0.02)
    assert "expect false alarms" in misfit["summary"]
