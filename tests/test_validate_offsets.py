"""What ``validate`` adds to a model's torques is named for what it is: constant torque
offsets are not friction (an identified model with the offset term alone was validated as
"RMS + friction", "with friction (classical)")."""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np

from dynid.cli.__main__ import main
from dynid.friction.model import ClassicalFriction, FrictionSum, SigmoidFriction, friction_words
from dynid.io.friction_json import save_friction_json
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive

from conftest import recordings

OFFSETS = np.array([0.4, -0.3, 0.2, 0.5, -0.1, 0.15, -0.05])  # N m


def test_friction_words_tell_offsets_from_friction():
    """Constant torques read as offsets, velocity-dependent ones as friction, both as
    both, wherever each part acts."""
    z = np.zeros(7)
    assert friction_words(ClassicalFriction(z, z, OFFSETS)) == "offsets"
    assert friction_words(ClassicalFriction(z + 0.1, z, OFFSETS)) == "friction and offsets"
    assert friction_words(ClassicalFriction(z, z + 0.2, z)) == "friction"
    assert friction_words(SigmoidFriction(z + 1.0, z + 20.0, z + 0.01)) == "friction"
    drive = Drive.from_gears(np.full(7, 2.0))
    both = FrictionSum(
        (ClassicalFriction(z, z, OFFSETS).at(drive), ClassicalFriction(z, z + 0.2, z))
    )
    assert friction_words(both) == "friction and offsets"
    assert friction_words(None) == "friction"


def test_validate_names_offsets_as_offsets(panda, tmp_path):
    """Regression: validate printed "RMS + friction" and its report "with friction" for a
    model that adds torque offsets only; the table, validation.json and the report now say
    offsets (and the offsets remove the error they explain)."""
    (log,) = recordings(
        panda, (7,), friction=None, duration=3.0, added=lambda g: g.tau * 0 + OFFSETS
    )
    save_torque_log(tmp_path / "rec.csv", log)
    z = np.zeros(7)
    save_friction_json(tmp_path / "offsets.json", ClassicalFriction(z, z, OFFSETS))
    argv = ["validate", "--robot", "panda", "--friction", str(tmp_path / "offsets.json")]
    argv += ["--data", str(tmp_path / "rec.csv"), "--out", str(tmp_path / "v"), "--no-figures"]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(argv) == 0
    text = out.getvalue()
    assert "RMS + offsets [N m]" in text and "RMS no offsets [N m]" in text
    assert "friction" not in text.split("\n", 1)[0]
    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert doc["friction_terms"] == "offsets"
    assert (
        doc["with_friction"]["relative_error_percent"]
        < 0.1 * (doc["without_friction"]["relative_error_percent"])
    )
    page = (tmp_path / "v" / "report.html").read_text()
    assert "with offsets" in page and "with friction" not in page
