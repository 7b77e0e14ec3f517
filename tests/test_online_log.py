"""A log read for the control loop as the identified model reads it
(:func:`~dynid.workflows.observe.read_log_as_identified`, what ``dynid observe --model``
runs). Regression: the tutorial's loop read the log with ``load_torque_log``, which
applies none of the model's record; on an arm whose joint 3 torque is logged with the
opposite sign (the model identified with ``--units tau3=-1``) the observer raised a
contact at the second sample. Truth: a simulated 3R arm, its exact torques with a known
external torque injected on joint 1, joint 2's torque (the one gravity loads) written
negated; the model fitted to exact logs of the truth."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from dynid.exceptions import DataError, WrongTypeError
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.friction_json import save_friction_json
from dynid.io.model_json import load_model_json, save_model_json
from dynid.io.observer_files import save_thresholds
from dynid.io.torque_log import load_torque_log, save_torque_log
from dynid.model.drive import Drive
from dynid.model.robot import Robot
from dynid.observer import from_identified
from dynid.observer.residual import DEFAULT_OPTIONS, MomentumObserver
from dynid.observer.thresholds import Thresholds
from dynid.workflows.observe import read_log_as_identified

from conftest import recordings

DOCS = Path(__file__).resolve().parents[1] / "docs" / "tutorials" / "collision-detection.md"

#: The injected external torque on joint 1 [N m]: a plateau of 2 N m from ONSET [s],
#: reached through a 10 ms ramp, for 0.3 s; a fixed contact level [N m] on every joint.
ONSET, PUSH, LEVEL = 1.5, 2.0, 0.5


def _arm() -> Robot:
    """A spatial 3R arm (its flange turned about three axes)."""
    inertia = [np.diag([0.02, 0.02, 0.01]), np.diag([0.03, 0.03, 0.01]), np.diag([0.01] * 3)]
    return Robot.from_mdh(
        [0.0, 0.0, 0.4],
        [0.3, 0.0, 0.0],
        [0.0, -np.pi / 2, np.pi / 2],
        flange=(0.0, 0.1, 0.0, 0.0),
        mass=[2.0, 1.5, 1.0],
        com=[[0, 0, -0.1], [0.2, 0, 0], [0, 0, 0.05]],
        inertia=np.array(inertia),
        name="arm3",
    )


def _external(t: np.ndarray) -> np.ndarray:
    """The external torque (N, 3) [N m] at the times ``t`` [s]: on joint 1 alone."""
    up = np.clip((t - ONSET) / 0.01, 0.0, 1.0) * np.clip((ONSET + 0.31 - t) / 0.01, 0.0, 1.0)
    out = np.zeros((t.size, 3))
    out[:, 0] = PUSH * up
    return out


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """``id/identification.json`` (fitted to exact logs of the truth, recording ``--units
    tau2=-1``), ``fr/friction.json`` (none: the truth has none), ``cal/thresholds.json``
    (:data:`LEVEL` on every joint) and ``hit.csv``: the truth's exact torques less the
    external torque (the motors hold what the push adds), joint 2's written negated, with
    one row of NaN."""
    root = tmp_path_factory.mktemp("online")
    truth = _arm()
    train = recordings(truth, (1, 2), friction=None, duration=3.0)
    model = identify_recordings(truth, train, cutoff_hz=None, structure=Structure(friction=()))
    info = dataclasses.replace(model.info, column_map={"columns": None, "units": "tau2=-1"})
    for sub in ("id", "fr", "cal"):
        (root / sub).mkdir()
    save_model_json(root / "id" / "identification.json", dataclasses.replace(model, info=info))
    save_friction_json(root / "fr" / "friction.json", ClassicalFriction(*np.zeros((3, 3))))
    level = np.full(3, LEVEL)
    th = Thresholds(level, 2 * level, 1.5, 1.0, 2.0, DEFAULT_OPTIONS, 1)
    save_thresholds(root / "cal" / "thresholds.json", th, joints=truth.joint_names)
    (log,) = recordings(truth, (9,), friction=None, duration=3.0)
    tau = (log.tau - _external(log.t)) * [1.0, -1.0, 1.0]  # as the arm logs joint 2
    path = save_torque_log(root / "hit.csv", dataclasses.replace(log, tau=tau, ddq=None))
    lines = path.read_text().splitlines()
    head = next(k for k, x in enumerate(lines) if x.startswith("t,"))
    cells = lines[head + 200].split(",")
    lines[head + 200] = ",".join(cells[:1] + ["nan"] * (len(cells) - 1))
    path.write_text("\n".join(x for x in lines if not x.startswith("# rows")) + "\n")
    return root


def _crossings(log, model) -> tuple[np.ndarray, np.ndarray]:
    """The residual (N, 3) [N m] of the observer stepped sample by sample, and the times
    [s] it lies over :data:`LEVEL` on some joint."""
    observer = MomentumObserver(from_identified(model))
    r = np.array(
        [observer.step(log.q[k], log.dq[k], log.tau[k], log.t[k]) for k in range(len(log.t))]
    )
    return r, log.t[np.any(np.abs(r) > LEVEL, axis=1)]


def test_the_log_read_as_identified_gives_the_push_and_no_false_contact(folder):
    """Read as the model reads it (joint 2 negated back), the residual stays under the
    level until the push and crosses it on joint 1 within 20 ms of its onset, reaching the
    injected 2 N m; the file read as it is (``load_torque_log``) is over the level from the
    second sample on, on joint 2 (the tutorial's loop before)."""
    model = load_model_json(folder / "id" / "identification.json")
    log = read_log_as_identified(folder / "hit.csv", model, drop_invalid=True)
    r, over = _crossings(log, model)
    assert over.size and ONSET <= over[0] < ONSET + 0.02
    assert np.all(over <= ONSET + 0.31 + 0.2)  # the push's own decay, nothing after
    plateau = (log.t > ONSET + 0.2) & (log.t < ONSET + 0.3)
    np.testing.assert_allclose(r[plateau], _external(log.t[plateau]), atol=0.02)
    raw = load_torque_log(folder / "hit.csv", drop_invalid=True)
    r_raw, over_raw = _crossings(raw, model)
    assert over_raw.size and over_raw[0] == raw.t[1] and abs(r_raw[1, 1]) > LEVEL


def test_invalid_rows_are_refused_unless_dropped(folder):
    """The NaN row is refused, naming it, without ``drop_invalid`` (the model's
    identification dropped none), and dropped with it."""
    model = load_model_json(folder / "id" / "identification.json")
    with pytest.raises(DataError, match="hit.csv"):
        read_log_as_identified(folder / "hit.csv", model)
    log = read_log_as_identified(folder / "hit.csv", model, drop_invalid=True)
    assert log.n_samples == 1500 and np.all(np.isfinite(log.tau))


def test_the_tutorials_control_loop_runs_as_written(folder, monkeypatch, capsys):
    """The Python block of the tutorial's "In the control loop" section, run as written in
    the folder: it prints the push's contact within 20 ms of the injected onset."""
    text = DOCS.read_text("utf-8")
    section = text[text.index("## 4. In the control loop") :]
    code = re.search(r"```python\n(.*?)```", section, re.S)
    assert code is not None
    monkeypatch.chdir(folder)
    exec(compile(code.group(1), str(DOCS), "exec"), {})
    said = re.search(r"contact at t = ([0-9.]+) s", capsys.readouterr().out)
    assert said is not None and ONSET <= float(said.group(1)) < ONSET + 0.02


def test_a_motor_side_current_log_is_read_at_the_joints(folder, tmp_path):
    """A model recorded with a drive (gears 10, 20, 5 at the motors, currents through
    torque constants 0.1, 0.2, 0.05 N m/A) reads the log of motor angles and currents at
    the joints: ``q = q_m / G``, ``dq = dq_m / G``, ``tau = G k i`` (closed form of a
    diagonal drive), as the observer's step takes them; joint 2's current still negated
    back by the recorded ``tau2=-1``."""
    gears, kt = np.array([10.0, 20.0, 5.0]), np.array([0.1, 0.2, 0.05])
    drive = Drive.from_gears(gears, side="motor", effort="current", torque_constant=kt)
    model = load_model_json(folder / "id" / "identification.json")
    save_model_json(tmp_path / "identification.json", dataclasses.replace(model, drive=drive))
    geared = load_model_json(tmp_path / "identification.json")
    (log,) = recordings(_arm(), (9,), friction=None, duration=1.0)
    current = log.tau / (gears * kt) * [1.0, -1.0, 1.0]  # joint 2 logged negated
    motor = dataclasses.replace(log, q=log.q * gears, dq=log.dq * gears, tau=current, ddq=None)
    read = read_log_as_identified(save_torque_log(tmp_path / "motor.csv", motor), geared)
    np.testing.assert_allclose(read.q, log.q, atol=1e-8)
    np.testing.assert_allclose(read.dq, log.dq, atol=1e-7)
    np.testing.assert_allclose(read.tau, log.tau, rtol=1e-7, atol=1e-8)


def test_the_observer_model_in_place_of_the_identified_one_is_refused_by_name(folder):
    """The observer's model holds no column map: given in place of the identified model,
    one WrongTypeError naming the argument and what it takes."""
    model = load_model_json(folder / "id" / "identification.json")
    with pytest.raises(WrongTypeError, match="model.*IdentifiedModel.*ObserverModel"):
        read_log_as_identified(folder / "hit.csv", from_identified(model))  # type: ignore[arg-type]
