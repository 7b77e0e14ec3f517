"""Stribeck friction on the smooth sign: the Stribeck law with ``tanh(dq / v_s)`` for ``s``.

.. math:: \\tau_f(\\dot q) = f_v \\dot q
          + \\big(f_c + (f_s - f_c)\\, e^{-(\\dot q / v_{st})^2}\\big)
          \\tanh(\\dot q / v_s) + f_o

``v_s`` [rad/s] is not fitted: it is the law's band, as for
:mod:`dynid.friction.laws.smooth`. ``identify`` chooses it on held-out data among multiples
of the velocity noise band; the narrowest (0.3 bands, about the noise's standard deviation)
is the expected sign of a sharp law given the noise. A Stribeck bump of height ``fs - fc``
sits right where the measured velocity crosses zero, and the banded sign of
:mod:`dynid.friction.laws.stribeck` switches all of it off there (a Kinova-like arm with a
bump of 0.8 ``fc`` at 0.05 rad/s: held-out error 6.6 % banded, 4.3 % on the smooth sign,
against a noise floor of 3 %). Parameters, bounds, fit and MuJoCo mapping as the
Stribeck law's; ``dynid friction`` fits it only when named (at the band itself the bump
merely reshapes a ``tanh`` wider than the noise).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ...regressors.friction_columns import smooth_sign
from .base import canonical_rows
from .stribeck import stribeck_law

__all__ = ["LAW"]


def _canonical(P: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    # (fc + (fs - fc) e) tanh(dq / band): the bump takes the Coulomb term's tanh where
    # ``vs > 0``, the plain sign where the band is 0 (the banded law's with a band of 0)
    fv, fc, fs, vst, fo = P.T
    smooth = band > 0
    sign = np.where(smooth, 0.0, fc)
    return canonical_rows(
        np.zeros_like(band), fv_pos=fv, fv_neg=fv, fc_pos=sign, fc_neg=sign, fo=fo,
        fs_minus_fc=fs - fc, vst=vst, ft=np.where(smooth, fc, 0.0), vs=band,
    )  # fmt: skip


LAW = stribeck_law(
    "smooth_stribeck",
    smooth_sign,
    "s(dq) = tanh(dq / width), width: the smooth sign's width (a multiple of the standstill "
    "band of the velocity noise)",
    _canonical,
    compared=False,
)
LAW = replace(LAW, band_key="width")
