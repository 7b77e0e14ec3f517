"""What validate, observe and identify say of the torques' delay (the one applied, its
source, the remedy for one the residual finds), against a simulated Panda whose torques lag
its positions by a known 3 ms; and the message of a log with fewer joints' columns than the
robot has."""

from __future__ import annotations

import dataclasses
import json
import re
import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.exceptions import DataError, DynidWarning
from dynid.friction.delay_check import logs_delay
from dynid.friction.heldout_torques import heldout_torques
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.identification.torque_delay import (
    AppliedDelay,
    TorqueDelay,
    applied_delay,
    torque_delay,
)
from dynid.io.model_json import load_model_json, save_model_json
from dynid.io.torque_log import save_torque_log
from dynid.report.delay import delay_facts, delay_section
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.data_files import read_torque_log
from dynid.workflows.validate import ValidateOptions, validate_files

DELAY = 0.003  # s, the truth
VISCOUS = np.array([0.6, 0.5, 0.4, 0.4, 0.15, 0.12, 0.1])  # N m s/rad
COULOMB = np.array([0.8, 0.7, 0.6, 0.6, 0.3, 0.25, 0.2])  # N m
NOISE = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)


def _late(panda, seed: int, delay: float = DELAY):
    """4 s of the Panda at 500 Hz on the Fourier trajectory of ``seed`` with classical
    friction and sensor noise, its torques those of ``delay`` [s] earlier."""
    t = sample_times(4.0, 500.0)
    traj = random_fourier(panda, np.random.default_rng(seed))
    fr = ClassicalFriction(VISCOUS, COULOMB, np.zeros(7))

    def at(times: np.ndarray):
        rng = np.random.default_rng(seed + 100)
        return simulate_measurement(panda, traj(times), rng=rng, noise=NOISE, friction=fr)

    return dataclasses.replace(at(t), tau=at(t - delay).tau)


@pytest.fixture(scope="module")
def files(panda, tmp_path_factory):
    """A model identified with ``torque_delay_s`` 3 ms on two late recordings, and a third
    late recording held out, as files."""
    d = tmp_path_factory.mktemp("delay")
    logs = [_late(panda, s) for s in (91, 92)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(
            panda, logs, structure=Structure.parse("viscous + coulomb"), torque_delay_s=DELAY
        )
    save_model_json(d / "identification.json", model)
    save_torque_log(d / "held.csv", _late(panda, 93))
    (d / "fit").mkdir()
    for s, log in zip((91, 92), logs, strict=True):
        save_torque_log(d / "fit" / f"r{s}.csv", log)
    return d


@pytest.fixture(scope="module")
def fitted(panda):
    """Two in-step recordings and the model fitted to them (no delay)."""
    logs = [_late(panda, s, 0.0) for s in (95, 96)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, structure=Structure.parse("viscous + coulomb"))
    return model, logs


def _options(report: str) -> dict[str, str]:
    """The report page's options table: option -> value as shown."""
    rows = re.findall(r"<code>(--[a-z-]+)</code></td><td>([^<]*)</td>", report)
    return {k: v.replace("&#x27;", "'") for k, v in rows}


def test_applied_delay_source() -> None:
    """Given (0 included) wins over the model's; nothing given or recorded is None."""
    assert applied_delay(None, 0.003) == AppliedDelay(0.003, "model")
    assert applied_delay(0.0, 0.003) == AppliedDelay(0.0, "given")
    assert applied_delay(None, 0.0) is None
    assert AppliedDelay(0.003, "model").sentence() == (
        "torque delay 3.0 ms (from the model's identification.json)"
    )
    assert AppliedDelay(0.00225, "given").text() == "2.25 ms (given)"


def test_validate_says_the_model_s_delay_and_takes_zero(files, tmp_path, capsys) -> None:
    """validate with a model identified at 3 ms says the delay and its source in the
    summary, validation.json and the report's options; ``--torque-delay 0`` says it was
    given, and the 3 ms lag the residual then shows is named with the hint to identify
    again with the whole delay, within 0.3 ms of the truth."""
    model, held = str(files / "identification.json"), str(files / "held.csv")
    base = ["validate", "--model", model, "--data", held, "--no-figures"]
    assert main([*base, "--out", str(tmp_path / "own")]) == 0
    out = capsys.readouterr().out
    said = "torque delay 3.0 ms (from the model's identification.json)"
    assert said in out
    doc = json.loads((tmp_path / "own" / "validation.json").read_text())
    assert doc["torque_delay_used"] == {"delay_ms": pytest.approx(3.0), "source": "model",
                                        "said": said}  # fmt: skip
    assert "torque_delay" not in doc  # the model holds the lag: none left to name
    report = (tmp_path / "own" / "report.html").read_text()
    assert _options(report)["--torque-delay"] == "3.0 ms (from the model's identification.json)"

    main([*base, "--torque-delay", "0", "--out", str(tmp_path / "zero")])
    assert "torque delay 0.0 ms (given)" in capsys.readouterr().out
    doc = json.loads((tmp_path / "zero" / "validation.json").read_text())
    assert doc["torque_delay_used"]["source"] == "given"
    report = (tmp_path / "zero" / "report.html").read_text()
    assert _options(report)["--torque-delay"] == "0.0 ms (given)"


def test_validate_names_the_truth_s_lag(panda, files) -> None:
    """The Panda's true parameters and friction on the 3 ms late log: the lag the residual
    shows is named within 0.3 ms of the truth, with --torque-delay as the remedy (a robot
    is not refitted); nothing applied is said as no delay."""
    truth = ClassicalFriction(VISCOUS, COULOMB, np.zeros(7))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        got = validate_files(panda, files / "held.csv", ValidateOptions(friction=truth))
    assert got.applied_delay is None and "torque_delay_used" not in got.metadata()
    assert got.torque_delay is not None and got.torque_delay.named
    found = re.search(r"hint: --torque-delay ([0-9.]+) pairs", got.verdict.reason)
    assert found is not None, got.verdict.reason
    assert abs(float(found.group(1)) - 1e3 * DELAY) < 0.3


def test_validate_of_a_model_asks_to_identify_again(panda, files, tmp_path, monkeypatch) -> None:
    """A log 5 ms late for a model identified at 3 ms, the 2 ms beyond it stood in for the
    residual's estimate: the hint is to identify again with the whole 5 ms."""
    import dynid.workflows.validate as workflow

    data = save_torque_log(tmp_path / "later.csv", _late(panda, 94, 0.005))
    beyond = TorqueDelay(0.002, 1e-5, 0.05, (), ())
    monkeypatch.setattr(workflow, "validations_delay", lambda model, parts: beyond)
    model = load_model_json(files / "identification.json")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        got = validate_files(model, data)
    assert "hint: identify it again with --torque-delay 5.00, then validate" in got.verdict.reason
    assert "beyond the 3.0 ms the logs were prepared with" in got.verdict.reason


def test_refit_hint_adds_the_applied_delay() -> None:
    """A residual lag of 1 ms beyond the 2 ms applied: the remedy names the whole 3 ms;
    a robot's (no refit) pairs the torques with --torque-delay."""
    d = TorqueDelay(0.001, 1e-5, 0.05, (), ())
    refit = d.sentence(0.002, refit=True)
    assert "identify it again with --torque-delay 3.00," in refit
    assert "beyond the 2.0 ms" in refit
    assert "hint: --torque-delay 1.00 pairs" in d.sentence()


def test_a_delay_is_said_to_its_std_s_first_digit() -> None:
    """2.056 +- 0.024 ms reads 2.06 +- 0.02 ms with the hint --torque-delay 2.06 (it read
    2.1 ms, +- 0.02, and hinted 2.1); 2.4 +- 0.3 ms reads 2.4 +- 0.3; 12 +- 3 ms reads 12."""
    said = TorqueDelay(0.002056, 0.000024, 0.05, (), ()).sentence()
    assert "lag the positions by 2.06 ms (+- 0.02 ms;" in said, said
    assert "hint: --torque-delay 2.06 pairs" in said, said
    said = TorqueDelay(0.0024, 0.0003, 0.05, (), ()).sentence()
    assert "by 2.4 ms (+- 0.3 ms;" in said and "--torque-delay 2.4 pairs" in said, said
    said = TorqueDelay(-0.012, 0.003, 0.05, (), ()).sentence()
    assert "lead the positions by 12 ms (+- 3 ms;" in said and "--torque-delay -12 pairs" in said


def test_observe_says_the_model_s_delay(files, tmp_path, capsys) -> None:
    """observe --calibrate with the 3 ms model says the delay and its source in the
    summary, thresholds.json and the report's options."""
    out = tmp_path / "cal"
    argv = ["observe", "--model", str(files / "identification.json"), "--data",
            str(files / "held.csv"), "--calibrate", "--no-figures", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    said = "torque delay 3.0 ms (from the model's identification.json)"
    assert said in capsys.readouterr().out
    cal = json.loads((out / "thresholds.json").read_text())["calibration"]
    assert cal["torque_delay_used"]["source"] == "model"
    assert _options((out / "report.html").read_text())["--torque-delay"] == said[13:]


def test_a_log_of_one_joint_names_the_robot_s_missing_columns(panda, tmp_path) -> None:
    """A ``t,q1,tau1`` file for the 7-joint Panda: the message names q2..q7 and
    tau2..tau7; with the joints' columns under other names beside, the --columns map
    that reads them."""
    t = np.arange(0.0, 1.0, 0.002)
    one = tmp_path / "one.csv"
    np.savetxt(one, np.c_[t, np.sin(t), np.cos(t)], delimiter=",", header="t,q1,tau1",
               comments="")  # fmt: skip
    with pytest.raises(DataError) as info:
        read_torque_log(one, 7, owner="robot 'panda'", robot=panda)
    text = str(info.value)
    assert "missing column(s) q2..q7, tau2..tau7 (the file has q1, tau1)" in text
    other = tmp_path / "other.csv"
    names = [f"pos_{i}" for i in range(1, 8)] + [f"eff_{i}" for i in range(1, 8)]
    table = np.c_[t, np.sin(t), np.cos(t), np.zeros((t.size, 14))]
    np.savetxt(other, table, delimiter=",", header=",".join(["t", "q1", "tau1", *names]),
               comments="")  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        with pytest.raises(DataError) as info:
            read_torque_log(other, 7, owner="robot 'panda'", robot=panda)
    assert "--columns 'q=pos_{i},tau=eff_{i}' reads them" in str(info.value)


def test_delay_check_reuses_the_heldout_pieces(fitted) -> None:
    """The held-out prediction of each recording keeps every piece prepared; the delay
    read from them is the one read after preparing the logs again, to the bit, and of
    recordings in step it names none (the truth: no lag)."""
    model, logs = fitted
    held = heldout_torques(model, logs[-1], others=logs[:-1])
    assert held is not None and len(held.prepared) == len(logs)
    again, reused = logs_delay(model, logs), logs_delay(model, logs, held.prepared)
    assert again is not None and reused is not None
    assert (reused.delay_s, reused.std_s, reused.share) == (again.delay_s, again.std_s, again.share)
    np.testing.assert_array_equal(reused.joints_s, again.joints_s)
    assert not reused.named


def test_per_joint_delays_shown_only_where_clear(panda) -> None:
    """Closed form: joints 1 and 2 whose torques change fast lag 3 ms, joint 3 barely
    moves: the record keeps the first two joints' own delays (each within 3 std of 3 ms)
    and null for the third; the report's table lists those two by name, in ms, with its
    caption; a delay without a clear joint shows no table."""
    rng = np.random.default_rng(12)
    t = np.arange(0.0, 10.0, 0.002)
    tau = np.column_stack([10 * np.sin(3 * t), 8 * np.cos(2 * t), 1e-3 * np.sin(0.1 * t)])
    late = np.column_stack(
        [10 * np.sin(3 * (t - DELAY)), 8 * np.cos(2 * (t - DELAY)), 1e-3 * np.sin(0.1 * t)]
    )
    found = torque_delay([t], [tau], [late - tau + rng.normal(0.0, 0.02, tau.shape)], lag=5)
    assert found is not None and found.named
    rec = found.as_dict()
    assert rec["joints_ms"][2] is None and rec["joints_std_ms"][2] is None
    for j in (0, 1):
        assert abs(rec["joints_ms"][j] - 1e3 * DELAY) < 3 * rec["joints_std_ms"][j]
    html = delay_section({"torque_delay": rec, "joint_names": ["a1", "a2", "a3"]})
    assert "delay [ms]" in html and "std [ms]" in html and "3 standard deviations" in html
    assert ">a1<" in html and ">a2<" in html and ">a3<" not in html
    bare = {k: v for k, v in rec.items() if not k.startswith("joints")}
    assert delay_section({"torque_delay": bare}) == ""
    assert "lag the positions by" in delay_facts({"torque_delay": bare})[0]


def test_identify_names_the_delay_before_the_hints(files, tmp_path, capsys) -> None:
    """identify on the two 3 ms late recordings without --torque-delay: the delay (within
    0.3 ms of the truth) is said before the held-out verdict and its hints, in the summary
    and first in the report's verdict box."""
    out = tmp_path / "id"
    argv = ["identify", "--robot", "panda", "--data", str(files / "fit"), "--terms",
            "viscous + coulomb", "--no-figures", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    lines = capsys.readouterr().out.splitlines()
    note = next(i for i, x in enumerate(lines) if x.startswith("note: the torques lag"))
    verdict = next(i for i, x in enumerate(lines) if x.startswith("held-out verdict"))
    assert note < verdict
    ms = float(re.search(r"--torque-delay ([0-9.]+)", lines[note]).group(1))
    assert abs(ms - 1e3 * DELAY) < 0.3
    box = (out / "report.html").read_text().split('<section class="verdict')[1]
    first = re.search(r"<li>(.*?)</li>", box).group(1)
    assert first.startswith("<b>The torques lag the positions by")
