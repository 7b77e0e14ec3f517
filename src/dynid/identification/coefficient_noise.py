"""The noise an identified model's own coefficients put into its prediction of a log.

Coefficients fitted on noisy recordings differ from the truth's by their estimation
error, of covariance ``Sigma`` (the one the fit records,
:meth:`~dynid.identification.model.IdentifiedModel.coefficient_covariance`: the base
parameters and the appended terms' coefficients together). A model of the right structure
then predicts a log the fit did not see with an error beside the sensors' noise, however
exact that log: a UR5 identified from noisy recordings erred 0.05 % on an exact held-out
log, for 8.6e-14 % of noise there, while its coefficients' uncertainty allowed 0.1 %. The
prediction's variance at a sample is ``diag(Y_i Sigma Y_i^T)`` (n,) with ``Y_i`` the
model's columns there (:func:`~dynid.identification.log_rows.term_regressor`,
:func:`~dynid.identification.fold_spread.prediction_variance`), counted in the noise
floor sample by sample like the states' noise, at its mean plus one standard deviation of
the one draw the coefficients are
(:func:`~dynid.identification.fold_spread.draw_margin_of`: every sample shares them).

* :func:`coefficient_noise`: that variance at the samples of prepared pieces (every k-th,
  as :func:`~dynid.identification.floor_verdict.prediction_input_noise` carries the
  states' noise), and the draw's margin (:class:`CoefficientNoise`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .floor_verdict import input_step
from .fold_spread import draw_margin_of, joint_grams, prediction_variance
from .log import TorqueLog
from .log_rows import less_known_rotors, term_regressor
from .model import IdentifiedModel
from .verdict import SYSTEMATIC_RATIO

__all__ = ["CoefficientNoise", "coefficient_noise", "held_at_floor"]

#: Samples of a piece whose columns are formed at once (bounds the regressor held).
_BLOCK = 2_048


@dataclass(frozen=True, slots=True, eq=False)
class CoefficientNoise:
    """The variance a model's coefficients put into its prediction of pieces.

    Attributes
    ----------
    pieces : tuple of (int, ndarray (M_k, n))
        Per piece, the step ``k`` and the variance [N^2 m^2] at its every k-th sample:
        the mean over the coefficients' estimation error, ``diag(Y_i Sigma Y_i^T)``.
    margin : ndarray, shape (n,)
        Per joint, the factor from the squared error the one draw of the coefficients adds
        over every sample at its mean to its mean plus one standard deviation
        (:func:`~dynid.identification.fold_spread.draw_margin_of`; at least 1).
    """

    pieces: tuple[tuple[int, NDArray[np.float64]], ...]
    margin: NDArray[np.float64]

    @property
    def counted(self) -> list[tuple[int, NDArray[np.float64]]]:
        """Per piece, the step and the variance [N^2 m^2] the floor counts: ``pieces``'
        times ``margin``."""
        return [(k, V * self.margin) for k, V in self.pieces]


def held_at_floor(model: IdentifiedModel) -> bool:
    """Whether ``model``'s own identification predicted its held-out folds within
    :data:`~dynid.identification.verdict.SYSTEMATIC_RATIO` times their noise floor
    (``info.heldout``'s ``heldout_error_percent`` against ``noise_floor_percent``): only
    then is the covariance it recorded its coefficients' estimation error alone. A fit
    that left effects outside its model records a covariance the misfit inflates (a
    heteroskedasticity-and-autocorrelation-consistent estimate reads the misfit as
    noise), and counted in the floor it would hide the tilt, spring or torque-constant
    findings ``validate`` exists to name. False where the file records no held-out
    errors."""
    held = model.info.heldout or {}
    err, floor = held.get("heldout_error_percent"), held.get("noise_floor_percent")
    if err is None or floor is None or not (np.isfinite(err) and np.isfinite(floor)):
        return False
    return bool(floor > 0 and err <= SYSTEMATIC_RATIO * floor)


def coefficient_noise(
    model: IdentifiedModel,
    logs: Sequence[TorqueLog],
    tau_model: Sequence[NDArray[np.float64]],
    *,
    friction: bool,
    seen: Sequence[bool] | None = None,
) -> CoefficientNoise | None:
    """Per prepared piece, the variance [N^2 m^2] ``model``'s coefficients' covariance
    puts into its prediction at every k-th of its samples, and the margin of their one
    draw (module docstring).

    Parameters
    ----------
    model : IdentifiedModel
    logs : sequence of TorqueLog
        The prepared pieces (with ``ddq``), at the joints.
    tau_model : sequence of ndarray, each (N_p, n)
        The model's torques at the pieces' samples, friction not included [N m] (the
        model's columns are checked against them).
    friction : bool
        The prediction holds the model's own friction: its friction terms' columns count
        (else the base parameters' and the other appended terms' alone).
    seen : sequence of bool, optional
        Per piece, whether the fit saw it (a recording the model was identified from):
        its residual holds no estimation error of its own, no part is counted there
        (zeros).

    Returns
    -------
    CoefficientNoise or None
        The steps as :func:`~dynid.identification.floor_verdict.input_step`; None where
        the model records no covariance of every coefficient or its columns do not give
        its torques (a piece without ``ddq``), or whose own identification was not held
        out at its floor (:func:`held_at_floor`).
    """
    cov = model.coefficient_covariance()
    if cov is None or not logs or not held_at_floor(model):
        return None
    terms = tuple(t.term for t in model.terms.values())
    x = np.concatenate([np.asarray(model.fit.beta)] + [t.values for t in model.appended])
    own = np.ones(x.size, dtype=bool)  # the columns of the torques without friction
    c = model.base.rank
    for t in model.appended:
        own[c : c + len(t.labels)] = t.friction is None
        c += len(t.labels)
    cols = np.ones(x.size, dtype=bool) if friction else own
    S = cov[np.ix_(cols, cols)]
    out, grams = [], np.zeros((model.robot.n, int(cols.sum()), int(cols.sum())))
    for p, log in enumerate(logs):
        if log.ddq is None:
            return None
        k = input_step(log.n_samples)
        at = np.arange(0, log.n_samples, k)
        V = np.zeros((at.size, log.n))
        for a in range(0, at.size, _BLOCK):
            i = at[a : a + _BLOCK]
            Y, _ = term_regressor(model.robot, model.base, terms, log.q[i], log.dq[i], log.ddq[i])
            want = less_known_rotors(tau_model[p][i], log.ddq[i], model.drive)
            scale = max(float(np.sqrt(np.mean(tau_model[p][i] ** 2))), 1e-300)
            if not np.allclose(Y[..., own] @ x[own], want, rtol=0.0, atol=1e-6 * scale):
                return None  # not the model's columns: no part said
            if seen is not None and seen[p]:
                continue
            V[a : a + i.size] = prediction_variance(Y[..., cols], S)
            grams += joint_grams(Y[..., cols], k)
        out.append((k, V))
    return CoefficientNoise(tuple(out), draw_margin_of([(grams, S)]))
