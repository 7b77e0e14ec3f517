"""The noise a prediction's own inputs put into its torques: the floor beside the sensors'.

A model predicts torques from states: positions, and velocities and accelerations that are
measured with noise or derived from positions (filtered, then differentiated). The states'
noise passes through the model, so that even the true model errs by it:

* the accelerations' noise times the mass matrix, with the rotors' inertia on a geared arm
  (``K^T diag(I_a) K``) often its largest part;
* the velocities' noise through the friction law: where a velocity's noise flips its sign
  (a reversal, a standstill) a Coulomb step predicts ``2 f_c`` off.

A sensor-noise floor alone blames that error on "effects outside the model": an SO-101 at
100 Hz whose positions are quantized to 4096 ticks per turn and whose currents to 6.5 mA
steps, validated with its true model: error 1.23 %, 2.3 x a floor of 0.535 %, of which 1.1 %
came from five samples at reversals where the derived velocity had the wrong sign, 0.24 %
from the accelerations' noise through the rotors' inertia, and 0.69 % from the torques'
noise and quantization (the sensor floor read 0.535 %: the quantized wrist currents read
no noise at all).

:func:`quantized_noise_std` reads a signal's white noise, at least its quantization's
(``step / sqrt(12)``) when its samples lie on a lattice (:func:`quantization_step`);
:func:`state_noise` carries the positions' or the measured velocities' noise through the
preparation (:func:`derived_noise_gains`); :func:`input_noise_var` propagates it through
the prediction: exactly for the accelerations (the torques are linear in them), by
equal-probability nodes of the noise for the velocities (a friction step is not
differentiable); :func:`noise_floor` weighs a prediction's error against both, sample by
sample, in the terms :func:`~dynid.identification.verdict.judge_prediction` takes.
:func:`exact_to_round_off` tells logs without noise (a simulation), which identification
fits unfiltered (:func:`exact_note` says so).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, signals
from ..exceptions import ShapeError
from .log import TorqueLog
from .velocity_noise import ROUND_OFF_SHARE, at_round_off, signal_noise_std
from .verdict import NOISE_FLOOR_SHARE, joint_ratios

__all__ = [
    "FITTED_WORDS",
    "LATTICE_SHARE",
    "NODES",
    "NoiseFloor",
    "StateNoise",
    "derived_noise_gains",
    "exact_note",
    "exact_to_round_off",
    "input_noise_var",
    "noise_floor",
    "quantization_step",
    "quantized_noise_std",
    "rounding_std",
    "state_noise",
]

#: A signal is quantized when at least this share of its non-zero steps are whole multiples
#: of one step (the rest: spikes replaced, rounding of a unit scale).
LATTICE_SHARE = 0.9
#: Equal-probability nodes of a velocity's noise at which the prediction is evaluated.
NODES = 16
#: Tolerance of a whole multiple of the step, in steps (a log printed to 6 decimals).
_TOL = 0.02
Predict = Callable[
    [NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]
]


def quantization_step(x: ArrayLike) -> NDArray[np.float64]:
    """The step (n,) of each column of ``x`` (N, n) whose samples lie on a lattice (a
    quantized sensor: encoder ticks, current steps), 0 for a column that does not.

    The candidate steps are the 50th, 25th, 10th and 2nd percentiles of the non-zero
    changes between samples (a few spikes off the lattice do not set them all) divided by 1
    to 10; the largest of which at least :data:`LATTICE_SHARE` of the non-zero changes are
    whole multiples (within 2 % of a step) is the column's, refined as the median of the
    changes over their multiples. A column with fewer than 10 changes has none.
    """
    a = _checks.as_array("x", x)
    if a.ndim != 2:
        raise ShapeError(f"x must have shape (N, n); got {a.shape}")
    out = np.zeros(a.shape[1])
    for j in range(a.shape[1]):
        d = np.abs(np.diff(a[:, j]))
        scale = float(np.max(np.abs(a[:, j]), initial=0.0))
        d = d[d > 1e-12 * scale]
        if d.size < 10:
            continue
        for base in np.quantile(d, (0.5, 0.25, 0.1, 0.02)):
            for k in range(1, 11):
                m = d / (base / k)
                whole = (np.abs(m - np.rint(m)) <= _TOL) & (m > 0.5)
                if np.mean(whole) >= LATTICE_SHARE:
                    out[j] = max(out[j], float(np.median(d[whole] / np.rint(m[whole]))))
                    break
    return out


def quantized_noise_std(x: ArrayLike, t: ArrayLike | None = None) -> NDArray[np.float64]:
    """The white-noise std (n,) of the samples ``x`` (N, n) at times ``t`` (N,): the
    differences' estimate (:func:`~dynid.identification.velocity_noise.signal_noise_std`), at
    least ``step / sqrt(12)`` of a quantized column (:func:`quantization_step`).

    A quantized signal that moves less than a step between samples changes at a few samples
    only: the differences' median reads no noise (the wrist currents of an SO-101 at
    6.5 mA steps: 0), while the rounding errs by ``step / sqrt(12)`` RMS over a motion
    that spans many steps.
    """
    a = _checks.as_array("x", x)
    return np.maximum(signal_noise_std(a, t), rounding_std(a))


def exact_to_round_off(logs: Sequence[TorqueLog]) -> bool:
    """Whether every log of ``logs`` is exact to round-off: its positions, measured
    velocities, torques and accelerations (when it holds them), each column
    (:func:`~dynid.identification.velocity_noise.at_round_off`: a noise-free simulation).

    Such logs need nothing a filter gives: a zero-phase low-pass of exact signals only
    bends the motion the rigid body's torques follow (their products of the states are
    not the products of the filtered states), and its edges and the decimation cost
    samples. Velocities derived from positions (``dq_derived``) are not exact here.
    """
    if not logs:
        return False
    for log in logs:
        if log.dq_derived or log.n_samples < 4:
            return False
        for x in (log.tau, log.q, log.dq, *(() if log.ddq is None else (log.ddq,))):
            if not at_round_off(x, log.t).all():
                return False
    return True


def exact_note(logs: Sequence[TorqueLog]) -> str:
    """The one line that says the logs were found exact (:func:`exact_to_round_off`) and
    fitted as they are, and what limits the fit of those without accelerations."""
    said = (
        "the logs' positions, velocities{} and torques are exact to round-off (noise at most "
        f"{ROUND_OFF_SHARE:g} of their RMS): fitted unfiltered at every sample, none trimmed "
        "or decimated (--cutoff sets a filter)"
    )
    if all(log.ddq is not None for log in logs):
        return said.format(", accelerations")
    return said.format("") + (
        "; their accelerations differentiated from the velocities "
        f"(differences of order {signals.EXACT_DERIVATIVE_ORDER}), which err by "
        f"(2 pi f dt)^{signals.EXACT_DERIVATIVE_ORDER} / 630 of them: a ddq column is exact"
    )


def rounding_std(x: ArrayLike) -> NDArray[np.float64]:
    """The RMS error ``step / sqrt(12)`` (n,) of rounding each column of ``x`` (N, n) to its
    quantization step (:func:`quantization_step`; 0 for a column that is not quantized)."""
    return quantization_step(x) / np.sqrt(12.0)


def derived_noise_gains(
    dt: float, cutoff_hz: float | None, *, derived: bool
) -> tuple[float, float]:
    """The std of the prepared velocities [1/s] and accelerations [1/s^2] per unit white
    noise on the positions (``derived``: a log without velocities, whose velocities are the
    filtered derivative of its positions, low-passed again) or on the measured velocities
    (the velocities low-passed [1], the accelerations their derivative [1/s]), at the step
    ``dt`` [s] and ``cutoff_hz`` [Hz] (None: not filtered): the root sum of squares of the
    preparation's impulse response
    (:func:`~dynid.identification.prepare.prepare_log`'s steps 2 and 3)."""
    fc = cutoff_hz
    half = int(np.ceil(8.0 * signals.edge_seconds(fc) / dt)) + 8 if fc else 8
    t = dt * np.arange(2 * half + 1)
    x = np.zeros((2 * half + 1, 1))
    x[half] = 1.0
    if derived:
        assert fc is not None  # positions only: derived at a cut-off
        v = signals.lowpass(signals.filtered_derivative(t, x, fc), 1.0 / dt, fc)
    else:
        v = signals.lowpass(x, 1.0 / dt, fc) if fc else x
    a = signals.derivative(t, v)
    return float(np.sqrt(np.sum(v**2))), float(np.sqrt(np.sum(a**2)))


@dataclass(frozen=True, slots=True)
class StateNoise:
    """The white noise of prepared states, per joint.

    Attributes
    ----------
    dq : ndarray, shape (n,)
        Of the velocities [rad/s].
    ddq : ndarray, shape (n,)
        Of the accelerations [rad/s^2].
    derived : bool
        The velocities were derived from the positions (some log without velocities).
    """

    dq: NDArray[np.float64]
    ddq: NDArray[np.float64]
    derived: bool = False


def state_noise(pieces: Sequence[TorqueLog], cutoff_hz: float | None) -> StateNoise | None:
    """The noise of the velocities and accelerations the pieces ``pieces`` (joint side, as
    read: before filtering) are prepared to at ``cutoff_hz`` [Hz]: each piece's positions'
    noise (velocities derived from them, ``dq_derived``) or its measured velocities' noise
    (:func:`quantized_noise_std`) times :func:`derived_noise_gains`; a recorded ``ddq`` its
    own noise low-passed. The variances are averaged with the pieces' samples as weights;
    None when no piece has 8 samples."""
    var_v, var_a, w = [], [], []
    derived = False
    for p in pieces:
        if p.n_samples < 8:
            continue
        dt = float(np.median(np.diff(p.t)))
        fc = cutoff_hz
        if fc is not None and fc >= 0.5 / dt:  # moved below Nyquist, as the preparation does
            fc = 0.25 / dt
        if p.dq_derived and fc is None:  # not prepared so (derived at a cut-off only)
            continue
        derived |= p.dq_derived
        src = p.q if p.dq_derived else p.dq
        sigma = quantized_noise_std(src, p.t)
        gv, ga = derived_noise_gains(dt, fc, derived=p.dq_derived)
        var_v.append((gv * sigma) ** 2)
        if p.ddq is not None:  # recorded: its own noise, low-passed
            g = signals.lowpass_noise_gain(1.0 / dt, fc)
            var_a.append((g * quantized_noise_std(p.ddq, p.t)) ** 2)
        else:
            var_a.append((ga * sigma) ** 2)
        w.append(p.n_samples)
    if not w:
        return None
    dq = np.sqrt(np.average(np.asarray(var_v), axis=0, weights=w))
    ddq = np.sqrt(np.average(np.asarray(var_a), axis=0, weights=w))
    return StateNoise(_checks.frozen(dq), _checks.frozen(ddq), derived)


def _nodes(m: int) -> NDArray[np.float64]:
    """``m`` equal-probability nodes of a unit normal (the midpoints of ``m`` equal slices
    of probability), scaled to a second moment of exactly 1."""
    from scipy.special import ndtri

    z = ndtri((np.arange(m) + 0.5) / m)
    return np.asarray(z / np.sqrt(np.mean(z**2)), dtype=np.float64)


def input_noise_var(
    rigid: Predict,
    friction: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    noise: StateNoise,
    separable: bool = False,
) -> NDArray[np.float64]:
    """The variance (N, n) [N^2 m^2] the states' ``noise`` puts into the prediction
    ``rigid(q, dq, ddq) + friction(dq)`` [N m] of each joint at each sample.

    .. math:: V_{kj} = \\sum_i \\big(M_{ji} \\sigma_{\\ddot q_i}\\big)^2
              + \\sum_i \\Big(\\frac{\\partial \\tau_j}{\\partial \\dot q_i}
              \\sigma_{\\dot q_i}\\Big)^2
              + \\sum_i \\mathrm E_\\epsilon \\big[(f_j(\\dot q_k + \\sigma_{\\dot q_i}
              \\epsilon e_i) - f_j(\\dot q_k))^2\\big]

    The accelerations' part is exact (the torques are linear in them: the prediction at
    ``ddq + sigma_i e_i`` less that at ``ddq``), the rigid body's velocity part a central
    difference (smooth: quadratic), the friction's the mean over :data:`NODES`
    equal-probability nodes ``epsilon`` of a unit normal, so that a Coulomb step counts
    ``(2 f_c)^2`` times the probability that the noise flips the velocity's sign. The joints'
    noises are taken independent, and the velocities' of the accelerations'.

    Parameters
    ----------
    rigid : callable
        ``(q, dq, ddq) -> tau`` [N m], each (N, n): the prediction without friction.
    friction : callable or None
        ``dq -> tau_f`` [N m], (N, n) -> (N, n): the friction added to it.
    q, dq, ddq : ndarray, shape (N, n)
        The prepared states [rad, rad/s, rad/s^2].
    noise : StateNoise
    separable : bool
        Each joint's friction depends on its own velocity alone
        (:func:`~dynid.friction.model.joint_separable`): then every joint's velocity is
        moved to a node at once, one ``friction`` call per node instead of one per node
        and joint, the same numbers (a joint whose velocity did not move adds exactly 0).
    """
    base = rigid(q, dq, ddq)
    var = np.zeros(base.shape)
    f0 = None if friction is None else friction(dq)
    z = _nodes(NODES)
    each = (
        None
        if friction is None or f0 is None or not separable
        else _node_terms(friction, f0, dq, noise, z)
    )
    for i in range(q.shape[1]):
        if noise.ddq[i] > 0:
            a = ddq.copy()
            a[:, i] += noise.ddq[i]
            var += (rigid(q, dq, a) - base) ** 2
        s = noise.dq[i]
        if s > 0:
            up, down = dq.copy(), dq.copy()
            up[:, i] += s
            down[:, i] -= s
            var += ((rigid(q, up, ddq) - rigid(q, down, ddq)) / 2.0) ** 2
            if each is not None:  # joint i's own column: the others' terms are 0
                for d in each:
                    var[:, i] += d[:, i]
            elif friction is not None and f0 is not None:
                for e in z:
                    up[:, i] = dq[:, i] + s * e
                    var += (friction(up) - f0) ** 2 / z.size
    return var


def _node_terms(
    friction: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    f0: NDArray[np.float64],
    dq: NDArray[np.float64],
    noise: StateNoise,
    z: NDArray[np.float64],
) -> list[NDArray[np.float64]]:
    """Per node ``e`` of ``z``, ``(friction(dq + s e) - f0)^2 / z.size`` (N, n) [N^2 m^2]
    with every joint's velocity moved by its own noise ``s`` (those without noise not
    moved): column ``i`` the term :func:`input_noise_var` adds for joint ``i``'s node when
    each joint's friction depends on its own velocity alone."""
    s = np.asarray(noise.dq, dtype=np.float64)
    moved = np.flatnonzero(s > 0)
    out = []
    for e in z:
        up = dq.copy()
        up[:, moved] = dq[:, moved] + s[moved] * e
        out.append((friction(up) - f0) ** 2 / z.size)
    return out


#: How the floor's words name the part of coefficients fitted without the samples judged
#: (a held-out fold's).
FITTED_WORDS = "that of the coefficients fitted without these samples"


@dataclass(frozen=True, slots=True)
class NoiseFloor:
    """The noise a perfect model leaves on some pieces, and an error weighed against it.

    Attributes
    ----------
    sensor_rms : ndarray, shape (n,)
        The torque sensors' noise per joint [N m].
    input_rms : ndarray, shape (n,), or None
        The states' noise through the model per joint [N m] (RMS over the samples); None:
        not known.
    total_rms : ndarray, shape (n,)
        Both, root sum of squares [N m].
    percent : float
        ``total`` over every sample relative to the torques' norm [%] (0: torques of zero
        norm).
    ratio : float or None
        The error over the floor, each sample's squared error weighed by its joint's mean
        noise variance over its own (None: the plain quotient applies, no states' noise).
    joint_ratios : ndarray, shape (n,), or None
        Each joint's error over its noise, weighed so (None: no noise known).
    words : str or None
        The floor's parts for the verdict (``judge_prediction``'s ``floor_parts``).
    fit_rms : ndarray, shape (n,), or None
        The noise of coefficients fitted without the samples judged, through the model,
        per joint [N m] (RMS over the samples; :mod:`~dynid.identification.fold_spread`);
        None: not counted.
    """

    sensor_rms: NDArray[np.float64]
    input_rms: NDArray[np.float64] | None
    total_rms: NDArray[np.float64]
    percent: float
    ratio: float | None
    joint_ratios: NDArray[np.float64] | None
    words: str | None
    fit_rms: NDArray[np.float64] | None = None


def noise_floor(
    tau: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    sensor_var: Sequence[NDArray[np.float64] | None],
    inputs: Sequence[tuple[int, NDArray[np.float64]]] | None = None,
    rms: NDArray[np.float64] | None = None,
    fitted: Sequence[tuple[int, NDArray[np.float64]]] | None = None,
    fitted_words: str = FITTED_WORDS,
) -> NoiseFloor:
    """The noise floor of pieces and their prediction error weighed against it.

    The floor is the sensors' noise and, with ``inputs``, the states' noise through the
    model (:func:`input_noise_var`). The latter varies from sample to sample (a friction
    step where the velocity's noise can flip its sign): each sample's squared error is
    weighed by its joint's mean noise variance over its own, so that the noise at a few
    reversals does not excuse an error spread over the moving samples; a constant noise
    gives the plain quotient of the errors' and the floor's norms. A joint's noise counts at
    least :data:`~dynid.identification.verdict.NOISE_FLOOR_SHARE` of the largest joint's.

    Parameters
    ----------
    tau, error : sequence of ndarray, each (N_p, n)
        Each piece's measured torques and measured less predicted torques [N m].
    sensor_var : sequence of ndarray (n,) or None
        Each piece's sensor noise variance [N^2 m^2] (None: unknown, the pieces' mean).
    inputs : sequence of (int, ndarray (M_p, n)), optional
        Each piece's step ``k`` and the states' noise variance at its every k-th sample
        [N^2 m^2].
    rms : ndarray, shape (n,), optional
        The RMS error per joint over every sample [N m] (default: over ``error``'s), for
        pieces that keep every k-th sample of a longer prediction.
    fitted : sequence of (int, ndarray (M_p, n)), optional
        The noise of coefficients fitted without these pieces through the model, each
        piece's as ``inputs`` (the same steps), a part of the floor weighed with the
        states' noise and said on its own.
    fitted_words : str
        How the floor's words name that part (default :data:`FITTED_WORDS`: coefficients
        fitted without these samples).
    """
    n = tau[0].shape[1]
    N = sum(t.shape[0] for t in tau)
    var = sum(
        (t.shape[0] * s for t, s in zip(tau, sensor_var, strict=True) if s is not None), np.zeros(n)
    )
    norm2 = float(sum(np.sum(t**2) for t in tau))
    own = None if fitted is None else _every_sample(fitted, N, n)
    alone = None if inputs is None else _every_sample(inputs, N, n)  # the states' own part
    if fitted is not None:
        inputs = (
            fitted
            if inputs is None
            else [(k, V + F) for (k, V), (_, F) in zip(inputs, fitted, strict=True)]
        )
    put = np.zeros(n) if inputs is None else _every_sample(inputs, N, n)
    total = np.sqrt((var + put) / max(N, 1))
    percent = 100.0 * float(np.sqrt((var + put).sum() / norm2)) if norm2 > 0 else 0.0
    if rms is None:
        rms = np.sqrt(sum(np.sum(e**2, axis=0) for e in error) / max(N, 1))
    ratio, ratios, words = None, None, None
    if np.all(total > 0):
        ratios = joint_ratios(rms, total)
    if inputs is not None and norm2 > 0 and put.sum() > 0 and np.all(total > 0):
        least = (NOISE_FLOOR_SHARE * float(np.max(total))) ** 2
        mean = np.maximum(total**2, least)
        w_e2, count = np.zeros(n), 0
        for (k, V), e, s2 in zip(inputs, error, sensor_var, strict=True):
            f = np.maximum(V + (var / max(N, 1) if s2 is None else s2), least)
            w_e2 += np.sum(e[::k] ** 2 * mean / f, axis=0)
            count += V.shape[0]
        ratios = np.sqrt(w_e2 / max(count, 1) / mean)
        ratio = float(np.sqrt(np.sum(w_e2) / max(count, 1) / np.sum(mean)))
        words = _floor_words(var, alone, own, norm2, fitted_words)
    return NoiseFloor(
        sensor_rms=np.sqrt(var / max(N, 1)),
        input_rms=None if alone is None else np.sqrt(alone / max(N, 1)),
        total_rms=total,
        percent=percent,
        ratio=ratio,
        joint_ratios=ratios,
        words=words,
        fit_rms=None if own is None else np.sqrt(own / max(N, 1)),
    )


def _every_sample(
    pieces: Sequence[tuple[int, NDArray[np.float64]]], N: int, n: int
) -> NDArray[np.float64]:
    """The variances of ``pieces`` (each its step and its every k-th sample's (M, n))
    summed per joint over all ``N`` samples [N^2 m^2] (n,)."""
    put = sum((k * np.sum(V, axis=0) for k, V in pieces), np.zeros(n))
    return np.asarray(put * N / max(sum(k * V.shape[0] for k, V in pieces), 1), np.float64)


def _floor_words(
    var: NDArray[np.float64],
    states: NDArray[np.float64] | None,
    own: NDArray[np.float64] | None,
    norm2: float,
    fitted_words: str = FITTED_WORDS,
) -> str:
    """The floor's parts in words: the torques' noise ``var``, the states' (``states``,
    when known) and that of the coefficients (``own``, named by ``fitted_words``, default
    :data:`FITTED_WORDS`), each summed over the samples [N^2 m^2] (n,), in % of the
    torques' norm."""

    def pct(x: NDArray[np.float64]) -> str:
        return f"{100 * np.sqrt(max(float(x.sum()), 0.0) / norm2):.3g} %"

    parts = [f"the torques' noise {pct(var)}"]
    if states is not None:
        parts.append(f"that of the states through the model {pct(states)}")
    if own is not None:
        parts.append(f"{fitted_words} {pct(own)}")
    said = ", ".join(parts[:-1]) + f" and {parts[-1]}"
    return (
        f", of which {said}; the ratio weighs each sample against its own noise, which "
        "varies along the motion, so it is not the quotient of the pooled percentages"
    )
