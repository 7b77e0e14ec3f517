"""The library's messages name Python arguments and print numbers plainly; the command line
says the same messages with its flags (``cli_text``)."""

import logging
import warnings

import numpy as np
import pytest

import dynid
from dynid._checks import short
from dynid.cli.__main__ import _signals_and_warnings
from dynid.cli.common import cli_text
from dynid.cli.console import Console, LogFormat
from dynid.exceptions import DataError, DynidWarning, ModelError
from dynid.observer.model import from_robot
from dynid.observer.residual import MomentumObserver
from dynid.simulation.contact import Contact

LINK = (
    '<link name="{0}"><inertial><mass value="1"/>'
    '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>'
)
JOINT = (
    '<joint name="{0}" type="revolute"><parent link="{1}"/><child link="{2}"/>'
    '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
)


def two_leaves(tmp_path):
    """A URDF whose base carries two arms: the reader needs the chain's tip."""
    body = "".join(LINK.format(n) for n in ("base", "a", "b"))
    body += JOINT.format("ja", "base", "a") + JOINT.format("jb", "base", "b")
    path = tmp_path / "two.urdf"
    path.write_text(f'<robot name="two">{body}</robot>')
    return path


def test_urdf_reader_names_tip_link_and_the_command_line_says_tip(tmp_path):
    """Robot.from_urdf said "pass --tip", a flag no Python caller can pass."""
    with pytest.raises(ModelError, match="several leaf links") as info:
        dynid.Robot.from_urdf(two_leaves(tmp_path))
    said = str(info.value)
    assert "pass tip_link=... to choose the end of the chain" in said and "--" not in said
    assert cli_text(said) == said.replace("tip_link=...", "--tip")
    robot = dynid.Robot.from_urdf(two_leaves(tmp_path), tip_link="b")
    assert robot.joint_names == ("jb",)


@pytest.mark.parametrize(
    ("python", "command_line"),
    [
        (
            "hint: max_std_percent=... removes them, or add excitation",
            "hint: --max-std-percent removes them, or add excitation",
        ),
        (
            "or fix these parameters (max_std_percent=... drops them)",
            "or fix these parameters (--max-std-percent drops them)",
        ),
        ("pass base_link=... to choose one", "pass --base to choose one"),
        (
            "choose base=.../tip=... so that the chains match",
            "choose --base/--tip so that the chains match",
        ),
        ("with cutoff_hz=... set", "with --cutoff set"),
        ("x.tip_link=... and a_b=1 stay", "x.tip_link=... and a_b=1 stay"),
        # a flag's own value, an XML attribute, a flag and a switch beside it stay
        (
            "as torque_constant (--units tau=... scales)",
            "as torque_constant (--units tau=... scales)",
        ),
        ("needs a finite <mass value=...>", "needs a finite <mass value=...>"),
        ("`dynid predict --q=... --json`", "`dynid predict --q=... --json`"),
        ("(--keep-outlying, keep_outlying=True)", "(--keep-outlying, keep_outlying=True)"),
        # a string option given its value: the flag and the value
        ("scale them (units='tau=1.2') again", "scale them (--units tau=1.2) again"),
        ("a tag <joint name='a'> stays", "a tag <joint name='a'> stays"),
    ],
)
def test_a_python_option_becomes_its_flag(python, command_line):
    """An option of a value (``name=...``) becomes its flag, where it is not a flag's value
    or an XML attribute (the library's messages hold both)."""
    assert cli_text(python) == command_line


def test_warnings_and_notes_are_printed_with_flags(capsys):
    """The command prints the library's warnings and logged notes with flags, as before."""
    with _signals_and_warnings(Console("identify")):
        warnings.warn("2 kept; hint: max_std_percent=... removes them", DynidWarning, stacklevel=1)
    err = capsys.readouterr().err
    assert "dynid identify: warning: 2 kept; hint: --max-std-percent removes them" in err
    record = logging.LogRecord(
        "dynid", logging.WARNING, "", 0, "max_std_percent=... removes", (), None
    )
    assert (
        LogFormat("identify").format(record) == "dynid identify: warning: --max-std-percent removes"
    )


def test_observer_times_are_said_plainly(panda):
    """A repeated time said "got 0.0 after np.float64(0.0)" (numpy 2's repr)."""
    obs = MomentumObserver(from_robot(panda))
    q = np.zeros(7)
    obs.step(q, q, q, np.float64(0.0))
    with pytest.raises(
        DataError, match=r"^t must increase from sample to sample; got 0.0 after 0.0$"
    ):
        obs.step(q, q, q, np.float64(0.0))
    with pytest.raises(dynid.ShapeError, match=r"^t must have shape \(\); got \(1,\)$"):
        obs.step(q, q, q, np.array([1.0]))  # was a bare TypeError of float()
    obs.reset()
    t = np.array([0.0, 0.001, 0.001])
    with pytest.raises(DataError, match=r"sample 2 \(t = 0.001\) does not$"):
        obs.run(t, np.zeros((3, 7)), np.zeros((3, 7)), np.zeros((3, 7)))


def test_echoed_values_show_numpy_scalars_as_numbers():
    """Echoed values (``got ...``) read as Python's numbers, in tuples too."""
    assert short(np.float64(0.5)) == "0.5"
    assert short((np.float64(1.5), np.int64(2))) == "(1.5, 2)"
    with pytest.raises(dynid.OptionError, match=r"got \(1.0, nan\)$"):
        Contact("link7", (np.float64(1.0), np.float64("nan")), 0.0, 1.0)
