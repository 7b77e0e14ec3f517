"""``identify`` under a ``--units`` whose torque signs read the files the wrong way (logs
already in dynid's sign read with ``tau=-1``, or with a joint's ``tau3=-1`` they do not
need): refused with the ``--units`` that read the files right given those applied, not
the very flip applied (it once hinted ``--units tau=-1`` to a run given ``--units
tau=-1``). Following the hint, the fit's residual falls to the simulated sensors' noise."""

from __future__ import annotations

import dataclasses
import json
import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

#: The simulated torque sensors' noise [N m]: the truth the fit's residual falls to.
TAU_STD = 0.01


def _negated(log):
    """``log`` with every torque column negated (a controller of the other convention)."""
    return dataclasses.replace(log, tau=-log.tau)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Two Panda logs in dynid's sign (a.csv, b.csv) and b.csv negated (nb.csv)."""
    a, b = recordings(
        dynid.panda(), (3, 4), friction=None, duration=3.0, noise=SensorNoise(tau_std=TAU_STD)
    )
    d = tmp_path_factory.mktemp("idsign")
    save_torque_log(d / "a.csv", a)
    save_torque_log(d / "b.csv", b)
    save_torque_log(d / "na.csv", _negated(a))
    return d


def _identify(d, names, units, out, *extra):
    """identify's exit code and its error line (the last one of stderr)."""
    args = ["identify", "--robot", "panda", "--data", *(str(d / n) for n in names)]
    args += ["--out", str(out), "--terms", "links", "--units", units, "--no-figures", *extra]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return main(args)


def _hint(text):
    return re.search(r"hint: --units (\S+)", text).group(1)


@pytest.mark.parametrize(
    ("names", "units", "hint"),
    [
        (["a.csv", "b.csv"], "tau=-1", "tau=1"),
        (["a.csv", "b.csv"], "tau=-1,tau3=-1", "tau=1"),
        (["na.csv", "b.csv"], "tau=-1", "tau=-1,b.csv:tau=-1"),
        (["a.csv", "b.csv"], "tau=-1,b.csv:tau=-1", "tau=1"),
    ],
    ids=["every-file", "every-joint-but-one", "one-file-of-two", "a-files-entry"],
)
def test_identify_hints_the_units_that_read_the_files_right(
    files, tmp_path, capsys, names, units, hint
):
    """Refused naming the files' sign under the units given; the hint is no relative
    flip (``tau=-1`` again) but the --units that read every file right; following it,
    the residual is below the sensors' noise (0.01 N m; the filter lowers it)."""
    assert _identify(files, names, units, tmp_path / "x") == 2
    err = capsys.readouterr().err
    assert "the sign map given (--units " + units + ")" in err
    assert _hint(err) == hint
    assert _identify(files, names, _hint(err), tmp_path / "y", "-q") == 0
    fit = json.loads((tmp_path / "y" / "identification.json").read_text())
    assert fit["residual_rms"] < TAU_STD


def test_identify_consistent_hints_the_units_that_read_the_files_right(files, tmp_path, capsys):
    """identify --consistent reads the files as identify does: the same hint."""
    assert _identify(files, ["a.csv", "b.csv"], "tau=-1", tmp_path / "x", "--consistent") == 2
    assert _hint(capsys.readouterr().err) == "tau=1"


def test_units_that_read_the_files_right_are_not_doubted(files, tmp_path, capsys):
    """na.csv negated, read with tau=-1: no sign finding."""
    assert _identify(files, ["na.csv"], "tau=-1", tmp_path / "x", "-q") == 0
    assert "sign" not in capsys.readouterr().err


def _run(command, d, names, units, out, *extra):
    """A command on the files ``names`` with ``--units units``: its exit code."""
    args = [command, "--robot", "panda", "--data", *(str(d / n) for n in names)]
    args += ["--out", str(out), "--units", units, *extra]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return main(args)


def test_friction_hints_the_units_that_read_the_files_right(files, tmp_path, capsys):
    """friction on logs in dynid's sign read with tau=-1 once fitted friction that pushes
    the arm (a law set aside, "check the sign of tau1, tau4, tau5"); now refused with
    --units tau=1, and following it the residual per joint is within twice the sensors' noise (the
    derived accelerations' error adds to it)."""
    names = ["a.csv", "b.csv"]
    assert _run("friction", files, names, "tau=-1", tmp_path / "x", "--no-figures") == 2
    err = capsys.readouterr().err
    assert "the sign map given (--units tau=-1)" in err and _hint(err) == "tau=1"
    assert _run("friction", files, names, _hint(err), tmp_path / "y", "--no-figures", "-q") == 0
    doc = json.loads((tmp_path / "y" / "friction.json").read_text())
    assert max(j["rms_after"] for j in doc["joints"]) < 2 * TAU_STD


def test_payload_hints_the_units_that_read_the_files_right(tmp_path, capsys):
    """payload on logs of a loaded Panda in dynid's sign read with tau=-1 hinted --units
    tau=-1 again; now --units tau=1, and following it the load's mass is the simulated
    one within 4 of its standard deviations."""
    mass, com = 0.83, np.array([0.012, -0.021, 0.064])
    loaded = dynid.panda().with_tool(np.eye(4), mass, com, np.diag([2e-3, 3e-3, 4e-3]))
    noise = SensorNoise(tau_std=TAU_STD)
    logs = recordings(loaded, (5, 6), friction=None, duration=3.0, noise=noise)
    for seed, log in zip((5, 6), logs, strict=True):
        save_torque_log(tmp_path / f"l{seed}.csv", log)
    names = ["l5.csv", "l6.csv"]
    assert _run("payload", tmp_path, names, "tau=-1", tmp_path / "x") == 2
    err = capsys.readouterr().err
    assert "the sign map given (--units tau=-1)" in err and _hint(err) == "tau=1"
    assert _run("payload", tmp_path, names, _hint(err), tmp_path / "y", "-q") == 0
    doc = json.loads((tmp_path / "y" / "payload.json").read_text())
    assert abs(doc["mass"] - mass) < 4 * doc["std"]["mass"]


def test_the_held_out_log_gets_its_own_entry_beside_the_units(files, tmp_path, capsys):
    """--validate-on b.csv (in dynid's sign) beside na.csv (negated), given tau=-1: the
    held-out log was refused with --units tau=-1 (read again as the flip applied); now
    with --units tau=-1,b.csv:tau=-1, which reads both; following it, the fit's residual
    is below the sensors' noise."""
    extra = ("--validate-on", str(files / "b.csv"))
    assert _identify(files, ["na.csv"], "tau=-1", tmp_path / "x", *extra) == 2
    err = capsys.readouterr().err
    assert "b.csv: the file looks already in dynid's sign" in err
    assert _hint(err) == "tau=-1,b.csv:tau=-1"
    assert _identify(files, ["na.csv"], _hint(err), tmp_path / "y", "-q", *extra) == 0
    fit = json.loads((tmp_path / "y" / "identification.json").read_text())
    assert fit["residual_rms"] < TAU_STD


def test_units_reading_writes_the_fewest_entries():
    """The --units text that reads each file with its torques negated, by hand."""
    from dynid.io.sign_entries import units_reading

    assert units_reading("tau=-1", {"a.csv": [], "b.csv": []}, 6) == "tau=1"
    assert units_reading("tau=-1", {"a.csv": range(6), "b.csv": []}, 6) == "tau=-1,b.csv:tau=-1"
    assert units_reading("q=deg,tau=-1,b.csv:tau=-1", {"a.csv": [], "b.csv": [2]}, 6) == (
        "q=deg,tau=1,b.csv:tau3=-1"
    )
    assert units_reading("tau=-1", {"a.csv": range(6), "b.csv": [0, 1, 3, 4, 5]}, 6) == (
        "tau=-1,b.csv:tau3=-1"
    )
    flips = "tau3=-1,tau4=-1"  # every file's flips stay: b.csv's own entries add to them
    assert units_reading(flips, {"a.csv": [2, 3], "b.csv": [2]}, 6) is None
