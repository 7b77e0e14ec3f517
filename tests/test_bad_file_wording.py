"""A bad data file is worded one way whether given alone or after good files: the file,
the line when known, what is wrong; one line on stderr, exit 2, no output folder.

References: the files written here (an empty file, a CSV whose header names neither a
torque log's nor static data's columns, static data with a bad header), their line
numbers counted by hand.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("wording")
    panda = dynid.panda()
    rng = np.random.default_rng(2)
    traj = random_fourier(panda, rng)(sample_times(1.0, 100.0))
    save_torque_log(d / "good.csv", simulate_measurement(panda, traj, rng=rng))
    (d / "empty.csv").write_text("")
    (d / "garbage.csv").write_text("hello,world\n1,2\nfoo\n")
    (d / "static.csv").write_text("# a comment\n\nq1,M1_1,M1_1,g1\n1,2,3,4\n")
    return d


#: (file, the whole line the command prints about it, without the command's prefix)
BAD = [
    ("empty.csv", "empty.csv: no header line found; expected columns t,q1,...,dq1,...,tau1,..."),
    (
        "garbage.csv",
        "garbage.csv, line 1: header must name columns t, q1..qn, dq1..dqn, tau1..taun; "
        "got hello, world",
    ),
]


@pytest.mark.parametrize(("bad", "said"), BAD, ids=[b for b, _ in BAD])
@pytest.mark.parametrize("command", ["identify", "validate"])
def test_a_bad_file_alone_or_after_good_ones_is_worded_alike(
    files, tmp_path, capsys, bad, said, command
):
    extra = ["--robot", "panda", "--no-figures"]
    for k, data in enumerate(([bad], ["good.csv", bad])):
        out = tmp_path / f"out{k}"
        argv = [command, *extra, "--data", *(str(files / f) for f in data), "--out", str(out)]
        rc = main(argv)
        err = capsys.readouterr().err.strip().splitlines()
        assert rc == 2 and err == [f"dynid {command}: error: {said}"], (data, err)
        assert not out.exists()


def test_static_data_name_the_line_as_the_logs_do(files, tmp_path, capsys):
    """Static data's header errors read ``file, line N: ...`` (they read ``file: line N:``)."""
    rc = main(["identify", "--data", str(files / "static.csv"), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err == ["dynid identify: error: static.csv, line 3: duplicated columns M1_1"]
    assert not (tmp_path / "o").exists()
