"""Validations of several pieces of data pooled into one: the errors over every sample
of every piece, ``RMS_j = sqrt(sum_pieces sum_k e_kj^2 / N)`` and the relative error
``100 ||E||_F / ||tau||_F`` over all of them; the pieces' samples one after another."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..identification.log import TorqueLog
from ..identification.metrics import TorqueErrors
from .validation import Validation, errors_from_sums

__all__ = ["joined_validation", "pooled_errors"]


def pooled_errors(
    parts: Sequence[Validation], with_friction: bool, n: int | None = None
) -> TorqueErrors:
    """The errors of ``parts`` (without or with their friction) over every prepared
    sample of all of them (a part that keeps every k-th sample counts all its samples);
    ``n`` joints (default: the first part's)."""
    n = parts[0].log.n if n is None else n
    se2, sa2, N = np.zeros(n), np.zeros(n), 0
    for v in parts:
        if v.step > 1:  # every k-th sample kept: the sums over all of them
            assert v.tau_ss is not None
            err = v.with_friction if with_friction else v.without_friction
            assert err is not None
            se2 += np.asarray(err.mse) * err.n_samples
            sa2 += v.tau_ss
            N += err.n_samples
            continue
        hat = v.tau_hat if with_friction else v.tau_model
        e = v.log.tau - hat
        se2 += np.einsum("ij,ij->j", e, e)
        sa2 += np.einsum("ij,ij->j", v.log.tau, v.log.tau)
        N += v.log.n_samples
    return errors_from_sums(se2, sa2, N)


def joined_validation(parts: Sequence[Validation]) -> Validation:
    """One :class:`~dynid.friction.validation.Validation` of the pieces ``parts`` (each
    prepared on its own, of one model and friction): their samples one after another
    (time keeps its gaps; a part that starts no later than the one before ends, another
    recording with its own clock, is moved to begin one of its sample steps after it),
    the errors pooled (:func:`pooled_errors`)."""
    if len(parts) == 1:
        return parts[0]
    logs = [v.log for v in parts]

    def cat(get: object) -> NDArray[np.float64]:
        return np.concatenate([getattr(x, str(get)) for x in logs])

    ddq = None if any(x.ddq is None for x in logs) else cat("ddq")
    log = TorqueLog(_times(logs), cat("q"), cat("dq"), cat("tau"), ddq, logs[0].cleaning)
    fr = parts[0].friction
    tf = None if fr is None else np.concatenate([np.asarray(v.tau_friction) for v in parts])
    sums = [v.tau_ss if v.tau_ss is not None else np.sum(v.log.tau**2, axis=0) for v in parts]
    return Validation(
        log=log,
        tau_model=np.concatenate([v.tau_model for v in parts]),
        tau_friction=tf,
        without_friction=pooled_errors(parts, False),
        with_friction=None if fr is None else pooled_errors(parts, True),
        friction=fr,
        step=max(v.step for v in parts),
        tau_ss=np.sum(sums, axis=0),
    )


def _times(logs: Sequence[TorqueLog]) -> NDArray[np.float64]:
    """The logs' times one after another, a log that starts no later than the one before
    ends moved to begin one of its median steps after it."""
    out = [logs[0].t]
    for g in logs[1:]:
        end = float(out[-1][-1])
        if g.t[0] > end:
            out.append(g.t)
            continue
        step = float(np.median(np.diff(g.t))) if g.t.size > 1 else 1.0
        out.append(g.t - g.t[0] + end + step)
    return np.concatenate(out)
