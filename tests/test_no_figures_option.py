"""Every command that writes an output folder of its own runs takes ``--no-figures``: the
ones that draw figures skip them, ``payload`` (which draws none) accepts it and writes the
same files. ``demo`` runs the paper's stages as written, figures included."""

from __future__ import annotations

import argparse

import pytest

from dynid.cli import __main__ as cli

FOLDER_COMMANDS = [
    name
    for name in cli.SUBCOMMANDS
    if getattr(cli.importlib.import_module(f"dynid.cli.{name}"), "OUTPUT", None) == "folder"
    and name != "demo"
]


def _options(command: str) -> set[str]:
    """The option strings of one subcommand's parser."""
    parser = cli.build_parser((command,))
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return set(next(iter(sub.choices.values()))._option_string_actions)


@pytest.mark.parametrize("command", FOLDER_COMMANDS)
def test_every_folder_command_takes_no_figures(command):
    """Regression: `dynid payload ... --no-figures` (and excite's) was refused as an
    unknown option, while identify, friction, validate, observe and retrieve took it."""
    assert "--no-figures" in _options(command)


def test_payload_runs_with_no_figures(tmp_path):
    """payload --no-figures: exit 0 and its files (it draws no figure), and the 1 kg load
    the log was simulated with (Newton-Euler of the arm with the load) is found."""
    import numpy as np

    import dynid
    from dynid.io.torque_log import save_torque_log

    robot = dynid.panda()
    load = dict(mass=1.0, com=(0.0, 0.0, 0.05))
    arm = robot.with_tool(np.eye(4), name="load", **load)
    rng = np.random.default_rng(21)
    t = np.arange(0, 3.0, 0.02)
    w = rng.uniform(1.5, 3.0, robot.n)
    a = rng.uniform(0.2, 0.5, robot.n)
    mid = 0.5 * (robot.q_min + robot.q_max)
    q = mid + a * np.sin(np.outer(t, w))
    dq = a * w * np.cos(np.outer(t, w))
    ddq = -a * w**2 * np.sin(np.outer(t, w))
    log = dynid.TorqueLog(t, q, dq, dynid.rnea(arm, q, dq, ddq))
    data = save_torque_log(tmp_path / "loaded.csv", log)
    out = tmp_path / "out"
    argv = ["payload", "--robot", "panda", "--data", str(data), "--out", str(out), "-q"]
    assert cli.main([*argv, "--no-figures"]) == 0
    assert (out / "payload.json").exists() and not list(out.glob("*.png"))
    import json

    assert json.loads((out / "payload.json").read_text())["mass"] == pytest.approx(1.0, abs=0.02)
