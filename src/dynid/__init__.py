"""dynid: kinematics, dynamics and dynamic identification of robot manipulators.

The pipeline, in the order data flows (each name is re-exported here):

* model: :func:`panda`, :func:`fr3`, :class:`Robot` (``from_mdh``, ``from_urdf``, ``from_toml``)
* kinematics: :func:`fk`, :func:`jacobian`, :func:`jacobian_to_tool`, :func:`ik`
* dynamics: :func:`rnea`, :func:`mass_matrix`, :func:`gravity_torques`, :func:`coriolis`,
  :func:`coriolis_matrix`, :func:`forward_dynamics`
* regressors: :func:`torque_regressor`, :func:`static_regressor`, :func:`base_parameters`,
  :func:`identifiability`
* identification: :func:`identify_static` (Gaz et al. 2019, Sec. IV-A),
  :func:`identify_from_log` (a torque log: its terms chosen on held-out data, as ``dynid
  identify`` chooses them), :class:`IdentifiedModel`
* friction: :func:`fit_friction`, :func:`sigmoid_friction`, :func:`validate_torques`,
  :func:`model_torques` (a model's whole torques: links, rotors, spring and friction)
* simulation: trajectories (:func:`sinusoid_trajectory`, :func:`random_fourier`,
  :func:`check_limits`), :class:`SimulatedController`, :func:`acquire_static`,
  :func:`simulate_measurement`,
  :func:`select_static_configurations`, :func:`optimise_excitation` (:class:`ExcitingTrajectory`,
  :class:`ExcitationOptions`, :class:`Obstacles`)
* feasibility: see :mod:`dynid.feasibility`
* files: :mod:`dynid.io`; figures: :mod:`dynid.plots` (matplotlib, imported lazily)
* errors: :class:`DynidError` and every subclass of :mod:`dynid.exceptions` (each also a
  builtin: ``ShapeError`` a ``ValueError``, ``WrongTypeError`` a ``TypeError``, ...)

Conventions: SI units, batch-first arrays (``(..., n)`` joint vectors, ``(..., 4, 4)``
poses), ``T_a_b`` is the pose of frame b in frame a, gravity 9.80665 m/s^2 along -z of the
base by default; standard parameters are 10 per link (m, m c, J about the link origin).
"""

import importlib
from typing import TYPE_CHECKING, Any

from .exceptions import (
    ConvergenceError,
    DataError,
    DynidError,
    DynidWarning,
    InfeasibleError,
    LimitError,
    ModelError,
    NonFiniteError,
    OptionError,
    OutputError,
    RankDeficientError,
    ShapeError,
    SolverError,
    UnknownNameError,
    WrongTypeError,
)

if TYPE_CHECKING:  # the names as static imports, for type checkers and editors
    from .dynamics.rnea import rnea
    from .dynamics.terms import (
        coriolis,
        coriolis_matrix,
        forward_dynamics,
        gravity_torques,
        mass_matrix,
    )
    from .friction.fit import FrictionFit, fit_friction
    from .friction.model import (
        ClassicalFriction,
        Friction,
        SigmoidFriction,
        classical_friction,
        sigmoid_friction,
    )
    from .friction.validation import Validation, model_torques, validate_torques
    from .identification.classical import identify_from_log
    from .identification.data import StaticDataset
    from .identification.least_squares import LeastSquaresFit, fit_least_squares
    from .identification.log import TorqueLog
    from .identification.model import IdentifiedModel
    from .identification.static import identify_static
    from .kinematics.forward import fk, joint_transforms, link_poses
    from .kinematics.inverse import IKOptions, IKResult, ik
    from .kinematics.jacobian import jacobian, jacobian_to_tool
    from .model.fr3 import fr3
    from .model.inertia import inertial_from_phi, param_labels, phi_from_inertial
    from .model.panda import PANDA_NEUTRAL_Q, panda
    from .model.robot import Frame, Robot
    from .regressors.base import BaseParameters, base_parameters, identifiability
    from .regressors.static import static_regressor
    from .regressors.torque import torque_regressor
    from .simulation.collision import Box, Obstacles, Plane
    from .simulation.controller import (
        SimulatedController,
        acquire_static,
        acquire_static_at,
        sample_configurations,
    )
    from .simulation.excitation import (
        ExcitationOptions,
        ExcitationResult,
        ExcitingTrajectory,
        excitation_condition_number,
        optimise_excitation,
    )
    from .simulation.limits import check_limits, scale_into_limits
    from .simulation.measurement import SensorNoise, simulate_measurement
    from .simulation.static_selection import StaticSelection, select_static_configurations
    from .simulation.trajectories import Trajectory, random_fourier, sinusoid_trajectory

#: public name -> (module under dynid, attribute): imported on first use (PEP 562), so that
#: ``import dynid`` (and every command line call) loads only what it uses
_LAZY: dict[str, tuple[str, str]] = {
    "BaseParameters": ("regressors.base", "BaseParameters"),
    "Box": ("simulation.collision", "Box"),
    "ClassicalFriction": ("friction.model", "ClassicalFriction"),
    "ExcitationOptions": ("simulation.excitation", "ExcitationOptions"),
    "ExcitationResult": ("simulation.excitation", "ExcitationResult"),
    "ExcitingTrajectory": ("simulation.excitation", "ExcitingTrajectory"),
    "Frame": ("model.robot", "Frame"),
    "Friction": ("friction.model", "Friction"),
    "FrictionFit": ("friction.fit", "FrictionFit"),
    "IKOptions": ("kinematics.inverse", "IKOptions"),
    "IKResult": ("kinematics.inverse", "IKResult"),
    "IdentifiedModel": ("identification.model", "IdentifiedModel"),
    "LeastSquaresFit": ("identification.least_squares", "LeastSquaresFit"),
    "Obstacles": ("simulation.collision", "Obstacles"),
    "PANDA_NEUTRAL_Q": ("model.panda", "PANDA_NEUTRAL_Q"),
    "Plane": ("simulation.collision", "Plane"),
    "Robot": ("model.robot", "Robot"),
    "SensorNoise": ("simulation.measurement", "SensorNoise"),
    "SigmoidFriction": ("friction.model", "SigmoidFriction"),
    "SimulatedController": ("simulation.controller", "SimulatedController"),
    "StaticDataset": ("identification.data", "StaticDataset"),
    "StaticSelection": ("simulation.static_selection", "StaticSelection"),
    "TorqueLog": ("identification.log", "TorqueLog"),
    "Trajectory": ("simulation.trajectories", "Trajectory"),
    "Validation": ("friction.validation", "Validation"),
    "acquire_static": ("simulation.controller", "acquire_static"),
    "acquire_static_at": ("simulation.controller", "acquire_static_at"),
    "base_parameters": ("regressors.base", "base_parameters"),
    "check_limits": ("simulation.limits", "check_limits"),
    "classical_friction": ("friction.model", "classical_friction"),
    "coriolis": ("dynamics.terms", "coriolis"),
    "coriolis_matrix": ("dynamics.terms", "coriolis_matrix"),
    "excitation_condition_number": ("simulation.excitation", "excitation_condition_number"),
    "fit_friction": ("friction.fit", "fit_friction"),
    "fit_least_squares": ("identification.least_squares", "fit_least_squares"),
    "fk": ("kinematics.forward", "fk"),
    "fr3": ("model.fr3", "fr3"),
    "forward_dynamics": ("dynamics.terms", "forward_dynamics"),
    "gravity_torques": ("dynamics.terms", "gravity_torques"),
    "identifiability": ("regressors.base", "identifiability"),
    "identify_from_log": ("identification.classical", "identify_from_log"),
    "identify_static": ("identification.static", "identify_static"),
    "ik": ("kinematics.inverse", "ik"),
    "inertial_from_phi": ("model.inertia", "inertial_from_phi"),
    "jacobian": ("kinematics.jacobian", "jacobian"),
    "jacobian_to_tool": ("kinematics.jacobian", "jacobian_to_tool"),
    "joint_transforms": ("kinematics.forward", "joint_transforms"),
    "link_poses": ("kinematics.forward", "link_poses"),
    "mass_matrix": ("dynamics.terms", "mass_matrix"),
    "model_torques": ("friction.validation", "model_torques"),
    "optimise_excitation": ("simulation.excitation", "optimise_excitation"),
    "panda": ("model.panda", "panda"),
    "param_labels": ("model.inertia", "param_labels"),
    "phi_from_inertial": ("model.inertia", "phi_from_inertial"),
    "random_fourier": ("simulation.trajectories", "random_fourier"),
    "rnea": ("dynamics.rnea", "rnea"),
    "sample_configurations": ("simulation.controller", "sample_configurations"),
    "scale_into_limits": ("simulation.limits", "scale_into_limits"),
    "select_static_configurations": ("simulation.static_selection", "select_static_configurations"),
    "sigmoid_friction": ("friction.model", "sigmoid_friction"),
    "simulate_measurement": ("simulation.measurement", "simulate_measurement"),
    "sinusoid_trajectory": ("simulation.trajectories", "sinusoid_trajectory"),
    "static_regressor": ("regressors.static", "static_regressor"),
    "torque_regressor": ("regressors.torque", "torque_regressor"),
    "validate_torques": ("friction.validation", "validate_torques"),
}

__version__ = "0.2.0"

__all__ = [
    "BaseParameters",
    "Box",
    "ClassicalFriction",
    "ConvergenceError",
    "DataError",
    "DynidError",
    "DynidWarning",
    "ExcitationOptions",
    "ExcitationResult",
    "ExcitingTrajectory",
    "Frame",
    "Friction",
    "FrictionFit",
    "IKOptions",
    "IKResult",
    "IdentifiedModel",
    "InfeasibleError",
    "LeastSquaresFit",
    "LimitError",
    "ModelError",
    "NonFiniteError",
    "Obstacles",
    "OptionError",
    "OutputError",
    "PANDA_NEUTRAL_Q",
    "Plane",
    "RankDeficientError",
    "Robot",
    "SensorNoise",
    "ShapeError",
    "SolverError",
    "SigmoidFriction",
    "SimulatedController",
    "StaticDataset",
    "StaticSelection",
    "TorqueLog",
    "Trajectory",
    "UnknownNameError",
    "Validation",
    "WrongTypeError",
    "__version__",
    "acquire_static",
    "acquire_static_at",
    "base_parameters",
    "check_limits",
    "classical_friction",
    "coriolis",
    "coriolis_matrix",
    "excitation_condition_number",
    "fit_friction",
    "fit_least_squares",
    "fk",
    "forward_dynamics",
    "fr3",
    "gravity_torques",
    "identifiability",
    "identify_from_log",
    "identify_static",
    "ik",
    "inertial_from_phi",
    "jacobian",
    "jacobian_to_tool",
    "joint_transforms",
    "link_poses",
    "mass_matrix",
    "model_torques",
    "optimise_excitation",
    "panda",
    "param_labels",
    "phi_from_inertial",
    "random_fourier",
    "rnea",
    "sample_configurations",
    "scale_into_limits",
    "select_static_configurations",
    "sigmoid_friction",
    "simulate_measurement",
    "sinusoid_trajectory",
    "static_regressor",
    "torque_regressor",
    "validate_torques",
]


#: subpackages and modules reachable as attributes (``dynid.spatial``), imported on first use
_SUBMODULES = frozenset(
    (
        "cli dynamics feasibility friction identification io kinematics model observer plots "
        "regressors signals simulation spatial"
    ).split()
)


def __getattr__(name: str) -> Any:
    """Import a public name or a subpackage on first use (PEP 562)."""
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    try:
        module, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'dynid' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(f"{__name__}.{module}"), attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
