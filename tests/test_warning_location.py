"""Library warnings point to the user's call: ``warnings.warn`` in the package is given
the stacklevel of the first frame outside it (:func:`dynid._checks.caller_level`), so a
warning's ``filename`` is the caller's file whatever the depth of the call that makes it;
and a warning reached from the Python API names the arguments, not the command line's
flags."""

from __future__ import annotations

import warnings

import numpy as np

import dynid
from dynid._checks import caller_level
from dynid.exceptions import DynidWarning
from dynid.io.export import save_robot
from dynid.model.drive import Drive


def _said(call, *args, **kw):
    """The DynidWarnings ``call(*args, **kw)`` makes, recorded."""
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        call(*args, **kw)
    return [w for w in said if issubclass(w.category, DynidWarning)]


def test_a_urdf_export_warns_at_the_callers_line_naming_no_flag(tmp_path):
    """Regression: save_robot of a robot and a drive with rotor inertias to a URDF warned
    from inside the package (a fixed stacklevel) and offered ``--out r.xml``, a command's
    flag, to a Python caller. Now the warning's filename is this file, and it names the
    file that would hold the armature, ``r.xml``, with no flag."""
    robot = dynid.panda()
    drive = Drive(np.eye(7), np.zeros(7), rotor_inertia=np.full(7, 0.05))
    (w,) = _said(save_robot, tmp_path / "r.urdf", robot, drive=drive)
    assert w.filename == __file__, w.filename
    text = str(w.message)
    assert "--" not in text and "an MJCF export (r.xml, not written)" in text, text


def test_a_warning_deep_in_a_read_points_to_the_caller(tmp_path):
    """A robot TOML file whose inertial is physically inconsistent, read through
    load_robot_file (several calls deep in the package): the warning's filename is this
    file, where the fixed stacklevels pointed into the package."""
    from dynid.io.robot_file import load_robot

    robot = dynid.panda()
    path = save_robot(tmp_path / "p.toml", robot)
    text = path.read_text()
    first = "inertia = [0.70337,"
    assert first in text
    bad = text.replace(first, "inertia = [9.0,", 1)  # Ixx beyond Iyy + Izz
    path.write_text(bad)
    said = _said(load_robot, path)
    assert said and all(w.filename == __file__ for w in said), [w.filename for w in said]


def test_caller_level_counts_the_frames_inside_the_package():
    """Called from outside the package, the level is 1: the function itself."""
    assert caller_level() == 1
