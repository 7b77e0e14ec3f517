"""dynid: kinematics, dynamics and dynamic identification of robot manipulators."""

from .dynamics.rnea import rnea
from .dynamics.terms import coriolis, coriolis_matrix, forward_dynamics, gravity_torques, mass_matrix
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
    UnknownNameError,
)
from .kinematics.forward import fk, joint_transforms, link_poses
from .kinematics.jacobian import jacobian, jacobian_to_tool
from .model.inertia import inertial_from_phi, param_labels, phi_from_inertial
from .model.panda import PANDA_NEUTRAL_Q, panda
from .model.robot import Frame, Robot

__version__ = "0.1.0"

__all__ = [
    "ConvergenceError",
    "DataError",
    "DynidError",
    "DynidWarning",
    "Frame",
    "InfeasibleError",
    "LimitError",
    "ModelError",
    "NonFiniteError",
    "PANDA_NEUTRAL_Q",
    "RankDeficientError",
    "Robot",
    "ShapeError",
    "UnknownNameError",
    "__version__",
    "coriolis",
    "coriolis_matrix",
    "fk",
    "forward_dynamics",
    "gravity_torques",
    "inertial_from_phi",
    "jacobian",
    "jacobian_to_tool",
    "joint_transforms",
    "link_poses",
    "mass_matrix",
    "panda",
    "param_labels",
    "phi_from_inertial",
    "rnea",
]
