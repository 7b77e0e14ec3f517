"""Jittered timestamps are jitter, not gaps: only steps that drop samples are gaps.

Reference: stamps simulated on a 100 Hz grid with Gaussian jitter of 2 ms (std), the
samples dropped known (none, or four: a 50 ms step); the jitter is the drawn one.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.cli.summaries import samples_text
from dynid.identification.log import TorqueLog
from dynid.identification.prepared_log import prepare_torque_log
from dynid.signals import grid_steps

H = 0.01  # 100 Hz


def _stamps(seed: int, n: int = 2001, std: float = 2e-3) -> tuple[np.ndarray, float]:
    """``n`` stamps at 100 Hz jittered by ``std`` (clipped at 0.45 periods: increasing),
    and the jitter drawn [s]."""
    rng = np.random.default_rng(seed)
    e = np.clip(rng.normal(0.0, std, n), -0.45 * H, 0.45 * H)
    return np.arange(n) * H + e, float(np.std(e))


def _gap(t: np.ndarray) -> np.ndarray:
    """``t`` without its samples 1000 to 1003: one 50 ms step, 4 samples dropped."""
    return np.delete(t, np.arange(1000, 1004))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_jitter_alone_drops_no_sample_and_a_real_gap_is_found(seed):
    """2 ms of jitter: many steps over 1.5 periods, none a gap, the jitter and the period
    as drawn; with samples 1000-1003 removed, one gap of 4 samples there."""
    t, drawn = _stamps(seed)
    assert np.count_nonzero(np.diff(t) > 1.5 * H) > 30  # what the old rule called gaps
    steps, period, jitter = grid_steps(t)
    assert np.all(steps == 1)
    assert period == pytest.approx(H, rel=5e-5)  # 3.5 std / N^1.5: 8e-6
    assert jitter == pytest.approx(drawn, rel=0.05)
    steps, _, jitter = grid_steps(_gap(t))
    assert np.flatnonzero(steps != 1).tolist() == [999] and steps[999] == 5
    assert jitter == pytest.approx(drawn, rel=0.05)


def test_random_drops_are_counted_exactly_under_heavy_jitter():
    """1 kHz, jitter of 0.2 periods, 2 % of 20,000 samples dropped at random: the samples
    dropped counted exactly, and each gap found where it is or beside a neighbour gap."""
    rng = np.random.default_rng(7)
    n = 20_000
    t = np.arange(n) * 1e-3 + np.clip(rng.normal(0.0, 2e-4, n), -4.5e-4, 4.5e-4)
    kept = np.flatnonzero(rng.random(n) >= 0.02)
    steps, _, _ = grid_steps(t[kept])
    assert int(np.sum(steps - 1)) == int(np.sum(np.diff(kept) - 1))
    true_gaps = np.count_nonzero(np.diff(kept) > 1)
    assert 0.9 * true_gaps <= np.count_nonzero(steps > 1) <= true_gaps


@pytest.mark.parametrize("past", [0.55, -0.55])
def test_a_stamp_jittered_past_half_a_period_drops_no_sample(past):
    """Regression (a Baxter trial's train1: 1.5 ms of Gaussian jitter at 100 Hz, one stamp
    0.53 periods late in 3000; import said "std 5.2 ms ... 1 sample(s) dropped", the two
    other recordings made the same way 1.5 ms and none): 1.45 ms of unclipped jitter (0.145
    periods, placed on the grid stamp by stamp) with stamp 1500 0.55 periods late or early:
    no step holds a dropped sample, the jitter is the drawn one (to 5 %), and with
    samples 1000-1003 removed the one gap of 4 is found."""
    rng = np.random.default_rng(11)
    e = rng.normal(0.0, 1.45e-3, 3000)
    e[1499:1502] = [0.0, past * H, 0.0]
    t = np.arange(3000) * H + e
    steps, _, jitter = grid_steps(t)
    assert np.all(steps == 1) and jitter == pytest.approx(float(np.std(e)), rel=0.05)
    c = _log(t, seed=5).cleaning
    assert c.n_dropped == 0 and c.stamp_jitter_s == pytest.approx(float(np.std(e)), rel=0.05)
    steps, _, _ = grid_steps(_gap(t))
    assert np.flatnonzero(steps != 1).tolist() == [999] and steps[999] == 5


def _log(t: np.ndarray, seed: int) -> TorqueLog:
    """A Panda torque log at stamps ``t`` (a slow sinusoid, noise-free torques)."""
    panda = dynid.panda()
    rng = np.random.default_rng(seed)
    q = 0.3 * np.sin(2 * np.pi * 0.5 * t[:, None] + rng.uniform(0, 6, 7))
    dq = 0.3 * np.pi * np.cos(2 * np.pi * 0.5 * t[:, None] + rng.uniform(0, 6, 7))
    tau = dynid.gravity_torques(panda, q)
    return TorqueLog.from_raw(t, q, dq, tau)


def test_cleaning_and_the_identify_summary_call_jitter_jitter(seed=4):
    """from_raw: no gap for jitter alone (4 dropped and one gap with it); the summary line
    says the stamps jittered with their size, resampled, no sample dropped, and no gap."""
    t, drawn = _stamps(seed)
    log = _log(t, seed)
    c = log.cleaning
    assert c.gaps == () and c.n_dropped == 0
    prep = prepare_torque_log(dynid.panda(), log, cutoff_hz=5.0, check=False)
    text = samples_text(prep.record(1).log)
    ms = float(re.search(r"stamps jittered, std (\S+) ms at a 10 ms period", text)[1])
    assert ms == pytest.approx(drawn * 1e3, rel=0.05)
    assert "resampled onto a uniform grid, no sample dropped" in text and "gap" not in text
    assert prep.record(1).log.decimate == 2 and "(1 in 2 after the" in text, text
    every = prepare_torque_log(dynid.panda(), log, cutoff_hz=10.0, check=False).record(1).log
    said = samples_text(every)  # "1 in 1" read as a riddle
    assert every.decimate == 1 and "(every sample after the 10 Hz low-pass" in said, said
    gapped = _log(_gap(t), seed).cleaning
    assert gapped.n_dropped == 4 and gapped.gaps == ((t[999], t[1004]),)


def _rostopic(path, log: TorqueLog) -> None:
    """``rostopic echo -p`` rows of ``log`` (stamps in ns from an epoch)."""
    head = ["%time", "field.header.seq", "field.header.stamp", "field.header.frame_id"]
    head += [f"field.name{i}" for i in range(7)]
    head += [f"field.{f}{i}" for f in ("position", "velocity", "effort") for i in range(7)]
    lines = [",".join(head)]
    names = [f"panda_joint{j}" for j in range(1, 8)]
    for k in range(log.n_samples):
        s = str(1_700_000_000_000_000_000 + int(round(log.t[k] * 1e9)))
        row = [s, str(k), s, "", *names]
        row += [repr(float(v)) for a in (log.q, log.dq, log.tau) for v in a[k]]
        lines.append(",".join(row))
    path.write_text("\n".join(lines) + "\n")


def test_cli_import_names_jitter_and_only_real_gaps(tmp_path, capsys):
    """dynid import of a jittered export: a note of the jitter (no sample dropped) and no
    gap; with the 50 ms step: the 4 samples dropped and one gap."""
    t, _ = _stamps(5, n=600)
    for name, stamps in (("jit", t), ("gap", np.delete(t, np.arange(300, 304)))):
        _rostopic(tmp_path / f"{name}.csv", _log(stamps, 5))
        argv = ["import", str(tmp_path / f"{name}.csv"), "--out", str(tmp_path / f"{name}.npz")]
        assert main(argv) == 0
        out = capsys.readouterr().out
        assert "stamps jittered, std" in out and "at a 10 ms period" in out
        if name == "jit":
            assert "(no sample dropped)" in out and "gap" not in out
        else:
            assert "(4 sample(s) dropped)" in out
            assert "1 gap(s) in time of dropped samples at t = " in out
