"""Rows holding NaN dropped from a log read through a column map (``observe --model``,
``identify``) are named as the strict reader names them: one warning, with the rows and
their lines, whichever reader the command took."""

from __future__ import annotations

import logging

import numpy as np
import pytest

import dynid
from dynid.io.columns import ColumnMap
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.data_files import read_torque_log


def test_the_mapped_reader_names_the_dropped_rows_as_the_strict_reader(tmp_path, caplog):
    """A 1 s Panda log with NaN in rows 7 and 31 (tau3, q1): both readers warn "dropped 2
    row(s) of N holding NaN, inf or an empty cell: row 7 (line L), row 31 (line L')",
    the lines counted in the file itself; without --drop-invalid the mapped one refuses
    naming the same rows."""
    from dynid.exceptions import DataError

    panda = dynid.panda()
    rng = np.random.default_rng(7)
    log = simulate_measurement(
        panda, random_fourier(panda, rng)(sample_times(1.0, 200.0)), rng=rng, noise=SensorNoise()
    )
    path = save_torque_log(tmp_path / "log.csv", log)
    lines = path.read_text().splitlines()
    head = next(k for k, x in enumerate(lines) if x.startswith("t,"))
    cells = {7: "tau3", 31: "q1"}
    names = lines[head].split(",")
    for row, col in cells.items():
        parts = lines[head + 1 + row].split(",")
        parts[names.index(col)] = "nan"
        lines[head + 1 + row] = ",".join(parts)
    path.write_text("\n".join(lines) + "\n")
    n = log.t.shape[0]
    want = (
        f"log.csv: dropped 2 row(s) of {n} holding NaN, inf or an empty cell: "
        f"row 7 (line {head + 9}), row 31 (line {head + 33})"
    )
    said = []
    for columns in (None, ColumnMap()):
        caplog.clear()
        with caplog.at_level(logging.WARNING):
            got = read_torque_log(path, 7, columns=columns, drop_invalid=True)
        assert got.t.shape[0] == n - 2
        said.append([r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING])
    assert said[0] == said[1] == [want]
    with pytest.raises(DataError, match=r"row 7 \(line \d+\), row 31"):
        read_torque_log(path, 7, columns=ColumnMap())
