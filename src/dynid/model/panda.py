"""The built-in Franka Emika Panda (FER).

Kinematics: modified DH table of Gaz et al. 2019 (Fig. 1) and Franka's documentation; the
flange (frame 8) is 0.107 m along z7. Link frames ``link0..link7`` coincide with the
``panda_link0..7`` frames of Franka's URDF.

Inertial parameters: the feasible set p_hat of Gaz et al., "Dynamic Identification of the
Franka Emika Panda Robot With Retrieval of Feasible Parameters Using Penalty-Based
Optimization", IEEE RA-L 4(4):4147-4154, 2019 (supplementary material, Tables VIII and IX;
identical to ``DynPars2VREP.m`` of marcocognetti/FrankaEmikaPandaDynModel). Mass [kg],
CoM in the MDH link frame [m], inertia about the CoM in link axes [kg m^2], order
``xx, xy, xz, yy, yz, zz``. The CoM z of link 1 is not identifiable and is stored as 0.

Friction: the sigmoid model of the same paper (supplementary Table I),
``tau_f = phi1 / (1 + exp(-phi2 (dq + phi3))) - phi1 / (1 + exp(-phi2 phi3))``.

Limits: Franka's "Limits for Panda" (frankaemika/docs, control_parameters).
"""

from __future__ import annotations

import numpy as np

from .robot import Robot

__all__ = [
    "panda",
    "PANDA_FRICTION",
    "PANDA_NEUTRAL_Q",
    "GAZ2019_EXCITING_A",
    "GAZ2019_EXCITING_B",
    "GAZ2019_EXCITING_Q_START",
    "GAZ2019_EXCITING_W_F",
    "GAZ2019_EXCITING_DURATION",
    "GAZ2019_EXCITING_RAMP",
    "PANDA_RETRIEVAL_COM_BOX",
    "PANDA_RETRIEVAL_INERTIA_DIAG_MAX",
    "PANDA_RETRIEVAL_MASS",
    "PANDA_RETRIEVAL_TOTAL_MASS",
]

_A = [0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088]
_D = [0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0]
_ALPHA = [0.0, -np.pi / 2, np.pi / 2, np.pi / 2, -np.pi / 2, np.pi / 2, np.pi / 2]
_FLANGE = (0.0, 0.107, 0.0, 0.0)

_MASS = [4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522]
_COM = [
    [0.003875, 0.002081, 0.0],
    [-0.003141, -0.02872, 0.003495],
    [0.027518, 0.039252, -0.066502],
    [-0.05317, 0.104419, 0.027454],
    [-0.011953, 0.041065, -0.038437],
    [0.060149, -0.014117, -0.010517],
    [0.010517, -0.004252, 0.061597],
]
_INERTIA = [  # xx, xy, xz, yy, yz, zz about the CoM
    [0.70337, -0.000139, 0.006772, 0.70661, 0.019169, 0.009117],
    [0.007962, -0.003925, 0.010254, 0.02811, 0.000704, 0.025995],
    [0.037242, -0.004761, -0.011396, 0.036155, -0.012805, 0.01083],
    [0.025853, 0.007796, -0.001332, 0.019552, 0.008641, 0.028323],
    [0.035549, -0.002117, -0.004037, 0.029474, 0.000229, 0.008627],
    [0.001964, 0.000109, -0.001158, 0.004354, 0.000341, 0.005433],
    [0.012516, -0.000428, -0.001196, 0.010027, -0.000741, 0.004815],
]
#: The Panda's published sigmoid friction parameters (module docstring), (7, 3): columns
#: ``phi1 [N m], phi2 [s/rad], phi3 [rad/s]``; :func:`panda` holds them as a
#: ``dynid.SigmoidFriction``.
PANDA_FRICTION = np.array(
    [
        [0.54615, 0.87224, 0.64068, 1.2794, 0.83904, 0.30301, 0.56489],  # phi1 [N m]
        [5.1181, 9.0657, 10.136, 5.5903, 8.3469, 17.133, 10.336],  # phi2 [s/rad]
        [0.039533, 0.025882, -0.04607, 0.036194, 0.026226, -0.021047, 0.0035526],  # phi3 [rad/s]
    ]
).T

_Q_MAX = [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973]
_Q_MIN = [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973]
_DQ_MAX = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61]
_DDQ_MAX = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0]
_TAU_MAX = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]

#: Neutral pose [rad] (franka_ros' "ready" pose), used as the default start for IK and demos.
PANDA_NEUTRAL_Q = np.array([0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4])
PANDA_NEUTRAL_Q.setflags(write=False)


#: The exciting trajectory of Gaz et al. 2019 (supplementary material Sec. II; their
#: "Trajectory_1", files ``gen_params.txt`` and ``gen_q0.txt`` of the authors' repository
#: marcocognetti/FrankaEmikaPandaDynModel, matlab/data/Exciting_Traj): velocity
#: coefficients ``a`` (cosine) and ``b`` (sine) [rad/s] of 5 harmonics of
#: ``w_f = 0.15 pi`` rad/s per joint (rows joints 1..7), for 20 s between (1 - cos) ramps
#: of 0.5 s each, starting at rest at ``GAZ2019_EXCITING_Q_START`` [rad].
GAZ2019_EXCITING_A = (
    (-0.2031, 0.1295, -0.0090, 0.2319, -0.7598),
    (-0.0699, -0.5380, -0.2015, -0.5535, 0.2352),
    (0.3076, 0.5864, -0.4813, -0.1228, -0.5273),
    (0.1269, -0.0253, -0.2405, 0.2178, 0.6984),
    (-0.2773, -0.0857, 0.4810, 0.5311, -0.1639),
    (0.2100, -0.1194, -0.0950, -0.0964, -0.0399),
    (-0.2273, -0.5636, -0.2099, 0.5725, -0.3748),
)
#: Sine coefficients [rad/s] of the same trajectory (see :data:`GAZ2019_EXCITING_A`).
GAZ2019_EXCITING_B = (
    (-0.1136, 0.6600, -0.1858, 0.1867, 0.2357),
    (-0.2437, 0.1820, -0.2390, -0.2647, 0.4252),
    (0.3898, -0.0268, 0.0179, 0.4767, 0.2726),
    (0.0401, -0.1503, 0.2359, -0.2022, 0.3693),
    (0.5491, 0.1046, 0.0407, -0.0432, 0.2448),
    (0.0692, -0.6946, -0.4442, -0.5749, -0.0698),
    (0.2023, -0.2570, -0.5010, 0.0774, -0.4833),
)
#: Start (rest) position [rad] of the same trajectory.
GAZ2019_EXCITING_Q_START = (-0.9584, 0.5622, -1.4576, -2.2141, -2.5711, 3.0661, -0.164597)
#: Base angular frequency [rad/s], duration of the Fourier part [s] and of the two ramps
#: together [s] of the same trajectory.
GAZ2019_EXCITING_W_F = 0.15 * np.pi
GAZ2019_EXCITING_DURATION = 20.0
GAZ2019_EXCITING_RAMP = 1.0


def panda() -> Robot:
    """The Franka Emika Panda with the published feasible parameters and friction.

    Returns
    -------
    Robot
        7 revolute joints ``joint1..joint7``, links ``link0..link7``, frame ``flange``
        0.107 m along z7; gravity 9.80665 m/s^2 along -z of ``link0``; friction the
        published sigmoid (:data:`PANDA_FRICTION`).
    """
    # The one friction type is built from the law registry of a later layer, imported when
    # called (tests/test_layers.py lists this facade): the published data is an array.
    from ..friction.model import SigmoidFriction

    robot = Robot.from_mdh(
        _A,
        _D,
        _ALPHA,
        flange=_FLANGE,
        mass=_MASS,
        com=_COM,
        inertia=np.asarray(_INERTIA),
        q_min=_Q_MIN,
        q_max=_Q_MAX,
        dq_max=_DQ_MAX,
        ddq_max=_DDQ_MAX,
        tau_max=_TAU_MAX,
        friction=SigmoidFriction.from_array(PANDA_FRICTION),
        name="panda",
    )
    return robot.replace(q_neutral=PANDA_NEUTRAL_Q)


#: Bounds of the Panda used by Gaz et al. 2019 for the retrieval (marcocognetti/
#: FrankaEmikaPandaDynModel, matlab/parameters_retrieval/bounds_gM.csv): masses 0..10 kg,
#: CoM boxes from the link geometry in the MDH frames [m] (x, y, z ranges per link),
#: total mass of links 1..7 in 16..20 kg (error_fcn_gM_LMI.m).
PANDA_RETRIEVAL_COM_BOX = (
    ((-0.05, 0.05), (-0.05, 0.05), (-0.40, 0.05)),
    ((-0.05, 0.05), (-0.15, 0.05), (-0.05, 0.05)),
    ((-0.05, 0.15), (-0.05, 0.05), (-0.10, 0.05)),
    ((-0.15, 0.05), (-0.05, 0.15), (-0.05, 0.05)),
    ((-0.05, 0.05), (-0.05, 0.05), (-0.35, 0.05)),
    ((-0.05, 0.15), (-0.05, 0.05), (-0.05, 0.05)),
    ((-0.05, 0.05), (-0.05, 0.05), (0.04, 0.15)),
)
PANDA_RETRIEVAL_MASS = (0.0, 10.0)
PANDA_RETRIEVAL_TOTAL_MASS = (16.0, 20.0)
PANDA_RETRIEVAL_INERTIA_DIAG_MAX = 1.0
