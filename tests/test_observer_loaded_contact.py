"""A contact on an arm carrying a payload its model knows, against simulated truth.

The Panda carries 1.5 kg at the flange (CoM 5 cm out, its own inertia), simulated with it
and observed with a model that holds it (``--params`` the robot with the load):

* a push at the flange is one event, starting within the observer's first-order lag of
  the true onset (the crossing of ``tau (1 - exp(-K t))`` through the calibrated
  threshold, closed form), and a contact-free log with the load raises no event;
* why a loaded arm's contacts are found later: its thresholds are wider, because the
  residual passes the velocities' noise through ``K M(q) dq`` and the load enlarges
  ``M(q)``. Calibrated on the velocities' noise alone, each joint's threshold grows from
  the bare arm's to the loaded arm's as the largest norm of its row of ``M(q)`` over the
  log (Pinocchio's mass matrix), within 15 %.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.io.robot.toml import save_toml
from dynid.io.torque_log import load_torque_log
from dynid.observer.residual import DEFAULT_GAIN
from dynid.workflows.observe import ObserveOptions, observe_files

from conftest import pinocchio_panda_model

MASS, COM = 1.5, np.array([0.0, 0.0, 0.05])  # [kg], [m] in the flange's axes
INERTIA = np.diag([0.004, 0.004, 0.002])  # about the CoM [kg m^2]
FLANGE_Z = 0.107  # the flange on link 7 [m]
RATE = 1000.0
ONSET, RELEASE = 1.5, 2.0  # [s]


def _sim(d, robot, name, seed, *extra):
    args = ["simulate", "--robot", str(robot), "--trajectory", "fourier", "-q"]
    assert main([*args, "--seed", str(seed), *extra, "--out", str(d / name)]) == 0


@pytest.fixture(scope="module")
def loaded(tmp_path_factory):
    d = tmp_path_factory.mktemp("loaded")
    arm = dynid.panda()
    save_toml(d / "plain.toml", arm, friction=arm.friction)
    with_load = arm.with_tool(np.eye(4), MASS, COM, INERTIA, parent="flange", name="load")
    save_toml(d / "loaded.toml", with_load, friction=with_load.friction)
    robot = d / "loaded.toml"
    _sim(d, robot, "free.csv", 2, "--duration", "8")
    _sim(d, robot, "quiet.csv", 4, "--duration", "3")
    _sim(d, robot, "hit.csv", 3, "--duration", "3", "--contact", f"flange:0,8,0:{ONSET},{RELEASE}")
    cal = ["observe", "--params", str(robot), "--no-figures", "-q", "--calibrate"]
    assert main([*cal, "--data", str(d / "free.csv"), "--out", str(d / "cal")]) == 0
    return d


def _detect(d, name):
    opts = ObserveOptions(
        data=(d / name,),
        params=str(d / "loaded.toml"),
        thresholds=d / "cal" / "thresholds.json",
        keep_series=True,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return observe_files(opts)


def test_a_push_on_a_known_payload_is_found_within_the_observer_lag(loaded):
    """One event, starting within the closed-form lag's crossing of the threshold."""
    result = _detect(loaded, "hit.csv")
    (log,) = result.logs
    t, tau = log.t, log.tau_ext
    on = np.abs(tau).max(axis=1) > 0
    t0 = t[on][0]
    assert t0 == pytest.approx(ONSET, abs=1.5 / RATE)
    theta = result.thresholds.contact
    first = np.abs(tau[on][0])
    up = first > theta
    assert up.any()
    rise = float(np.min(-np.log(1.0 - theta[up] / first[up]) / DEFAULT_GAIN))
    (event,) = log.events  # no false alarm
    assert t0 - 1 / RATE <= event.start <= t0 + rise + 5 / RATE


def test_a_contact_free_log_with_the_payload_raises_no_event(loaded):
    """The load the model holds is no contact: no event on a free log carrying it."""
    (log,) = _detect(loaded, "quiet.csv").logs
    assert log.events == []


def test_the_thresholds_grow_with_the_mass_matrix_the_payload_adds(tmp_path, loaded):
    """Velocity noise alone: loaded over bare thresholds = ratio of M's largest row norms."""
    pin = pytest.importorskip("pinocchio")
    quiet = ["--duration", "4", "--noise", "0", "--q-noise", "0", "--dq-noise", "1e-3"]
    levels = {}
    for name in ("plain", "loaded"):
        robot = loaded / f"{name}.toml"
        _sim(tmp_path, robot, f"{name}.csv", 2, *quiet)
        out = tmp_path / f"cal_{name}"
        assert main(["observe", "--params", str(robot), "--no-figures", "-q", "--calibrate",
                     "--data", str(tmp_path / f"{name}.csv"), "--out", str(out)]) == 0  # fmt: skip
        levels[name] = np.array(json.loads((out / "thresholds.json").read_text())["contact"])
    q = load_torque_log(tmp_path / "plain.csv").q[::5]
    load = pin.Inertia(MASS, COM + [0.0, 0.0, FLANGE_Z], INERTIA)
    rows = {}
    for name, model in (
        ("plain", pinocchio_panda_model()),
        ("loaded", pinocchio_panda_model(None, load)),
    ):
        data = model.createData()
        M = np.array([pin.crba(model, data, qk) for qk in q])
        M = np.triu(M) + np.swapaxes(np.triu(M, 1), 1, 2)  # crba fills the upper triangle
        rows[name] = np.linalg.norm(M, axis=2).max(axis=0)
    grew = levels["loaded"] / levels["plain"]
    assert np.all(grew[:4] > 1.25)  # the shoulder and elbow: 30 % and more
    np.testing.assert_allclose(grew[:4], (rows["loaded"] / rows["plain"])[:4], rtol=0.15)
