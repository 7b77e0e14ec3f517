"""The velocity functions friction is linear in, once its shape is fixed: one definition each.

Friction laws (:mod:`dynid.friction.laws`) and the friction columns identified with the
links (:class:`~dynid.regressors.terms.LinearFriction`) are built from these, so that a
law fitted on a residual and the same law identified with the links are the same function.
Velocities ``v`` [rad/s] of shape (..., n); per-joint shapes of shape (n,) or scalars.

* :func:`standstill_sign`: ``sign(v)`` outside the standstill band ``b``, 0 inside (at
  rest the measured velocity is encoder noise, whose sign must not switch Coulomb friction
  on);
* :func:`smooth_sign`: ``tanh(v / w)``, a Coulomb term rounded over the width ``w``
  (the plain ``sign`` where ``w = 0``);
* :func:`stribeck_decay`: ``exp(-(v / v_st)^2)``, the Stribeck bump near rest (0 where
  ``v_st = 0``, a joint left unidentified).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["distinct_rows", "smooth_sign", "standstill_sign", "stribeck_decay"]


def standstill_sign(v: ArrayLike, band: ArrayLike = 0.0) -> NDArray[np.float64]:
    """``sign(v)`` where ``|v| > band``, else 0: (..., n)."""
    x = np.asarray(v, dtype=np.float64)
    out: NDArray[np.float64] = np.where(
        np.abs(x) > np.asarray(band, dtype=np.float64), np.sign(x), 0.0
    )
    return out


def smooth_sign(v: ArrayLike, width: ArrayLike) -> NDArray[np.float64]:
    """``tanh(v / width)`` (``sign(v)`` where ``width = 0``): (..., n)."""
    x = np.asarray(v, dtype=np.float64)
    w = np.asarray(width, dtype=np.float64)
    ok = w > 0
    out: NDArray[np.float64] = np.where(ok, np.tanh(x / np.where(ok, w, 1.0)), np.sign(x))
    return out


def stribeck_decay(v: ArrayLike, vst: ArrayLike) -> NDArray[np.float64]:
    """``exp(-(v / vst)^2)`` (0 where ``vst = 0``): (..., n)."""
    x = np.asarray(v, dtype=np.float64)
    s = np.asarray(vst, dtype=np.float64)
    ok = s > 0
    out: NDArray[np.float64] = np.where(ok, np.exp(-((x / np.where(ok, s, 1.0)) ** 2)), 0.0)
    return out


def distinct_rows(G: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rows of ``G`` (constraints ``G f >= 0`` on friction coefficients), each scaled to
    a largest entry of 1, without repeats (a joint with Coulomb friction alone gives one
    row, ``fc >= 0``, not one per velocity)."""
    if not G.shape[0]:
        return G
    G = G / np.max(np.abs(G), axis=1, keepdims=True)
    _, first = np.unique(np.round(G, 12), axis=0, return_index=True)
    return G[np.sort(first)]
