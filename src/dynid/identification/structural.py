"""The structural rank of a model's columns: what no data can identify.

The base parameters are the link parameters' combinations the kinematics identify
(:func:`~dynid.regressors.base.base_parameters`, from the regressor at random states). The
appended terms (friction at the motors and at the joints of a coupled drive) can be
dependent in the same way: viscous friction at both motors of a differential wrist and at
both of its joints is four coefficients of the three entries of the damping matrix
``K^T diag(f_v) K + diag(f_vj)``. :func:`structural_rank` finds such combinations from the
model's columns at random states, so that a rank error tells a model that no trajectory
identifies from a trajectory that does not excite it.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from ..regressors.torque import torque_regressor_prepared
from .dataset import ModelColumns
from .solvers import column_scale, unexcited_columns, unexcited_combinations

__all__ = [
    "STRUCTURAL_RTOL",
    "StructuralRank",
    "absorbed_by",
    "combined_notes",
    "held_by",
    "mixed_sign",
    "structural_rank",
]

#: Relative tolerance of the structural rank (singular values of the column-scaled
#: regressor at random states, relative to the largest): exact dependencies fall to
#: rounding (about 1e-15), the nearest distinct columns stay far above.
STRUCTURAL_RTOL = 1e-9


@dataclass(frozen=True, slots=True)
class StructuralRank:
    """The rank of a model's columns at random states.

    Attributes
    ----------
    rank : int
        The structural rank.
    needed : int
        The number of columns.
    combinations : tuple of str
        Every combination of the columns that vanishes at every state (``needed - rank``
        of them, ``"jfv7 - 0.0005556*fv7 - 0.0005556*fv6 + 1*jfv6"``), in the coefficients'
        units.
    redundant : tuple of str
        The label naming each combination: without these the others have full rank.
    rtol : float
        The tolerance used (:data:`STRUCTURAL_RTOL`).
    """

    rank: int
    needed: int
    combinations: tuple[str, ...]
    redundant: tuple[str, ...]
    rtol: float


def structural_rank(
    robot: Robot,
    columns: ModelColumns,
    used: NDArray[np.bool_] | None = None,
    *,
    n_samples: int = 128,
    rng: np.random.Generator | None = None,
) -> StructuralRank:
    """The rank of the torque regressor over ``columns`` (those ``used``) at random states.

    Positions uniform within the limits (``[-pi, pi]`` where unlimited), speeds
    log-uniform from 0.002 to 2 rad/s of either sign (every friction law's shape, a
    Stribeck bump's too) and accelerations in ``[-5, 5]`` rad/s^2; the columns scaled to
    unit norm, the rank from the singular values at :data:`STRUCTURAL_RTOL`.

    Parameters
    ----------
    robot : Robot
    columns : ModelColumns
        The base parameters and the terms (:func:`~dynid.identification.core.model_columns`).
    used : ndarray of bool, shape (c,), optional
        The columns fitted (default all; those a data set freezes left out).
    n_samples : int
        Random states.
    rng : numpy.random.Generator, optional
        Default seeded 0 (reproducible).

    Returns
    -------
    StructuralRank
    """
    import scipy.linalg  # scipy on first use (start-up time)

    W = _random_columns(robot, columns, n_samples, rng)
    labels = columns.labels
    if used is not None:
        W = W[:, used]
        labels = tuple(lab for lab, u in zip(labels, used, strict=True) if u)
    scale = column_scale(W)
    R = scipy.linalg.qr(W / scale, mode="r")[0][: W.shape[1]]
    sv = np.linalg.svd(R, compute_uv=False)
    rank = int(np.sum(sv > STRUCTURAL_RTOL * sv[0])) if sv.size else 0
    combos = unexcited_combinations(R, scale, rank, labels)
    named = tuple(labels[k] for k in unexcited_columns(R, scale, rank))
    return StructuralRank(rank, W.shape[1], combos, named, STRUCTURAL_RTOL)


def _random_columns(
    robot: Robot, columns: ModelColumns, n_samples: int, rng: np.random.Generator | None
) -> NDArray[np.float64]:
    """The torque regressor over ``columns`` (stacked rows, c) at random states:
    positions within the limits (``[-pi, pi]`` where unlimited), speeds from 0.002 to 2
    rad/s (log-uniform, either sign), accelerations in ``[-5, 5]`` rad/s^2."""
    rng = np.random.default_rng(0) if rng is None else rng
    lo = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    hi = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    q = rng.uniform(lo, hi, (n_samples, robot.n))
    # speeds log-uniform over three decades: a Stribeck bump of 0.002 rad/s is 0 at most
    # speeds of a uniform draw in [-2, 2], which would call its column structurally zero
    dq = rng.choice([-2.0, 2.0], q.shape) * 10.0 ** rng.uniform(-3, 0, q.shape)
    ddq = rng.uniform(-5, 5, q.shape)
    full = [torque_regressor_prepared(robot, q, dq, ddq, robot.gravity)]
    full += [t.torque_columns(q, dq, ddq) for t in columns.terms if t.in_base]
    blocks = [columns.base.reduce(np.concatenate(full, axis=-1))]
    blocks += [t.torque_columns(q, dq, ddq) for t in columns.appended]
    return np.concatenate(blocks, axis=-1).reshape(-1, len(columns.labels))


def absorbed_by(
    robot: Robot,
    columns: ModelColumns,
    label: str,
    *,
    n_samples: int = 128,
    rng: np.random.Generator | None = None,
) -> dict[str, str]:
    """What the other coefficients hold when ``label`` is left out of ``columns`` (which
    hold it) because it is structurally combined with them.

    With ``label`` in the model, a combination ``c_label + sum_j v_j c_j = 0`` of the
    columns at every state (:func:`structural_rank`) makes its torque ``theta_label
    c_label`` that of ``-v_j theta_label`` on every ``j``: left out, each such coefficient
    is fitted as ``theta_j - v_j theta_label``.

    Returns
    -------
    dict of str to str
        Each coefficient of the combination (its label) to what it holds
        (``"fv6 + 0.0005556*jfv7"``); empty when ``label`` is in no combination (it was
        left out for another reason).
    """
    labels = columns.labels
    if label not in labels:
        return {}
    W = _random_columns(robot, columns, n_samples, rng)
    scale = column_scale(W)
    sv, Vt = np.linalg.svd(W / scale, full_matrices=False)[1:]
    null = Vt[sv <= STRUCTURAL_RTOL * sv[0]] / scale  # (d, c), coefficients' units
    k = labels.index(label)
    mine = [v for v in null if abs(v[k] * scale[k]) > 1e-6]
    if len(mine) != 1:  # in none, or in several (not one expression each)
        return {}
    v = mine[0] / mine[0][k]
    w = np.abs(v * scale)
    out = {}
    for j in np.flatnonzero(w >= 1e-3 * w.max()):
        if j != k:
            c = -float(v[j])
            times = "" if f"{abs(c):.4g}" == "1" else f"{abs(c):.4g}*"
            out[labels[j]] = f"{labels[j]} {'-' if c < 0 else '+'} {times}{label}"
    return out


def combined_notes(combined: Mapping[str, str]) -> tuple[str, ...]:
    """One line for a model whose coefficients hold structurally combined ones left out
    (:attr:`~dynid.identification.info.IdentificationInfo.combined`), none without."""
    if not combined:
        return ()
    held = "; ".join(f"{lab} holds {expr}" for lab, expr in combined.items())
    return (
        "friction coefficients that hold one left out as structurally dependent on them (no "
        f"data tell them apart), not their own values alone: {held}",
    )


def mixed_sign(combined: Mapping[str, str]) -> frozenset[str]:
    """The coefficients of ``combined`` (label to what it holds,
    :func:`absorbed_by`) whose combination is a difference (``"fv6 - fv5"``, with
    viscous friction at both motors of a differential wrist and at its joints, fv5 left
    out): its sign says nothing of the friction's, which a sign check or a bound at zero
    would misread. A sum of friction coefficients (``"jfv5 + 1.445e+04*fv5"``) is below
    zero only when one of them is, and is not among them."""
    return frozenset(lab for lab, expr in combined.items() if " - " in expr)


def held_by(combinations: Sequence[str], left_out: Collection[str]) -> dict[str, str]:
    """What the coefficients hold when the first label of each of ``combinations`` (the
    model's columns dependent at every motion, as
    :attr:`~dynid.exceptions.RankDeficientError.structural` names them:
    ``"fv5 - 1.445e+04*jfv6 - 1.445e+04*jfv5 + 1*fv6"``, the direction ``v`` with
    ``v_fv5 = 1`` that changes no torque) is among ``left_out``: each other coefficient
    ``j`` of it holds ``theta_j - v_j theta_first`` (``{"fv6": "fv6 - fv5", "jfv5": "jfv5 +
    1.445e+04*fv5", ...}``, as :func:`absorbed_by` says it from the columns)."""
    out: dict[str, str] = {}
    for combination in combinations:
        first, *rest = combination.split(" ")
        if first not in left_out:
            continue
        for sign, term in zip(rest[::2], rest[1::2], strict=True):
            c, _, lab = term.rpartition("*")
            times = "" if c in ("", "1") else f"{c}*"
            expr = f"{lab} {'-' if sign == '+' else '+'} {times}{first}"
            out[lab] = expr if lab not in out else f"{out[lab]}{expr[len(lab) :]}"
    return out
