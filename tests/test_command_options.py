"""Each command's policy lives in its library entry point, which takes typed options: the
Python API and the command refuse the same input (an ``OptionError`` carrying the field,
which the command names by its flag) and give the same result."""

from __future__ import annotations

from pathlib import Path

import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.cli.common import flag, option_message
from dynid.exceptions import OptionError
from dynid.workflows.identify import IdentifyOptions, identify_files


@pytest.fixture(scope="module")
def static(tmp_path_factory) -> Path:
    """Static data of the Panda (40 configurations, noise-free)."""
    path = tmp_path_factory.mktemp("options") / "s.csv"
    assert main(["acquire-static", "--n", "40", "--seed", "3", "--out", str(path), "-q"]) == 0
    return path


def _refusal(capsys, argv: list[str]) -> str:
    """The one error line of a refused command (exit 2), without its prefix."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    prefix = f"dynid {argv[0]}: error: "
    assert err[0].startswith(prefix), err
    return err[0][len(prefix) :]


def test_an_option_error_names_its_field_in_the_api_and_its_flag_on_the_command_line():
    exc = OptionError("applies with {unmodelled} only", field="arm_seed", others=("unmodelled",))
    assert str(exc) == "arm_seed applies with unmodelled only"
    assert option_message(exc) == "--arm-seed applies with --unmodelled only"
    assert exc.field == "arm_seed" and isinstance(exc, ValueError)
    assert option_message(OptionError("no field: as it is")) == "no field: as it is"
    assert flag("cutoff_hz") == "--cutoff" and flag("max_gap_s") == "--max-gap"


@pytest.mark.parametrize(
    ("options", "argv", "field"),
    [
        ({"prior": "panda"}, ["--prior", "panda"], "prior"),
        ({"total_mass": (16.0, 20.0)}, ["--total-mass", "16,20"], "total_mass"),
        (
            {"consistent": True, "max_std_percent": 30.0},
            ["--consistent", "--max-std-percent", "30"],
            "max_std_percent",
        ),
        ({"terms": "armature,viscous"}, ["--terms", "armature,viscous"], "terms"),
        ({"terms": "viscous,smooth,coulomb"}, ["--terms", "viscous,smooth,coulomb"], "terms"),
        ({"folds": 3}, ["--folds", "3"], "folds"),
        ({"consistent": True, "max_gap_s": 0.1}, ["--consistent", "--max-gap", "0.1"], "max_gap_s"),
    ],
    ids=["prior", "mass-band", "prune-consistent", "terms-static", "terms-smooth", "folds", "gap"],
)
def test_identify_refuses_alike(static, tmp_path, capsys, options, argv, field):
    """identify's policies (consistent-only options, options of torque logs given static
    data, terms that do not go together) through identify_files and dynid identify."""
    panda = dynid.panda()
    with pytest.raises(OptionError) as api:
        identify_files(panda, static, IdentifyOptions(**options))
    assert api.value.field == field
    line = _refusal(
        capsys, ["identify", "--data", str(static), *argv, "--out", str(tmp_path / "o")]
    )
    assert line == option_message(api.value) and line.startswith(flag(field))
    assert not (tmp_path / "o").exists()


def test_identify_gives_the_same_model_through_both(static, tmp_path):
    """The coefficients of dynid identify are those of identify_files (with an option
    that changes them: pruning)."""
    import json

    model = identify_files(dynid.panda(), static, IdentifyOptions(max_std_percent=30.0)).model
    out = tmp_path / "id"
    argv = ["identify", "--data", str(static), "--max-std-percent", "30", "--out", str(out)]
    assert main([*argv, "-q"]) == 0
    doc = json.loads((out / "identification.json").read_text())
    got = [(c["value"], c["kept"]) for c in doc["coefficients"]]
    want = [(float(b), bool(k)) for b, k in zip(model.fit.beta, model.fit.kept, strict=False)]
    assert got == want[: len(got)] and len(got) == model.base.rank
