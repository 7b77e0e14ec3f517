"""A long log prepared in blocks (issue 28 item 5): each block filtered over a window that
reaches beyond it, so that the blocks together equal the whole-array steps.

References: scipy's zero-phase Butterworth (each end continued by numpy's cubic fitted to
its last period of the cut-off, as :func:`dynid.signals.lowpass` does) and numpy's gradient
and interpolation on the whole arrays.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from dynid.exceptions import ShapeError
from dynid.identification import prepare as prepare_module
from dynid.identification.log import TorqueLog
from dynid.identification.prepare import Preprocessing, prepare_log, prepared_blocks


def _log(seed: int, N: int, n: int = 3, *, jitter: bool = False) -> TorqueLog:
    """Sinusoids of 0.5-5 Hz with position noise, white-noise torques, at 1 kHz (jittered
    times when ``jitter``)."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) * 1e-3
    if jitter:
        t = t + rng.uniform(-2e-4, 2e-4, N)
        t[0] = 0.0
    f = rng.uniform(0.5, 5.0, (4, n))
    a = rng.uniform(0.1, 1.0, (4, n))
    w = 2 * np.pi * f
    q = np.einsum("kj,ikj->ij", a, np.sin(w * t[:, None, None])) + rng.normal(0, 1e-4, (N, n))
    dq = np.einsum("kj,ikj->ij", a * w, np.cos(w * t[:, None, None]))
    return TorqueLog(t, q, dq + rng.normal(0, 1e-2, (N, n)), rng.normal(size=(N, n)))


def _lowpass(x: np.ndarray, fs: float, cut: float) -> np.ndarray:
    """scipy's forward-backward Butterworth of each column of ``x`` (N, n), continued at each
    end over three periods of the cut-off by numpy's cubic fitted to one period."""
    sos = scipy.signal.butter(4, cut, fs=fs, output="sos")
    period = fs / cut
    N = x.shape[0]
    m, L = min(N, max(4, int(np.ceil(period)))), int(np.ceil(3 * period))
    k = np.arange(m)
    out = np.empty_like(x)
    for j in range(x.shape[1]):
        left = np.polyval(np.polyfit(k, x[:m, j], 3), np.arange(-L, 0))
        right = np.polyval(np.polyfit(k, x[-m:, j], 3), m - 1 + np.arange(1, L + 1))
        ext = np.concatenate([left, x[:, j], right])
        y = scipy.signal.sosfiltfilt(sos, ext, padtype="odd", padlen=int(np.ceil(period)))
        out[:, j] = y[L : L + N]
    return out


def _reference(
    log: TorqueLog, fs: float, cut: float, filter_tau: bool, k: int, jitter: bool
) -> dict:
    """The steps of prepare_log on the whole arrays: resample a jittered log (numpy's
    interp on the grid t0 + i / fs), scipy's sosfiltfilt (:func:`_lowpass`), numpy's
    gradient, trim 2 / cut, every k-th."""
    m = int(np.floor((log.t[-1] - log.t[0]) * fs * (1 + 1e-12))) + 1
    t = log.t[0] + np.arange(m) / fs if jitter else log.t
    raw = {
        name: np.stack([np.interp(t, log.t, x[:, j]) for j in range(x.shape[1])], 1)
        for name, x in (("q", log.q), ("dq", log.dq), ("tau", log.tau))
    }

    def lp(x):
        return _lowpass(x, fs, cut)

    dq = lp(raw["dq"])
    ref = {"t": t, "q": lp(raw["q"]), "dq": dq, "ddq": np.gradient(dq, t, axis=0, edge_order=2)}
    ref["tau"] = lp(raw["tau"]) if filter_tau else raw["tau"]
    keep = (t >= t[0] + 2 / cut) & (t <= t[-1] - 2 / cut)
    return {name: x[keep][::k] for name, x in ref.items()}


@pytest.mark.parametrize(
    ("filter_tau", "k", "jitter"), [(True, 1, False), (False, 7, False), (True, 3, True)]
)
def test_blocks_equal_the_whole_array_steps(monkeypatch, filter_tau, k, jitter):
    """prepare_log forced into blocks of 500 samples (a window of 20 cut-off periods beyond
    each) equals scipy and numpy on the whole arrays to rounding; so does the
    concatenation of prepared_blocks."""
    log = _log(1, 9_000, jitter=jitter)
    fs, cut = 1000.0, 20.0
    ref = _reference(log, fs, cut, filter_tau, k, jitter)
    monkeypatch.setattr(prepare_module, "PREPARE_BLOCK_SAMPLES", 500)
    prep = Preprocessing(cutoff_hz=cut, filter_tau=filter_tau, decimate=k, fs=fs)
    p = prepare_log(log, prep)
    blocks = list(prepared_blocks(log, prep))
    assert len(blocks) > 2
    for name, x in ref.items():
        scale = float(np.max(np.abs(x)))
        np.testing.assert_allclose(getattr(p, name), x, rtol=0, atol=1e-12 * scale)
        joined = np.concatenate([getattr(b, name) for b in blocks])
        np.testing.assert_allclose(joined, x, rtol=0, atol=1e-12 * scale)


def test_blocks_of_derived_velocities_equal_the_whole_log(monkeypatch):
    """Velocities derived from positions are filtered twice: the blocks' wider windows
    still give the whole log's preparation (scipy's filter and numpy's gradient)."""
    base = _log(2, 8_000)
    log = TorqueLog(base.t, base.q, np.zeros_like(base.q), base.tau, dq_derived=True)
    fs, cut = 1000.0, 25.0

    def lp(x):
        return _lowpass(x, fs, cut)

    dq = lp(np.gradient(lp(log.q), log.t, axis=0, edge_order=2))
    ddq = np.gradient(dq, log.t, axis=0, edge_order=2)
    keep = (log.t >= 2 / cut) & (log.t <= log.t[-1] - 2 / cut)
    monkeypatch.setattr(prepare_module, "PREPARE_BLOCK_SAMPLES", 600)
    p = prepare_log(log, Preprocessing(cutoff_hz=cut))
    for got, want in ((p.dq, dq[keep]), (p.ddq, ddq[keep])):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * float(np.max(np.abs(want))))


def test_a_block_size_below_one_is_refused():
    with pytest.raises(ShapeError, match="block_samples"):
        next(prepared_blocks(_log(3, 2_000), Preprocessing(cutoff_hz=20.0), block_samples=0))


def test_a_long_recording_is_validated_in_blocks_with_every_samples_errors(monkeypatch):
    """A recording longer than KEPT_SAMPLES is prepared and predicted block by block: its
    errors (pooled, per joint, with and without friction) equal those of the whole
    prepared log written out with numpy; the figures' log keeps every k-th sample."""
    from dynid.friction import validation
    from dynid.friction.model import ClassicalFriction
    from dynid.friction.recordings import prepare_pieces, validate_recordings

    log = _log(4, 9_000)
    fr = ClassicalFriction.from_array(np.array([[0.5, 0.2, 0.01], [0.3, 0.1, 0.0], [1.0, 0, 0]]))

    def model(q, dq, ddq):
        return 0.1 * q + 0.01 * ddq

    whole = prepare_pieces(model, [log], cutoff_hz=20.0).logs[0]  # one block: the reference
    e0 = whole.tau - (0.1 * whole.q + 0.01 * whole.ddq)
    e1 = e0 - fr.torques(whole.dq)
    monkeypatch.setattr(prepare_module, "PREPARE_BLOCK_SAMPLES", 700)
    monkeypatch.setattr(validation, "KEPT_SAMPLES", 2_000)
    val = validate_recordings(model, [log], friction=fr, cutoff_hz=20.0)
    (part,) = val.parts
    assert part.step == 5
    np.testing.assert_allclose(part.log.t, whole.t[::5], rtol=0, atol=1e-12)
    assert val.pieces.n_samples == whole.n_samples
    for got, e in ((val.without_friction, e0), (val.with_friction, e1)):
        np.testing.assert_allclose(got.rms, np.sqrt(np.mean(e**2, axis=0)), rtol=1e-10)
        np.testing.assert_allclose(
            got.relative_error_percent_per_joint,
            100 * np.linalg.norm(e, axis=0) / np.linalg.norm(whole.tau, axis=0),
            rtol=1e-10,
        )
        assert got.n_samples == whole.n_samples
    rec = val.recordings[0].errors
    np.testing.assert_allclose(
        rec.relative_error_percent, 100 * np.linalg.norm(e1) / np.linalg.norm(whole.tau), rtol=1e-10
    )


def test_a_read_log_is_immutable_without_a_copy(tmp_path):
    """The CSV reader fills buffers that only read-only views reach: nobody can make the
    arrays writable again (numpy refuses), as with the frozen copies before."""
    from dynid.io.torque_log import load_torque_log, save_torque_log

    log = _log(5, 300)
    save_torque_log(tmp_path / "a.csv", log)
    back = load_torque_log(tmp_path / "a.csv")
    np.testing.assert_array_equal(back.q, log.q)
    for x in (back.t, back.q, back.dq, back.tau):
        with pytest.raises(ValueError):
            x.setflags(write=True)


@pytest.mark.parametrize("N", [40, 41, 43])
def test_a_long_signal_is_differentiated_in_blocks_as_numpy_whole(monkeypatch, N):
    """derivative in blocks of 7 samples (one of overlap) is numpy's second-order gradient
    of the whole signal on a non-uniform grid, bit for bit (a last block of one sample
    included)."""
    from dynid import signals

    rng = np.random.default_rng(N)
    t = np.cumsum(rng.uniform(0.5, 1.5, N))
    x = rng.normal(size=(N, 2))
    monkeypatch.setattr(signals, "_GRADIENT_BLOCK", 7)
    np.testing.assert_array_equal(signals.derivative(t, x), np.gradient(x, t, axis=0, edge_order=2))


def test_the_observer_run_block_by_block_equals_one_run_and_the_numpy_path():
    """A long log's residual is computed a block at a time, the observer's state carried
    (observe's batch path): the same residual as one run and as the numpy loop over every
    sample."""
    import dynid
    from dynid.observer import MomentumObserver, ObserverOptions, from_robot

    robot = dynid.panda()
    rng = np.random.default_rng(9)
    N = 1_000
    t = np.arange(N) * 1e-3 + np.r_[0.0, rng.uniform(-3e-4, 3e-4, N - 1)]
    q = 0.3 * np.sin(np.outer(t, np.arange(1, 8)))
    dq = 0.3 * np.arange(1, 8) * np.cos(np.outer(t, np.arange(1, 8)))
    tau = rng.normal(size=q.shape)
    model, opts = from_robot(robot), ObserverOptions(gain=50.0)
    whole = MomentumObserver(model, opts).run(t, q, dq, tau)
    obs = MomentumObserver(model, opts)
    blocks = np.concatenate(
        [
            obs.run(t[a : a + 97], q[a : a + 97], dq[a : a + 97], tau[a : a + 97])
            for a in range(0, N, 97)
        ]
    )
    slow = MomentumObserver(model, opts)
    ref = slow._run_numpy(t, q, dq, slow._u(q, dq, tau, friction=True))
    np.testing.assert_allclose(blocks, ref, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(blocks, whole)
