"""The span identify cuts out of a recording (a burst in the fit's own residual) is on the
report's first screen, in the answer box beside the verdict: it changes the data the model
was fitted on. It was only in the collapsed warnings.

Reference: a simulated planar 2R arm with known friction and sensor noise, one of its two
recordings with a 20 N m burst on joint 2 at a known time (2.0 to 2.1 s).
"""

from __future__ import annotations

import dataclasses
import html
import re

import numpy as np

from dynid.cli.__main__ import main
from dynid.friction.model import ClassicalFriction
from dynid.io.robot.toml import save_toml
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise

from conftest import planar_2r, recordings

FRICTION = ClassicalFriction(np.array([0.3, 0.2]), np.array([0.8, 0.5]), np.zeros(2))


def _box(page: str) -> str:
    """The text of the page's answer box (headline and facts)."""
    start = page.index('id="verdict"')
    return html.unescape(re.sub(r"<[^>]+>", "", page[start : page.index("</section>", start)]))


def test_the_cut_span_is_beside_the_verdict(tmp_path):
    """identify of a clean and a burst recording: the answer box names the recording cut,
    its span (around 2.0 to 2.1 s) and why, with --keep-outlying."""
    arm = planar_2r().replace(q_min=(-2.5, -2.5), q_max=(2.5, 2.5))
    clean, burst = recordings(
        arm, (1, 2), friction=FRICTION, duration=4.0, fs=200.0, noise=SensorNoise()
    )
    tau = burst.tau.copy()
    tau[(burst.t >= 2.0) & (burst.t < 2.1), 1] += 20.0
    paths = [
        save_torque_log(tmp_path / "a.csv", clean),
        save_torque_log(tmp_path / "b.csv", dataclasses.replace(burst, tau=tau)),
    ]
    robot = save_toml(tmp_path / "arm.toml", arm)
    args = ["identify", "--robot", str(robot), "--data", *map(str, paths), "--no-figures"]
    out = tmp_path / "out"
    assert main([*args, "--terms", "viscous,coulomb", "-q", "--out", str(out)]) == 0
    box = _box((out / "report.html").read_text())
    (fact,) = [x for x in box.splitlines() if "Cut out of the fit" in x]
    a, b = (float(x) for x in re.findall(r"t = ([\d.]+) to ([\d.]+) s", fact)[0])
    assert 1.8 < a < 2.0 and 2.1 < b < 2.3, fact
    assert "b.csv" in fact and "a burst in the fit's own residual" in fact, fact
    assert "--keep-outlying" in fact
