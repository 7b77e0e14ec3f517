"""The identify report's headline names each joint above its noise with the number the
held-out verdict's reason gives it (the verdict weighs each sample against its own noise;
the headline once divided the RMS error by the mean noise: 9.3 x against 9.45 x, and
named a joint the verdict did not)."""

from __future__ import annotations

import html
import json
import re
import warnings

import numpy as np

from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.io.robot_file import load_robot
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise

from conftest import SO101_URDF, recordings


def _spring(log):
    """An unmodelled spring at the second joint [N m]."""
    out = np.zeros_like(log.tau)
    out[:, 1] = -0.3 * (log.q[:, 1] - 0.2)
    return out


def test_identify_headline_and_verdict_give_each_joint_one_ratio(tmp_path):
    """Headline, verdict reason, torques table and heldout.json agree on every joint's
    error over its noise, on a log whose states' noise varies (Coulomb friction)."""
    robot = load_robot(str(SO101_URDF), snap_angles=True)
    fr = ClassicalFriction(np.full(5, 0.02), np.full(5, 0.05), np.zeros(5))
    noise = SensorNoise(tau_std=0.005, dq_std=0.01)
    (log,) = recordings(robot, (3,), friction=fr, duration=6.0, noise=noise, added=_spring)
    path = save_torque_log(tmp_path / "a.npz", log)
    out = tmp_path / "id"
    args = ["identify", "--robot", str(SO101_URDF), "--snap-angles", "--data", str(path)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        main([*args, "--out", str(out), "--terms", "viscous,coulomb", "-q", "--no-figures"])
    held = json.loads((out / "heldout.json").read_text())
    reason = dict(re.findall(r"(\w+) at ([\d.]+) x \(", held["verdict"]["reason"]))
    assert "shoulder_lift" in reason  # the spring's joint
    page = html.unescape(re.sub(r"<[^>]+>", "", (out / "report.html").read_text()))
    headline = page[page.index("The model predicts held-out torques") :].split(".\n")[0]
    said = dict(re.findall(r"(\w+) at ([\d.]+) x its noise", headline))
    assert said == reason
    names = held["joint_names"]
    for name, r in reason.items():
        assert float(r) == float(f"{held['joint_ratios'][names.index(name)]:.3g}")
    # the table's ratio column says it is the weighed one, not RMS over a noise column
    assert "error / noise (each sample against its own)" in page
    assert "not the quotient of the pooled percentages" in held["verdict"]["reason"]


def test_validate_report_gives_the_worst_joint_the_verdicts_ratio(tmp_path):
    """validate on the same kind of log: validation.json's joint_ratios are the numbers
    of the verdict's reason, and the report's worst joint line gives the largest."""
    robot = load_robot(str(SO101_URDF), snap_angles=True)
    fr = ClassicalFriction(np.full(5, 0.02), np.full(5, 0.05), np.zeros(5))
    noise = SensorNoise(tau_std=0.005, dq_std=0.01)
    logs = recordings(robot, (3, 4), friction=fr, duration=4.0, noise=noise, added=_spring)
    paths = [save_torque_log(tmp_path / f"{k}.npz", g) for k, g in enumerate(logs)]
    args = ["--robot", str(SO101_URDF), "--snap-angles", "--no-figures", "-q"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        main(["identify", *args, "--data", str(paths[0]), "--out", str(tmp_path / "id")])
        model = str(tmp_path / "id" / "identification.json")
        main(
            [
                "validate",
                "--model",
                model,
                "--data",
                str(paths[1]),
                "--out",
                str(tmp_path / "v"),
                "--no-figures",
                "-q",
            ]
        )
    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    reason = dict(re.findall(r"(\w+) at ([\d.]+) x \(", doc["verdict"]["reason"]))
    assert reason, doc["verdict"]["reason"]
    names, r = doc["joint_names"], doc["joint_ratios"]
    for name, said in reason.items():
        assert float(said) == float(f"{r[names.index(name)]:.3g}")
    page = html.unescape(re.sub(r"<[^>]+>", "", (tmp_path / "v" / "report.html").read_text()))
    worst = max(range(len(r)), key=lambda j: r[j])
    assert f"{names[worst]}: relative error" in page and f"{r[worst]:.3g} x its noise" in page
