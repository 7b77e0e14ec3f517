"""Friction's step at a velocity reversal: a span of residual that is not a contact.

Coulomb friction steps by twice its height where a joint's velocity changes sign. A model
places that step where its own (filtered, derived) velocity leaves its standstill band, or
smooths it, while the torques step at the true reversal: the residual stands off there
for a sample or a few by up to the step's height, on that joint alone (a Panda's 3 N m
Coulomb: single samples 27 times the noise; a noise-free log, far more). A span of a
residual where it stands off (:func:`~dynid.identification.outlying_spans.outlying_spans`)
is friction's step (:func:`friction_step`) when each of its joints reverses there (its
velocity changes sign, or lies inside its standstill band, within the span and one sample
either side: :func:`reverses`) and the residual would not stand off with
:data:`STEP_MARGIN` times the step the model's friction makes across it taken off each of
those joints: a misplaced step misfits by at most its height, while a contact at a
reversal stands off beyond it. Times [s], velocities [rad/s], torques in the residual's
units (N m, or units of each joint's noise).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .outlying_spans import OFF_SIGMAS, Span

__all__ = ["STEP_MARGIN", "friction_step", "reverses"]

#: A span at a reversal is friction's step, placed differently by the torques and the
#: model, when its residual would not stand off with this many times the step the model's
#: friction makes across it taken off each of its joints [1] (a misplaced step misfits
#: by at most its height; the margin: a fitted step against the truth's, a filter's
#: overshoot). A burst there larger than that is judged as any other span.
STEP_MARGIN = 1.5


def reverses(dq: NDArray[np.float64], band: NDArray[np.float64] | float = 0.0) -> NDArray[np.bool_]:
    """Whether each joint's velocity ``dq`` (K, m) [rad/s] over K consecutive samples
    reverses: changes sign, or lies inside the standstill ``band`` (m,) or scalar [rad/s]
    (0: exactly zero) at some sample. Returns (m,)."""
    sign = np.sign(dq)
    inside = (np.abs(dq) <= np.asarray(band, dtype=np.float64)).any(axis=0)
    changes = (np.diff(sign, axis=0) != 0).any(axis=0)
    return np.asarray(inside | changes | (sign == 0).any(axis=0), dtype=bool)


def friction_step(
    span: Span,
    t: NDArray[np.float64],
    dev: NDArray[np.float64],
    level: NDArray[np.float64],
    dq: NDArray[np.float64],
    f: NDArray[np.float64],
    band: NDArray[np.float64] | float = 0.0,
) -> bool:
    """Whether ``span`` of a residual is friction's step at a reversal (module docstring).

    Parameters
    ----------
    span : Span
        Where the residual stands off (:func:`~.outlying_spans.outlying_spans`).
    t : ndarray, shape (N,)
        Sample times [s], ascending.
    dev, level : ndarray, shapes (N, n) and (n,)
        The residual less each joint's median and each joint's robust level
        (:func:`~.outlying_spans.robust_levels`), in the residual's units.
    dq : ndarray, shape (N, n)
        The joint velocities the model was evaluated at [rad/s].
    f : ndarray, shape (N, n)
        The model's friction torques, in the residual's units.
    band : ndarray, shape (n,), or float
        The velocities' standstill band [rad/s] (0: a reversal only where the sign changes
        or the velocity is exactly zero).

    Returns
    -------
    bool
        Each of the span's joints reverses within it and one sample either side
        (:func:`reverses`), and its residual there stands off by no more than
        :data:`~.outlying_spans.OFF_SIGMAS` levels plus :data:`STEP_MARGIN` times the
        range of ``f`` over those samples.
    """
    i0 = int(np.searchsorted(t, span.t0))
    i1 = int(np.searchsorted(t, span.t1, side="right"))
    near = slice(max(i0 - 1, 0), min(i1 + 1, t.size))
    joints = list(span.joints)
    if i1 <= i0 or not joints:
        return False
    bands = np.broadcast_to(np.asarray(band, dtype=np.float64), (dq.shape[1],))[joints]
    if not np.all(reverses(dq[near][:, joints], bands)):
        return False
    step = np.ptp(f[near][:, joints], axis=0)
    peak = np.abs(dev[i0:i1][:, joints]).max(axis=0)
    return bool(np.all(peak <= OFF_SIGMAS * level[joints] + STEP_MARGIN * step))
