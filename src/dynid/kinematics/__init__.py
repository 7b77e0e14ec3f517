"""Kinematics: forward kinematics, geometric Jacobians and inverse kinematics.

Poses are ``T_base_x`` (frame x in the base frame, link 0) [m]; Jacobians have rows
``[v; w]`` expressed in the base frame, about the origin of the frame (or tool) they
belong to. See :mod:`.forward`, :mod:`.jacobian` and :mod:`.inverse` (the IK driver; its
numpy loop and :mod:`._ik_kernel`, the compiled solve).
"""

from .forward import fk, frame_pose_in_link, joint_transforms, link_poses
from .inverse import IKOptions, IKResult, default_q0, ik
from .jacobian import jacobian, jacobian_to_tool

__all__ = [
    "IKOptions",
    "IKResult",
    "default_q0",
    "fk",
    "frame_pose_in_link",
    "ik",
    "jacobian",
    "jacobian_to_tool",
    "joint_transforms",
    "link_poses",
]
