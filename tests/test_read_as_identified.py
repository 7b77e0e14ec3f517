"""The commands that read logs for an identified model read them as ``identify`` did:
rows with NaN dropped (``--drop-invalid``), gaps bridged up to its ``--max-gap`` and, for
``payload``, the torques' delay. Regression: a model identified with ``--drop-invalid``
from a log with NaN rows refused the next log with NaN rows in ``validate``, ``friction``,
``observe`` and ``payload``; ``observe`` and ``payload`` cut a log at a 22 ms gap that
``identify`` bridged with ``--max-gap 0.05``; ``payload`` prepared its logs without the
model's ``--torque-delay``."""

from __future__ import annotations

import dataclasses
import logging
import warnings
from pathlib import Path

import numpy as np
import pytest

from dynid.exceptions import DataError
from dynid.friction.model import ClassicalFriction
from dynid.identification.info import LogInfo
from dynid.io.feasible import load_feasible_json, save_feasible_json
from dynid.io.model_json import load_model_json, save_model_json
from dynid.io.torque_log import save_torque_log
from dynid.model.robot import Robot
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.as_identified import read_as_identified
from dynid.workflows.friction import FrictionOptions, fit_friction_files
from dynid.workflows.identify import IdentifyOptions, identify_files
from dynid.workflows.observe import ObserveOptions, observe_files
from dynid.workflows.payload import identify_payload_files
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import recordings

#: The rows of each log written with a NaN, and the rows left out of the second (a gap of
#: 11 steps of 2 ms: 22 ms, over the default rule's 5 ms, under the 50 ms bridged).
NAN_ROWS, GAP = (150, 900), slice(1200, 1210)
MAX_GAP_S, DELAY_S = 0.05, 0.002


def _with_nan(path: Path, gap: slice | None = None) -> tuple[Path, int]:
    """``path`` with NaN in ``tau1`` of the rows :data:`NAN_ROWS` and the rows ``gap``
    left out; the rows it holds."""
    lines = path.read_text().splitlines()
    head = next(k for k, x in enumerate(lines) if x.startswith("t,"))
    col = lines[head].split(",").index("tau1")
    rows = lines[head + 1 :]
    for r in NAN_ROWS:
        cells = rows[r].split(",")
        cells[col] = "nan"
        rows[r] = ",".join(cells)
    if gap is not None:
        del rows[gap]
    top = [x for x in lines[: head + 1] if not x.startswith("# rows")]  # rows left out
    path.write_text("\n".join([*top, *rows]) + "\n")
    return path, len(rows)


def _arm(load_kg: float = 0.0) -> Robot:
    """A spatial 3R arm (its flange turned about three axes), ``load_kg`` [kg] added to its
    last link at that link's centre of mass."""
    inertia = [
        np.diag([0.02, 0.02, 0.01]),
        np.diag([0.03, 0.03, 0.01]),
        np.diag([0.01, 0.01, 0.005]),
    ]
    return Robot.from_mdh(
        [0.0, 0.0, 0.4],
        [0.3, 0.0, 0.0],
        [0.0, -np.pi / 2, np.pi / 2],
        flange=(0.0, 0.1, 0.0, 0.0),
        mass=[2.0, 1.5, 1.0 + load_kg],
        com=[[0, 0, -0.1], [0.2, 0, 0], [0, 0, 0.05]],
        inertia=np.array(inertia),
        name="arm3",
    )


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    """A 3R arm with classical friction identified from a noisy 4 s log with NaN rows
    (``drop_invalid``, ``max_gap_s`` 0.05 s, ``torque_delay_s`` 2 ms), saved; and a
    second log of another motion, the arm carrying 0.6 kg, with NaN rows and a 22 ms
    gap."""
    d = tmp_path_factory.mktemp("as_identified")
    truth = ClassicalFriction(np.array([0.3, 0.2, 0.1]), np.array([0.4, 0.3, 0.2]), np.zeros(3))
    kw = dict(friction=truth, duration=4.0, noise=SensorNoise())
    (log,) = recordings(_arm(), [3], **kw)
    (loaded,) = recordings(_arm(0.6), [4], **kw)
    fitted, _ = _with_nan(save_torque_log(d / "fit.csv", log))
    other, n_rows = _with_nan(save_torque_log(d / "other.csv", loaded), GAP)
    opt = IdentifyOptions(
        terms="viscous,coulomb", drop_invalid=True, max_gap_s=MAX_GAP_S, torque_delay_s=DELAY_S
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = identify_files(_arm(), fitted, opt).model
    path = save_model_json(d / "identification.json", model)
    save_feasible_json(d / "feasible.json", _arm())  # as --consistent writes it beside
    return path, other, n_rows


def test_the_identification_records_that_it_dropped_invalid_rows(identified):
    """identification.json holds drop_invalid true beside the gap rule given."""
    log = load_model_json(identified[0]).info.log
    assert log is not None and log.drop_invalid is True and log.max_gap_s == MAX_GAP_S


def test_the_record_applies_unless_given_with_one_note(caplog):
    """The record's --drop-invalid and --max-gap applied with one note naming both; a gap
    given kept; no record (a robot): the options as given."""
    record = LogInfo(None, 0.0, 1, 500.0, 10, 10, 1.0, drop_invalid=True, max_gap_s=0.05)
    with caplog.at_level(logging.INFO):
        assert read_as_identified(record, False, None) == (True, 0.05)
    said = [r.getMessage() for r in caplog.records]
    assert said == [
        "using the identification's --drop-invalid, --max-gap 0.05 s (as identify read its "
        "logs; identification.json's metadata)"
    ]
    assert read_as_identified(record, False, 0.01) == (True, 0.01)
    assert read_as_identified(None, False, None) == (False, None)


def _quiet(fn, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*args, **kw)


def test_validate_and_friction_read_the_log_as_identify_did(identified):
    """The second log (2 NaN rows, a 22 ms gap) is read without --drop-invalid: its 2 rows
    dropped and the 10 left out missing from the grid (12), one piece; refused when
    the model's record says nothing of them."""
    path, other, _ = identified
    model = load_model_json(path)
    got = _quiet(validate_files, model, other, ValidateOptions())
    (rec,) = got.validation.pieces.summary()
    assert rec["pieces"] == 1 and rec["samples_missing"] == len(NAN_ROWS) + 10
    fr = _quiet(fit_friction_files, model, other, FrictionOptions(law="classical"))
    assert fr.pieces is not None and [s["pieces"] for s in fr.pieces.summary()] == [1]
    bare = dataclasses.replace(
        model.info, log=dataclasses.replace(model.info.log, drop_invalid=False)
    )
    with pytest.raises(DataError, match=r"2 row\(s\) hold NaN"):
        _quiet(validate_files, dataclasses.replace(model, info=bare), other)


def test_observe_and_payload_read_the_log_as_identify_did(identified, caplog):
    """observe calibrates on the second log without a cut at its gap; payload fits its
    load (0.6 kg) in one piece with the model's gap rule and torque delay, as its record
    says."""
    path, other, _ = identified
    with caplog.at_level(logging.WARNING):
        _quiet(observe_files, ObserveOptions(data=(other,), model=path, calibrate=True))
    assert not [r for r in caplog.records if "cut at gaps" in r.getMessage()]
    est = _quiet(identify_payload_files, load_model_json(path), other, terms="viscous")
    prep = est.estimate.preprocessing
    assert prep["max_gap_s"] == MAX_GAP_S and prep["torque_delay_s"] == DELAY_S
    assert [r["pieces"] for r in est.recordings] == [1]
    assert est.estimate.mass == pytest.approx(0.6, abs=0.2)


def test_params_of_a_feasible_file_reads_as_the_identification_beside_it(identified):
    """observe and payload of the feasible.json beside the identification.json read the
    second log as --model does: its NaN rows dropped, its gap bridged (one piece), and
    observe with the identification's torque delay."""
    path, other, _ = identified
    feasible = path.with_name("feasible.json")
    got = _quiet(observe_files, ObserveOptions(data=(other,), params=feasible, calibrate=True))
    assert got.model.torque_delay_s == DELAY_S
    robot = load_feasible_json(feasible)
    est = _quiet(identify_payload_files, robot, other, feasible=feasible, terms="viscous")
    assert est.estimate.preprocessing["max_gap_s"] == MAX_GAP_S
    assert [r["pieces"] for r in est.recordings] == [1]
