"""dynid: kinematics, dynamics and dynamic identification of robot manipulators.

The pipeline, in the order data flows (each name is re-exported here):

* model: :func:`panda`, :class:`Robot` (``from_mdh``, ``from_urdf``, ``from_toml``)
* kinematics: :func:`fk`, :func:`jacobian`, :func:`jacobian_to_tool`, :func:`ik`,
  trajectories (:func:`sinusoid_trajectory`, :func:`random_fourier`, :func:`check_limits`)
* dynamics: :func:`rnea`, :func:`mass_matrix`, :func:`gravity_torques`, :func:`coriolis`,
  :func:`coriolis_matrix`, :func:`forward_dynamics`
* regressors: :func:`torque_regressor`, :func:`static_regressor`, :func:`base_parameters`,
  :func:`identifiability`
* identification: :func:`identify_static` (Gaz et al. 2019, Sec. IV-A),
  :func:`identify_from_log` (classical route), :class:`IdentifiedModel`
* friction: :func:`fit_friction`, :func:`sigmoid_friction`, :func:`validate_torques`
* simulation: :class:`SimulatedController`, :func:`acquire_static`, :func:`simulate_measurement`,
  :func:`select_static_configurations`, :func:`optimise_excitation` (:class:`ExcitingTrajectory`,
  :class:`ExcitationOptions`, :class:`Obstacles`)
* feasibility: see :mod:`dynid.feasibility`
* files: :mod:`dynid.io`; figures: :mod:`dynid.plots` (matplotlib, imported lazily)

Conventions: SI units, batch-first arrays (``(..., n)`` joint vectors, ``(..., 4, 4)``
poses), ``T_a_b`` is the pose of frame b in frame a, gravity 9.80665 m/s^2 along -z of the
base by default; standard parameters are 10 per link (m, m c, J about the link origin).
"""

from .dynamics.rnea import rnea
from .dynamics.terms import (
    coriolis,
    coriolis_matrix,
    forward_dynamics,
    gravity_torques,
    mass_matrix,
)
from .exceptions import (
    ConvergenceError,
    DataError,
    DynidError,
    DynidWarning,
    InfeasibleError,
    LimitError,
    ModelError,
    NonFiniteError,
    RankDeficientError,
    ShapeError,
    SolverError,
    UnknownNameError,
)
from .friction.fit import FrictionFit, fit_friction
from .friction.model import ClassicalFriction, SigmoidFriction, classical_friction, sigmoid_friction
from .friction.validation import Validation
from .friction.validation import validate as validate_torques
from .identification.classical import identify_from_log
from .identification.data import StaticDataset
from .identification.least_squares import LeastSquaresFit, fit_least_squares
from .identification.log import TorqueLog
from .identification.model import IdentifiedModel
from .identification.static import identify_static
from .kinematics.forward import fk, joint_transforms, link_poses
from .kinematics.ik import IKOptions, IKResult, ik
from .kinematics.jacobian import jacobian, jacobian_to_tool
from .kinematics.trajectories import (
    Trajectory,
    check_limits,
    random_fourier,
    scale_into_limits,
    sinusoid_trajectory,
)
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
from .simulation.measurement import SensorNoise, simulate_measurement
from .simulation.static_selection import StaticSelection, select_static_configurations

__version__ = "0.1.0"

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
