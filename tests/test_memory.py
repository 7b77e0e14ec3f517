"""Bounded memory on long logs (issue 20 item 5).

References: the whole-array signal steps (scipy's zero-phase filter, numpy's gradient) and
the error formulas written out with numpy; a subprocess under an address-space limit
(RLIMIT_AS) for the command line.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from test_log_blocks import _lowpass as continued_lowpass

import dynid
from dynid.exceptions import ShapeError
from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import BLOCK_SAMPLES, validate_torques
from dynid.identification.classical import identify_from_log
from dynid.identification.log import TorqueLog
from dynid.identification.prepare import Preprocessing, prepare_log
from dynid.io.torque_log import load_torque_log, save_torque_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier


def _log(seed: int, N: int, n: int = 3) -> TorqueLog:
    rng = np.random.default_rng(seed)
    t = np.arange(N) * 1e-3
    q = np.cumsum(rng.normal(size=(N, n)), axis=0) * 1e-3
    return TorqueLog(t, q, rng.normal(size=(N, n)), rng.normal(size=(N, n)))


@pytest.mark.parametrize("filter_tau", [True, False])
def test_decimated_preparation_equals_the_whole_array_steps(filter_tau):
    """prepare_log with decimate=k, which works column by column, equals the zero-phase
    Butterworth of scipy on whole arrays (their ends continued by numpy's cubic), numpy's
    gradient of the filtered dq, trimmed and every k-th sample taken."""
    log = _log(1, 12_000)
    fs, cut, k = 1000.0, 5.0, 20

    def lp(x):  # scipy's filter of the ends continued by numpy's cubic (test_log_blocks)
        return continued_lowpass(x, fs, cut)

    dq = lp(log.dq)
    ref = {"q": lp(log.q), "dq": dq, "ddq": np.gradient(dq, log.t, axis=0, edge_order=2)}
    ref["tau"] = lp(log.tau) if filter_tau else log.tau
    keep = (log.t >= log.t[0] + 2 / cut) & (log.t <= log.t[-1] - 2 / cut)
    p = prepare_log(log, Preprocessing(cutoff_hz=cut, filter_tau=filter_tau, decimate=k))
    np.testing.assert_array_equal(p.t, log.t[keep][::k])
    for name, x in ref.items():
        np.testing.assert_allclose(getattr(p, name), x[keep][::k], rtol=0, atol=1e-12)


def test_prepare_log_refuses_a_bad_decimation():
    with pytest.raises(ShapeError, match="decimate"):
        prepare_log(_log(2, 1000), Preprocessing(decimate=0))


def test_validation_of_a_long_log_sums_its_errors_by_blocks():
    """A log longer than one block: the errors with friction equal those written out with
    numpy on the whole arrays."""
    N = BLOCK_SAMPLES + 20_001
    log = _log(3, N)
    fr = ClassicalFriction.from_array(
        np.array([[0.5, 0.2, 0.01], [0.3, 0.1, 0.0], [1.0, 0.0, 0.2]])
    )

    def model(q, dq, ddq):
        return 0.1 * q + 0.01 * ddq

    val = validate_torques(model, log, friction=fr, cutoff_hz=5.0)
    p = val.log
    hat = 0.1 * p.q + 0.01 * p.ddq + fr.torques(p.dq)
    e = p.tau - hat
    np.testing.assert_allclose(val.with_friction.rms, np.sqrt(np.mean(e**2, axis=0)), rtol=1e-12)
    np.testing.assert_allclose(
        val.with_friction.relative_error_percent,
        100 * np.linalg.norm(e) / np.linalg.norm(p.tau),
        rtol=1e-12,
    )
    np.testing.assert_allclose(
        val.with_friction.relative_error_percent_per_joint,
        100 * np.linalg.norm(e, axis=0) / np.linalg.norm(p.tau, axis=0),
        rtol=1e-12,
    )
    assert val.with_friction.n_samples == p.n_samples


@pytest.mark.parametrize("estimator", ["ols", "wls"])
def test_classical_route_streamed_equals_stacked(monkeypatch, estimator):
    """A log identified with its regressor streamed in blocks (DYNID_MAX_STACK_BYTES=0)
    gives the stacked fit's estimates, standard deviations, friction and held-out errors
    (the stacked estimators on the whole regressor) to 1e-9."""
    robot = dynid.panda()
    series = random_fourier(robot, np.random.default_rng(7))
    log = simulate_measurement(
        robot, series(sample_times(40.0, 1000.0)), rng=np.random.default_rng(8)
    )
    ref = identify_from_log(robot, log, estimator=estimator, structure="classical")
    monkeypatch.setenv("DYNID_MAX_STACK_BYTES", "0")
    got = identify_from_log(robot, log, estimator=estimator, structure="classical")
    np.testing.assert_allclose(got.fit.beta, ref.fit.beta, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(got.fit.std, ref.fit.std, rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(got.friction.params, ref.friction.params, rtol=1e-9, atol=1e-12)
    assert got.fit.relative_error_percent == pytest.approx(ref.fit.relative_error_percent, rel=1e-9)
    h, hr = got.info.heldout, ref.info.heldout
    assert h["heldout_error_percent"] == pytest.approx(hr["heldout_error_percent"], rel=1e-9)
    assert got.info.n_rows == ref.info.n_rows


_VM_RUN = """
import resource, sys
limit = int(sys.argv[1])
if limit > 0:
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
from dynid.cli.__main__ import main
code = main(sys.argv[2:])
peak = [l for l in open("/proc/self/status") if l.startswith("VmPeak")][0].split()[1]
print("VMPEAK", int(peak) * 1024)
hwm = [l for l in open("/proc/self/status") if l.startswith("VmHWM")][0].split()[1]
print("VMHWM", int(hwm) * 1024)
sys.exit(code)
"""


_VM_FORKS = """
import os, resource, sys, traceback
from dynid.cli.__main__ import main

def vm(key):
    line = [l for l in open("/proc/self/status") if l.startswith(key)][0]
    return int(line.split()[1]) * 1024

warm = sys.stdin.readline().split()
os.environ["DYNID_MAX_STACK_BYTES"] = "0"
code = main(warm)  # imports and loads every module and kernel the runs below share
print("EXIT", code, flush=True)
for line in sys.stdin:
    limit, stack_bytes, err, *argv = line.split()
    pid = os.fork()
    if pid == 0:
        code = 3
        try:
            os.dup2(os.open(err, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), 2)
            os.environ["DYNID_MAX_STACK_BYTES"] = stack_bytes
            if int(limit) > 0:
                resource.setrlimit(resource.RLIMIT_AS, (int(limit), int(limit)))
            code = main(argv)
            print("VMPEAK", vm("VmPeak"), flush=True)
        except BaseException:
            traceback.print_exc()
        finally:
            sys.stderr.flush()
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    print("EXIT", os.waitstatus_to_exitcode(status), flush=True)
"""


class _LimitedRuns:
    """``dynid identify`` runs of one log, each a process forked from one interpreter that
    has run it once on a short log (the modules and compiled kernels loaded once, not in
    every run: each fork starts from the same state), under RLIMIT_AS."""

    def __init__(self, tmp_path, log, warm_log):
        self.tmp_path, self.log = tmp_path, log
        env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
        self.proc = subprocess.Popen(
            [sys.executable, "-c", _VM_FORKS],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            env=env,
        )
        self._send(self._argv(warm_log, tmp_path / "warm"))
        assert self._exit()[0] == 0, "the run on the short log failed"

    @staticmethod
    def _argv(log, out) -> list[str]:
        argv = ["identify", "--robot", "panda", "--data", str(log), "--cutoff", "50"]
        argv += ["--out", str(out), "--no-figures", "-q"]
        return argv + ["--terms", "viscous,coulomb,offset"]  # one fit: no structure search

    def _send(self, words) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(" ".join(words) + "\n")
        self.proc.stdin.flush()

    def __call__(self, limit: int, stack_bytes: int):
        """One run under RLIMIT_AS ``limit`` bytes (0: none), the regressor stacked whole up
        to ``stack_bytes``; exit code, peak virtual memory [bytes] (None when it died),
        stderr."""
        out = self.tmp_path / f"out-{limit}-{stack_bytes}"
        err = self.tmp_path / f"err-{limit}-{stack_bytes}"
        self._send([str(limit), str(stack_bytes), str(err), *self._argv(self.log, out)])
        code, peak = self._exit()
        return code, peak, err.read_text()

    def _exit(self) -> tuple[int, int | None]:
        """The exit code and peak virtual memory [bytes] of the run just sent."""
        assert self.proc.stdout is not None
        peak = None
        for line in self.proc.stdout:
            if line.startswith("VMPEAK "):
                peak = int(line.split()[1])
            elif line.startswith("EXIT "):
                return int(line.split()[1]), peak
        raise AssertionError(f"the runs ended early: exit {self.proc.wait()}")

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        self.proc.wait(timeout=60)


@pytest.mark.slow
def test_a_long_log_identifies_under_an_address_space_limit(tmp_path):
    """A 100,000-row log at 1 kHz identified with a 50 Hz cutoff and the paper's friction
    (decimated by 2: a stacked regressor of 350,000 rows, 0.18 GB; the default structure
    search's memory is the benchmark's, bench_memory): streamed in blocks it identifies
    within its peak address space, and under a limit 150 MB above that peak the stacked
    regressor runs out of memory and says so in one line (exit 2, no traceback). The
    library reads no resource limit, so a run of the streamed fit under that limit repeats
    the first to the byte and is not made. Each run is a process forked from one that ran
    the command on a 4 s log (imports and kernels loaded once for both; 4 s, not 10 s:
    1 s of CPU less, and 2 s would not do, joint 4 turning one way: rank deficient)."""
    resource = pytest.importorskip("resource")
    if not hasattr(resource, "RLIMIT_AS") or not os.path.exists("/proc/self/status"):
        pytest.skip("needs RLIMIT_AS and /proc/self/status (Linux)")
    robot = dynid.panda()
    series = random_fourier(robot, np.random.default_rng(11))
    log = simulate_measurement(
        robot, series(sample_times(99.999, 1000.0)), rng=np.random.default_rng(12)
    )
    path, warm = tmp_path / "long.npz", tmp_path / "warm.npz"
    save_torque_log(path, log)
    del log
    short = series(sample_times(4.0, 1000.0))
    save_torque_log(warm, simulate_measurement(robot, short, rng=np.random.default_rng(13)))
    runs = _LimitedRuns(tmp_path, path, warm)
    try:
        code, peak, err = runs(0, 0)
        assert code == 0, err
        assert peak is not None
        code, _, err = runs(peak + 150 * 2**20, 1 << 50)
    finally:
        runs.close()
    lines = err.strip().splitlines()
    assert code == 2 and "out of memory in" in lines[-1], err
    assert "Traceback" not in err and "DYNID_MAX_STACK_BYTES" in lines[-1]


def _chain(n: int, seed: int) -> dynid.Robot:
    """A revolute chain of ``n`` joints with random modified DH constants and inertias."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.05, 0.2, n)
    a[0] = 0.0
    alpha = rng.choice([-np.pi / 2, np.pi / 2, 0.0], n)
    alpha[0] = 0.0
    A = rng.normal(size=(n, 3, 3))
    return dynid.Robot.from_mdh(
        a,
        rng.uniform(0.0, 0.1, n),
        alpha,
        mass=rng.uniform(0.5, 2.0, n),
        com=rng.uniform(-0.05, 0.05, (n, 3)),
        inertia=0.01 * (A @ A.transpose(0, 2, 1) + np.eye(3)),
        q_min=np.full(n, -2.8),
        q_max=np.full(n, 2.8),
        name=f"chain{n}",
    )


@pytest.mark.parametrize("kind", ["static", "torque"])
def test_base_parameters_from_blocks_of_states_equal_the_stacked_ones(kind):
    """Base parameters found block by block (the triangular factor of the random states'
    rows, max_bytes small) are those of the stacked rows: the same independent columns,
    the same combination coefficients, the same rank."""
    from dynid.regressors.base import base_parameters

    robot = _chain(6, 1)
    ref = base_parameters(robot, kind=kind)
    got = base_parameters(robot, kind=kind, max_bytes=20_000)
    assert got.rank == ref.rank
    np.testing.assert_array_equal(got.independent, ref.independent)
    np.testing.assert_allclose(got.K_d, ref.K_d, rtol=1e-12, atol=1e-14)
    assert got.expressions == ref.expressions


@pytest.mark.parametrize(
    ("estimator", "std"),
    [("ols", "robust"), ("ols", "classical"), ("wls", "robust"), ("irls", "classical")],
)
@pytest.mark.parametrize("one_factor", [False, True])
def test_static_route_streamed_equals_stacked(monkeypatch, estimator, std, one_factor):
    """Static data fitted from pieces of configurations (DYNID_MAX_STACK_BYTES=0), with a
    factor per row of [tril M; g] or one factor of all rows (GROUP_FACTOR_BYTES=0), give
    the stacked fit's estimates, standard deviations and dropped rows (g1 of the Panda)
    to 1e-10; with noise-free data both recover the generating parameters."""
    from dynid.identification import data as data_module
    from dynid.identification import streaming
    from dynid.identification.static import identify_static

    robot = dynid.panda()
    ctrl = dynid.SimulatedController(robot, 1e-3, rng=np.random.default_rng(2))
    data = dynid.acquire_static(ctrl, 300, np.random.default_rng(1))
    ref = identify_static(robot, data, estimator=estimator, std=std, max_std_percent=30)
    monkeypatch.setenv("DYNID_MAX_STACK_BYTES", "0")
    monkeypatch.setattr(data_module, "_BLOCK_BYTES", 8 * 35 * 43 * 70)  # 5 pieces
    if one_factor:
        monkeypatch.setattr(streaming, "GROUP_FACTOR_BYTES", 0)
    got = identify_static(robot, data, estimator=estimator, std=std, max_std_percent=30)
    np.testing.assert_allclose(got.fit.beta, ref.fit.beta, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(got.fit.std, ref.fit.std, rtol=1e-10, atol=1e-16)
    np.testing.assert_array_equal(got.fit.kept, ref.fit.kept)
    assert got.info.dropped_rows == ref.info.dropped_rows == ("g1",)
    assert got.info.n_rows == ref.info.n_rows == 300 * 34
    assert got.fit.relative_error_percent == pytest.approx(ref.fit.relative_error_percent, 1e-10)
    exact = dynid.acquire_static(dynid.SimulatedController(robot), 120, np.random.default_rng(3))
    model = identify_static(robot, exact, std=std)
    truth = model.base.beta_from_phi(robot.phi)  # the generating parameters
    np.testing.assert_allclose(model.fit.beta, truth, rtol=1e-8, atol=1e-10)


@pytest.mark.slow
def test_static_data_of_a_50_joint_arm_identify_under_an_address_space_limit(tmp_path):
    """A 50-joint arm (1325 rows of [tril M; g] per configuration, 500 standard parameters):
    its static data identify through the command line under RLIMIT_AS 1.5 GiB (the Gram
    matrices of the rows of s alone were 1.3 GB, the random states' rows 0.34 GB) and
    recover the base parameters of the generating inertias."""
    resource = pytest.importorskip("resource")
    if not hasattr(resource, "RLIMIT_AS") or not os.path.exists("/proc/self/status"):
        pytest.skip("needs RLIMIT_AS and /proc/self/status (Linux)")
    from dynid.io.model_json import load_model_json
    from dynid.io.robot.toml import save_toml
    from dynid.io.static_data import save_static_data

    robot = _chain(50, 4)
    save_toml(tmp_path / "arm.toml", robot)
    ctrl = dynid.SimulatedController(robot)
    save_static_data(tmp_path / "s.npz", dynid.acquire_static(ctrl, 10, np.random.default_rng(5)))
    limit = 3 * 2**29
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    env.pop("DYNID_MAX_STACK_BYTES", None)
    cmd = [sys.executable, "-c", _VM_RUN, str(limit), "identify", "--robot"]
    cmd += [str(tmp_path / "arm.toml"), "--data", str(tmp_path / "s.npz"), "--std", "classical"]
    cmd += ["--out", str(tmp_path / "out"), "--no-figures", "-q"]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=900)
    assert proc.returncode == 0, proc.stderr
    model = load_model_json(tmp_path / "out" / "identification.json")
    truth = model.base.beta_from_phi(robot.phi)
    np.testing.assert_allclose(model.fit.beta, truth, rtol=1e-6, atol=1e-9 * np.abs(truth).max())


def test_simulated_log_in_blocks_equals_the_whole_array_simulation():
    """measured_blocks, a block of 1000 samples at a time, gives exactly the log of
    simulate_measurement on the whole arrays (the same noise of every signal, the same
    dropped samples, rotor and unmodelled torques, the drive's side), and leaves the
    generator where the whole-array simulation leaves it."""
    from dynid.model.drive import Drive
    from dynid.simulation.measurement import measured_blocks
    from dynid.simulation.unmodelled import UnmodelledEffects

    robot = dynid.panda()
    series = random_fourier(robot, np.random.default_rng(1))
    traj = series(sample_times(7.5, 1000.0))
    drive = Drive.from_gears(np.full(7, 50.0), offset=np.linspace(-0.1, 0.1, 7))
    kw = {
        "drop_fraction": 0.1,
        "with_ddq": True,
        "effects": UnmodelledEffects.typical(7, np.random.default_rng(2)),
        "drive": drive,
    }
    rng_a, rng_b = np.random.default_rng(3), np.random.default_rng(3)
    ref = simulate_measurement(robot, traj, rng=rng_a, **kw)
    at = lambda b: series(traj.t[b])  # noqa: E731
    got = measured_blocks(robot, at, len(traj), rng=rng_b, block=1000, **kw)
    pieces = list(got())
    assert len(pieces) == 8 and got.n_samples == ref.n_samples
    for name in ("t", "q", "dq", "tau", "ddq"):
        joined = np.concatenate([getattr(p, name) for p in pieces])
        np.testing.assert_array_equal(joined, getattr(ref, name), err_msg=name)
    assert rng_a.standard_normal() == rng_b.standard_normal()


def test_limits_over_blocks_equal_those_of_the_whole_trajectory(panda):
    """check_limits_blocks and limit_scaling over pieces of a trajectory that exceeds its
    limits give the report and the factors of check_limits and scale_into_limits on the
    whole (each written out on the joined arrays)."""
    from dynid.simulation.limits import (
        check_limits,
        check_limits_blocks,
        limit_scaling,
        scale_into_limits,
    )
    from dynid.simulation.trajectories import sinusoid_trajectory

    t = sample_times(12.0, 500.0)
    A = 1.6 * np.array([1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0])
    T = np.array([3.68, 2.04, 2.98, 1.75, 4.43, 2.749, 1.06])
    traj = sinusoid_trajectory(t, np.zeros(7), A, T)
    at = [sinusoid_trajectory(t[a : a + 700], np.zeros(7), A, T) for a in range(0, t.size, 700)]
    ref = check_limits(panda, traj)
    assert not ref.ok
    assert check_limits_blocks(panda, at) == ref
    for method in ("amplitude", "time"):
        try:
            whole, factor = scale_into_limits(panda, traj, method=method)
        except dynid.LimitError as exc:
            with pytest.raises(dynid.LimitError, match=str(exc)[:40]):
                limit_scaling(panda, lambda: iter(at), method=method)
            continue
        scaling = limit_scaling(panda, lambda: iter(at), method=method)
        assert scaling.factor == factor
        joined = [scaling.apply(p) for p in at]
        np.testing.assert_array_equal(np.concatenate([p.q for p in joined]), whole.q)
        np.testing.assert_array_equal(np.concatenate([p.t for p in joined]), whole.t)


def _simulate_peak(tmp_path, seconds: float) -> int:
    """Peak resident memory [bytes] of ``dynid simulate`` of ``seconds`` at 1 kHz to NPZ
    (the virtual peak also counts address space the allocator reserves and never touches,
    which moves by 150 MB with the order the modules are imported in)."""
    out = tmp_path / f"sim-{seconds:g}.npz"
    cmd = [sys.executable, "-c", _VM_RUN, "0", "simulate", "--trajectory", "fourier"]
    cmd += ["--duration", f"{seconds:g}", "--seed", "1", "--out", str(out), "-q"]
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr
    log = load_torque_log(out)
    assert log.n_samples == round(seconds * 1000) + 1
    return [int(s.split()[1]) for s in proc.stdout.splitlines() if s.startswith("VMHWM")][0]


@pytest.mark.slow
def test_simulate_memory_does_not_grow_with_the_length_of_the_log(tmp_path):
    """dynid simulate computes and writes a log in blocks: 400,001 samples (four blocks)
    peak within 100 MB of 150,001 (two blocks; the whole arrays of the longer log,
    trajectory and measurements, are 0.19 GB more)."""
    if not os.path.exists("/proc/self/status"):
        pytest.skip("needs /proc/self/status (Linux)")
    short = _simulate_peak(tmp_path, 150.0)
    long = _simulate_peak(tmp_path, 400.0)
    assert long < short + 100 * 2**20, (short, long)
