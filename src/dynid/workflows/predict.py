"""The dynamic terms of a model at one state: the entry point of ``dynid predict``.

A model is an identified one (``identification.json``: :class:`~dynid.identification.
model.IdentifiedModel`, its rotor inertia and other appended terms included) or a set of
feasible link parameters (``feasible.json`` from ``dynid retrieve`` or ``identify
--consistent``: the robot it holds, with its drive's identified rotor inertias
``K^T diag(I_a) K`` where it holds a drive). Friction is never included.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..dynamics.rnea import rnea
from ..dynamics.terms import coriolis, gravity_torques, mass_matrix
from ..exceptions import DataError, OptionError
from ..identification.model import IdentifiedModel
from ..io.feasible import FEASIBLE_SCHEMA, load_feasible_drive, load_feasible_json
from ..io.model_json import MODEL_SCHEMA, load_model_json
from ..model.drive import Drive
from ..model.robot import Robot

__all__ = ["Predicting", "load_predicting", "model_terms"]


def model_terms(
    model: IdentifiedModel | Robot,
    q: ArrayLike,
    dq: ArrayLike | None = None,
    ddq: ArrayLike | None = None,
    drive: Drive | None = None,
) -> dict[str, NDArray[np.float64]]:
    """``M`` (n, n) [kg m^2] and ``g`` (n,) [N m] at ``q`` (n,) [rad]; with ``dq`` [rad/s]
    also ``c`` (Coriolis and centrifugal torques [N m]); with ``ddq`` [rad/s^2] too
    ``tau = M ddq + c + g`` [N m]. Of a robot, ``drive``'s rotor inertias (when it has
    them) add ``K^T diag(I_a) K`` to ``M`` and ``tau``. Friction is not included.

    Raises
    ------
    OptionError
        ``ddq`` without ``dq``.
    """
    if ddq is not None and dq is None:
        raise OptionError("--ddq needs --dq (tau = M ddq + c + g)")
    if isinstance(model, IdentifiedModel):
        out = {"M": model.mass_matrix(q), "g": model.gravity_torques(q)}
        if dq is not None:
            out["c"] = model.coriolis(q, dq)
            if ddq is not None:
                out["tau"] = model.torques(q, dq, ddq)
        return out
    rotors = None if drive is None else drive.rotor_inertia
    M = mass_matrix(model, q)
    if rotors is not None and drive is not None:
        M = M + drive.rotor_mass_matrix(rotors)
    out = {"M": M, "g": gravity_torques(model, q)}
    if dq is not None:
        out["c"] = coriolis(model, q, dq)
        if ddq is not None:
            tau = rnea(model, q, dq, ddq)
            if rotors is not None and drive is not None:
                tau = tau + drive.rotor_torques(np.asarray(ddq, dtype=np.float64), rotors)
            out["tau"] = tau
    return out


@dataclass(frozen=True, slots=True)
class Predicting:
    """A model read for :func:`model_terms`: an identified one, or a robot of feasible
    parameters with the drive it holds (None: none)."""

    model: IdentifiedModel | Robot
    drive: Drive | None = None

    @property
    def n(self) -> int:
        """The joints' count."""
        return self.model.robot.n if isinstance(self.model, IdentifiedModel) else self.model.n

    def terms(
        self, q: ArrayLike, dq: ArrayLike | None = None, ddq: ArrayLike | None = None
    ) -> dict[str, NDArray[np.float64]]:
        """:func:`model_terms` of this model."""
        return model_terms(self.model, q, dq, ddq, self.drive)


def load_predicting(model: str | Path | None, params: str | Path | None) -> Predicting:
    """The identified model ``model`` (``identification.json``) or the feasible parameters
    ``params`` (``feasible.json``, with its drive's rotor inertias): one of them.

    Raises
    ------
    OptionError
        Both or neither given.
    DataError
        A file of another schema (the one it holds named).
    """
    if (model is None) == (params is None):
        raise OptionError(
            "give one model: --model identification.json (dynid identify) or --params "
            "feasible.json (dynid retrieve, identify --consistent)"
        )
    if params is not None:
        try:
            return Predicting(load_feasible_json(params), load_feasible_drive(params))
        except DataError as exc:
            if MODEL_SCHEMA not in str(exc):
                raise
            raise DataError(f"{exc}; hint: --model reads identification.json") from exc
    assert model is not None
    try:
        return Predicting(load_model_json(model))
    except DataError as exc:
        if FEASIBLE_SCHEMA not in str(exc):
            raise
        raise DataError(f"{exc}; hint: --params reads feasible.json") from exc
