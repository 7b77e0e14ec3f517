"""The built-in Franka Research 3 (FR3): the Panda's kinematics with the FR3's own limits.

Kinematics and flange: the Panda's (:mod:`dynid.model.panda`); Franka documents the same
modified DH table for the FR3 (a_i, d_i, alpha_i and the flange 0.107 m along z7).

Limits: Franka's documentation, "Limits for Franka Research 3" (frankaemika/docs,
control_parameters, table ``control-parameters-joint-fr3.csv``): position [rad], velocity
[rad/s], acceleration [rad/s^2], jerk [rad/s^3], torque [N m] and torque rate [N m/s] per
joint. A :class:`~dynid.model.robot.Robot` holds the position, velocity, acceleration and
torque limits; the jerk and torque-rate limits are kept here (:data:`FR3_DDDQ_MAX`,
:data:`FR3_DTAU_MAX`) for controllers that need them.

Inertial parameters and friction: **the Panda's** (the feasible set of Gaz et al. 2019, see
:mod:`dynid.model.panda`). Franka publishes no link parameters for the FR3; they serve as a
prior and for simulation, and the FR3's own are what an identification gives
(:data:`FR3_PARAMETER_NOTE`).
"""

from __future__ import annotations

import numpy as np

from .panda import PANDA_NEUTRAL_Q, panda
from .robot import Robot

__all__ = [
    "fr3",
    "FR3_Q_MIN",
    "FR3_Q_MAX",
    "FR3_DQ_MAX",
    "FR3_DDQ_MAX",
    "FR3_DDDQ_MAX",
    "FR3_TAU_MAX",
    "FR3_DTAU_MAX",
    "FR3_PARAMETER_NOTE",
]

#: Position limits [rad] (Franka's FR3 control parameters, see the module docstring).
FR3_Q_MIN = (-2.7437, -1.7837, -2.9007, -3.0421, -2.8065, 0.5445, -3.0159)
FR3_Q_MAX = (2.7437, 1.7837, 2.9007, -0.1518, 2.8065, 4.5169, 3.0159)
#: Velocity limits [rad/s].
FR3_DQ_MAX = (2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26)
#: Acceleration limits [rad/s^2].
FR3_DDQ_MAX = (10.0, 10.0, 10.0, 10.0, 10.0, 10.0, 10.0)
#: Jerk limits [rad/s^3] (not held by a Robot).
FR3_DDDQ_MAX = (5000.0, 5000.0, 5000.0, 5000.0, 5000.0, 5000.0, 5000.0)
#: Torque limits [N m].
FR3_TAU_MAX = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)
#: Torque-rate limits [N m/s] (not held by a Robot).
FR3_DTAU_MAX = (1000.0, 1000.0, 1000.0, 1000.0, 1000.0, 1000.0, 1000.0)

#: Where the FR3's link parameters and friction come from, said wherever they are used.
FR3_PARAMETER_NOTE = (
    "the link parameters and friction of 'fr3' are the Panda's (Gaz et al. 2019): Franka "
    "publishes none for the FR3"
)


def fr3() -> Robot:
    """The Franka Research 3: the Panda's kinematics, flange and parameters, the FR3's limits.

    Returns
    -------
    Robot
        Named ``fr3``; 7 revolute joints ``joint1..joint7``, links ``link0..link7``, frame
        ``flange`` 0.107 m along z7; gravity 9.80665 m/s^2 along -z of ``link0``; limits
        :data:`FR3_Q_MIN` .. :data:`FR3_TAU_MAX`; link parameters and friction the Panda's
        (:data:`FR3_PARAMETER_NOTE`); neutral pose :data:`~dynid.model.panda.PANDA_NEUTRAL_Q`,
        which lies within the FR3's limits.
    """
    return panda().replace(
        name="fr3",
        q_min=np.array(FR3_Q_MIN),
        q_max=np.array(FR3_Q_MAX),
        dq_max=np.array(FR3_DQ_MAX),
        ddq_max=np.array(FR3_DDQ_MAX),
        tau_max=np.array(FR3_TAU_MAX),
        q_neutral=PANDA_NEUTRAL_Q,
    )
