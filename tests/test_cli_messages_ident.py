"""Messages that say what is true, in the command line's words: a missing input file
named with its option, ``export`` of an identification.json pointed to what makes link
parameters, a drive mismatch naming the key, ``--terms -LABEL`` refusals that read as
sentences, hints with flags instead of Python, and ``simulate --help`` with its defaults.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.cli.common import cli_text
from dynid.exceptions import DataError, OptionError
from dynid.friction.fit import model_drive
from dynid.identification.structure import Structure
from dynid.io.json_files import save_json
from dynid.model.drive import Drive


def _error(argv, capsys):
    assert main(argv) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    return line


@pytest.mark.parametrize(
    "argv",
    [
        ["identify", "--robot", "panda", "--data", "{d}/nope.csv", "--out", "{d}/o"],
        ["validate", "--model", "{d}/nope.json", "--data", "{d}/x.csv", "--out", "{d}/o"],
        ["observe", "--params", "panda", "--data", "{d}/x.csv", "--thresholds",
         "{d}/nope.json", "--out", "{d}/o"],
        ["excite", "--robot", "panda", "--obstacles", "{d}/nope.json", "--out", "{d}/o"],
    ],
)  # fmt: skip
def test_a_missing_input_file_is_named_with_its_option(tmp_path, capsys, argv):
    argv = [a.format(d=tmp_path) for a in argv]
    sim = ["simulate", "--robot", "panda", "--duration", "1", "--rate", "200", "-q"]
    assert main([*sim, "--out", str(tmp_path / "x.csv")]) == 0  # present: the others named
    capsys.readouterr()
    line = _error(argv, capsys)
    missing = next(a for a in argv if "nope" in a)
    flag = argv[argv.index(missing) - 1]
    assert line.endswith(f"error: nope.{missing.split('.')[-1]}: {flag}: {missing} does not exist")
    assert not (tmp_path / "o").exists()


def test_files_joined_by_a_comma_are_told_to_be_separated_by_spaces(tmp_path, capsys):
    """Regression (``--data a.csv,b.csv`` said only that the joined name does not exist):
    when every comma-separated part exists, the hint gives the option with them apart."""
    sim = ["simulate", "--robot", "panda", "--duration", "1", "--rate", "200", "-q"]
    for name in ("a.csv", "b.csv"):
        assert main([*sim, "--out", str(tmp_path / name)]) == 0
    capsys.readouterr()
    joined = f"{tmp_path / 'a.csv'},{tmp_path / 'b.csv'}"
    line = _error(["identify", "--robot", "panda", "--data", joined, "--out", "o"], capsys)
    assert line.endswith(
        f"does not exist; hint: separate the files with spaces, --data {tmp_path / 'a.csv'} "
        f"{tmp_path / 'b.csv'}"
    )


def test_export_of_base_parameters_says_what_makes_link_parameters(tmp_path, capsys):
    path = tmp_path / "identification.json"
    save_json(path, {"coefficients": []}, schema="dynid-identified-model/1")
    line = _error(["export", "--params", str(path), "--out", str(tmp_path / "r.urdf")], capsys)
    assert "--params: identification.json holds base parameters" in line
    assert "dynid retrieve --model" in line and "dynid identify --consistent" in line


def test_a_drive_mismatch_names_the_key_that_differs():
    robot = dynid.panda()
    ident = Drive(np.diag(np.full(7, 50.0)), np.zeros(7), side="motor")
    other = dataclasses.replace(ident, offset=np.full(7, 0.1))
    model = dynid.IdentifiedModel.__new__(dynid.IdentifiedModel)  # only its drive is read
    object.__setattr__(model, "drive", ident)
    object.__setattr__(model, "robot", robot)
    assert model_drive(model, ident) is ident
    with pytest.raises(DataError, match=r"differs .* identified with: offset = \[0\.1"):
        model_drive(model, other)


@pytest.mark.parametrize(
    ("terms", "message"),
    [
        (
            "viscous,-fc1",
            r"--terms -fc1: .fc. is none of the coefficients of the terms given \(fv\)",
        ),
        ("viscous,-fv", "--terms -fv: give the joint number from 1 after the label"),
        ("viscous,-fv0", "--terms -fv0: give the joint number from 1 after the label"),
    ],
)
def test_leaving_out_a_coefficient_is_explained_in_words(terms, message):
    with pytest.raises(OptionError, match=message):
        Structure.parse(terms)


def test_a_python_hint_becomes_its_flag():
    text = "x.csv: NaN; hint: fix the file or pass --drop-invalid (drop_invalid=True) to drop them"
    assert cli_text(text) == "x.csv: NaN; hint: fix the file or pass --drop-invalid to drop them"
    assert cli_text("hint: drop them when loading (drop_invalid=True)") == (
        "hint: drop them when loading (--drop-invalid)"
    )


def test_simulate_help_shows_the_noise_defaults(capsys):
    assert main(["simulate", "--help"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "position noise std [rad] (default 1e-4)" in out
    assert "velocity noise std [rad/s] (default 1e-3)" in out
