"""Identification of the dynamic coefficients from ``M(q)`` and ``g(q)`` at static configurations.

Gaz et al. 2019, Sec. IV-A ("reverse engineering" of the controller's model library): at
each of ``N`` configurations the inertia matrix and the gravity torques are linear in the
base parameters ``beta``,

.. math:: s(q_s) = \\begin{bmatrix} \\mathrm{tril}\\, M(q_s) \\\\ g(q_s) \\end{bmatrix}
          = Y_b(q_s) \\, \\beta \\quad \\text{(eqs. 17-19)}

and stacking the configurations gives the overdetermined system of eq. 20,
``W beta = y``, solved by least squares (eq. 21; :mod:`dynid.identification.least_squares`).
The rows of ``s(q)`` are ordered as :func:`dynid.regressors.static.static_labels` (``tril
M`` by ``np.tril_indices``, then ``g``). Internally the stack is held row-major over (row of
``s``, configuration) so that ``W`` is column-major for LAPACK and BLAS without a copy; the
order of the rows does not change a least-squares solution or its statistics. Only the
columns of the base parameters are computed. Row ``(i, j)`` of ``tril M`` and row ``g_i``
do not depend on the parameters of the links before link ``i``, so each row of ``s`` is a
block of ``N`` rows of ``W`` that is exactly zero in those columns (with the base columns
in increasing order, a leading block of them): the products over the rows of ``W`` (Gram
matrix, ``W^T y``, residuals, robust covariance) skip them, and the Gram matrix of each
block gives the sums of squares of the row check below.

Rows that carry no information about ``beta`` for this robot are found numerically over
the data set and dropped: a row whose (column-scaled) regressor vanishes at every
configuration, such as the gravity torque of joint 1 when gravity is along the joint-1
axis (``g1`` of the Panda). Keeping them would add equations ``0 = 0`` that lower the
residual variance estimate. Their labels are recorded in the model's metadata.

Standard deviations are by default the heteroscedasticity-consistent ones
(``std="robust"``): the stacked vector mixes kg m^2 and N m and a controller's errors scale
with each entry, so the paper's single-variance formula (``std="classical"``) misstates
them (see :func:`identify_static`).

The steps are those of every route (:func:`dynid.identification.core.identify`); the
static data set's rows are :meth:`~dynid.identification.data.StaticDataset.blocks`.

:func:`basis_transform` and :func:`coefficients_in_basis` express identified coefficients
in another basis defined on the standard parameters, e.g. the 43 expressions printed by
Gaz et al. (supplementary Table III).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import RankDeficientError, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot, checked_robot
from ..regressors.base import BaseParameters
from .core import identify, informative_blocks
from .data import STATIC_EXPECTED, StaticDataset
from .estimators import Estimator, EstimatorName
from .least_squares import StdMethod
from .model import IdentifiedModel

__all__ = ["identify_static", "informative_static_rows", "basis_transform", "coefficients_in_basis"]


def informative_static_rows(Y_b: ArrayLike, *, rtol: float = 1e-10) -> NDArray[np.bool_]:
    """Which rows of the static vector carry information about the base parameters.

    Parameters
    ----------
    Y_b : array_like, shape (N, s, r)
        Base regressor at ``N`` configurations, ``s = n (n + 1) / 2 + n`` rows each.
    rtol : float
        A row is uninformative when the norm of its block (over configurations and
        column-scaled coefficients) is at most ``rtol`` times the largest block norm.

    Returns
    -------
    informative : ndarray of bool, shape (s,)
    """
    Y = _checks.as_array("Y_b", Y_b)
    if Y.ndim != 3:
        raise ShapeError(f"Y_b must have shape (N, s, r); got {Y.shape}")
    return informative_blocks(np.einsum("bkj,bkj->jk", Y, Y), rtol)


def identify_static(
    robot: Robot,
    data: StaticDataset,
    *,
    max_std_percent: float | None = None,
    rtol: float | None = None,
    base: BaseParameters | None = None,
    std: StdMethod = "robust",
    drive: Drive | None = None,
    estimator: EstimatorName | Estimator = "ols",
) -> IdentifiedModel:
    """Identify the base parameters from inertia matrices and gravity torques at rest.

    .. math:: \\hat\\beta = \\arg\\min_\\beta \\|W \\beta - y\\|^2, \\quad
              W = \\begin{bmatrix} Y_b(q_1) \\\\ \\vdots \\\\ Y_b(q_N) \\end{bmatrix},\\;
              y = \\begin{bmatrix} s(q_1) \\\\ \\vdots \\\\ s(q_N) \\end{bmatrix}
              \\quad \\text{(Gaz et al. 2019, eqs. 20-21)}

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity vector the data were recorded with; its inertial
        parameters are not used.
    data : StaticDataset
        ``q`` (N, n) [rad], ``M`` (N, n, n) [kg m^2], ``g`` (N, n) [N m].
    max_std_percent : float, optional
        Remove the coefficients whose relative standard deviation exceeds this (the paper
        used 30 %) and re-fit the rest (one pass); removed coefficients are 0.
    rtol : float, optional
        Relative rank tolerance of the base parameters (singular values of the
        column-scaled regressor), of the fit (diagonal of R) and threshold for
        uninformative rows (:func:`informative_static_rows`). Default: the base
        parameters' rank from the first clear gap in the singular values
        (:func:`dynid.regressors.base.rank_from_gap`), and ``1e-10`` for the rest.
    base : BaseParameters, optional
        The base parameters to identify; default ``base_parameters(robot, rtol=rtol)``
        (the structural ones, from random configurations).
    std : {"robust", "classical"}
        Standard deviations from the heteroscedasticity-consistent covariance (White 1980,
        HC1; default) or from ``sigma^2 (W^T W)^{-1}`` (the paper's formula, valid when
        every row has the same error variance).
    drive : Drive, optional
        A drive train whose rotors the controller's ``M`` includes
        (``K^T diag(I_a) K``, :mod:`dynid.model.drive`): unknown rotor inertias are
        identified with the links (``Ia1 .. Ia_n`` after the link parameters in
        ``base.std_labels``), known ones subtracted from ``M``.
    estimator : {"ols", "wls", "irls"} or Estimator
        Ordinary least squares (default), weighted by the noise level of each row of
        ``[tril M; g]``, or Huber-robust (:mod:`dynid.identification.estimators`).

    Returns
    -------
    IdentifiedModel
        ``fit`` holds ``beta`` (r,) with std, std %, rank, condition number and relative
        error (%); ``info`` records ``route="static"``, ``n_rows``, ``dropped_rows``
        (labels such as ``"g1"``), ``pruned`` (labels of removed coefficients),
        ``max_std_percent``, ``std``, ``estimator``, ``rtol``, the configurations
        (``static``) and the data set's own metadata (``data``).

    Raises
    ------
    DataError
        The data set's joint count differs from the robot's.
    ShapeError
        ``base`` was built for a different number of standard parameters.
    RankDeficientError
        The stacked regressor has rank below the number of base parameters (too few or
        too similar configurations); the message gives the rank found and the rank needed.
    OptionError
        ``max_std_percent`` not positive, or an unknown ``std``.

    Warns
    -----
    DynidWarning
        A dropped (identically zero) row holds non-zero data: the gravity vector or the
        kinematics probably differ from the controller's. The regressor is
        ill-conditioned, or a kept coefficient has a standard deviation above 1000 %
        (:func:`~dynid.identification.least_squares.conditioning_advice`: the message names
        the columns and what to do).

    Notes
    -----
    With the Panda, 1010 configurations and noise-free data the fit recovers the
    coefficients of the generating parameters to round-off; rank 43 after ``g1`` is dropped.
    """
    checked_robot(robot)
    data = _checks.of_type("data", data, StaticDataset, STATIC_EXPECTED)
    return identify(
        robot,
        data,
        drive=drive,
        base=base,
        estimator=estimator,
        std=std,
        max_std_percent=max_std_percent,
        rtol=rtol,
    )


def basis_transform(
    base: BaseParameters,
    A: ArrayLike,
    *,
    labels: tuple[str, ...] | None = None,
    rtol: float = 1e-8,
) -> NDArray[np.float64]:
    """The matrix ``T`` (k, r) with ``A phi = T beta`` for every standard parameter vector.

    ``A`` defines ``k`` coefficients as linear combinations of the standard parameters
    (e.g. the 43 expressions of Gaz et al. 2019). They are functions of the base
    parameters exactly when every row of ``A`` lies in the row space of the base
    projection ``P`` (``beta = P phi``); then ``T = A P^+``.

    Parameters
    ----------
    base : BaseParameters
    A : array_like, shape (k, p)
        Coefficients on the standard parameters, columns as ``base.std_labels``.
    labels : tuple of str, length k, optional
        Names of the coefficients, used in error messages.
    rtol : float
        Tolerance of the row-space test, relative to each row's norm.

    Returns
    -------
    T : ndarray, shape (k, r)

    Raises
    ------
    ShapeError
        ``A`` not (k, p).
    RankDeficientError
        A row of ``A`` is not a combination of the base parameters (it cannot be
        identified); the message names the first such row and its residual.
    """
    A = _checks.as_array("A", A)
    p = base.n_std
    if A.ndim != 2 or A.shape[1] != p:
        raise ShapeError(f"A must have shape (k, {p}); got {A.shape}")
    P = base.projection
    T = np.asarray(np.linalg.lstsq(P.T, A.T, rcond=None)[0].T, dtype=np.float64)
    res = np.linalg.norm(T @ P - A, axis=1)
    scale = np.linalg.norm(A, axis=1)
    bad = np.flatnonzero(res > rtol * np.maximum(scale, np.finfo(float).tiny))
    if bad.size:
        k = int(bad[0])
        name = f" ({labels[k]!r})" if labels is not None else ""
        raise RankDeficientError(
            f"row {k}{name} of A is not a combination of the base parameters (residual "
            f"{res[k] / scale[k]:.3g} relative, tolerance {rtol:g}); {bad.size} row(s) in all "
            "cannot be identified; hint: check the labels' order and the kinematic constants"
        )
    return T


def coefficients_in_basis(
    base: BaseParameters, beta: ArrayLike, A: ArrayLike, *, rtol: float = 1e-8
) -> NDArray[np.float64]:
    """Values of the coefficients ``A phi`` from base parameters ``beta``: (..., r) -> (..., k).

    See :func:`basis_transform` (which raises when ``A`` is not identifiable).
    """
    b = _checks.as_batch("beta", beta, (base.rank,))
    T = basis_transform(base, A, rtol=rtol)
    return b @ T.T
