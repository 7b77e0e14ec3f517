"""Messages that say what is true (issue 28): each case was a message that misled.

Every case runs the command line in this process and checks the one line it prints (or the
refusal of an option that does not apply to the route taken).
"""

from __future__ import annotations

import contextlib
import io
import subprocess
from pathlib import Path

import numpy as np
import pytest

from dynid.cli.__main__ import main, out_of_memory
from dynid.friction.laws import LAWS
from dynid.io.friction_json import save_friction_json


def _main(*args: str) -> subprocess.CompletedProcess:
    """``dynid *args`` in this process: its exit code, stdout and stderr."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return subprocess.CompletedProcess(["dynid", *args], code, out.getvalue(), err.getvalue())


@pytest.fixture(scope="module")
def one_configuration(tmp_path_factory) -> Path:
    """Static data of one configuration: 34 rows for the Panda's 43 base parameters."""
    path = tmp_path_factory.mktemp("messages") / "one.csv"
    assert _main("acquire-static", "--n", "1", "--seed", "1", "--out", str(path)).returncode == 0
    return path


@pytest.mark.parametrize("stack_bytes", [None, "1000"], ids=["stacked", "streamed"])
def test_too_few_rows_name_the_dependent_columns(
    one_configuration, tmp_path, monkeypatch, stack_bytes
):
    """Fewer rows than coefficients names columns of a null direction; it said "nearly
    dependent columns: ?" (and the streamed fit lost its names)."""
    if stack_bytes is not None:
        monkeypatch.setenv("DYNID_MAX_STACK_BYTES", stack_bytes)
    r = _main("identify", "--data", str(one_configuration), "--out", str(tmp_path / "id"))
    assert r.returncode == 2
    assert "rank 28 < 43" in r.stderr and "nearly dependent columns: beta" in r.stderr, r.stderr
    assert "?" not in r.stderr


def test_a_huge_pool_is_refused_naming_pool(tmp_path):
    """``acquire-static --pool 1000000000``: refused before sampling, naming --pool (it said
    "give a smaller n", and a smaller pool that ran out of memory got a hint about logs)."""
    r = _main("acquire-static", "--pool", "1000000000", "--out", str(tmp_path / "s.csv"))
    assert r.returncode == 2 and "--pool" in r.stderr and "smaller n" not in r.stderr, r.stderr
    assert not (tmp_path / "s.csv").exists()


def test_out_of_memory_hint_fits_the_command():
    """The out-of-memory hint names what the command can make smaller: configurations for
    acquire-static, the log only for the commands that read one."""
    assert "(--n, --pool)" in out_of_memory(MemoryError(), "acquire-static")
    assert "log" not in out_of_memory(MemoryError(), "acquire-static")
    assert "DYNID_MAX_STACK_BYTES" in out_of_memory(MemoryError(), "identify")
    assert out_of_memory(MemoryError(), "retrieve").endswith("machine's memory: raise it")


def test_a_huge_friction_coefficient_is_named_not_the_log(tmp_path):
    """validate with a friction file of fv = 1e300: the overflow names the friction file
    (it said "the log holds values far outside a robot's range")."""
    log = tmp_path / "log.csv"
    assert _main("simulate", "--duration", "1", "--rate", "200", "--out", str(log)).returncode == 0
    law = LAWS["classical"]
    params = np.tile([0.1, 0.5, 0.0], (7, 1))
    params[2, 0] = 1e300
    save_friction_json(tmp_path / "huge.json", law.model(params, np.zeros(7)))
    r = _main(
        *("validate", "--robot", "panda", "--data", str(log), "--out", str(tmp_path / "v")),
        *("--friction", str(tmp_path / "huge.json"), "--no-figures"),
    )
    assert r.returncode == 2, r.stderr
    assert "friction torques are far outside" in r.stderr and "huge.json" in r.stderr, r.stderr
    assert "the log holds" not in r.stderr


def test_payload_refuses_cutoff_with_static_data(one_configuration, tmp_path):
    """``payload --cutoff`` on static data is refused in one line (it was ignored)."""
    args = ("payload", "--robot", "panda", "--data", str(one_configuration))
    r = _main(*args, "--cutoff", "10", "--out", str(tmp_path / "p"))
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "--cutoff applies to torque logs" in r.stderr, r.stderr
    assert not (tmp_path / "p").exists()


def test_make_test_says_what_it_installs_beside_python_packages(tmp_path):
    """`make test` without chromium says it installs Debian's package and whether it could
    (the install was done, or failed, quietly)."""
    import shutil

    root = Path(__file__).resolve().parents[1]
    make = shutil.which("make")
    if make is None or not (root / "Makefile").exists():
        pytest.skip("needs make and the repository's Makefile")
    plan = subprocess.run(
        [make, "-n", "test"], cwd=root, capture_output=True, text=True, check=True
    ).stdout.splitlines()
    line = next(x for x in plan if "chromium" in x and "apt-get" in x)
    fake = tmp_path / "bin"
    fake.mkdir()
    (fake / "apt-get").write_text("#!/bin/sh\nexit 100\n")
    (fake / "apt-get").chmod(0o755)
    sh = shutil.which("sh") or "/bin/sh"
    out = subprocess.run(
        [sh, "-c", line], env={"PATH": str(fake)}, capture_output=True, text=True
    ).stdout
    assert "installing Debian's package" in out and "could not be installed" in out, out


_ONE_JOINT = """name = "one"
[[joints]]
name = "j1"
type = "revolute"
parent = "base"
child = "l1"
axis = [0.0, 1.0, 0.0]
limits = { lower = -2.0, upper = 2.0, velocity = 2.0, effort = 50.0 }
[joints.inertial]
mass = 2.0
com = [0.3, 0.0, 0.0]
inertia = [0.01, 0.0, 0.0, 0.02, 0.0, 0.02]
"""


def test_retrieve_takes_a_none_friction_file_and_names_another_law(tmp_path):
    """retrieve --friction with a one-joint "none" friction file puts no friction on the
    robot (it was refused as "a robot holds sigmoid friction"); a classical file is refused
    naming its law and the sigmoid fit that --friction takes."""
    robot = tmp_path / "one.toml"
    robot.write_text(_ONE_JOINT)
    log, model = tmp_path / "log.csv", tmp_path / "id"
    sim = ("simulate", "--robot", str(robot), "--duration", "4", "--rate", "250")
    assert _main(*sim, "--amplitudes", "1", "--periods", "2", "--out", str(log)).returncode == 0
    fit = ("identify", "--robot", str(robot), "--data", str(log), "--no-figures")
    assert _main(*fit, "--out", str(model)).returncode == 0
    for law, params in (("none", np.zeros((1, 0))), ("classical", np.array([[0.1, 0.2, 0.0]]))):
        save_friction_json(tmp_path / f"{law}.json", LAWS[law].model(params, np.zeros(1)))
    args = ("retrieve", "--model", str(model / "identification.json"), "--no-figures")
    r = _main(*args, "--friction", str(tmp_path / "none.json"), "--out", str(tmp_path / "r1"))
    assert r.returncode in (0, 1) and "sigmoid" not in r.stderr, r.stderr
    r = _main(*args, "--friction", str(tmp_path / "classical.json"), "--out", str(tmp_path / "r2"))
    assert r.returncode == 2 and "classical.json holds classical friction" in r.stderr, r.stderr
