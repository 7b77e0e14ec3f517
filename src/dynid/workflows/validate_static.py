"""``dynid validate`` on static data: a model's ``M(q)`` and ``g(q)`` at held-out
configurations (:mod:`dynid.identification.static_validation`).

The paper's route identifies from the controller's ``M`` and ``g`` at static
configurations; its held-out check is a second such file (``dynid acquire-static`` with
another seed, or configurations the identification did not use). One file a call: the
configurations are independent, so several files are one file's rows.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..dynamics.terms import gravity_torques, mass_matrix
from ..exceptions import DataError
from ..identification.model import IdentifiedModel, kinematics_of
from ..identification.static_validation import StaticValidation, static_validation
from ..io.static_data import load_static_data
from ..model.robot import Robot
from ..regressors.static import static_regressor
from .data_files import data_files, data_kind

__all__ = ["base_coefficients", "static_files", "validate_static_file"]


def static_files(data: str | Path | Sequence[str | Path]) -> Path | None:
    """The static data file among ``data``, or None when every file is a torque log.

    Raises
    ------
    DataError
        Static data beside torque logs, or several static data files.
    """
    paths = data_files(data)
    kinds = []
    for path in paths:
        try:
            kinds.append(data_kind(path))
        except (DataError, OSError):  # the torque log's reader names it in its own words
            kinds.append("torque_log")
    static = [p for p, k in zip(paths, kinds, strict=True) if k == "static"]
    if not static:
        return None
    if len(static) < len(paths):
        raise DataError(
            f"{static[0].name} holds static data (q, M, g) and the other files torque logs: "
            "validate judges one kind a call"
        )
    if len(static) > 1:
        raise DataError(
            f"{static[0].name} holds static data: give one static data file ({len(static)} "
            "given; their configurations are one file's rows)"
        )
    return static[0]


def validate_static_file(
    model: IdentifiedModel | Robot, path: str | Path, *, drop_invalid: bool = False
) -> StaticValidation:
    """Compare ``model``'s ``M(q)`` [kg m^2] and ``g(q)`` [N m] with a static data file
    (``q``, ``M``, ``g`` at each configuration): an identified model's own (its drive's
    rotor inertia in ``M``), or a robot's link parameters.

    Raises
    ------
    DataError
        A bad file, data of another robot (:func:`~dynid.io.static_data.load_static_data`).
    """
    robot = kinematics_of(model)
    data, _ = load_static_data(path, robot, drop_invalid=drop_invalid)
    q = np.asarray(data.q)
    if isinstance(model, IdentifiedModel):
        M, g = model.mass_matrix(q), model.gravity_torques(q)
        spread = base_coefficients(model, q)
    else:
        M, g, spread = mass_matrix(model, q), gravity_torques(model, q), None
    return static_validation(M, g, data, robot.joint_names, spread)


def base_coefficients(
    model: IdentifiedModel, q: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """The model's base regressor of ``[tril M; g]`` at ``q`` (N, n (n + 1) / 2 + n, r:
    the static regressor's columns of the independent parameters) and its base
    parameters' covariance (r, r) [their units squared]; None without a covariance, or for
    a base that holds rotor inertias."""
    cov = model.fit.covariance
    if cov is None or model.base.n_std != 10 * model.robot.n:
        return None
    Y = static_regressor(model.robot, q)[..., np.asarray(model.base.independent)]
    return Y, np.asarray(cov, dtype=float)
