"""Stribeck friction: Coulomb friction that rises to a static level ``fs`` near rest.

.. math:: \\tau_f(\\dot q) = f_v \\dot q
          + \\big(f_c + (f_s - f_c)\\, e^{-(\\dot q / v_{st})^2}\\big)\\, s(\\dot q) + f_o

with ``s`` the sign outside the standstill band (:func:`~dynid.friction.model.coulomb_sign`);
:func:`stribeck_law` makes the law for another sign
(:mod:`dynid.friction.laws.smooth_stribeck`).
``fv`` [N m s/rad], ``fc``, ``fs`` [N m] ``>= 0`` (``fs`` at most twice the largest
torque of the samples the bump acts at, and ``fc`` where it acts at none), the Stribeck
velocity ``vst`` [rad/s] in ``[1e-3, 10]``, the offset ``fo`` [N m] of either sign.
Given ``vst`` the law is linear in the others; the fit is a variable projection: bounded
linear least squares for each ``vst`` on a logarithmic grid, then a bounded scalar search
of ``ln vst`` between the grid neighbours of the best point (deterministic). MuJoCo holds
``fv`` as ``damping`` and ``fc`` as ``frictionloss``; the peak ``fs - fc`` at low speed and
the offset are dropped.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

import numpy as np
from numpy.typing import NDArray

from ...regressors.friction_columns import standstill_sign, stribeck_decay
from .base import Canonical, FrictionLaw, JointFit, MjcfTerms, bounded_lstsq, canonical_rows

__all__ = ["LAW", "stribeck_law"]

_LOWER = (0.0, 0.0, 0.0, 1e-3, -np.inf)
_UPPER = (np.inf, np.inf, np.inf, 10.0, np.inf)
_LIN = [0, 1, 2, 4]  # the parameters the law is linear in: fv, fc, fs, fo

#: ``sign(dq (..., n), band (n,))``: the law's Coulomb sign.
Sign = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]


def _columns(
    dq: NDArray[np.float64], band: NDArray[np.float64], vst: NDArray[np.float64], sign: Sign
) -> NDArray[np.float64]:
    """The columns (..., n, 4) the law is linear in, ``fv, fc, fs, fo``, at ``vst``."""
    return _at_vst(dq, sign(dq, band), np.ones_like(dq), vst)


def _at_vst(
    dq: NDArray[np.float64],
    s: NDArray[np.float64],
    ones: NDArray[np.float64],
    vst: NDArray[np.float64],
) -> NDArray[np.float64]:
    """:func:`_columns` of the velocities ``dq`` given their Coulomb sign ``s`` and a
    column of ones, both alike ``dq`` (what does not depend on ``vst``: a fit's grid of
    Stribeck velocities computes them once)."""
    # vst = 0 is a joint left unidentified (it never moved; every coefficient 0): the
    # limit of exp(-(dq / vst)^2) as vst -> 0 (stribeck_decay gives 0 there)
    e = stribeck_decay(dq, vst)
    return np.stack([dq, s * (1.0 - e), s * e, ones], axis=-1)


def _torques(
    dq: NDArray[np.float64], P: NDArray[np.float64], band: NDArray[np.float64], sign: Sign
) -> NDArray[np.float64]:
    C = _columns(dq, band, P[:, 3], sign)
    out: NDArray[np.float64] = np.einsum("...jk,jk->...j", C, P[:, _LIN])
    return out


def _fit(dq: NDArray[np.float64], r: NDArray[np.float64], band: float, sign: Sign) -> JointFit:
    lo = np.asarray(_LOWER)[_LIN]
    hi = np.asarray(_UPPER)[_LIN]
    step = max(1, dq.size // 5_000)  # the search on a subsample, the final solve on all
    dqs, rs = dq[::step], r[::step]
    # what the columns hold whatever vst (the sign, the ones), computed once per data set
    sub = (dqs, sign(dqs, np.asarray(band)), np.ones_like(dqs), rs)
    full = (dq, sign(dq, np.asarray(band)), np.ones_like(dq), r)

    def solve(
        ln_vst: float, data: tuple[NDArray[np.float64], ...]
    ) -> tuple[NDArray[np.float64], float]:
        """The linear coefficients at ``vst = exp(ln_vst)`` on ``data`` (velocities, their
        sign, ones, residual) and their squared error."""
        v, s, ones, rr = data
        A = _at_vst(v, s, ones, np.asarray(np.exp(ln_vst)))
        x = _bounded_bump(A, rr, lo, hi)
        return x, float(np.sum((A @ x - rr) ** 2))

    top = min(_UPPER[3], max(float(np.max(np.abs(dq))), 2 * _LOWER[3]))
    # a band wider than the largest vst (a motor behind a gear of 345, its velocities
    # derived from 30 Hz positions: 12.7 rad/s) leaves the one vst at the top
    grid = np.linspace(np.log(min(max(_LOWER[3], band), top)), np.log(top), 24)
    costs = [solve(g, sub)[1] for g in grid]
    k = int(np.argmin(costs))
    a, b = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    if not b > a:
        x, _ = solve(float(grid[k]), full)
        return JointFit(np.array([x[0], x[1], x[2], np.exp(grid[k]), x[3]]), True, grid.size)
    import scipy.optimize  # here: a robot holding the law loads no solver

    res = scipy.optimize.minimize_scalar(
        lambda g: solve(g, sub)[1], bounds=(a, b), method="bounded", options={"xatol": 1e-4}
    )
    g = float(res.x) if res.fun <= costs[k] else float(grid[k])
    x, _ = solve(g, full)
    p = np.array([x[0], x[1], x[2], np.exp(g), x[3]])
    return JointFit(p, bool(res.success), int(res.nfev) + grid.size)


#: A sample holds the Stribeck bump where its column ``s(dq) exp(-(dq/vst)^2)`` is at least
#: this (the bump at 1 % of its height).
BUMP_ACTS = 0.01


def _bounded_bump(
    A: NDArray[np.float64], r: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The bounded least squares of ``fv, fc, fs, fo`` on the columns ``A`` (N, 4) at one
    ``vst``, with the static level ``fs`` at most twice the largest torque ``r`` of the
    samples where the bump acts (:data:`BUMP_ACTS`) and ``fs = fc`` (no bump) where none
    does: data without slow motion outside the standstill band leave the bump's column
    near zero and ``fs`` free (one recording of a geared arm's shoulder: fs 1.2e7 N m, the
    other predicted at 7e7 %)."""
    acts = np.abs(A[:, 2]) >= BUMP_ACTS
    if not acts.any():
        merged = np.column_stack([A[:, 0], A[:, 1] + A[:, 2], A[:, 3]])
        fv, fc, fo = bounded_lstsq(merged, r, lo[[0, 1, 3]], hi[[0, 1, 3]])
        return np.array([fv, fc, fc, fo])
    top = hi.copy()
    top[2] = min(top[2], 2.0 * float(np.max(np.abs(r[acts]))))
    return bounded_lstsq(A, r, lo, top)


def _mjcf(P: NDArray[np.float64], dq_max: NDArray[np.float64]) -> MjcfTerms:
    peak = np.any(P[:, 2] != P[:, 1])
    dropped = "the Stribeck peak fs - fc at low speed" if peak else ""
    return MjcfTerms(P[:, 0].copy(), P[:, 1].copy(), P[:, 4].copy(), dropped)


def _canonical(P: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    fv, fc, fs, vst, fo = P.T
    return canonical_rows(
        band, fv_pos=fv, fv_neg=fv, fc_pos=fc, fc_neg=fc, fo=fo, fs_minus_fc=fs - fc, vst=vst
    )


def stribeck_law(
    name: str, sign: Sign, formula: str, canonical: Canonical, compared: bool = True
) -> FrictionLaw:
    """A Stribeck law whose Coulomb term and bump take ``sign(dq, band)``, its ``formula``
    of ``s(dq)`` and its observer form ``canonical``."""
    return FrictionLaw(
        name,
        ("fv", "fc", "fs", "vst", "fo"),
        ("N m s/rad", "N m", "N m", "rad/s", "N m"),
        "tau_f = fv dq + (fc + (fs - fc) exp(-(dq / vst)^2)) s(dq) + fo, " + formula,
        partial(_torques, sign=sign),
        partial(_fit, sign=sign),
        _LOWER,
        _UPPER,
        _mjcf,
        canonical,
        compared=compared,
    )


LAW = stribeck_law(
    "stribeck",
    standstill_sign,
    "s(dq) = sign(dq) where |dq| > standstill_band, else 0",
    _canonical,
)
