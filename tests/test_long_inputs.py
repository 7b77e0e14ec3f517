"""Long inputs in bounded memory (issue 28): what a long log or trajectory holds at once.

The figures (peak memory on a 5-million-row log under 1.5 GB) are measured by
``benchmarks/bench_memory.py``; the tests here check, on short inputs, that the long ones
take the blocked path, and that it gives what the whole-array path gives.
"""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.io.excitation import EXCITATION_SCHEMA
from dynid.io.torque_log import load_torque_log
from dynid.simulation.excitation import ExcitingTrajectory

NEUTRAL = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])


def test_simulate_evaluates_a_trajectory_json_a_block_at_a_time(tmp_path, monkeypatch):
    """simulate --trajectory trajectory.json evaluates the series per block of samples: the
    whole series was sampled first (a 5-million-row log: 3.7 GB at its peak); the log
    equals the series sampled whole."""
    rng = np.random.default_rng(3)
    series = ExcitingTrajectory(
        w_f=2 * np.pi * 0.1,
        a=rng.normal(0.0, 0.02, (7, 5)),
        b=rng.normal(0.0, 0.02, (7, 5)),
        q_start=NEUTRAL,
        duration=4.0,
        ramp=1.0,
    )
    path = tmp_path / "trajectory.json"
    path.write_text(json.dumps({"schema": EXCITATION_SCHEMA, "trajectory": series.to_dict()}))
    whole = series.sample(500.0)

    def refused(self, fs=1000.0):
        raise AssertionError("the whole trajectory was sampled")

    monkeypatch.setattr(ExcitingTrajectory, "sample", refused)
    out = tmp_path / "log.csv"
    with contextlib.redirect_stdout(io.StringIO()):
        code = main(
            [
                *("simulate", "--trajectory", str(path), "--rate", "500", "--out", str(out)),
                *("--q-noise", "0", "--dq-noise", "0"),
            ]
        )
    assert code == 0
    log = load_torque_log(out)
    np.testing.assert_allclose(log.t, whole.t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(log.q, whole.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(log.dq, whole.dq, rtol=0, atol=1e-12)


def test_a_columns_log_is_read_side_by_side_without_a_copy(tmp_path, monkeypatch):
    """A --columns CSV (another tool's names, a text column) gives the log dynid's own CSV
    gives, each joint quantity read straight into its (N, n) array: the columns were read one
    by one and stacked, then copied again (a 5-million-row log peaked at 2.78 GB, 1.80 GB
    after)."""
    from dynid.io import columns as columns_module
    from dynid.io.columns import load_mapped_torque_log, parse_column_map

    plain = tmp_path / "log.csv"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["simulate", "--duration", "2", "--rate", "500", "--out", str(plain)]) == 0
    lines = [x for x in plain.read_text().splitlines() if not x.startswith("#")]
    rename = {"t": "time_s"} | {
        f"{k}{i + 1}": f"{v}_{i}"
        for k, v in (("q", "pos"), ("dq", "vel"), ("tau", "eff"))
        for i in range(7)
    }
    header = ",".join(rename[c] for c in lines[0].split(","))
    other = tmp_path / "other.csv"
    other.write_text("\n".join([header + ",status"] + [x + ",ok" for x in lines[1:]]) + "\n")

    def no_stack(*a, **k):
        raise AssertionError("columns stacked one by one")

    monkeypatch.setattr(columns_module.np, "stack", no_stack)
    cmap = parse_column_map("t=time_s,q=pos_{i0},dq=vel_{i0},tau=eff_{i0}")
    got = load_mapped_torque_log(other, cmap, n=7).log
    monkeypatch.undo()
    ref = load_torque_log(plain)
    for name in ("t", "q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(got, name), getattr(ref, name))


def test_stacked_condition_numbers_are_built_a_block_at_a_time(monkeypatch):
    """acquire-static --pool's condition numbers build the static regressor a block of
    configurations at a time (a 50-joint arm's 1010 configurations were 5.4 GB at once) and
    equal the singular values of the whole stack (numpy's SVD) to 1e-12."""
    import dynid
    from dynid.regressors.base import base_parameters
    from dynid.regressors.static import static_regressor
    from dynid.simulation import static_selection

    robot = dynid.panda()
    q = np.random.default_rng(5).uniform(robot.q_min, robot.q_max, (40, 7))
    base = base_parameters(robot)
    W = static_regressor(robot, q)[..., base.independent].reshape(-1, base.rank)
    s = np.linalg.svd(W, compute_uv=False)
    ss = np.linalg.svd(W / np.linalg.norm(W, axis=0), compute_uv=False)
    sizes = []

    def counted(robot, q):
        sizes.append(q.shape[0])
        return static_regressor(robot, q)

    monkeypatch.setattr(static_selection, "_BLOCK_BYTES", 3 * 35 * 70 * 8)  # 3 configurations
    monkeypatch.setattr(static_selection, "static_regressor", counted)
    cond, scaled = static_selection.stacked_condition_numbers(robot, q, base)
    assert max(sizes) == 3 and sum(sizes) == 40
    assert cond == pytest.approx(s[0] / s[-1], rel=1e-12)
    assert scaled == pytest.approx(ss[0] / ss[-1], rel=1e-12)
