"""Smooth Coulomb: viscous, a Coulomb term rounded at rest by ``tanh``, and an offset.

.. math:: \\tau_f(\\dot q) = f_v \\dot q + f_c \\tanh(\\dot q / v_s) + f_o

``v_s`` [rad/s] is not fitted: it is the law's band (:mod:`dynid.friction.laws.base`),
the Coulomb torque reaching 76 % of ``fc`` at ``dq = v_s`` (without a band, ``v_s = 0``:
the plain sign). ``dynid friction`` and ``identify`` both choose it on held-out data
among the same multiples of the joint's standstill band
(:func:`~dynid.identification.structure.smooth_width_grid`), the narrowest (0.3 bands,
about the noise's standard deviation) the expected sign of a sharp Coulomb law given
the noise. Linear in ``fv`` [N m s/rad] ``>= 0``,
``fc`` [N m] ``>= 0`` and ``fo`` [N m]. MuJoCo holds ``fv`` as ``damping`` and ``fc`` as
``frictionloss`` (its dry friction is itself a smoothed constraint); the offset is dropped.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ...regressors.friction_columns import smooth_sign
from .base import MjcfTerms, canonical_rows, linear_law

__all__ = ["LAW", "columns"]


def columns(dq: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    """Regressor (..., n, 3): ``(dq, tanh(dq / v_s), 1)`` per joint, ``v_s = band``."""
    return np.stack([dq, smooth_sign(dq, band), np.ones_like(dq)], axis=-1)


def _mjcf(P: NDArray[np.float64], dq_max: NDArray[np.float64]) -> MjcfTerms:
    return MjcfTerms(P[:, 0].copy(), P[:, 1].copy(), P[:, 2].copy())


def _canonical(P: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    # fc tanh(dq / band), the plain sign where band = 0
    fv, fc, fo = P.T
    tanh = band > 0
    sign = np.where(tanh, 0.0, fc)
    return canonical_rows(
        np.zeros_like(band), fv_pos=fv, fv_neg=fv, fc_pos=sign, fc_neg=sign, fo=fo,
        ft=np.where(tanh, fc, 0.0), vs=band,
    )  # fmt: skip


LAW = replace(
    linear_law(
        "smooth",
        ("fv", "fc", "fo"),
        ("N m s/rad", "N m", "N m"),
        "tau_f = fv dq + fc tanh(dq / width) + fo, width: the smooth sign's width (a multiple of "
        "the standstill band of the velocity noise)",
        columns,
        (0.0, 0.0, -np.inf),
        (np.inf, np.inf, np.inf),
        _mjcf,
        _canonical,
    ),
    band_key="width",
)
