"""Short bursts in a fit's own residual: a contact or a logging fault in one or two recordings.

Of three recordings or more, one holding torques no candidate models (a contact, a burst on
one joint for a fraction of a second) is found by leaving each out in turn
(:mod:`~dynid.identification.selection`); of one or two, that check cannot run. What is
left is the fit's own residual: :func:`own_bursts` computes it for every recording (the
torques as measured less the fitted model's, at the fit's samples), in units of each
joint's own noise (the raw torque noise of each piece, through the low-pass where the
residual is judged on filtered torques), and judges each by the rule of a validation
(:func:`~dynid.identification.error_spans.error_spans`: at most
:data:`~dynid.identification.error_spans.SHORT_SHARE` of its samples holding at least
:data:`~dynid.identification.error_spans.MOST_SHARE` of its squared error above the
noise), no more than :data:`~dynid.identification.outlying_spans.SPANS_SHOWN` spans
standing off (more recur with the motion: friction at each start of a point-to-point
log's moves). A span at a reversal of its joints that stands off by no more than the
model's friction steps there is friction's step, placed differently by the fit and the
model (:func:`~dynid.identification.friction_steps.friction_step`), and left out; a
burst there stands off beyond it.
A clean recording stays near the noise; an effect the model lacks (a
spring, a tilted base) spreads over the motion: neither is judged so. Times [s]
as the logs hold them, torques [N m].
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from ..regressors.terms import ModelTerm
from ..signals import lowpass_noise_gain
from .core import model_columns
from .error_spans import ErrorSpans, error_spans
from .friction_steps import friction_step
from .model import IdentifiedModel, IdentifiedTerm
from .outlying_spans import MIN_SHARE, SPANS_SHOWN, outlying_spans, robust_levels
from .recordings import Recordings

__all__ = ["fit_residuals", "own_bursts"]


#: A recording's times [s] (N,), residual [N m] (N, n), noise [N m] (N, n), joint
#: velocities [rad/s] (N, n) and the model's friction torques [N m] (N, n) at the fit's
#: samples.
_Residual = tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
]


def fit_residuals(
    robot: Robot, model: IdentifiedModel, terms: Sequence[ModelTerm], data: Recordings
) -> list[_Residual] | None:
    """Each recording's sample times [s] (N,), the residual of ``model`` (fitted with
    ``terms`` on ``data``) on its torques as measured [N m] (N, n), each sample's joints'
    noise [N m] (N, n): the raw torque noise of its piece, times the low-pass's noise gain
    where the torques judged are filtered, and the prepared joint velocities [rad/s]
    (N, n). None where a piece's noise is not known or the rows do not match the
    samples."""
    pieces = data.pieces
    if any(p.torque_noise_std is None for p in pieces):
        return None
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    x = np.asarray(fit.beta, dtype=np.float64)
    columns = model_columns(robot, data, drive=model.drive, terms=tuple(terms), base=model.base)
    rows = [blk.y - blk.W @ x for blk in data.measured_blocks(robot, columns)]
    e = np.concatenate(rows) if rows else np.zeros(0)
    n = data.n
    if e.size != sum(p.log.n_samples for p in pieces) * n:
        return None
    out = []
    o = 0
    by_recording: dict[int, list[tuple[NDArray[np.float64], ...]]] = {}
    frictions = [tm for tm in model.appended if tm.friction is not None]
    for p, r in zip(pieces, data.recording, strict=True):
        m = p.log.n_samples
        gain = 1.0 if data.measured else lowpass_noise_gain(p.sample_rate_hz, p.cutoff_hz)
        noise = np.broadcast_to(gain * np.asarray(p.torque_noise_std, dtype=np.float64), (m, n))
        t = np.asarray(p.log.t, dtype=np.float64)
        dq = np.asarray(p.log.dq, dtype=np.float64)
        f = _friction_torques(frictions, p.log.q, dq, p.log.ddq)
        by_recording.setdefault(int(r), []).append(
            (t, e[o : o + m * n].reshape(m, n), noise, dq, f)
        )
        o += m * n
    for k in range(len(data.names)):
        mine = by_recording.get(k, [])
        if not mine:
            out.append((np.zeros(0), *(np.zeros((0, n)),) * 4))
            continue
        out.append(tuple(np.concatenate([part[i] for part in mine]) for i in range(5)))  # type: ignore[arg-type]
    return out


def _friction_torques(
    frictions: Sequence[IdentifiedTerm],
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64] | None,
) -> NDArray[np.float64]:
    """The joint torques [N m] (N, n) of the friction terms ``frictions`` at the joint
    states ``q`` [rad], ``dq`` [rad/s], ``ddq`` [rad/s^2] (N, n) (None: zero; friction does
    not depend on it)."""
    out = np.zeros(np.shape(dq))
    a = np.zeros(out.shape) if ddq is None else ddq
    for tm in frictions:
        out += tm.torques(q, dq, a)
    return out


def own_bursts(
    robot: Robot,
    model: IdentifiedModel,
    terms: Sequence[ModelTerm],
    data: Recordings,
    exact: bool = False,
) -> dict[int, ErrorSpans]:
    """The recordings (indices into ``data.names``) whose residual under ``model`` (its own
    fit, :func:`fit_residuals`) sits in a few short spans
    (:func:`~dynid.identification.error_spans.error_spans` on the residual in units of each
    joint's noise, the spans of friction's step at a reversal of their joints left out:
    :func:`_friction_steps`),
    each with those spans, their peaks [N m] as measured; empty where the noise is not
    known, the logs are ``exact`` to round-off (no noise to judge against) or none is so."""
    found = None if exact else fit_residuals(robot, model, terms, data)
    if found is None:
        return {}
    out = {}
    starts = data.starts
    for k, (t, e, noise, dq, f) in enumerate(found):
        if t.size == 0 or not np.all(noise > 0):
            continue
        z = e / noise
        keep = ~_friction_steps(t, z, dq, f / noise)
        t, z, e = t[keep], z[keep], e[keep]
        if t.size == 0 or _recurring(t, z):
            continue
        t0 = starts[k] if k < len(starts) else None
        spans = error_spans(t, z, np.ones(e.shape[1]), data.names[k], t0)
        if spans is None:
            continue
        peaks = []
        for s in spans.spans:
            inside = (t >= s.t0) & (t <= s.t1)
            peaks.append(replace(s, peak=float(np.abs(e[inside][:, list(s.joints)]).max())))
        out[k] = replace(spans, spans=tuple(peaks))
    return out


def _friction_steps(
    t: NDArray[np.float64],
    z: NDArray[np.float64],
    dq: NDArray[np.float64],
    f: NDArray[np.float64],
) -> NDArray[np.bool_]:
    """The samples (N,) of the spans where the residual ``z`` (N, n) [noise units] at times
    ``t`` [s] stands off (:func:`~.outlying_spans.outlying_spans`) as friction's step at a
    reversal does (:func:`~dynid.identification.friction_steps.friction_step`): each of
    its joints reverses (its velocity ``dq`` (N, n) [rad/s] at zero or changing sign
    within the span and one sample either side) and no more than the model's friction
    ``f`` (N, n) [noise units] steps there. The
    fit on filtered torques and the model's sharp step place that step differently (a
    Panda's 3 N m Coulomb: single samples 27 times the noise); a burst at a reversal stands
    off beyond the step and is not left out."""
    out = np.zeros(t.size, dtype=bool)
    dev, level = robust_levels(z)
    for s in outlying_spans(t, z):
        if friction_step(s, t, dev, level, dq, f):
            out[(t >= s.t0) & (t <= s.t1)] = True
    return out


def _recurring(t: NDArray[np.float64], z: NDArray[np.float64]) -> bool:
    """Whether more than :data:`~dynid.identification.outlying_spans.SPANS_SHOWN` spans of
    the residual ``z`` (N, n) [noise units] at times ``t`` [s] stand off, each holding at
    least :data:`~dynid.identification.outlying_spans.MIN_SHARE` of it: an effect that
    recurs with the motion (friction at every start of a point-to-point log's moves), not
    a burst."""
    big = [s for s in outlying_spans(t, z) if s.share >= MIN_SHARE]
    return len(big) > SPANS_SHOWN
