"""`dynid validate` on static data: a model's M(q) and g(q) against a file of q, M, g at
configurations it was not fitted to (the paper's route, Gaz et al. 2019 Sec. IV-A).

References: Pinocchio's M and g of the Panda (CRBA, generalized gravity); the simulated
controller's multiplicative noise, whose norm over the entries' is its relative level
``eps`` (closed form); a model with a known mass error."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError
from dynid.identification.data import StaticDataset
from dynid.io.static_data import save_static_csv
from dynid.workflows.validate_static import validate_static_file

from conftest import pinocchio_panda_static


def _acquired(robot, n, eps, seed):
    ctrl = dynid.SimulatedController(robot, relative_noise=eps, rng=np.random.default_rng(seed))
    return dynid.acquire_static(ctrl, n, np.random.default_rng(seed + 100))


def test_the_panda_matches_pinocchios_m_and_g_to_round_off(tmp_path):
    q, M, g = pinocchio_panda_static(3, 40)
    save_static_csv(tmp_path / "pin.csv", StaticDataset(q, M, g))
    got = validate_static_file(dynid.panda(), tmp_path / "pin.csv")
    assert got.relative_error_percent < 1e-10
    assert got.floor_percent is None  # the file records no noise: a controller's model
    assert got.verdict.level == "good" and got.n_configurations == 40


def test_the_true_model_on_noisy_data_sits_at_the_recorded_noise(tmp_path):
    """Multiplicative noise eps on every entry: the noise's norm over the entries' is eps,
    so the true model's error is about 100 eps % and the floor exactly that."""
    robot = dynid.panda()
    save_static_csv(tmp_path / "noisy.csv", _acquired(robot, 200, 1e-3, 5))
    got = validate_static_file(robot, tmp_path / "noisy.csv")
    assert got.floor_percent == pytest.approx(0.1)
    assert got.relative_error_percent == pytest.approx(0.1, rel=0.1)
    assert got.verdict.label == "at the noise floor", got.verdict.reason


def test_a_link_mass_off_by_ten_percent_is_seen(tmp_path):
    robot = dynid.panda()
    phi = np.array(robot.phi).reshape(7, 10).copy()
    phi[2] *= 1.1  # link 3: m, m c and J scaled by 1.1 (its inertia about the origin)
    wrong = robot.with_params(phi)
    data = _acquired(robot, 100, 1e-4, 6)
    save_static_csv(tmp_path / "d.csv", data)
    got = validate_static_file(wrong, tmp_path / "d.csv")
    # the error's size from the two models alone, on the data's configurations
    dg = dynid.gravity_torques(wrong, data.q) - dynid.gravity_torques(robot, data.q)
    expected = 100 * np.linalg.norm(dg) / np.linalg.norm(data.g)
    assert got.g_error_percent == pytest.approx(expected, rel=0.02)
    assert got.verdict.level != "good" and got.relative_error_percent > 30 * got.floor_percent


def test_a_model_fitted_to_noisy_data_counts_its_coefficients_noise(tmp_path):
    """A model identified from 300 configurations at eps = 1e-3 errs on joint 7's small
    entries by its coefficients' own error (8.4 x eps there): at the floor with them
    counted, not "effects outside the model"."""
    save_static_csv(tmp_path / "train.csv", _acquired(dynid.panda(), 300, 1e-3, 3))
    save_static_csv(tmp_path / "held.csv", _acquired(dynid.panda(), 100, 1e-3, 9))
    assert main(["identify", "--data", str(tmp_path / "train.csv"), "--out",
                 str(tmp_path / "id"), "-q", "--no-figures"]) == 0  # fmt: skip
    model = dynid.io.model_json.load_model_json(tmp_path / "id" / "identification.json")
    got = validate_static_file(model, tmp_path / "held.csv")
    assert got.joint_floor_percent is not None and got.joint_floor_percent[6] > 0.5
    assert got.verdict.label == "at the noise floor", got.verdict.reason


def test_the_command_writes_the_static_validation_and_refuses_log_options(tmp_path, capsys):
    save_static_csv(tmp_path / "s.csv", _acquired(dynid.panda(), 50, 1e-3, 1))
    out = tmp_path / "v"
    argv = ["validate", "--robot", "panda", "--data", str(tmp_path / "s.csv"), "--out", str(out)]
    assert main(argv + ["--no-figures"]) == 0
    doc = json.loads((out / "validation.json").read_text())
    assert doc["schema"] == "dynid-static-validation/1" and doc["n_configurations"] == 50
    assert "match the data's" in (out / "report.html").read_text()
    assert "verdict: at the noise floor" in capsys.readouterr().out
    assert main(argv + ["--cutoff", "5", "--force"]) == 2
    assert "--cutoff applies to torque logs only" in capsys.readouterr().err


def test_static_data_beside_a_torque_log_is_refused(tmp_path):
    save_static_csv(tmp_path / "s.csv", _acquired(dynid.panda(), 5, 0.0, 1))
    log = tmp_path / "log.csv"
    log.write_text("t,q1,q2,q3,q4,q5,q6,q7,dq1,dq2,dq3,dq4,dq5,dq6,dq7,"
                   "tau1,tau2,tau3,tau4,tau5,tau6,tau7\n")  # fmt: skip
    from dynid.workflows.validate_static import static_files

    with pytest.raises(DataError, match="validate judges one kind a call"):
        static_files([tmp_path / "s.csv", log])


@pytest.mark.parametrize(
    ("scale", "level", "said"),
    [
        (1.2, "poor", "the model's M and g miss what the data hold (another arm's links"),
        (3.0, "unusable", "the model does not explain M and g: error 66.7 % (50 % or more"),
    ],
)
def test_a_static_verdict_speaks_of_m_and_g_not_of_torques(tmp_path, scale, level, said):
    """Static data of an arm whose every inertial is `scale` x the Panda's (Pinocchio's M
    and g times `scale`, exactly): the Panda's model errs by 1 - 1 / scale of the data's
    entries (16.7 %: poor; 66.7 %: unusable) and the reason names M and g, never
    excitation, the drive or a log (no motion and no drive in static data)."""
    q, M, g = pinocchio_panda_static(4, 30)
    save_static_csv(tmp_path / "s.csv", StaticDataset(q, scale * M, scale * g))
    got = validate_static_file(dynid.panda(), tmp_path / "s.csv")
    assert got.relative_error_percent == pytest.approx(100 * (1 - 1 / scale), rel=1e-9)
    reason = got.verdict.reason
    assert got.verdict.level == level and said in reason, reason
    for torque_word in ("torque", "excitation", "drive", "a log"):
        assert torque_word not in reason


def test_the_command_prints_each_joints_floor_and_what_no_noise_means(tmp_path, capsys):
    """The table's floor per joint is the recorded relative noise (100 eps % on every
    joint for a model without coefficients' error); a file that records none is judged
    on the relative thresholds, and the line says so."""
    save_static_csv(tmp_path / "s.csv", _acquired(dynid.panda(), 20, 2e-3, 2))
    argv = ["validate", "--robot", "panda", "--data", str(tmp_path / "s.csv"), "--no-figures"]
    assert main(argv + ["--out", str(tmp_path / "v")]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = next(k for k, line in enumerate(lines) if line.startswith("joint"))
    assert head >= 0 and lines[head].rstrip().endswith("noise floor [%]")
    floors = [float(line.split()[-1]) for line in lines[head + 1 : head + 8]]
    assert floors == pytest.approx([0.2] * 7, rel=1e-9)
    q, M, g = pinocchio_panda_static(5, 10)
    save_static_csv(tmp_path / "exact.csv", StaticDataset(q, M, g))
    argv[4] = str(tmp_path / "exact.csv")
    assert main(argv + ["--out", str(tmp_path / "w")]) == 0
    out = capsys.readouterr().out
    assert "the data record no noise: judged on the relative thresholds (below 5 % good" in out
    assert "noise floor [%]" not in out


def test_joints_judged_worse_than_the_pooled_level_are_named_in_static_words():
    """A pooled 8 % (usable) with one joint at 30 % and one at 120 % of its entries: poor by
    its worst joints, in words of M and g; the same numbers as torques keep the torque
    log's words."""
    from dynid.identification.verdict import judge_prediction

    args = dict(joint_percent=[2.0, 30.0, 120.0], joint_names=["a", "b", "c"])
    static = judge_prediction(8.0, None, kind="static", **args)
    assert static.level == "poor", static.reason
    assert "the model's M and g miss what the data hold there" in static.reason
    assert "at 100 % or more: data of another robot, or other kinematics?" in static.reason
    torques = judge_prediction(8.0, None, **args)
    assert (
        "the model misses effects the data show there (model terms, excitation, the drive)"
        in (torques.reason)
        and "a log of another robot" in torques.reason
    )
