"""validate of a folder ``identify --consistent`` wrote: which model, and the recorded units.

A 6-DoF arm whose torques were logged with the opposite sign, identified with ``--units
tau=-1 --consistent``: ``validate --model out/identification.json`` silently validated the
least-squares model (0.251 % on exact held-out data), and ``validate --params
out/feasible.json`` read the held-out log without the recorded ``--units tau=-1`` (200 %,
exit 1, where the consistent model read 0.208 % with the units given). The reference: a
planar 2R arm simulated exactly, its torques logged negated; ``feasible.json`` holds its
true parameters, so that the log read as the run recorded is predicted to round-off.
"""

from __future__ import annotations

import dataclasses
import logging

from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.feasible import load_feasible_json, save_feasible_json
from dynid.io.model_json import load_model_json, save_model_json
from dynid.io.torque_log import save_torque_log
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import planar_2r, recordings


def _folder(tmp_path):
    """A folder as ``identify --units tau=-1 --consistent`` writes it (the model fitted to
    negated exact logs, recorded with that column map; feasible.json the true robot), and
    a held-out exact log of the truth with its torques negated."""
    truth = planar_2r()
    train = recordings(truth, (1, 2), friction=None, duration=3.0)
    # the logs as read with --units tau=-1: the model of the torques' true sign
    model = identify_recordings(truth, train, cutoff_hz=None, structure=Structure(friction=()))
    info = dataclasses.replace(model.info, column_map={"columns": None, "units": "tau=-1"})
    out = tmp_path / "cons"
    out.mkdir()
    save_model_json(out / "identification.json", dataclasses.replace(model, info=info))
    save_feasible_json(out / "feasible.json", truth)
    (held,) = recordings(truth, (9,), friction=None, duration=3.0)
    path = save_torque_log(tmp_path / "held.csv", dataclasses.replace(held, tau=-held.tau))
    return out, path


def test_params_reads_the_data_as_the_identification_beside_it_recorded(tmp_path, caplog):
    """``--params feasible.json`` reads the log with the ``--units tau=-1`` recorded in the
    identification.json beside it, as ``--model`` does, and says so: the true parameters
    predict the negated log to round-off, where it was read unflipped (about 200 %)."""
    out, path = _folder(tmp_path)
    feasible = out / "feasible.json"
    with caplog.at_level(logging.INFO, logger="dynid"):
        result = validate_files(load_feasible_json(feasible), path, feasible=feasible)
    assert result.validation.errors.relative_error_percent < 1e-4
    assert not result.verdict.unusable
    said = " ".join(r.getMessage() for r in caplog.records)
    assert "identification.json beside it" in said and "tau=-1" in said


def test_model_of_a_consistent_folder_names_the_model_validated(tmp_path, caplog):
    """``--model`` of a folder that holds feasible.json too says, in one line, that the
    least-squares model is validated and that ``--params .../feasible.json`` validates the
    consistent one."""
    out, path = _folder(tmp_path)
    ident = out / "identification.json"
    with caplog.at_level(logging.INFO, logger="dynid"):
        validate_files(load_model_json(ident), path, ValidateOptions(), source=ident)
    lines = [r.getMessage() for r in caplog.records if "least-squares model" in r.getMessage()]
    assert len(lines) == 1 and f"--params {out / 'feasible.json'}" in lines[0], lines
