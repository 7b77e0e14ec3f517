"""A model's ``M(q)`` and ``g(q)`` judged against static data it was not fitted to.

The paper's route (Gaz et al. 2019, Sec. IV-A) identifies the base parameters from the
controller's inertia matrices and gravity torques at static configurations; the check of
such a model is the same quantities at configurations held out. :func:`static_validation`
compares a model's predictions with a static data set entry by entry over the stacked
rows ``s = [tril M; g]`` (:func:`~dynid.regressors.static.static_vector`, the rows the
identification fits):

* the relative error ``100 ||s - s_hat|| / ||s||`` [%], pooled, and of ``M`` and ``g``
  apart;
* per joint ``j``, the RMS error of ``g_j`` [N m] and of row ``j`` of ``M`` [kg m^2], and
  the relative error of the entries that hold joint ``j`` (``g_j`` and ``M_jk``, every
  ``k``) [%];
* the noise floor where the data record their noise: the simulated controller's relative
  noise ``eps`` multiplies every entry by ``1 + eps z``
  (:mod:`~dynid.simulation.controller`), so the noise's norm over the entries' is ``eps``
  (``100 eps`` %, each joint's too), and an identified model's coefficients, fitted to
  noisy data, err by their own covariance ``C`` (``y^T C y`` an entry, ``y`` its row of
  the base regressor): a model of a Panda fitted to 300 configurations at ``eps = 1e-3``
  predicted joint 7's small entries at 8.4 x ``eps``, its coefficients' error, not an
  effect it lacks. Data that record no noise (a real controller's answers, its own
  model's): no floor, and the relative thresholds judge.

The verdict is :func:`~dynid.identification.verdict.judge_prediction`'s, as for torques,
in words of ``M`` and ``g`` (``kind="static"``: no excitation or drive to blame).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import ShapeError
from ..regressors.static import static_vector
from .data import StaticDataset
from .verdict import Verdict, judge_prediction

__all__ = ["CHANCE_SIGMAS", "StaticValidation", "recorded_noise", "static_validation"]


@dataclass(frozen=True, slots=True, eq=False)
class StaticValidation:
    """A model's ``M`` and ``g`` against static data.

    Attributes
    ----------
    relative_error_percent : float
        ``100 ||s - s_hat|| / ||s||`` over every configuration's ``[tril M; g]`` [%].
    m_error_percent, g_error_percent : float
        The same of ``tril M`` and of ``g`` alone [%].
    g_rms : ndarray, shape (n,)
        Each joint's RMS error of ``g_j`` [N m] (N for a prismatic joint).
    m_rms : ndarray, shape (n,)
        Each joint's RMS error over row ``j`` of ``M`` (every ``M_jk``) [kg m^2].
    joint_percent : ndarray, shape (n,)
        Each joint's relative error over ``g_j`` and row ``j`` of ``M`` [%].
    floor_percent : float or None
        The noise floor [%] (the data's recorded relative noise and the model's
        coefficients'), None when the data record no noise.
    joint_floor_percent : ndarray, shape (n,), or None
        Each joint's floor over its entries [%], None with ``floor_percent``.
    n_configurations : int
    verdict : Verdict
    measured, predicted : ndarray, shape (N, n (n + 1) / 2 + n)
        The data's rows ``[tril M; g]`` and the model's (figures; not in :meth:`as_dict`).
    """

    relative_error_percent: float
    m_error_percent: float
    g_error_percent: float
    g_rms: NDArray[np.float64]
    m_rms: NDArray[np.float64]
    joint_percent: NDArray[np.float64]
    floor_percent: float | None
    joint_floor_percent: NDArray[np.float64] | None
    n_configurations: int
    verdict: Verdict
    measured: NDArray[np.float64]
    predicted: NDArray[np.float64]

    def as_dict(self) -> dict[str, Any]:
        """JSON values: the errors, the floor, the count and the verdict."""
        v = self.verdict
        return {
            "relative_error_percent": self.relative_error_percent,
            "m_error_percent": self.m_error_percent,
            "g_error_percent": self.g_error_percent,
            "g_rms": [float(x) for x in self.g_rms],
            "m_rms": [float(x) for x in self.m_rms],
            "relative_error_percent_per_joint": [float(x) for x in self.joint_percent],
            "noise_floor_percent": self.floor_percent,
            "joint_floor_percent": None
            if (f := self.joint_floor_percent) is None
            else [float(x) for x in f],
            "n_configurations": self.n_configurations,
            "verdict": {"level": v.level, "label": v.label, "reason": v.reason},
        }


def recorded_noise(metadata: Mapping[str, Any]) -> float | None:
    """The relative noise ``eps`` [1] a static data set records (``relative_noise``, as
    ``dynid acquire-static`` writes it), None when it records none."""
    eps = metadata.get("relative_noise")
    if isinstance(eps, bool) or not isinstance(eps, int | float) or not math.isfinite(eps):
        return None
    return float(eps) if eps >= 0 else None


def _percent(err: NDArray[np.float64], ref: NDArray[np.float64]) -> float:
    den = float(np.sqrt(np.sum(ref**2)))
    return 100.0 * float(np.sqrt(np.sum(err**2))) / den if den > 0 else math.inf


def _joint_rows(n: int) -> list[NDArray[np.intp]]:
    """For each joint ``j``, the rows of ``[tril M; g]`` that hold it: ``M_jk`` for every
    ``k`` (each once, from the lower triangle) and ``g_j``."""
    i, j = np.tril_indices(n)
    where = {(int(a), int(b)): r for r, (a, b) in enumerate(zip(i, j, strict=True))}
    k = i.size
    return [
        np.array([where[max(a, b), min(a, b)] for b in range(n)] + [k + a], dtype=np.intp)
        for a in range(n)
    ]


def static_validation(
    M_hat: NDArray[np.float64],
    g_hat: NDArray[np.float64],
    data: StaticDataset,
    joint_names: Sequence[str] | None = None,
    coefficients: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> StaticValidation:
    """Judge predicted ``M_hat`` (N, n, n) [kg m^2] and ``g_hat`` (N, n) [N m] against
    ``data`` (module docstring). ``coefficients``: the model's base regressor at the
    data's configurations (N, n (n + 1) / 2 + n, r) and its coefficients' covariance
    (r, r), whose error (fitted to noisy data) the floor counts beside the data's noise.

    A joint is judged against its floor only where its error is beyond what the floor
    makes by chance (:func:`_beyond_chance`): a joint's few large entries (the true model
    on 50 configurations: joint 3 at 1.32 x its floor) and a model's coefficients' one
    draw (a model of 300 configurations: joint 7 at 1.25 to 1.33 x on three held-out
    sets) are not effects outside the model.

    Raises
    ------
    ShapeError
        Predictions of another shape than the data's.
    """
    M_hat, g_hat = np.asarray(M_hat, dtype=float), np.asarray(g_hat, dtype=float)
    if M_hat.shape != data.M.shape or g_hat.shape != data.g.shape:
        raise ShapeError(
            f"predictions of shape {M_hat.shape}, {g_hat.shape} for data of "
            f"{data.M.shape}, {data.g.shape}"
        )
    N, n = data.g.shape
    measured, predicted = static_vector(data.M, data.g), static_vector(M_hat, g_hat)
    err, k = predicted - measured, n * (n + 1) // 2
    rows = _joint_rows(n)
    joint = np.array([_percent(err[:, r], measured[:, r]) for r in rows])
    eps = recorded_noise(data.metadata)
    floor, ratios, parts, own = None, None, None, None
    if eps is not None:  # the data's noise known: with the coefficients', the floor
        noise = (eps * measured) ** 2
        coef = np.zeros_like(measured) if coefficients is None else _entry_variance(*coefficients)
        var = noise + coef
        floor = 100.0 * _norm(np.sqrt(var)) / _norm(measured)
        if floor > 0:
            own = np.array(
                [100.0 * _norm(np.sqrt(var[:, r])) / _norm(measured[:, r]) for r in rows]
            )
            beyond = _beyond_chance(err, noise, coefficients, rows)
            ratios = np.where(beyond, joint / own, np.minimum(joint / own, 1.0))
            if coefficients is not None:
                parts = (
                    f", of which the data's recorded noise {100.0 * eps:.3g} % and the "
                    f"model's coefficients' {100.0 * _norm(np.sqrt(coef)) / _norm(measured):.3g} %"
                )
        else:
            floor = None
    pooled = _percent(err, measured)
    verdict = judge_prediction(
        pooled, floor, joint_ratios=ratios, joint_percent=joint, joint_names=joint_names,
        floor_parts=parts, kind="static",
    )  # fmt: skip
    return StaticValidation(
        relative_error_percent=pooled,
        m_error_percent=_percent(err[:, :k], measured[:, :k]),
        g_error_percent=_percent(err[:, k:], measured[:, k:]),
        g_rms=np.sqrt(np.mean(err[:, k:] ** 2, axis=0)),
        m_rms=np.array([np.sqrt(np.mean(err[:, r[:-1]] ** 2)) for r in rows]),
        joint_percent=joint,
        floor_percent=floor,
        joint_floor_percent=own,
        n_configurations=N,
        verdict=verdict,
        measured=measured,
        predicted=predicted,
    )


#: Standard deviations of a joint's squared error above its expectation beyond which the
#: error is not the floor's chance.
CHANCE_SIGMAS = 3.0


def _entry_variance(Y: NDArray[np.float64], C: NDArray[np.float64]) -> NDArray[np.float64]:
    """``y^T C y`` of every entry: (N, rows) from ``Y`` (N, rows, r) and ``C`` (r, r)."""
    return np.maximum(np.einsum("nkr,nkr->nk", Y @ C, Y), 0.0)


def _beyond_chance(
    err: NDArray[np.float64],
    noise: NDArray[np.float64],
    coefficients: tuple[NDArray[np.float64], NDArray[np.float64]] | None,
    rows: Sequence[NDArray[np.intp]],
) -> NDArray[np.bool_]:
    """Per joint, whether its squared error exceeds its expectation by more than
    :data:`CHANCE_SIGMAS` of its standard deviation. The squared error over a joint's
    entries is the data's independent noise (variances ``noise``: mean ``sum v``, variance
    ``2 sum v^2``) plus the coefficients' one error ``delta ~ N(0, C)`` seen through the
    entries' regressor rows ``Y_j`` (``delta^T A delta``, ``A = Y_j^T Y_j``: mean ``tr(C
    A)``, variance ``2 tr((C A)^2)``): a weighted chi-square whose few large weights (a
    joint's largest entries, a model's few coefficients) spread it widely."""
    out = np.zeros(len(rows), dtype=bool)
    for j, r in enumerate(rows):
        v = noise[:, r].ravel()
        mean, spread = float(np.sum(v)), 2.0 * float(np.sum(v**2))
        if coefficients is not None:
            Y, C = coefficients
            Yj = Y[:, r, :].reshape(-1, Y.shape[-1])
            B = C @ (Yj.T @ Yj)
            mean += float(np.trace(B))
            spread += 2.0 * float(np.sum(B * B.T))
        out[j] = float(np.sum(err[:, r] ** 2)) > mean + CHANCE_SIGMAS * math.sqrt(spread)
    return out


def _norm(x: NDArray[np.float64]) -> float:
    return float(np.sqrt(np.sum(x**2)))
