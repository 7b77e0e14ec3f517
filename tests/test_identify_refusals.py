"""Options that do not apply are refused in one line naming them, never accepted
silently: ``identify --terms`` (a placement without a coupling drive, empty, a term twice),
``--folds`` with several recordings, ``--cutoff``/``--max-gap`` with static data;
``simulate --contact-ramp`` without ``--contact`` and a contact outside the log.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import OptionError
from dynid.io.static_data import save_static_data
from dynid.workflows.identify import IdentifyOptions, identify_files


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("refusals")
    for s in (1, 2):
        args = ["simulate", "--robot", "panda", "--duration", "3", "--rate", "200"]
        assert main([*args, "--seed", str(s), "--out", str(d / f"r{s}.csv"), "-q"]) == 0
    return [str(d / "r1.csv"), str(d / "r2.csv")]


@pytest.fixture(scope="module")
def static(tmp_path_factory):
    panda = dynid.panda()
    ctrl = dynid.SimulatedController(panda, rng=np.random.default_rng(5))
    path = tmp_path_factory.mktemp("static") / "s.csv"
    save_static_data(path, dynid.acquire_static(ctrl, 20, np.random.default_rng(6)))
    return str(path)


def _refused(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    return err[0]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--terms", "viscous,at:motor"], "--terms at:motor: friction at the motors"),
        (["--terms", "viscous,viscous"], "--terms names viscous twice"),
        (["--terms", ""], "--terms is empty"),
        (["--folds", "3"], "--folds sets time blocks of one recording; with 2 recordings"),
    ],
)
def test_identify_refuses_what_does_not_apply_to_logs(logs, tmp_path, capsys, extra, message):
    argv = ["identify", "--robot", "panda", "--data", *logs, "--out", str(tmp_path), *extra]
    assert message in _refused(argv, capsys)


@pytest.mark.parametrize(
    ("extra", "flag"),
    [
        (["--cutoff", "5"], "--cutoff"),
        (["--max-gap", "0.1"], "--max-gap"),
    ],
)
def test_identify_refuses_log_options_with_static_data(static, tmp_path, capsys, extra, flag):
    argv = ["identify", "--robot", "panda", "--data", static, "--out", str(tmp_path), *extra]
    line = _refused(argv, capsys)
    assert f"{flag} applies to torque logs, not static data (s.csv)" in line


def test_the_api_names_the_field(static):
    with pytest.raises(OptionError) as err:
        identify_files(dynid.panda(), static, IdentifyOptions(cutoff_hz=5.0))
    assert err.value.field == "cutoff_hz"


def test_simulate_refuses_a_ramp_without_contact_and_a_contact_outside_the_log(tmp_path, capsys):
    base = ["simulate", "--robot", "panda", "--duration", "2", "--out", str(tmp_path / "x.csv")]
    line = _refused([*base, "--contact-ramp", "0.1"], capsys)
    assert "--contact-ramp applies with --contact only" in line
    line = _refused([*base, "--contact", "link5:0,0,-20:4,4.5"], capsys)
    assert "--contact link5: the window 4 to 4.5 s lies outside the log (0 to 2 s)" in line
    assert not (tmp_path / "x.csv").exists()
