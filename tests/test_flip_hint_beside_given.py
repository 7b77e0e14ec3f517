"""The hint of friction that pushes the arm, beside the sign flips ``--units`` applied.

Reference: the set of columns read flipped, by the column map dynid reads a file with
(``parse_column_map``): the flips applied and those found, a joint in both read as it is.
Before, after ``--units tau2=-1,...,tau5=-1`` a Kinova log whose joints 1 and 6 were of the
opposite sign too was told ``--units tau1=-1,tau6=-1``, not the ``tau=-1`` that flips
every joint, which the sign check's hint gives when it judges every joint.
"""

from __future__ import annotations

import re

import numpy as np

from dynid.identification.dissipation import ReversedSignError, Violation, reversed_sign_finding
from dynid.io.columns import parse_column_map

NAMES = tuple(f"joint{j + 1}" for j in range(6))


def _pushing(*joints: int) -> list[Violation]:
    return [Violation(j, "joint", ("fv", "fc"), (-1.1, -0.9), 1.0, 1.0, True) for j in joints]


def _flipped(units: str) -> np.ndarray:
    """Per joint, the sign each torque column is read with through ``units``."""
    cmap = parse_column_map(None, units)
    sign = np.full(6, np.sign(cmap.factor("tau")))
    sign[list(cmap.flips.get("tau", ()))] *= -1
    return sign


def _hinted(msg: str) -> str:
    return re.search(r"hint: --units (\S+)", msg).group(1)


def test_flips_given_and_found_on_every_joint_are_told_tau_minus_one():
    given = "t=us,q=deg,dq=deg/s,tau2=-1,tau3=-1,tau4=-1,tau5=-1"
    msg = reversed_sign_finding(_pushing(0, 5), NAMES, applied=(1, 2, 3, 4), text=given)
    assert _hinted(msg) == "t=us,q=deg,dq=deg/s,tau=-1"
    assert "tau=-1 in place of tau2=-1,tau3=-1,tau4=-1,tau5=-1" in msg
    np.testing.assert_array_equal(_flipped(_hinted(msg)), -np.ones(6))
    err = ReversedSignError(_pushing(0, 5), NAMES)
    assert "hint: --units tau1=-1,tau6=-1 reads them flipped" in str(err)  # as before
    assert _hinted(str(err.beside((1, 2, 3, 4), given))) == "t=us,q=deg,dq=deg/s,tau=-1"


def test_some_joints_flipped_are_told_the_flips_that_read_every_column_right():
    """Joints 1, 2 flipped by --units; joints 1 and 6 found pushing: joint 1 was flipped
    wrongly, joint 6 needs it: tau2 and tau6 flipped, the columns each read the other
    way than given on joints 1 and 6 alone."""
    given = "q=deg,tau1=-1,tau2=-1"
    msg = reversed_sign_finding(_pushing(0, 5), NAMES, applied=(0, 1), text=given)
    hinted = _hinted(msg)
    assert hinted == "q=deg,tau2=-1,tau6=-1", msg
    change = _flipped(hinted) * _flipped(given)
    np.testing.assert_array_equal(change, [-1, 1, 1, 1, 1, -1])
