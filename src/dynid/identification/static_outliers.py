"""Configurations of static data that stand off the others: a wrong ``q`` among a
controller's ``M(q)`` and ``g(q)``.

A controller's ``M`` and ``g`` are its model's output, exact up to its rounding, so every
configuration's residual is of the rounding's size. One whose ``q`` is wrong (a row out of
step with its ``M`` and ``g``, a position logged before the arm settled) cannot be fitted
and spoils every coefficient: one such row of 100 took an FR3's held-out error from
0.0003 % to 1.5 %. Its residual in a fit that holds it spreads over every configuration,
so each is judged *left out*: the residual of configuration ``s`` predicted by the fit of
the others,

.. math:: e_{(s)} = y_s - W_s \\hat\\beta_{(s)}, \\quad
          \\hat\\beta_{(s)} = (W^T W - W_s^T W_s)^{-1} (W^T y - W_s^T y_s),

each row of ``[tril M; g]`` in units of its RMS over the configurations (``M`` in kg m^2
and ``g`` in N m weigh alike). A configuration whose ``||e_(s)||`` stands more than
:data:`MAD_FACTOR` robust standard deviations (1.4826 times the median absolute deviation)
above the median, more than :data:`MEDIAN_FACTOR` times the median and above
:data:`MIN_RESIDUAL` (data exact to round-off have nothing to stand off) is outlying; the
search runs again without those found (one may hide another) at most
:data:`MAX_PASSES` times. A configuration whose leaving out loses rank is not judged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..model.drive import Drive
from ..model.robot import Robot
from ..signals import MAD_TO_STD
from .core import model_columns
from .data import StaticDataset

__all__ = [
    "MAD_FACTOR",
    "MEDIAN_FACTOR",
    "MAX_PASSES",
    "MIN_CONFIGURATIONS",
    "MIN_RESIDUAL",
    "OutlyingConfigurations",
    "left_out_residuals",
    "outlying_configurations",
]

#: Robust standard deviations above the median of the left-out residuals.
MAD_FACTOR = 10.0
#: Times the median of the left-out residuals ("many times the others'").
MEDIAN_FACTOR = 5.0
#: Smallest left-out residual judged (each row in units of its RMS): a wrong ``q`` leaves
#: 1 or more, a controller's rounding (M to 1e-4 kg m^2, g to 1e-3 N m) about 0.05,
#: data exact to round-off 1e-13.
MIN_RESIDUAL = 1e-3
#: A row of ``[tril M; g]`` whose RMS is below this share of the largest row's holds
#: nothing but round-off (``g1`` about a vertical axis): not judged.
_ZERO_ROW = 1e-9
#: The smallest RMS a row is put in units of, as a share of the largest row's.
_SMALL_ROW = 1e-6
#: Searches, each without the configurations found before.
MAX_PASSES = 3
#: Fewer configurations are not judged (no median to stand off).
MIN_CONFIGURATIONS = 10


@dataclass(frozen=True, slots=True)
class OutlyingConfigurations:
    """The configurations found outlying.

    Attributes
    ----------
    rows : tuple of int
        Their rows of the data set (from 0), in order.
    ratios : tuple of float
        Each one's left-out residual over the median of the others' (1).
    """

    rows: tuple[int, ...]
    ratios: tuple[float, ...]


def left_out_residuals(
    robot: Robot, data: StaticDataset, *, drive: Drive | None = None
) -> NDArray[np.float64] | None:
    """Each configuration's residual predicted by the fit of the others (module docstring).

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity the data were recorded with.
    data : StaticDataset
        ``N`` configurations.
    drive : Drive, optional
        The drive whose rotor inertias the controller's ``M`` holds (as identified).

    Returns
    -------
    ndarray, shape (N,), or None
        ``||e_(s)||`` with each row of ``[tril M; g]`` in units of its RMS (1); NaN for a
        configuration whose leaving out loses rank; None for data too large to stack.
    """
    cols = model_columns(robot, data, drive=drive)
    blocks = list(data.blocks(robot, cols))
    if any(b.group_labels for b in blocks):
        return None
    W = np.stack([b.W for b in blocks], axis=1)  # (N, s, c)
    y = np.stack([b.y for b in blocks], axis=1)  # (N, s)
    big = np.max(np.abs(y), initial=0.0)
    if not np.isfinite(big) or big > 1e150:  # values the fit itself refuses
        return None
    scale = np.sqrt(np.mean(y**2, axis=0))
    top = float(np.max(scale))
    keep = (scale > _ZERO_ROW * top) & np.any(W != 0, axis=(0, 2))  # g1 of a vertical axis
    scale = np.maximum(scale, _SMALL_ROW * top)  # a row near zero: its round-off not magnified
    W = W[:, keep] / scale[keep][None, :, None]
    y = y[:, keep] / scale[keep]
    norm = np.sqrt(np.einsum("nsc,nsc->c", W, W))
    W = W / np.where(norm > 0, norm, 1.0)
    G = np.einsum("nsc,nsd->cd", W, W)
    b = np.einsum("nsc,ns->c", W, y)
    rank = np.linalg.matrix_rank(G)
    out = np.full(len(y), np.nan)
    for s in range(len(y)):
        Gs = G - W[s].T @ W[s]
        beta, _, r, _ = np.linalg.lstsq(Gs, b - W[s].T @ y[s], rcond=None)
        if r == rank:
            out[s] = float(np.linalg.norm(y[s] - W[s] @ beta))
    return out


def outlying_configurations(
    robot: Robot, data: StaticDataset, *, drive: Drive | None = None
) -> OutlyingConfigurations | None:
    """The configurations whose left-out residual stands off the others' (module
    docstring), or None when none does (or fewer than :data:`MIN_CONFIGURATIONS`).

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity the data were recorded with.
    data : StaticDataset
    drive : Drive, optional
        The drive whose rotor inertias the controller's ``M`` holds.

    Returns
    -------
    OutlyingConfigurations or None
    """
    rows = np.arange(data.n_configurations)
    found: dict[int, float] = {}
    for _ in range(MAX_PASSES):
        kept = rows[~np.isin(rows, list(found))]
        if kept.size < MIN_CONFIGURATIONS:
            break
        z = left_out_residuals(robot, data.select(kept), drive=drive)
        if z is None or not np.isfinite(z).any():
            break
        med = float(np.nanmedian(z))
        mad = MAD_TO_STD * float(np.nanmedian(np.abs(z - med)))
        bad = np.isfinite(z) & (z > med + MAD_FACTOR * mad) & (z > MEDIAN_FACTOR * med)
        bad &= z > MIN_RESIDUAL
        if not bad.any():
            break
        found.update({int(kept[k]): float(z[k] / med) for k in np.flatnonzero(bad)})
    if not found:
        return None
    order = sorted(found)
    return OutlyingConfigurations(tuple(order), tuple(found[k] for k in order))
