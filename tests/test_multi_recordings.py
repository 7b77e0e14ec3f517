"""Several recordings on ``validate``, ``friction`` and ``payload``: each recording, and
each piece of one cut at a gap, prepared on its own, errors pooled over every sample.

References: simulated Panda logs with known friction and sensor noise (the RMS of the true
robot is the noise level), the closed form of the pooled RMS and relative error over the
concatenated per-sample errors, and the friction the logs were simulated with.
"""

from __future__ import annotations

import dataclasses
import json
import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError, DynidWarning, OptionError
from dynid.friction.model import ClassicalFriction
from dynid.io.feasible import save_feasible_json
from dynid.io.static_data import save_static_data
from dynid.io.torque_log import load_torque_log, save_torque_log
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.friction import FrictionOptions, fit_friction_files
from dynid.workflows.identify import identify_files
from dynid.workflows.payload import identify_payload_files
from dynid.workflows.recordings import Recorded, check_limits
from dynid.workflows.validate import ValidateOptions, validate_files

NOISE = 0.05  # N m, the simulated torque sensor noise (SensorNoise's default)
VISCOUS = np.linspace(0.4, 0.15, 7)  # N m s/rad
COULOMB = np.linspace(0.8, 0.3, 7)  # N m


def _recording(robot, seed, friction, *, duration=6.0, cut=(2.0, 2.5)):
    """A simulated 500 Hz torque log of a random Fourier trajectory with the stretch
    ``cut`` [s] cut out (a gap that splits it into two pieces)."""
    log = simulate_measurement(
        robot,
        random_fourier(robot, np.random.default_rng(seed))(sample_times(duration, 500.0)),
        rng=np.random.default_rng(seed + 100),
        noise=SensorNoise(),
        friction=friction,
    )
    if cut is None:
        return log
    return log.select(~((log.t > cut[0]) & (log.t < cut[1])))


@pytest.fixture(scope="module")
def panda():
    return dynid.panda()


@pytest.fixture(scope="module")
def files(panda, tmp_path_factory):
    """Two recordings of the Panda with its own sigmoid friction, each with a gap, and two
    of the Panda with classical friction."""
    d = tmp_path_factory.mktemp("multi")
    for s in (1, 2):
        save_torque_log(d / f"rec{s}.csv", _recording(panda, s, "robot"))
    fr = ClassicalFriction(VISCOUS, COULOMB, np.zeros(7))
    for s in (3, 4):
        save_torque_log(d / f"cl{s}.csv", _recording(panda, s, fr))
    return d


@pytest.fixture(scope="module")
def validated(panda, files):
    """validate_files of the true robot on rec1 alone and on rec1 and rec2 (the tests that
    read these validations share them)."""
    return {
        "rec1": validate_files(panda, files / "rec1.csv"),
        "both": validate_files(panda, [files / "rec1.csv", files / "rec2.csv"]),
    }


def test_the_true_robot_over_two_recordings_with_gaps_is_at_the_noise_level(validated):
    """The true robot and friction over two recordings cut by gaps: every piece filtered
    on its own, the pooled RMS per joint is the sensor noise and each file says how many
    pieces and samples it gave."""
    res = validated["both"]
    val = res.validation
    np.testing.assert_allclose(val.errors.rms, NOISE, rtol=0.06)
    assert np.all(val.without_friction.rms > 2 * NOISE)  # the friction is there
    assert [s["pieces"] for s in val.pieces.summary()] == [2, 2]
    assert val.pieces.describe().startswith("rec1.csv: 2 pieces, ")
    assert [r.file for r in val.recordings] == ["rec1.csv", "rec2.csv"]
    for r in val.recordings:
        np.testing.assert_allclose(r.errors.rms, NOISE, rtol=0.1)
    assert res.friction_source == "model" and res.files == ("rec1.csv", "rec2.csv")


def test_the_validate_report_names_its_worst_joint_by_the_robots_name(panda, validated, tmp_path):
    """validation.json holds the robot's joint names, so that the page names the worst
    joint as the robot does (it said "Worst joint joint 1")."""
    from dynid.io.validation_json import save_validation_json
    from dynid.report import RunSummary, render_html_report

    res = validated["rec1"]
    assert res.metadata()["joint_names"] == list(panda.joint_names)
    p = save_validation_json(tmp_path / "validation.json", res.validation, **res.metadata())
    page = render_html_report(RunSummary(command="validate"), {p.name: p})
    worst = page.split("Worst joint against its own noise (", 1)[1].split(") ", 1)[1]
    assert worst.split(":", 1)[0] in panda.joint_names


def test_a_gap_bridged_across_ruins_what_the_pieces_keep(panda, files, validated):
    """The same recording with its 0.5 s gap bridged by interpolation (--max-gap 1): the
    filter and the derivatives run across the join and the error grows far above the
    noise; cut into pieces it stays at the noise."""
    cut = validated["rec1"].validation
    bridged = validate_files(panda, files / "rec1.csv", ValidateOptions(max_gap_s=1.0))
    assert np.max(cut.errors.rms) < 1.1 * NOISE
    assert np.max(bridged.validation.errors.rms) > 3 * NOISE


def test_pooled_errors_are_those_of_every_sample_together(validated):
    """Closed form: the pooled RMS per joint and relative error equal those computed over
    the concatenated per-sample errors of every piece; each recording's over its own."""
    val = validated["both"].validation
    E = np.concatenate([v.log.tau - v.tau_hat for v in val.parts])
    T = np.concatenate([v.log.tau for v in val.parts])
    np.testing.assert_allclose(val.errors.rms, np.sqrt(np.mean(E**2, axis=0)), rtol=1e-12)
    rel = 100 * np.linalg.norm(E) / np.linalg.norm(T)
    assert val.errors.relative_error_percent == pytest.approx(rel, rel=1e-12)
    assert val.errors.n_samples == E.shape[0]
    for r, rec in enumerate(val.recordings):
        mine = [v for v, k in zip(val.parts, val.pieces.recording, strict=True) if k == r]
        e = np.concatenate([v.log.tau - v.tau_hat for v in mine])
        np.testing.assert_allclose(rec.errors.rms, np.sqrt(np.mean(e**2, axis=0)), rtol=1e-12)


def test_the_command_and_the_api_apply_one_policy(panda, files, tmp_path, capsys):
    """dynid validate with two files (a folder too) writes the errors validate_files
    returns, one entry per recording, and prints the pieces of each file."""
    paths = [files / "rec1.csv", files / "rec2.csv"]
    api = validate_files(panda, paths, ValidateOptions(friction="none"), label="robot panda")
    argv = ["validate", "--robot", "panda", "--no-friction", "--no-figures"]
    assert main([*argv, "--data", *map(str, paths), "--out", str(tmp_path / "v")]) == 0
    out = capsys.readouterr().out
    assert "rec1.csv: 2 pieces" in out and "rec2.csv: relative error" in out
    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    np.testing.assert_allclose(doc["rms"], api.validation.errors.rms, rtol=1e-12)
    assert [r["file"] for r in doc["recordings"]] == ["rec1.csv", "rec2.csv"]
    assert doc["recordings"][0]["pieces"] == 2 and doc["files"] == ["rec1.csv", "rec2.csv"]
    folder = tmp_path / "logs"
    folder.mkdir()
    for p in paths:
        (folder / p.name).write_bytes(p.read_bytes())
    assert main([*argv, "--data", str(folder), "--out", str(tmp_path / "w")]) == 0
    doc2 = json.loads((tmp_path / "w" / "validation.json").read_text())
    assert doc2["rms"] == doc["rms"]


def test_validate_options_name_what_they_mean():
    """Options out of range are refused naming the option's meaning."""
    with pytest.raises(OptionError, match=r"cutoff_hz \(the low-pass cut-off"):
        ValidateOptions(cutoff_hz=-1.0)
    with pytest.raises(OptionError, match=r"max_gap_s \(the longest gap"):
        ValidateOptions(max_gap_s=0.0)
    with pytest.raises(OptionError, match="friction added to the model"):
        ValidateOptions(friction=3)  # type: ignore[arg-type]


def test_friction_is_recovered_from_several_recordings(panda, files):
    """Classical friction fitted on the residual of two recordings (four pieces) comes
    back as simulated; the law is chosen leaving one recording out at a time, every
    candidate judged on the same recordings."""
    rigid = panda.with_friction(None)
    paths = [files / "cl3.csv", files / "cl4.csv"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        fixed = fit_friction_files(rigid, paths, FrictionOptions(law="classical"))
        auto = fit_friction_files(rigid, paths)
    fr = fixed.fit.friction.as_array()
    np.testing.assert_allclose(fr[:, 0], VISCOUS, atol=0.05)
    np.testing.assert_allclose(fr[:, 1], COULOMB, atol=0.05)
    # the noise, and the Coulomb step at reversals seen through filtered velocities
    assert np.all(fixed.fit.rms_after < 2 * NOISE)
    assert np.all(fixed.fit.rms_after < 0.3 * fixed.fit.rms_before)
    assert fixed.fit.n_samples == sum(s["samples"] for s in fixed.pieces.summary())
    sel = auto.selection
    assert sel.method == "leave one recording out (2 recordings)" and sel.folds == 2
    held = {s.name: s.heldout_error_percent for s in sel.scores}
    assert sel.chosen in ("classical", "smooth", "stribeck")
    assert held[sel.chosen] < 0.5 * held["none"]


def test_the_own_friction_is_judged_on_the_same_recordings(panda, files):
    """A model identified from rec1 and rec2: on those recordings its friction is judged by
    the law it was identified with (its standstill band or smooth width) refitted on the
    recording left out, which predicts them at least as well as the registry's law at the
    noise band (0.445 % against 0.832 %: judged with the registry's band it read 0.832 %);
    the robot's own (true) friction on recordings new to it is judged as it is, and
    predicts them best."""
    paths = [files / "rec1.csv", files / "rec2.csv"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_files(panda, paths).model
        sel = fit_friction_files(model, paths).selection
        robot = fit_friction_files(panda, paths).selection
    held = {s.name: s.heldout_error_percent for s in sel.scores}
    law = model.friction.law
    assert sel.scores[-1].name == "own" and held["own"] <= held[law]
    assert sel.method.startswith("leave one recording out")
    held_r = {s.name: s.heldout_error_percent for s in robot.scores}
    assert robot.scores[0].name == "own"
    assert held_r["own"] <= 1.01 * min(held_r.values())


# --- one line naming the file, never a silently dropped recording ----------------------


def _copy(src, dst, edit):
    """``src`` rewritten through ``edit`` (a function of the CSV's lines) as ``dst``."""
    lines = src.read_text().splitlines()
    lines = [s for s in lines if not s.startswith("# rows:")]
    dst.write_text("\n".join(edit(lines)) + "\n")
    return dst


def _nan(line):
    """A CSV row with its second value NaN."""
    cells = line.split(",")
    return ",".join([cells[0], "nan", *cells[2:]])


def _header(lines):
    return next(i for i, s in enumerate(lines) if s.startswith("t,"))


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda ls: ls[: _header(ls) + 1], "bad.csv: no data rows"),
        (
            lambda ls: [*ls[: _header(ls) + 5], _nan(ls[_header(ls) + 5])] + ls[_header(ls) + 6 :],
            "bad.csv: 1 row",
        ),
        (
            lambda ls: [*ls[: _header(ls) + 5], ls[_header(ls) + 4]] + ls[_header(ls) + 5 :],
            "bad.csv: .*repeat",
        ),
    ],
    ids=["empty", "nan", "duplicated-stamp"],
)
def test_a_bad_recording_among_several_is_named(panda, files, tmp_path, edit, message):
    """An empty recording, one with NaN or a repeated time stamp: one error naming it, on
    validate and friction alike."""
    bad = _copy(files / "rec2.csv", tmp_path / "bad.csv", edit)
    for call in (validate_files, fit_friction_files):
        with pytest.raises(DataError, match=message):
            call(panda, [files / "rec1.csv", bad])


def test_a_recording_of_another_joint_count_is_named(panda, files, tmp_path):
    """A six-joint recording beside a Panda's: refused, the file named."""
    log = load_torque_log(files / "rec2.csv")
    six = type(log)(log.t, log.q[:, :6], log.dq[:, :6], log.tau[:, :6])
    save_torque_log(tmp_path / "six.csv", six)
    with pytest.raises(DataError, match="six.csv: the log has 6 joints"):
        validate_files(panda, [files / "rec1.csv", tmp_path / "six.csv"])


def test_a_recording_in_other_units_is_named(panda, files, tmp_path, capsys):
    """A recording in mN m, or with its time in milliseconds, beside recordings in SI
    units: refused, the file named, through the API and the command alike."""
    log = load_torque_log(files / "rec2.csv")
    save_torque_log(tmp_path / "mnm.csv", type(log)(log.t, log.q, log.dq, 1000 * log.tau))
    save_torque_log(tmp_path / "ms.csv", type(log)(1000 * log.t, log.q, log.dq, log.tau))
    with pytest.raises(DataError, match=r"mnm.csv: its torques \(RMS\) are 1\.\d+e\+03 times tho"):
        validate_files(panda, [files / "rec1.csv", tmp_path / "mnm.csv"])
    with pytest.raises(
        DataError, match=r"ms\.csv: .*time column looks like ms.*--units ms\.csv:t=ms"
    ):
        fit_friction_files(panda, [files / "rec1.csv", tmp_path / "ms.csv"])
    code = main(["identify", "--robot", "panda", "--data", str(tmp_path / "ms.csv"), "--out",
                 str(tmp_path / "i"), "--no-figures"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and err.count("ms.csv") == 1, err  # one recording: its name said once
    with pytest.raises(DataError) as api:
        validate_files(panda, [files / "rec1.csv", tmp_path / "mnm.csv"])
    argv = ["validate", "--robot", "panda", "--out", str(tmp_path / "v"), "--data"]
    assert main([*argv, str(files / "rec1.csv"), str(tmp_path / "mnm.csv")]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
    assert len(err) == 1 and err[0].endswith(str(api.value))


def test_a_recording_of_another_robot_is_named(panda, files, tmp_path):
    """Positions far outside the Panda's joint limits (another arm: shifted by 3 rad): a
    warning naming the file; positions in degrees beside radians: refused, naming it."""
    log = load_torque_log(files / "rec2.csv")
    far = type(log)(log.t, log.q + 3.0, log.dq, log.tau)
    rec = Recorded((log, far), (files / "rec2.csv", tmp_path / "far.csv"))
    with pytest.warns(
        DynidWarning, match="far.csv: joint .* far outside the limits of robot"
    ) as said:
        check_limits(rec, panda)
    assert "encoder counts" not in " ".join(str(w.message) for w in said)
    # a servo's encoder counts (4096 a turn, about its middle) read as radians: every joint
    # named, and the factor that reads counts in radians
    counts = np.round(log.q * 4096 / (2 * np.pi)) + 2048
    tick = type(log)(log.t, counts, log.dq, log.tau)
    rec = Recorded((log, tick), (files / "rec2.csv", tmp_path / "tick.csv"))
    with pytest.warns(DynidWarning, match="tick.csv: joint") as said:
        check_limits(rec, panda)
    text = " ".join(str(w.message) for w in said)
    assert "outside theirs" in text and "joint7" in text, text
    assert f"--units q={2 * np.pi / 4096:.10g}" in text, text
    save_torque_log(tmp_path / "deg.csv", type(log)(log.t, np.degrees(log.q), log.dq, log.tau))
    with pytest.raises(DataError, match="deg.csv: its positions look like degrees"):
        validate_files(panda, [files / "rec1.csv", tmp_path / "deg.csv"])


def test_a_piece_too_short_to_filter_is_named_and_a_recording_without_one_refused(
    panda, files, tmp_path
):
    """A gap that leaves a piece of ten samples: left out with a warning naming the file
    and its times; a recording of only such pieces: an error naming it."""
    log = load_torque_log(files / "rec2.csv")
    keep = ~((log.t > 0.02) & (log.t < 0.5))  # samples 0..10, then a gap
    save_torque_log(tmp_path / "short.csv", log.select(keep))
    said = r"short.csv: piece t = 0.000-0.020 s \(11 samples\) left out"
    with pytest.warns(DynidWarning, match=said):
        val = validate_files(panda, [files / "rec1.csv", tmp_path / "short.csv"]).validation
    assert val.pieces.skipped and val.pieces.summary()[1]["pieces"] == 2
    stub = log.select(np.arange(12))
    save_torque_log(tmp_path / "stub.csv", stub)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        with pytest.raises(DataError, match="stub.csv: no piece long enough to filter"):
            validate_files(panda, [files / "rec1.csv", tmp_path / "stub.csv"])


# --- payload -----------------------------------------------------------------------------

LOAD_MASS = 0.83  # kg
LOAD_COM = np.array([0.012, -0.021, 0.064])  # m, in the flange frame
LOAD_INERTIA = np.diag([0.0021, 0.0032, 0.0043])  # kg m^2 about the CoM


@pytest.fixture(scope="module")
def loaded_files(tmp_path_factory):
    """Two recordings of the Panda carrying a known load (no friction), 200 Hz, each
    with a 0.5 s gap, and the arm without the load."""
    arm = dynid.panda().with_friction(None)
    loaded = arm.with_tool(np.eye(4), LOAD_MASS, LOAD_COM, LOAD_INERTIA, name="load")
    d = tmp_path_factory.mktemp("payload")
    for s in (41, 42):
        traj = random_fourier(arm, np.random.default_rng(s), q0=dynid.PANDA_NEUTRAL_Q)(
            sample_times(8.0, 200.0)
        )
        log = simulate_measurement(loaded, traj, rng=np.random.default_rng(s + 100))
        save_torque_log(d / f"load{s}.csv", log.select(~((log.t > 3.0) & (log.t < 3.5))))
    return arm, d


def test_a_load_is_identified_from_several_recordings_with_gaps(loaded_files, tmp_path, capsys):
    """Two recordings of the loaded arm, cut by gaps into four pieces, each filtered on
    its own: the mass and the CoM come back within four reported standard deviations;
    dynid payload prints the pieces of each file, and where each was cut."""
    arm, d = loaded_files
    paths = [d / "load41.csv", d / "load42.csv"]
    res = identify_payload_files(arm, paths)
    est = res.estimate
    assert [r["pieces"] for r in res.recordings] == [2, 2]
    assert est.route == "2 torque logs"  # recordings; their pieces in res.recordings
    assert abs(est.mass - LOAD_MASS) < 4 * est.std_mass + 1e-3
    assert np.all(np.abs(est.com - LOAD_COM) < 4 * est.std_com + 1e-3)
    # the gaps bridged by interpolation (--max-gap 1): the mass is off by several stds
    bridged = identify_payload_files(arm, paths, max_gap_s=1.0).estimate
    assert abs(bridged.mass - LOAD_MASS) > 5 * abs(est.mass - LOAD_MASS)
    argv = ["payload", "--robot", "panda", "--data", *map(str, paths), "--out", str(tmp_path)]
    assert main(argv) == 0
    out = capsys.readouterr().out  # the gap named as identify names it: its stamp, length
    assert re.search(
        r"load41\.csv: 2 pieces, \d+ samples, cut at the gap\(s\) after "
        r"t = 3\.000 s \(0\.5 s long\)",
        out,
    )


def test_payload_params_reads_the_logs_as_the_fit_read_its_own(loaded_files, tmp_path):
    """Regression: with --params feasible.json the sign flips the fit's data were read
    with were forgotten (with --model identification.json they are reused), and a log of
    the same controller, joint 2 logged negated, was refused for its sign. feasible.json
    records them (``column_map``) and payload reads the log through them: the mass and
    CoM within four standard deviations of the truth."""
    arm, d = loaded_files
    log = load_torque_log(d / "load41.csv")
    flipped = log.tau.copy()
    flipped[:, 1] *= -1.0
    save_torque_log(tmp_path / "flipped.csv", dataclasses.replace(log, tau=flipped))
    feasible = save_feasible_json(
        tmp_path / "feasible.json", arm, column_map={"columns": None, "units": "tau2=-1"}
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)  # the reuse is said
        est = identify_payload_files(arm, tmp_path / "flipped.csv", feasible=feasible).estimate
    assert abs(est.mass - LOAD_MASS) < 4 * est.std_mass + 1e-3, est.mass
    assert np.all(np.abs(est.com - LOAD_COM) < 4 * est.std_com + 1e-3), est.com


def test_payload_static_data_stay_one_file(tmp_path):
    """Static data come in one file: two are refused in one line naming the first."""
    panda = dynid.panda()
    ctrl = dynid.SimulatedController(panda, rng=np.random.default_rng(5))
    for seed, name in ((6, "s1.csv"), (7, "s2.csv")):  # two acquisitions (a copy is refused)
        save_static_data(
            tmp_path / name, dynid.acquire_static(ctrl, 20, np.random.default_rng(seed))
        )
    with pytest.raises(DataError, match=r"s1.csv holds static data: give one static data file"):
        identify_payload_files(panda, [tmp_path / "s1.csv", tmp_path / "s2.csv"])


def test_recordings_at_other_rates_say_each_rate(panda, files, tmp_path, capsys):
    """A recording at 125 Hz (a UR's RTDE default) beside one at 500 Hz: each line of the
    summary says its rate and the record holds each one's (the identification's
    metadata kept the first file's alone)."""
    slow = _recording(panda, 5, "robot", cut=None)
    save_torque_log(tmp_path / "slow.csv", slow.select(np.arange(slow.t.size) % 4 == 0))
    argv = ["identify", "--data", str(files / "rec1.csv"), str(tmp_path / "slow.csv")]
    assert (
        main([*argv, "--terms", "viscous,coulomb", "--out", str(tmp_path / "id"), "--no-figures"])
        == 0
    )
    out = capsys.readouterr().out
    assert re.search(r"recording rec1\.csv: .*, at 500 Hz", out), out
    assert re.search(r"recording slow\.csv: .*, at 125 Hz", out), out
    recs = json.loads((tmp_path / "id" / "identification.json").read_text())["metadata"]
    assert [r["sample_rate_hz"] for r in recs["recordings"]] == pytest.approx([500.0, 125.0])
