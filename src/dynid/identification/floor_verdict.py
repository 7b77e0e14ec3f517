"""A prediction on measured torques judged against its noise floor: the one engine of
``validate``'s verdict and of ``identify``'s held-out verdict.

The floor is the sensors' noise and the noise the prepared states put into the prediction
(:mod:`~dynid.identification.input_noise`), each sample weighed against its own noise
(:func:`~dynid.identification.input_noise.noise_floor`); the verdict is
:func:`~dynid.identification.verdict.judge_prediction`'s on that floor.

* :func:`prediction_input_noise`: the states' noise through a model at the samples of
  prepared pieces (every k-th sample of a long one);
* :func:`sensor_variance`: a piece's torque sensors' noise variance, at least a quantized
  sensor's rounding;
* :func:`opposite_sign`: whether the measured torques are anti-correlated with the model's;
* :func:`judged_prediction`: the verdict and the floor of pieces' errors.

The callers say what the floor's parts are: ``validate`` reads the sensors' noise from the
torques it judges, ``identify`` takes the noise its fit recorded, at least the held-out
torques' rounding (:func:`~dynid.friction.heldout_torques.heldout_torques`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from .input_noise import (
    FITTED_WORDS,
    NoiseFloor,
    Predict,
    StateNoise,
    input_noise_var,
    noise_floor,
    quantized_noise_std,
)
from .log import TorqueLog
from .metrics import TorqueErrors
from .model_sign import anticorrelated
from .verdict import Verdict, judge_prediction

__all__ = [
    "INPUT_SAMPLES",
    "input_step",
    "judged_prediction",
    "opposite_sign",
    "prediction_input_noise",
    "sensor_variance",
]

#: Samples of a piece at most at which the states' noise is carried through the model
#: (every k-th).
INPUT_SAMPLES = 20_000


def input_step(n_samples: int) -> int:
    """The step ``k`` of the samples of a piece of ``n_samples`` at which a prediction's
    noise is carried (every k-th, at most :data:`INPUT_SAMPLES` of them)."""
    return max(1, n_samples // INPUT_SAMPLES)


def prediction_input_noise(
    rigid: Predict,
    friction: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None,
    logs: Sequence[TorqueLog],
    noise: StateNoise | None,
    separable: bool = False,
) -> list[tuple[int, NDArray[np.float64]]] | None:
    """Per prepared piece ``logs`` (with ``ddq``), every k-th of its samples (at most
    :data:`INPUT_SAMPLES`) and the variance [N^2 m^2] (N_k, n) the states' ``noise`` puts
    into the prediction ``rigid(q, dq, ddq) + friction(dq)`` there
    (:func:`~dynid.identification.input_noise.input_noise_var`, ``separable`` passed on:
    each joint's friction of its own velocity alone); None when the states' noise is not
    known."""
    if noise is None:
        return None
    out = []
    for p in logs:
        assert p.ddq is not None  # prepared: always with ddq
        k = input_step(p.n_samples)
        q, dq, ddq = (np.ascontiguousarray(x[::k]) for x in (p.q, p.dq, p.ddq))
        out.append((k, input_noise_var(rigid, friction, q, dq, ddq, noise, separable)))
    return out


def sensor_variance(log: TorqueLog) -> NDArray[np.float64] | None:
    """The white-noise variance [N^2 m^2] (n,) of a piece's measured torques, at least a
    quantized sensor's ``step^2 / 12``
    (:func:`~dynid.identification.input_noise.quantized_noise_std`); None for fewer than
    3 samples."""
    if log.n_samples < 3:
        return None
    return np.asarray(quantized_noise_std(log.tau, log.t) ** 2, dtype=np.float64)


def opposite_sign(tau: Sequence[NDArray[np.float64]], model: Sequence[NDArray[np.float64]]) -> bool:
    """Whether the measured torques ``tau`` are anti-correlated with the model's ``model``
    (each a sequence of (N_p, n) [N m]) on the joints the model loads (its spread above 5 %
    of the largest), on at most 20 000 samples
    (:func:`~dynid.identification.model_sign.anticorrelated`)."""
    N = sum(t.shape[0] for t in tau)
    step = max(1, N // 20_000)
    t = np.concatenate([x[::step] for x in tau])
    m = np.concatenate([x[::step] for x in model])
    spread = np.std(m, axis=0)
    loaded = spread > 0.05 * max(float(spread.max(initial=0.0)), 1e-300)
    return anticorrelated(m - m.mean(axis=0), t - t.mean(axis=0), loaded) is not None


def judged_prediction(
    tau: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    sensor_var: Sequence[NDArray[np.float64] | None],
    errors: TorqueErrors,
    joint_names: Sequence[str],
    inputs: Sequence[tuple[int, NDArray[np.float64]]] | None = None,
    *,
    opposite: bool = False,
    fitted: Sequence[tuple[int, NDArray[np.float64]]] | None = None,
    fitted_words: str = FITTED_WORDS,
) -> tuple[Verdict, NoiseFloor]:
    """The verdict of a prediction on pieces and the noise floor it was judged against.

    Parameters
    ----------
    tau, error : sequence of ndarray, each (N_p, n)
        Each piece's measured torques and measured less predicted torques [N m].
    sensor_var : sequence of ndarray (n,) or None
        Each piece's torque sensors' noise variance [N^2 m^2] (None: unknown).
    errors : TorqueErrors
        The errors pooled over every sample of the pieces (of a long piece more than
        ``error`` keeps).
    joint_names : sequence of str
    inputs : sequence of (int, ndarray), optional
        The states' noise through the model per piece (:func:`prediction_input_noise`);
        None: not known (the sensors' noise alone).
    opposite : bool
        The torques are anti-correlated with the model's (:func:`opposite_sign`).
    fitted : sequence of (int, ndarray), optional
        The noise the coefficients of a fit that did not see the pieces put into the
        prediction, per piece as ``inputs``
        (:mod:`~dynid.identification.fold_spread`), or of the model's own coefficients
        (:mod:`~dynid.identification.coefficient_noise`); None: not counted.
    fitted_words : str
        How the verdict's floor names that part (default: the folds' coefficients).

    Returns
    -------
    (Verdict, NoiseFloor)
        :func:`~dynid.identification.verdict.judge_prediction` of the pooled error
        against :func:`~dynid.identification.input_noise.noise_floor`, each joint against
        its own noise.
    """
    fl = noise_floor(
        tau, error, sensor_var, inputs, rms=errors.rms, fitted=fitted, fitted_words=fitted_words
    )
    verdict = judge_prediction(
        errors.relative_error_percent,
        fl.percent,
        opposite_sign=opposite,
        joint_ratios=fl.joint_ratios,
        joint_percent=errors.relative_error_percent_per_joint,
        joint_names=joint_names,
        joint_rms=errors.rms,
        joint_rough=None if fl.input_rms is None else fl.input_rms > fl.sensor_rms,
        floor_parts=fl.words,
        ratio=fl.ratio,
    )
    return verdict, fl
