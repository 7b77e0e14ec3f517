"""Torques read from a controller's command (a UR's ``target_moment_0..5``, libfranka's
``tau_J_d``, ``effort_desired``) are warned of, with the measured family the header holds;
measured ones are not.

Regression: a UR3 log read with ``--columns tau=target_moment_{i0}`` (the controller's
model torque, no drive) fitted to 0.07 % with a held-out verdict "usable" and a spring
suggested, and nothing said the torques held no friction and almost no noise.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning
from dynid.io.column_hint import commanded_torques
from dynid.io.columns import parse_column_map
from dynid.workflows.data_files import read_torque_log

#: The header of a UR's real-time data exchange log (six joints, numbered from 0).
UR = [
    "timestamp",
    *(f"{s}_{j}" for s in ("target_q", "actual_q", "actual_qd") for j in range(6)),
    *(f"{s}_{j}" for s in ("actual_current", "target_current", "target_moment") for j in range(6)),
]


@pytest.mark.parametrize(
    ("template", "commanded"),
    [
        ("target_moment_{i0}", True),
        ("target_current_{i0}", True),
        ("tau_J_d{i}", True),  # libfranka's desired link-side torque
        ("effort_desired_{i}", True),
        ("torque_cmd{i}", True),
        ("tau_commanded_{i}", True),
        ("TargetTorque{i}", True),
        ("model_torque{i}", True),
        ("actual_current_{i0}", False),
        ("tau_J{i}", False),  # libfranka's measured torque
        ("tau{i}", False),
        ("effort{i}", False),
        ("d_tau{i}", False),  # a first "d" is no desired value's suffix
        ("tau_ext{i}", False),
    ],
)
def test_a_commanded_column_is_told_by_its_name(template, commanded):
    """The names that say a command, a target, a desired value or a model's are told; the
    measured ones of the same tools are not."""
    said = commanded_torques(template, [], 6)
    assert (said is not None) is commanded, said


def test_the_warning_names_the_columns_and_the_measured_family():
    """UR's target_moment_0..5: the columns named as a span, what they are, and the hint
    the header's measured currents, read through a drive (not target_current_*)."""
    said = commanded_torques("target_moment_{i0}", UR, 6)
    assert said is not None
    assert said.startswith("tau is read from target_moment_0..5, a controller's target, not a")
    assert "no friction and almost no noise" in said
    assert "hint: --columns tau=actual_current_{i0} --units tau=A" in said
    assert "effort is current" in said


def _write(path, header, rng):
    """A 60-sample log at 100 Hz of ``header``'s columns (the first one the time)."""
    body = rng.uniform(-1, 1, (60, len(header)))
    body[:, 0] = np.arange(60) / 100.0
    np.savetxt(path, body, delimiter=",", header=",".join(header), comments="", fmt="%.17g")


def test_reading_a_target_column_warns_and_a_measured_one_does_not(tmp_path):
    """read_torque_log through --columns tau=target_moment_{i0} warns once with the
    sentence; through actual_current_{i0} it warns of nothing commanded."""
    path = tmp_path / "rtde.csv"
    _write(path, UR, np.random.default_rng(3))
    base = "t=timestamp,q=actual_q_{i0},dq=actual_qd_{i0}"
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        log = read_torque_log(path, 6, columns=parse_column_map(f"{base},tau=target_moment_{{i0}}"))
    said = [str(w.message) for w in got if issubclass(w.category, DynidWarning)]
    assert log.n == 6
    assert [s for s in said if s.startswith("tau is read from target_moment_0..5")], said
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        read_torque_log(path, 6, columns=parse_column_map(f"{base},tau=actual_current_{{i0}}"))
    assert not [w for w in got if "not a measurement" in str(w.message)]
