"""Static configurations chosen from a larger random pool to condition the static regressor.

The pool holds ``pool_factor * n`` configurations drawn uniformly within the joint limits
(away from them by ``margin``) and free of self-collision and of collision with the
obstacles (:mod:`dynid.simulation.collision`). Each configuration contributes a block
``B_c = Y_b(q_c)`` (the static base regressor ``[tril M; g]``; with ``scaled=True`` its
columns divided by their norms over the pool) to the stacked regressor ``W``, whose Gram
matrix is ``G = sum_c B_c^T B_c``. The condition number ``sqrt(lambda_max / lambda_min)``
of ``W`` is minimised through the smooth surrogate

.. math:: J(G) = \\frac{1}{p} \\log \\operatorname{tr} G^{-p}
          + \\frac{1}{p} \\log \\operatorname{tr} G^{p}
          \\;\\to\\; \\log \\frac{\\lambda_{max}}{\\lambda_{min}} \\quad (p \\to \\infty)

(``p = 8``), whose derivative for adding configuration ``c`` is
``sum_i ||B_c v_i||^2 (lambda_i^{p-1} / tr G^p - lambda_i^{-p-1} / tr G^{-p})`` with
``G = V diag(lambda) V^T``: configurations that excite the weak directions and not the
strong ones lower it. Greedy construction in ``batches`` steps from a seed of the first
pool configurations, then ``exchange`` passes that swap the ``n / 50`` chosen
configurations of least use for the best unused ones (a Fedorov-type exchange; Atkinson
and Donev, "Optimum Experimental Designs", 1992). The choice is deterministic given the
pool. On the Panda (1010 of 5050) the unscaled condition number drops from about 48 for
random configurations to about 36.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import LimitError, OptionError
from ..model.robot import Robot, checked_robot
from ..regressors.base import BaseParameters, base_parameters
from ..regressors.static import static_regressor
from .collision import Obstacles, capsule_model, obstacle_distances, self_distances
from .controller import DEFAULT_MARGIN, sample_configurations

__all__ = ["StaticSelection", "select_static_configurations", "stacked_condition_numbers"]


@dataclass(frozen=True, slots=True, eq=False)
class StaticSelection:
    """Chosen configurations and the conditioning they give.

    Attributes
    ----------
    q : ndarray, shape (n, dof)
        The configurations [rad], in the order chosen.
    condition_number : float
        Of the stacked static base regressor ``[tril M; g]`` of ``q``, unscaled.
    scaled_condition_number : float
        Of the same with unit column norms.
    pool_size : int
        Collision-free configurations the choice was made from.
    pool_condition_number : float
        Unscaled condition number of ``n`` configurations of the pool taken at random
        (the same number, for comparison).
    """

    q: NDArray[np.float64]
    condition_number: float
    scaled_condition_number: float
    pool_size: int
    pool_condition_number: float


#: Bytes of static regressor built at a time by :func:`stacked_condition_numbers` (a long
#: chain's is large: 5.3 MB per configuration of a 50-joint arm).
_BLOCK_BYTES = 64 << 20


def stacked_condition_numbers(
    robot: Robot, q: NDArray[np.float64], base: BaseParameters | None = None
) -> tuple[float, float]:
    """Unscaled and scaled condition numbers of the stacked ``[tril M; g]`` base regressor.

    Built a block of configurations at a time: the singular values of the stack ``W`` are
    those of its triangular factor ``R`` (``W = Q R``), updated block by block, and the
    column-scaled ones those of ``R D^-1`` (``D``: the column norms, summed by block).
    """
    import scipy.linalg  # scipy on first use (start-up time)

    base = base_parameters(robot) if base is None else base
    n, r = robot.n, base.rank
    per = (n * (n + 1) // 2 + n) * 10 * n * 8  # bytes of one configuration's regressor
    k = max(1, _BLOCK_BYTES // per)
    R = np.zeros((0, r))
    sq = np.zeros(r)
    for a in range(0, q.shape[0], k):
        W = static_regressor(robot, q[a : a + k])[..., base.independent].reshape(-1, r)
        sq += np.einsum("ij,ij->j", W, W)
        R = scipy.linalg.qr(np.concatenate([R, W]), mode="r", check_finite=False)[0][:r]
    nrm = np.sqrt(sq)
    s = np.linalg.svd(R, compute_uv=False)
    ss = np.linalg.svd(R / np.where(nrm > 0, nrm, 1.0), compute_uv=False)
    return float(s[0] / s[-1]), float(ss[0] / ss[-1])


def _collision_free_pool(
    robot: Robot,
    size: int,
    rng: np.random.Generator,
    margin: float,
    obstacles: Obstacles | None,
    radii: float | ArrayLike | None,
    clearance: float,
) -> NDArray[np.float64]:
    caps = capsule_model(robot, radii, clearance=clearance)
    kept: list[NDArray[np.float64]] = []
    total = 0
    for _ in range(50):
        q = sample_configurations(robot, max(size, 64), rng, margin=margin)
        ok = np.all(self_distances(robot, q, caps) >= clearance, axis=-1)
        if obstacles is not None and len(obstacles):
            ok &= np.all(obstacle_distances(robot, q, obstacles, caps) >= clearance, axis=-1)
        kept.append(q[ok])
        total += int(ok.sum())
        if total >= size:
            break
    pool = np.concatenate(kept)[:size]
    if pool.shape[0] < size:
        raise LimitError(
            f"only {pool.shape[0]} of {size} pool configurations are collision-free; hint: "
            "check the obstacles and the capsule radii"
        )
    return pool


def _greedy_design(
    B: NDArray[np.float64],
    n: int,
    batches: int,
    exchange: int,
    p: float,
    progress: Callable[[int, int], None] | None,
) -> NDArray[np.bool_]:
    """Which of the pool's regressor blocks ``B`` (P, s, r) to choose, ``n`` of them.

    Greedy construction in ``batches`` steps on the first-order gains of the surrogate
    ``J(G)`` (see the module docstring), then up to ``exchange`` passes that swap
    ``max(n // 50, 1)`` blocks while a swap improves ``J`` to first order; ``progress`` as
    in :func:`select_static_configurations`. Returns a (P,) bool mask.
    """
    P, s, r = B.shape
    flat = B.reshape(-1, r)

    def block_gram(idx: NDArray[np.intp]) -> NDArray[np.float64]:
        Bi = B[idx].reshape(-1, r)
        return Bi.T @ Bi

    def gains() -> NDArray[np.float64]:
        lam, V = np.linalg.eigh(G)
        lam = np.maximum(lam / lam.max(), 1e-300)
        w = lam ** (p - 1) / np.sum(lam**p) - lam ** (-p - 1) / np.sum(lam**-p)
        E = ((flat @ V) ** 2).reshape(P, s, r).sum(axis=1)  # ||B_c v_i||^2
        return E @ w  # dJ for adding c: negative helps

    chosen = np.zeros(P, bool)
    seed = np.arange(min(n, max(n // batches, -(-2 * r // s))))
    chosen[seed] = True
    G = block_gram(seed)
    sizes = np.diff(np.linspace(seed.size, n, batches + 1).round().astype(int))
    for step, k in enumerate(sizes, start=1):
        if k > 0:
            g = np.where(chosen, np.inf, gains())
            pick = np.argpartition(g, k - 1)[:k]
            chosen[pick] = True
            G = G + block_gram(pick)
        if progress is not None:
            progress(step, batches + exchange)
    m = max(n // 50, 1)
    for step in range(exchange):
        g = gains()
        add = np.argpartition(np.where(chosen, np.inf, g), m - 1)[:m]
        drop = np.argpartition(np.where(chosen, -g, np.inf), m - 1)[:m]
        if np.sum(g[add]) >= np.sum(g[drop]):
            break  # no swap improves the surrogate to first order
        chosen[add], chosen[drop] = True, False
        G = G + block_gram(add) - block_gram(drop)
        if progress is not None:
            progress(batches + step + 1, batches + exchange)
    return chosen


def _check_pool_memory(robot: Robot, size: int) -> None:
    """Refuse a pool whose static regressors (``size`` x (n(n+1)/2 + n) x 10 n floats, held
    twice) need more than the machine's physical memory (unknown: not checked)."""
    try:
        memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):  # pragma: no cover - not POSIX
        return
    n = robot.n
    need = 2 * 8 * size * (n * (n + 1) // 2 + n) * 10 * n
    if need > memory:
        raise OptionError(
            f"a pool of {size:.4g} configurations needs {need / 1e9:.3g} GB for their static "
            f"regressors, more than this machine's {memory / 1e9:.3g} GB; give a smaller "
            "pool_factor (--pool) or n (--n)"
        )


def select_static_configurations(
    robot: Robot,
    n: int,
    rng: np.random.Generator,
    *,
    pool_factor: int = 5,
    margin: float = DEFAULT_MARGIN,
    obstacles: Obstacles | None = None,
    radii: float | ArrayLike | None = None,
    clearance: float = 0.0,
    batches: int = 50,
    exchange: int = 40,
    scaled: bool = False,
    p: float = 8.0,
    base: BaseParameters | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> StaticSelection:
    """Choose ``n`` static configurations from a random pool (greedy D-optimal design).

    Parameters
    ----------
    robot : Robot
    n : int
        Number of configurations to choose.
    rng : numpy.random.Generator
        Source of the pool (the choice itself is deterministic).
    pool_factor : int
        The pool holds ``pool_factor * n`` collision-free configurations (>= 2).
    margin : float
        Distance kept from the joint limits [rad].
    obstacles : Obstacles, optional
        Obstacles the capsules must clear; self-collision is always checked.
    radii : float or array_like, shape (dof + 1,), optional
        Capsule radii [m] (:func:`~dynid.simulation.collision.capsule_model`).
    clearance : float
        Smallest signed distance allowed between capsules and to obstacles [m].
    batches : int
        Greedy steps (more: closer to one-at-a-time greedy, slower).
    exchange : int
        Exchange passes after the greedy construction (0: none).
    scaled : bool
        Minimise the condition number of the column-scaled regressor instead of the
        unscaled one (the one Gaz et al. report).
    p : float
        Exponent of the surrogate (larger: closer to the condition number itself).
    base : BaseParameters, optional
        Default ``base_parameters(robot)``.
    progress : callable, optional
        ``progress(step, batches + exchange)`` after each step.

    Returns
    -------
    StaticSelection

    Raises
    ------
    OptionError
        ``n < 1``, ``pool_factor < 2``, ``batches < 1`` or ``exchange < 0``; a pool whose
        static regressors need more than the machine's memory.
    LimitError
        Too few collision-free configurations, or limits narrower than the margin.
    """
    _checks.checked_rng(rng)
    checked_robot(robot)
    if n < 1 or pool_factor < 2 or batches < 1 or exchange < 0:
        raise OptionError(
            f"need n >= 1, pool_factor >= 2, batches >= 1 and exchange >= 0; got {n}, "
            f"{pool_factor}, {batches}, {exchange}"
        )
    _check_pool_memory(robot, pool_factor * n)
    base = base_parameters(robot) if base is None else base
    pool = _collision_free_pool(robot, pool_factor * n, rng, margin, obstacles, radii, clearance)
    B = static_regressor(robot, pool)[..., base.independent]  # (P, s, r)
    if scaled:
        scale = np.sqrt(np.einsum("psr,psr->r", B, B))
        B /= np.where(scale > 0, scale, 1.0)
    chosen = _greedy_design(B, n, batches, exchange, p, progress)
    order = np.flatnonzero(chosen)
    q = pool[order]
    cond, scond = stacked_condition_numbers(robot, q, base)
    P = B.shape[0]
    ref = pool[rng.permutation(P)[:n]]
    return StaticSelection(
        q=_checks.frozen(q),
        condition_number=cond,
        scaled_condition_number=scond,
        pool_size=int(P),
        pool_condition_number=stacked_condition_numbers(robot, ref, base)[0],
    )
