"""A load carried at the flange over a long event, against simulated truth.

* a 0.8 kg weight at the flange from 1 s to 5 s (a simulated wrench ``-m g`` at the
  flange, base axes) with a contact on a link on top of it: named as a load within 3 % of
  its mass, not an event, and the contact on top detected;
* a person pushing at a fixed point of link 4 for 2 s while the arm moves: an event,
  never a load;
* a 0.8 kg load held through a whole log (the arm simulated carrying it): named with its
  mass, pointing to ``dynid payload`` rather than the model.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.io.robot.toml import save_toml
from dynid.observer.unmodelled_load import LOAD_FRAME
from dynid.workflows.observe import ObserveOptions, observe_files

MASS, G = 0.8, 9.81


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("carried")
    sim = ["simulate", "--trajectory", "fourier", "-q", "--duration", "6"]
    assert main([*sim, "--seed", "2", "--out", str(d / "free.csv")]) == 0
    weight = f"{LOAD_FRAME}:0,0,{-MASS * G}:1,5"
    hit = "link5:10,-12,5:3,3.3"
    assert main([*sim, "--seed", "3", "--contact", weight, "--contact", hit,
                 "--out", str(d / "carried.csv")]) == 0  # fmt: skip
    push = "link4:15,-10,-5:1.5,3.5"
    assert main([*sim, "--seed", "3", "--contact", push, "--out", str(d / "push.csv")]) == 0
    loaded = dynid.panda().with_tool(
        np.eye(4), mass=MASS, com=(0.0, 0.0, 0.0), inertia=np.diag([1e-4] * 3), parent=LOAD_FRAME
    )
    save_toml(d / "loaded.toml", loaded)
    robot = ["--robot", str(d / "loaded.toml")]
    assert main([*sim, *robot, "--seed", "5", "--out", str(d / "loaded.csv")]) == 0
    cal = ["observe", "--params", "panda", "--no-figures", "-q", "--calibrate"]
    assert main([*cal, "--data", str(d / "free.csv"), "--out", str(d / "cal")]) == 0
    return d


def _detect(d, name):
    opts = ObserveOptions(
        data=(d / name,), params="panda", thresholds=d / "cal" / "thresholds.json", frame="flange"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return observe_files(opts)


def test_a_carried_load_is_named_and_the_contact_on_top_is_found(logs):
    result = _detect(logs, "carried.csv")
    (log,) = result.logs
    (load,) = log.loads
    assert load.mass == pytest.approx(MASS, rel=0.03)
    assert load.picked == pytest.approx(1.0, abs=0.02)
    assert load.released == pytest.approx(5.0, abs=0.02)
    assert not load.whole
    assert not any(e.end - e.start > 1.0 for e in log.events)  # the load is no event
    assert any(2.9 <= e.start <= 3.3 for e in log.events)  # the contact on top
    said = [x for x in result.notes if "load: 0.8" in x]
    assert said and "picked and released; not a contact" in said[0]


def test_a_long_push_at_a_fixed_point_is_not_a_load(logs):
    (log,) = _detect(logs, "push.csv").logs
    assert log.loads == ()
    assert any(e.start < 1.7 and e.end > 3.3 for e in log.events)


def test_a_load_held_through_the_log_is_named_with_payload_advice(logs):
    result = _detect(logs, "loaded.csv")
    (load,) = result.logs[0].loads
    assert load.whole and load.mass == pytest.approx(MASS, rel=0.08)
    notes = " ".join(result.notes)
    assert "dynid payload" in notes and "dynid validate" not in notes
